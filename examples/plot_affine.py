"""
Affine arc length polylines
===========================

Käferböck's affine arc length polylines: control polygons of curvature continuous
uniform quadratic B-splines, and their discrete affine curvature.

The figures are the ``affine`` section of ``curvesmith demo``, drawn from the bundled data.
"""

from curvesmith.demo import show_section

ctx = show_section("affine")
