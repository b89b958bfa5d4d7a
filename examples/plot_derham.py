"""
de Rham curves of a prescribed length
=====================================

Merrien's G1 de Rham curves between two points and tangents with a prescribed
length (Fig. 4), and the certified length bounds closing in.

The figures are the ``derham`` section of ``curvesmith demo``, drawn from the bundled data.
"""

from curvesmith.demo import show_section

ctx = show_section("derham")
