"""
Linear subdivision
==================

Chaikin, de Rham and Lane–Riesenfeld corner cutting on a bundled polygon: each step
converges to its limit curve and loses enclosed area.

The figures are the ``subdivision`` section of ``curvesmith demo``, drawn from the bundled data.
"""

from curvesmith.demo import show_section

ctx = show_section("subdivision")
