"""Uniform B-splines of control polylines (Käferböck, sections 2.5 and 3).

A uniform quadratic B-spline is curvature continuous exactly when its control
polyline is an affine arc length polyline; in ``R^n`` the uniform B-spline of
degree ``n`` has all Frenet curvatures continuous exactly when the control
polyline satisfies eq. (9) (Theorem 4). This module evaluates such splines with
:class:`scipy.interpolate.BSpline`, splits quadratic ones into Bézier
segments (written and read as SVG ``Q`` paths by :mod:`curvesmith.io.svg`), and
measures their curvature on both sides of every joint.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike
from scipy.interpolate import BSpline, PPoly

from .._validate import as_int, as_points
from ..errors import CurveError

__all__ = [
    "bezier_segments",
    "bspline",
    "joint_curvatures",
    "spline_curvature",
]


def _control(points, closed: bool, degree: int, dim) -> np.ndarray:
    p = as_points(points, closed=closed, min_points=degree + 1, dim=dim)
    if closed:
        p = np.concatenate([p, p[:degree]])
    return p


def bspline(points: ArrayLike, *, degree: int = 2, closed: bool = False) -> BSpline:
    """Uniform B-spline of the given degree with `points` as control polygon.

    Knots are the integers, so the spline is ``f(t) = sum_i B_i^n(t) x_i`` of
    the proof of Theorem 4. The valid parameter range is ``spline.t[degree] ..
    spline.t[-degree-1]``; each unit interval is one polynomial segment.

    Parameters
    ----------
    points : (N, d) array_like
        Control points in any dimension, ``N >= degree + 1``.
    degree : int, optional
        Degree ``n >= 1`` (2: quadratic, the planar case of the paper).
    closed : bool, optional
        Periodic spline of a closed control polygon (the first `degree` control
        points are appended again).

    Returns
    -------
    scipy.interpolate.BSpline
        With ``extrapolate=False``; use ``spline(t)`` and ``spline.derivative()``.

    Examples
    --------
    >>> s = bspline([[0, 0], [2, 0], [2, 2]])
    >>> s(2.5).tolist()
    [1.75, 0.25]
    """
    degree = as_int(degree, name="degree", minimum=1)
    c = _control(points, closed, degree, None)
    knots = np.arange(c.shape[0] + degree + 1, dtype=float)
    return BSpline(knots, c, degree, extrapolate=False)


def bezier_segments(points: ArrayLike, *, closed: bool = False) -> np.ndarray:
    """Quadratic Bézier segments of the uniform quadratic B-spline of a control polygon.

    Segment ``j`` runs from ``(x_j + x_{j+1}) / 2`` with control point
    ``x_{j+1}`` to ``(x_{j+1} + x_{j+2}) / 2`` (the parametrisation ``p_1(t)`` of
    section 2.5).

    Parameters
    ----------
    points : (N, 2) array_like
        Control polygon, ``N >= 3``.
    closed : bool, optional
        Closed control polygon (``N`` segments).

    Returns
    -------
    (N - 2, 3, 2) ndarray, or (N, 3, 2) if closed
        Start, control and end point of every segment.

    Examples
    --------
    >>> bezier_segments([[0, 0], [2, 0], [2, 2]]).tolist()
    [[[1.0, 0.0], [2.0, 0.0], [2.0, 1.0]]]
    """
    p = as_points(points, closed=closed, min_points=3, dim=None)
    if closed:
        p = np.concatenate([p, p[:2]])
    mid = 0.5 * (p[:-1] + p[1:])
    return np.stack([mid[:-1], p[1:-1], mid[1:]], axis=1)


def _ppoly(s: BSpline) -> PPoly:
    """Piecewise polynomial form of a vector-valued BSpline (one coordinate at a time)."""
    parts = [PPoly.from_spline(BSpline(s.t, s.c[:, i], s.k)) for i in range(s.c.shape[1])]
    return PPoly(np.stack([p.c for p in parts], axis=-1), parts[0].x, extrapolate=False)


def spline_curvature(
    points: ArrayLike, *, closed: bool = False, per_segment: int = 16
) -> tuple[np.ndarray, np.ndarray]:
    """Euclidean curvature of the uniform quadratic B-spline of a planar control polygon.

    ``kappa = det(f', f'') / |f'|^3`` sampled on every segment (signed, positive
    where the curve turns left).

    Parameters
    ----------
    points : (N, 2) array_like
        Control polygon.
    closed : bool, optional
        Closed control polygon.
    per_segment : int, optional
        Samples per segment (both segment ends included).

    Returns
    -------
    t : (M,) ndarray
        Spline parameters (knots are integers).
    kappa : (M,) ndarray
        Curvature.

    Examples
    --------
    >>> t, k = spline_curvature([[0, 0], [1, 0], [2, 1], [3, 3]], per_segment=2)
    >>> np.round(k, 6).tolist()
    [1.0, 0.353553, 0.353553, 0.089443]
    """
    per_segment = as_int(per_segment, name="per_segment", minimum=2)
    s = bspline(points, degree=2, closed=closed)
    t0, t1 = s.t[2], s.t[-3]
    seg = np.arange(t0, t1)
    t = (seg[:, None] + np.linspace(0.0, 1.0, per_segment)[None, :]).ravel()
    pp = _ppoly(s)
    # evaluate each sample on its own segment (segment ends from the left piece)
    idx = np.repeat(np.searchsorted(pp.x, seg, side="right") - 1, per_segment)
    d1, d2 = _piece_derivatives(pp, idx, t, 2)
    return t, (d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]) / np.hypot(d1[:, 0], d1[:, 1]) ** 3


def _piece_derivatives(pp: PPoly, idx: np.ndarray, t: np.ndarray, order: int) -> list[np.ndarray]:
    """Derivatives 1..order of piece `idx` of `pp` at `t` (no switching at knots)."""
    c = pp.c  # (k + 1, m, d), highest power first
    k = c.shape[0] - 1
    dx = t - pp.x[idx]
    out = []
    for r in range(1, order + 1):
        val = np.zeros((t.size, c.shape[2]))
        # direct sum: sum_{m>=r} coef_m * m!/(m-r)! * dx^(m-r), coef_m = c[k - m]
        for m in range(r, k + 1):
            fac = float(np.prod(np.arange(m - r + 1, m + 1)))
            val += (c[k - m, idx] * fac) * (dx ** (m - r))[:, None]
        out.append(val)
    return out


def joint_curvatures(
    points: ArrayLike, *, degree: int = 2, closed: bool = False
) -> tuple[np.ndarray, np.ndarray]:
    """Highest Frenet curvature of the uniform B-spline on both sides of every interior joint.

    In the plane (``degree = 2``) this is the Euclidean curvature
    ``det(f', f'') / |f'|^3``; in ``R^3`` (``degree = 3``) the torsion
    ``det(f', f'', f''') / |f' x f''|^2``; in general ``R^n`` with ``degree = n``
    the last Frenet curvature through the formula of the proof of Theorem 4,
    ``k_{n-1} = det(f', .., f^(n)) |f' ^ .. ^ f^(n-2)| / (|f'| |f' ^ .. ^ f^(n-1)|^2)``
    (the paper prints ``|f|`` for ``|f'|`` in the denominator; with ``|f'|`` the
    formula gives the classical curvature for ``n = 2`` and torsion for
    ``n = 3``, checked in the tests).
    Each side is evaluated from its own polynomial piece (PPoly form of the
    :class:`scipy.interpolate.BSpline`), so a jump is measured exactly.

    Parameters
    ----------
    points : (N, n) array_like
        Control polygon in ``R^n``, ``n = degree`` (``n >= 2``).
    degree : int, optional
        Spline degree, equal to the dimension.
    closed : bool, optional
        Closed control polygon.

    Returns
    -------
    left, right : (J,) ndarray
        Curvature at the end of the segment before and at the start of the
        segment after each interior joint.

    Examples
    --------
    An affine arc length control polygon (on a parabola) gives a G2 spline:

    >>> left, right = joint_curvatures([[0, 0], [1, 1], [2, 4], [3, 9], [4, 16]])
    >>> bool(np.allclose(left, right))
    True
    """
    degree = as_int(degree, name="degree", minimum=2)
    p = as_points(points, closed=closed, min_points=degree + 2, dim=degree)
    s = bspline(p, degree=degree, closed=closed)
    pp = _ppoly(s)
    joints = np.arange(s.t[degree] + 1, s.t[-degree - 1])
    if joints.size == 0:
        raise CurveError(
            f"points must have at least {degree + 2} control points for a joint, got {p.shape[0]}"
        )
    right_idx = np.searchsorted(pp.x, joints, side="right") - 1
    left_idx = right_idx - 1
    return _frenet_last(pp, left_idx, joints, degree), _frenet_last(pp, right_idx, joints, degree)


def _gram_volume(vectors: list[np.ndarray]) -> np.ndarray:
    """Length of the multivector ``v_1 ^ .. ^ v_r`` (sqrt of the Gram determinant)."""
    m = np.stack(vectors, axis=1)  # (J, r, n)
    g = np.einsum("jrn,jsn->jrs", m, m)
    return np.sqrt(np.abs(np.linalg.det(g)))


def _frenet_last(pp: PPoly, idx: np.ndarray, t: np.ndarray, n: int) -> np.ndarray:
    d = _piece_derivatives(pp, idx, t, n)
    top = (
        np.linalg.det(np.stack(d, axis=1))
        if n > 2
        else d[0][:, 0] * d[1][:, 1] - d[0][:, 1] * d[1][:, 0]
    )
    norm1 = np.linalg.norm(d[0], axis=1)
    if n == 2:
        return top / norm1**3
    return top * _gram_volume(d[: n - 2]) / (norm1 * _gram_volume(d[: n - 1]) ** 2)
