"""Matplotlib figures shared by the demo, the CLI and users: overlays, curvature combs, fits.

Functions draw into a given ``Axes`` (or create a figure) and return the ``Axes``; they
never call ``plt.show``. Curves are drawn with equal axis scaling. One module per
capability: ``_core`` (axes, curves, markers, combs, convergence, deviation and curvature
along a curve), ``_cca``, ``_derham``, ``_affine``, ``_elastica`` (fits and keylines),
``_geo`` (layers, heights, terrain) and ``_results`` (what results show in notebooks).

Functions
---------
before_after, draw_curve, curvature_comb, bezier_comb, comb_before_after
    Curves before and after an operation, and their curvature combs.
convergence, length_bracket, alpha_profile, scaling
    Sequences against the level or iteration; de Rham's certified length; CCA's profile;
    cost per item against the number of items.
affine_approximation, affine_curvature, spline_curvature
    Affine arc length polylines, their discrete affine curvature, G2 against C1 splines.
elastica_fit, elastica_invariant, elastica_segments, segments_deviation
    Elastica fits over their data; Prop. 4.1's invariant; multi-segment fits.
fit_panels, fit_figure, deviation_along, curvature_along
    A fit's curve, deviation and curvature along the curve, in data units.
inflection_estimate, keyline_fit, keyline_scans, keyline_sides
    Keylines: the RDP inflection, the fits per side, 3D scans, a family of sides.
draw_geometries, layer_before_after, area_change, z_profile, hillshade
    GIS layers.
mark_points, window_box, new_axes
    Markers with names, a zoom window, a row of axes.
result_figure, result_svg
    The small figure of a result (its notebook representation).
"""

from __future__ import annotations

from ._affine import affine_approximation, affine_curvature, spline_curvature
from ._cca import alpha_profile
from ._core import (
    before_after,
    bezier_comb,
    comb_before_after,
    convergence,
    curvature_along,
    curvature_comb,
    deviation_along,
    draw_curve,
    mark_points,
    new_axes,
    scaling,
    window_box,
)
from ._derham import length_bracket
from ._elastica import (
    elastica_fit,
    elastica_invariant,
    elastica_segments,
    fit_figure,
    fit_panels,
    inflection_estimate,
    keyline_fit,
    keyline_scans,
    keyline_sides,
    segments_deviation,
)
from ._geo import area_change, draw_geometries, hillshade, layer_before_after, z_profile
from ._results import result_figure, result_svg

__all__ = [
    "affine_approximation",
    "affine_curvature",
    "alpha_profile",
    "area_change",
    "before_after",
    "bezier_comb",
    "comb_before_after",
    "convergence",
    "curvature_along",
    "curvature_comb",
    "deviation_along",
    "draw_curve",
    "draw_geometries",
    "elastica_fit",
    "elastica_invariant",
    "elastica_segments",
    "fit_figure",
    "fit_panels",
    "hillshade",
    "inflection_estimate",
    "keyline_fit",
    "keyline_scans",
    "keyline_sides",
    "layer_before_after",
    "length_bracket",
    "mark_points",
    "new_axes",
    "result_figure",
    "result_svg",
    "scaling",
    "segments_deviation",
    "spline_curvature",
    "window_box",
    "z_profile",
]
