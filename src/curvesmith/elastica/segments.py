"""Multi-segment fairing to a tolerance: the fewest discrete elasticae, joined G1.

A curve that no single discrete elastica follows within a tolerance ``T`` is replaced by a
chain of discrete elasticae (eq. (4.4), each with its own ``h, z, q, k``) fitted jointly to
the equal-chord data by eq. (4.8) summed over the chain.

G1 by construction
------------------
Segment ``i + 1`` starts at the last vertex of segment ``i`` (the joint, shared) and
continues its vertex tangent: with ``theta_n = phi + 2 a_n`` of eq. (4.3)
(``a_n = (theta_n - phi)/2``), its rotation is not a free parameter but

    phi_{i+1} = theta^i_last - 2 a(q_{i+1}; k_{i+1}),

so ``theta^{i+1}_0 = theta^i_last``. The edges then turn at the joint by the mean of the
two segments' half turnings there: no kink. The unknowns are ``(x0, y0, phi)`` of the first
segment and ``(h, z, q, k)`` of every segment, ``3 + 4 M`` in all; the Jacobian is
analytic, eqs. (4.10)-(4.11) per segment chained through the joint vertex and ``phi``
(forward mode: ``d gamma^i_n = d P_i + i (gamma^i_n - P_i) d phi_i + own columns``; checked
against finite differences in the tests). Levenberg-Marquardt (MINPACK lmder) solves it.
G2 (equal discrete curvature, eq. (3.20), across the joint) is not imposed: it is measured
and reported per joint.

Fewest segments
---------------
1. The single global fit of :func:`.fit` (resampled to equal chords end to end). If its
   geometric max deviation is within ``T``: one segment, no chain solve.
2. Greedy free segments: from the start, each the longest stretch of the data whose own
   free fit (seven parameters) keeps every data vertex of it within ``T``, by bisection on
   its end vertex (each probe one solve warm-started from the last feasible probe, the
   global search only when that misses by less than ``_CLEAR_MISS T``). Free segments are
   more flexible than a chain, so this count is where the chain starts. If the rest after a
   segment would be shorter than ``2 MIN_SEGMENT_POINTS`` vertices, that segment and the
   last share the rest evenly: a free fit of a few vertices has its seven parameters barely
   determined (an 8-vertex end of the section scan fitted ``k = 1`` and ``z`` anywhere
   from 0.4 to 1.8 with last-ulp changes of the data), and the penalty path from it ended
   in a basin 4x above the good one's cost, or in the good one, by chance.
3. From the free fits to the chain by a penalty path: the joint conditions (shared vertex,
   equal vertex tangent) enter as residuals weighted ``0.1, 10, 1000`` (:class:`_PenaltyProblem`),
   each stage solved from the last, then the chain solve. Chaining the free fits directly
   starts 2.7 mm rms off on two G1 pieces and the chain solve stops in another minimum.
4. Joint search: coordinate descent over the joint indices (pattern search over shifts of
   4, 2, 1 vertices, the moved segment restarting on its own elastica, ``q += z d``), each
   trial a capped solve of the two segments next to the joint with the rest of the chain
   following rigidly; a move is kept if it lowers the cost by ``_GAIN``. On two G1 pieces
   with 0.02 mm noise the chain's rms is 0.021 mm with the joint at the true vertex, 0.45
   with it one vertex off: the joint must be found to the vertex, which a free greedy end
   (where the free fit just reaches ``T``) is not.
5. While some input point is farther than ``T`` from the chained polyline (exact
   point-to-polyline distance, :func:`._geom.point_polyline_distance`) and fewer than
   ``max_segments`` segments: split the segment with the largest deviation at its middle
   (if it is too short to split, its longer neighbour, whose joint search can then move
   the short one's joints; never a segment within ``T`` while one beyond ``T`` or its
   neighbour can be split),
   from the better of two starts (the same elastica continued, ``(h, z, q + z c, k)``,
   which is exactly the previous chain; and free fits of the halves up the penalty path),
   and search the joints next to it. At ``max_segments``, ``within_tolerance`` is False and
   the message says so.

What was measured not to work (issue #11 notes): greedy longest segments, each next one
G1-constrained from the previous (a fit's end tangent is an extrapolation, 0.045 rad off,
1.3 mm), and free greedy segments chained afterwards with their joints fixed (0.46-0.87 mm
against 0.15). Here too: splitting from a single fit alone (steps 1 and 5 without 2-4)
needed 7 segments for 2 G1 pieces; decoupling the joint-search trials from the rest of
the chain (a free end) swung the downstream chain away (50 mm).

The data are oriented canonically first (the end with the lexicographically smaller
coordinates first, as :func:`.fit` does) and the result mapped back, so the segmentation does
not depend on the point order.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike
from scipy.optimize import leastsq

from .._validate import as_float, as_int, as_points
from ..errors import CurveError
from . import _geom
from .exact import (
    ElasticaParams,
    _family,
    _half_angles,
    _positions,
    _positions_and_jacobian,
    exact_curvature,
)
from .fit import FitResult, _reverse_params, fit

__all__ = ["Joint", "Segment", "SegmentFit", "fit_segments"]

#: Fewest vertices of a segment.
MIN_SEGMENT_POINTS = 8
#: Default largest number of segments.
DEFAULT_MAX_SEGMENTS = 12
#: Function evaluations per chain solve (and per trial of the joint search).
_CHAIN_MAXFEV = 200
_TRIAL_MAXFEV = 40
#: Relative reduction of the cost (and step) at which a chain solve has converged.
_FTOL = 1e-8
#: A warm-started probe of the greedy that converges this far outside the tolerance is
#: taken as infeasible without the global search.
_CLEAR_MISS = 1.5
#: First index shift of the joint search.
_JOINT_STEP = 4
#: A joint move is kept if it lowers the cost by at least this fraction.
_GAIN = 1e-3


@dataclass(frozen=True)
class Segment:
    """One discrete elastica segment of :func:`fit_segments`.

    Attributes
    ----------
    params : ElasticaParams
        Its seven parameters ``(x0, y0, h, phi, z, q, k)`` of eq. (4.5): ``(x0, y0)`` its
        first vertex (the previous segment's last), its own ``h``.
    first, last : int
        Its vertex range in `SegmentFit.data`, both included; ``last`` of a segment is
        ``first`` of the next (the joint).
    points : (K, 2) ndarray
        Its vertices, ``K = last - first + 1``.
    rms : float
        Index-paired rms over its data vertices (eq. (4.8)).
    max_deviation : float
        Largest geometric distance to the chain of the input points nearest to this segment.
    """

    params: ElasticaParams
    first: int
    last: int
    points: np.ndarray = field(repr=False)
    rms: float
    max_deviation: float


@dataclass(frozen=True)
class Joint:
    """A joint between segments ``index`` and ``index + 1`` of :func:`fit_segments`.

    Attributes
    ----------
    index : int
        The segment before the joint.
    vertex : int
        The shared vertex, in `SegmentFit.data`.
    g1_defect : float
        ``|theta^i_last - theta^{i+1}_0|`` (radians, wrapped to ``[0, pi]``), from each
        segment's own parameters (eq. (4.3)); zero to rounding by construction.
    turning : float
        Turning angle of the chained polyline at the joint vertex (radians, signed).
    curvature_before, curvature_after : float
        Discrete curvature of eq. (3.20) at the joint vertex of each segment.
    curvature_jump : float
        ``curvature_after - curvature_before`` (G2 holds where it is 0).
    """

    index: int
    vertex: int
    g1_defect: float
    turning: float
    curvature_before: float
    curvature_after: float
    curvature_jump: float


@dataclass(frozen=True)
class SegmentFit:
    """Result of :func:`fit_segments`.

    Attributes
    ----------
    segments : tuple of Segment
        In order along the curve (the input's order).
    joints : tuple of Joint
        ``len(segments) - 1`` joints.
    points : (N, 2) ndarray
        The chained vertices, one per data vertex (joints once).
    data : (N, 2) ndarray
        The equal-chord data that was fitted, in the input's order.
    deviation : (M,) ndarray
        Distance of every input point (repeats dropped) to the chained polyline.
    max_deviation, rms_deviation : float
        Their maximum and rms.
    rms : float
        Index-paired rms over all data vertices.
    tolerance : float
        The tolerance ``T``.
    within_tolerance : bool
        ``max_deviation <= tolerance``.
    success : bool
        The final chain solve converged (Levenberg-Marquardt); for one segment, the single
        fit's ``success``.
    message : str
        What happened, in words.
    single : FitResult
        The single global fit that the search started from.
    solves : int
        Chain solves run (splits and joint-search trials).
    """

    segments: tuple
    joints: tuple
    points: np.ndarray = field(repr=False)
    data: np.ndarray = field(repr=False)
    deviation: np.ndarray = field(repr=False)
    max_deviation: float
    rms_deviation: float
    rms: float
    tolerance: float
    within_tolerance: bool
    success: bool
    message: str
    single: FitResult = field(repr=False)
    solves: int


# --- the chain -------------------------------------------------------------------------


@functools.lru_cache(maxsize=64)
def _segment_family(z: float, q: float, k: float, n: int, jac: bool):
    """``S, C`` (and ``da/ds, da/dk`` with `jac`) of a segment: eq. (4.3) at ``s = z n + q``.

    Memoised: a solve with some segments held (the joint search) re-evaluates only the
    others. The arrays are read-only.
    """
    s = z * np.arange(n, dtype=float) + q
    out = _family(s, k) if jac else _half_angles(s, k)
    for arr in out:
        arr.flags.writeable = False
    return out


def _chain(x: np.ndarray, sizes, jac: bool):
    """Vertices (complex, ``(N,)``) of the G1 chain with unknowns `x`, and the Jacobian.

    ``x = (x0, y0, phi, h_0, z_0, q_0, k_0, h_1, ...)``; `sizes` the vertex counts of the
    segments (joints counted in both). Returns ``(vertices, J, thetas)`` with ``J`` complex
    ``(N, len(x))`` (None unless `jac`) and ``thetas`` the per-segment
    ``(phi_i, theta_first, theta_last)``.
    """
    npar = x.size
    P = complex(x[0], x[1])
    phi = float(x[2])
    dP = np.zeros(npar, dtype=complex)
    dP[0], dP[1] = 1.0, 1j
    dphi = np.zeros(npar)
    dphi[2] = 1.0
    verts, rows, angles = [], [], []
    theta_prev = 0.0  # set by the first segment, used from the second on
    dtheta_prev = np.zeros(npar)
    for i, n in enumerate(sizes):
        h, z, q, k = (float(v) for v in x[3 + 4 * i : 7 + 4 * i])
        if jac:
            S, C, a_s, a_k = _segment_family(z, q, k, n, True)
        else:
            S, C = _segment_family(z, q, k, n, False)
        if i:
            phi = theta_prev - 2.0 * math.atan2(S[0], C[0])
            if jac:
                dphi = dtheta_prev.copy()
                dphi[5 + 4 * i] -= 2.0 * a_s[0]
                dphi[6 + 4 * i] -= 2.0 * a_k[0]
        E = C + 1j * S
        T = E[:-1] * E[1:] * complex(math.cos(phi), math.sin(phi))
        W = np.empty(n, dtype=complex)
        W[0] = 0.0
        np.cumsum(T, out=W[1:])
        g = P + h * W
        theta_last = phi + 2.0 * math.atan2(S[-1], C[-1])
        angles.append((phi, phi + 2.0 * math.atan2(S[0], C[0]), theta_last))
        verts.append(g if i == 0 else g[1:])
        if jac:
            J = np.outer(np.ones(n), dP) + np.outer(1j * h * W, dphi)
            J[:, 3 + 4 * i] += W
            rates = np.stack((a_s * np.arange(n), a_s, a_k))
            steps = (1j * h) * T * (rates[:, :-1] + rates[:, 1:])
            cols = np.zeros((3, n), dtype=complex)
            np.cumsum(steps, axis=1, out=cols[:, 1:])
            J[:, 4 + 4 * i : 7 + 4 * i] += cols.T
            rows.append(J if i == 0 else J[1:])
            dP = J[-1].copy()
            dtheta_prev = dphi.copy()
            dtheta_prev[4 + 4 * i] += 2.0 * a_s[-1] * (n - 1)
            dtheta_prev[5 + 4 * i] += 2.0 * a_s[-1]
            dtheta_prev[6 + 4 * i] += 2.0 * a_k[-1]
        P = complex(g[-1])
        theta_prev = theta_last
    return np.concatenate(verts), (np.concatenate(rows) if jac else None), angles


class _ChainProblem:
    """Residuals ``gamma - zeta`` of the chain (real, interleaved) and their Jacobian."""

    def __init__(self, data: np.ndarray, sizes):
        self.zeta = np.ascontiguousarray(data).view(complex).ravel()
        self.sizes = tuple(int(v) for v in sizes)

    def residuals(self, x):
        g, _, _ = _chain(x, self.sizes, False)
        return (g - self.zeta).view(float)

    def jacobian(self, x):
        _, J, _ = _chain(x, self.sizes, True)
        out = np.empty((J.shape[0], 2, J.shape[1]))
        out[:, 0] = J.real
        out[:, 1] = J.imag
        return out.reshape(-1, J.shape[1])

    def cost(self, x) -> float:
        r = self.residuals(x)
        return float(r @ r)


def _solve_chain(data, sizes, x0, maxfev, free=None):
    """Levenberg-Marquardt on the chain from `x0`: ``(x, cost, converged)``.

    `free`: a mask of the unknowns to solve for (default all). A trial outside ``h, k > 0``
    or with non-finite vertices gets a huge residual, which MINPACK rejects as a step.
    """
    prob = _ChainProblem(data, sizes)
    big = np.full(2 * prob.zeta.size, 1e30)
    if free is None:
        free = np.ones(x0.size, dtype=bool)
    base = x0.copy()

    def full(xf):
        x = base.copy()
        x[free] = xf
        return x

    def res(xf):
        x = full(xf)
        if np.any(x[3::4] <= 0) or np.any(x[6::4] <= 0):
            return big
        r = prob.residuals(x)
        return r if np.all(np.isfinite(r)) else big

    def jac(xf):
        return prob.jacobian(full(xf))[:, free]

    with np.errstate(all="ignore"):
        xf, _, _, _, ier = leastsq(
            res, x0[free], Dfun=jac, full_output=True, ftol=_FTOL, xtol=_FTOL, maxfev=maxfev
        )
    x = full(xf)
    cost = prob.cost(x) if np.all(np.isfinite(x)) else math.inf
    if not math.isfinite(cost) or np.any(x[3::4] <= 0) or np.any(x[6::4] <= 0):
        return x0, prob.cost(x0), False
    return x, cost, ier in (1, 2, 3, 4)


def _local(npar: int, j: int) -> np.ndarray:
    """Mask of the unknowns of segments `j` and ``j + 1`` (and the start's, for ``j = 0``)."""
    free = np.zeros(npar, dtype=bool)
    free[3 + 4 * j : 11 + 4 * j] = True
    if j == 0:
        free[:3] = True
    return free


def _end_angles(p: ElasticaParams, n: int):
    """Vertex tangents ``theta_0, theta_{n-1}`` (eq. 4.3) and their gradients in ``p`` (7,)."""
    s = np.array([p.q, p.z * (n - 1) + p.q])
    S, C, a_s, a_k = _family(s, p.k)
    th = p.phi + 2.0 * np.arctan2(S, C)
    d0 = np.zeros(7)
    d1 = np.zeros(7)
    d0[3] = d1[3] = 1.0
    d0[5], d0[6] = 2.0 * a_s[0], 2.0 * a_k[0]
    d1[4], d1[5], d1[6] = 2.0 * a_s[1] * (n - 1), 2.0 * a_s[1], 2.0 * a_k[1]
    return th, d0, d1


class _PenaltyProblem:
    """Free segments (7 parameters each) with the joint conditions as weighted residuals.

    Rows: every segment's index-paired residuals on its own vertex range, then per joint
    ``w (gamma^i_last - gamma^{i+1}_0)`` and ``w L (theta^i_last - theta^{i+1}_0)`` with
    ``L`` half the next segment's length. Raising ``w`` from the free fits (``w = 0``) to a
    large value moves them continuously to a nearly G1 chain, which the chain solve then
    makes exact.
    """

    def __init__(self, data, sizes, weight, lengths):
        self.data = data
        self.lengths = lengths
        self.sizes = list(sizes)
        self.firsts = np.concatenate([[0], np.cumsum(np.array(self.sizes[:-1]) - 1)]).astype(int)
        self.w = weight

    def _eval(self, y, jac):
        m = len(self.sizes)
        res, rows = [], []
        ends = []
        npar = 7 * m
        for i, (f, n) in enumerate(zip(self.firsts, self.sizes, strict=True)):
            p = ElasticaParams(*(float(v) for v in y[7 * i : 7 * i + 7]))
            if jac:
                g, J = _positions_and_jacobian(p, n)
                block = np.zeros((2 * n, npar))
                block[:, 7 * i : 7 * i + 7] = J.reshape(2 * n, 7)
                rows.append(block)
                ends.append((g, J, *_end_angles(p, n)))
            else:
                g = _positions(p, n)
                ends.append((g, None, _end_angles(p, n)[0]))
            res.append((g - self.data[f : f + n]).ravel())
        for i in range(m - 1):
            ga, gb = ends[i][0], ends[i + 1][0]
            ell = self.lengths[i]
            tha, thb = ends[i][2], ends[i + 1][2]
            dth = math.remainder(float(tha[1] - thb[0]), 2.0 * math.pi)
            res.append(self.w * np.array([*(ga[-1] - gb[0]), ell * dth]))
            if jac:
                block = np.zeros((3, npar))
                Ja, Jb = ends[i][1], ends[i + 1][1]
                block[:2, 7 * i : 7 * i + 7] = Ja[-1]
                block[:2, 7 * i + 7 : 7 * i + 14] = -Jb[0]
                block[2, 7 * i : 7 * i + 7] = ell * ends[i][4]
                block[2, 7 * i + 7 : 7 * i + 14] = -ell * ends[i + 1][3]
                rows.append(self.w * block)
        r = np.concatenate(res)
        return r, (np.vstack(rows) if jac else None)

    def residuals(self, y):
        return self._eval(y, False)[0]

    def jacobian(self, y):
        return self._eval(y, True)[1]


def _penalty_path(data, sizes, y, weights=(1e-1, 10.0, 1e3)):
    """Follow the penalty weights up from free segments `y` (7 per segment)."""
    lengths = [0.5 * sizes[i + 1] * float(y[7 * (i + 1) + 2]) for i in range(len(sizes) - 1)]
    for w in weights:
        prob = _PenaltyProblem(data, sizes, w, lengths)
        with np.errstate(all="ignore"):
            yn, _, _, _, _ = leastsq(
                prob.residuals,
                y,
                Dfun=prob.jacobian,
                full_output=True,
                ftol=1e-10,
                xtol=1e-10,
                maxfev=100,
            )
        if np.all(np.isfinite(yn)) and np.all(yn[2::7] > 0) and np.all(yn[6::7] > 0):
            y = yn
    return y


def _chain_from_free(y, sizes):
    """Chain unknowns from free segment parameters (7 per segment): drop the derived ones."""
    m = len(sizes)
    x = [y[0], y[1], y[3]]
    for i in range(m):
        x.extend(y[7 * i + 2 : 7 * i + 3])
        x.extend(y[7 * i + 4 : 7 * i + 7])
    return np.array(x, dtype=float)


def _split(x, sizes, i, c):
    """Split segment `i` at its vertex `c`: the same curve, one more segment."""
    h, z, q, k = x[3 + 4 * i : 7 + 4 * i]
    x = np.concatenate([x[: 7 + 4 * i], [h, z, q + z * c, k], x[7 + 4 * i :]])
    sizes = [*sizes[:i], c + 1, sizes[i] - c, *sizes[i + 1 :]]
    return x, sizes


def _split_starts(data, x, sizes, i, c):
    """Starts for splitting segment `i` at its vertex `c`.

    The exact copy (:func:`_split`), and the free single fits of the two halves followed
    up the penalty path (:class:`_PenaltyProblem`) with the other segments as they are.
    """
    yield _split(x, sizes, i, c)
    params, _ = _params_of(x, sizes)
    first = int(sum(n - 1 for n in sizes[:i]))
    halves = []
    for lo, hi in ((first, first + c), (first + c, first + sizes[i] - 1)):
        try:
            halves.append(np.array(fit(data[lo : hi + 1]).params, dtype=float))
        except CurveError:
            return
    y = np.concatenate(
        [
            *(np.array(p, dtype=float) for p in params[:i]),
            *halves,
            *(np.array(p, dtype=float) for p in params[i + 1 :]),
        ]
    )
    ss = [*sizes[:i], c + 1, sizes[i] - c, *sizes[i + 1 :]]
    yield _chain_from_free(_penalty_path(data, ss, y), ss), ss


def _move(x, sizes, j, d):
    """Move the joint after segment `j` by `d` vertices (segment ``j + 1`` restarts there)."""
    x = x.copy()
    sizes = list(sizes)
    sizes[j] += d
    sizes[j + 1] -= d
    x[9 + 4 * j] += x[8 + 4 * j] * d  # q_{j+1} += z_{j+1} d
    return x, sizes


class _Search:
    def __init__(self, data):
        self.data = data
        self.solves = 0
        self.free_fits = 0

    def solve(self, x, sizes, maxfev=None, free=None):
        self.solves += 1
        if maxfev is None:
            maxfev = max(_CHAIN_MAXFEV, 50 * x.size)
        x, cost, ok = _solve_chain(self.data, sizes, x, maxfev, free)
        return x, cost, ok

    def joints(self, x, sizes, cost, which, passes=3):
        """Search the positions of the joints `which` (the joint after segment ``j``).

        Coordinate descent: a pattern search per joint over index shifts halving from
        ``_JOINT_STEP`` down to one vertex, keeping a move that lowers the cost by ``_GAIN``,
        in passes over all joints until one moves none. A trial re-solves only the two
        segments next to the joint (the rest of the chain follows rigidly); the caller
        re-solves all.
        """
        which = [j for j in which if 0 <= j < len(sizes) - 1]
        first = True
        for _ in range(passes):
            any_moved = False
            for j in which:
                step = min(_JOINT_STEP if first else 2, max(1, min(sizes[j], sizes[j + 1]) // 8))
                while step >= 1:
                    moved = False
                    for d in (step, -step):
                        if min(sizes[j] + d, sizes[j + 1] - d) < MIN_SEGMENT_POINTS:
                            continue
                        xt, st = _move(x, sizes, j, d)
                        xt, ct, _ = self.solve(xt, st, _TRIAL_MAXFEV, _local(x.size, j))
                        if ct < cost * (1.0 - _GAIN):
                            x, sizes, cost, moved, any_moved = xt, st, ct, True, True
                            break
                    if not moved:
                        step //= 2
            first = False
            if not any_moved:
                break
        return x, sizes, cost


def _greedy(data, tolerance, max_segments, search):
    """Free segments, each the longest from the previous end within `tolerance`.

    Bisection on the end vertex; a probe is feasible if every data vertex of its range is
    within `tolerance` of its single fit's polyline. A probe first solves from the fit of
    the last feasible probe of the same start (the same curve, one solve) and runs the
    global search of :func:`.fit` only if that misses. Returns ``[(first, last, params)]``.
    """
    n = data.shape[0]
    out = []
    a = 0
    while True:
        warm = None
        last_segment = len(out) == max_segments - 1
        # the whole curve (a = 0) is the single fit, which missed
        p = _probe(data, a, n - 1, None, tolerance, search) if a and not last_segment else None
        if p is not None or last_segment or n - 1 - a < 2 * MIN_SEGMENT_POINTS:
            if p is None:
                p = fit(data[a:]).params
                search.free_fits += 1
            out.append((a, n - 1, p))
            return out
        lo, hi = a + MIN_SEGMENT_POINTS - 1, n - 1
        p_lo = None
        while hi - lo > 1:
            mid = (lo + hi) // 2
            p = _probe(data, a, mid, warm, tolerance, search)
            if p is not None:
                lo, p_lo, warm = mid, p, (p, mid)
            else:
                hi = mid
        if p_lo is None:
            p_lo = fit(data[a : lo + 1]).params
        if n - 1 - lo < 2 * MIN_SEGMENT_POINTS and n - 1 - a >= 2 * (MIN_SEGMENT_POINTS - 1):
            # the rest would be a short last segment, whose free fit (seven parameters on
            # a few vertices) is ill-determined and starts the chain in a chance basin:
            # the last two segments share the rest evenly
            mid = (a + n - 1) // 2
            p_mid = _probe(data, a, mid, (p_lo, lo), tolerance, search) or p_lo
            out.append((a, mid, p_mid))
            out.append((mid, n - 1, fit(data[mid:]).params))
            search.free_fits += 1
            return out
        if n - 1 - lo < MIN_SEGMENT_POINTS - 1:
            lo = n - MIN_SEGMENT_POINTS
        out.append((a, lo, p_lo))
        a = lo


def _probe(data, a, b, warm, tolerance, search):
    """Parameters of a fit of ``data[a..b]`` within `tolerance`, or None (see :func:`_greedy`)."""
    piece = data[a : b + 1]
    for start in (warm, None):
        try:
            res = fit(piece, start=None if start is None else start[0])
        except CurveError:
            continue
        search.free_fits += 1
        worst = float(_geom.point_polyline_distance(piece, res.points).max())
        if res.success and worst <= tolerance:
            return res.params
        if start is not None and res.success and worst > _CLEAR_MISS * tolerance:
            return None  # the warm fit converged far outside: no global search
    return None


def _deviations(raw, g_segments):
    """Distance of every raw point to the chain, and the index of its nearest segment."""
    per = np.stack([_geom.point_polyline_distance(raw, seg) for seg in g_segments])
    return per.min(axis=0), per.argmin(axis=0)


def _orient(raw: np.ndarray) -> bool:
    return bool(tuple(raw[-1].tolist()) < tuple(raw[0].tolist()))


def fit_segments(
    points: ArrayLike,
    tolerance: float,
    *,
    max_segments: int | None = None,
    resample: bool | float = True,
    max_iterations: int | None = None,
) -> SegmentFit:
    """Fewest discrete elasticae, joined G1, whose union is within `tolerance` of every point.

    Parameters
    ----------
    points : (M, 2) array_like
        Data in order along an open curve, ``M >= 5``, any spacing.
    tolerance : float
        Largest allowed geometric distance ``T > 0`` of an input point to the chained
        polyline, in data units.
    max_segments : int, optional
        Largest number of segments (default 12). If ``T`` is not met with that many,
        the result has ``within_tolerance`` False and its message says so.
    resample : bool or float, optional
        As in :func:`.fit` (default True: equal chords end to end; a float is the chord).
        The chain pairs data and model vertices by index, so unevenly spaced data need it.
    max_iterations : int, optional
        Passed to the single fit of the start (:func:`.fit`).

    Returns
    -------
    SegmentFit
        Segments (params, vertex range, rms, max deviation), joints (G1 defect, curvature
        jump), deviations, verdict.

    Raises
    ------
    CurveError
        Bad points or options (as :func:`.fit`), or `tolerance` not > 0.

    Examples
    --------
    Two discrete elasticae joined G1 (the second continues the first's vertex tangent):

    >>> import numpy as np
    >>> from curvesmith import elastica
    >>> a = elastica.sample((0, 0, 1.0, 0.0, 0.03, 0.2, 0.6), 120)
    >>> th = elastica.tangent_angles(a)[-1] + 0.5 * (elastica.tangent_angles(a)[-1]
    ...                                             - elastica.tangent_angles(a)[-2])
    >>> b = elastica.sample((*a[-1], 1.0, th, 0.02, 0.0, 3.0), 120)  # k = 3, no inflection
    >>> res = elastica.fit_segments(np.vstack([a, b[1:]]), 0.05)
    >>> len(res.segments), bool(res.within_tolerance), bool(res.max_deviation <= 0.05)
    (2, True, True)
    >>> bool(res.joints[0].g1_defect < 1e-9)
    True
    """
    tolerance = as_float(tolerance, name="tolerance", low=0.0)
    if not tolerance > 0:
        raise CurveError(f"tolerance must be > 0, got {tolerance}")
    if max_segments is None:
        max_segments = DEFAULT_MAX_SEGMENTS
    max_segments = as_int(max_segments, name="max_segments", minimum=1)
    if resample is False or resample is None:
        raw = as_points(points, min_points=5, distinct=True)
    else:
        raw = _geom.drop_repeats(as_points(points, min_points=5))
        if raw.shape[0] < 5:
            raise CurveError(f"points must have at least 5 distinct points, got {raw.shape[0]}")
    rev = _orient(raw)
    work = np.ascontiguousarray(raw[::-1] if rev else raw)
    single = fit(work, resample=resample, tolerance=tolerance, max_iterations=max_iterations)
    data = single.data
    n = data.shape[0]
    p = single.params
    x = np.array([p.x0, p.y0, p.phi, p.h, p.z, p.q, p.k], dtype=float)
    sizes = [n]
    ok_all = bool(single.success)
    search = _Search(data)
    if single.within_tolerance or max_segments == 1:
        dev = single.deviation
        assert dev is not None  # elastica.fit measures every point
        near = np.zeros(dev.size, dtype=int)
    else:
        free = _greedy(data, tolerance, max_segments, search)
        sizes = [b - a + 1 for a, b, _ in free]
        y = np.concatenate([np.array(p, dtype=float) for _, _, p in free])
        x = _chain_from_free(_penalty_path(data, sizes, y), sizes)
        x, cost, _ = search.solve(x, sizes)
        x, sizes, cost = search.joints(x, sizes, cost, range(len(sizes) - 1))
        x, cost, ok_all = search.solve(x, sizes)
        dev, near = _deviations(work, _segment_vertices(x, sizes))
    while dev.max() > tolerance and len(sizes) < max_segments:
        seg_max = np.array(
            [dev[near == i].max() if np.any(near == i) else 0.0 for i in range(len(sizes))]
        )
        i = _to_split(seg_max, sizes, tolerance)
        if i is None:
            break
        best: tuple | None = None
        c = (sizes[i] - 1) // 2
        for xs, ss in _split_starts(data, x, sizes, i, c):
            xs, cs, _ = search.solve(xs, ss, _CHAIN_MAXFEV)
            if best is None or cs < best[2]:
                best = (xs, ss, cs)
        assert best is not None  # _split_starts yields at least one start
        x, sizes, cost = best
        x, sizes, cost = search.joints(x, sizes, cost, (i - 1, i, i + 1))
        x, cost, ok_all = search.solve(x, sizes)
        dev, near = _deviations(work, _segment_vertices(x, sizes))
    return _result(data, x, sizes, dev, near, tolerance, max_segments, single, ok_all, search, rev)


def _to_split(seg_max, sizes, tolerance):
    """The segment to split: the worst one beyond `tolerance` that has room for two.

    A segment beyond `tolerance` too short to split (fewer than ``2 MIN_SEGMENT_POINTS - 1``
    vertices) is served by splitting its longer neighbour: the joint search next to the
    split can then move its joints. Only if no segment beyond `tolerance` or next to one can
    be split, the worst splittable segment; None if there is none.
    """
    splittable = [sz >= 2 * MIN_SEGMENT_POINTS - 1 for sz in sizes]
    for i in np.argsort(-seg_max, kind="stable"):
        if seg_max[i] <= tolerance:
            break
        if splittable[i]:
            return int(i)
        near = [j for j in (i - 1, i + 1) if 0 <= j < len(sizes) and splittable[j]]
        if near:
            return int(max(near, key=lambda j: sizes[j]))
    order = [int(i) for i in np.argsort(-seg_max, kind="stable") if splittable[i]]
    return order[0] if order else None


def _segment_vertices(x, sizes):
    g, _, _ = _chain(x, sizes, False)
    out, start = [], 0
    for n in sizes:
        out.append(g[start : start + n].view(float).reshape(-1, 2))
        start += n - 1
    return out


def _params_of(x, sizes):
    """Per-segment ElasticaParams of the chain (start vertex and derived rotation)."""
    g, _, angles = _chain(x, sizes, False)
    out, start = [], 0
    for i, n in enumerate(sizes):
        h, z, q, k = (float(v) for v in x[3 + 4 * i : 7 + 4 * i])
        out.append(
            ElasticaParams(float(g[start].real), float(g[start].imag), h, angles[i][0], z, q, k)
        )
        start += n - 1
    return out, angles


def _result(data, x, sizes, dev, near, tolerance, max_segments, single, ok_all, search, rev):
    n = data.shape[0]
    if len(sizes) == 1:
        params = [single.params]
        verts = [single.points]
    else:
        params, _ = _params_of(x, sizes)
        verts = _segment_vertices(x, sizes)
    firsts = np.concatenate([[0], np.cumsum(np.array(sizes[:-1]) - 1)]).astype(int)
    if rev:  # back to the input's order
        params = [_reverse_params(p, sz) for p, sz in zip(params[::-1], sizes[::-1], strict=True)]
        verts = [v[::-1] for v in verts[::-1]]
        firsts = (n - 1) - (firsts[::-1] + np.array(sizes[::-1]) - 1)
        sizes = sizes[::-1]
        near = len(sizes) - 1 - near
        data = data[::-1].copy()
        dev = dev[::-1]
        near = near[::-1]
    pts = np.vstack([verts[0], *[v[1:] for v in verts[1:]]])
    segments = []
    for i, (p, v, f, sz) in enumerate(zip(params, verts, firsts, sizes, strict=True)):
        d = v - data[f : f + sz]
        mine = dev[near == i]
        segments.append(
            Segment(
                params=p,
                first=int(f),
                last=int(f + sz - 1),
                points=v,
                rms=float(np.sqrt(np.mean(np.sum(d * d, axis=1)))),
                max_deviation=float(mine.max()) if mine.size else 0.0,
            )
        )
    joints = []
    for i in range(len(segments) - 1):
        a, b = segments[i], segments[i + 1]
        na = a.last - a.first + 1
        th_a = _vertex_theta(a.params, na, last=True)
        th_b = _vertex_theta(b.params, b.last - b.first + 1, last=False)
        defect = abs(math.remainder(th_a - th_b, 2.0 * math.pi))
        e1 = pts[a.last] - pts[a.last - 1]
        e2 = pts[a.last + 1] - pts[a.last]
        turn = math.atan2(e1[0] * e2[1] - e1[1] * e2[0], float(e1 @ e2))
        ka = float(exact_curvature(a.params, na)[-1])
        kb = float(exact_curvature(b.params, b.last - b.first + 1)[0])
        joints.append(Joint(i, int(a.last), defect, turn, ka, kb, kb - ka))
    diff = pts - data
    rms = float(np.sqrt(np.mean(np.sum(diff * diff, axis=1))))
    max_dev = float(dev.max())
    within = bool(max_dev <= tolerance)
    m = len(segments)
    if within:
        msg = (
            f"{m} segment{'s' if m > 1 else ''} within the tolerance {tolerance:g}: "
            f"max deviation {max_dev:.3g}"
        )
    else:
        msg = (
            f"the tolerance {tolerance:g} is not met with {m} segment{'s' if m > 1 else ''} "
            f"(max_segments = {max_segments}, at least {MIN_SEGMENT_POINTS} vertices each): "
            f"max deviation {max_dev:.3g}"
        )
    if not ok_all:
        msg += "; the final chain solve did not converge (evaluation cap)"
    return SegmentFit(
        segments=tuple(segments),
        joints=tuple(joints),
        points=pts,
        data=data,
        deviation=dev,
        max_deviation=max_dev,
        rms_deviation=float(np.sqrt(np.mean(dev**2))),
        rms=rms,
        tolerance=tolerance,
        within_tolerance=within,
        success=bool(ok_all),
        message=msg,
        single=single,
        solves=search.solves,
    )


def _vertex_theta(p: ElasticaParams, n: int, *, last: bool) -> float:
    """Vertex tangent ``theta_n = phi + 2 a_n`` (eq. 4.3) at the first or last vertex."""
    s = np.array([p.z * (n - 1) + p.q if last else p.q])
    S, C = _half_angles(s, p.k)
    return p.phi + 2.0 * math.atan2(float(S[0]), float(C[0]))
