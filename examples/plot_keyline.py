"""
Scan to keyline
===============

The paper's section 5 pipeline on 3D scans: plane fit, equilateral resampling,
inflection estimate and an elastica on each side.

The figures are the ``keyline`` section of ``curvesmith demo``, drawn from the bundled data.
"""

from curvesmith.demo import show_section

ctx = show_section("keyline")
