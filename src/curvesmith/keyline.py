"""Keyline pipeline: from a scanned 3D polyline to two discrete elasticae.

Implements section 5 of Graiff Zurita, Kajiwara & Suzuki, *Fairing of discrete
planar curves by integrable discrete analogue of Euler's elasticae*: the
characterisation of the keylines of hand-made pantiles.

1. :func:`fit_plane` -- plane fitting of the 3D keyline by principal component
   analysis and projection to 2D coordinates in that plane (section 5.3, eq. (5.1)).
2. :func:`resample_equilateral` -- the equilateral open polygon approximation
   with step ``r`` (section 5.3, Figs. 11-13).
3. :func:`principal_frame` -- the second principal component analysis that puts
   the equilateral polygon in its own principal-axes frame, with the sign
   convention of section 5.3.
4. :func:`estimate_inflection` -- the RDP-style estimate of the global
   inflection point, steps (1)-(4) of section 5.3 (Fig. 14).
5. :func:`fit` -- the whole pipeline, then a discrete elastica fitted to each
   side of the inflection with its start ``(x0, y0)`` pinned at the inflection
   point (section 5.4), summarised as a table of ``(h, phi, z, q, k)`` per side
   like the paper's Table 1.

:func:`canonical_params` picks one representative of parameter vectors that
draw the same curve (so tables can be averaged), and :func:`synthetic_keyline`
makes realistic 3D test scans from two exact elastica halves.

Conventions: points are rows, ``(N, 3)`` for scans and ``(N, 2)`` in the plane;
angles are radians; every frame is a proper rotation (no mirror images).

Notes on the paper (section 5), checked numerically in ``tests/test_keyline.py``:

* The x''y'' conversion prints "the coordinate ``q'_k`` in the x'y'z'-coordinate
  system"; it is the x''y'' system. Its sign rule "the diagonal components of
  ``(f1 f2)`` are all positive" can only hold for the rotation
  ``f2 = R(pi/2) f1`` with ``f1_x > 0``, which is what we use.
* The 3D axes signs are fixed by the physical set-up of Fig. 9, which data do
  not carry; :func:`fit_plane` documents the data-only rule used instead.
* The resampling rule, the choice of end in RDP step (1) and the meaning of
  "upper side" in step (3) are stated for the pictured keylines only; the
  docstrings of :func:`resample_equilateral` and :func:`estimate_inflection`
  give the general reading implemented (it reproduces the pictured cases).
* With scan noise the RDP estimate, which recurses down to adjacent vertices
  as the paper prescribes, moves by several vertices: near an inflection the
  curve departs from its chords only cubically. The paper notes the same
  effect on its F16/F24 keylines; the demo reports it.

Examples
--------
>>> syn = synthetic_keyline(n_left=60, n_right=50, left=(0.02, None, 0.3))
>>> res = fit(syn.points, step=1.0)
>>> bool(res.success), res.inflection.index == syn.joint
(True, True)
>>> [round(row["k"], 6) for row in res.table()]
[0.3, 0.4]
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike

from ._rich import RichRepr
from ._validate import as_float, as_int, as_points
from .errors import CurveError
from .geometry import _resample_equilateral as _resample
from .geometry import pca_frame, principal_axes, resample_equilateral

if TYPE_CHECKING:
    from .elastica import FitResult

__all__ = [
    "DEFAULT_STEPS",
    "TABLE_COLUMNS",
    "InflectionEstimate",
    "KeylineFit",
    "PlaneFit",
    "PrincipalFrame",
    "SyntheticKeyline",
    "canonical_params",
    "estimate_inflection",
    "estimate_inflections",
    "fit",
    "fit_plane",
    "principal_frame",
    "resample_equilateral",
    "synthetic_keyline",
]


# --------------------------------------------------------------------------------------
# 5.3 plane fitting by principal component analysis
# --------------------------------------------------------------------------------------


@dataclass(frozen=True)
class PlaneFit:
    """Least-squares plane of a 3D point sequence and the points in its frame.

    Attributes
    ----------
    centroid : (3,) ndarray
        Centre of gravity ``p_bar`` of the points, eq. (5.1).
    axes : (3, 3) ndarray
        Rows ``e1, e2, e3``: orthonormal eigenvectors of the covariance matrix
        ``C`` for ``lambda1 >= lambda2 >= lambda3``; ``e3`` is the plane normal.
        A proper rotation (``det = +1``, ``e1 x e2 = e3``).
    eigenvalues : (3,) ndarray
        ``lambda1 >= lambda2 >= lambda3 >= 0`` of ``C = (1/m) sum (p - p_bar)(p - p_bar)^t``.
    coords : (N, 3) ndarray
        ``p'_k = (e1 e2 e3)^t (p_k - p_bar)``: columns x', y' (in the plane) and z'
        (signed distance from the plane).
    """

    centroid: np.ndarray
    axes: np.ndarray
    eigenvalues: np.ndarray
    coords: np.ndarray

    @property
    def normal(self) -> np.ndarray:
        """(3,) ndarray: unit normal ``e3`` of the plane."""
        return self.axes[2]

    @property
    def points2d(self) -> np.ndarray:
        """(N, 2) ndarray: the points projected on the plane, in x'y' coordinates."""
        return self.coords[:, :2]

    @property
    def rms_distance(self) -> float:
        """float: root mean square distance of the points from the plane, ``sqrt(lambda3)``."""
        return float(np.sqrt(np.mean(self.coords[:, 2] ** 2)))

    def to_3d(self, points2d: ArrayLike) -> np.ndarray:
        """Map x'y' plane coordinates back to 3D points on the plane.

        Parameters
        ----------
        points2d : (M, 2) array_like
            Coordinates in the plane frame.

        Returns
        -------
        (M, 3) ndarray
            ``p_bar + x' e1 + y' e2``.
        """
        q = as_points(points2d, name="points2d", min_points=1)
        return self.centroid + q @ self.axes[:2]


def fit_plane(points: ArrayLike, *, normal_hint: ArrayLike = (0.0, 0.0, 1.0)) -> PlaneFit:
    """Fit a plane to 3D points by principal component analysis and project on it.

    Implements the plane fitting of section 5.3 (Graiff Zurita, Kajiwara &
    Suzuki): the plane through the centre of gravity ``p_bar`` (eq. (5.1))
    spanned by the eigenvectors ``e1, e2`` of the two largest eigenvalues of
    the covariance matrix ``C`` minimises the sum of squared distances; the
    coordinates in the frame ``(e1 e2 e3)`` are ``p' = (e1 e2 e3)^t (p - p_bar)``.
    The eigenvectors are computed by an SVD of the centred points (the right
    singular vectors are the eigenvectors of ``C``, with ``lambda = s^2 / m``),
    which is better conditioned than forming ``C``.

    Sign convention. The paper fixes the axes by the physical set-up of its
    scanner (Fig. 9). Here, so that the result depends only on the data and a
    viewing direction: ``e3`` points to the side of `normal_hint` (the 2D curve
    is the keyline as seen from that side; if ``e3`` is orthogonal to the hint,
    its largest component is made positive); ``e1`` points from the first
    input point towards the last (the scan order runs in +x'); ``e2 = e3 x e1``
    so the frame is a proper rotation and the 2D curve is never mirrored.

    Parameters
    ----------
    points : (N, 3) array_like
        The scanned keyline, N >= 3, not all on one line.
    normal_hint : (3,) array_like, optional
        Direction from which the plane is viewed; default ``+z``.

    Returns
    -------
    PlaneFit

    Raises
    ------
    CurveError
        If the points are not finite, fewer than 3, or collinear (no plane).

    Examples
    --------
    >>> pf = fit_plane([[0, 0, 1], [1, 0, 1], [2, 1, 1], [3, 3, 1]])
    >>> pf.normal.round(12).tolist()
    [0.0, 0.0, 1.0]
    >>> float(abs(pf.coords[:, 2]).max()) < 1e-12
    True
    """
    p = as_points(points, dim=3, min_points=3)
    centroid, axes, lam = pca_frame(p, normal_hint=normal_hint)
    coords = (p - centroid) @ axes.T
    return PlaneFit(centroid=centroid, axes=axes, eigenvalues=lam, coords=coords)


# --------------------------------------------------------------------------------------
# 5.3 principal-axes frame of the 2D keyline
# --------------------------------------------------------------------------------------


@dataclass(frozen=True)
class PrincipalFrame:
    """Principal-axes frame of a 2D point sequence (the x''y'' system of section 5.3).

    Attributes
    ----------
    centre : (2,) ndarray
        Centre of gravity ``q_bar`` of the points.
    axes : (2, 2) ndarray
        Rows ``f1, f2``: normalised eigenvectors of the covariance matrix ``D``
        for ``mu1 >= mu2``, signed so that the diagonal of ``(f1 f2)`` is
        positive (a rotation by an angle in ``(-pi/2, pi/2]``).
    eigenvalues : (2,) ndarray
        ``mu1 >= mu2 >= 0`` of ``D = (1/n) sum (q - q_bar)(q - q_bar)^t``.
    coords : (N, 2) ndarray
        ``q'_k = (f1 f2)^t (q_k - q_bar)``.
    """

    centre: np.ndarray
    axes: np.ndarray
    eigenvalues: np.ndarray
    coords: np.ndarray

    @property
    def angle(self) -> float:
        """float: angle of ``f1`` from the x axis, in ``(-pi/2, pi/2]`` radians."""
        return math.atan2(self.axes[0, 1], self.axes[0, 0])

    def to_frame(self, points: ArrayLike) -> np.ndarray:
        """Express other points of the same plane in this frame.

        Parameters
        ----------
        points : (M, 2) array_like

        Returns
        -------
        (M, 2) ndarray
            ``(f1 f2)^t (q - q_bar)``.
        """
        q = as_points(points, min_points=1)
        return (q - self.centre) @ self.axes.T

    def from_frame(self, coords: ArrayLike) -> np.ndarray:
        """Map frame coordinates back: ``q = q_bar + (f1 f2) q'``.

        Parameters
        ----------
        coords : (M, 2) array_like

        Returns
        -------
        (M, 2) ndarray
        """
        c = as_points(coords, name="coords", min_points=1)
        return self.centre + c @ self.axes


def principal_frame(points: ArrayLike) -> PrincipalFrame:
    """Put a 2D point sequence in its principal-axes frame (section 5.3).

    Implements the coordinate conversion of the approximated 2D keyline in
    section 5.3: with the centre of gravity ``q_bar`` and the eigenvectors
    ``f1, f2`` of ``D`` (``mu1 >= mu2``), ``q'_k = (f1 f2)^t (q_k - q_bar)``.
    The paper fixes the signs of ``f1, f2`` "so that the diagonal components of
    ``(f1 f2)`` are all positive"; that makes ``(f1 f2)`` the rotation by the
    angle of ``f1`` in ``(-pi/2, pi/2)``, i.e. ``f1`` has a positive x component
    and ``f2 = R(pi/2) f1``. In the tie ``f1 = (0, +-1)`` we take ``f1 = (0, 1)``.
    (The paper writes "the x'y'z'-coordinate system" for the result; it means
    the x''y'' system, as the following sentence says.)

    Parameters
    ----------
    points : (N, 2) array_like
        N >= 2 points, not all equal.

    Returns
    -------
    PrincipalFrame

    Examples
    --------
    >>> fr = principal_frame([[0, 0], [1, 1], [2, 2], [3, 3]])
    >>> round(fr.angle, 12) == round(math.pi / 4, 12)
    True
    >>> fr.coords[:, 1].round(12).tolist()
    [0.0, 0.0, 0.0, 0.0]
    """
    q = as_points(points, min_points=2)
    return _principal_frame(q)


def _principal_frame(q: np.ndarray) -> PrincipalFrame:
    centre, s, vt = principal_axes(q)
    c = q - centre
    if s[0] <= 0.0:
        raise CurveError(f"points must not all coincide, got every point at {centre.tolist()}")
    f1 = vt[0]
    if f1[0] < 0.0 or (f1[0] == 0.0 and f1[1] < 0.0):
        f1 = -f1
    f2 = np.array([-f1[1], f1[0]])
    axes = np.vstack([f1, f2])
    lam = np.zeros(2)
    lam[: s.size] = s**2 / q.shape[0]
    return PrincipalFrame(centre=centre, axes=axes, eigenvalues=lam, coords=c @ axes.T)


# --------------------------------------------------------------------------------------
# 5.3 equilateral open polygon approximation
# --------------------------------------------------------------------------------------


# --------------------------------------------------------------------------------------
# 5.3 inflection estimate (RDP method)
# --------------------------------------------------------------------------------------


@dataclass(frozen=True)
class InflectionEstimate:
    """Result of the RDP-style inflection estimate of section 5.3.

    Attributes
    ----------
    index : int
        Vertex index of the estimated inflection point.
    point : (2,) ndarray
        Its coordinates.
    labels : tuple of int
        Vertex indices of the numbered points of Fig. 14 in order of creation:
        ``labels[0]`` is point 1 (end without the inflection), ``labels[1]``
        point 2 (end on the inflection side), ``labels[2]`` point 3 (farthest
        from the end chord), then 4, 5, ...; the last one is the estimate.
    """

    index: int
    point: np.ndarray
    labels: tuple[int, ...]


def _farthest(p: np.ndarray, i: int, j: int) -> tuple[int, int, float]:
    """Vertex strictly between i < j farthest from the segment p_i p_j.

    Returns (index, side, distance) with side = +1 on the left of the segment
    directed from p_i to p_j (the "upper side" of the paper for a keyline
    running left to right), -1 on the right, 0 if on the line.
    """
    a = p[i]
    u = p[j] - a
    w = p[i + 1 : j] - a
    uu = float(u @ u)
    cross = u[0] * w[:, 1] - u[1] * w[:, 0]
    if uu > 0.0:
        tt = np.clip((w @ u) / uu, 0.0, 1.0)
        dist = np.hypot(w[:, 0] - tt * u[0], w[:, 1] - tt * u[1])
    else:
        dist = np.hypot(w[:, 0], w[:, 1])
    m = int(np.argmax(dist))
    return i + 1 + m, int(np.sign(cross[m])), float(dist[m])


#: Largest number of vertices used to measure how far a sub-polyline is from convex.
_DEPTH_SAMPLES = 1024


def _concavity_depth(p: np.ndarray, i: int, j: int) -> float:
    """Largest distance from a vertex of p[i..j] to the boundary of their convex hull.

    Zero (to rounding) for a convex arc, whose vertices are all on the hull; an
    arc through an inflection has vertices inside the hull of its two lobes.
    """
    from scipy.spatial import ConvexHull, QhullError

    q = p[i : j + 1]
    if q.shape[0] > _DEPTH_SAMPLES:  # the measure is coarse-scale: cap its O(n * facets) cost
        q = q[np.linspace(0, q.shape[0] - 1, _DEPTH_SAMPLES).round().astype(np.intp)]
    if q.shape[0] < 4:
        return 0.0
    try:
        hull = ConvexHull(q)
    except QhullError:  # collinear: no inside
        return 0.0
    inside = -(q @ hull.equations[:, :2].T + hull.equations[:, 2])  # >= 0 inside, per facet
    return float(max(0.0, inside.min(axis=1).max()))


def estimate_inflection(points: ArrayLike) -> InflectionEstimate:
    """Estimate the global inflection point of an S-shaped polyline (RDP method).

    Implements steps (1)-(4) of section 5.3 (Fig. 14), inspired by the
    Ramer-Douglas-Peucker algorithm:

    (1) point 3 is the vertex farthest from the segment joining the two ends;
        point 2 is the end on the inflection side, point 1 the other end;
    (2) point 4 is the vertex between 2 and 3 farthest from segment 2-3;
    (3) repeatedly, point ``P+2`` is the vertex between ``P`` and ``P+1``
        farthest from segment ``P(P+1)``; if ``P+1`` and ``P+2`` lie on the same
        side ("upper" or "lower") of their segments, ``P`` and ``P+1`` are
        switched, i.e. the new point replaces ``P+1`` and the next bracket is
        ``(P, P+2)``; otherwise it is ``(P+1, P+2)``;
    (4) when the bracket's two points are adjacent vertices, the newest point
        is the estimate.

    Interpretation, as the paper leaves some choices to the eye:

    * "upper side" is the left of the segment directed along the polyline
      (increasing vertex index), which is the upper side for a keyline running
      left to right and makes the method rotation invariant. The point
      farthest from a chord shows which lobe it belongs to by its side: each
      convex lobe bulges to one side of any chord of its own.
    * The inflection side in step (1) is the end whose sub-polyline to point 3
      is the less convex: the one with the vertex deepest inside the convex
      hull of that sub-polyline (a convex arc has all its vertices on its hull;
      a short second lobe can stay on one side of the chord, so the chord test
      alone is not enough). The lobe test of step (3) is applied to point 4
      too (against point 3's side of chord 1-2), which the printed step (2)
      leaves implicit.
    * Distances are to the segment, as printed (classic RDP uses the line).

    The bracket shrinks at every step, so the method ends after at most N
    steps. On noise-free S curves made of two exact elastica halves whose lobes
    turn by up to about 2 asin(0.85) = 116 degrees the estimate is within one
    vertex of the inflection (property test); on curled lobes (a hook turning
    back behind the chord, lobes turning by ~140 degrees and more) the side
    test of step (3) can misjudge the lobe, as the method assumes keyline-like
    gentle curves.

    Parameters
    ----------
    points : (N, 2) array_like
        Open polyline with one global inflection, N >= 5.

    Returns
    -------
    InflectionEstimate

    Raises
    ------
    CurveError
        If the polyline is straight or has no vertex on the far side of a
        chord (no inflection: a convex arc).

    Examples
    --------
    >>> x = np.linspace(-1.0, 2.0, 61)
    >>> est = estimate_inflection(np.column_stack([x, x**3]))
    >>> abs(float(est.point[0])) <= 0.05
    True
    """
    p = as_points(points, min_points=5)
    return _estimate_inflection(p)


def _estimate_inflection(p: np.ndarray) -> InflectionEstimate:
    n = p.shape[0]
    i3, s3, d3 = _farthest(p, 0, n - 1)
    if d3 <= 0.0 or s3 == 0:
        raise CurveError("points must bend (an S curve with an inflection), got a straight line")
    scale = float(np.ptp(p, axis=0).max())
    dev_first = _concavity_depth(p, 0, i3)
    dev_last = _concavity_depth(p, i3, n - 1)
    if max(dev_first, dev_last) <= 1e-9 * scale:
        raise CurveError(
            "points must have an inflection, got a convex arc (every vertex on the convex hull "
            "of its side of the farthest point)"
        )
    end2, end1 = (0, n - 1) if dev_first >= dev_last else (n - 1, 0)
    labels = [end1, end2, i3]
    a, b, s_b = end2, i3, s3
    while abs(a - b) > 1:
        lo, hi = (a, b) if a < b else (b, a)
        c, s_c, _ = _farthest(p, lo, hi)
        labels.append(c)
        if s_c != 0 and s_c == s_b:
            b = c  # same lobe as the newest point: switch, the bracket is (P, P+2)
        else:
            a, b = b, c  # the bracket is (P+1, P+2)
        s_b = s_c
    idx = labels[-1]
    return InflectionEstimate(index=idx, point=p[idx].copy(), labels=tuple(labels))


#: A sub-polyline has an inflection if a vertex lies deeper than this many noise levels
#: inside the convex hull of the sub-polyline (a convex arc: only the noise is inside).
_DEPTH_NOISE = 10.0


def _inflections(p: np.ndarray, lo: int, hi: int, floor: float) -> list[int]:
    """Inflection indices of ``p[lo..hi]``: the RDP method of section 5.3, recursively.

    A piece whose :func:`_concavity_depth` is at most `floor` is convex (no inflection).
    Otherwise the RDP estimate ``i`` splits it and both halves are searched; on a curve with
    two inflections the estimate is the apex of the middle lobe (the method assumes one),
    so ``i`` itself is kept only if the piece between the nearest inflections found on
    either side still has one, estimated again on that piece (an S with one inflection).
    """
    if hi - lo < 4 or _concavity_depth(p, lo, hi) <= floor:
        return []
    rdp = _rdp_index(p, lo, hi)
    estimate = rdp is not None
    # the estimate fell on an end: split at point 3 of step (1) instead
    i = rdp if rdp is not None else _farthest(p, lo, hi)[0]
    left = _inflections(p, lo, i, floor)
    right = _inflections(p, i, hi, floor)
    a = left[-1] if left else lo
    b = right[0] if right else hi
    middle = None
    if (a, b) == (lo, hi):
        middle = i if estimate else None
    elif b - a >= 4 and _concavity_depth(p, a, b) > floor:
        middle = _rdp_index(p, a, b)
    return [*left, *([] if middle is None else [middle]), *right]


def _rdp_index(p: np.ndarray, lo: int, hi: int) -> int | None:
    """The RDP estimate on ``p[lo..hi]`` as an index of `p`; None if it fails or is an end."""
    try:
        i = lo + _estimate_inflection(p[lo : hi + 1]).index
    except CurveError:
        return None
    return i if lo + 2 <= i <= hi - 2 else None


def estimate_inflections(
    points: ArrayLike, *, noise: float | None = None
) -> tuple[InflectionEstimate, ...]:
    """Estimate every inflection of an open polyline by the RDP method, recursively.

    The RDP method of section 5.3 (:func:`estimate_inflection`) assumes one global
    inflection; on a curve with two it returns the apex of the middle lobe. Here it splits
    the polyline, both halves are searched again, and a split point is kept only where the
    piece between the nearest inflections on either side still has one (then estimated on
    that piece, an S with a single inflection). A piece has an inflection if one of its
    vertices lies deeper inside the convex hull of the piece than ``10`` noise levels (the
    robust noise of ``elastica.fit._scan_noise``): a noisy convex arc has only its noise
    inside. Each estimate is thus the paper's, made on a piece with one inflection, then
    refined to the zero of curvature of a least-squares quintic graph over the S between
    the apexes of the two lobes around it (``labels`` holds the RDP estimate): under scan
    noise the RDP estimate moves by tens of vertices on gentle curves (on 0.05 mm noise,
    1 mm steps, lobes turning by ~0.5 rad: up to 30 mm), the fit by a few.

    Parameters
    ----------
    points : (N, 2) array_like
        Open polyline, roughly equally spaced (e.g. :func:`resample_equilateral`), N >= 5.
    noise : float, optional
        Noise level (standard deviation per coordinate) of the data; default: estimated
        from `points`. A polygon resampled with chords shorter than the scan's noise hides
        part of it (its vertices are a biased sample), so :func:`fit` passes the larger of
        the scan's and the polygon's.

    Returns
    -------
    tuple of InflectionEstimate
        In order along the polyline, indices into `points` (``labels`` = the RDP estimate
        before the refinement); empty for a convex arc.

    Examples
    --------
    >>> t = np.linspace(0.0, 3.0 * np.pi, 301)
    >>> est = estimate_inflections(np.column_stack([t, np.sin(t)]))
    >>> [round(float(e.point[0]) / np.pi, 2) for e in est]
    [1.0, 2.0]
    """
    from .elastica.fit import _scan_noise

    p = as_points(points, min_points=5)
    extent = float(np.ptp(p, axis=0).max())
    sigma = (
        _scan_noise(p) if noise is None else as_float(noise, name="noise", low=0.0, low_open=False)
    )
    floor = max(_DEPTH_NOISE * sigma, 1e-9 * extent)
    found = _inflections(p, 0, p.shape[0] - 1, floor)
    bounds = [0, *found, p.shape[0] - 1]
    out = []
    for j, idx in enumerate(found):
        # the S between the apexes of the two lobes around this inflection
        a = _farthest(p, bounds[j], idx)[0] if idx - bounds[j] >= 2 else bounds[j]
        b = _farthest(p, idx, bounds[j + 2])[0] if bounds[j + 2] - idx >= 2 else bounds[j + 2]
        best = _refine_inflection(p, a, b, idx, floor)
        out.append(InflectionEstimate(index=best, point=p[best].copy(), labels=(idx,)))
    return tuple(out)


def _centred_on_straight_run(
    p: np.ndarray, est: InflectionEstimate, floor: float
) -> InflectionEstimate:
    """The RDP estimate, moved to the middle of the straight run it lies on, if any.

    Where the two lobes are joined by a straight run (every vertex between the lobes'
    apexes within `floor` of their chord), the curvature vanishes on an interval and the
    RDP method stops at one end of it (a keyline of five scanned points: vertex 159 of
    217 instead of 108); the middle of the run is the inflection. Curved S shapes, the
    paper's, are left as they are.
    """
    i, n = est.index, p.shape[0]
    a = _farthest(p, 0, i)[0] if i >= 2 else 0
    b = _farthest(p, i, n - 1)[0] if n - 1 - i >= 2 else n - 1
    j = _straight_middle(p, a, b, floor)
    if j is None or j == i:
        return est
    return InflectionEstimate(index=j, point=p[j].copy(), labels=(*est.labels, j))


def _straight_middle(p: np.ndarray, a: int, b: int, floor: float) -> int | None:
    """The middle vertex of ``p[a..b]`` if all of it lies within `floor` of its chord."""
    if b - a < 2:
        return None
    u = p[b] - p[a]
    length = math.hypot(u[0], u[1])
    if length == 0.0:
        return None
    d = p[a : b + 1] - p[a]
    y = (d[:, 1] * u[0] - d[:, 0] * u[1]) / length
    return (a + b) // 2 if float(np.max(np.abs(y))) <= floor else None


#: Degree of the polynomial graph that locates an inflection between two lobe apexes.
_REFINE_DEGREE = 5


def _refine_inflection(p: np.ndarray, a: int, b: int, idx: int, floor: float = 0.0) -> int:
    """The vertex of ``p[a..b]`` nearest the zero of curvature of a least-squares quintic.

    ``p[a..b]`` runs from the apex of one lobe to the apex of the next (an S with the one
    inflection `idx`, the RDP estimate). In the frame of its chord it is a graph
    ``y(x)``; the zero of ``y''`` of the fitted polynomial nearest `idx` is the inflection
    (``kappa = y'' / (1 + y'^2)^{3/2}``). Under scan noise the RDP estimate, which
    recurses down to adjacent vertices where the curve leaves its chords only cubically,
    moves by tens of vertices on gentle keylines; the fit averages the noise over the whole
    S. Returns `idx` where the piece is not a graph over its chord or has no such zero.

    Where the lobes are joined by a straight run (every vertex between the apexes within
    `floor` of their chord: the curvature vanishes on an interval, as on a polygon of few
    scanned points or a profile with a straight middle), the inflection is the middle
    vertex of the run; the quintic's zero would fall anywhere on it.
    """
    middle = _straight_middle(p, a, b, floor)
    if middle is not None:
        return middle
    seg = p[a : b + 1]
    if seg.shape[0] < 3 * _REFINE_DEGREE:
        return idx
    u = seg[-1] - seg[0]
    u = u / math.hypot(u[0], u[1])
    d = seg - seg[0]
    x = d @ u
    y = d[:, 1] * u[0] - d[:, 0] * u[1]
    if np.any(np.diff(x) <= 0.0):
        return idx
    poly = np.polynomial.Polynomial.fit(x, y, _REFINE_DEGREE)
    roots = poly.deriv(2).roots()
    roots = roots[np.abs(roots.imag) < 1e-9].real
    roots = roots[(roots > x[0]) & (roots < x[-1])]
    if roots.size == 0:
        return idx
    x0 = roots[np.argmin(np.abs(roots - x[idx - a]))]
    return a + int(np.argmin(np.abs(x - x0)))


# --------------------------------------------------------------------------------------
# 5.4 the pipeline: one discrete elastica on each side of the inflection
# --------------------------------------------------------------------------------------

#: Columns of :meth:`KeylineFit.table`, in order.
TABLE_COLUMNS = (
    "side",
    "n_points",
    "h",
    "phi",
    "phi_deg",
    "z",
    "q",
    "k",
    "rms",
    "success",
    "case",
)

#: Default number of steps across the keyline's extent when no step is given.
DEFAULT_STEPS = 200


@dataclass(frozen=True)
class KeylineFit(RichRepr):
    """Result of :func:`fit`: the keyline in its frame and one discrete elastica per side.

    Attributes
    ----------
    points : (M, 2) ndarray
        The equilateral open polygon (chords = `step`) in the principal-axes
        frame x''y'' of section 5.3, from the left end to the stop point.
    step : float
        The chord length ``r`` used by :func:`resample_equilateral`.
    plane : PlaneFit or None
        The plane fit of the 3D input, None for 2D input.
    frame : PrincipalFrame
        The second principal component analysis (x'y' -> x''y'').
    inflection : InflectionEstimate
        The RDP estimate; ``inflection.index`` indexes `points`.
    left, right : curvesmith.elastica.FitResult
        Fits of ``points[index::-1]`` (from the inflection to the left end) and
        ``points[index:]`` (to the right end), each with ``(x0, y0)`` pinned at
        the inflection point (section 5.4): ``params``, ``points``, ``rms``,
        ``success``, ``message``, ... (see ``curvesmith.elastica.fit``).
        With several inflections, the first and the last piece.
    whole : curvesmith.elastica.FitResult or None
        The fit of the whole keyline when it has no inflection (``single_if_convex``).
    resampling : str
        ``"paper"`` or ``"walk"`` (see :func:`fit`).
    pieces : tuple of curvesmith.elastica.FitResult
        With several inflections: one fit per piece between consecutive inflections (and
        the ends), in order; the first traversed from its inflection to the left end, the
        others from their first inflection onwards, each pinned there. Empty otherwise.
    inflections : tuple of InflectionEstimate
        With several inflections: all of them, in order (`inflection` is the first).
    """

    points: np.ndarray
    step: float
    plane: PlaneFit | None
    frame: PrincipalFrame
    inflection: InflectionEstimate
    left: FitResult | None
    right: FitResult | None
    whole: FitResult | None = None
    resampling: str = "paper"
    pieces: tuple = ()
    inflections: tuple = ()

    @property
    def sides(self) -> tuple[tuple[str, FitResult], ...]:
        """tuple: the fitted pieces, ``(("left", fit), ("right", fit))``.

        ``(("whole", fit),)`` for a keyline without inflection (``single_if_convex``);
        ``(("left", fit), ("middle1", fit), ..., ("right", fit))`` for several inflections.
        """
        if self.whole is not None:
            return (("whole", self.whole),)
        if self.pieces:
            middle = [(f"middle{i}", f) for i, f in enumerate(self.pieces[1:-1], start=1)]
            return (("left", self.pieces[0]), *middle, ("right", self.pieces[-1]))
        assert self.left is not None and self.right is not None  # two sides without whole
        return (("left", self.left), ("right", self.right))

    @property
    def piece_ranges(self) -> tuple[tuple[int, int, int], ...]:
        """tuple: ``(first, last, pinned)`` vertex indices of `points` per entry of `sides`.

        Each piece runs from inflection to inflection (or to an end) and includes both;
        ``pinned`` is the inflection its fit starts from (``(x0, y0)`` pinned there), -1 for
        the whole keyline.
        """
        n = self.points.shape[0]
        if self.whole is not None:
            return ((0, n - 1, -1),)
        idx = [e.index for e in (self.inflections or (self.inflection,))]
        bounds = [0, *idx, n - 1]
        out = []
        for j in range(len(bounds) - 1):
            pinned = bounds[1] if j == 0 else bounds[j]
            out.append((bounds[j], bounds[j + 1], pinned))
        return tuple(out)

    @property
    def success(self) -> bool:
        """bool: every side fit converged."""
        return all(res.success for _, res in self.sides)

    @property
    def message(self) -> str:
        """str: the fits' messages."""
        return "; ".join(f"{side}: {res.message}" for side, res in self.sides)

    def transform(self) -> dict:
        """The map from the x''y'' frame of `points` and the fits to the input's coordinates.

        Returns
        -------
        dict
            ``origin`` (d,) and ``axes`` (2, d) with ``x_in = origin + x'' axes[0] + y'' axes[1]``
            (d = 3 for a scan, 2 for planar input), and the plane (``centroid``, ``normal``,
            ``rms``) for 3D input.
        """
        origin = self.to_input_frame(np.zeros((1, 2)))[0]
        ex = self.to_input_frame(np.array([[1.0, 0.0]]))[0] - origin
        ey = self.to_input_frame(np.array([[0.0, 1.0]]))[0] - origin
        out = {"origin": origin.tolist(), "axes": [ex.tolist(), ey.tolist()]}
        if self.plane is not None:
            out["plane"] = {
                "centroid": self.plane.centroid.tolist(),
                "normal": self.plane.normal.tolist(),
                "rms": self.plane.rms_distance,
            }
        return out

    def table(self) -> list[dict]:
        """Parameters ``(h, phi, z, q, k)`` of each side, like Table 1 of the paper.

        Returns
        -------
        list of dict
            Two rows (``side`` = ``"left"``, ``"right"``) with the keys of
            :data:`TABLE_COLUMNS`; the parameters in the canonical form of
            :func:`canonical_params`, ``phi`` in radians and ``phi_deg`` in
            degrees (the paper's "grad" column), ``rms`` the fit residual and
            ``case`` that of :attr:`curvesmith.elastica.FitResult.case`: for the
            degenerate ``"circle"`` and ``"line"``, ``k`` is a stand-in (``1e8`` for
            infinity; any value draws the line) and ``z`` follows from it.
        """
        rows = []
        for side, res in self.sides:
            _, _, h, phi, z, q, k = canonical_params(res.params)
            rows.append(
                {
                    "side": side,
                    "n_points": len(res.points),
                    "h": h,
                    "phi": phi,
                    "phi_deg": math.degrees(phi),
                    "z": z,
                    "q": q,
                    "k": k,
                    "rms": float(res.rms),
                    "success": bool(res.success),
                    "case": res.case,
                }
            )
        return rows

    def to_input_frame(self, points2d: ArrayLike) -> np.ndarray:
        """Map x''y'' coordinates (e.g. a side's fitted points) back to the input's frame.

        Parameters
        ----------
        points2d : (K, 2) array_like

        Returns
        -------
        (K, 3) or (K, 2) ndarray
            Points on the fitted plane in scan coordinates for 3D input, or
            in the input's 2D coordinates.
        """
        q = self.frame.from_frame(points2d)
        return q if self.plane is None else self.plane.to_3d(q)


def fit(
    points: ArrayLike,
    *,
    step: float | None = None,
    normal_hint: ArrayLike = (0.0, 0.0, 1.0),
    inflection: int | Sequence[int] | None = None,
    min_side_points: int = 5,
    fit_options: dict | None = None,
    single_if_convex: bool = False,
) -> KeylineFit:
    """Run the keyline pipeline of section 5 and fit a discrete elastica to each side.

    Steps (Graiff Zurita, Kajiwara & Suzuki, sections 5.3-5.4):

    1. 3D input: plane fit by PCA and projection, :func:`fit_plane`; 2D input
       is taken as already planar (its own PCA frame plays the x'y' role).
    2. The end with the smaller x' coordinate is the left end ``A_1``; the
       polyline is resampled from it by :func:`resample_equilateral` with
       chord `step`.
    3. The equilateral polygon is put in its principal-axes frame x''y''
       (:func:`principal_frame`).
    4. The global inflection is estimated by the RDP method
       (:func:`estimate_inflection`); where the lobes are joined by a straight run
       (the curvature vanishes on an interval: a keyline of a few scanned points), the
       estimate moves to the run's middle vertex (the method stops at one end of it).
    5. Each side, traversed from the inflection outwards, is fitted by
       ``curvesmith.elastica.fit`` with ``(x0, y0)`` pinned at the inflection
       point; the other five parameters ``(h, phi, z, q, k)`` are optimised.

    A keyline with several inflections (:func:`estimate_inflections` finds two or more)
    is split at each, and every piece is fitted from an inflection, pinned there
    (``result.pieces``, ``result.inflections``; ``sides`` names them left, middle1, ...,
    right). With one inflection the paper's steps 4-5 run unchanged.

    Parameters
    ----------
    points : (N, 3) or (N, 2) array_like
        The keyline as scanned (3D) or already planar (2D), in scan order,
        N >= 5; dense and noisy is fine.
    step : float, optional
        Chord length ``r`` of the equilateral polygon, in the units of the
        points (the paper uses 1 mm on 270 mm tiles). Default: the extent of
        the keyline along its first principal axis divided by
        :data:`DEFAULT_STEPS` (200).
    normal_hint : (3,) array_like, optional
        Side from which the plane is viewed, see :func:`fit_plane` (3D only).
    inflection : int or sequence of int, optional
        Vertex index of the equilateral polygon to use as the inflection
        instead of the RDP estimate (e.g. to correct an estimate moved by
        noise, as for F16/F24 in the paper); the result's
        ``inflection.labels`` is then empty. Several increasing indices split the
        keyline at each (as for an estimate of several inflections).
    min_side_points : int, optional
        Minimum number of vertices on each side of the inflection (>= 5).
    fit_options : dict, optional
        Extra keyword arguments for ``curvesmith.elastica.fit``.
    single_if_convex : bool, optional
        A keyline without inflection (a convex arc, e.g. a C-shaped section) is an
        error by default (section 5 needs the inflection); with True it gets one
        elastica fitted to the whole polygon (``result.whole``; ``left`` and ``right``
        are None), and so does a keyline whose estimated inflection lies within
        `min_side_points` of an end (noise at the end of a convex scan).

    Returns
    -------
    KeylineFit

    Notes
    -----
    The resampling rule of section 5.3 takes the candidate closest to the right end, so
    a curve that comes back within ``r`` of itself (a loop, a self-intersection) is
    short-cut there and the rest of the loop is lost. When the paper's polygon skips
    more than two chords of arc length anywhere, or stops more than two chords before
    the end, the keyline is resampled by the plain walk instead (first point ahead at
    distance ``r``, ``geometry.resample_equilateral(..., rule="walk")``), which never
    short-cuts; ``result.resampling`` says which (``"paper"`` or ``"walk"``). A closed
    curve (ends within two chords of each other) is refused with that reason.

    Raises
    ------
    CurveError
        On non-finite or too few points, a non-positive step, a step longer
        than the keyline reaches, no inflection, or an inflection so close to
        an end that a side has fewer than `min_side_points` vertices.
        Non-convergence of a side fit is not an error: it is reported in the
        result (``success``, ``message``).
    """
    p = as_points(points, dim=(2, 3), min_points=5)
    min_side = as_int(min_side_points, name="min_side_points", minimum=5)
    plane = fit_plane(p, normal_hint=normal_hint) if p.shape[1] == 3 else None
    if plane is not None:
        q = plane.points2d
        xs = q[:, 0]
    else:
        q = p
        xs = _principal_frame(q).coords[:, 0]
    if xs[-1] < xs[0]:
        q = q[::-1]
    if step is None:
        r = float(np.ptp(xs)) / DEFAULT_STEPS
        if r <= 0.0:
            raise CurveError("points must extend along a line, got all points at one place")
    else:
        r = as_float(step, name="step", low=0.0)
    q = np.ascontiguousarray(q)
    total = float(np.hypot(*np.diff(q[:, :2], axis=0).T).sum())
    extent = float(np.ptp(q, axis=0).max())
    if total > 4 * r and float(np.linalg.norm(q[-1] - q[0])) < min(2 * r, 0.05 * extent):
        raise CurveError(
            f"points form a closed curve (the ends are {np.linalg.norm(q[-1] - q[0]):.3g} "
            f"apart on a curve {total:.6g} long); the keyline pipeline fits an open keyline "
            "with ends: split the closed curve into open pieces first"
        )
    poly, ts = _resample(q, r)
    rule = "paper"
    if (ts.size > 1 and float(np.diff(ts).max()) > 2.0 * r) or ts[-1] < total - 2.0 * r:
        from .geometry import _resample_walk

        poly, rule = _resample_walk(q, r), "walk"
    if poly.shape[0] < 2 * min_side - 1:
        raise CurveError(
            f"step must leave at least {2 * min_side - 1} vertices on the keyline, got "
            f"{poly.shape[0]} vertices with step {r:.6g}; use a smaller step"
        )
    frame = _principal_frame(poly)
    xy = frame.coords
    several = None
    floor = 0.0
    convex = False  # no vertex deeper inside the hull than the noise explains
    if inflection is None:
        from .elastica.fit import _scan_noise

        sigma = max(_scan_noise(q), _scan_noise(xy))
        floor = max(_DEPTH_NOISE * sigma, 1e-9 * float(np.ptp(xy, axis=0).max()))
        found = estimate_inflections(xy, noise=sigma)
        convex = not found
        if len(found) >= 2:
            several = found
    elif np.ndim(inflection) == 1:
        given = np.asarray(inflection, dtype=object).tolist()
        idx = [as_int(j, name="inflection", minimum=0, maximum=xy.shape[0] - 1) for j in given]
        if sorted(set(idx)) != idx or not idx:
            raise CurveError(f"inflection must be increasing vertex indices, got {given}")
        if len(idx) == 1:
            inflection = idx[0]
        else:
            several = tuple(InflectionEstimate(index=j, point=xy[j].copy(), labels=()) for j in idx)
    if several is not None:
        pieces = _fit_pieces(xy, several, min_side, dict(fit_options or {}))
        return KeylineFit(
            points=xy,
            step=r,
            plane=plane,
            frame=frame,
            inflection=several[0],
            left=pieces[0],
            right=pieces[-1],
            resampling=rule,
            pieces=pieces,
            inflections=several,
        )
    if inflection is None and convex and single_if_convex:
        # convex within the noise: the RDP estimate would split a noisy convex arc (a
        # spiral whose curvature grows from 0.004 to 0.022 per mm, 0.02 mm noise, was cut
        # at vertex 218 of 223), though no vertex lies deeper inside its hull than the noise
        est = None
    elif inflection is None:
        try:
            est = _centred_on_straight_run(xy, _estimate_inflection(xy), floor)
        except CurveError as exc:
            if not (single_if_convex and "convex arc" in str(exc)):
                raise
            est = None
    else:
        j = as_int(inflection, name="inflection", minimum=0, maximum=xy.shape[0] - 1)
        est = InflectionEstimate(index=j, point=xy[j].copy(), labels=())
    if est is not None:
        i = est.index
        n_left, n_right = i + 1, xy.shape[0] - i
        if min(n_left, n_right) < min_side:
            if not (single_if_convex and inflection is None):
                raise CurveError(
                    "points must have an inflection away from the ends, got the estimate at "
                    f"vertex {i} of {xy.shape[0]} ({n_left} vertices on the left side, "
                    f"{n_right} on the right; need {min_side} on each)"
                )
            est = None  # an "inflection" within min_side vertices of an end: noise there
    if est is None:
        whole = _fit_whole(xy, dict(fit_options or {}))
        return KeylineFit(
            points=xy,
            step=r,
            plane=plane,
            frame=frame,
            inflection=InflectionEstimate(index=0, point=xy[0].copy(), labels=()),
            left=None,
            right=None,
            whole=whole,
            resampling=rule,
        )
    options = dict(fit_options or {})
    left = _fit_side(xy[i::-1], options)
    right = _fit_side(xy[i:], options)
    return KeylineFit(
        points=xy,
        step=r,
        plane=plane,
        frame=frame,
        inflection=est,
        left=left,
        right=right,
        resampling=rule,
    )


def _fit_pieces(xy: np.ndarray, inflections, min_side: int, options: dict) -> tuple:
    """Fit each piece between consecutive inflections, pinned at an inflection (section 5.4)."""
    idx = [e.index for e in inflections]
    bounds = [0, *idx, xy.shape[0] - 1]
    sizes = [b - a + 1 for a, b in itertools.pairwise(bounds)]
    if min(sizes) < min_side:
        j = int(np.argmin(sizes))
        raise CurveError(
            f"points must have inflections at least {min_side} vertices apart, got inflections "
            f"at vertices {idx} of {xy.shape[0]}: piece {j + 1} (vertices {bounds[j]}-"
            f"{bounds[j + 1]}) has {sizes[j]}"
        )
    pieces = [_fit_side(xy[idx[0] :: -1], options)]
    for a, b in itertools.pairwise(bounds[1:]):
        pieces.append(_fit_side(xy[a : b + 1], options))
    return tuple(pieces)


def _fit_whole(xy: np.ndarray, options: dict):
    """One elastica through the whole equilateral polygon (no inflection): the global fit."""
    from . import elastica

    return elastica.fit(xy, **options)


def _fit_side(side: np.ndarray, options: dict):
    """Fit one side with its start pinned at the inflection (section 5.4).

    The paper starts the optimiser from the initial guess of section 4.3, which
    reads the discrete curvature (4.33) of the data. On a scan resampled at a
    fine step the noise of that curvature grows like ``sigma / h^2`` and the
    guess can land in the wrong basin (e.g. near the separatrix ``k = 1``).
    So the side is first fitted at a coarser resolution, every ``m``-th vertex
    (curvature noise down by ``m^2``), and that fit, rescaled to the full
    resolution (``h / m``, ``z / m``; ``phi``, ``q``, ``k`` unchanged), starts
    the full fit (restarted once from where it stopped if it ran into the
    iteration limit in a flat valley); if that does not succeed the
    full-resolution guess is tried too, and the better converged fit is kept.
    """
    from . import elastica

    fixed = {"x0": float(side[0, 0]), "y0": float(side[0, 1])}
    n = side.shape[0]
    m = max(1, min(n // 32, (n - 1) // 7))
    candidates = []
    if m >= 2 and "start" not in options:
        coarse = elastica.fit(side[::m], fixed=fixed, **options)
        c = coarse.params
        start = (c.x0, c.y0, c.h / m, c.phi, c.z / m, c.q, c.k)
        first = {"max_iterations": 100, **options}
        res = elastica.fit(side, fixed=fixed, start=start, **first)
        if not res.success:  # a slow valley ends on the iteration limit: restart there
            res = elastica.fit(side, fixed=fixed, start=res.params, **options)
        if res.success:
            return res
        candidates.append(res)
    res = elastica.fit(side, fixed=fixed, **options)
    candidates.append(res)
    return min(candidates, key=lambda r: (not r.success, r.rms))


def canonical_params(params: Sequence[float]) -> tuple[float, ...]:
    """A canonical representative of discrete elastica parameters ``(x0, y0, h, phi, z, q, k)``.

    Different parameter vectors draw the same vertices: ``phi`` matters
    modulo ``2 pi``; for ``k < 1`` (case (ii)) the half angle ``a(s)`` with
    ``sin a = k sn(s; k)``, ``cos a = dn(s; k)`` has period ``4K(k)`` in ``s``
    and ``a(-s - 2K) = a(s)``, so ``(z, q)`` and ``(-z, -q - 2K)`` give the same
    curve; for ``k > 1`` (case (i), modulus ``1/k``), shifting ``q`` by
    ``2K(1/k^2)/k`` turns ``a`` by ``pi`` and every tangent by ``2 pi``. This
    returns ``phi`` in ``(-pi, pi]``, ``z >= 0`` when ``k < 1``, and ``q``
    reduced to ``[0, period)``, so that tables of fits (Table 1) can be
    averaged. Verified: the vertices of the input and of the output agree to
    rounding (tests).

    Parameters
    ----------
    params : sequence of 7 float

    Returns
    -------
    tuple of 7 float

    Examples
    --------
    >>> from scipy.special import ellipk
    >>> K = float(ellipk(0.16))
    >>> p = canonical_params((0, 0, 1.0, 7.0, -0.015, -1.64 - 2 * K, 0.4))
    >>> [round(v, 6) for v in p[3:6]]
    [0.716815, 0.015, 1.64]
    """
    from scipy.special import ellipk

    x0, y0, h, phi, z, q, k = (float(v) for v in params)
    phi = math.remainder(phi, 2.0 * math.pi)
    if phi == -math.pi:
        phi = math.pi
    if k < 1.0:
        big_k = float(ellipk(k * k))
        if z < 0.0:
            z, q = -z, -q - 2.0 * big_k
        q = q % (4.0 * big_k)
    elif k > 1.0:
        q = q % (2.0 * float(ellipk(1.0 / (k * k))) / k)
    return (x0, y0, h, phi, z, q, k)


# --------------------------------------------------------------------------------------
# synthetic scans for tests, demos and benchmarks
# --------------------------------------------------------------------------------------


@dataclass(frozen=True)
class SyntheticKeyline:
    """A synthetic 3D keyline scan made from two exact discrete elastica halves.

    Attributes
    ----------
    points : (M, 3) ndarray
        The "scan": dense points along the generating polygon, embedded in a
        tilted plane, with Gaussian noise.
    vertices : (n_left + n_right - 1, 2) ndarray
        The generating equilateral polygon in its plane's coordinates.
    joint : int
        Index in `vertices` of the shared start vertex of both halves (the
        inflection when both phases ``q`` are ``K(k)``).
    left_params, right_params : tuple of 7 float
        ``(x0, y0, h, phi, z, q, k)`` of the two halves in the plane's
        coordinates, each traversed from the joint outwards.
    rotation : (3, 3) ndarray
        Columns: the plane's in-plane axes and its normal in 3D.
    offset : (3,) ndarray
        3D position of the plane's origin (the joint).
    """

    points: np.ndarray
    vertices: np.ndarray
    joint: int
    left_params: tuple
    right_params: tuple
    rotation: np.ndarray
    offset: np.ndarray

    def params_in(self, result: KeylineFit) -> tuple[tuple, tuple]:
        """The true parameters expressed in the x''y'' frame of a pipeline result.

        The scan's plane coordinates map to the result's frame by a rigid
        motion ``A xy + b`` (``A`` a rotation by ``alpha``); the true elastica
        parameters there are ``(A (x0, y0) + b, h, phi + alpha, z, q, k)``.

        Parameters
        ----------
        result : KeylineFit
            Output of :func:`fit` on ``self.points``.

        Returns
        -------
        (left, right) : tuple of two 7-tuples
        """
        a = self.rotation[:, :2]
        if result.plane is not None:
            lin = result.frame.axes @ result.plane.axes[:2] @ a
            off = result.frame.axes @ (
                result.plane.axes[:2] @ (self.offset - result.plane.centroid) - result.frame.centre
            )
        else:
            lin = result.frame.axes
            off = -result.frame.axes @ result.frame.centre
        if np.linalg.det(lin) < 0:
            raise CurveError("result must view the plane from the scan's normal side (mirrored)")
        alpha = math.atan2(lin[1, 0], lin[0, 0])
        out = []
        for x0, y0, h, phi, z, q, k in (self.left_params, self.right_params):
            x0n, y0n = lin @ np.array([x0, y0]) + off
            out.append((float(x0n), float(y0n), h, phi + alpha, z, q, k))
        return out[0], out[1]


def _rotation_xyz(angles) -> np.ndarray:
    ax, ay, az = (float(a) for a in angles)
    cx, sx, cy, sy, cz, sz = (
        math.cos(ax),
        math.sin(ax),
        math.cos(ay),
        math.sin(ay),
        math.cos(az),
        math.sin(az),
    )
    rx = np.array([[1, 0, 0], [0, cx, -sx], [0, sx, cx]])
    ry = np.array([[cy, 0, sy], [0, 1, 0], [-sy, 0, cy]])
    rz = np.array([[cz, -sz, 0], [sz, cz, 0], [0, 0, 1]])
    return rz @ ry @ rx


def synthetic_keyline(
    left: tuple[float, float | None, float] = (0.008, None, 0.30),
    right: tuple[float, float | None, float] = (0.015, None, 0.40),
    *,
    h: float = 1.0,
    n_left: int = 150,
    n_right: int = 120,
    phi: float = -0.2,
    tilt: ArrayLike = (0.35, -0.25, 0.6),
    offset: ArrayLike = (120.0, -40.0, 15.0),
    noise: float = 0.0,
    points_per_edge: int = 8,
    seed: int | None = None,
) -> SyntheticKeyline:
    """Make a realistic synthetic 3D keyline scan from two exact discrete elasticae.

    Both halves start at a shared joint vertex and run outwards with
    ``curvesmith.elastica.sample``; the left half is turned so that its first
    edge is exactly opposite the right half's (a G1 joint). With the phases
    ``q = K(k)`` (the default, ``None``) the discrete curvature ``kappa_n``,
    proportional to ``cn(z n + q; k)`` (eq. (3.20)), vanishes at the joint, so
    the keyline has its inflection there. The polygon is sampled densely
    (`points_per_edge` points per edge, vertices included), embedded in a plane
    tilted by the rotation ``Rz Ry Rx`` of `tilt`, shifted by `offset`, and
    Gaussian noise of standard deviation `noise` is added in 3D.

    Parameters
    ----------
    left, right : (z, q, k)
        Argument step, phase (None: ``K(k)``, inflection at the joint) and
        continued modulus of each half (``k < 1``: inflections possible).
    h : float, optional
        Edge length of the generating polygon (both halves).
    n_left, n_right : int, optional
        Vertices of each half, the joint included in both.
    phi : float, optional
        Rotation of the right half (radians).
    tilt : (3,) array_like, optional
        Rotation angles about x, y, z (radians) of the plane.
    offset : (3,) array_like, optional
        3D position of the joint.
    noise : float, optional
        Standard deviation of the 3D Gaussian noise (>= 0).
    points_per_edge : int, optional
        Scan points per polygon edge (>= 1).
    seed : int, optional
        Seed of ``numpy.random.default_rng`` for the noise.

    Returns
    -------
    SyntheticKeyline
    """
    from scipy.special import ellipk

    from . import elastica

    h = as_float(h, name="h", low=0.0)
    n_left = as_int(n_left, name="n_left", minimum=3)
    n_right = as_int(n_right, name="n_right", minimum=3)
    ppe = as_int(points_per_edge, name="points_per_edge", minimum=1)
    noise = as_float(noise, name="noise", low=0.0, low_open=False)

    def halfparams(spec, name):
        try:
            z, q, k = spec
        except (TypeError, ValueError):
            raise CurveError(f"{name} must be (z, q, k), got {spec!r}") from None
        k = as_float(k, name=f"{name} k", low=0.0)
        if q is None:
            if k >= 1.0:
                raise CurveError(f"{name} k must be < 1 for an inflection at the joint, got {k}")
            q = float(ellipk(k * k))
        return as_float(z, name=f"{name} z"), as_float(q, name=f"{name} q"), k

    zr, qr, kr = halfparams(right, "right")
    zl, ql, kl = halfparams(left, "left")
    rp = (0.0, 0.0, h, float(phi), zr, qr, kr)
    rv = elastica.sample(rp, n_right)
    lv0 = elastica.sample((0.0, 0.0, h, 0.0, zl, ql, kl), n_left)
    theta_r = math.atan2(*(rv[1] - rv[0])[::-1])
    theta_l = math.atan2(*(lv0[1] - lv0[0])[::-1])
    phi_l = math.remainder(theta_r + math.pi - theta_l, 2 * math.pi)
    lp = (0.0, 0.0, h, phi_l, zl, ql, kl)
    lv = elastica.sample(lp, n_left)
    vertices = np.vstack([lv[::-1], rv[1:]])
    frac = np.arange(ppe) / ppe
    edges = np.diff(vertices, axis=0)
    dense = (vertices[:-1, None, :] + frac[None, :, None] * edges[:, None, :]).reshape(-1, 2)
    dense = np.vstack([dense, vertices[-1:]])
    rot = _rotation_xyz(as_points([tilt], name="tilt", dim=3, min_points=1)[0])
    off = as_points([offset], name="offset", dim=3, min_points=1)[0]
    pts = off + dense @ rot[:, :2].T
    if noise > 0.0:
        pts = pts + noise * np.random.default_rng(seed).standard_normal(pts.shape)
    return SyntheticKeyline(
        points=pts,
        vertices=vertices,
        joint=n_left - 1,
        left_params=lp,
        right_params=rp,
        rotation=rot,
        offset=off,
    )
