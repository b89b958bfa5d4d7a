"""
Curvature-continuous Bézier curves
==================================

Smoothed curves written as the fewest quadratic (or cubic) Bézier segments of a G2 quadratic
B-spline within a tolerance, with the enclosed area kept exactly; curvature combs before and after.

The figures are the ``curves`` section of ``curvesmith demo``, drawn from the bundled data.
"""

from curvesmith.demo import show_section

ctx = show_section("curves")
