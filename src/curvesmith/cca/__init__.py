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
The package's parts: :mod:`._profiles` (alpha-profiles), :mod:`._restrict`
(the restriction rules in whole-array numpy), :mod:`._kernel` (the one 2D
step, compiled with numba, over a ragged batch of curves), :mod:`._stepnd`
(the N-d numpy step: 3D polylines, and the reference the tests hold the
kernel to), :mod:`._input` (duplicates, anchors, planes) and :mod:`._api` (the
public functions). Every 2D curve -- one through :func:`smooth`, many through
:func:`smooth_ragged` -- runs through the same kernel, so a curve smoothed in a
batch gets the same bits as alone. The kernel is compiled on first use and
cached by numba (first call in a fresh environment: 20-40 s of compilation;
later processes load it from the cache in about a second, from the package's
``__pycache__`` or, when that is not writable, numba's user cache folder);
``import curvesmith.cca`` does not load numba. Curves of 65536 or more
vertices are cut into blocks of 32768 vertices with halos (the step is local,
so the result is the same to the last bit), and batches of 65536 or more
vertices run in ``threads`` threads, groups of whole curves and blocks (the
kernel releases the GIL; the result does not depend on the threads).

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

from ._api import (
    AlphaSpec,
    CCAResult,
    RaggedCCAResult,
    smooth,
    smooth_ragged,
    smooth_ragged_with_info,
    smooth_with_info,
)
from ._profiles import (
    LIMIT_ALPHA,
    TRIANGLE_ALPHA,
    alpha_profile,
    profile_nodes,
    regular_alpha,
    solve_regular_alpha,
)

__all__ = [
    "LIMIT_ALPHA",
    "TRIANGLE_ALPHA",
    "AlphaSpec",
    "CCAResult",
    "RaggedCCAResult",
    "alpha_profile",
    "profile_nodes",
    "regular_alpha",
    "smooth",
    "smooth_ragged",
    "smooth_ragged_with_info",
    "smooth_with_info",
    "solve_regular_alpha",
]
