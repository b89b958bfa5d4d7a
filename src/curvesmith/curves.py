"""Compact curvature continuous Bézier curves from dense curves (for SVG and fonts).

:func:`fit` turns a dense planar curve (a smoothed polyline, a sampled glyph
outline) into the fewest quadratic Bézier segments of a curvature continuous
(G2) uniform quadratic B-spline that stay within a tolerance of it, with the
enclosed area of a closed curve kept exactly. Cubic output is the exact degree
elevation of the same curve.

How
---
* Käferböck's section 2.5: the uniform quadratic B-spline of a control polygon
  is G2 exactly when the polygon is an *affine arc length polyline*
  (``det(x_i - x_{i-1}, x_{i+1} - x_i) = A`` constant). Such a polygon is built
  on the curve by :func:`curvesmith.affine.approximate` (section 4); its
  Bézier segments run between edge midpoints with the vertices as control
  points, which is exactly a TrueType contour (the midpoints are the implied
  on-curve points).
* Closed convex curves use the closed construction. Closed curves with
  inflections are cut at an inflection of the replacement curve and fitted as
  an open curve whose last vertex lands on its first (section 4.4 with
  ``match_end``); the polygon is then closed at that shared vertex.
* Open curves and pieces between *anchors* (corners the user keeps) must start
  and end at the anchor points. The uniform spline starts at the midpoint of
  the first edge instead, so the first segment is replaced by
  ``(x_0, x_1 + (1/2 - 1/sqrt 2) v_1, (x_1 + x_2) / 2)`` with ``v_1 = x_2 - x_1``:
  it ends on the same tangent and, by the curvature of a quadratic Bézier at
  an end, ``det(P_1 - P_0, P_2 - P_1) / (2 |P_2 - P_1|^3) = A / |v_1|^3``, with
  the same curvature as the next segment (derivation: ``mu^2 = 1/2`` for
  ``P_1 = (x_1 + x_2)/2 - mu v_1``). The last segment mirrors it. So the curve
  stays G2 up to the corner, which is an explicit on-curve point.
* The number of segments is searched (doubling, then bisection) for the
  smallest count whose measured deviation is within the tolerance. The
  deviation is not strictly monotone in the count, so the result is the
  smallest count found by bisection, not a proof of minimality.
* Area: the area of a closed path of quadratic Bézier segments is a quadratic
  form in the control points (shoelace of the on-curve points plus 2/3 of
  every segment's control triangle). A uniform scaling by
  ``sqrt(target / area)`` about the area centroid makes it exact; scaling is
  an affine map, so the control polygons stay affine arc length polylines (A
  scales by the factor squared) and the spline stays G2. Corners (anchors) do
  not move: a closed curve with anchors keeps its area by scaling each piece
  about its chord instead (exact for the piece's area against its chord, the
  quantity cca keeps).

Quadratic Béziers have no curvature zero, so across an inflection the
curvature changes sign at a joint (reported separately, ``inflection_jump``);
no quadratic (TrueType) curve can be G2 through an inflection.

Examples
--------
>>> import numpy as np
>>> from curvesmith import curves
>>> u = np.linspace(0, 2 * np.pi, 800, endpoint=False)
>>> fit = curves.fit(np.c_[30 * np.cos(u), 20 * np.sin(u)], closed=True, tolerance=0.05)
>>> fit.segments.shape[1:], bool(fit.deviation <= 0.05), bool(fit.g2_defect < 1e-6)
((3, 2), True, True)
>>> bool(abs(fit.area / fit.target_area - 1) < 1e-12)
True
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike
from scipy.spatial import cKDTree

from ._rich import RichRepr
from ._validate import as_float, as_int, as_points
from .errors import CurveError

__all__ = [
    "CurveFit",
    "bezier_area",
    "bezier_deviation",
    "elevate",
    "fit",
    "joint_curvatures",
    "sample_segments",
]

_MU = 0.5 - 1.0 / math.sqrt(2.0)  # end segment control point: x_1 + _MU * v_1
_SAMPLES_PER_VERTEX = 24
_MAX_SAMPLES = 60_000
_OFFSET_ROUNDS = 2
_LINE_FACTOR = 8.0


@dataclass(frozen=True)
class CurveFit(RichRepr):
    """Result of :func:`fit`: one path of Bézier segments.

    Attributes
    ----------
    segments : (S, degree + 1, 2) ndarray
        Bézier control points of the segments in order; segment ``k`` ends where
        ``k + 1`` starts (and the last where the first starts, closed).
    degree : int
        2 (quadratic, TrueType / SVG ``Q``) or 3 (cubic, exact elevation, SVG ``C``).
    closed : bool
        Closed path.
    controls : tuple of (K, 2) ndarray
        The affine arc length control polygons (one per piece between corners;
        one closed polygon for a closed curve without corners), after the area
        correction.
    corners : (C,) ndarray of int
        Segment indices that start at a corner (an anchor: tangent free).
    inflections : (I,) ndarray of int
        Segment indices that start at a joint where the curvature changes sign.
    tolerance : float
        The requested maximal deviation.
    deviation : float
        Measured maximal geometric distance between the path and the input
        curve (both ways: every input point to the path and the path to the
        input polyline, 48 points per segment).
    area : float
        Signed area enclosed by the path (closed), or between the path and the
        chord of its end points (open); CCW positive.
    target_area : float
        The same area of the input polyline.
    g2_defect : float
        Largest relative curvature jump ``|k_left - k_right| / max(|k_left|, |k_right|)``
        at the smooth joints (neither corners nor inflections); 0 for G2.
    inflection_jump : float
        Largest relative curvature jump at inflection joints (about 2: the sign flips).
    success : bool
        Whether the deviation is within the tolerance.
    message : str
        What happened.
    """

    segments: np.ndarray
    degree: int
    closed: bool
    controls: tuple
    corners: np.ndarray
    inflections: np.ndarray
    tolerance: float
    deviation: float
    area: float
    target_area: float
    g2_defect: float
    inflection_jump: float
    success: bool
    message: str

    @property
    def count(self) -> int:
        """Number of Bézier segments."""
        return int(self.segments.shape[0])

    def bezier_polygon(self) -> np.ndarray:
        """The path's Bézier control points in order: on, off, (off,) on, ...

        Every ``degree``-th point is on the curve; a closed path does not repeat
        its first point.

        Returns
        -------
        (S * degree (+ 1 if open), 2) ndarray
        """
        body = self.segments[:, :-1].reshape(-1, 2)
        return body if self.closed else np.vstack([body, self.segments[-1, -1:]])


# ------------------------------------------------------------------------------- Bézier tools


def elevate(segments: ArrayLike) -> np.ndarray:
    """Exact degree elevation of quadratic Bézier segments to cubics.

    ``(P0, P1, P2) -> (P0, P0 + 2/3 (P1 - P0), P2 + 2/3 (P1 - P2), P2)``: the same curve.

    Parameters
    ----------
    segments : (S, 3, 2) array_like

    Returns
    -------
    (S, 4, 2) ndarray

    Examples
    --------
    >>> elevate([[[0, 0], [3, 3], [6, 0]]]).tolist()
    [[[0.0, 0.0], [2.0, 2.0], [4.0, 2.0], [6.0, 0.0]]]
    """
    q = np.asarray(segments, dtype=float)
    if q.ndim != 3 or q.shape[1:] != (3, 2):
        raise CurveError(f"segments must have shape (S, 3, 2), got {q.shape}")
    return np.stack(
        [
            q[:, 0],
            q[:, 0] + 2.0 / 3.0 * (q[:, 1] - q[:, 0]),
            q[:, 2] + 2.0 / 3.0 * (q[:, 1] - q[:, 2]),
            q[:, 2],
        ],
        axis=1,
    )


def _check_segments(segments) -> np.ndarray:
    q = np.asarray(segments, dtype=float)
    if q.ndim != 3 or q.shape[1] not in (3, 4) or q.shape[2] != 2 or q.shape[0] < 1:
        raise CurveError(f"segments must have shape (S, 3, 2) or (S, 4, 2), got {q.shape}")
    return q


def sample_segments(segments: ArrayLike, per_segment: int = 48) -> np.ndarray:
    """Points along Bézier segments, ``per_segment`` per segment plus the final end point.

    Parameters
    ----------
    segments : (S, d + 1, 2) array_like
        Quadratic (d = 2) or cubic (d = 3) segments.
    per_segment : int, optional

    Returns
    -------
    (S * per_segment + 1, 2) ndarray

    Examples
    --------
    >>> sample_segments([[[0, 0], [1, 1], [2, 0]]], per_segment=2).tolist()
    [[0.0, 0.0], [1.0, 0.5], [2.0, 0.0]]
    """
    q = _check_segments(segments)
    per_segment = as_int(per_segment, name="per_segment", minimum=1)
    t = np.arange(per_segment) / per_segment
    d = q.shape[1] - 1
    coef = np.array([math.comb(d, i) * t**i * (1 - t) ** (d - i) for i in range(d + 1)])  # (d+1, m)
    pts = np.einsum("im,sij->smj", coef, q).reshape(-1, 2)
    return np.vstack([pts, q[-1, -1:]])


def bezier_area(segments: ArrayLike, *, closed: bool = True) -> float:
    r"""Signed area of a path of Bézier segments (CCW positive), exact.

    Closed: the enclosed area. Open: the area between the path and the chord
    from its first to its last point. For a quadratic segment the area between
    it and its chord is 2/3 of its control triangle; a cubic segment uses the
    exact formula of ``1/2 \\int det(B, B') dt``.

    Parameters
    ----------
    segments : (S, 3, 2) or (S, 4, 2) array_like
    closed : bool, optional

    Returns
    -------
    float

    Examples
    --------
    The unit parabola ``y = 1 - x^2`` over ``[-1, 1]`` bounds 4/3 with its chord:

    >>> bezier_area([[[1, 0], [0, 2], [-1, 0]]], closed=False)
    1.3333333333333333
    """
    q = _check_segments(segments)
    q = q - q[0, 0]  # translation invariant: relative coordinates avoid cancellation
    on = np.vstack([q[:, 0], q[-1:, -1]])
    if closed:
        on = on[:-1]
    x, y = on[:, 0], on[:, 1]
    poly = 0.5 * float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))
    if not closed:  # the closing chord contributes the term from last to first
        poly = 0.5 * float(np.sum(x[:-1] * y[1:] - x[1:] * y[:-1]) + x[-1] * y[0] - x[0] * y[-1])
    if q.shape[1] == 3:
        a, b = q[:, 1] - q[:, 0], q[:, 2] - q[:, 0]
        bulge = float(np.sum(a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0])) / 3.0
    else:
        p0, p1, p2, p3 = (q[:, i] for i in range(4))

        def det(u, v):
            return u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0]

        # 1/2 int det(B, B') dt over the segment minus the chord triangle term
        full = (
            6 * det(p0, p1)
            + 3 * det(p0, p2)
            + det(p0, p3)
            + 3 * det(p1, p2)
            + 3 * det(p1, p3)
            + 6 * det(p2, p3)
        ) / 20.0
        bulge = float(np.sum(full - 0.5 * det(p0, p3)))
    return poly + bulge


def joint_curvatures(segments: ArrayLike, *, closed: bool) -> tuple[np.ndarray, np.ndarray]:
    """Curvature at the end of each segment and at the start of the next one.

    Parameters
    ----------
    segments : (S, 3, 2) or (S, 4, 2) array_like
    closed : bool
        Include the joint from the last segment to the first.

    Returns
    -------
    left, right : (J,) ndarray
        ``J = S`` closed, ``S - 1`` open; joint ``j`` is the end of segment ``j``.

    Examples
    --------
    Two halves of one parabola meet with equal curvature:

    >>> halves = [[[-1, 1], [-0.5, 0], [0, 0]], [[0, 0], [0.5, 0], [1, 1]]]
    >>> left, right = joint_curvatures(halves, closed=False)
    >>> left.tolist(), right.tolist()
    ([2.0], [2.0])
    """
    q = _check_segments(segments)
    d = q.shape[1] - 1

    def curvature(a, b, c):  # curvature of a Bézier of degree d at the end point a (b, c next)
        u, w = b - a, c - b
        cr = u[:, 0] * w[:, 1] - u[:, 1] * w[:, 0]
        return (d - 1) / d * cr / np.hypot(u[:, 0], u[:, 1]) ** 3

    with np.errstate(divide="ignore", invalid="ignore"):
        end = -curvature(q[:, -1], q[:, -2], q[:, -3])  # reversed traversal flips the sign
        start = curvature(q[:, 0], q[:, 1], q[:, 2])
    if closed:
        return end, np.roll(start, -1)
    return end[:-1], start[1:]


def bezier_deviation(
    segments: ArrayLike, points: ArrayLike, *, closed: bool, per_segment: int = 48
) -> float:
    """Largest distance between a Bézier path and a polyline, both ways.

    Every polyline vertex is measured to the path (sampled with ``per_segment``
    points per segment, then to the nearest chords of that sampling) and every
    path sample to the polyline's nearest edges; the maximum of both is a
    (sampled) Hausdorff distance. The chords of the sampling differ from the
    path by at most ``k h^2 / 8`` (``h`` the sample spacing, ``k`` the curvature).

    Parameters
    ----------
    segments : (S, 3, 2) or (S, 4, 2) array_like
    points : (N, 2) array_like
    closed : bool
        Both are closed.
    per_segment : int, optional

    Returns
    -------
    float

    Examples
    --------
    The parabola through ``(1, 0.5)`` against the polyline of its three points:

    >>> d = bezier_deviation([[[0, 0], [1, 1], [2, 0]]], [[0, 0], [1, 0.5], [2, 0]], closed=False)
    >>> round(d, 4)
    0.1118
    """
    path = sample_segments(segments, per_segment)
    p = as_points(points, closed=closed, min_points=2)
    if closed:
        path = path[:-1]
    return max(_to_polyline(p, path, closed), _to_polyline(path, p, closed))


def _to_polyline(query: np.ndarray, poly: np.ndarray, closed: bool) -> float:
    """Max over `query` of the exact distance to the polyline `poly`.

    The polyline's edges are split into pieces no longer than ``h`` (twice the
    median edge; the same polyline) and every query point is measured to the
    edges at its ``k`` nearest vertices. That minimum ``d`` is exact once the
    ``k``-th nearest vertex is farther than ``d + h / 2`` (every point of a closer
    edge has an end point within ``h / 2`` of it); the points not yet certified
    are measured again with twice ``k``. (Nearest vertices alone are not enough
    on an unevenly sampled path: next to a corner between a short, densely
    sampled edge and a long one, the nearest vertices all lie on the short edge;
    a line glyph's corner measured 15.8 units for 0.)
    """
    ring = np.vstack([poly, poly[:1]]) if closed else poly
    e = np.hypot(*np.diff(ring, axis=0).T)
    if e.size == 0 or not np.any(e > 0):
        return float(np.max(np.hypot(*(query - poly[0]).T)))
    h = 2.0 * float(np.median(e[e > 0]))
    parts = np.maximum(1, np.ceil(e / h).astype(int))
    if np.any(parts > 1):
        seg = np.repeat(np.arange(e.size), parts)
        frac = (np.arange(seg.size) - np.repeat(np.cumsum(parts) - parts, parts)) / parts[seg]
        dense = ring[seg] + frac[:, None] * (ring[seg + 1] - ring[seg])
        ring = np.vstack([dense, ring[-1:]])
        h = float(np.max(np.hypot(*np.diff(ring, axis=0).T)))
    verts = ring[:-1] if closed else ring
    n = len(verts)
    tree = cKDTree(verts)
    best = np.full(len(query), np.inf)
    todo = np.arange(len(query))
    k = min(4, n)
    while todo.size:
        dist_v, idx = tree.query(query[todo], k=k)
        dist_v, idx = dist_v.reshape(len(todo), -1), idx.reshape(len(todo), -1)
        q = query[todo]
        d = best[todo]
        for col in range(idx.shape[1]):
            for off in (-1, 0):
                i = idx[:, col] + off
                if closed:
                    i, j = i % n, (i + 1) % n
                else:
                    i = np.clip(i, 0, n - 2)
                    j = i + 1
                a, ab = verts[i], verts[j] - verts[i]
                ll = np.einsum("ij,ij->i", ab, ab)
                t = np.einsum("ij,ij->i", q - a, ab) / np.where(ll > 0, ll, 1.0)
                t = np.clip(t, 0, 1)
                d = np.minimum(d, np.hypot(*(q - a - t[:, None] * ab).T))
        best[todo] = d
        if k >= n:
            break
        sure = dist_v[:, -1] > d + 0.5 * h
        todo = todo[~sure]
        k = min(2 * k, n)
    return float(best.max())


# ------------------------------------------------------------------------------- pieces


def _uniform_segments(x: np.ndarray, closed: bool) -> np.ndarray:
    if closed:
        nxt = np.roll(x, -1, axis=0)
        mid = 0.5 * (x + nxt)
        return np.stack([np.roll(mid, 1, axis=0), x, mid], axis=1)
    mid = 0.5 * (x[:-1] + x[1:])
    return np.stack([mid[:-1], x[1:-1], mid[1:]], axis=1)


def _clamped_segments(x: np.ndarray) -> np.ndarray:
    """Open polygon x_0 .. x_n -> n - 1 segments from x_0 to x_n, G2 at every inner joint."""
    seg = _uniform_segments(x, False).copy()
    v1 = x[2] - x[1]
    seg[0] = [x[0], x[1] + _MU * v1, 0.5 * (x[1] + x[2])]
    w = x[-3] - x[-2]
    seg[-1] = [0.5 * (x[-3] + x[-2]), x[-2] + _MU * w, x[-1]]
    return seg


def _normal_residual(segments: np.ndarray, samples: np.ndarray, closed: bool) -> np.ndarray:
    """Per sample: the normal component of (sample - nearest point of the path), as vectors."""
    path = sample_segments(segments, 48)
    if closed:
        path = path[:-1]
    tree = cKDTree(path)
    _, k = tree.query(samples)
    n = len(path)
    best = np.full(len(samples), np.inf)
    foot = samples.copy()
    for off in (-1, 0):
        i = k + off
        if closed:
            i, j = i % n, (i + 1) % n
        else:
            i = np.clip(i, 0, n - 2)
            j = i + 1
        a, ab = path[i], path[j] - path[i]
        ll = np.einsum("ij,ij->i", ab, ab)
        t = np.clip(np.einsum("ij,ij->i", samples - a, ab) / np.where(ll > 0, ll, 1.0), 0, 1)
        q = a + t[:, None] * ab
        d = np.hypot(*(samples - q).T)
        better = d < best
        best = np.where(better, d, best)
        foot[better] = q[better]
    if closed:
        tang = np.roll(samples, -1, axis=0) - np.roll(samples, 1, axis=0)
    else:
        tang = np.gradient(samples, axis=0)
    tang /= np.hypot(*tang.T)[:, None]
    nrm = np.c_[-tang[:, 1], tang[:, 0]]
    r = np.einsum("ij,ij->i", samples - foot, nrm)
    for _ in range(4):  # binomial smoothing: the distance to chords of the path ripples
        if closed:
            r = 0.25 * (np.roll(r, 1) + 2 * r + np.roll(r, -1))
        else:
            r[1:-1] = 0.25 * (r[:-2] + 2 * r[1:-1] + r[2:])
    if not closed:
        r[0] = r[-1] = 0.0
    return r[:, None] * nrm


def _resample(points: np.ndarray, closed: bool, count: int) -> np.ndarray:
    """`count` points on the piecewise parabolic replacement curve of a polyline.

    Käferböck's replacement curve (section 4.1) keeps the turning direction of
    every arc of the polyline, so the resampled curve has the same inflections;
    a C2 cubic interpolant wiggles on the near-straight runs of a smoothed
    polyline and made a hundred spurious inflections on a cca-smoothed star.
    """
    from .affine.approximation import replacement_curve

    rc = replacement_curve(points, closed=closed)
    n = rc.segments
    return rc.evaluate(np.linspace(0.0, n, count, endpoint=not closed))


class _Piece:
    """One part fitted by one affine construction: open between corners, or a whole ring."""

    def __init__(self, points: np.ndarray, kind: str):
        # the input polyline of this part relative to its first point (open: ends are corners)
        self.origin = points[0].copy()
        self.points = points - self.origin
        self.kind = kind  # "open", "ring" (closed, convex or with inflections)
        self.area = _ring_area(self.points) if kind == "ring" else _open_area(self.points)
        self.samples: np.ndarray | None = None
        self.convex = False  # set by the first construction of a closed convex curve
        if kind == "line":
            self.min_vertices = 2
            return
        from .affine.approximation import replacement_curve

        rc = replacement_curve(self.points, closed=kind == "ring")
        # section 4.4 needs 3 edges per inflection-free piece
        self.min_vertices = 3 * (rc.inflections().size + 1) + 1

    def dense(self, vertices: int) -> np.ndarray:
        need = min(_SAMPLES_PER_VERTEX * vertices, _MAX_SAMPLES)
        if self.samples is None or len(self.samples) < need:
            base = self.points
            if len(base) >= need:
                self.samples = base
            else:
                count = max(need, 4 * len(base))
                closed = self.kind == "ring"
                self.samples = _resample(base, closed, min(count, _MAX_SAMPLES))
                if not closed:
                    self.samples[0], self.samples[-1] = base[0], base[-1]
        return self.samples

    def build(self, vertices: int):
        """Area-corrected (segments, control polygon, inflection joints) for `vertices`.

        The vertices of the affine construction lie on the curve, so its spline
        lies inside by ``O(k h^2)`` (``h`` an edge). The construction is repeated
        on samples moved outward by the normal part of their distance to the last
        spline (``_OFFSET_ROUNDS`` times); then the spline runs on both sides of the
        curve and the deviation falls from ``O(h^2)`` to about ``O(h^3)``.
        """
        base = self.dense(vertices)
        closed = self.kind == "ring"
        out = self._build_on(base, vertices)
        if self.convex:
            # a closed convex curve: the scaling to the exact area already centres the spline
            # on the curve (ellipse 30 x 20, 9 segments: 0.031 with or without the rounds)
            return out
        p = base
        for _ in range(_OFFSET_ROUNDS):
            p = p + _normal_residual(out[0], base, closed)
            try:
                out = self._build_on(p, vertices)
            except CurveError:  # the moved samples did not admit the construction: keep the last
                break
        return out

    def _build_on(self, p: np.ndarray, vertices: int):
        from .affine.approximation import approximate, replacement_curve

        if self.kind == "open":
            res = approximate(p, vertices=vertices)
            if not res.success:
                raise CurveError(res.message)
            gap = math.hypot(*(res.points[-1] - p[-1]))
            if gap > 1e-6 * float(np.mean(np.hypot(*np.diff(res.points, axis=0).T))):
                # x_n is replaced by the end point: the last area (and the G2 end) would be off
                raise CurveError(f"the last vertex missed the end by {gap:.3g} ({res.message})")
            x = res.points.copy()
            x[0], x[-1] = self.points[0], self.points[-1]  # within 1e-10 edges already
            # a join vertex x_j carries the cross area A_j: joints j - 2 and j - 1 (clamped)
            joints = [j + d for j in res.joins.tolist() for d in (-2, -1)]
            seg = _correct_open(_clamped_segments(x), x, self.area)
            return seg[0], seg[1], joints
        rc = replacement_curve(p, closed=True)
        infl = rc.inflections()
        signs = np.sign(rc.lengths[rc.lengths != 0])
        if infl.size == 0 and (signs.size == 0 or np.all(signs == signs[0])):
            self.convex = True
            res = approximate(p, vertices=vertices, closed=True)
            if not res.success:
                raise CurveError(res.message)
            return (*_scale_ring(_uniform_segments(res.points, True), res.points, self.area), [])
        # closed with inflections: start at an inflection, fit open, close at the shared vertex
        start = int(infl[0]) if infl.size else int(np.argmin(np.abs(rc.lengths)))
        rolled = np.vstack([np.roll(p, -start, axis=0), p[start : start + 1]])
        res = approximate(rolled, vertices=vertices + 1)
        if not res.success:
            raise CurveError(res.message)
        gap = math.hypot(*(res.points[-1] - rolled[0]))
        edge = float(np.mean(np.hypot(*np.diff(res.points, axis=0).T)))
        if gap > 1e-6 * edge:
            # x_n must be x_0: the polygon is closed there, and A_(n-1) is off by about
            # gap / edge (the curvature jump at the joint before the seam)
            raise CurveError(f"the closing vertex missed the start by {gap:.3g} ({res.message})")
        x = res.points[:-1].copy()
        x[0] = rolled[0]
        # join vertices x_j (and the seam x_0) carry the cross area A_j: joints j - 1 and j
        m = len(x)
        joints = [(j + d) % m for j in [0, *res.joins.tolist()] for d in (-1, 0)]
        return (*_scale_ring(_uniform_segments(x, True), x, self.area), joints)


def _search(piece: _Piece, tol: float, max_vertices: int):
    """Smallest vertex count whose deviation is within `tol`, and whether one was found.

    A safeguarded secant search on ``log(deviation)`` against ``log(vertices)``
    (after the area correction the deviation falls like ``vertices^-4``; the
    step assumes ``-3`` to stay conservative) inside the bracket of counts known
    to fail and to pass, bisecting when the step leaves the bracket.
    """
    cache: dict[int, tuple] = {}
    closed = piece.kind == "ring"

    def trial(nv: int) -> float:
        if nv not in cache:
            try:
                seg, x, joints = piece.build(nv)
                dev = bezier_deviation(seg, piece.points, closed=closed)
                cache[nv] = (dev, seg, x, joints, None)
            except CurveError as exc:
                cache[nv] = (math.inf, None, None, None, str(exc))
        return cache[nv][0]

    lo, hi = 4, None  # lo: largest count known to fail (4 vertices rarely build); hi: passes
    nv = max(8, piece.min_vertices)
    lo = max(lo, piece.min_vertices - 1)
    while True:
        dev = trial(nv)
        # a count whose construction fails (the line misses the curve next to an inflection,
        # the polygon does not close) says nothing about the deviation: try the next ones
        for extra in range(1, 4):
            if (
                math.isfinite(dev)
                or nv + extra > max_vertices
                or (hi is not None and nv + extra >= hi)
            ):
                break
            if trial(nv + extra) < math.inf:
                nv += extra
                dev = trial(nv)
                break
        if dev <= tol:
            hi = nv
        else:
            lo = max(lo, nv)
        if hi is not None and hi - lo <= 1:
            break
        if hi is None and lo >= max_vertices:
            break
        if math.isfinite(dev) and dev > 0:
            guess = round(nv * (dev / tol) ** (1.0 / 3.0))
        else:
            guess = 2 * nv if hi is None else (lo + hi) // 2
        top = hi if hi is not None else max_vertices + 1
        if not lo < guess < top:
            guess = (lo + top) // 2 if hi is not None else min(2 * nv, max_vertices)
        if guess in cache or not lo < guess < top:
            guess = (lo + top) // 2
            if guess in cache or guess <= lo:
                break
        nv = guess
    if hi is None:
        return min(cache.values(), key=lambda c: c[0]), False
    return cache[hi], True


# ------------------------------------------------------------------------------- fit


def _straight_runs(p: np.ndarray, closed: bool, tol: float) -> list[int]:
    """End vertices of the straight runs of a polyline (to become line pieces).

    A run is a maximal stretch of vertices turning by less than ``1e-3`` rad each,
    at least 8 median edges long, whose vertices stay within ``tol / 4`` of its
    chord; an edge longer than 8 median edges is a run by itself.
    """
    n = len(p)
    ring = np.vstack([p, p[:1]]) if closed else p
    e = np.hypot(*np.diff(ring, axis=0).T)
    med = float(np.median(e))
    out: set[int] = set()
    for i in np.flatnonzero(e > _LINE_FACTOR * med):
        out |= {int(i), int(i + 1) % n}
    v = np.diff(np.vstack([p[-1:], p, p[:1]]) if closed else p, axis=0)
    turn = np.abs(
        np.arctan2(v[:-1, 0] * v[1:, 1] - v[:-1, 1] * v[1:, 0], np.sum(v[:-1] * v[1:], 1))
    )
    flat = np.zeros(n, dtype=bool)
    if closed:
        flat = turn < 1e-3
    else:
        flat[1:-1] = turn < 1e-3
    if flat.all():
        return sorted(out)
    # maximal runs of flat vertices (cyclic for a ring): start after a non-flat vertex
    start = int(np.flatnonzero(~flat)[0]) if closed else 0
    order = [(start + k) % n for k in range(n)] if closed else list(range(n))
    run: list[int] = []
    for k in [*order, order[0]] if closed else order:
        if flat[k]:
            run.append(k)
            continue
        if run:
            a, b = (run[0] - 1) % n, (run[-1] + 1) % n  # the bent vertices around the run
            seq = [(a + j) % n for j in range((b - a) % n + 1)]
            length = float(np.sum(e[seq[:-1]]))
            if length >= _LINE_FACTOR * med and _chord_distance(p[seq]) <= 0.25 * tol:
                out |= {a, b}
        run = []
    return sorted(out)


def _chord_distance(points: np.ndarray) -> float:
    """Largest distance of an open polyline's vertices from the chord of its end points."""
    e = points[-1] - points[0]
    ln = math.hypot(*e)
    r = points - points[0]
    if ln == 0.0:
        return float(np.max(np.hypot(*r.T)))
    return float(np.max(np.abs(r[:, 0] * e[1] - r[:, 1] * e[0])) / ln)


def _open_area(points: np.ndarray) -> float:
    points = points - points[0]
    x, y = points[:, 0], points[:, 1]
    return 0.5 * float(np.sum(x[:-1] * y[1:] - x[1:] * y[:-1]) + x[-1] * y[0] - x[0] * y[-1])


def _ring_area(points: np.ndarray) -> float:
    points = points - points[0]
    x, y = points[:, 0], points[:, 1]
    return 0.5 * float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))


def fit(
    points: ArrayLike,
    *,
    closed: bool,
    tolerance: float,
    degree: int = 2,
    anchors: Sequence[int] | None = None,
    max_segments: int = 4000,
    area: float | None = None,
    lines: bool = True,
) -> CurveFit:
    """Few Bézier segments of a G2 quadratic B-spline within `tolerance` of a curve.

    The count is the smallest that a search (a secant step, then bisection) on the
    count finds within the tolerance. The deviation is not monotone in the count, so
    a smaller count may pass too: on a 5-lobed star, 0.1 gives 129 segments where 103
    (found at 0.05) would pass.

    Parameters
    ----------
    points : (N, 2) array_like
        The curve as a dense polyline (e.g. :func:`curvesmith.cca.smooth` output or
        a sampled outline), no repeated consecutive points. Sparse polylines are
        resampled on their C2 cubic interpolant (chord-length parameter) to about
        24 samples per control vertex; the deviation is measured against the
        polyline as given.
    closed : bool
        Closed curve (a repeated closing vertex is dropped).
    tolerance : float
        Largest allowed geometric distance between the path and the polyline,
        in the units of the points, ``> 0``.
    degree : {2, 3}, optional
        2: quadratic segments (TrueType, SVG ``Q``); 3: their exact cubic elevation
        (SVG ``C``, CFF).
    anchors : sequence of int, optional
        Indices of vertices that stay corners: the path passes through them and
        the tangents on both sides are free. An open curve always passes through
        its end points. A curve of fewer than 4 vertices is its polyline: every
        vertex a corner, every edge a line.
    max_segments : int, optional
        Upper limit of the search per piece.
    lines : bool, optional
        Edges longer than 8 times the median edge are straight lines between two
        corners (a sparse polygon's sides: an affine arc length polyline cannot
        follow a straight line). Their joints with the curves are G1 at best
        (quadratics have no zero curvature) and count as corners.
    area : float, optional
        Closed curves: the area to keep, when the polyline samples a curve whose
        exact area is known (a glyph outline: the polygon of its samples has
        slightly less); default the polyline's own signed area.

    Returns
    -------
    CurveFit
        ``success`` False (with the best deviation found) if the tolerance was
        not reached within `max_segments` segments.

    Raises
    ------
    CurveError
        For bad arguments, a straight piece (no affine arc length: it needs
        anchors at its ends, or is better written as a line), or too few points.

    Examples
    --------
    A quarter of a circle of radius 100 within 0.01 (two corners at its ends):

    >>> t = np.linspace(0, np.pi / 2, 400)
    >>> f = fit(100 * np.c_[np.cos(t), np.sin(t)], closed=False, tolerance=0.01)
    >>> f.count, f.segments[0, 0].tolist(), bool(f.g2_defect < 1e-6)
    (7, [100.0, 0.0], True)
    """
    p = as_points(points, closed=closed, min_points=3 if closed else 2, distinct=True)
    tolerance = as_float(tolerance, name="tolerance", low=0.0)
    if tolerance <= 0.0:
        raise CurveError(f"tolerance must be > 0, got {tolerance}")
    if degree not in (2, 3):
        raise CurveError(f"degree must be 2 or 3, got {degree!r}")
    max_segments = as_int(max_segments, name="max_segments", minimum=4)
    n = len(p)
    idx: list[int] = []
    if anchors is not None:
        idx = sorted({int(a) for a in anchors})
        bad = [a for a in idx if not -n <= a < n]
        if bad:
            raise CurveError(f"anchors must be vertex indices in [0, {n}), got {bad[0]}")
        idx = sorted({a % n for a in idx})
    if n < 4:
        # too few vertices for a curve (a segment, a triangle): the polyline itself, every
        # vertex a corner, every edge a line
        idx = list(range(n))
    elif lines:
        # long straight edges (a sparse polygon's sides, a cca-smoothed polygon keeps their
        # middles) have no affine arc length: the construction cannot cross them, so they
        # become line pieces between two corners
        idx = sorted(set(idx) | set(_straight_runs(p, closed, tolerance)))
    if not closed:
        idx = sorted(set(idx) | {0, n - 1})
    # the pieces, each fitted on coordinates relative to its first point
    pieces: list[_Piece] = []
    if closed and not idx:
        pieces.append(_Piece(p, "ring"))
    else:
        cuts = [*idx, idx[0] + n] if closed else idx
        ext = np.vstack([p, p]) if closed else p
        for a, b in itertools.pairwise(cuts):
            part = ext[a : b + 1]
            if len(part) < 4:
                if _chord_distance(part) > 0.5 * tolerance:
                    raise CurveError(
                        f"anchors {a % n} and {b % n} must be at least 3 vertices apart "
                        "(or resample the curve densely first)"
                    )
                pieces.append(_Piece(part, "line"))
                continue
            pieces.append(_Piece(part, "open"))
    if area is not None:
        area = as_float(area, name="area")
        if not closed:
            raise CurveError("area applies to closed curves only")
        poly = _ring_area(p)
        if area * poly <= 0:
            raise CurveError(f"area must have the sign of the curve's area {poly:.6g}, got {area}")
        if len(pieces) == 1 and pieces[0].kind == "ring":
            pieces[0].area = area
        else:  # distribute the difference over the pieces' areas against their chords
            total = sum(abs(pc.area) for pc in pieces)
            if total > 0:
                for pc in pieces:
                    pc.area += (area - poly) * abs(pc.area) / total
    # straight pieces (within half the tolerance of their chord) become lines, which have no
    # area against their chord: their pieces' areas are given to the curved pieces instead
    straight = [
        pc.kind == "line" or (pc.kind == "open" and _chord_distance(pc.points) <= 0.5 * tolerance)
        for pc in pieces
    ]
    if any(straight) and len(pieces) > 1:
        deficit = sum(pc.area for pc, st in zip(pieces, straight, strict=True) if st)
        curved = [pc for pc, st in zip(pieces, straight, strict=True) if not st]
        # all straight, and the lines already enclose the area (a polygon, like a glyph N,
        # up to the rounding of the area sums): the polygon of corners is the fit
        rounding = 1e-12 * sum(abs(pc.area) for pc in pieces) + 1e-12 * abs(area or 0.0)
        if not curved and abs(deficit) <= rounding:
            deficit = 0.0
        if not curved and deficit != 0.0:
            big = max(
                (i for i, pc in enumerate(pieces) if pc.kind == "open"),
                key=lambda i: abs(pieces[i].area),
                default=None,
            )
            if big is not None:
                straight[big] = False
                curved = [pieces[big]]
                deficit -= pieces[big].area
        total = sum(abs(pc.area) for pc in curved)
        for pc in curved:
            pc.area += deficit * (abs(pc.area) / total if total > 0 else 1.0 / len(curved))
    segs, controls, fails = [], [], []
    corners, flagged = [], []
    start = 0
    for k, piece in enumerate(pieces):
        max_v = max_segments + (1 if piece.kind == "open" else 0)
        if straight[k]:
            # a straight piece (no affine arc length): one straight quadratic segment
            a, b = piece.points[0], piece.points[-1]
            seg = np.array([[a, 0.5 * (a + b), b]])
            dev, x, joints, err, ok = _chord_distance(piece.points), seg[0], [], None, True
        else:
            (dev, seg, x, joints, err), ok = _search(piece, tolerance, max_v)
            if seg is None and piece.kind == "open" and _chord_distance(piece.points) <= tolerance:
                # nearly straight (no usable affine arc length) but within the tolerance
                a, b = piece.points[0], piece.points[-1]
                seg = np.array([[a, 0.5 * (a + b), b]])
                dev, x, joints, ok = _chord_distance(piece.points), seg[0], [], True
        if seg is None:
            raise CurveError(f"piece {k} of the curve: {err}")
        if not ok:
            fails.append(f"piece {k}: best deviation {dev:.3g} > tolerance {tolerance:.3g}")
        if piece.kind in ("open", "line"):
            corners.append(start)
        flagged += [start + j for j in joints]
        segs.append(seg + piece.origin)
        controls.append(x + piece.origin)
        start += len(seg)
    segments = np.concatenate(segs)
    target = _ring_area(p) if closed else _open_area(p)
    if area is not None:
        target = area
    area = bezier_area(segments, closed=closed)
    deviation = bezier_deviation(segments, p, closed=closed)
    left, right = joint_curvatures(segments, closed=closed)
    with np.errstate(divide="ignore", invalid="ignore"):
        big = np.maximum(np.abs(left), np.abs(right))
        jump = np.where(big > 0, np.abs(left - right) / np.where(big > 0, big, 1.0), 0.0)
    joint_corner = np.zeros(left.size, dtype=bool)
    for c in corners:  # joint j ends segment j: a corner at segment c is joint c - 1
        j = c - 1
        if j >= 0 or closed:
            joint_corner[j % max(left.size, 1)] = True
    flip = np.zeros(left.size, dtype=bool)
    flip[[j for j in flagged if 0 <= j < left.size]] = True
    flip |= np.sign(left) * np.sign(right) < 0
    flip &= ~joint_corner
    smooth = ~joint_corner & ~flip
    g2 = float(np.max(jump[smooth])) if smooth.any() else 0.0
    infl_jump = float(np.max(jump[flip])) if flip.any() else 0.0
    inflections = np.flatnonzero(flip) + 1
    if closed:
        inflections %= segments.shape[0]
    if degree == 3:
        segments = elevate(segments)
    success = not fails and deviation <= tolerance * (1 + 1e-9)
    msg = (
        f"{segments.shape[0]} {'quadratic' if degree == 2 else 'cubic'} segment(s) in "
        f"{len(pieces)} piece(s); deviation {deviation:.3g} (tolerance {tolerance:.3g}); "
        f"area error {abs(area - target) / max(abs(target), 1e-300):.2g}; G2 defect {g2:.2g}"
    )
    if fails:
        msg += "; tolerance not reached: " + ", ".join(fails)
    return CurveFit(
        segments=segments,
        degree=degree,
        closed=closed,
        controls=tuple(controls),
        corners=np.asarray(sorted(set(corners)), dtype=int)
        if not closed or idx
        else np.zeros(0, int),
        inflections=np.sort(inflections).astype(int),
        tolerance=tolerance,
        deviation=deviation,
        area=area,
        target_area=target,
        g2_defect=g2,
        inflection_jump=infl_jump,
        success=success,
        message=msg,
    )


def _scale_ring(segments: np.ndarray, x: np.ndarray, target: float):
    """Scale a closed path about the centroid of its control polygon to area `target`.

    The area is ``s^2`` times the area for a scaling by ``s`` (about any centre), so
    ``s = sqrt(target / area)``; a second step removes the rounding of the first.
    """
    area = bezier_area(segments, closed=True)
    if area == 0.0 or target / area <= 0.0:
        raise CurveError(f"the fitted ring has area {area:.6g}, the curve {target:.6g}")
    c = x.mean(axis=0)
    s = math.sqrt(target / area)
    seg = c + s * (segments - c)
    s2 = s * math.sqrt(target / bezier_area(seg, closed=True))
    return c + s2 * (segments - c), c + s2 * (x - c)


def _correct_open(seg: np.ndarray, x: np.ndarray, target: float):
    """Scale an open piece normal to its chord to the area `target` against the chord.

    The map ``z -> a + ((z - a) . e) e + s ((z - a) . n) n`` (``a`` the first point,
    ``e`` along the chord, ``n`` normal to it) is affine, fixes both end points
    (corners) and multiplies the area against the chord by ``s``. Being affine it
    keeps the control polygon an affine arc length polyline and the end
    segments G2. The pieces of a ring with corners each keep their area against
    their chord, so the ring keeps its area.
    """
    a = seg[0, 0].copy()
    e = seg[-1, -1] - a
    ln = math.hypot(*e)
    area = bezier_area(seg, closed=False)
    if ln == 0.0 or area == 0.0 or target / area <= 0.0:
        return seg, x  # a loop or a piece that should be straight: no correction
    e = e / ln
    nrm = np.array([-e[1], e[0]])
    s = target / area

    def f(z):
        r = z - a
        return a + np.multiply.outer(r @ e, e) + s * np.multiply.outer(r @ nrm, nrm)

    return f(seg), f(x)
