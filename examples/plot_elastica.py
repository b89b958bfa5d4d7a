"""
Discrete elastica fairing
=========================

Fitting the closest discrete Euler elastica (Graiff Zurita, Kajiwara, Suzuki) to
digitised curves: input, initial guess and fit.

The figures are the ``elastica`` section of ``curvesmith demo``, drawn from the bundled data.
"""

from curvesmith.demo import show_section

ctx = show_section("elastica")
