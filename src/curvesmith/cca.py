"""Area-preserving smoothing by corner cutting and augmentation (CCA1).

Implements D. Gordon, *Corner cutting and augmentation: an area-preserving
method for smoothing polygons and polylines*, CAGD 27 (2010) 551-562.

One CCA1 step (section 3) does, at every vertex ``V_i`` that is not fixed
(polyline end or anchor):

* **corner cut** -- two points at distance ``a_i = alpha_i * min(|e_{i-1}|, |e_i|)``
  on the two incident edges, ``L_i = V_i - a_i u_{i-1}`` and
  ``R_i = V_i + a_i u_i``; the isosceles triangle ``(L_i, V_i, R_i)`` is cut off.
  Its signed area is ``K_i = a_i^2 det(u_{i-1}, u_i) / 2`` (CCW positive);
* **augmentation** -- on every edge ``e_i`` an isosceles triangle is built on the
  segment ``R_i L_{i+1}`` with its apex on the perpendicular bisector and signed
  area ``(K_i + K_{i+1}) / 2``. This single signed rule is the paper's three
  cases: a convex edge gets half the sum of the two cuts on the side opposite
  the cuts, an end edge (``K = 0`` at the fixed end, Fig. 9) half the cut, an
  inflection edge the net of the two halves on the side that compensates it.
  When the two halves of an inflection edge balance (``|net| <= balance_tol``
  of the cut areas), the two-triangle construction of Fig. 11 is used instead:
  two congruent triangles on the two halves of the segment, on opposite sides,
  whose inner sides are collinear, so that long inflection edges still halve.
  Their tilt against the edge is ``tilt / 2**n`` at iteration ``n``, so the sum
  of tilts stays below ``tilt`` as section 3.2 requires; any residual net area
  is carried exactly by making the two heights differ.

The removed and added areas cancel edge by edge, so the signed area of a
closed polygon -- and for an open polyline the area between the polyline and
its chord, whose ends stay fixed -- is preserved up to rounding (relative
1e-15 in practice), for convex, non-convex and self-intersecting input.

Implementation restrictions (Definition 2, Lemma 4, section 3.2, Fig. 12)
-------------------------------------------------------------------------
With ``restrict=True`` (default) the local alphas of the profile are decreased
where needed, vertex by vertex, in a few vectorized passes:

* convex edges and end edges: Definition 2 asks for the apex ``G`` strictly
  inside the triangle ``ECD`` bounded by the extended cutting lines, with
  ``|EF| / |IF| >= c > 1``. With ``beta_i`` the half interior angle at the
  endpoints and ``gamma`` the apex half-angle, ``tan(beta_1) = |CF| / |EF|``,
  ``tan(beta_2) = |DF| / |EF|``, and the sides CG, DG meet the line EF at
  heights ``|CF| / tan(gamma)`` and ``|DF| / tan(gamma)``. The Lemma 5 proof
  uses ``|MF| <= |IF|`` with M on CG, so I lies on the extension of the other
  side and the condition reads ``tan(gamma) >= c tan(beta_i)`` for both
  endpoints -- which is also exactly "G strictly inside ECD" (``gamma > beta_i``)
  with a margin. For the end edge of Fig. 9 ``tan(gamma) / tan(beta) = |EF| / |GF|``,
  the same form. As
  ``tan(gamma) = w^2 / |A|`` for base half-width ``w`` and area ``A``, both
  endpoint alphas are scaled by ``sqrt(w^2 / (c T |A|))``, ``T = max tan(beta_i)``,
  when it fails (the very obtuse angles of Fig. 12). Scaling only decreases the
  area and widens the base, so one pass satisfies every convex edge.
* inflection edges: with ``epsilon`` the base angle of the augmenting triangle
  and ``gamma' = |tau_m| / 2`` the base angle of the cut triangle at the vertex
  ``m`` with the smaller cut (``tau`` the turning angle), the new angle at the
  cut point next to ``m`` is ``pi/2 + beta_m - epsilon`` and it exceeds the old
  ``2 beta_m`` iff ``epsilon < gamma'`` (Fig. 10). The dominant cut is decreased
  until ``epsilon <= C gamma'``, ``C < 1``, as section 3.2 prescribes. A later
  decrease of the minor cut can break that again, hence the repeated passes
  (at most ``max_passes``); edges still violating are counted in
  :class:`CCAResult`.
* at an exactly straight vertex (``tau = 0``, outside Lemma 4's hypotheses,
  where the bounding-hull wedge is empty) no restriction is imposed.
* in 3D an edge counts as convex when ``K_B . K_C > 0`` and as an inflection
  edge when ``K_B . K_C < 0``; the same bounds apply to ``|A| = |K_B + K_C| / 2``.

With the defaults ``c = 2`` (the rate ``min(2, c)`` of the Lemma 5 proof is
then 2), ``C = 1/2`` and ``min_factor = 0``, convex input with all angles < pi
stays convex and every new angle exceeds the old angle it replaces (Lemma 4);
every new edge is shorter than the edge it comes from (at most 2/3 of it;
Lemma 6). The price, visible in the ``cca`` demo: next to a nearly straight
vertex Definition 2 can only be met with a tiny cut (``K`` must vanish as
``tan(beta)`` of the neighbour blows up), so such corners stay almost uncut.
Definition 2 also asks ``alpha_i > epsilon``; ``min_factor`` is that floor, as
a fraction of the profile alpha (e.g. 0.8 smooths those corners; edges where
the floor binds are counted in :attr:`CCAResult.unsatisfied`).

alpha-profiles (section 4)
--------------------------
``alpha`` is a float in (0, 1/3), a callable of the interior angle (radians,
in [0, pi]) returning values in [0, 1/3), or ``"regular"``: the profile of
Table 1 through the control points (0, 0), (40 deg, alpha_4), (60 deg,
alpha_T), (90 deg, alpha_4), (120 deg, alpha_6), (150 deg, alpha_12),
(180 deg, (sqrt(3) - 1)/4), where ``alpha_n`` solves eq. (5) for the regular
n-gon and ``alpha_T ~ 0.24443`` is the positive root of the triangle quadratic.
The "cubic interpolation" is :class:`scipy.interpolate.PchipInterpolator`
(monotone piecewise cubic Hermite): it keeps the maximum exactly at 60 deg, as
the paper intends with its 40 deg control point, and never overshoots, so the
profile stays within [0, 0.24443].

3D polylines (section 5, Fig. 15)
---------------------------------
``(N, 3)`` input that lies in a plane (to rounding) is smoothed in 2D
coordinates of that plane, so it gives the 2D result. Otherwise the cut areas
are vectors ``K_i = a_i^2 (u_{i-1} x u_i) / 2`` and the augmenting triangle on
``B_1 C_1`` is built in the plane through the edge with normal ``K_B + K_C``,
with area ``|K_B + K_C| / 2``. When the two cut areas are equal this is exactly
the paper's plane ``P`` bisecting the half-planes ``H_1`` and ``H_2`` and the
area of the projected 2D problem (half the sum of the cut areas projected on
``P``); in general it is the area-weighted bisector, which keeps the vector
area ``1/2 sum x_i x x_{i+1}`` -- hence the signed area of the projection on
every plane -- exactly invariant, and which reduces to the 2D rule (net area
at inflections) for coplanar half-planes. Fig. 11 is 2D only (the paper:
"the concept of an inflection edge is meaningless" in 3D).

Input handling and numerics
---------------------------
Consecutive duplicate points are removed first (an anchor on a removed copy
moves to the kept one); fewer than 3 (closed) or 2 (open) distinct points
raise :class:`~curvesmith.errors.CurveError`. The work is done relative to the
first vertex; fixed vertices (ends, anchors) are returned bit-exact. Zero-length
edges created on the way (spikes) are compacted; nothing divides by zero.
Every step is a fixed sequence of whole-array numpy operations (no loop per
vertex); the restriction passes after the first touch only the edges next to
vertices just decreased. Steps over 65536 or more 2D vertices run in blocks of
32768 vertices with halos (the step is local, so the result is the same to the
last bit), which keeps the temporaries in the processor's cache, and the blocks
run in ``workers`` threads. The counts of :class:`CCAResult` are exact: an edge
whose decrease is stopped by the ``min_factor`` floor stays counted as
unsatisfied while other vertices still move.

Vertex count
------------
Per step a closed n-gon becomes a 3n-gon; an open polyline with N vertices
becomes one with ``3N - 3`` (both ends kept, an apex on each of the N - 1
edges, two cut points at each of the N - 2 inner vertices). Every interior
anchor emits one point instead of two (closed: ``3N - k`` for k anchors), every
Fig. 11 edge one more, and a vertex whose cut length is zero (alpha = 0, e.g.
the regular profile at a 0 angle) one point instead of two.

Paper typos found while verifying (scratch scripts, then the tests)
-------------------------------------------------------------------
* Section 4 says eq. (5) holds "for every pi/6 <= beta < pi"; beta is a half
  interior angle, so the range is ``pi/6 <= beta < pi/2`` (at pi/2 eq. (5) has
  the limit ``8 alpha^2 + 4 alpha - 1 = 0``, checked).
* Proof of Lemma 4: "G is strictly interior to triangle GCD" should read ECD.
* Proof of Lemma 2: "pi(E) and pi(F) are internal to AB and AC" should read
  AB and BC.
* Eq. (5) itself is right: its small root ``1 / (2 + sqrt(2 tan(gamma) sin(2 beta)))``
  turns the square into a regular 12-gon (all edges equal to 1e-15) and gives
  every apex of a regular n-gon the half-angle ``gamma = (beta + pi)/3`` of
  eq. (4) (checked by an independent construction in the tests); the triangle
  root 0.2444296 gives a 9-gon of aspect ratio 1.000000 as claimed.
"""

from __future__ import annotations

import contextvars
import math
import os
from collections import deque
from collections.abc import Callable, Sequence
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from functools import lru_cache
from itertools import islice

import numpy as np

from ._validate import MAX_VERTICES, as_bool, as_float, as_int, as_points, check_growth
from .errors import CurveError

__all__ = [
    "LIMIT_ALPHA",
    "TRIANGLE_ALPHA",
    "CCAResult",
    "alpha_profile",
    "profile_nodes",
    "regular_alpha",
    "smooth",
    "smooth_with_info",
    "solve_regular_alpha",
]

#: Limit of eq. (5) as the half-angle tends to pi/2: root of 8 a^2 + 4 a - 1 = 0.
LIMIT_ALPHA: float = (math.sqrt(3.0) - 1.0) / 4.0


def _triangle_alpha() -> float:
    # (3 sqrt3 - 4) a^2 + (6 - 3 sqrt3) a + sqrt3 - 2 = 0, positive root (section 4).
    s3 = math.sqrt(3.0)
    qa, qb, qc = 3.0 * s3 - 4.0, 6.0 - 3.0 * s3, s3 - 2.0
    return (2.0 * qc) / (-qb - math.sqrt(qb * qb - 4.0 * qa * qc))


#: alpha for the equilateral triangle (9-gon of aspect ratio 1), section 4: ~0.24443.
TRIANGLE_ALPHA: float = _triangle_alpha()


def solve_regular_alpha(beta):
    """Solve eq. (5) for alpha given the half interior angle ``beta``.

    Eq. (5), ``(4 - 2 tan(gamma) sin(2 beta)) alpha^2 - 4 alpha + 1 = 0`` with
    ``gamma = (beta + pi) / 3`` (eq. (4)), chooses alpha so that one CCA1 step
    of a regular n-gon with half-angle ``beta`` gives apexes with the half-angle
    ``gamma`` of a regular 3n-gon. The root in (0, 1/2) is evaluated in the
    cancellation-free form ``1 / (2 + sqrt(2 tan(gamma) sin(2 beta)))``; at
    ``beta = pi/2`` it is the limit ``(sqrt(3) - 1) / 4`` of ``8 a^2 + 4 a - 1 = 0``.

    Parameters
    ----------
    beta : float or array_like
        Half interior angle(s) in radians, ``pi/6 <= beta <= pi/2``.

    Returns
    -------
    float or ndarray
        alpha, same shape as `beta`.

    Examples
    --------
    >>> round(float(solve_regular_alpha(np.pi / 4)), 6)  # square
    0.211325
    >>> round(float(solve_regular_alpha(np.pi / 2)), 7)  # limit
    0.1830127
    """
    b = np.asarray(beta, dtype=float)
    if not np.all(np.isfinite(b)) or np.any(b < np.pi / 6 - 1e-12) or np.any(b > np.pi / 2):
        raise CurveError(f"beta must be in [pi/6, pi/2], got {np.asarray(beta).tolist()}")
    x = np.pi / 2 - b  # gamma = pi/2 - x/3, so tan(gamma) = 1/tan(x/3); sin(2 beta) = sin(2x)
    with np.errstate(divide="ignore", invalid="ignore"):
        prod = np.where(x > 0, np.sin(2 * x) / np.tan(x / 3), 6.0)
    out = 1.0 / (2.0 + np.sqrt(2.0 * prod))
    return float(out) if out.ndim == 0 else out


def regular_alpha(n: int) -> float:
    """Return alpha of eq. (5) for the regular n-gon (``beta = pi (n - 2) / (2 n)``).

    Parameters
    ----------
    n : int
        Number of edges, >= 3.

    Returns
    -------
    float
        For n = 3 this is eq. (5)'s 0.23915, which the paper rejects for the
        triangle in favour of :data:`TRIANGLE_ALPHA` (used by the profile).

    Examples
    --------
    >>> [round(regular_alpha(n), 6) for n in (4, 6, 12)]
    [0.211325, 0.194774, 0.185845]
    >>> round(regular_alpha(3), 5)
    0.23915
    """
    n = as_int(n, name="n", minimum=3)
    return float(solve_regular_alpha(np.pi * (n - 2) / (2 * n)))


def profile_nodes() -> tuple[np.ndarray, np.ndarray]:
    """Control points of the ``"regular"`` alpha-profile (Table 1).

    Returns
    -------
    angles : (7,) ndarray
        Interior angles in radians: 0, 40, 60, 90, 120, 150, 180 degrees.
    alphas : (7,) ndarray
        0, alpha_4, :data:`TRIANGLE_ALPHA`, alpha_4, alpha_6, alpha_12,
        :data:`LIMIT_ALPHA` (alpha_n from eq. (5)).

    Examples
    --------
    >>> np.round(profile_nodes()[1], 6).tolist()
    [0.0, 0.211325, 0.24443, 0.211325, 0.194774, 0.185845, 0.183013]
    """
    deg = np.array([0.0, 40.0, 60.0, 90.0, 120.0, 150.0, 180.0])
    a4 = regular_alpha(4)
    vals = np.array([0.0, a4, TRIANGLE_ALPHA, a4, regular_alpha(6), regular_alpha(12), LIMIT_ALPHA])
    return np.deg2rad(deg), vals


@lru_cache(maxsize=1)
def _profile_poly():
    from scipy.interpolate import PchipInterpolator

    x, y = profile_nodes()
    p = PchipInterpolator(x, y, extrapolate=False)
    return p.x.copy(), p.c.copy()


def _eval_profile(theta: np.ndarray) -> np.ndarray:
    # Evaluate scipy's PCHIP piecewise cubic (its breakpoints and coefficients) by Horner.
    # Smoothed curves have almost all angles in the last piece (150..180 deg): that piece is
    # evaluated with scalar coefficients for every angle, the others are redone on their
    # (few) angles -- the same floating-point operations as the general path.
    theta = np.asarray(theta, dtype=float)
    brk, coef = _profile_poly()
    if theta.ndim == 0 or theta.size < 64:
        return _eval_profile_pieces(theta)
    dt = theta - brk[-2]
    c = coef[:, -1]
    out = np.multiply(dt, c[0])
    for k in (1, 2, 3):
        out += c[k]
        if k < 3:
            out *= dt
    rest = np.flatnonzero(theta <= brk[-2])
    if rest.size:
        out[rest] = _eval_profile_pieces(theta[rest])
    return out


def _eval_profile_pieces(theta: np.ndarray) -> np.ndarray:
    # np.take on the 6 pieces is about twice as fast as PPoly.__call__ on large arrays. The
    # piece index is the number of inner breakpoints below theta (searchsorted, side="left"),
    # counted by five comparisons: about three times faster than a binary search per angle.
    brk, coef = _profile_poly()
    if theta.ndim == 0:
        idx = np.searchsorted(brk[1:-1], theta, side="left")
    else:
        idx = np.zeros(theta.shape, dtype=np.intp)
        for b in brk[1:-1]:
            idx += theta > b
    dt = theta - brk.take(idx)
    out = coef[0].take(idx)
    for k in (1, 2, 3):
        out *= dt
        out += coef[k].take(idx)
    return out


def alpha_profile(angle):
    """The ``"regular"`` alpha-profile of section 4 (Table 1, Fig. 14).

    Monotone cubic (PCHIP, :class:`scipy.interpolate.PchipInterpolator`)
    interpolation through :func:`profile_nodes`.

    Parameters
    ----------
    angle : float or array_like
        Interior angle(s) in radians, in [0, pi].

    Returns
    -------
    float or ndarray
        alpha in [0, :data:`TRIANGLE_ALPHA`], same shape as `angle`.

    Examples
    --------
    >>> round(float(alpha_profile(np.pi / 2)), 6)
    0.211325
    >>> round(float(alpha_profile(np.pi)), 7)
    0.1830127
    """
    a = np.asarray(angle, dtype=float)
    if not np.all(np.isfinite(a)) or np.any(a < 0) or np.any(a > np.pi * (1 + 1e-15)):
        raise CurveError(f"angle must be in [0, pi] radians, got {np.asarray(angle).tolist()}")
    out = _eval_profile(a)
    return float(out) if out.ndim == 0 else out


@dataclass(frozen=True)
class CCAResult:
    """Result of :func:`smooth_with_info`.

    Attributes
    ----------
    points : (M, d) ndarray
        The smoothed polygon or polyline (same as :func:`smooth` returns).
    iterations : int
        Number of CCA1 steps performed.
    reductions : int
        Total number of local alpha decreases (vertices whose profile alpha was
        lowered by the restrictions), summed over all steps.
    reductions_per_step : tuple of int
        The same, per step.
    fig11_edges : int
        Number of balanced inflection edges treated with the two-triangle
        construction of Fig. 11, summed over all steps.
    unsatisfied : int
        Number of edges (summed over steps) where the restrictions do not hold
        in the end: not met within ``max_passes`` passes, or the
        ``min_factor`` floor stopped the decrease; 0 means every restriction held.
    success : bool
        ``unsatisfied == 0``. The area is preserved either way.
    message : str
        Human-readable summary.
    """

    points: np.ndarray
    iterations: int
    reductions: int
    reductions_per_step: tuple[int, ...]
    fig11_edges: int
    unsatisfied: int
    success: bool
    message: str


AlphaSpec = str | float | Callable[[np.ndarray], object]


def smooth(
    points,
    *,
    closed: bool,
    iterations: int = 1,
    alpha: AlphaSpec = "regular",
    anchors: Sequence[int] | None = None,
    c: float = 2.0,
    C: float = 0.5,
    restrict: bool = True,
    tilt: float = np.pi / 8,
    balance_tol: float = 1e-9,
    max_passes: int = 16,
    min_factor: float = 0.0,
    workers: int | None = None,
) -> np.ndarray:
    """Area-preserving CCA1 smoothing of a polygon or polyline (Gordon 2010).

    Parameters
    ----------
    points : (N, 2) or (N, 3) array_like
        Vertices as rows. With ``closed=True`` a repeated closing vertex is
        dropped. Consecutive duplicate points are removed first (anchors on a
        removed duplicate move to the kept copy).
    closed : bool
        Closed polygon (signed area preserved) or open polyline (ends fixed,
        area between polyline and chord preserved).
    iterations : int, optional
        Number of CCA1 steps, >= 0.
    alpha : "regular", float or callable, optional
        alpha-profile (section 4): ``"regular"`` (Table 1, PCHIP), a constant
        in (0, 1/3), or a function of the interior angle in radians (array in,
        array out; values in [0, 1/3)). The function must act angle by angle:
        long curves are smoothed in blocks, possibly in several threads at once
        (see `workers`), so it is called on pieces of the angle array.
    anchors : sequence of int, optional
        Indices of input vertices that stay fixed (section 5); the pieces between
        anchors are smoothed as independent polylines, each keeping its area
        against its chord.
    c : float, optional
        Constant ``c > 1`` of Definition 2 (``tan(gamma) >= c tan(beta)``).
    C : float, optional
        Constant ``0 < C < 1`` of section 3.2 (``epsilon <= C gamma`` at
        inflection edges).
    restrict : bool, optional
        Apply the restrictions (local alpha decrease). False gives plain CCA1
        with the profile's alphas.
    tilt : float, optional
        Bound (radians, in (0, pi/4]) on the summed tilts of Fig. 11 edges; the
        tilt at step n is ``tilt / 2**n`` (with ``restrict``, at most ``C`` times
        the smaller half turning angle).
    balance_tol : float, optional
        Inflection edges whose net cut area is at most this fraction of the
        mean cut area count as balanced and get the Fig. 11 construction (2D).
    max_passes : int, optional
        Maximum number of restriction passes per step.
    min_factor : float, optional
        Floor of the local decrease, in [0, 1): a restricted alpha never drops
        below ``min_factor`` times the profile's alpha (the ``epsilon < alpha_i``
        of Definition 2). With the default 0 the restrictions are always met, at
        the price of almost uncut corners next to nearly straight vertices
        (Fig. 12); a floor such as 0.5 keeps those corners smoothing, and edges
        where it binds are counted in :attr:`CCAResult.unsatisfied`.
    workers : int, optional
        Threads for long 2D curves: a step over at least 65536 vertices runs in
        blocks of 32768 (with halos; the result does not depend on the blocks
        or the threads), and ``workers`` blocks at a time. Default: the number
        of processors available to this process, at most 4 and at most
        ``OMP_NUM_THREADS`` when that is set (Dask workers set it to 1); 1 for
        no threads.

    Returns
    -------
    (M, d) ndarray
        The smoothed vertices (see the module notes for M).

    Raises
    ------
    CurveError
        Bad shape or values, fewer than 3 (closed) or 2 (open) distinct points,
        parameters out of range, anchors out of range.

    Examples
    --------
    >>> sq = [[0, 0], [1, 0], [1, 1], [0, 1]]
    >>> out = smooth(sq, closed=True, iterations=2)
    >>> out.shape
    (36, 2)
    >>> from curvesmith.geometry import signed_area
    >>> round(signed_area(out), 12)
    1.0
    """
    return smooth_with_info(
        points,
        closed=closed,
        iterations=iterations,
        alpha=alpha,
        anchors=anchors,
        c=c,
        C=C,
        restrict=restrict,
        tilt=tilt,
        balance_tol=balance_tol,
        max_passes=max_passes,
        min_factor=min_factor,
        workers=workers,
    ).points


def smooth_with_info(
    points,
    *,
    closed: bool,
    iterations: int = 1,
    alpha: AlphaSpec = "regular",
    anchors: Sequence[int] | None = None,
    c: float = 2.0,
    C: float = 0.5,
    restrict: bool = True,
    tilt: float = np.pi / 8,
    balance_tol: float = 1e-9,
    max_passes: int = 16,
    min_factor: float = 0.0,
    workers: int | None = None,
) -> CCAResult:
    """Like :func:`smooth`, returning a :class:`CCAResult` with restriction counts.

    Parameters
    ----------
    points, closed, iterations, alpha, anchors, c, C, restrict, tilt, balance_tol
        As in :func:`smooth`.
    max_passes, min_factor, workers
        As in :func:`smooth`.

    Returns
    -------
    CCAResult

    Examples
    --------
    A nearly straight vertex next to a sharp corner forces a local decrease
    (Fig. 12):

    >>> res = smooth_with_info([[0, 0], [4, 0], [4.0, 1], [2, 1.01], [0, 1]], closed=True)
    >>> res.reductions > 0, res.success
    (True, True)
    """
    closed = as_bool(closed, name="closed")
    iterations = as_int(iterations, name="iterations", minimum=0)
    c = as_float(c, name="c", low=1.0)
    C = as_float(C, name="C", low=0.0, high=1.0)
    tilt = as_float(tilt, name="tilt", low=0.0, high=np.pi / 4, high_open=False)
    balance_tol = as_float(balance_tol, name="balance_tol", low=0.0, high=1.0, low_open=False)
    max_passes = as_int(max_passes, name="max_passes", minimum=1)
    min_factor = as_float(min_factor, name="min_factor", low=0.0, high=1.0, low_open=False)
    workers = _default_workers() if workers is None else as_int(workers, name="workers", minimum=1)
    alpha_fn = _alpha_function(alpha)
    raw = as_points(points, closed=closed, min_points=1, dim=(2, 3))
    # Coordinates so small or so large that squared edge lengths would underflow or overflow
    # are scaled by a power of two (exact) and scaled back at the end; CCA1 commutes with it.
    top = float(np.abs(raw).max())
    exp2 = math.frexp(top)[1] if top > 0 and not _TINY < top < _HUGE else 0
    if exp2:
        raw = np.ldexp(raw, -exp2)
    n_in = raw.shape[0]
    fixed = np.zeros(n_in, dtype=bool)
    if anchors is not None:
        # a closed ring given with its closing vertex repeated may name that last index
        repeated = closed and np.shape(points)[0] == n_in + 1
        idx = _anchor_indices(anchors, n_in + 1 if repeated else n_in)
        fixed[idx % n_in] = True
    if not closed:
        fixed[0] = fixed[-1] = True
    p, fixed = _dedupe(raw, fixed, closed)
    need = 3 if closed else 2
    if p.shape[0] < need:
        raise CurveError(
            f"points must have at least {need} distinct points for a "
            f"{'closed polygon' if closed else 'polyline'} after removing consecutive "
            f"duplicates, got {p.shape[0]}"
        )
    # _dedupe leaves consecutive vertices distinct, so "all identical" shows in p[0], p[1]
    if closed and not np.any(p[1] != p[0]):
        raise CurveError("points are all identical: a polygon needs non-zero extent")

    if iterations == 0:
        out = np.ldexp(p, exp2) if exp2 else p
        return CCAResult(out, 0, 0, (), 0, 0, True, "0 CCA1 steps: input returned")
    # every step triples the vertex count (closed 3n, open 3n - 3, Fig. 11 edges one more)
    check_growth(p.shape[0], iterations, lambda n: 3 * n, limit=MAX_VERTICES)
    fixed_in = fixed
    origin = p[0].copy()
    q = p - origin
    frame = None
    if q.shape[1] == 3:
        frame = _plane_frame(q)
        if frame is not None:
            q = q @ frame.T  # (N, 2) coordinates in the plane
    cols = [np.ascontiguousarray(q[:, k]) for k in range(q.shape[1])]

    red_steps: list[int] = []
    fig11_total = 0
    unsat_total = 0
    for it in range(1, iterations + 1):
        step = _step_cols if len(cols) == 3 or _FORCE_GENERIC else _step2_cols
        last = it == iterations and frame is None and len(cols) == 2
        cols, fixed, nred, nfig, nunsat, stacked = step(
            cols,
            fixed,
            closed,
            alpha_fn,
            restrict,
            c,
            C,
            tilt / 2.0**it,
            balance_tol,
            (max_passes, min_factor),
            stacked=(float(origin[0]), float(origin[1])) if last else None,
            workers=workers,
        )
        red_steps.append(nred)
        fig11_total += nfig
        unsat_total += nunsat

    if stacked is None:
        out = np.column_stack(cols)
        if frame is not None:
            out = out @ frame
        out += origin
    else:
        out = stacked  # the last step added the origin on writing
    if fixed_in.any():
        out[fixed] = p[fixed_in]  # fixed vertices (ends, anchors) are returned bit-exact
    if exp2:
        np.ldexp(out, exp2, out=out)
    ok = unsat_total == 0
    msg = (
        f"{iterations} CCA1 step(s), {sum(red_steps)} local alpha reduction(s), "
        f"{fig11_total} Fig. 11 edge(s)"
        + ("" if ok else f"; restrictions not met on {unsat_total} edge(s)")
    )
    return CCAResult(
        points=out,
        iterations=iterations,
        reductions=int(sum(red_steps)),
        reductions_per_step=tuple(red_steps),
        fig11_edges=int(fig11_total),
        unsatisfied=int(unsat_total),
        success=ok,
        message=msg,
    )


# --------------------------------------------------------------------------- input helpers


def _default_workers() -> int:
    """Processors available to this process, at most 4 and at most ``OMP_NUM_THREADS``.

    The environment cap follows the convention of numerical libraries (Dask's
    worker processes set ``OMP_NUM_THREADS=1``), so a parallel caller does not
    get threads inside each of its workers.
    """
    try:
        available = len(os.sched_getaffinity(0))
    except (AttributeError, OSError):  # not on Linux
        available = os.cpu_count() or 1
    cap = os.environ.get("OMP_NUM_THREADS", "").strip()
    if cap.isdigit() and int(cap) >= 1:
        available = min(available, int(cap))
    return max(1, min(4, available))


def _alpha_function(alpha) -> Callable[[np.ndarray], np.ndarray]:
    if isinstance(alpha, str):
        if alpha != "regular":
            raise CurveError(
                f"alpha must be 'regular', a float in (0, 1/3) or a callable, got {alpha!r}"
            )
        return _eval_profile
    if callable(alpha):
        return _wrap_callable(alpha)
    value = as_float(alpha, name="alpha", low=0.0, high=1.0 / 3.0)

    def const(theta: np.ndarray) -> np.ndarray:
        return np.full(theta.shape, value)

    const.constant = value  # type: ignore[attr-defined]
    return const


def _wrap_callable(fn) -> Callable[[np.ndarray], np.ndarray]:
    def wrapped(theta: np.ndarray) -> np.ndarray:
        try:
            out = np.asarray(fn(theta), dtype=float)
        except (TypeError, ValueError):
            out = None
        if out is None or out.shape not in (theta.shape, ()):
            # not vectorized: evaluate per angle
            try:
                out = np.array([float(fn(float(t))) for t in theta], dtype=float)
            except (TypeError, ValueError) as exc:
                raise CurveError(f"alpha callable failed on an angle: {exc}") from None
        out = np.broadcast_to(out, theta.shape).astype(float)
        bad = ~(np.isfinite(out) & (out >= 0) & (out < 1.0 / 3.0))
        if bad.any():
            k = int(np.flatnonzero(bad)[0])
            raise CurveError(
                f"alpha(angle) must be in [0, 1/3), got {float(out[k])!r} at angle "
                f"{float(theta[k])!r} rad"
            )
        return out

    return wrapped


def _anchor_indices(anchors, n: int) -> np.ndarray:
    try:
        idx = np.asarray(anchors)
    except (TypeError, ValueError):
        raise CurveError(f"anchors must be a sequence of vertex indices, got {anchors!r}") from None
    idx = idx.reshape(-1)
    if idx.size and not (
        np.issubdtype(idx.dtype, np.integer)
        or (np.issubdtype(idx.dtype, np.floating) and np.all(np.mod(idx, 1) == 0))
    ):
        raise CurveError(f"anchors must be integer vertex indices, got {anchors!r}")
    idx = idx.astype(np.intp)
    bad = (idx < 0) | (idx >= n)
    if bad.any():
        raise CurveError(f"anchors must be vertex indices in [0, {n}), got {int(idx[bad][0])}")
    return idx


def _zero_gap(d: np.ndarray) -> np.ndarray:
    """Rows of differences whose squared length is 0 as the steps compute it.

    True for equal points and for points so close that every squared component
    underflows (``|d| < 1.5e-162``): the step would see a zero-length edge, so
    both count as duplicates (otherwise compacting could not remove the edge).
    """
    return ~np.any(d * d > 0, axis=1)


def _dedupe(p: np.ndarray, fixed: np.ndarray, closed: bool) -> tuple[np.ndarray, np.ndarray]:
    same = _zero_gap(p[1:] - p[:-1])
    if closed and p.shape[0] > 1:
        # drop trailing copies of the first vertex too
        tail = _zero_gap(p - p[0])
        tail[0] = False
        k = p.shape[0]
        while k > 1 and tail[k - 1]:
            k -= 1
        if k < p.shape[0]:
            fixed = fixed.copy()
            fixed[0] |= fixed[k:].any()
            p, fixed = p[:k], fixed[:k]
            same = same[: k - 1]
    if not same.any():
        return p, fixed
    keep = np.ones(p.shape[0], dtype=bool)
    keep[1:] = ~same
    group = np.cumsum(keep) - 1
    newfixed = np.zeros(int(group[-1]) + 1, dtype=bool)
    np.logical_or.at(newfixed, group, fixed)
    return p[keep], newfixed


def _plane_frame(q: np.ndarray) -> np.ndarray | None:
    """Orthonormal (2, 3) in-plane frame if the 3D points are planar to rounding, else None."""
    centred = q - q.mean(axis=0)
    _, _, vt = np.linalg.svd(centred, full_matrices=False)
    extent = float(np.max(np.abs(centred))) if centred.size else 0.0
    if extent == 0.0:
        return vt[:2].copy()
    dist = np.abs(centred @ vt[2])
    if float(dist.max()) <= 64.0 * np.finfo(float).eps * extent:
        return vt[:2].copy()
    return None


# --------------------------------------------------------------------------- the CCA1 step


_FORCE_GENERIC = False  # tests compare the lean 2D step with the generic one


def _step2_cols(cols, fixed, closed, *args, stacked=None, workers=1):
    x, y, fixed, nred, nfig, nunsat, xy = _step2_blocked(
        cols[0], cols[1], fixed, closed, *args, stacked=stacked, workers=workers
    )
    return [x, y], fixed, nred, nfig, nunsat, xy


def _step_cols(*args, stacked=None, workers=1):
    return (*_step(*args), None)


_SHRINK = 1.0 - 8.0 * np.finfo(float).eps
#: Coordinates outside (_TINY, _HUGE) in absolute value are rescaled by a power of two.
_TINY, _HUGE = 2.0**-400, 2.0**400


def _roll_m1(a: np.ndarray) -> np.ndarray:
    """a[i+1] (cyclic)."""
    out = np.empty_like(a)
    out[:-1] = a[1:]
    out[-1] = a[0]
    return out


def _roll_p1(a: np.ndarray) -> np.ndarray:
    """a[i-1] (cyclic)."""
    out = np.empty_like(a)
    out[1:] = a[:-1]
    out[0] = a[-1]
    return out


def _compact(cols, fixed, closed):
    p = np.column_stack(cols)
    p, fixed = _dedupe(p, fixed, closed)
    return [np.ascontiguousarray(p[:, k]) for k in range(p.shape[1])], fixed


def _step(cols, fixed, closed, alpha_fn, restrict, c, C, tilt_n, balance_tol, limits):
    d = len(cols)
    e = [_roll_m1(x) - x for x in cols]  # edge i: V_i -> V_{i+1} (wrap edge absent if open)
    length = np.sqrt(sum(ek * ek for ek in e))
    if np.any(length[: (None if closed else -1)] == 0):
        cols, fixed = _compact(cols, fixed, closed)
        e = [_roll_m1(x) - x for x in cols]
        length = np.sqrt(sum(ek * ek for ek in e))
    n = length.shape[0]
    edge_on = np.ones(n, dtype=bool)
    if not closed:
        edge_on[-1] = False
        fixed = fixed.copy()
        fixed[0] = fixed[-1] = True
    pos = length > 0
    inv = np.divide(1.0, length, out=np.zeros(n), where=pos)
    u = [ek * inv for ek in e]
    up = [_roll_p1(uk) for uk in u]
    len_prev = _roll_p1(length)

    # turn at every vertex: cross(u_{i-1}, u_i) (scalar in 2D, vector in 3D) and dot
    if d == 2:
        cr = [up[0] * u[1] - up[1] * u[0]]
        scross = np.abs(cr[0])
    else:
        cr = [
            up[1] * u[2] - up[2] * u[1],
            up[2] * u[0] - up[0] * u[2],
            up[0] * u[1] - up[1] * u[0],
        ]
        scross = np.sqrt(cr[0] ** 2 + cr[1] ** 2 + cr[2] ** 2)
    dot = sum(a * b for a, b in zip(up, u, strict=True))
    theta = np.arctan2(scross, -dot)  # interior angle in [0, pi]
    free = ~fixed
    alpha = np.zeros(n)
    alpha[free] = alpha_fn(theta[free])
    short = np.minimum(length, len_prev)
    half_a2 = 0.5 * short * short  # K_i = alpha_i^2 * half_a2_i * cross_i

    nred = 0
    nunsat = 0
    if restrict:
        alpha, nred, nunsat, _, _ = _restrict(
            alpha, half_a2, cr, scross, dot, short, length, fixed, edge_on, c, C, limits
        )

    a = alpha * short
    kfac = alpha * alpha * half_a2
    K = [kfac * ck for ck in cr]  # signed / vector cut areas
    K1 = K
    K2 = [_roll_m1(k) for k in K]
    A = [0.5 * (k1 + k2) for k1, k2 in zip(K1, K2, strict=True)]  # augmentation per edge
    a_next = _roll_m1(a)
    w = 0.5 * (length - a - a_next)
    wpos = w > 0
    winv = np.divide(1.0, w, out=np.zeros(n), where=wpos)

    # cut points
    Lp = [x - a * uk for x, uk in zip(cols, up, strict=True)]
    Rp = [x + a * uk for x, uk in zip(cols, u, strict=True)]
    Lnext = [_roll_m1(lk) for lk in Lp]
    M = [0.5 * (r + ln) for r, ln in zip(Rp, Lnext, strict=True)]
    # apex offset = cross(u, A) / w
    if d == 2:
        s = A[0] * winv
        G = [M[0] + s * u[1], M[1] - s * u[0]]
    else:
        G = [
            M[0] + (u[1] * A[2] - u[2] * A[1]) * winv,
            M[1] + (u[2] * A[0] - u[0] * A[2]) * winv,
            M[2] + (u[0] * A[1] - u[1] * A[0]) * winv,
        ]

    # Fig. 11: balanced inflection edges (2D)
    fig = np.zeros(n, dtype=bool)
    if d == 2:
        k1, k2 = K1[0], K2[0]
        mag = np.abs(k1) + np.abs(k2)
        fig = edge_on & (k1 * k2 < 0) & (np.abs(k1 + k2) <= balance_tol * 0.5 * mag) & wpos
    nfig = int(np.count_nonzero(fig))
    if nfig:
        i = np.flatnonzero(fig)
        s1 = np.sign(K1[0][i])
        phi = np.full(i.size, tilt_n)
        if restrict:
            tau1 = np.arctan2(scross[i], dot[i])
            j = (i + 1) % n
            tau2 = np.arctan2(scross[j], dot[j])
            phi = np.minimum(phi, C * 0.5 * np.minimum(tau1, tau2))
        wi = w[i]
        hb = 0.5 * wi * np.tan(phi)
        carry = s1 * A[0][i] / wi
        h1, h2 = hb + carry, hb - carry
        ux, uy = u[0][i], u[1][i]
        Mx, My = M[0][i], M[1][i]
        Rx, Ry = Rp[0][i], Rp[1][i]
        Lx, Ly = Lnext[0][i], Lnext[1][i]
        q1x, q1y = 0.5 * (Rx + Mx), 0.5 * (Ry + My)
        q2x, q2y = 0.5 * (Mx + Lx), 0.5 * (My + Ly)
        # right normal (uy, -ux); first apex on side s1 (opposite the cut at V_i)
        apx = q1x + s1 * h1 * uy
        apy = q1y - s1 * h1 * ux
        bpx = q2x - s1 * h2 * uy
        bpy = q2y + s1 * h2 * ux

    # assemble: vertex i -> [L_i, R_i] (or [V_i] if fixed / uncut), edge i -> [G_i] or [A', B']
    single = fixed | (a == 0)
    cnt_v = np.where(single, 1, 2)
    cnt_e = edge_on.astype(np.intp) + fig
    cnt = cnt_v + cnt_e
    start = np.cumsum(cnt) - cnt
    total = int(start[-1] + cnt[-1]) if n else 0
    out = [np.empty(total) for _ in range(d)]
    two = ~single
    s_first = start
    s_second = start[two] + 1
    s_edge = (start + cnt_v)[edge_on]
    for k in range(d):
        first = np.where(single, cols[k], Lp[k])
        out[k][s_first] = first
        out[k][s_second] = Rp[k][two]
        out[k][s_edge] = G[k][edge_on]
    if nfig:
        se = start[i] + cnt_v[i]
        out[0][se] = apx
        out[1][se] = apy
        out[0][se + 1] = bpx
        out[1][se + 1] = bpy
    newfixed = np.zeros(total, dtype=bool)
    newfixed[start[fixed]] = True
    return out, newfixed, nred, nfig, nunsat


def _ext(n: int) -> np.ndarray:
    """Buffer of n + 1 slots: ``b[:-1]`` is a[i] and ``b[1:]`` is a[i+1] once ``b[n] = b[0]``."""
    return np.empty(n + 1)


class _NeedsWholeStep(Exception):
    """A block of :func:`_step2_blocked` has zero-length edges: the whole step compacts."""


def _step2(
    x, y, fixed, closed, alpha_fn, restrict, c, C, tilt_n, balance_tol, limits, stacked, core=None
):
    """One 2D CCA1 step on coordinate columns; the same arithmetic as :func:`_step`, leaner.

    Cyclic neighbours are views into buffers of ``n + 1`` slots whose extra slot
    repeats the wrapped element (``u_{i-1}`` is ``ux_e[:-1]`` when ``ux_e[1:]``
    holds ``u_i``), so no shifted copies are made; the restriction pass hands
    back the edge terms it computed, and buffers that are dead are reused (a
    fresh large array costs its page faults). With ``stacked = (ox, oy)`` (the
    last step) the output is written into one ``(M, 2)`` array, with the origin
    added on writing -- the same ``value + origin`` rounding as adding it later
    -- and its columns are returned (no later stacking, no extra pass).

    With ``core = (lo, hi)`` the columns are one block of :func:`_step2_blocked`
    (its core vertices ``lo .. hi - 1`` and halos): the counts cover the core
    only, and the last item returned is the slice ``(start, stop)`` of the
    output that comes from the core (otherwise None).
    """
    n = x.shape[0]
    ex = np.empty(n)
    np.subtract(x[1:], x[:-1], out=ex[:-1])
    ex[-1] = x[0] - x[-1]
    ey = np.empty(n)
    np.subtract(y[1:], y[:-1], out=ey[:-1])
    ey[-1] = y[0] - y[-1]
    len_e = _ext(n)
    length = len_e[1:]
    tmp = np.multiply(ey, ey)
    np.multiply(ex, ex, out=length)
    length += tmp
    np.sqrt(length, out=length)
    body = length if closed else length[:-1]
    if body.size and body.min() == 0:
        if core is not None:
            raise _NeedsWholeStep
        (x, y), fixed = _compact([x, y], fixed, closed)
        args = (alpha_fn, restrict, c, C, tilt_n, balance_tol, limits, stacked)
        return _step2(x, y, fixed, closed, *args)
    if closed:
        edge_on = None
    else:
        edge_on = np.ones(n, dtype=bool)
        edge_on[-1] = False
        fixed = fixed.copy()
        fixed[0] = fixed[-1] = True
        length[-1] = max(float(length[-1]), 1.0)  # absent wrap edge: only guard the divisions
    len_e[0] = length[-1]
    inv = np.divide(1.0, length, out=tmp)
    ux_e = _ext(n)
    uy_e = _ext(n)
    ux, uy = ux_e[1:], uy_e[1:]
    np.multiply(ex, inv, out=ux)
    np.multiply(ey, inv, out=uy)
    ux_e[0] = ux[-1]
    uy_e[0] = uy[-1]
    upx, upy = ux_e[:-1], uy_e[:-1]
    del inv
    cr = np.multiply(upx, uy, out=ex)  # cross(u_{i-1}, u_i) = sin(turning angle)
    cr -= np.multiply(upy, ux, out=tmp)
    dot = np.multiply(upx, ux, out=ey)
    dot += np.multiply(upy, uy, out=tmp)
    del ex, ey
    scross = np.abs(cr)
    any_fixed = bool(fixed.any())
    constant = getattr(alpha_fn, "constant", None)
    if constant is not None:  # constant alpha: no angles needed
        alpha = np.full(n, constant)
        alpha[fixed] = 0.0
    elif any_fixed:
        alpha = np.zeros(n)
        free = ~fixed
        alpha[free] = alpha_fn(np.arctan2(scross[free], -dot[free]))
    else:
        alpha = alpha_fn(np.arctan2(scross, np.negative(dot, out=tmp)))  # interior angle
    del tmp
    short = np.minimum(length, len_e[:-1])
    half_a2 = np.multiply(short, 0.5)
    half_a2 *= short
    nred = nunsat = 0
    if restrict:
        alpha, nred, nunsat, a_e, K_e, w, A, k12 = _restrict2(
            alpha,
            half_a2,
            cr,
            scross,
            dot,
            short,
            length,
            fixed,
            any_fixed,
            edge_on,
            c,
            C,
            limits,
            core,
        )
        K = K_e[:-1]
        Kn = K_e[1:]
    else:
        a_e = _ext(n)
        np.multiply(alpha, short, out=a_e[:-1])
        a_e[n] = a_e[0]
        K_e = _ext(n)
        K = K_e[:-1]
        np.multiply(alpha, alpha, out=K)
        K *= half_a2
        K *= cr  # signed cut areas
        K_e[n] = K[0]
        Kn = K_e[1:]
        w = np.subtract(length, a_e[:-1])
        w -= a_e[1:]
        w *= 0.5
        A = np.add(K, Kn)
        k12 = np.multiply(K, Kn)
    A *= 0.5  # signed augmentation per edge
    a = a_e[:-1]

    # Fig. 11 candidates: inflection edges (opposite cut signs), usually few
    cand = np.flatnonzero(k12 < 0)
    # dead buffers reused below: k12 -> s, short/half_a2/alpha/cr -> R, G (no fresh pages)
    if w.min() > 0:
        s = np.divide(A, w, out=k12)
    else:
        s = k12
        s.fill(0.0)
        np.divide(A, w, out=s, where=w > 0)
    kc, knc = K[cand], Kn[cand]
    ok = np.abs(kc + knc) <= (0.5 * balance_tol) * (np.abs(kc) + np.abs(knc))
    ok &= w[cand] > 0
    if edge_on is not None:
        ok &= edge_on[cand]
    nfig = int(np.count_nonzero(ok))
    if core is None:
        nfig_counted = nfig
    else:
        edges_fig = cand[ok]
        nfig_counted = int(np.count_nonzero((edges_fig >= core[0]) & (edges_fig < core[1])))
    single = (a == 0) | fixed if any_fixed else a == 0
    any_single = bool(single.any())
    regular = nfig == 0 and edge_on is None and not any_single
    if regular:
        total = 3 * n
    else:
        fig = np.zeros(n, dtype=bool)
        fig[cand[ok]] = True
        on = np.ones(n, dtype=bool) if edge_on is None else edge_on
        cnt_v = np.where(single, 1, 2)
        cnt = cnt_v + on + fig
        start = np.cumsum(cnt) - cnt
        total = int(start[-1] + cnt[-1])
    if stacked is not None:  # last step: (M, 2) output with the origin added on writing
        xy = np.empty((total, 2))
        ox, oy = xy[:, 0], xy[:, 1]
        o_x, o_y = stacked
    else:
        xy = None
        ox, oy = np.empty(total), np.empty(total)

    # cut points L_i = V_i - a u_{i-1}, R_i = V_i + a u_i; apex G_i = M_i + s (uy, -ux)
    Lx_e, Ly_e = _ext(n), _ext(n)
    Lx, Ly = Lx_e[:-1], Ly_e[:-1]
    np.subtract(x, np.multiply(a, upx, out=Lx), out=Lx)
    np.subtract(y, np.multiply(a, upy, out=Ly), out=Ly)
    Lx_e[n] = Lx[0]
    Ly_e[n] = Ly[0]
    del upx, upy, ux_e, uy_e
    Rx, Ry, Gx, Gy = short, half_a2, alpha, cr
    del short, half_a2, alpha, cr
    np.add(x, np.multiply(a, ux, out=Rx), out=Rx)
    np.add(y, np.multiply(a, uy, out=Ry), out=Ry)
    np.add(Lx_e[1:], Rx, out=Gx)
    Gx *= 0.5
    tmp = np.multiply(s, uy, out=w if nfig == 0 else None)
    Gx += tmp
    np.add(Ly_e[1:], Ry, out=Gy)
    Gy *= 0.5
    Gy -= np.multiply(s, ux, out=s)
    del s, tmp
    if regular:  # layout [L_i, R_i, G_i]
        if stacked is not None:
            np.add(Lx, o_x, out=ox[0::3])
            np.add(Rx, o_x, out=ox[1::3])
            np.add(Gx, o_x, out=ox[2::3])
            np.add(Ly, o_y, out=oy[0::3])
            np.add(Ry, o_y, out=oy[1::3])
            np.add(Gy, o_y, out=oy[2::3])
        else:
            ox[0::3] = Lx
            ox[1::3] = Rx
            ox[2::3] = Gx
            oy[0::3] = Ly
            oy[1::3] = Ry
            oy[2::3] = Gy
        span = None if core is None else (3 * core[0], 3 * core[1])
        return ox, oy, np.zeros(total, dtype=bool), nred, 0, nunsat, xy, span

    if nfig:
        i = np.flatnonzero(fig)
        j = (i + 1) % n
        s1 = np.sign(K[i])
        phi = np.full(i.size, tilt_n)
        if restrict:
            tau1 = np.arctan2(scross[i], dot[i])
            tau2 = np.arctan2(scross[j], dot[j])
            phi = np.minimum(phi, C * 0.5 * np.minimum(tau1, tau2))
        wi = w[i]
        hb = 0.5 * wi * np.tan(phi)
        carry = s1 * A[i] / wi
        h1, h2 = hb + carry, hb - carry
        uxi, uyi = ux[i], uy[i]
        mx = 0.5 * (Rx[i] + Lx[j])
        my = 0.5 * (Ry[i] + Ly[j])
        q1x, q1y = 0.5 * (Rx[i] + mx), 0.5 * (Ry[i] + my)
        q2x, q2y = 0.5 * (mx + Lx[j]), 0.5 * (my + Ly[j])
        # first apex on side s1 of the right normal (uy, -ux): opposite the cut at V_i
        fig_pts = (
            q1x + s1 * h1 * uyi,
            q1y - s1 * h1 * uxi,
            q2x - s1 * h2 * uyi,
            q2y + s1 * h2 * uxi,
        )
    if any_single:  # uncut or fixed vertex: the vertex itself (x - 0 u = x, same value)
        np.copyto(Lx, x, where=single)
        np.copyto(Ly, y, where=single)
    if stacked is not None:
        for arr, o in ((Lx, o_x), (Rx, o_x), (Gx, o_x), (Ly, o_y), (Ry, o_y), (Gy, o_y)):
            arr += o
    s_edge = start + cnt_v
    ox[start] = Lx
    oy[start] = Ly
    if any_single:
        two = ~single
        s_second = start[two] + 1
        ox[s_second] = Rx[two]
        oy[s_second] = Ry[two]
    else:
        ox[1:][start] = Rx  # at start + 1, without a fresh index array
        oy[1:][start] = Ry
    if edge_on is not None:
        s_edge = s_edge[on]
        ox[s_edge] = Gx[on]
        oy[s_edge] = Gy[on]
    else:
        ox[s_edge] = Gx
        oy[s_edge] = Gy
    if nfig:
        se = start[i] + cnt_v[i]
        px, py, qx, qy = fig_pts
        if stacked is not None:
            px, py, qx, qy = px + o_x, py + o_y, qx + o_x, qy + o_y
        ox[se] = px
        oy[se] = py
        ox[se + 1] = qx
        oy[se + 1] = qy
    newfixed = np.zeros(total, dtype=bool)
    if any_fixed:
        newfixed[start[fixed]] = True
    span = None
    if core is not None:
        span = (int(start[core[0]]), int(start[core[1]]) if core[1] < n else total)
    return ox, oy, newfixed, nred, nfig_counted, nunsat, xy, span


#: Core vertices per block of :func:`_step2_blocked`: a block's temporaries (a few
#: dozen arrays of this length) stay in the processor's cache.
_BLOCK = 32768


def _step2_blocked(x, y, fixed, closed, *args, stacked, workers=1):
    """:func:`_step2` over cache-sized blocks of vertices: the same result, faster on long rings.

    CCA1 is local: the output of vertex ``i`` (its cut points and the apex on
    edge ``i``) depends on vertices ``i - 1 .. i + 2`` and on the local alpha
    decreases, and each restriction pass moves a decrease by at most one vertex.
    So each block of ``_BLOCK`` vertices is computed with a halo of
    ``max_passes + 8`` vertices on both sides (the block's own wrap edge, which
    is not an edge of the curve, disturbs only the halo), and the outputs of the
    core vertices are copied out in order. Every value is computed by the same
    element-wise arithmetic as in the one-piece step, so the result is the same
    to the last bit; counts (decreases, Fig. 11 edges, unsatisfied edges) cover
    each block's core only. The temporaries of a block stay in the cache and
    are reused between blocks (no page faults); the one-piece step streams
    several dozen arrays of the whole length through memory.

    Blocks are independent, so with ``workers > 1`` they run in a thread pool
    (numpy releases the GIL inside its loops); at most ``2 * workers`` blocks
    are in flight and their outputs are copied in order, so the result does
    not depend on the number of threads.

    A block that meets a zero-length edge stops the blocked step: if the curve
    has one (a step can create them on real data), it is removed, as
    :func:`_step2` does, and the blocked step starts again; if only the block's
    own wrap edge has zero length, the one-piece step runs. Short curves and a
    halo too long for the block (a large ``max_passes``) take the one-piece step.
    """
    n = x.shape[0]
    halo = args[-1][0] + 8  # limits = (max_passes, min_factor)
    block = _BLOCK
    if n < 2 * block or 4 * halo > block:
        return _step2(x, y, fixed, closed, *args, stacked)[:7]

    def run(s: int):
        e = min(n, s + block)
        if closed:
            lo, hi = s - halo, e + halo
            idx = slice(lo, hi) if lo >= 0 and hi <= n else np.arange(lo, hi) % n
            core = (halo, halo + e - s)
            piece_closed = True
        else:
            lo, hi = max(0, s - halo), min(n, e + halo)
            idx = slice(lo, hi)
            core = (s - lo, e - lo)
            piece_closed = hi < n  # a block's wrap edge sits in its halo; the true end stays open
        return _step2(x[idx], y[idx], fixed[idx], piece_closed, *args, None, core)

    starts = range(0, n, block)
    try:
        if workers > 1:
            with ThreadPoolExecutor(min(workers, len(starts))) as pool:
                return _gather_blocks(n, _in_order(pool, run, starts, 2 * workers), stacked)
        return _gather_blocks(n, map(run, starts), stacked)
    except _NeedsWholeStep:
        if _has_zero_edges(x, y, closed):
            (x, y), fixed = _compact([x, y], fixed, closed)
            return _step2_blocked(x, y, fixed, closed, *args, stacked=stacked, workers=workers)
        return _step2(x, y, fixed, closed, *args, stacked)[:7]


def _has_zero_edges(x: np.ndarray, y: np.ndarray, closed: bool) -> bool:
    """Whether some edge has zero length as :func:`_step2` computes it (``ex^2 + ey^2 == 0``)."""
    ex = np.subtract(x[1:], x[:-1])
    ey = np.subtract(y[1:], y[:-1])
    ex *= ex
    ey *= ey
    ex += ey
    if not ex.all():
        return True
    wx, wy = float(x[0] - x[-1]), float(y[0] - y[-1])
    return closed and wx * wx + wy * wy == 0.0


def _in_order(pool, fn, items, ahead: int):
    """``fn`` over `items` in `pool`, results in order, at most `ahead` in flight.

    Each call runs in a copy of the caller's context, so that numpy's floating-point
    error state (``np.errstate``, a context variable) holds in the worker threads too.
    """

    def submit(item):
        return pool.submit(contextvars.copy_context().run, fn, item)

    items = iter(items)
    futures = deque(submit(item) for item in islice(items, ahead))
    try:
        while futures:
            result = futures.popleft().result()
            for item in islice(items, 1):
                futures.append(submit(item))
            yield result
    finally:
        for future in futures:  # an error (or a zero-length edge) stops the rest
            future.cancel()


def _gather_blocks(n: int, results, stacked):
    """Copy the core outputs of the blocks, in order, into the step's output."""
    cap = 4 * n  # at most L, R and two Fig. 11 apexes per vertex
    if stacked is not None:
        xy = np.empty((cap, 2))
        ox, oy = xy[:, 0], xy[:, 1]
    else:
        ox, oy = np.empty(cap), np.empty(cap)
    newfixed = np.zeros(cap, dtype=bool)
    pos = nred = nfig = nunsat = 0
    for bx, by, bfixed, bred, bfig, bunsat, _, (a, b) in results:
        m = b - a
        if stacked is not None:  # the same value + origin rounding as the one-piece step
            np.add(bx[a:b], stacked[0], out=ox[pos : pos + m])
            np.add(by[a:b], stacked[1], out=oy[pos : pos + m])
        else:
            ox[pos : pos + m] = bx[a:b]
            oy[pos : pos + m] = by[a:b]
        newfixed[pos : pos + m] = bfixed[a:b]
        pos += m
        nred += bred
        nfig += bfig
        nunsat += bunsat
    newfixed.resize(pos, refcheck=False)  # in place: frees the unused tail
    if stacked is None:
        ox.resize(pos, refcheck=False)
        oy.resize(pos, refcheck=False)
        return ox, oy, newfixed, nred, nfig, nunsat, None
    del ox, oy  # no views of xy may outlive its resize
    xy.resize((pos, 2), refcheck=False)
    return xy[:, 0], xy[:, 1], newfixed, nred, nfig, nunsat, xy


def _restrict(*args):
    # Nearly straight vertices (sin of the turning angle ~1e-309) give tan(beta) = inf;
    # the comparisons below then decide correctly (inf demands a decrease where there is
    # a cut area, inf * 0 = nan demands none), so overflow is expected, not an error.
    with np.errstate(over="ignore", invalid="ignore"):
        return _restrict_passes(*args)


def _restrict_passes(alpha, half_a2, cr, scross, dot, short, length, fixed, edge_on, c, C, limits):
    """Local alpha decrease for Definition 2 / Fig. 12 and the section 3.2 inflection rule.

    Per edge ``i`` (vertices ``i``, ``i + 1``): convex and end edges need
    ``w^2 >= c T |A|`` (``tan(gamma) >= c tan(beta)``), inflection edges
    ``|K_1 + K_2| <= 2 w^2 tan(C |tau_m| / 2)``. The first pass checks every
    edge, later passes only the edges next to vertices just decreased. Returns
    the decreased alphas, the number of vertices decreased, the number of
    edges violating at the end (pass limit reached, or decreases stopped by the
    ``min_factor`` floor), and the matching cut lengths ``a`` and cut areas
    ``K`` (so the caller need not recompute them). An edge is rechecked only
    when one of its vertices moved, so each edge's violation state is kept from
    its latest check: an edge stuck at the floor stays counted while decreases
    elsewhere go on.
    """
    max_passes, min_factor = limits
    n = alpha.shape[0]
    alpha = alpha.copy()
    alpha0 = alpha.copy()
    floor = min_factor * alpha0
    turning = ~fixed & (scross > 0)
    tanb = np.zeros(n)
    np.divide(1.0 + dot, scross, out=tanb, where=turning)  # tan(beta) = cot(|tau| / 2)
    endish_all = (fixed & _roll_m1(turning)) | (_roll_m1(fixed) & turning)  # end edges
    a = alpha * short
    kfac = alpha * alpha * half_a2
    K = [kfac * ck for ck in cr]
    edges = None  # None: all edges
    # violation state of every edge at its latest check: an edge is rechecked only when
    # one of its vertices moved, so this is the state at the end for every edge
    pending = np.zeros(n, dtype=bool)
    for npass in range(max_passes + 1):
        if edges is None:  # first pass: all edges, with shifts instead of gathers
            i = np.arange(n)
            j = _roll_m1(i)
            K1 = K
            K2 = [_roll_m1(k) for k in K]
            w = 0.5 * (length - a - _roll_m1(a))
        else:
            i = edges
            j = i + 1
            j[j == n] = 0
            K1 = [k[i] for k in K]
            K2 = [k[j] for k in K]
            w = 0.5 * (length[i] - a[i] - a[j])
        if len(cr) == 1:
            k12 = K1[0] * K2[0]
            net = np.abs(K1[0] + K2[0])
        else:
            k12 = sum(p * q for p, q in zip(K1, K2, strict=True))
            net = np.sqrt(sum((p + q) ** 2 for p, q in zip(K1, K2, strict=True)))
        w2 = w * w
        if edges is None:
            T = np.maximum(tanb, _roll_m1(tanb))
            endish = endish_all
            on = edge_on
        else:
            T = np.maximum(tanb[i], tanb[j])
            endish = endish_all[i]
            on = edge_on[i]
        need_c = (0.5 * c) * T * net  # c T |A|
        viol_c = (w2 < need_c * (1.0 - 1e-12)) & ((k12 > 0) | endish) & on
        ic = np.flatnonzero(viol_c)
        # inflection edges: epsilon = atan(|A| / w^2) <= C |tau_m| / 2
        ii = np.flatnonzero((k12 < 0) & on)
        if len(cr) == 1:
            m1 = np.abs(K1[0][ii])
            m2 = np.abs(K2[0][ii])
        else:
            m1 = np.sqrt(sum(k[ii] ** 2 for k in K1))
            m2 = np.sqrt(sum(k[ii] ** 2 for k in K2))
        minor2 = m2 <= m1
        mv = np.where(minor2, j[ii], i[ii])
        tau_m = np.arctan2(scross[mv], dot[mv])
        s2 = 2.0 * w2[ii] * np.tan(0.5 * C * tau_m)  # bound on |K_1 + K_2|
        bad = net[ii] > s2 * (1.0 + 1e-12)
        nbad = int(np.count_nonzero(bad))
        pending[i] = False
        pending[i[ic]] = True
        pending[i[ii[bad]]] = True
        if (ic.size == 0 and nbad == 0) or npass == max_passes:
            break
        f = np.sqrt(w2[ic] / need_c[ic]) * _SHRINK
        verts = [i[ic], j[ic]]
        facs = [f, f]
        if nbad:
            ib, mi2 = ii[bad], minor2[bad]
            mag_d = np.where(mi2, m1[bad], m2[bad])
            mag_m = np.where(mi2, m2[bad], m1[bad])
            dotab = k12[ib]  # K_d . K_m
            sb = s2[bad]
            # largest t = f^2 with |t K_d + K_m| <= s2 (2D: t = (|K_m| + s2) / |K_d|)
            disc = dotab * dotab - mag_d * mag_d * (mag_m * mag_m - sb * sb)
            ok = disc >= 0
            t = (-dotab + np.sqrt(np.maximum(disc, 0.0))) / (mag_d * mag_d)
            f_dom = np.sqrt(np.clip(t, 0.0, 1.0)) * _SHRINK
            dom = np.where(mi2, i[ib], j[ib])
            verts.append(dom[ok])
            facs.append(f_dom[ok])
            if not ok.all():
                # 3D only: the dominant cut alone cannot reach the bound; scale both
                fb = np.sqrt(sb[~ok] / net[ib[~ok]]) * _SHRINK
                verts += [i[ib[~ok]], j[ib[~ok]]]
                facs += [fb, fb]
        v = np.concatenate(verts)
        fv = np.concatenate(facs)
        f_v = np.ones(n)
        np.minimum.at(f_v, v, fv)  # per vertex the smallest factor of its edges
        f_v[fixed] = 1.0
        v = np.flatnonzero(f_v < 1.0)
        new = np.maximum(alpha[v] * f_v[v], floor[v])
        moved = new < alpha[v]
        if not moved.all():
            v, new = v[moved], new[moved]
            if v.size == 0:  # every violation sits at the floor
                break
        alpha[v] = new
        a[v] = alpha[v] * short[v]
        kv = alpha[v] * alpha[v] * half_a2[v]
        for k, ck in zip(K, cr, strict=True):
            k[v] = kv * ck[v]
        touched = np.zeros(n, dtype=bool)
        touched[v] = True
        touched[v - 1] = True  # edge v - 1 ends at v (index -1 wraps to n - 1)
        edges = np.flatnonzero(touched)
    nred = int(np.count_nonzero(alpha < alpha0))
    return alpha, nred, int(np.count_nonzero(pending)), a, K


def _sorted_unique(v: np.ndarray) -> np.ndarray:
    """Sorted distinct values of an integer array (np.unique without its hash path)."""
    s = np.sort(v)
    if s.size > 1:
        keep = np.empty(s.size, dtype=bool)
        keep[0] = True
        np.not_equal(s[1:], s[:-1], out=keep[1:])
        s = s[keep]
    return s


def _restrict2(*args):
    """2D :func:`_restrict_passes` that also returns the edge terms of the final alphas.

    Same rules and the same arithmetic (so the same alphas); the generic
    :func:`_restrict_passes` is the reference the tests compare against. Cut
    lengths and cut areas live in buffers of ``n + 1`` slots (``b[n] = b[0]``)
    so that the next vertex's value is a view. Work saved on the way: the
    trig bound of inflection edges is evaluated only where the trig-free lower
    bound ``tan(C |tau| / 2) >= C |sin(tau)| / 2`` does not already clear the
    edge, and per-vertex factors are merged on the touched vertices only.
    Returns ``alpha, nred, nunsat, a_e, K_e, w, S, k12`` with ``S = K_i +
    K_{i+1}``, ``k12 = K_i K_{i+1}`` and the half-width ``w`` per edge; with
    ``core = (lo, hi)`` the counts cover vertices and edges ``lo .. hi - 1`` only
    (a block of :func:`_step2_blocked`).
    """
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        return _restrict2_passes(*args)


def _restrict2_passes(
    alpha, half_a2, cr, scross, dot, short, length, fixed, any_fixed, edge_on, c, C, limits, core
):
    max_passes, min_factor = limits
    n = alpha.shape[0]
    alpha0 = alpha
    alpha = alpha.copy()
    a_e = _ext(n)
    a = a_e[:-1]
    np.multiply(alpha, short, out=a)
    a_e[n] = a[0]
    K_e = _ext(n)
    K = K_e[:-1]
    np.multiply(alpha, alpha, out=K)
    K *= half_a2
    K *= cr
    K_e[n] = K[0]
    Kn = K_e[1:]
    # edge terms, kept current for every edge through the passes
    w = np.subtract(length, a)
    w -= a_e[1:]
    w *= 0.5
    k12 = np.multiply(K, Kn)
    S = np.add(K, Kn)
    # tan(beta) = cot(|tau| / 2) at turning vertices, 0 elsewhere
    turning = scross > 0
    if any_fixed:
        turning &= ~fixed
    tanb_e = _ext(n)
    tanb = tanb_e[:-1]
    np.add(dot, 1.0, out=tanb)
    tanb /= scross  # inf / nan where not turning: reset
    if any_fixed or not turning.all():
        tanb[~turning] = 0.0
    tanb_e[n] = tanb[0]
    if any_fixed:
        tn = np.empty(n + 1, dtype=bool)
        tn[:-1] = turning
        tn[n] = turning[0]
        fx = np.empty(n + 1, dtype=bool)
        fx[:-1] = fixed
        fx[n] = fixed[0]
        endish_all = (fixed & tn[1:]) | (fx[1:] & turning)  # end edges
    else:
        endish_all = None
    del turning
    half_c = 0.5 * c
    f_v = None  # per-vertex factor buffer, allocated on demand, kept at 1 between passes
    decreased = False
    bufs = None
    edges = None  # None: pass over every edge (restricted to ``mask`` if not None)
    mask = None  # None: all edges
    pending = np.zeros(n, dtype=bool)  # violation state of every edge at its latest check
    for npass in range(max_passes + 1):
        if edges is None:  # every edge, with views instead of gathers
            if mask is not None:  # the same values as before for the untouched edges
                np.subtract(length, a, out=w)
                w -= a_e[1:]
                w *= 0.5
                np.multiply(K, Kn, out=k12)
                np.add(K, Kn, out=S)
            if bufs is None:  # one set of scratch arrays for every whole-array pass
                bufs = [np.empty(n) for _ in range(4)]
                bufs += [np.empty(n, dtype=bool), np.empty(n, dtype=bool)]
            net = np.abs(S, out=bufs[0])
            w2 = np.multiply(w, w, out=bufs[1])
            need_c = np.maximum(tanb, tanb_e[1:], out=bufs[2])
            need_c *= half_c
            need_c *= net  # c T |A|
            viol_c = np.less(w2, np.multiply(need_c, 1.0 - 1e-12, out=bufs[3]), out=bufs[4])
            conv = np.greater(k12, 0, out=bufs[5])
            if endish_all is not None:
                conv |= endish_all
            viol_c &= conv
            infl = np.less(k12, 0, out=conv)
            if edge_on is not None:
                viol_c &= edge_on
                infl &= edge_on
            if mask is not None:  # later pass: only the edges next to decreased vertices
                viol_c &= mask
                infl &= mask
            ic = np.flatnonzero(viol_c)
            ii = np.flatnonzero(infl)
            del viol_c, conv, infl
            jc = ic + 1
            jc[jc == n] = 0
            jj = ii + 1
            jj[jj == n] = 0
            k12_ii = k12[ii]
            net_ii = net[ii]
            w2_ii = w2[ii]
            m1 = np.abs(K[ii])
            m2 = np.abs(Kn[ii])
            f = w2[ic]
            f /= need_c[ic]
            del net, w2, need_c
        else:
            i = edges
            j = i + 1
            j[j == n] = 0
            K1, K2 = K[i], K[j]
            we = 0.5 * (length[i] - a[i] - a[j])
            w[i] = we
            k12e = K1 * K2
            k12[i] = k12e
            Se = K1 + K2
            S[i] = Se
            nete = np.abs(Se)
            w2e = we * we
            T = np.maximum(tanb[i], tanb[j])
            need = half_c * T * nete
            conv = k12e > 0
            if endish_all is not None:
                conv |= endish_all[i]
            viol = (w2e < need * (1.0 - 1e-12)) & conv
            infl = k12e < 0
            if edge_on is not None:
                on = edge_on[i]
                viol &= on
                infl &= on
            sel = np.flatnonzero(viol)
            ic, jc = i[sel], j[sel]
            f = w2e[sel] / need[sel]
            sel = np.flatnonzero(infl)
            ii, jj = i[sel], j[sel]
            k12_ii = k12e[sel]
            net_ii = nete[sel]
            w2_ii = w2e[sel]
            m1 = np.abs(K1[sel])
            m2 = np.abs(K2[sel])
        # inflection edges: epsilon = atan(|A| / w^2) <= C |tau_m| / 2, i.e.
        # |K_1 + K_2| <= s2 = 2 w^2 tan(C |tau_m| / 2); as tan(x) >= x and
        # |tau| >= |sin(tau)|, s2 >= C w^2 |sin(tau_m)| clears most edges trig-free
        minor2 = m2 <= m1
        mv = np.where(minor2, jj, ii)
        scm = scross[mv]
        unsure = np.flatnonzero(net_ii > (C * (1.0 - 1e-9)) * w2_ii * scm)
        tau_m = np.arctan2(scm[unsure], dot[mv[unsure]])
        s2u = 2.0 * w2_ii[unsure] * np.tan(0.5 * C * tau_m)  # bound on |K_1 + K_2|
        badu = net_ii[unsure] > s2u * (1.0 + 1e-12)
        bad = unsure[badu]
        nbad = bad.size
        if edges is not None:
            pending[i] = False
        elif mask is not None:
            pending &= ~mask
        else:
            pending.fill(False)
        pending[ic] = True
        pending[ii[bad]] = True
        if (ic.size == 0 and nbad == 0) or npass == max_passes:
            break
        np.sqrt(f, out=f)
        f *= _SHRINK
        verts = [ic, jc]
        facs = [f, f]
        if nbad:
            mi2 = minor2[bad]
            m1b, m2b = m1[bad], m2[bad]
            mag_d = np.where(mi2, m1b, m2b)
            mag_m = np.where(mi2, m2b, m1b)
            dotab = k12_ii[bad]  # K_d . K_m
            sb = s2u[badu]
            # largest t = f^2 with |t K_d + K_m| <= s2 (2D: t = (|K_m| + s2) / |K_d|)
            disc = dotab * dotab - mag_d * mag_d * (mag_m * mag_m - sb * sb)
            okd = disc >= 0
            t = (-dotab + np.sqrt(np.maximum(disc, 0.0))) / (mag_d * mag_d)
            f_dom = np.sqrt(np.clip(t, 0.0, 1.0)) * _SHRINK
            dom = np.where(mi2, ii[bad], jj[bad])
            verts.append(dom[okd])
            facs.append(f_dom[okd])
            if not okd.all():
                # cannot happen in 2D (disc = (|K_d| s2)^2); kept as in the generic pass
                nb = net_ii[bad][~okd]
                fb = np.sqrt(sb[~okd] / nb) * _SHRINK
                verts += [ii[bad][~okd], jj[bad][~okd]]
                facs += [fb, fb]
        v = np.concatenate(verts)
        fv = np.concatenate(facs)
        if f_v is None:
            f_v = np.ones(n)
        np.minimum.at(f_v, v, fv)  # per vertex the smallest factor of its edges
        v = np.flatnonzero(f_v < 1.0) if 32 * v.size > n else _sorted_unique(v)
        fv = f_v[v]
        f_v[v] = 1.0  # restore the buffer
        keep = fv < 1.0
        if any_fixed:
            keep &= ~fixed[v]
        if not keep.all():
            v, fv = v[keep], fv[keep]
        av = alpha[v]
        new = av * fv
        if min_factor > 0:  # with a zero floor max(new, 0) is new (both >= 0 or nan)
            np.maximum(new, min_factor * alpha0[v], out=new)
        moved = new < av
        if not moved.all():
            v, new = v[moved], new[moved]
            if v.size == 0:  # every violation sits at the floor
                break
        alpha[v] = new
        decreased = True
        a[v] = new * short[v]
        K[v] = new * new * half_a2[v] * cr[v]
        a_e[n] = a[0]
        K_e[n] = K[0]
        ev = v - 1  # edge v - 1 ends at v
        ev[0] = n - 1 if ev[0] < 0 else ev[0]
        if 8 * v.size > n:  # many edges: a masked pass with views beats gathers
            mask = np.zeros(n, dtype=bool)
            mask[v] = True
            mask[ev] = True
            edges = None
        else:
            edges = _sorted_unique(np.concatenate([v, ev]))
    lo, hi = (0, n) if core is None else core
    nred = int(np.count_nonzero(alpha[lo:hi] < alpha0[lo:hi])) if decreased else 0
    nunsat = int(np.count_nonzero(pending[lo:hi]))
    return alpha, nred, nunsat, a_e, K_e, w, S, k12
