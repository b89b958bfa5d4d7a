"""De Rham curves: certified lengths, acceleration and curves of prescribed length.

Implements Merrien, *Prescribing the length of a de Rham curve*
(``shared/papers/derham-prescribed-length.md``) on top of
:func:`curvesmith.subdivision.de_rham`.

Lengths (section 2)
    The de Rham curve of an open control polygon ``S_0 .. S_{N-1}`` runs from
    the midpoint of the first side to the midpoint of the last side and is a
    chain of ``N - 2`` arcs, one per corner ``S_{i-1} S_i S_{i+1}``; each arc is
    the paper's curve ``C_gamma`` of that triangle (corner cutting is local, so
    refining the whole polygon refines every corner triangle independently).
    ``L^n`` is the length of the level-``n`` polygon ``P^n`` from the midpoint of
    its first side to the midpoint of its last side, ``l^n`` the length of the
    polyline through the midpoints of its sides; both are sums over the
    corners, and for a triangle they are exactly the paper's ``L^n``, ``l^n``
    (``L^0 = (|AB| + |BC|) / 2``, ``l^0 = |AC| / 2``). For every corner
    ``l^n <= l^{n+1} <= L <= L^{n+1} <= L^n``, and
    ``L^{n+1} = (gamma L^n + 2 l^n) / (gamma + 2)`` (verified to rounding in the
    tests, also for chains with inflections, i.e. non-convex polygons).

    Internally the level-``n`` polygon is kept as its side vectors ``e_i``
    (complex numbers), exactly the polygon of
    :func:`~curvesmith.subdivision.de_rham` (checked against it in the tests):
    one step maps them to ``(1 - 2 beta) e_i`` alternating with
    ``beta (e_i + e_{i+1})``, ``beta = 1 / (gamma + 2)``;
    ``l^n = sum |e_i + e_{i+1}| / 2`` and ``L^n`` follows from the recurrence.
    Deep levels are refined in blocks of consecutive sides (bounded memory),
    and x-derivatives are refined alongside (subdivision is linear).

Acceleration
    ``L^n - L`` decays geometrically (ratio exactly 1/4 for ``gamma = 2``;
    observed about 0.264 for ``gamma = 1.2``, 0.248 for 3, 0.236 for 5 and an
    oscillating 0.18 .. 0.21 for 12), so the paper's suggestion applies:
    iterated Aitken Δ² (:func:`aitken`) and Wynn's epsilon algorithm
    (:func:`wynn_epsilon`). Extrapolated values carry no error bound; every
    result reports them clipped into the certified bracket.

Exact length for gamma = 2 (:func:`parabola_length`)
    ``C_2`` is a parabola arc, the quadratic Bézier curve with control points
    ``M_0, B, M_1``, whose derivative is ``ΔS_0 + t Δ²S_0``. The closed form
    printed in section 2 is **twice** the arc length: both of its terms lack a
    factor 1/2 (the antiderivative of ``sqrt(A t² + B t + C)`` has
    ``(4AC - B²) / (8 A^{3/2})`` and ``(2At + B) / (4A)``). Checked against the
    refinement limit and adaptive quadrature: printed / true = 2.0000000000000004
    on the paper's triangle. Its ``S_3 = C`` should read ``S_2 = C``. The
    implementation uses the corrected formula rewritten without cancellation
    (it stays accurate for nearly straight corners, where the printed form
    loses all digits).

Prescribed length (sections 3-4)
    Given ``A``, ``u_A``, ``C``, ``u_C`` the tangent lines meet at
    ``B = A + alpha u_A = C - beta u_C`` (``alpha, beta > 0`` required); the
    control polygon is ``S_0 = A - x (B - A)``, ``S_1 = A + x (B - A)``,
    ``S_2 = C + x (B - C)``, ``S_3 = C - x (B - C)`` (the paper's ``y = x``), and
    ``f(x) = L(x, x)`` increases from ``|AC|`` to ``|AB| + |BC|``.
    :func:`interpolate` solves ``f(x) = length`` by the paper's regula falsi
    (Lemma 4) or modified secant method (Lemma 5) on ``f^n``, or by the default
    ``"accelerated"`` method: bracketed inversion of a local Taylor polynomial of
    an extrapolated length (the closed form for ``gamma = 2``), followed by a
    certificate ``l^n(x) <= f(x) <= L^{n+1}(x)`` (outward
    rounded) inside ``[length - tol, length + tol]``.

    Evaluations counted in the results are evaluations of ``f^n``, of the
    extrapolated or exact length (with derivatives) and of the certificate; the
    level-0 starting model and the known ``f(0)``, ``f(1)`` are arithmetic on the
    four control points and are not counted (the evaluations of the default
    method return a Taylor polynomial of order 12 in x). ``benchmarks/bench_derham.py``
    measured (one run, shared machine): gamma = 2, certified to tol 1e-12 in 2
    evaluations and about 1 ms median, where the secant method needs 6
    evaluations at level 22 (about 8 s per case) for 1e-12, and 5.5 (paper's
    data) or 7 (random data) at 1e-9. For gamma != 2 the certificate needs one
    refinement to level 17..21 (0.05 to 0.4 s at tol 1e-12).

Section 4 states the rule "choose n with ``(|AB| + |BC|) 0.25^n < eps / 2``"; the
levels printed in the tables of section 5 (5, 8, 10) do not follow it (it gives
5, 9, 11), so the tables are reproduced with the printed levels passed as
``length_level``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike

from ._rich import RichRepr
from ._validate import as_choice, as_float, as_int, as_points
from .errors import CurveError
from .subdivision import de_rham

__all__ = [
    "ChainResult",
    "InterpolationResult",
    "LengthResult",
    "aitken",
    "control_polygon",
    "interpolate",
    "interpolate_chain",
    "length",
    "length_bounds",
    "length_sequences",
    "paper_level",
    "parabola_length",
    "wynn_epsilon",
]

METHODS = ("accelerated", "regula_falsi", "secant")

_EPS = float(np.finfo(float).eps)
CHUNK = 1 << 18  # corners refined together; bounds memory at high levels
_MAX_LEVEL = 26
_GL_T, _GL_W = np.polynomial.legendre.leggauss(32)
_GL_T = 0.5 * (_GL_T + 1.0)
_GL_W = 0.5 * _GL_W


# --------------------------------------------------------------------------- refinement kernel


def _sides(p: np.ndarray) -> np.ndarray:
    """Side vectors of an open polygon as complex numbers, shape (N - 1,)."""
    e = np.diff(p, axis=0)
    return e[:, 0] + 1j * e[:, 1]


def _refine(e: np.ndarray, beta: float, s: np.ndarray | None = None) -> np.ndarray:
    """One de Rham step on side vectors, (m, K) -> (m, 2K - 1) (rows: value, x-derivative).

    The sides of ``P^{n+1}`` are ``(1 - 2 beta) e_i`` (the middle part of side
    i) alternating with ``beta (e_i + e_{i+1})`` (the cut at vertex i + 1);
    ``s = e[:, :-1] + e[:, 1:]`` may be passed when already computed.
    """
    m, k = e.shape
    out = np.empty((m, 2 * k - 1), dtype=complex)
    np.multiply(e, 1.0 - 2.0 * beta, out=out[:, 0::2])
    if s is None:
        s = e[:, :-1] + e[:, 1:]
    np.multiply(s, beta, out=out[:, 1::2])
    return out


def _abs_taylor(z: np.ndarray, dz: np.ndarray, order: int) -> np.ndarray:
    """Taylor coefficients in h of ``|z + h dz|`` up to ``h^order``, shape (order + 1, ...).

    ``|z + h dz|² = q0 + q1 h + q2 h²`` with ``q0 = |z|²``, ``q1 = 2 Re(conj(z) dz)``,
    ``q2 = |dz|²``; squaring the series gives ``a_0 = |z|``, ``a_1 = q1 / (2 a_0)``,
    ``a_2 = det(z, dz)² / (2 |z|³)`` (written without cancellation) and
    ``a_k = -sum_{j=1}^{k-1} a_j a_{k-j} / (2 a_0)`` for ``k >= 3``. The series
    converges for ``|h| < |z| / |dz|``. Where ``z = 0`` only ``a_1 = |dz|`` is set.
    """
    r = np.abs(z)
    out = np.zeros((order + 1, *np.shape(z)))
    out[0] = r
    if order == 0:
        return out
    pos = r > 0.0
    safe = np.where(pos, r, 1.0)
    out[1] = np.where(pos, (z.real * dz.real + z.imag * dz.imag) / safe, np.abs(dz))
    if order >= 2:
        cross = z.real * dz.imag - z.imag * dz.real
        out[2] = np.where(pos, 0.5 * cross * cross / (safe * safe * safe), 0.0)
    inv = np.where(pos, -0.5 / safe, 0.0)
    for k in range(3, order + 1):
        acc = out[1] * out[k - 1]
        for j in range(2, k):
            acc += out[j] * out[k - j]
        out[k] = acc * inv
    return out


def _abs_sums(w: np.ndarray, order: int) -> np.ndarray:
    """Sums of the Taylor coefficients in x of ``|w|`` up to ``x^order``.

    Rows of w: the side vectors and (if ``order >= 1``) their x-derivatives.
    """
    if order == 0:
        return np.array([np.abs(w[0]).sum()])
    return _abs_taylor(w[0], w[1], order).sum(axis=1)


def _accumulate(
    e: np.ndarray, depth: int, beta: float, out: np.ndarray, start: int, order: int
) -> None:
    """Add ``l^k`` (and x-derivatives) of levels ``start .. start + depth`` into ``out[k]``.

    ``l^k`` is half the sum of ``|e_i + e_{i+1}|`` over consecutive sides. Refines
    level by level; once the side array would exceed ``CHUNK`` it recurses over
    blocks of consecutive sides that overlap by one side (every corner, i.e. pair
    of consecutive sides, lies in exactly one block; corner cutting is local).
    """
    k = 0
    while True:
        s = e[:, :-1] + e[:, 1:]
        out[start + k] += 0.5 * _abs_sums(s, order)
        if k == depth:
            return
        if 2 * e.shape[1] > CHUNK:
            step = CHUNK // 2
            for i in range(0, e.shape[1] - 1, step):
                child = _refine(e[:, i : i + step + 1], beta)
                _accumulate(child, depth - k - 1, beta, out, start + k + 1, order)
            return
        e = _refine(e, beta, s)
        k += 1


def _sums(e: np.ndarray, levels: int, beta: float, order: int = 0) -> np.ndarray:
    """Per-level ``l^k`` and ``L^k`` (and their Taylor coefficients in x up to ``order``).

    Returns ``(levels + 1, 2 (order + 1))``: columns ``l_0 .. l_order`` then
    ``L_0 .. L_order`` (coefficient j of ``h^j``). ``e`` is (m, K) complex: row 0
    the side vectors, row 1 (if ``order >= 1``) their x-derivatives.
    ``L^0 = sum |e_i| - (|e_0| + |e_{K-1}|) / 2`` and the higher ``L^k`` follow
    from the recurrence ``L^{k+1} = (1 - 2 beta) L^k + 2 beta l^k`` of section 2,
    which holds term by term (the norms of the new sides are
    ``(1 - 2 beta) |e_i|`` and ``beta |e_i + e_{i+1}|``), hence also for every
    Taylor coefficient.
    """
    m = order + 1
    out = np.zeros((levels + 1, 2 * m))
    low = np.zeros((levels + 1, m))
    _accumulate(e, levels, beta, low, 0, order)
    out[:, :m] = low
    up = _abs_sums(e, order) - 0.5 * (_abs_sums(e[:, :1], order) + _abs_sums(e[:, -1:], order))
    for k in range(levels + 1):
        out[k, m:] = up
        up = (1.0 - 2.0 * beta) * up + 2.0 * beta * low[k]
    return out


def _margin(level: int, beta: float, upper0: float, terms: float) -> float:
    """Bound on the rounding error of a level-``level`` sum (first order in machine epsilon).

    Each refinement step perturbs the corner vectors by a few ulps relative to
    the parent's upper length (``u + v`` may cancel in sharp corners; the
    children's upper length is at least ``(1 - 2 beta)`` times the parent's),
    and a pairwise sum of ``terms`` norms adds ``log2(terms)`` ulps.
    """
    per_level = 4.0 + 2.0 / (1.0 - 2.0 * beta)
    return _EPS * ((level + 2) * per_level + math.log2(max(terms, 2.0)) + 4.0) * upper0


# --------------------------------------------------------------------------- public lengths


def _check_polygon(points, gamma) -> tuple[np.ndarray, float]:
    gamma = as_float(gamma, name="gamma", low=1.0)
    p = as_points(points, min_points=3, distinct=True)
    return p, gamma


def length_sequences(
    points: ArrayLike, *, gamma: float, levels: int
) -> tuple[np.ndarray, np.ndarray]:
    """Lengths ``l^k`` and ``L^k`` for every level ``k`` from 0 to ``levels`` (Merrien, section 2).

    Parameters
    ----------
    points : (N, 2) array_like
        Open control polygon, ``N >= 3``, no zero-length sides. A triangle is
        the paper's case; a longer polygon is a chain of ``N - 2`` arcs from the
        midpoint of the first side to the midpoint of the last.
    gamma : float
        De Rham parameter, ``gamma > 1``.
    levels : int
        Highest level ``n >= 0``.

    Returns
    -------
    lower : (levels + 1,) ndarray
        ``l^k``, length of the polyline through the midpoints of the sides of
        ``P^k``; increasing in ``k``.
    upper : (levels + 1,) ndarray
        ``L^k``, length of ``P^k`` between the midpoints of its first and last
        sides; decreasing, with ``L^{k+1} = (gamma L^k + 2 l^k) / (gamma + 2)``.

    Examples
    --------
    The paper's triangle: ``l^0 = |AC| / 2`` and ``L^0 = (|AB| + |BC|) / 2``.

    >>> lo, up = length_sequences([[-1.5, -1], [0, 1], [1.5, 0]], gamma=2.0, levels=2)
    >>> [round(float(v), 6) for v in lo], [round(float(v), 6) for v in up]
    ([1.581139, 1.736627, 1.769558], [2.151388, 1.866263, 1.801445])
    """
    p, gamma = _check_polygon(points, gamma)
    levels = as_int(levels, name="levels", minimum=0, maximum=_MAX_LEVEL)
    s = _sums(_sides(p)[None], levels, 1.0 / (gamma + 2.0))
    return s[:, 0], s[:, 1]


def length_bounds(points: ArrayLike, *, gamma: float, levels: int) -> tuple[float, float]:
    """The pair ``(l^n, L^n)`` at level ``n = levels`` that brackets the de Rham curve's length.

    Parameters
    ----------
    points : (N, 2) array_like
        Open control polygon, ``N >= 3`` (see :func:`length_sequences`).
    gamma : float
        De Rham parameter, ``gamma > 1``.
    levels : int
        Number of refinement steps ``n >= 0``.

    Returns
    -------
    lower, upper : float
        ``l^n <= L <= L^n`` (up to rounding of order ``1e-16 L``; :func:`length`
        returns outward-rounded certified bounds).

    Examples
    --------
    For ``gamma = 2`` the limit is the parabola length 1.78020496684...:

    >>> lo, up = length_bounds([[-1.5, -1], [0, 1], [1.5, 0]], gamma=2.0, levels=10)
    >>> round(lo, 6), round(up, 6)
    (1.780205, 1.780205)
    >>> lo < parabola_length([[-1.5, -1], [0, 1], [1.5, 0]]) < up
    True
    """
    lo, up = length_sequences(points, gamma=gamma, levels=levels)
    return float(lo[-1]), float(up[-1])


def aitken(sequence: ArrayLike, *, iterations: int | None = None) -> float:
    """Iterated Aitken Δ² extrapolation of a sequence; returns the last entry of the last column.

    Parameters
    ----------
    sequence : (M,) array_like
        Terms ``s_0 .. s_{M-1}``, ``M >= 1``.
    iterations : int, optional
        Number of Δ² sweeps (default: as many as the length allows,
        ``(M - 1) // 2``).

    Returns
    -------
    float
        The extrapolated limit. A sweep stops early where a second difference
        vanishes (the sequence is already constant to rounding).

    Examples
    --------
    Exact on a geometric sequence:

    >>> aitken([1 + 0.25**k for k in range(5)])
    1.0
    """
    s = np.asarray(sequence, dtype=float).ravel()
    if s.size == 0:
        raise CurveError("sequence must have at least 1 term, got 0")
    sweeps = (s.size - 1) // 2 if iterations is None else as_int(iterations, name="iterations")
    for _ in range(sweeps):
        if s.size < 3:
            break
        d1 = s[1:-1] - s[:-2]
        d2 = s[2:] - 2.0 * s[1:-1] + s[:-2]
        if np.any(d2 == 0.0):
            break
        s = s[:-2] - d1 * d1 / d2
    return float(s[-1])


def wynn_epsilon(sequence: ArrayLike) -> float:
    """Wynn's epsilon algorithm; returns the last entry of the highest even column.

    ``eps_{-1} = 0``, ``eps_0^{(k)} = s_k``,
    ``eps_{j+1}^{(k)} = eps_{j-1}^{(k+1)} + 1 / (eps_j^{(k+1)} - eps_j^{(k)})``
    (Brezinski & Redivo Zaglia, ch. 2, the reference [1] of the paper).

    Parameters
    ----------
    sequence : (M,) array_like
        Terms, ``M >= 1``.

    Returns
    -------
    float
        The estimate; if a difference vanishes (the column has converged to
        rounding) the current even-column value is returned.

    Examples
    --------
    >>> round(wynn_epsilon([1 + 0.25**k + 0.1 * 0.0625**k for k in range(7)]), 14)
    1.0
    """
    s = np.asarray(sequence, dtype=float).ravel()
    if s.size == 0:
        raise CurveError("sequence must have at least 1 term, got 0")
    prev = np.zeros(s.size + 1)
    cur = s.copy()
    best = float(cur[-1])
    col = 0
    while cur.size >= 2:
        diff = cur[1:] - cur[:-1]
        if np.any(diff == 0.0):
            break
        nxt = prev[1 : cur.size] + 1.0 / diff
        prev, cur = cur, nxt
        col += 1
        if col % 2 == 0:
            if not np.all(np.isfinite(cur)):
                break
            best = float(cur[-1])
    return best


def _parabola_arcs(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Length of ``t -> |a + t (b - a)|`` integrated over [0, 1], per row; a, b are (K, 2).

    Corrected closed form of section 2, written without cancellation: with
    ``d = b - a``, ``sigma_0 = a.d/|d|``, ``sigma_1 = b.d/|d|``,
    ``h = |det(a, d)| / |d|`` (after reversing the arc if ``sigma_0 + sigma_1 < 0``),
    ``length = (|a| + sigma_1 (sigma_0 + sigma_1) / (|a| + |b|)) / 2
    + h² log1p(z) / (2 |d|)``, ``z = |d| (1 + (sigma_0 + sigma_1) / (|a| + |b|)) /
    (sigma_0 + |a|)``, which is ``[sigma |r| + h² ln(sigma + |r|)] / (2 |d|)``
    between ``sigma_0`` and ``sigma_1`` rearranged. Exact for straight corners
    and for cusps (``b`` antiparallel to ``a``).
    """
    flip = ((a + b) * (b - a)).sum(axis=1) < 0.0
    a, b = np.where(flip[:, None], -b, a), np.where(flip[:, None], -a, b)
    d = b - a
    nd = np.hypot(d[:, 0], d[:, 1])
    na = np.hypot(a[:, 0], a[:, 1])
    nb = np.hypot(b[:, 0], b[:, 1])
    out = 0.5 * (na + nb)  # straight corners (|d| negligible): the arc is the segment
    bent = nd > 1e-14 * np.maximum(na, nb)
    a, b, d, nd, na, nb = a[bent], b[bent], d[bent], nd[bent], na[bent], nb[bent]
    s0 = (a * d).sum(axis=1) / nd
    s1 = (b * d).sum(axis=1) / nd
    h = np.abs(a[:, 0] * d[:, 1] - a[:, 1] * d[:, 0]) / nd
    ssum = s0 + s1
    term1 = 0.5 * (na + s1 * ssum / (na + nb))
    # sigma_0 + |a|, stably: h² / (|a| - sigma_0) when sigma_0 < 0.
    neg = s0 < 0.0
    base = np.where(neg, h * h / np.where(neg, na - s0, 1.0), s0 + na)
    # log term h² ln((sigma_1 + |b|) / (sigma_0 + |a|)) / (2 |d|) = h² log1p(z) / (2 |d|),
    # z = |d| num / base with num = 1 + (sigma_0 + sigma_1)/(|a| + |b|) in [1, 2]; base = 0
    # only at an exact cusp, where h = 0. Near a cusp z is huge: use log z.
    ok = base > 0.0
    num = 1.0 + ssum / (na + nb)
    logz = np.log(nd) + np.log(num) - np.log(np.where(ok, base, 1.0))
    big = logz > 30.0
    z = nd * num / np.where(ok & ~big, base, 1.0)
    log1pz = np.where(big, logz + np.log1p(np.exp(-np.maximum(logz, 30.0))), np.log1p(z))
    term2 = np.where(ok, 0.5 * h * h * log1pz / nd, 0.0)
    out[bent] = term1 + term2
    return out


def parabola_length(points: ArrayLike) -> float:
    """Exact length of the ``gamma = 2`` de Rham (Chaikin) curve of an open polygon.

    Every arc is a parabola; this is the corrected closed form of section 2
    (the printed formula is twice the arc length, see the module docstring).

    Parameters
    ----------
    points : (N, 2) array_like
        Open control polygon, ``N >= 3``, no zero-length sides.

    Returns
    -------
    float
        Length of the limit curve from the first side's midpoint to the last
        side's midpoint.

    Examples
    --------
    A quarter of ``y = x²``-like parabola on the paper's triangle:

    >>> round(parabola_length([[-1.5, -1], [0, 1], [1.5, 0]]), 12)
    1.780204966841
    """
    p = as_points(points, min_points=3, distinct=True)
    e = np.diff(p, axis=0)
    return float(_parabola_arcs(e[:-1], e[1:]).sum())


@dataclass(frozen=True)
class LengthResult(RichRepr):
    """Certified length of a de Rham curve (see :func:`length`).

    Attributes
    ----------
    value : float
        Best estimate of the length: the exact closed form for ``gamma = 2``,
        otherwise Wynn's epsilon extrapolation of ``(L^k)``; always clipped into
        ``[lower, upper]``.
    lower, upper : float
        Certified bracket ``lower <= L <= upper``: ``l^n`` and
        ``L^{n+1} = (gamma L^n + 2 l^n) / (gamma + 2)``, widened by a rounding
        bound (for ``gamma = 2`` the closed form plus or minus its rounding bound).
    level : int
        Level ``n`` of the bracket.
    aitken, wynn : float
        Unclipped extrapolations (iterated Aitken Δ², Wynn epsilon) of ``L^0 .. L^n``.
    lower_sequence, upper_sequence : (n + 1,) ndarray
        ``l^k`` and ``L^k`` for ``k = 0 .. n``.
    success : bool
        Whether ``upper - lower <= tol``.
    message : str
        Human-readable outcome.
    """

    value: float
    lower: float
    upper: float
    level: int
    aitken: float
    wynn: float
    lower_sequence: np.ndarray = field(repr=False)
    upper_sequence: np.ndarray = field(repr=False)
    success: bool
    message: str


def _predict_level(gap: np.ndarray, level: int, target: float, floor: float) -> int:
    """Smallest level whose gap ``gap[level] r^(n - level)`` falls below ``target``."""
    g = float(gap[level])
    if g <= target:
        return level
    r = float(gap[level] / gap[level - 1]) if level >= 1 and gap[level - 1] > 0 else 0.3
    r = min(max(r, 0.1), 0.6)
    return (
        level + max(1, math.ceil(math.log(target / g) / math.log(r))) if target > floor else level
    )


def length(
    points: ArrayLike, *, gamma: float, tol: float = 1e-9, max_level: int = 24
) -> LengthResult:
    """Length of the de Rham curve with a certified bracket and an extrapolated value.

    Refines until the bracket ``[l^n, L^{n+1}]`` (section 2 and the recurrence
    ``L^{n+1} = (gamma L^n + 2 l^n) / (gamma + 2)``) is narrower than `tol`,
    choosing ``n`` from the observed contraction of ``L^k - l^k`` so that the
    expensive last level is computed once. For ``gamma = 2`` the corrected
    closed form of section 2 is exact and gives the bracket directly.

    Parameters
    ----------
    points : (N, 2) array_like
        Open control polygon, ``N >= 3`` (a chain of ``N - 2`` arcs).
    gamma : float
        De Rham parameter, ``gamma > 1``.
    tol : float, optional
        Target width of the certified bracket, ``> 0``.
    max_level : int, optional
        Highest refinement level (the level-``n`` work is ``(N - 2) 2^n`` corners).

    Returns
    -------
    LengthResult

    Examples
    --------
    >>> r = length([[-1.5, -1], [0, 1], [1.5, 0]], gamma=5.0, tol=1e-8)
    >>> r.success, r.upper - r.lower <= 1e-8, r.lower <= r.value <= r.upper
    (True, True, True)
    """
    p, gamma = _check_polygon(points, gamma)
    tol = as_float(tol, name="tol", low=0.0)
    max_level = as_int(max_level, name="max_level", minimum=1, maximum=_MAX_LEVEL)
    beta = 1.0 / (gamma + 2.0)
    e = _sides(p)[None]
    first = min(8, max_level)
    s = _sums(e, first, beta)
    upper0 = float(s[0, 1])
    if gamma == 2.0:
        sides = np.diff(p, axis=0)
        exact = float(_parabola_arcs(sides[:-1], sides[1:]).sum())
        m = 32.0 * _EPS * upper0
        lo, hi = max(exact - m, float(s[-1, 0])), min(exact + m, float(s[-1, 1]))
        return LengthResult(
            value=exact,
            lower=lo,
            upper=hi,
            level=first,
            aitken=aitken(s[:, 1]),
            wynn=wynn_epsilon(s[:, 1]),
            lower_sequence=s[:, 0].copy(),
            upper_sequence=s[:, 1].copy(),
            success=hi - lo <= tol,
            message="exact closed form for gamma = 2 (parabola arcs)",
        )
    floor = 2.0 * _margin(max_level, beta, upper0, e.shape[1] * 2.0**max_level)
    at_floor = False
    while True:
        n = s.shape[0] - 1
        lo, hi = _certified(s, n, beta, upper0, e.shape[1])
        if hi - lo <= tol or n >= max_level:
            break
        if tol <= floor and hi - lo <= 2.0 * floor:
            at_floor = True  # rounding dominates: more levels cannot narrow the bracket
            break
        width = (1.0 - 2.0 * beta) * (s[:, 1] - s[:, 0])
        want = min(max_level, max(n + 1, _predict_level(width, n, 0.5 * tol, floor)))
        s = _sums(e, want, beta)
    est_w = wynn_epsilon(s[:, 1])
    ok = hi - lo <= tol
    if ok:
        message = f"certified bracket of width {hi - lo:.3g} at level {n}"
    elif at_floor:
        message = (
            f"bracket width {hi - lo:.3g} > tol = {tol:g}: tol is below the rounding floor "
            f"{floor:.3g} of a certificate in double precision"
        )
    else:
        message = f"bracket width {hi - lo:.3g} > tol = {tol:g} at max_level = {max_level}"
    return LengthResult(
        value=float(np.clip(est_w, lo, hi)),
        lower=lo,
        upper=hi,
        level=n,
        aitken=aitken(s[:, 1]),
        wynn=est_w,
        lower_sequence=s[:, 0].copy(),
        upper_sequence=s[:, 1].copy(),
        success=ok,
        message=message,
    )


def _certified(s: np.ndarray, n: int, beta: float, upper0: float, sides: int):
    """Outward-rounded bracket ``[l^n, L^{n+1}]`` from level-n sums (columns l, .., L, ..)."""
    lo_n, up_n = float(s[n, 0]), float(s[n, s.shape[1] // 2])
    m = _margin(n + 1, beta, upper0, sides * 2.0**n)
    up_next = (1.0 - 2.0 * beta) * up_n + 2.0 * beta * lo_n
    return lo_n - m, up_next + m


# --------------------------------------------------------------------------- interpolation


_SCALE_LIMIT = 2.0**100


def _rescaled(start, start_tangent, end, end_tangent):
    """Validate the data and bring extreme magnitudes near 1 by an exact power-of-two scaling.

    Returns ``(start, start_tangent, end, end_tangent, shift)``: the end points are multiplied
    by ``2**shift`` (``shift = 0`` unless coordinates exceed ``2**100`` or the chord is below
    ``2**-100``), tangents with an extreme magnitude are rescaled likewise (their direction is
    all that matters). Scaling by a power of two is exact, so the curve of the scaled data,
    scaled back, is the curve of the data, without the overflow (huge coordinates) or
    underflow (tiny ones) that made the length evaluation return NaN or divide by zero.
    """
    a = as_points([start], name="start", min_points=1)[0]
    c = as_points([end], name="end", min_points=1)[0]
    ua = as_points([start_tangent], name="start_tangent", min_points=1)[0]
    uc = as_points([end_tangent], name="end_tangent", min_points=1)[0]
    top = float(max(np.abs(a).max(), np.abs(c).max()))
    with np.errstate(over="ignore"):
        chord = float(np.abs(c - a).max())
    shift = 0
    if top > _SCALE_LIMIT:
        shift = -math.frexp(top)[1]
    elif 0.0 < chord < 1.0 / _SCALE_LIMIT:
        shift = -math.frexp(chord)[1]
    tangents = []
    for t in (ua, uc):
        size = float(np.abs(t).max())
        if size > _SCALE_LIMIT or 0.0 < size < 1.0 / _SCALE_LIMIT:
            t = np.ldexp(t, -math.frexp(size)[1])
        tangents.append(t)
    return np.ldexp(a, shift), tangents[0], np.ldexp(c, shift), tangents[1], shift


def _triangle(start, start_tangent, end, end_tangent) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    a = as_points([start], name="start", min_points=1)[0]
    c = as_points([end], name="end", min_points=1)[0]
    ua = as_points([start_tangent], name="start_tangent", min_points=1)[0]
    uc = as_points([end_tangent], name="end_tangent", min_points=1)[0]
    for name, t in (("start_tangent", ua), ("end_tangent", uc)):
        if not np.any(t):
            raise CurveError(f"{name} must be a non-zero vector, got {t.tolist()}")
    if np.array_equal(a, c):
        raise CurveError(f"start and end must differ, both are {a.tolist()}")
    ac = c - a
    den = ua[0] * uc[1] - ua[1] * uc[0]
    scale = math.hypot(*ua) * math.hypot(*uc)
    if abs(den) <= 1e-12 * scale:
        raise CurveError(
            f"start_tangent {ua.tolist()} and end_tangent {uc.tolist()} are parallel: "
            "the tangent lines must meet in a point B"
        )
    alpha = (ac[0] * uc[1] - ac[1] * uc[0]) / den
    beta = (ua[0] * ac[1] - ua[1] * ac[0]) / den
    if not (alpha > 0.0 and beta > 0.0):
        raise CurveError(
            f"the tangent lines meet at B = A + {alpha:.6g} start_tangent = C - {beta:.6g} "
            "end_tangent; both coefficients must be > 0 (tangents diverge or point away): "
            f"start_tangent {ua.tolist()}, end_tangent {uc.tolist()}"
        )
    b = a + alpha * ua
    return a, b, c


def _polygon(a: np.ndarray, b: np.ndarray, c: np.ndarray, x: float) -> np.ndarray:
    s1 = a + x * (b - a)
    s2 = c + x * (b - c)
    return np.array([2.0 * a - s1, s1, s2, 2.0 * c - s2])


def control_polygon(
    start: ArrayLike, start_tangent: ArrayLike, end: ArrayLike, end_tangent: ArrayLike, x: float
) -> np.ndarray:
    """The control polygon ``S_0(x), S_1(x), S_2(x), S_3(x)`` of section 3 with ``y = x``.

    Parameters
    ----------
    start, end : (2,) array_like
        End points ``A`` and ``C`` of the curve.
    start_tangent, end_tangent : (2,) array_like
        Tangent directions ``u_A``, ``u_C``; their lines must meet at
        ``B = A + alpha u_A = C - beta u_C`` with ``alpha, beta > 0``.
    x : float
        Parameter in ``[0, 1]``: ``S_1 = x B + (1 - x) A``, ``S_0 = 2A - S_1``,
        ``S_2 = x B + (1 - x) C``, ``S_3 = 2C - S_2``.

    Returns
    -------
    (4, 2) ndarray

    Examples
    --------
    >>> control_polygon([-1.5, -1], [1.5, 2], [1.5, 0], [1.5, -1], 0.5).tolist()
    [[-2.25, -2.0], [-0.75, 0.0], [0.75, 0.5], [2.25, -0.5]]
    """
    a, b, c = _triangle(start, start_tangent, end, end_tangent)
    x = as_float(x, name="x", low=0.0, high=1.0, low_open=False, high_open=False)
    return _polygon(a, b, c, x)


def paper_level(
    start: ArrayLike,
    start_tangent: ArrayLike,
    end: ArrayLike,
    end_tangent: ArrayLike,
    *,
    tol: float,
) -> int:
    """Level ``n`` of section 4: the smallest with ``(|AB| + |BC|) 0.25^n < tol / 2``.

    Examples
    --------
    >>> paper_level([-1.5, -1], [1.5, 2], [1.5, 0], [1.5, -1], tol=1e-4)
    9
    """
    a, b, c = _triangle(start, start_tangent, end, end_tangent)
    tol = as_float(tol, name="tol", low=0.0)
    return _paper_level(float(np.hypot(*(b - a)) + np.hypot(*(c - b))), tol)


def _paper_level(total: float, tol: float) -> int:
    n = 0
    while total * 0.25**n >= tol / 2.0:
        n += 1
    return n


@dataclass(frozen=True)
class InterpolationResult(RichRepr):
    """A de Rham curve through ``A`` and ``C`` with given tangents and prescribed length.

    Attributes
    ----------
    x : float
        The parameter of the control polygon :func:`control_polygon`.
    points : (2^(k+1) + 1, 2) ndarray
        Points of the curve from ``A`` to ``C``: the midpoints of the sides of the
        level-``k`` polygon (``k`` = the ``level`` argument), which lie exactly on
        the limit curve.
    length : float
        The method's estimate of the curve's length: ``f^n(x_p)`` for the paper's
        methods (as in its tables); the extrapolated (``gamma != 2``) or exact
        (``gamma = 2``) length, clipped into ``[lower, upper]``, for ``"accelerated"``.
    lower, upper : float
        Bracket of the true length ``f(x)``: ``l^n(x) <= f(x) <= L^{n+1}(x)``
        outward-rounded (for ``gamma = 2`` and ``"accelerated"``: the closed form
        plus or minus its rounding bound).
    iterations : int
        Index ``p`` of the returned iterate ``x_p`` (paper's methods, as counted in
        its tables) or number of Taylor steps (``"accelerated"``).
    evaluations : int
        Number of length evaluations (``f^n``, or the extrapolated or exact
        length with its Taylor polynomial, or the certifying refinement); the
        known values ``f(0) = |AC|``, ``f(1) = |AB| + |BC|`` and the level-0
        starting model (arithmetic on the four control points) are not counted.
    level : int
        Level ``n`` of ``f^n`` (paper's methods) or of the certificate.
    certified : bool
        Whether ``length - tol <= lower`` and ``upper <= length_target + tol``,
        i.e. the curve's true length is proven within `tol` of the target.
    success : bool
        Paper's methods: the stopping rule ``|f^n(x_p) - l| <= tol / 2`` was met.
        ``"accelerated"``: the result is certified.
    message : str
        Human-readable outcome.
    method : str
        The method used.
    """

    x: float
    points: np.ndarray = field(repr=False)
    length: float
    lower: float
    upper: float
    iterations: int
    evaluations: int
    level: int
    certified: bool
    success: bool
    message: str
    method: str


class _Problem:
    """f(x) = L(x, x) of section 3 for fixed A, B, C and gamma, with x-derivatives.

    The sides of the control polygon are affine in x:
    ``S_1 - S_0 = 2x (B - A)``, ``S_2 - S_1 = (1 - x)(C - A)`` (with ``y = x`` the
    ``B`` terms cancel), ``S_3 - S_2 = 2x (C - B)``; subdivision is linear, so
    every refined side is affine in x as well and its derivative is refined
    alongside.
    """

    def __init__(self, a: np.ndarray, b: np.ndarray, c: np.ndarray, gamma: float):
        self.a, self.b, self.c, self.gamma = a, b, c, gamma
        self.beta = 1.0 / (gamma + 2.0)
        self.f0 = float(np.hypot(*(c - a)))
        self.f1 = float(np.hypot(*(b - a)) + np.hypot(*(c - b)))
        z = (a[0] + 1j * a[1], b[0] + 1j * b[1], c[0] + 1j * c[1])
        self.e0 = np.array([0.0, z[2] - z[0], 0.0])
        self.e1 = np.array([2.0 * (z[1] - z[0]), z[0] - z[2], 2.0 * (z[2] - z[1])])
        self.evaluations = 0

    def sides(self, x: float, order: int) -> np.ndarray:
        e = self.e0 + x * self.e1
        return e[None] if order == 0 else np.stack([e, self.e1])

    def sums(self, x: float, levels: int, order: int = 0) -> np.ndarray:
        """Columns as in :func:`_sums` for levels ``0 .. levels``."""
        self.evaluations += 1
        return _sums(self.sides(x, order), levels, self.beta, order)

    def exact(self, x: float, order: int) -> np.ndarray:
        """For gamma = 2: Taylor coefficients of f at x up to ``h^order``.

        The constant term is the closed form (:func:`parabola_length`); the
        others integrate the coefficients of ``|r(t) + h r_x(t)|`` over each arc
        by Gauss-Legendre quadrature (the integrand is analytic in t).
        """
        self.evaluations += 1
        e = self.e0 + x * self.e1
        v = np.stack([e.real, e.imag], axis=1)
        t = _GL_T[:, None]
        r = e[None, :-1] + t * (e[1:] - e[:-1])[None]
        rx = self.e1[None, :-1] + t * (self.e1[1:] - self.e1[:-1])[None]
        c = (_abs_taylor(r, rx, order) * _GL_W[None, :, None]).sum(axis=(1, 2))
        c[0] = _parabola_arcs(v[:-1], v[1:]).sum()
        return c


def interpolate(
    start: ArrayLike,
    start_tangent: ArrayLike,
    end: ArrayLike,
    end_tangent: ArrayLike,
    *,
    length: float,
    gamma: float = 2.0,
    tol: float = 1e-9,
    method: Literal["accelerated", "regula_falsi", "secant"] = "accelerated",
    level: int = 6,
    length_level: int | None = None,
    max_iterations: int = 200,
) -> InterpolationResult:
    """Convex G1 de Rham curve from ``A`` to ``C`` with given tangents and prescribed length.

    Sections 3-4 of Merrien: the curve of the control polygon
    :func:`control_polygon` at the solution of ``f(x) = L(x, x) = length``;
    ``f`` is convex and strictly increasing (Propositions 1-3).

    Parameters
    ----------
    start, end : (2,) array_like
        End points ``A`` and ``C``, distinct.
    start_tangent, end_tangent : (2,) array_like
        Non-zero tangent directions ``u_A`` at ``A`` and ``u_C`` at ``C`` (the
        curve leaves ``A`` along ``u_A`` and arrives at ``C`` along ``u_C``);
        the lines must meet at ``B = A + alpha u_A = C - beta u_C`` with
        ``alpha, beta > 0``.
    length : float
        Prescribed length, strictly between ``|AC|`` and ``|AB| + |BC|``.
    gamma : float, optional
        De Rham parameter, ``gamma > 1``.
    tol : float, optional
        Accuracy ``eps > 0`` on the length.
    method : {"accelerated", "regula_falsi", "secant"}, optional
        ``"regula_falsi"``: Lemma 4, ``x_0 = 0``,
        ``x_{p+1} = 1 - g(1) (x_p - 1) / (g(x_p) - g(1))``.
        ``"secant"``: Lemma 5, ``x_0 = 0``, ``x_1 = 1``, secant steps with
        ``x_{3k+1} = min(u, x_1, x_4, .., x_{3k-2})``.
        Both on ``g = f^n - length`` with the algorithm of section 4: ``n`` from
        ``(|AB| + |BC|) 0.25^n < eps / 2`` and stop when ``|f^n(x_p) - length| <= eps / 2``.
        ``"accelerated"`` (default): steps from a local Taylor polynomial (order
        12 in x) of the exact length (``gamma = 2``) or of Wynn's extrapolation
        of ``L^k(x)``, bracketed in ``[0, 1]``, then certified by the exact
        length or by ``l^n(x) <= f(x) <= L^{n+1}(x)`` at the level ``n`` where
        the bracket fits within ``tol``; usually two length evaluations.
    level : int, optional
        Subdivision level ``k`` of the returned points (``2^(k+1) + 1`` points).
    length_level : int, optional
        Override ``n`` of the paper's methods (the tables of section 5 use
        levels that differ from the printed rule).
    max_iterations : int, optional
        Cap on iterations before reporting ``success=False``.

    Returns
    -------
    InterpolationResult

    Raises
    ------
    CurveError
        Parallel, diverging or zero tangents, ``start == end``, ``gamma <= 1``,
        ``tol <= 0`` or `length` outside ``(|AC|, |AB| + |BC|)``.

    Examples
    --------
    The paper's data (section 5), length 4:

    >>> r = interpolate([-1.5, -1], [1.5, 2], [1.5, 0], [1.5, -1], length=4.0, tol=1e-12)
    >>> r.success, round(r.x, 10), abs(r.length - 4.0) < 1e-12
    (True, 0.8252055686, True)
    """
    *data, shift = _rescaled(start, start_tangent, end, end_tangent)
    a, b, c = _triangle(*data)
    gamma = as_float(gamma, name="gamma", low=1.0)
    tol = math.ldexp(as_float(tol, name="tol", low=0.0), shift)
    level = as_int(level, name="level", minimum=0, maximum=16)
    max_iterations = as_int(max_iterations, name="max_iterations", minimum=1)
    as_choice(method, METHODS, name="method")
    prob = _Problem(a, b, c, gamma)
    length = as_float(length, name="length")
    target = math.ldexp(length, shift)
    if not prob.f0 < target < prob.f1:
        raise CurveError(
            f"length must lie in the open interval (|AC|, |AB| + |BC|) = "
            f"({math.ldexp(prob.f0, -shift):.10g}, {math.ldexp(prob.f1, -shift):.10g}) for "
            f"these end points and tangents, got {length:g}"
        )
    if method == "accelerated":
        out = _accelerated(prob, target, tol, max_iterations)
    else:
        if length_level is None:
            n = _paper_level(prob.f1, tol)
            if n > _MAX_LEVEL:
                raise CurveError(
                    f"tol = {tol:g} needs level n = {n} > {_MAX_LEVEL} by the rule of section 4 "
                    "for the paper's methods; use method='accelerated' or pass length_level"
                )
        else:
            n = as_int(length_level, name="length_level", minimum=0, maximum=_MAX_LEVEL)
        out = _paper_method(prob, target, tol, n, method, max_iterations)
    x, est, lo, hi, its, n, success, message = out
    if shift:
        message += f" (lengths above in units of 2**{-shift}: the data were scaled by 2**{shift})"
    certified = target - tol <= lo and hi <= target + tol
    x = float(x)
    return InterpolationResult(
        x=x,
        points=np.ldexp(_curve_points(a, c, _polygon(a, b, c, x), gamma, level), -shift),
        length=math.ldexp(float(est), -shift),
        lower=math.ldexp(float(lo), -shift),
        upper=math.ldexp(float(hi), -shift),
        iterations=its,
        evaluations=prob.evaluations,
        level=n,
        certified=certified,
        success=success,
        message=message,
        method=method,
    )


def _curve_points(a, c, poly: np.ndarray, gamma: float, level: int) -> np.ndarray:
    if np.array_equal(poly[0], poly[1]):  # x == 0: the chord
        return np.linspace(a, c, 2 ** (level + 1) + 1)
    q = de_rham(poly, gamma=gamma, iterations=level)
    pts = 0.5 * (q[1:] + q[:-1])
    pts[0], pts[-1] = a, c
    return pts


def _paper_method(prob: _Problem, target: float, tol: float, n: int, method: str, cap: int):
    """Regula falsi (Lemma 4) or modified secant (Lemma 5) on g = f^n - target, section 4."""
    upper0 = prob.f1

    def f(x: float) -> tuple[float, float]:
        s = prob.sums(x, n)
        return float(s[n, 1]), float(s[n, 0])

    g1 = prob.f1 - target
    # x_0 = 0 with f^n(0) = |AC|, known exactly.
    xs = [0.0]
    gs = [prob.f0 - target]
    lows = [prob.f0]
    if method == "secant":
        xs.append(1.0)
        gs.append(g1)
        lows.append(prob.f1)  # x = 1: S_1 = S_2 = B, the curve is the polygon A B C
    p = len(xs) - 1
    done = abs(gs[p]) <= tol / 2.0
    while not done and p < cap:
        if method == "regula_falsi":
            xn = 1.0 - g1 * (xs[p] - 1.0) / (gs[p] - g1)
        else:
            u = xs[p] - gs[p] * (xs[p] - xs[p - 1]) / (gs[p] - gs[p - 1])
            # p = 3k: x_{3k+1} = min(u, x_1, x_4, ..., x_{3k-2}); otherwise u.
            xn = min([u] + [xs[j] for j in range(1, p, 3)]) if p % 3 == 0 else u
        up, lo = f(xn)
        xs.append(xn)
        gs.append(up - target)
        lows.append(lo)
        p += 1
        done = abs(gs[p]) <= tol / 2.0
    x = xs[p]
    up = gs[p] + target
    if x == 0.0:
        lo_c, hi_c = prob.f0, prob.f0
    else:
        beta = prob.beta
        m = _margin(n + 1, beta, upper0, 2 * 2.0**n)
        lo_c = lows[p] - m
        hi_c = (1.0 - 2.0 * beta) * up + 2.0 * beta * lows[p] + m
    if done:
        message = f"|f^{n}(x_{p}) - length| = {abs(gs[p]):.3g} <= tol/2 after {p} iterations"
    else:
        message = f"no convergence in {cap} iterations: |f^{n}(x_p) - length| = {abs(gs[p]):.3g}"
    return x, up, lo_c, hi_c, p, n, done, message


def _halley(x: float, g: float, d1: float, d2: float, lo: float, hi: float) -> float:
    """One Halley step for g(x) = 0 kept inside the bracket (bisection otherwise)."""
    den = 2.0 * d1 * d1 - g * d2
    xn = x - 2.0 * g * d1 / den if den > 0.0 and d1 > 0.0 else x - g / max(d1, _EPS)
    return xn if lo < xn < hi else 0.5 * (lo + hi)


def _initial_guess(prob: _Problem, target: float) -> float:
    """Root of the level-0 model ``L^0 - 2 beta (L^0 - l^0) / (1 - 1/4)``.

    The model is the sum of the geometric tail ``L - L^0 = -2 beta sum_k d_k`` with
    ratio 1/4 (section 2); it is arithmetic on the four control points, like the
    known ``f(0) = |AC|`` and ``f(1) = |AB| + |BC|``, and is not counted as a length
    evaluation. Its root is within about 0.02 of the solution on the paper's data.
    """
    w = 2.0 * prob.beta / 0.75
    e0, e1 = prob.e0.tolist(), prob.e1.tolist()
    # (weight in the model, side vector at x = 0, its x-derivative)
    terms = [
        ((1.0 - w) * 0.5, e0[0], e1[0]),
        (1.0 - w, e0[1], e1[1]),
        ((1.0 - w) * 0.5, e0[2], e1[2]),
        (0.5 * w, e0[0] + e0[1], e1[0] + e1[1]),
        (0.5 * w, e0[1] + e0[2], e1[1] + e1[2]),
    ]
    lo, hi = 0.0, 1.0
    x = (target - prob.f0) / (prob.f1 - prob.f0)
    for _ in range(40):
        g, d1, d2 = -target, 0.0, 0.0
        for weight, z0, z1 in terms:
            z = z0 + x * z1
            r = abs(z)
            g += weight * r
            if r > 0.0:
                cross = z.real * z1.imag - z.imag * z1.real
                d1 += weight * (z.real * z1.real + z.imag * z1.imag) / r
                d2 += weight * cross * cross / (r * r * r)
            else:
                d1 += weight * abs(z1)
        if g < 0.0:
            lo = x
        else:
            hi = x
        xn = _halley(x, g, d1, d2, lo, hi)
        done = abs(xn - x) <= 1e-9
        x = xn
        if done:
            break
    return min(max(x, 1e-6), 1.0 - 1e-6)


_TAYLOR = 12  # order of the local Taylor model of f used by the default method


def _taylor_step(c: np.ndarray, target: float, lo: float, hi: float, x: float):
    """Solve ``sum_k c_k h^k = target`` for h by Newton's method on the polynomial.

    Returns ``(h, tail)`` with ``tail = 4 max_{k >= K-2} |c_k h^k|``, an estimate of
    the truncation error (large when ``|h|`` exceeds the radius of convergence),
    or ``(None, inf)`` if Newton fails or leaves ``(lo, hi)``.
    """
    g, d1, d2 = c[0] - target, c[1], 2.0 * c[2]
    den = 2.0 * d1 * d1 - g * d2
    h = -2.0 * g * d1 / den if den > 0.0 and d1 > 0.0 else -g / max(d1, _EPS)
    poly = np.polynomial.Polynomial(c)
    dpoly = poly.deriv()
    for _ in range(60):
        step = (poly(h) - target) / dpoly(h)
        h -= step
        if not (lo < x + h < hi and math.isfinite(h)):
            return None, math.inf
        if abs(step) <= 4.0 * _EPS * max(abs(h), 1e-300) or step == 0.0:
            break
    k = len(c) - 1
    tail = 4.0 * max(abs(c[j]) * abs(h) ** j for j in range(k - 2, k + 1))
    return h, tail


def _accelerated(prob: _Problem, target: float, tol: float, cap: int):
    """Local Taylor inversion of an accurate length model, then a certificate.

    Model: the Taylor polynomial of order 12 of ``f`` at the current x -- for
    ``gamma = 2`` the closed form plus Gauss-Legendre coefficients; otherwise
    Wynn's epsilon extrapolation of ``L^0(x) .. L^m(x)`` and ``L^k'(x)`` with
    the higher coefficients of ``L^m`` (``m = 8, 10, 12`` by tolerance; each
    ``|side|`` is the square root of a quadratic in x, whose Taylor
    coefficients follow from a recurrence). From the level-0 starting guess
    (:func:`_initial_guess`) the polynomial is solved for the step; a bracket
    ``[x_lo, x_hi]`` with ``f(x_lo) < length < f(x_hi)`` is kept (``f``
    increases, Proposition 3) and bisected when a step fails or leaves it. When
    the truncation estimate of a step is below ``tol / 10`` the step is taken
    without another model evaluation and x goes to the certificate: the exact
    length (``gamma = 2``) or ``l^n(x) <= f(x) <= L^{n+1}(x)`` at the level
    ``n`` predicted from the observed contraction of ``L^k - l^k`` (deepened
    while too wide). A narrow but off-centre certificate sends x back to the
    model. Typically two length evaluations in all.
    """
    exact = prob.gamma == 2.0
    m = 8 if tol >= 1e-7 else (10 if tol >= 1e-10 else 12)
    order = _TAYLOR
    beta = prob.beta
    m_round = 32.0 * _EPS * prob.f1
    margin = _margin(_MAX_LEVEL, beta, prob.f1, 3 * 2.0**_MAX_LEVEL)
    last: dict[str, np.ndarray] = {}

    def model(x: float) -> np.ndarray:
        if exact:
            return prob.exact(x, order)
        s = prob.sums(x, m, order=order)
        last["s"] = s
        low, up = s[m, : order + 1], s[m, order + 1 :]
        up_next = (1.0 - 2.0 * beta) * up + 2.0 * beta * low  # L^{m+1} and its coefficients
        w_up, w_low = wynn_epsilon(s[:, order + 1]), wynn_epsilon(s[:, 0])
        # Trust the extrapolation only inside the level-m bracket and when the two
        # sequences agree; before the asymptotic regime (a tiny side of S_0..S_3) the
        # smooth midpoint of the bracket is a safer model (the certificate corrects it).
        if low[0] <= w_up <= up_next[0] and abs(w_up - w_low) <= 1e-3 * (up_next[0] - low[0]):
            c = up.copy()
            c[0] = w_up
            c[1] = wynn_epsilon(s[:, order + 2])
        else:
            c = 0.5 * (low + up_next)
        c[0] += bias[0]
        return c

    bias = [0.0]  # defect of the model measured by the last certificate
    cert_lo, cert_hi = 0.0, 1.0  # bracket of the root proven by certificates
    x_lo, x_hi = 0.0, 1.0
    x = _initial_guess(prob, target)
    its = 0
    c = model(x)
    xc = x  # centre of the Taylor model c
    lo = hi = float("nan")
    n, ok = m, False
    est = float(c[0])
    corrected = False
    for _ in range(8):
        # model phase: Taylor steps until the truncation estimate is below tol / 10
        while not corrected:
            g = float(c[0]) - target if x == xc else math.nan
            if x == xc:
                if g < 0.0:
                    x_lo = max(x_lo, x)
                else:
                    x_hi = min(x_hi, x)
                if abs(g) + m_round <= (tol if exact else 0.1 * tol):
                    break
            if its >= cap or x_hi - x_lo <= 4.0 * _EPS:
                break
            h, tail = _taylor_step(c, target, x_lo, x_hi, xc)
            its += 1
            if h is None:
                x = xc = 0.5 * (x_lo + x_hi)
                c = model(x)
                continue
            x = xc + h
            if exact or tail > 0.1 * tol:
                xc = x
                c = model(x)
                continue
            break  # gamma != 2: certify x without another model evaluation
        if exact:
            est = float(c[0])
            lo, hi = est - m_round, est + m_round
            ok = target - tol <= lo and hi <= target + tol
            break
        s = last["s"]
        if tol <= 2.0 * margin:
            lo, hi = _certified(s, m, beta, prob.f1, 3)
            est = float(np.clip(c[0], lo, hi))
            break
        width = (1.0 - 2.0 * beta) * (s[:, order + 1] - s[:, 0])
        n = min(max(_predict_level(width, m, 0.8 * tol, 2.0 * margin), m, n), 24)
        while True:
            sc = prob.sums(x, n)
            lo, hi = _certified(sc, n, beta, prob.f1, 3)
            if hi - lo <= tol or n >= 24:
                break
            n += 1
        # the certificate's own sequence L^0(x) .. L^n(x), extrapolated
        est = float(np.clip(wynn_epsilon(sc[:, 1]), lo, hi))
        ok = target - tol <= lo and hi <= target + tol
        if ok or hi - lo > tol or its >= cap:
            break
        # Narrow but off-centre: the model is biased here (e.g. pre-asymptotic
        # levels when a side of S_0..S_3 is tiny). Shift its constant term by the
        # certified defect at x and step again from its centre (defect correction).
        if hi < target:
            cert_lo = max(cert_lo, x)
        elif lo > target:
            cert_hi = min(cert_hi, x)
        x_lo, x_hi = cert_lo, cert_hi  # model-based bracket updates may have been biased
        defect = est - float(np.polynomial.Polynomial(c)(x - xc))
        bias[0] += defect
        c = c.copy()
        c[0] += defect
        h, _ = _taylor_step(c, target, x_lo, x_hi, xc)
        its += 1
        corrected = h is not None  # certify the corrected x directly
        if h is None:
            x = xc = 0.5 * (x_lo + x_hi)
            c = model(x)
        else:
            x = xc + h
    if exact:
        g = est - target
        message = (
            f"certified |f(x) - length| <= {abs(g) + m_round:.3g} (exact length, gamma = 2) "
            f"after {its} steps"
            if ok
            else f"no certified solution after {its} steps: |f(x) - length| = {abs(g):.3g}"
        )
        return x, est, lo, hi, its, 0, ok, message
    if ok:
        message = f"certified: length in [{lo:.15g}, {hi:.15g}] (level {n}) after {its} steps"
    elif tol <= 2.0 * margin:
        n = m
        message = (
            f"not certified: tol = {tol:g} is below the rounding floor {2.0 * margin:.3g} "
            "of a certificate in double precision"
        )
    else:
        message = (
            f"not certified: bracket [{lo:.15g}, {hi:.15g}] at level {n} does not fit "
            f"within tol = {tol:g} of {target:g}"
        )
    return x, est, lo, hi, its, n, ok, message


@dataclass(frozen=True)
class ChainResult(RichRepr):
    """G1 chain of de Rham curves with a prescribed length per span (:func:`interpolate_chain`).

    Attributes
    ----------
    points : (M, 2) ndarray
        Points of the whole curve, spans joined without repeating the shared points.
    spans : tuple of InterpolationResult
        One result per span, in order.
    length, lower, upper : float
        Sums over the spans of the estimates and certified bounds.
    success : bool
        Whether every span succeeded.
    message : str
        Summary, naming the first failing span if any.
    """

    points: np.ndarray = field(repr=False)
    spans: tuple[InterpolationResult, ...] = field(repr=False)
    length: float
    lower: float
    upper: float
    success: bool
    message: str


def interpolate_chain(
    points: ArrayLike,
    tangents: ArrayLike,
    lengths: ArrayLike,
    *,
    gamma: float = 2.0,
    tol: float = 1e-9,
    method: Literal["accelerated", "regula_falsi", "secant"] = "accelerated",
    level: int = 6,
) -> ChainResult:
    """G1 curve through several points with given tangents and a prescribed length per span.

    Span ``i`` is :func:`interpolate` from ``points[i]`` with tangent
    ``tangents[i]`` to ``points[i + 1]`` with tangent ``tangents[i + 1]`` and length
    ``lengths[i]``; consecutive spans share the point and the tangent direction,
    so the chain is G1 (each span is convex; the chain may have inflections at
    the joints).

    Parameters
    ----------
    points : (K, 2) array_like
        Points to pass through, ``K >= 2``.
    tangents : (K, 2) array_like
        Non-zero tangent directions at the points.
    lengths : (K - 1,) array_like
        Length of every span, each in its admissible interval.
    gamma, tol, method, level
        As for :func:`interpolate`.

    Returns
    -------
    ChainResult

    Raises
    ------
    CurveError
        On bad shapes, or on bad data of any span (the message names the span).

    Examples
    --------
    >>> r = interpolate_chain([[0, 0], [2, 0], [4, 0]], [[1, 1], [1, -1], [1, 1]], [2.3, 2.3])
    >>> r.success, round(r.length, 9), r.points.shape
    (True, 4.6, (257, 2))
    """
    p = as_points(points, name="points", min_points=2)
    t = as_points(tangents, name="tangents", min_points=2)
    if t.shape != p.shape:
        raise CurveError(f"tangents must have the shape of points {p.shape}, got {t.shape}")
    try:
        lens = np.array(lengths, dtype=float).ravel()
    except (TypeError, ValueError):
        raise CurveError(f"lengths must be {p.shape[0] - 1} numbers, got {lengths!r}") from None
    if lens.shape[0] != p.shape[0] - 1:
        raise CurveError(
            f"lengths must have {p.shape[0] - 1} entries (one per span), got {lens.shape[0]}"
        )
    spans = []
    for i in range(p.shape[0] - 1):
        try:
            spans.append(
                interpolate(
                    p[i],
                    t[i],
                    p[i + 1],
                    t[i + 1],
                    length=lens[i],
                    gamma=gamma,
                    tol=tol,
                    method=method,
                    level=level,
                )
            )
        except CurveError as exc:
            raise CurveError(f"span {i} (points {i} -> {i + 1}): {exc}") from None
    pts = np.concatenate([spans[0].points] + [s.points[1:] for s in spans[1:]])
    bad = [i for i, s in enumerate(spans) if not s.success]
    return ChainResult(
        points=pts,
        spans=tuple(spans),
        length=float(sum(s.length for s in spans)),
        lower=float(sum(s.lower for s in spans)),
        upper=float(sum(s.upper for s in spans)),
        success=not bad,
        message="all spans succeeded"
        if not bad
        else f"span {bad[0]} failed: {spans[bad[0]].message}",
    )
