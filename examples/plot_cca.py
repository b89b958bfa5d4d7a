"""
Area-preserving smoothing (cca)
===============================

Gordon's corner cutting and augmentation: three iterations keep the enclosed area
exactly while Chaikin shrinks the polygon; the alpha profile of Table 1.

The figures are the ``cca`` section of ``curvesmith demo``, drawn from the bundled data.
"""

from curvesmith.demo import show_section

ctx = show_section("cca")
