"""
Line networks and contours
==========================

A line network smoothed with its junctions fixed and no new contacts between lines, and contour
lines of an elevation grid smoothed as one network so that neighbouring levels never touch.

The figures are the ``network`` section of ``curvesmith demo``, drawn from data that installed
packages ship.
"""

from curvesmith.demo import show_section

ctx = show_section("network")
