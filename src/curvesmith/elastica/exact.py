"""Exact discrete elasticae: sampling, discrete curvature and conserved quantities.

Implements sections 3.1-4.1 of Graiff Zurita, Kajiwara & Suzuki, "Fairing of
discrete planar curves by integrable discrete analogue of Euler's elasticae".

Parametrisation used throughout (one family in ``k``, Remark 2.4)
-----------------------------------------------------------------
The potential function of eq. (4.3) (case (ii)) is

    cos((theta_n - phi)/2) = dn(z n + q; k),   sin((theta_n - phi)/2) = k sn(z n + q; k),

and the vertices are ``gamma_{n+1} = gamma_n + h T_n`` with the tangent angle
``Theta_n = (theta_{n+1} + theta_n)/2`` of eq. (3.28). The modulus ``k > 0`` is
continued through ``k = 1``: by the reciprocal-modulus transformation
``k sn(w; k) = sn(k w; 1/k)`` and ``dn(w; k) = cn(k w; 1/k)``, so ``k > 1`` is
exactly case (i), eq. (4.2), with modulus ``1/k`` and the *same* ``z`` and ``q``.
Hence ``k < 1``: elastica with inflections (case (ii)); ``k > 1``: without
(case (i), modulus ``1/k``); ``k = 1``: the separatrix (``tanh``/``sech``). This
matches the paper's Table 1, where arc-like keylines have ``k`` of 27.

Verified discrepancies with the printed formulas (scratch checks, and the tests):

* eq. (4.4) prints the tangent angle as ``(theta_{n+1}-phi)/2 + (theta_n-phi)/2 - phi``.
  That is ``Theta_n - 2 phi``, i.e. the unrotated curve turned by ``-phi``; with
  it, Prop. 4.1 with ``I = (sin phi, -cos phi)`` of eq. (4.13) fails (the fitted
  affine law has residuals of order 1 unless ``phi = 0``). The rotation that
  agrees with eq. (4.1) and (4.13)-(4.16) is ``+ phi``: ``Theta_n = phi + a_n +
  a_{n+1}`` with ``a_n = (theta_n - phi)/2``. Prop. 4.1 then holds to 1e-13.
* eq. (4.4) also pairs ``gamma_n - gamma_{n-1}`` with ``theta_{n+1}, theta_n``,
  one index off eq. (3.28)/(3.1). We use (3.28), so vertex ``n`` sits at
  argument ``s_n = z n + q`` (``q = s_0`` as in eq. (4.54)) and its discrete
  curvature is ``kappa_n = (2 k sn(z)/(h dn(z))) cn(z n + q)``, eq. (3.20)
  shifted by ``q``.
* eqs. (4.17)/(4.18) print ``sin(Psi_n - phi)``; with ``Psi_n = pi/2 + Theta_n - phi``
  the projection step is ``(u_{n+1} - u_n)/h = -sin(Theta_n - phi) = cos(Psi_n)``
  (consistent with eq. (4.22)); the printed form is off by O(1) unless ``phi = 0``.
  Prop. 4.1 and Cor. 4.2 themselves hold to 1e-13 (tests).
* The proof of Prop. 3.6 prints ``dn v = (1+eps)/(1-eps)`` and ``cn v = (1+eps)(1-eps)``;
  the statements (3.43)/(3.44), ``(1-eps)/(1+eps)``, are right: with them
  ``Lambda = (1+eps) dn(z)`` and ``mu = 4 eps/h^2`` reproduce the slope ``mu/Lambda``
  of Prop. 4.1 on sampled curves to 1e-13 (:func:`invariants`).
* eq. (3.27) repeats (3.26) with the cases swapped (a duplicated line).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from typing import Literal, NamedTuple

import numpy as np
from numpy.typing import ArrayLike
from scipy.special import ellipj as _scipy_ellipj

from .._validate import as_choice, as_int, as_points
from ..errors import CurveError
from ._elliptic import _AGM_BAND, _sd2_integral, ellipj, ellipj_am, sech

__all__ = [
    "ElasticaParams",
    "Invariants",
    "case_of",
    "curvature",
    "exact_curvature",
    "invariants",
    "sample",
    "segment_length",
    "tangent_angles",
]

#: Within this distance of m = 1 the k-derivative is a central difference of the
#: guarded functions (the analytic form divides by 1 - m).
_SEPARATRIX_BAND = 1e-6
_FD_STEP = 1e-7


class ElasticaParams(NamedTuple):
    """The seven parameters ``p = (x0, y0, h, phi, z, q, k)`` of eq. (4.5).

    ``k`` is the modulus continued through 1 (see the module docstring):
    ``k < 1`` case (ii), ``k > 1`` case (i) with modulus ``1/k``.
    """

    x0: float
    y0: float
    h: float
    phi: float
    z: float
    q: float
    k: float


def case_of(k: float) -> str:
    """Name the paper's case for a continued modulus `k`.

    Parameters
    ----------
    k : float
        Continued modulus, ``k > 0``.

    Returns
    -------
    str
        ``"ii"`` (inflections, ``k < 1``), ``"i"`` (no inflection, ``k > 1``) or
        ``"separatrix"`` (``k == 1``).

    Examples
    --------
    >>> case_of(0.3), case_of(27.4)
    ('ii', 'i')
    """
    if k < 1.0:
        return "ii"
    if k > 1.0:
        return "i"
    return "separatrix"


def _as_params(params, *, case: str | None = None) -> ElasticaParams:
    try:
        arr = np.array(params, dtype=float).ravel()
    except (TypeError, ValueError) as exc:
        raise CurveError(f"params must be 7 numbers (x0, y0, h, phi, z, q, k): {exc}") from None
    if arr.size != 7:
        raise CurveError(f"params must be 7 numbers (x0, y0, h, phi, z, q, k), got {arr.size}")
    if not np.all(np.isfinite(arr)):
        raise CurveError(f"params must be finite, got {arr.tolist()}")
    if arr[2] <= 0:
        raise CurveError(f"params h must be > 0, got {arr[2]}")
    if arr[6] <= 0:
        raise CurveError(f"params k must be > 0, got {arr[6]}")
    as_choice(case, (None, "i", "ii"), name="case")
    if case == "i":
        if arr[6] > 1.0:
            raise CurveError(f"case (i) needs a modulus k <= 1, got {arr[6]}")
        arr[6] = 1.0 / arr[6]
    elif case == "ii" and arr[6] > 1.0:
        raise CurveError(f"case (ii) needs a modulus k <= 1, got {arr[6]}")
    return ElasticaParams(*(float(v) for v in arr))


def _ellipj_scalar_m(u: np.ndarray, m: float):
    """``sn, cn, dn, am`` for one parameter ``0 <= m <= 1``: scipy directly where it is accurate."""
    if m < 1.0 - _AGM_BAND:
        return _scipy_ellipj(u, m)
    return ellipj_am(u, m)


@functools.lru_cache(maxsize=2)
def _progression(z: float, q: float, n_points: int, k: float):
    """Arguments ``s_n = z n + q`` (n = 0..N-1) and the Jacobi functions of the half angle there.

    Returns ``(s, jf)``: ``jf = (sn, cn, dn, am)`` at ``(s | k^2)`` for ``k < 1``, at
    ``(k s | 1/k^2)`` for ``k > 1``, None for ``k = 1``. Memoised on the four numbers:
    a least-squares solver asks for the residuals and then for the Jacobian at the
    same point, and the initial guess samples the point the solver starts from. The
    arrays are read-only.
    """
    s = np.arange(n_points, dtype=float)
    s *= z
    s += q
    if k == 1.0:
        jf = None
    elif k < 1.0:
        jf = _ellipj_scalar_m(s, k * k)
    else:
        jf = _ellipj_scalar_m(k * s, 1.0 / (k * k))
    for arr in (s, *(jf or ())):
        arr.flags.writeable = False
    return s, jf


def _half_angles(s: np.ndarray, k: float, jf=None):
    """``S = sin a``, ``C = cos a``, ``a = (theta - phi)/2`` at arguments `s` (eq. 4.3).

    `jf`: the Jacobi functions of :func:`_progression` at `s`, if already known.
    """
    m = k * k
    if k == 1.0:
        return np.tanh(s), sech(s)
    if k < 1.0:
        sn, _, dn, _ = _ellipj_scalar_m(s, m) if jf is None else jf
        return k * sn, dn
    sn, cn, _, _ = _ellipj_scalar_m(k * s, 1.0 / m) if jf is None else jf
    return sn, cn


def _family(s: np.ndarray, k: float, jf=None):
    """Half angle ``a(s; k)`` as (S, C) with its derivatives ``da/ds`` and ``da/dk``.

    ``da/ds = k cn(s; k)`` for every ``k > 0`` (continued modulus), and
    ``da/dk = sd(s; k) - k^2 cn(s; k) I(s|k^2)`` for ``k < 1``,
    ``da/dk = dn(x|1/k^2) (s + I(x|1/k^2)/k^3)`` with ``x = k s`` for ``k > 1``,
    both from ``d am/dm = -dn I / 2`` (see ``_elliptic``). `jf` as in :func:`_half_angles`.
    """
    m = k * k
    if abs(1.0 - m) < _SEPARATRIX_BAND:
        S, C = _half_angles(s, k, jf)
        _, cn, _ = ellipj(s, m)
        Sp, Cp = _half_angles(s, k + _FD_STEP)
        Sm, Cm = _half_angles(s, k - _FD_STEP)
        a_k = (C * (Sp - Sm) - S * (Cp - Cm)) / (2.0 * _FD_STEP)
        return S, C, k * cn, a_k
    if k < 1.0:
        sn, cn, dn, ph = _ellipj_scalar_m(s, m) if jf is None else jf
        a_k = sn / dn - m * cn * _sd2_integral(s, m, sn, cn, dn, ph)
        return k * sn, dn, k * cn, a_k
    x = k * s
    sn, cn, dn, ph = _ellipj_scalar_m(x, 1.0 / m) if jf is None else jf
    a_k = dn * (s + _sd2_integral(x, 1.0 / m, sn, cn, dn, ph) / (m * k))
    return sn, cn, k * dn, a_k


def _phasors(p: ElasticaParams, n_points: int, *, derivatives: bool = False):
    """Tangents as complex numbers ``T_n = exp(i (phi + a_n + a_{n+1}))``, ``(N-1,)``.

    Formed as ``e^{i phi} E_n E_{n+1}`` with ``E_n = C_n + i S_n``: the same four
    products and two sums as the angle-addition formulas. With `derivatives` also
    ``da/ds`` and ``da/dk`` (see :func:`_family`).
    """
    s, jf = _progression(p.z, p.q, n_points, p.k)
    if derivatives:
        S, C, a_s, a_k = _family(s, p.k, jf)
    else:
        S, C = _half_angles(s, p.k, jf)
    E = np.empty(n_points, dtype=complex)
    E.real = C
    E.imag = S
    T = E[:-1] * E[1:]
    T *= complex(math.cos(p.phi), math.sin(p.phi))
    if not derivatives:
        return T
    return T, a_s, a_k


def _positions(p: ElasticaParams, n_points: int) -> np.ndarray:
    return _walk(p, _phasors(p, n_points))


def _walk(p: ElasticaParams, T: np.ndarray) -> np.ndarray:
    """``gamma_0 = (x0, y0)``, ``gamma_{n+1} = gamma_n + h T_n`` from complex `T`, as ``(N, 2)``."""
    out = np.empty(T.shape[0] + 1, dtype=complex)
    out[0] = complex(p.x0, p.y0)
    np.multiply(T, p.h, out=out[1:])
    np.add.accumulate(out[1:], out=out[1:])  # np.cumsum without its Python wrapper
    out[1:] += out[0]
    return out.view(float).reshape(-1, 2)


def _positions_and_jacobian(p: ElasticaParams, n_points: int):
    """Vertices ``gamma_n(p)`` and ``d gamma_n / d p`` by eqs. (4.10)-(4.11).

    Returns ``(points (N, 2), jac (N, 2, 7))`` in the parameter order of eq. (4.5)
    (``jac`` is a transposed view of :func:`_jacobian_columns`).
    ``dT_n/dp = N_n d(a_n + a_{n+1})/dp`` (eq. 4.11 with ``dS/C = da``, which stays
    finite where ``C = 0``), ``N_n = R(pi/2) T_n``.
    """
    T, a_s, a_k = _phasors(p, n_points, derivatives=True)
    return _walk(p, T), _columns(p, T, a_s, a_k).transpose(1, 2, 0)


def _jacobian_columns(p: ElasticaParams, n_points: int) -> np.ndarray:
    """``d gamma_n / d p_j`` as ``(7, N, 2)``, one parameter per leading index.

    The same numbers as :func:`_positions_and_jacobian` without the vertices; row
    ``j`` reshaped to ``(2N,)`` is column ``j`` of the Jacobian of the residual vector.
    """
    return _columns(p, *_phasors(p, n_points, derivatives=True))


def _columns(p: ElasticaParams, T: np.ndarray, a_s: np.ndarray, a_k: np.ndarray) -> np.ndarray:
    """Eq. (4.10) in complex form: ``d gamma_n/dp = sum_{j<n} d(h T_j)/dp``, all columns at once."""
    n_points = T.shape[0] + 1
    # d(a_n + a_{n+1})/dz, /dq, /dk (the a_n of vertex n sits at s_n = z n + q)
    rates = np.empty((3, n_points))
    np.multiply(a_s, np.arange(n_points, dtype=float), out=rates[0])
    rates[1] = a_s
    rates[2] = a_k
    pairs = rates[:, :-1] + rates[:, 1:]
    steps = np.empty((5, n_points - 1), dtype=complex)
    steps[0] = T  # d/dh
    np.multiply(T, complex(0.0, p.h), out=steps[1])  # d/dphi: h N_n = i h T_n
    np.multiply(steps[1], pairs, out=steps[2:])  # d/dz, d/dq, d/dk
    cols = np.empty((7, n_points), dtype=complex)
    cols[0] = 1.0  # d/dx0 = (1, 0)
    cols[1] = 1j  # d/dy0 = (0, 1)
    cols[2:, 0] = 0.0
    np.add.accumulate(steps, axis=1, out=cols[2:, 1:])
    return cols.view(float).reshape(7, n_points, 2)


def sample(
    params: ArrayLike, n_points: int, *, case: Literal["i", "ii"] | None = None
) -> np.ndarray:
    """Vertices of the discrete elastica with parameters `params`, eqs. (4.3)/(4.2) and (4.4).

    Parameters
    ----------
    params : sequence of 7 float
        ``(x0, y0, h, phi, z, q, k)`` of eq. (4.5): start vertex, segment length
        ``h > 0``, rotation ``phi`` (radians), argument step ``z``, phase ``q`` and
        modulus ``k > 0``. By default ``k`` is the continued modulus (``k < 1``
        case (ii), ``k > 1`` case (i) with modulus ``1/k``; module docstring).
    n_points : int
        Number of vertices ``N >= 2``.
    case : {None, "i", "ii"}, optional
        ``"i"`` reads ``k <= 1`` as the modulus of the paper's case (i), eq. (4.2);
        ``"ii"`` requires ``k <= 1`` (eq. 4.3). None (default): continued modulus.

    Returns
    -------
    (N, 2) ndarray
        ``gamma_0 .. gamma_{N-1}``; consecutive vertices are exactly ``h`` apart.

    Notes
    -----
    The rotation enters as ``Theta_n = phi + (theta_n - phi)/2 + (theta_{n+1} - phi)/2``;
    eq. (4.4) as printed subtracts ``phi`` instead (see the module docstring).

    Examples
    --------
    >>> pts = sample((0.0, 0.0, 0.1, 0.0, 0.05, 0.0, 0.5), 5)
    >>> pts.shape
    (5, 2)
    >>> np.allclose(np.linalg.norm(np.diff(pts, axis=0), axis=1), 0.1)
    True
    >>> np.allclose(sample((0, 0, 0.1, 0, 0.05, 0.2, 0.5), 5, case="i"),
    ...             sample((0, 0, 0.1, 0, 0.05, 0.2, 2.0), 5))
    True
    """
    p = _as_params(params, case=case)
    n = as_int(n_points, name="n_points", minimum=2)
    return _positions(p, n).copy()  # an array of its own, not a view of the complex walk


def exact_curvature(
    params: ArrayLike, n_points: int, *, case: Literal["i", "ii"] | None = None
) -> np.ndarray:
    """Closed-form discrete curvature ``kappa_n`` of a sampled elastica, eq. (3.20), continued in k.

    Parameters
    ----------
    params : sequence of 7 float
        As in :func:`sample`.
    n_points : int
        Number of vertices ``N >= 2``.
    case : {None, "i", "ii"}, optional
        As in :func:`sample`.

    Returns
    -------
    (N,) ndarray
        ``kappa_n = (2 k sn(z)/(h dn(z))) cn(z n + q)`` for ``n = 0 .. N-1``; entries
        ``1 .. N-2`` equal ``curvature(sample(params, N))``.

    Examples
    --------
    >>> p = (0.0, 0.0, 0.1, 0.3, 0.05, 0.2, 0.7)
    >>> np.allclose(exact_curvature(p, 20)[1:-1], curvature(sample(p, 20)))
    True
    """
    p = _as_params(params, case=case)
    n = as_int(n_points, name="n_points", minimum=2)
    return _kappa_max(p) * ellipj(p.z * np.arange(n) + p.q, p.k * p.k)[1]


def _kappa_max(p: ElasticaParams) -> float:
    sn, _, dn = ellipj(p.z, p.k * p.k)
    return float(2.0 * p.k * sn / (p.h * dn))


@dataclass(frozen=True)
class Invariants:
    """Constants of motion of a discrete elastica (sections 3.2-3.3, 4.3).

    Attributes
    ----------
    alpha : float
        The constant of eq. (3.9),
        ``kappa_{n+1} + kappa_{n-1} = alpha kappa_n / (1 + h^2 kappa_n^2/4)``;
        ``alpha = 2 cn(z)/dn(z)^2`` (eq. 3.20/3.47, continued in k).
    C : float
        The conserved quantity of eq. (3.18).
    lam : float
        ``lambda = (alpha - 2)/h^2`` (proof of Prop. 3.1).
    epsilon : float
        ``epsilon`` of eq. (3.30)/(3.44): ``cn(z) = (1 - epsilon)/(1 + epsilon)``.
    mu : float
        ``mu = 4 epsilon / h^2`` (eq. 4.1).
    Lambda : float
        ``Lambda = (1 + epsilon) dn(z)`` of eq. (3.31) (proof of Prop. 3.6).
    kappa_max : float
        Amplitude ``2 k sn(z)/(h dn(z))`` of ``kappa_n`` (eq. 4.27).
    case : str
        ``"i"``, ``"ii"`` or ``"separatrix"``.
    """

    alpha: float
    C: float
    lam: float
    epsilon: float
    mu: float
    Lambda: float
    kappa_max: float
    case: str


def invariants(params: ArrayLike, *, case: Literal["i", "ii"] | None = None) -> Invariants:
    """Conserved quantities of the discrete elastica with parameters `params`.

    Parameters
    ----------
    params : sequence of 7 float
        As in :func:`sample`.
    case : {None, "i", "ii"}, optional
        As in :func:`sample`.

    Returns
    -------
    Invariants
        ``alpha`` (eq. 3.9), ``C`` (eq. 3.18), ``lambda``, ``epsilon``, ``mu``,
        ``Lambda`` (eq. 3.31) and ``kappa_max``. Prop. 4.1 reads
        ``kappa_n = (mu / Lambda) u_n + A``.

    Examples
    --------
    >>> inv = invariants((0.0, 0.0, 0.1, 0.0, 0.05, 0.0, 0.5))
    >>> round(inv.alpha, 10), inv.case
    (1.9987489589, 'ii')
    """
    p = _as_params(params, case=case)
    _, cn, dn = ellipj(p.z, p.k * p.k)
    cn, dn = float(cn), float(dn)
    alpha = 2.0 * cn / (dn * dn)
    kmax = _kappa_max(p)
    k0, k1 = kmax * ellipj(np.array([p.q, p.z + p.q]), p.k * p.k)[1]
    C = k1 * k1 + k0 * k0 - alpha * k1 * k0 + 0.25 * p.h * p.h * k1 * k1 * k0 * k0
    eps = (1.0 - cn) / (1.0 + cn)
    return Invariants(
        alpha=alpha,
        C=float(C),
        lam=(alpha - 2.0) / (p.h * p.h),
        epsilon=eps,
        mu=4.0 * eps / (p.h * p.h),
        Lambda=(1.0 + eps) * dn,
        kappa_max=kmax,
        case=case_of(p.k),
    )


def segment_length(points: ArrayLike, *, rtol: float = 1e-6) -> float:
    """Common segment length ``h`` of a discrete curve with equal segments (section 3.1).

    Parameters
    ----------
    points : (N, 2) array_like
        Vertices, ``N >= 2``.
    rtol : float, optional
        Allowed relative spread ``(max - min) / mean`` of the edge lengths.

    Returns
    -------
    float
        The mean edge length.

    Raises
    ------
    CurveError
        If the edge lengths spread more than `rtol` (the message gives the
        measured spread), or on bad points.

    Examples
    --------
    >>> segment_length([[0, 0], [1, 0], [1, 1]])
    1.0
    """
    p = as_points(points, min_points=2, distinct=True)
    return _segment_length(p, rtol)


def _segment_length(p: np.ndarray, rtol: float) -> float:
    lengths = np.hypot(*np.diff(p, axis=0).T)
    h = float(lengths.mean())
    spread = float((lengths.max() - lengths.min()) / h)
    if spread > rtol:
        raise CurveError(
            f"points must have segments of equal length (relative spread <= {rtol:g}), "
            f"got lengths from {lengths.min():.6g} to {lengths.max():.6g} (spread {spread:.3g}); "
            "resample to equal steps first"
        )
    return h


def tangent_angles(points: ArrayLike) -> np.ndarray:
    """Discrete angle function ``Theta_n`` of eqs. (3.1)/(4.32), continuous (unwrapped).

    Parameters
    ----------
    points : (N, 2) array_like
        Vertices, ``N >= 2``, no zero-length edges.

    Returns
    -------
    (N-1,) ndarray
        Angle of ``gamma_{n+1} - gamma_n`` from the x axis, counter-clockwise, in
        radians; consecutive values differ by the turning angles ``K_{n+1}`` in
        ``(-pi, pi)``.

    Examples
    --------
    >>> np.degrees(tangent_angles([[0, 0], [1, 0], [1, 1], [0, 1]]))
    array([  0.,  90., 180.])
    """
    p = as_points(points, min_points=2, distinct=True)
    e = np.diff(p, axis=0)
    return np.unwrap(np.arctan2(e[:, 1], e[:, 0]))


def curvature(points: ArrayLike, *, rtol: float = 1e-6) -> np.ndarray:
    """Discrete curvature ``kappa_n = (2/h) tan(K_n / 2)`` of eqs. (3.4)/(4.33).

    Parameters
    ----------
    points : (N, 2) array_like
        Vertices of a discrete curve with segment length ``h`` (section 3.1),
        ``N >= 3``, open.
    rtol : float, optional
        Allowed relative spread of the edge lengths (see :func:`segment_length`).

    Returns
    -------
    (N-2,) ndarray
        ``kappa_1 .. kappa_{N-2}``: the reciprocal radius of the circle touching
        the two edges at vertex ``n`` at their midpoints, signed (positive for a
        left turn). ``K_n = Theta_n - Theta_{n-1}`` is the turning angle.

    Raises
    ------
    CurveError
        On unequal segments, zero-length edges, or a turn of pi (edge folding back).

    Examples
    --------
    >>> t = np.linspace(0, 1, 7)              # equal chords on the unit circle
    >>> pts = np.column_stack((np.cos(t), np.sin(t)))
    >>> np.allclose(curvature(pts), 1 / np.cos((t[1] - t[0]) / 2))  # midpoint circle
    True
    """
    p = as_points(points, min_points=3, distinct=True)
    h = _segment_length(p, rtol)
    return _curvature(p, h)


def _curvature(p: np.ndarray, h: float) -> np.ndarray:
    e = np.diff(p, axis=0)
    cross = e[:-1, 0] * e[1:, 1] - e[:-1, 1] * e[1:, 0]
    dot = np.einsum("ij,ij->i", e[:-1], e[1:])
    norms = np.hypot(*e[:-1].T) * np.hypot(*e[1:].T)
    # tan(K/2) = sin K / (1 + cos K), K the turning angle.
    denom = norms + dot
    if np.any(denom <= 1e-14 * norms):
        n = int(np.argmin(denom / norms)) + 1
        raise CurveError(f"points fold back on themselves at vertex {n} (turning angle pi)")
    return (2.0 / h) * cross / denom
