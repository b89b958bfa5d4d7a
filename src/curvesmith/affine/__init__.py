"""Affine arc length polylines and curvature continuous quadratic B-splines (Käferböck).

Implements F. Käferböck, *Affine arc length polylines and curvature continuous
uniform B-splines*:

* :mod:`~curvesmith.affine.discrete` — affine polyline coordinates (eq. 1, 2),
  affine lengths ``L_2``, ``L_n`` (eq. 3, 8), affine normals, curvatures (eq. 4),
  evolute (eq. 5), osculating conics (Theorem 2, eq. 7);
* :mod:`~curvesmith.affine.spline` — uniform B-splines of control polylines,
  quadratic Bézier segments, curvature at the joints (SVG ``Q`` paths: :mod:`curvesmith.io.svg`)
  (section 2.5, Theorem 4);
* :mod:`~curvesmith.affine.approximation` — :func:`approximate`: a curve from
  dense samples to an affine arc length polyline with smooth affine curvatures
  (section 4), whose uniform quadratic B-spline is curvature continuous.

Notes on the paper
------------------
Every formula was checked numerically (tests in ``tests/test_affine_*.py``).
Discrepancies found in the text:

* Section 2.1: eq. (2) is solved for ``v_{i+1}`` and needs ``A_i != 0``; the
  printed side condition "``B_i != 0``" is not needed (a polyline with
  ``B_1 = 0`` is reconstructed exactly).
* Proof of Theorem 2: the inner radius is ``r cos(lambda/2) = r sqrt(1 - k/4)``
  (the factor ``r`` is dropped); eq. (7) itself is right (checked against conics
  built independently).
* Proof of Theorem 4: the denominator of ``k_{n-1}`` has ``|f'|``, not ``|f|``.
* Theorem 5: the refined polyline has ``2N + 2 - n`` vertices, not
  ``x'_0 .. x'_{N+1}``; every element ``L_n`` is halved, so the total is kept.
* Section 4: ``S_i`` runs from ``x_i`` to ``x_{i+1}`` (printed "to ``x_{i-1}``").
* Section 4.4, step 3: ``A = ((S~_i - S~_{i-1}) / (n_i - n_{i-1}))^3`` (the cube is
  missing).
* The affine curvature of a curve in a general parametrisation is not
  ``det(c'', c''') / det(c', c'')^(5/3)`` (true only for a parametrisation
  proportional to affine arc length); :func:`parametric_affine_curvature` uses
  the full formula, verified on conics.
* Table 1's curve (a degree-8 Bézier curve) is not given; the bundled
  ``affine_bezier8.csv`` is a stand-in (``data/PROVENANCE_affine.md``).

Examples
--------
>>> import numpy as np
>>> from curvesmith import affine
>>> u = np.linspace(0, 2 * np.pi, 601)[:-1]
>>> res = affine.approximate(np.c_[3 * np.cos(u), np.sin(u)], vertices=24, closed=True)
>>> bool(affine.is_affine_arc_length(res.points, closed=True, rtol=1e-6))
True
"""

from __future__ import annotations

from .approximation import (
    Approximation,
    ReplacementCurve,
    approximate,
    construct,
    replacement_curve,
)
from .discrete import (
    Conic,
    affine_length,
    affine_length_elements,
    coordinates,
    curvature,
    evolute,
    is_affine_arc_length,
    normals,
    osculating_conic,
    osculating_curvatures,
    reconstruct,
)
from .exact import bezier_affine_curvature, bezier_curve, parametric_affine_curvature
from .spline import (
    bezier_segments,
    bspline,
    joint_curvatures,
    spline_curvature,
)

__all__ = [
    "Approximation",
    "Conic",
    "ReplacementCurve",
    "affine_length",
    "affine_length_elements",
    "approximate",
    "bezier_affine_curvature",
    "bezier_curve",
    "bezier_segments",
    "bspline",
    "construct",
    "coordinates",
    "curvature",
    "evolute",
    "is_affine_arc_length",
    "joint_curvatures",
    "normals",
    "osculating_conic",
    "osculating_curvatures",
    "parametric_affine_curvature",
    "reconstruct",
    "replacement_curve",
    "spline_curvature",
]
