"""
GIS coverages
=============

US counties smoothed as one coverage: every county keeps its area and no gaps or
overlaps open between neighbours.

The figures are the ``geo`` section of ``curvesmith demo``, drawn from the bundled data.
"""

from curvesmith.demo import show_section

ctx = show_section("geo")
