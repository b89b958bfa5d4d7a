"""Approximation of planar curves by affine arc length polylines (Käferböck, section 4).

The pipeline of section 4.3:

1. *Preprocessing* (section 4.1, Fig. 9): the dense samples ``p_j`` are joined
   by parabolic arcs whose tangent at ``p_j`` is parallel to
   ``p_{j+1} - p_{j-1}``; the result is the replacement curve ``f~(t)``,
   ``f~(j) = p_j``, each unit of ``t`` one quadratic Bézier arc.
2. The exact affine arc length of every arc is eq. (15),
   ``S_j = (4 A*_j A*_{j+1} / (A*_j + B*_j + A*_{j+1}))^(1/3)``; the affine length
   grows *linearly* in ``t`` on each arc (``det(f~', f~'')`` is constant on a
   parabola), so it is inverted exactly. ``A = (S / n)^3``.
3. ``x_0 = f~(0)``, ``x_1 = f~(t_1)`` and every further ``x_i`` is the first
   intersection of ``f~`` after ``x_{i-1}`` with the line
   ``det(x_{i-1} - x_{i-2}, z - x_{i-1}) = A`` (a quadratic equation per arc).
4. ``t_1`` minimises ``psi(t_1) = sum_i (k_{i+1} - k_i)^2`` by a one-dimensional
   search (section 4.2).

Curves with inflections are split at the inflections of ``f~`` (section 4.4)
and closed convex curves are closed up by adjusting ``A`` and ``t_1`` together.

Notes on the paper
------------------
* Eq. (15) was checked against ``(4 det(c - p_j, p_{j+1} - c))^(1/3)`` of the
  Bézier arc with control point ``c`` (tests), and against numerical
  integration of ``det(f', f'')^(1/3)``.
* Section 4.4, step 3, prints ``A := (S~_i - S~_{i-1}) / (n_i - n_{i-1})``; an
  affine length per edge must be cubed to give the area constant, as in
  ``A = (S / n)^3`` of section 4.2. The cube is used here.
* Section 4 defines ``S_i`` as the affine arc length "from ``x_i`` to
  ``x_{i-1}``" with the integral over ``[t_i, t_{i+1}]``: it runs from ``x_i``
  to ``x_{i+1}``.
* The initial ``t_1`` is the exact fractional parameter with affine length
  ``S / n`` from ``x_0`` (the paper rounds it to an integer "for simplicity").
* The end tangents of ``f~`` (not specified in the paper) are those of the
  parabola through the first (last) three samples, ``3 v_0 - v_1``; then the
  first arc is a piece of that parabola and ``S_0 = A*_1^(1/3)``.
"""

from __future__ import annotations

import bisect
import dataclasses
import math
from dataclasses import dataclass, field
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike
from scipy.optimize import least_squares, minimize_scalar

from .._rich import RichRepr
from .._validate import as_choice, as_float, as_int, as_points
from ..errors import CurveError

__all__ = ["Approximation", "ReplacementCurve", "approximate", "construct", "replacement_curve"]

_PHI = (math.sqrt(5.0) - 1.0) / 2.0  # 0.618...
# match_end: x_n within this many affine edge lengths of the curve's end (the refits of A
# converge linearly by a factor ~1e-3 each, so this costs 3-4 extra searches)
_END_TOL = 1e-10


@dataclass(frozen=True)
class ReplacementCurve:
    """Piecewise parabolic replacement curve ``f~`` of dense samples (section 4.1).

    Attributes
    ----------
    samples : (M, 2) ndarray
        The samples ``p_j`` (``M = N + 1`` open, ``M = N`` closed).
    controls : (N, 2) ndarray
        Bézier control point of arc ``j`` (from ``p_j`` to ``p_{j+1}``); the
        midpoint of the chord for a degenerate (straight or S-shaped) arc.
    lengths : (N,) ndarray
        Signed affine arc length ``S_j`` of every arc (eq. 15 for interior arcs of
        an open curve and all arcs of a closed one); positive for left turns, 0
        for degenerate arcs.
    closed : bool
        Periodic curve, ``f~(t + N) = f~(t)``.
    """

    samples: np.ndarray
    controls: np.ndarray
    lengths: np.ndarray
    closed: bool
    cumulative: np.ndarray = field(repr=False)

    @property
    def segments(self) -> int:
        """Number of parabolic arcs ``N``."""
        return int(self.controls.shape[0])

    @property
    def total_length(self) -> float:
        """Signed total affine arc length ``S = sum_j S_j``."""
        return float(self.cumulative[-1])

    def evaluate(self, t: ArrayLike) -> np.ndarray:
        """Points ``f~(t)``; the end arcs of an open curve are extended beyond ``[0, N]``.

        Parameters
        ----------
        t : (K,) array_like
            Parameters in sample units.

        Returns
        -------
        (K, 2) ndarray
        """
        t = np.atleast_1d(np.asarray(t, dtype=float))
        n = self.segments
        if self.closed:
            t = np.mod(t, n)
        j = np.clip(np.floor(t).astype(int), 0, n - 1)
        u = (t - j)[:, None]
        p = self.samples[j]
        q = self.samples[(j + 1) % self.samples.shape[0]]
        c = self.controls[j]
        return (1 - u) ** 2 * p + 2 * u * (1 - u) * c + u**2 * q

    def affine_length_at(self, t: ArrayLike) -> np.ndarray:
        """Signed affine arc length ``s(t)`` from ``f~(0)`` (piecewise linear in ``t``)."""
        t = np.atleast_1d(np.asarray(t, dtype=float))
        n = self.segments
        turns = np.floor(t / n) if self.closed else np.zeros_like(t)
        r = t - turns * n
        j = np.clip(np.floor(r).astype(int), 0, n - 1)
        return turns * self.total_length + self.cumulative[j] + (r - j) * self.lengths[j]

    def inflections(self) -> np.ndarray:
        """Integer parameters where the arcs change their turning direction (section 4.4, step 1).

        Degenerate arcs (``S_j = 0``) between a left and a right turning run put the
        inflection at the middle integer of the run.

        Returns
        -------
        (K,) ndarray of int
        """
        s = np.sign(self.lengths)
        nz = np.flatnonzero(s)
        if nz.size < 2:
            return np.zeros(0, dtype=int)
        change = np.flatnonzero(s[nz[1:]] != s[nz[:-1]])
        return np.array([(nz[c] + 1 + nz[c + 1]) // 2 for c in change], dtype=int)


def replacement_curve(samples: ArrayLike, *, closed: bool = False) -> ReplacementCurve:
    """Build the piecewise parabolic replacement curve of dense samples (section 4.1, Fig. 9).

    The arc from ``p_j`` to ``p_{j+1}`` is the parabola tangent to
    ``p_{j+1} - p_{j-1}`` at ``p_j`` and to ``p_{j+2} - p_j`` at ``p_{j+1}``. For
    an open curve the end tangents are ``3 v_0 - v_1`` and
    ``3 v_{N-1} - v_{N-2}`` (tangents of the parabola through three end samples).
    An arc whose two tangents do not admit a convex parabola (near an
    inflection, or on a straight run) is replaced by its chord (``S_j = 0``).

    Parameters
    ----------
    samples : (M, 2) array_like
        Dense samples of the curve, no repeated consecutive points, ``M >= 4``.
    closed : bool, optional
        Closed curve (a repeated closing sample is dropped).

    Returns
    -------
    ReplacementCurve

    Examples
    --------
    Samples of a parabola at equal parameter steps are reproduced exactly:

    >>> t = np.linspace(-1, 1, 5)
    >>> f = replacement_curve(np.c_[t, t**2])
    >>> np.allclose(f.evaluate([0.5, 1.5]), [[-0.75, 0.5625], [-0.25, 0.0625]])
    True
    """
    p = as_points(samples, name="samples", closed=closed, min_points=4, distinct=True)
    return _replacement(p, closed)


def _replacement(p: np.ndarray, closed: bool) -> ReplacementCurve:
    if closed:
        v = np.roll(p, -1, axis=0) - p
        d = np.roll(v, 1, axis=0) + v  # tangent at p_j: p_{j+1} - p_{j-1}
        d_next = np.roll(d, -1, axis=0)
        d_here = d
        q = np.roll(p, -1, axis=0)
        p0 = p
    else:
        v = np.diff(p, axis=0)
        d = np.empty_like(p)
        d[1:-1] = v[:-1] + v[1:]
        d[0] = 3.0 * v[0] - v[1]
        d[-1] = 3.0 * v[-1] - v[-2]
        d_here, d_next = d[:-1], d[1:]
        q = p[1:]
        p0 = p[:-1]
    den = d_here[:, 0] * d_next[:, 1] - d_here[:, 1] * d_next[:, 0]
    num_a = v[:, 0] * d_next[:, 1] - v[:, 1] * d_next[:, 0]
    num_b = d_here[:, 0] * v[:, 1] - d_here[:, 1] * v[:, 0]
    scale = np.abs(d_here[:, 0] * d_next[:, 1]) + np.abs(d_here[:, 1] * d_next[:, 0])
    ok = np.abs(den) > 1e-12 * scale
    safe = np.where(ok, den, 1.0)
    alpha = np.where(ok, num_a / safe, 0.0)
    beta = np.where(ok, num_b / safe, 0.0)
    ok &= (alpha > 0) & (beta > 0)
    controls = np.where(ok[:, None], p0 + alpha[:, None] * d_here, 0.5 * (p0 + q))
    lengths = np.where(ok, np.cbrt(4.0 * alpha * beta * den), 0.0)
    big = np.max(np.abs(lengths)) if lengths.size else 0.0
    lengths = np.where(np.abs(lengths) > 1e-9 * big, lengths, 0.0)
    cumulative = np.concatenate([[0.0], np.cumsum(lengths)])
    return ReplacementCurve(
        samples=p, controls=controls, lengths=lengths, closed=closed, cumulative=cumulative
    )


# --------------------------------------------------------------------------- construction


class _Curve:
    """Python-float view of a replacement curve for the scalar construction loop."""

    def __init__(self, rc: ReplacementCurve):
        p, c = rc.samples, rc.controls
        n = rc.segments
        q = p[(np.arange(n) + 1) % p.shape[0]]
        a2 = 2.0 * (c - p[:n])
        e = p[:n] - 2.0 * c + q
        self.n = n
        self.closed = rc.closed
        self.px, self.py = p[:, 0].tolist(), p[:, 1].tolist()
        self.ax, self.ay = a2[:, 0].tolist(), a2[:, 1].tolist()
        self.ex, self.ey = e[:, 0].tolist(), e[:, 1].tolist()
        # the same numbers as arrays, for the compiled construction
        self.arrays = tuple(
            np.ascontiguousarray(v, dtype=np.float64)
            for v in (p[:, 0], p[:, 1], a2[:, 0], a2[:, 1], e[:, 0], e[:, 1])
        )
        self.cum = rc.cumulative.tolist()
        self.ncum = (-rc.cumulative).tolist()
        self.len = rc.lengths.tolist()
        self.total = float(rc.cumulative[-1])
        self.rc = rc

    def point(self, t: float) -> tuple[float, float]:
        n = self.n
        j = math.floor(t)
        jj = j % n if self.closed else min(max(j, 0), n - 1)
        u = t - (j if self.closed or 0 <= j <= n - 1 else jj)
        return (
            self.px[jj] + u * (self.ax[jj] + u * self.ex[jj]),
            self.py[jj] + u * (self.ay[jj] + u * self.ey[jj]),
        )

    def s_of_t(self, t: float) -> float:
        n = self.n
        if self.closed:
            turns = math.floor(t / n)
            r = t - turns * n
            j = min(int(r), n - 1)
            return turns * self.total + self.cum[j] + (r - j) * self.len[j]
        j = min(max(math.floor(t), 0), n - 1)
        return self.cum[j] + (t - j) * self.len[j]

    def t_of_s(self, s: float, sign: float, lo: int = 0, hi: int | None = None) -> float:
        """Parameter with signed affine length `s`, searched on the arcs ``lo .. hi - 1``.

        The affine length is monotone only on an inflection-free part of the
        curve, so the search is restricted to the arcs of the current piece.
        """
        n = self.n
        turns = 0.0
        if self.closed:
            turns = math.floor(s / self.total)
            s = s - turns * self.total
            lo, hi = 0, n
        else:  # a piece's search may ask one arc past the last (lo = n): the last arc
            hi = n if hi is None else min(hi, n)
            lo = min(lo, hi - 1)
        cum = self.cum if sign > 0 else self.ncum
        ss = s if sign > 0 else -s
        j = bisect.bisect_right(cum, ss, lo, hi + 1) - 1
        j = min(max(j, lo, 0), hi - 1, n - 1)
        # skip degenerate arcs (zero length) forward
        seg = self.len[j] * (1 if sign > 0 else -1)
        if seg <= 0:
            return turns * n + j
        return turns * n + j + (ss - cum[j]) / seg


def _construct(
    cv: _Curve,
    t0: float,
    t1: float,
    area: float,
    m: int,
    t_end: float,
    u_max: float = 4.0,
    extrapolate: bool = True,
):
    """Vertices x_0 .. x_m of the affine arc length polyline from x_0 = f~(t0), x_1 = f~(t1).

    Each new vertex is the first intersection after ``x_{i-1}`` of ``f~`` with the
    line ``det(x_{i-1} - x_{i-2}, z - x_{i-1}) = A``. The arc holding it is found by
    a galloping search over the samples, started at the guess "same parameter
    step as the previous edge" (``g(z) = det(w, z - x_{i-1})`` increases while the
    tangent has not turned past ``w``, which is checked at the guess and at every
    forward probe), then a quadratic equation is solved on that arc. The cost per vertex
    is logarithmic in the samples per edge, so a construction is O(n log(N/n)).
    For an open curve the last arc before ``t_end`` is extrapolated up to
    ``u_max`` or two previous edges (in parameter) beyond the last vertex.
    With ``extrapolate=False`` (pieces ending at an inflection) the last vertex must
    lie on the curve, ``t <= t_end``: the next piece starts at ``f~(t)`` on the next
    arc, which is another point than one on the extrapolated arc.
    The loop is compiled (:mod:`curvesmith.affine._kernel`).
    Returns ``(xs, ys, ts, done)``, ``done`` = edges constructed.
    """
    n = cv.n
    jlast = n - 1 if cv.closed else min(n - 1, math.ceil(t_end) - 1)
    x0, y0 = cv.point(t0)
    x1, y1 = cv.point(t1)
    xs, ys, ts, count, done = _compiled().construct(
        *cv.arrays,
        bool(cv.closed),
        float(x0),
        float(y0),
        float(x1),
        float(y1),
        float(t0),
        float(t1),
        float(area),
        int(m),
        int(jlast),
        float(u_max),
        bool(extrapolate),
    )
    return xs[:count].tolist(), ys[:count].tolist(), ts[:count].tolist(), int(done)


def _compiled():
    """The compiled construction (numba is imported on the first construction only)."""
    from . import _kernel

    return _kernel


def _curvatures(xs: list[float], ys: list[float], area: float) -> list[float]:
    """k_i = 2 - B_i / A for i = 1 .. m-2 (list index i-1)."""
    vx = [xs[i + 1] - xs[i] for i in range(len(xs) - 1)]
    vy = [ys[i + 1] - ys[i] for i in range(len(ys) - 1)]
    return [2.0 - (vx[i] * vy[i + 2] - vy[i] * vx[i + 2]) / area for i in range(len(vx) - 2)]


def _psi(k: list[float], skip_lo: int, skip_hi: int) -> float:
    seq = k[skip_lo : len(k) - skip_hi]
    return sum((seq[i + 1] - seq[i]) ** 2 for i in range(len(seq) - 1))


def construct(
    curve: ReplacementCurve, *, t1: float, area: float, vertices: int, t0: float = 0.0
) -> tuple[np.ndarray, np.ndarray]:
    """Affine arc length polyline on a replacement curve from ``x_0, x_1`` and ``A`` (section 4).

    ``x_0 = f~(t0)``, ``x_1 = f~(t1)``, and each further vertex is the first
    intersection of ``f~`` after ``x_{i-1}`` with the line
    ``det(x_{i-1} - x_{i-2}, z - x_{i-1}) = A``. This is the inner step of
    :func:`approximate`; use it to study the sensitivity to ``t_1`` (Fig. 11).

    Parameters
    ----------
    curve : ReplacementCurve
        From :func:`replacement_curve`.
    t1 : float
        Parameter of ``x_1``, ``> t0``.
    area : float
        The constant ``A`` (its sign is the turning direction).
    vertices : int
        Number of vertices ``>= 3`` to construct.
    t0 : float, optional
        Parameter of ``x_0``.

    Returns
    -------
    points : (vertices, 2) ndarray
    t : (vertices,) ndarray
        Parameters of the vertices on `curve`.

    Raises
    ------
    CurveError
        If the line misses the curve before all vertices are built.

    Examples
    --------
    >>> s = np.linspace(0, 4, 41)
    >>> pts, t = construct(replacement_curve(np.c_[s, s**2]), t1=5.0, area=0.25, vertices=4)
    >>> np.round(t, 9).tolist()
    [0.0, 5.0, 10.0, 15.0]
    """
    vertices = as_int(vertices, name="vertices", minimum=3)
    area = as_float(area, name="area")
    if area == 0.0:
        raise CurveError("area must be non-zero, got 0")
    t0 = as_float(t0, name="t0")
    t1 = as_float(t1, name="t1", low=t0)
    cv = _Curve(curve)
    xs, ys, ts, done = _construct(cv, t0, t1, area, vertices - 1, float(cv.n))
    if done < vertices - 1:
        raise CurveError(
            f"the line det(x_i - x_(i-1), z - x_i) = A misses the curve after vertex {done}: "
            f"only {done + 1} of {vertices} vertices could be constructed"
        )
    return np.c_[xs, ys], np.asarray(ts)


# --------------------------------------------------------------------------- result


@dataclass(frozen=True)
class Approximation(RichRepr):
    """Result of :func:`approximate`.

    Attributes
    ----------
    points : (M, 2) ndarray
        The affine arc length polyline ``x_0 .. x_n`` (open, ``M = n + 1``) or the
        closed polygon ``x_0 .. x_{n-1}`` (``M = n``, first vertex not repeated).
    area : float
        The constant ``A = det(x_i - x_{i-1}, x_{i+1} - x_i)``; for a curve split at
        inflections, the ``A`` of the first piece (all in `piece_areas`).
    curvature : (M - 3,) ndarray, or (M,) if closed
        Discrete affine curvatures ``k_i = 2 - B_i / A`` (eq. 4), aligned like
        :func:`curvesmith.affine.curvature`. Values marked False in `valid`
        straddle an inflection and carry no meaning (paper, Fig. 13).
    kappa_m : ndarray
        ``k_i |A|^(-2/3)``, the affine curvature of the middle osculating conic
        (eq. 7), an estimate of the smooth affine curvature.
    valid : ndarray of bool
        Whether the quadruple of ``k_i`` lies within one affine arc length piece.
    t : (M,) ndarray
        Parameters of the vertices on the replacement curve, in sample units
        (``x_i = f~(t_i)``; may exceed the last sample where the final arc was
        extrapolated). Closed curves: increasing from ``t_0`` in ``[0, N)``
        (``x_0`` is moved off the first sample when closing needs it).
    t1 : float
        The optimised parameter of ``x_1``.
    objective : float
        ``psi = sum_i (k_{i+1} - k_i)^2`` at the optimum (over the differences used
        in the optimisation, i.e. without skipped curvatures near inflections).
    success : bool
        Whether every vertex was constructed (and, for a closed curve, the polygon
        closed within tolerance).
    message : str
        What happened.
    closed : bool
        Closed polygon.
    closing_error : float
        Closed curves: ``max(|x_n - x_0|, |x_{n+1} - x_1|)`` before dropping the
        repeated vertices (0 for open curves).
    end_gap : float
        Open curves: affine length from ``x_n`` to the end of the curve, in units
        of the affine edge length ``|A|^(1/3)`` (negative: ``x_n`` lies beyond;
        ``inf`` if the construction failed). 0 for closed curves. With the
        paper's ``A = (S/n)^3`` it is a few hundredths for samples at uniform
        parameter steps; samples at irregular steps bias the affine length of the
        replacement curve (its tangents assume uniform steps) and the gap can
        exceed an edge (the message says so): ``match_end=True`` fixes ``A``.
    piece_areas : (P,) ndarray
        Signed ``A`` of every affine arc length piece (one per inflection-free
        part of the curve).
    joins : (P - 1,) ndarray of int
        Indices of the vertices shared by consecutive pieces.
    evaluations : int
        Number of polyline constructions performed.
    """

    points: np.ndarray
    area: float
    curvature: np.ndarray
    kappa_m: np.ndarray
    valid: np.ndarray
    t: np.ndarray
    t1: float
    objective: float
    success: bool
    message: str
    closed: bool
    closing_error: float
    end_gap: float
    piece_areas: np.ndarray
    joins: np.ndarray
    evaluations: int


# --------------------------------------------------------------------------- search


class _Piece:
    """One inflection-free part: construct with a given A, optimise t1."""

    def __init__(self, cv, t0, t_end, m, sign, skip_lo, skip_hi, penalty_scale):
        self.cv, self.t0, self.t_end, self.m = cv, t0, t_end, m
        self.sign, self.skip_lo, self.skip_hi = sign, skip_lo, skip_hi
        self.penalty = penalty_scale
        self.evaluations = 0
        self.extrapolate = True  # False: x_m must lie on the curve (piece ends at an inflection)

    def objective(self, t1: float, area: float) -> float:
        self.evaluations += 1
        xs, ys, _, done = _construct(
            self.cv, self.t0, t1, area, self.m, self.t_end, extrapolate=self.extrapolate
        )
        if done < self.m:
            return self.penalty * (2.0 - done / self.m)
        return _psi(_curvatures(xs, ys, area), self.skip_lo, self.skip_hi)

    def search(self, area: float, search: str, xtol: float, iterations: int) -> float:
        step = abs(area) ** (1.0 / 3.0)
        s0 = self.cv.s_of_t(self.t0)
        lo = max(math.floor(self.t0), 0)
        hi = self.cv.n if self.cv.closed else min(self.cv.n, math.ceil(self.t_end))
        t1 = self.cv.t_of_s(s0 + self.sign * step, self.sign, lo, max(hi, lo + 1))
        h = max(t1 - self.t0, 1e-9)
        a, d = self.t0 + 1e-6 * h, self.t0 + 2.0 * h  # the paper's interval [0, 2 t_1]
        # coarse bracket (guards against a non-unimodal psi far from the optimum)
        grid = [a + (d - a) * i / 8 for i in range(9)]
        vals = [self.objective(g, area) for g in grid]
        i = min(range(9), key=vals.__getitem__)
        lo, hi = grid[max(i - 1, 0)], grid[min(i + 1, 8)]
        tol = xtol * h
        if search == "golden":
            return self._golden(lo, hi, area, tol, iterations)
        res = minimize_scalar(
            lambda x: self.objective(x, area),
            bounds=(lo, hi),
            method="bounded",
            options={"xatol": tol, "maxiter": iterations},
        )
        return float(res.x)

    def _golden(self, a: float, d: float, area: float, tol: float, iterations: int) -> float:
        """Golden section search exactly as in section 4.2 of the paper."""
        b = d - _PHI * (d - a)
        c = a + _PHI * (d - a)
        fb, fc = self.objective(b, area), self.objective(c, area)
        for _ in range(iterations):
            if d - a <= tol:
                break
            if fb < fc:  # minimum not in (c, d]
                a, b, c, d = a, a + c - b, b, c
                fc, fb = fb, self.objective(b, area)
            else:
                a, b, c, d = b, c, b + d - c, d
                fb, fc = fc, self.objective(c, area)
        return 0.5 * (b + c)


def approximate(
    samples: ArrayLike,
    *,
    vertices: int,
    closed: bool = False,
    search: Literal["brent", "golden"] = "brent",
    xtol: float = 1e-10,
    max_iterations: int = 200,
    skip: int = 2,
    match_end: bool = True,
    close_tol: float = 1e-7,
) -> Approximation:
    """Approximate a curve by an affine arc length polyline with smooth curvatures (section 4).

    The control polygon returned makes a curvature continuous uniform quadratic
    B-spline (section 2.5); its ``kappa_m`` approximate the affine curvature of
    the sampled curve (Table 1).

    Parameters
    ----------
    samples : (N, 2) array_like
        Dense samples of the curve in order, no repeated consecutive points; the
        paper suggests about 20 samples per vertex (Table 1). At least
        ``2 * vertices`` samples are required.
    vertices : int
        Number of polyline vertices, ``>= 4`` (``n + 1`` for an open curve, whose
        edges number ``n``; ``n`` for a closed one).
    closed : bool, optional
        The samples describe a closed convex curve (repeated closing sample
        dropped). The polygon then closes up with the same ``A`` across the seam:
        ``A`` and ``t_1`` are adjusted together (Levenberg–Marquardt, with the
        smoothness of the ``k_i`` as a weak extra objective) so that ``x_n = x_0``
        and ``x_{n+1} = x_1``. Near an ellipse with even ``n`` these two
        conditions are almost dependent (Theorem 1: alternating polygons close
        too); if they are not met, ``x_0 = f~(t_0)`` is released as a third unknown.
    search : {"brent", "golden"}, optional
        One-dimensional minimiser of ``psi(t_1)``: scipy's bounded Brent method
        (golden section with parabolic steps, fewer evaluations) or the plain
        golden section search of section 4.2. Both start from a 9-point scan of
        the paper's interval ``[0, 2 t_1]``.
    xtol : float, optional
        Final interval width of the search relative to the initial ``t_1``.
    max_iterations : int, optional
        Iteration limit of the search.
    skip : int, optional
        For curves with inflections: curvatures ``l`` skipped at both ends of
        every inflection-free piece in the objective (section 4.4, step 3).
    match_end : bool, optional
        Open curves: adjust ``A`` (re-optimising ``t_1`` each time) until ``x_n``
        is the end of the curve (within ``1e-10`` affine edge lengths), so that
        every vertex lies on the sampled curve. The paper keeps ``A = (S/n)^3``;
        then the construction runs past the last sample and ``x_n`` lies on the
        extrapolated last arc, a few hundredths of an edge beyond the end (False).
        Matching changes ``A`` by ``3 |end gap| / n`` relative (0.2 % for the
        Table 1 curve with 60 vertices) and keeps the Table 1 accuracy. Pieces
        ending at an inflection are always re-fitted when their last vertex is more
        than a quarter edge from it (section 4.4, step 3).
    close_tol : float, optional
        Closed curves: closing error allowed, relative to the diagonal of the
        bounding box of the samples. The closure equations are only piecewise
        smooth (the affine length of the replacement curve has kinks at the
        samples), which limits the attainable error to about 1e-9 relative.

    Returns
    -------
    Approximation

    Raises
    ------
    CurveError
        For too few samples or vertices, a straight line (no affine length),
        a closed curve with inflections, or too few vertices for the number of
        inflection pieces.

    Examples
    --------
    An ellipse with semi-axes 2 and 1 is approximated by an affinely regular
    20-gon; its outer osculating conics are the ellipse, affine curvature
    ``2^(-2/3)`` (the middle ones, ``kappa_m``, differ by ``(1 - k/4)^(-1/3)``):

    >>> from curvesmith.affine import osculating_curvatures
    >>> u = np.linspace(0, 2 * np.pi, 401)[:-1]
    >>> res = approximate(np.c_[2 * np.cos(u), np.sin(u)], vertices=20, closed=True)
    >>> kappa_o, _, _ = osculating_curvatures(res.points, closed=True)
    >>> res.success, bool(np.allclose(kappa_o, 2 ** (-2 / 3), rtol=1e-9))
    (True, True)
    """
    vertices = as_int(vertices, name="vertices", minimum=4)
    as_choice(search, ("brent", "golden"), name="search")
    xtol = as_float(xtol, name="xtol", low=0.0)
    max_iterations = as_int(max_iterations, name="max_iterations", minimum=1)
    skip = as_int(skip, name="skip", minimum=0)
    close_tol = as_float(close_tol, name="close_tol", low=0.0)
    p = as_points(samples, name="samples", closed=closed, min_points=4, distinct=True)
    if p.shape[0] < 2 * vertices:
        raise CurveError(
            f"samples must have at least 2 * vertices = {2 * vertices} points "
            f"for vertices={vertices}, "
            f"got {p.shape[0]} (about 20 per vertex are recommended)"
        )
    # Affine arc length is translation invariant, but the equal-area construction is not
    # numerically: with georeferenced coordinates (UTM, ~5e6) the determinants cancel
    # catastrophically (psi grew from 1e-25 to 2e-3, closed curves failed to close at 1e8).
    # Work relative to the first sample, which comes back exactly.
    origin = p[0].copy()
    p = p - origin
    result = _approximate_centred(
        p, closed, vertices, search, xtol, max_iterations, skip, close_tol, match_end
    )
    if not origin.any():
        return result
    return dataclasses.replace(result, points=result.points + origin)


def _approximate_centred(
    p, closed, vertices, search, xtol, max_iterations, skip, close_tol, match_end
) -> Approximation:
    rc = _replacement(p, closed)
    diag = float(np.hypot(*(p.max(axis=0) - p.min(axis=0))))
    total_abs = float(np.sum(np.abs(rc.lengths)))
    if total_abs <= 1e-9 * diag ** (2.0 / 3.0):
        raise CurveError("samples lie on a straight line: the curve has no affine arc length")
    cv = _Curve(rc)
    inflections = rc.inflections()
    if closed:
        if inflections.size or np.any(rc.lengths * rc.total_length < 0):
            raise CurveError(
                f"closed curves must be convex (no inflections), got {max(inflections.size, 1)} "
                "sign change(s) of the turning direction; approximate it as an open curve"
            )
        return _approximate_closed(cv, vertices, search, xtol, max_iterations, close_tol * diag)
    return _approximate_open(
        cv, inflections, vertices - 1, search, xtol, max_iterations, skip, match_end
    )


def _fit_piece(piece: _Piece, area: float, search, xtol, iterations, target_t, tol_steps, refits):
    """Optimise t1 for `area`; refit A until x_m is within `tol_steps` edges of `target_t`.

    If the curve ends before all ``m`` edges are built (``A = (S/n)^3`` slightly too
    large, typical for few vertices on coarse samples), the edges are shortened by
    3 % and the construction repeated, up to 8 times, before giving up.

    The refits scale the edges by the missing affine length (a secant step on
    ``|A|^(1/3)``), safeguarded by a bracket: an ``A`` whose polygon stops short
    of the target is a lower bound, one that overshoots or runs off the curve an
    upper bound, and a step leaving the bracket bisects it instead. The bracket
    matters on irregular samples, where the optimal ``t_1`` jumps between two
    minima of ``psi`` as ``A`` changes and the plain secant step cycles.
    """
    cv = piece.cv
    best = None
    s_target = cv.s_of_t(target_t)
    refits_used = recoveries = 0
    lo = hi = None  # |A|^(1/3) bounds: x_m short of the target / beyond it (or curve ended)
    sign = 1.0 if area > 0 else -1.0
    while True:
        t1 = piece.search(area, search, xtol, iterations)
        xs, ys, ts, done = _construct(
            cv, piece.t0, t1, area, piece.m, piece.t_end, extrapolate=piece.extrapolate
        )
        step = abs(area) ** (1.0 / 3.0)
        if done == piece.m:
            gap = (s_target - cv.s_of_t(ts[-1])) * piece.sign / step
            # the same gap in parameter steps of the last edge: the affine length is flat on
            # the degenerate arcs next to an inflection, where x_m can be far off at gap 0
            gap_t = (target_t - ts[-1]) / max(ts[-1] - ts[-2], 1e-300)
        else:
            gap = gap_t = math.inf
        miss = max(abs(gap), abs(gap_t))
        cand = (miss, area, t1, xs, ys, ts, done, gap)
        if best is None or cand[0] < best[0] or (cand[0] == best[0] and done > best[6]):
            best = cand
        if done == piece.m and miss <= tol_steps:
            break
        if done < piece.m or gap_t < 0:
            hi = step if hi is None else min(hi, step)
        else:
            lo = step if lo is None else max(lo, step)
        if done < piece.m and lo is None:
            if recoveries >= 8:
                break
            recoveries += 1
            area *= 0.97**3  # the curve ended first: shorter edges
            continue
        if refits_used >= refits:
            break
        refits_used += 1
        new = math.nan
        if done == piece.m and gap != 0.0:
            covered = abs(cv.s_of_t(ts[-1]) - cv.s_of_t(piece.t0))
            if covered > 0.0:
                new = step * (covered + gap * step) / covered  # scale the edges to the target
        if not (lo is None or new > lo) or not (hi is None or new < hi) or math.isnan(new):
            if lo is not None and hi is not None:
                new = 0.5 * (lo + hi)
            else:
                new = step * (1.01 if hi is None else 1 / 1.01)
        if new == step:
            break
        area = sign * new**3
    return best[1:]


def _approximate_open(
    cv, inflections, n, search, xtol, iterations, skip, match_end
) -> Approximation:
    s_abs = np.concatenate([[0.0], np.cumsum(np.abs(cv.rc.lengths))])
    bounds = [0, *inflections.tolist(), cv.n]
    total = s_abs[-1]
    idx = [0]
    for b in bounds[1:-1]:
        idx.append(round(n * s_abs[b] / total))
    idx.append(n)
    edges = np.diff(idx)
    pieces = len(bounds) - 1
    if np.any(edges < 3) and n >= 3 * pieces:
        # a piece of small affine length (a shallow dent between two inflections) gets the
        # minimum of 3 edges, taken from the pieces whose share is rounded up the most
        share = n * np.diff(s_abs[bounds]) / total
        edges = np.maximum(np.floor(share).astype(int), 3)
        while edges.sum() > n:
            over = np.where(edges > 3, edges - share, -np.inf)
            edges[int(np.argmax(over))] -= 1
        while edges.sum() < n:
            edges[int(np.argmax(share - edges))] += 1
    if np.any(edges < 3):
        raise CurveError(
            f"vertices must give each of the {len(bounds) - 1} inflection-free pieces at least "
            f"3 edges (section 4.4), got vertices={n + 1} and a piece with "
            f"{int(edges.min())} edges: use more vertices"
            + (" or smooth the samples (noise makes inflections)" if len(bounds) > 6 else "")
        )
    penalty = 1e6
    xs_all: list[float] = []
    ys_all: list[float] = []
    ts_all: list[float] = []
    areas, joins, objective, evaluations = [], [], 0.0, 0
    t0 = 0.0
    ok = True
    msg = []
    t1_first = math.nan
    gap_last = 0.0
    extrapolated: list[int] = []
    for pi in range(len(bounds) - 1):
        m = int(edges[pi])
        t_end = float(bounds[pi + 1])
        sign = 1.0 if cv.s_of_t(t_end) - cv.s_of_t(bounds[pi]) > 0 else -1.0
        last = pi == len(bounds) - 2
        # section 4.4: with inflections, l curvatures are skipped at both ends of every
        # sub-polyline (a curve end may itself be an inflection, like sin x at 0)
        lo = hi = skip if len(bounds) > 2 else 0
        while m - 2 - lo - hi < 2 and (lo or hi):  # keep at least two curvatures
            lo, hi = (lo - 1, hi) if lo >= hi else (lo, hi - 1)
        piece = _Piece(cv, t0, t_end, m, sign, lo, hi, penalty)
        # a piece ending at an inflection ends on the curve: the next one starts at f~(t) on
        # the next arc, another point than one on this piece's extrapolated last arc (the
        # first area of the next piece was off by up to 4 % at such joins)
        piece.extrapolate = last
        length = abs(cv.s_of_t(t_end) - cv.s_of_t(t0))
        area = sign * (length / m) ** 3
        if not area:
            raise CurveError(
                f"the samples from t = {t0:.6g} to {t_end:.6g} have no affine arc length "
                "(a straight run: every arc of the replacement curve is a chord), so no "
                "affine arc length polyline follows them; fit straight runs as lines"
            )
        if last:
            tol_steps, refits = (_END_TOL, 60) if match_end else (math.inf, 0)
        else:
            tol_steps, refits = 0.25, 8
        area0 = area
        area, t1, xs, ys, ts, done, gap = _fit_piece(
            piece, area, search, xtol, iterations, t_end, tol_steps, refits
        )
        if done < m and not piece.extrapolate:
            # no A puts x_m on the curve before the inflection: fall back to the paper's
            # construction, x_m on the extrapolated last arc (the next piece then starts at
            # f~(t_m), a slightly different point, and the join is not exactly equal-area)
            piece.extrapolate = True
            area, t1, xs, ys, ts, done, gap = _fit_piece(
                piece, area0, search, xtol, iterations, t_end, tol_steps, refits
            )
            extrapolated.append(pi)
        evaluations += piece.evaluations
        if pi == 0:
            t1_first = t1
        if done < m:
            ok = False
            msg.append(f"piece {pi}: only {done} of {m} edges could be constructed")
        else:
            objective += _psi(_curvatures(xs, ys, area), lo, hi)
        if pi > 0:
            joins.append(len(xs_all) - 1)
            xs, ys, ts = xs[1:], ys[1:], ts[1:]
        xs_all += xs
        ys_all += ys
        ts_all += ts
        areas.append(area)
        t0 = ts_all[-1]
        gap_last = gap
        if done < m:
            break
    pts = np.c_[xs_all, ys_all]
    area_per_edge = np.repeat(areas, edges[: len(areas)])[: pts.shape[0] - 1]
    k, valid = _piecewise_curvature(pts, area_per_edge)
    if ok:
        msg.append(
            f"constructed {n} edges in {len(areas)} piece(s); psi = {objective:.3g}; "
            f"end gap {gap_last:+.3g} edge(s)"
        )
        if extrapolated:
            msg.append(
                f"piece(s) {', '.join(map(str, extrapolated))} end on their extrapolated last "
                "arc: the following piece starts at a slightly different point"
            )
        if match_end and abs(gap_last) > 1e3 * _END_TOL:
            msg.append(
                f"match_end did not converge: x_n is {gap_last:+.3g} edge(s) from the end of "
                "the curve (the optimal t_1 jumps as A changes: irregular or noisy samples?)"
            )
        elif abs(gap_last) > 0.5:
            where = "short of" if gap_last > 0 else "beyond"
            msg.append(
                f"the polyline ends {abs(gap_last):.3g} edge(s) {where} the end of the curve "
                "(A = (S/n)^3 misjudged: non-uniform samples?); use match_end=True to fit A"
            )
    return Approximation(
        points=pts,
        area=float(areas[0]),
        curvature=k,
        kappa_m=k * np.abs(area_per_edge[1 : 1 + k.size]) ** (-2.0 / 3.0),
        valid=valid,
        t=np.asarray(ts_all),
        t1=float(t1_first),
        objective=float(objective),
        success=ok,
        message="; ".join(msg),
        closed=False,
        closing_error=0.0,
        end_gap=float(gap_last),
        piece_areas=np.asarray(areas, dtype=float),
        joins=np.asarray(joins, dtype=int),
        evaluations=evaluations,
    )


def _piecewise_curvature(pts: np.ndarray, area_per_edge: np.ndarray):
    """k_i = 2 - B_i / A for every quadruple; valid where its three edges share one piece."""
    v = np.diff(pts, axis=0)
    b = v[:-2, 0] * v[2:, 1] - v[:-2, 1] * v[2:, 0]
    a_mid = area_per_edge[1:-1]
    k = 2.0 - b / a_mid
    valid = (area_per_edge[:-2] == a_mid) & (area_per_edge[2:] == a_mid)
    return k, valid


def _closing(cv: _Curve, z3: np.ndarray, sign: float, n: int):
    """x_0 .. x_{n+1} for z3 = (log|A|, t0, t1 - t0) and the closing error."""
    xs, ys, ts, done = _construct(cv, z3[1], z3[1] + z3[2], sign * math.exp(z3[0]), n + 1, math.inf)
    if done < n + 1:
        raise CurveError(
            "closed construction failed after closing; try more samples or fewer vertices"
        )
    full = np.c_[xs, ys]
    err = float(max(np.hypot(*(full[n] - full[0])), np.hypot(*(full[n + 1] - full[1]))))
    return full, ts, err


def _approximate_closed(cv, n, search, xtol, iterations, close_abs) -> Approximation:
    total = cv.total
    sign = 1.0 if total > 0 else -1.0
    piece = _Piece(cv, 0.0, math.inf, n + 1, sign, 0, 0, 1e6)
    area = sign * (abs(total) / n) ** 3
    t1 = piece.search(area, search, xtol, iterations)
    step0 = abs(area) ** (1.0 / 3.0)

    def residual(z, weight):
        # z = (log|A|, t1) with x_0 = f~(0), or (log|A|, t0, t1 - t0)
        a = sign * math.exp(z[0])
        t0, t1 = (0.0, z[1]) if z.size == 2 else (z[1], z[1] + z[2])
        xs, ys, ts, done = _construct(cv, t0, t1, a, n + 2, math.inf)
        piece.evaluations += 1
        if done < n + 2:
            return np.full(n + 1, 1e3)
        close = [
            (cv.s_of_t(ts[n]) - cv.s_of_t(t0) - total) / step0,
            (cv.s_of_t(ts[n + 1]) - cv.s_of_t(t1) - total) / step0,
        ]
        k = _curvatures(xs, ys, a)[: n + 1]
        return np.array(close + [weight * (k[i + 1] - k[i]) for i in range(n - 1)])

    # Closure x_n = x_0, x_{n+1} = x_1 (same A across the seam) with the smoothness of
    # the k_i as a weak second objective. First A and t1 with x_0 = f~(0); near an
    # ellipse with even n closure alone is (nearly) degenerate (Theorem 1: a family of
    # alternating polygons closes), so x_0 is then released too: A, t0, t1 together.
    opts = {"method": "lm", "xtol": 1e-15, "ftol": 1e-15, "gtol": 1e-15}
    z = np.array([math.log(abs(area)), t1])
    z = least_squares(residual, z, args=(1e-2,), max_nfev=300, **opts).x
    z3 = np.array([z[0], 0.0, z[1]])
    full, ts, err = _closing(cv, z3, sign, n)
    if err > 1e-3 * close_abs:
        z3 = least_squares(residual, z3, args=(1e-4,), max_nfev=60, **opts).x
        z3 = least_squares(residual, z3, args=(0.0,), max_nfev=100, **opts).x  # polish closure
        full, ts, err = _closing(cv, z3, sign, n)
    piece.evaluations += 2
    area = sign * math.exp(z3[0])
    t1 = float(z3[1] + z3[2])
    pts = full[:n]
    v = np.roll(pts, -1, axis=0) - pts
    vm = np.roll(v, 1, axis=0)
    b = vm[:, 0] * np.roll(v, -1, axis=0)[:, 1] - vm[:, 1] * np.roll(v, -1, axis=0)[:, 0]
    k = 2.0 - b / area
    psi = float(np.sum((np.roll(k, -1) - k) ** 2))
    ok = err <= close_abs
    msg = (
        f"closed {n}-gon with A = {area:.6g}; closing error {err:.3g}; psi = {psi:.3g}"
        if ok
        else f"polygon did not close: closing error {err:.3g} > {close_abs:.3g}"
    )
    return Approximation(
        points=pts,
        area=float(area),
        curvature=k,
        kappa_m=k * abs(area) ** (-2.0 / 3.0),
        valid=np.ones(n, dtype=bool),
        t=np.asarray(ts[:n]) - math.floor(ts[0] / cv.n) * cv.n,  # t_0 in [0, N)
        t1=t1,
        objective=psi,
        success=bool(ok),
        message=msg,
        closed=True,
        closing_error=err,
        end_gap=0.0,
        piece_areas=np.array([area]),
        joins=np.zeros(0, dtype=int),
        evaluations=piece.evaluations,
    )
