"""Initial parameters of a discrete elastica from data: the pseudo code of section 4.3.

Implements eqs. (4.32)-(4.55) of Graiff Zurita, Kajiwara & Suzuki, with these
verified refinements (each checked on sampled elasticae, see the tests):

* (4.35) uses the exact discrete law (4.21) ``sin Psi_n = (mu/2Lambda) u_{n+1} u_n
  + A (u_{n+1} + u_n)/2 + B`` rather than its smooth expansion (4.26): the slope
  fitted by (4.34) *is* ``mu/Lambda`` (eq. 4.20), so ``B`` comes out exact on exact
  data at no cost.
* The case decision (4.36)/(4.37) is one formula in the continued modulus:
  ``k = Delta / (2 sqrt(mu))`` with ``Delta^2 = A^2 - 2 mu (B - 1)``; ``k > 1`` is
  case (i) with modulus ``1/k`` (the inequality below (4.35) is ``k > 1``).
* The number ``m`` of monotone segments of ``u_n``: (4.38) as printed, a floor plus
  one when ``u`` has the same monotonicity at both ends, can give the wrong
  parity (a half segment crossing one extremum: floor 0, different directions,
  yet ``m = 2``). We take ``m`` of the parity fixed by the end directions (odd iff
  equal) whose end argument ``s_{N-1}`` from (4.42)-(4.53) is closest to the
  estimate ``s_0 + (N-1) h sqrt(mu)`` that underlies (4.38).
* The least squares (4.34) are solved on coordinates centred over ``n = 1 .. N-2``,
  where the constant column is orthogonal to the other two and ``(mu2, -mu1)`` solve
  2x2 normal equations (no SVD: half the time of ``np.linalg.lstsq``, equal to it to
  ~1e-11 relative on 500 random noisy curves, scratch check).
* The pseudo code assumes ``mu u_n + A`` has the sign of the curvature amplitude
  (positive); for clockwise data (negative mean curvature) we run it on the
  mirror image ``y -> -y`` and map back with ``(phi, z, q) -> (-phi, -z, -q)``,
  which mirrors a sampled elastica exactly (``a(s)`` is odd in ``s``).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike
from scipy.special import ellipk, ellipkinc

from .._validate import as_points
from ..errors import CurveError
from .exact import ElasticaParams, _curvature, _positions

__all__ = ["initial_guess"]


def _end_directions(u: np.ndarray) -> tuple[float, float]:
    """Signs of the trend of ``u`` over its first and last few samples (least-squares slopes)."""
    w = int(max(2, min(5, u.size // 10)))
    t = np.arange(w) - (w - 1) / 2.0
    start = float(t @ u[:w])
    end = float(t @ u[-w:])
    return (1.0 if start >= 0.0 else -1.0), (1.0 if end >= 0.0 else -1.0)


def _argument_pieces(U0: float, U1: float, kq: float, case_ii: bool):
    """The parts of eqs. (4.41)-(4.46) (case i) or (4.48)-(4.53) (case ii) that do not depend on m.

    Returns ``(F0, F1, seg, scale)``: the incomplete integrals at both ends, the length of
    one monotone segment and the factor that turns the sums into arguments ``s``.
    """
    m = kq * kq
    K = float(ellipk(m))
    if case_ii:
        F0, F1 = ellipkinc(math.acos(U0), m), ellipkinc(math.acos(U1), m)
        return float(F0), float(F1), 2.0 * K, 1.0  # one monotone segment of cn
    F0, F1 = ellipkinc(math.asin(U0), m), ellipkinc(math.asin(U1), m)
    return float(F0), float(F1), K, kq  # one monotone segment of dn, in units of k^{-1} s


def _arguments(pieces, dec_start: bool, m: int):
    """(s_0, s_{N-1}) for `m` monotone segments from :func:`_argument_pieces`."""
    F0, F1, seg, scale = pieces
    odd = m % 2 == 1
    if dec_start:
        s0 = F0
        s1 = (m - 1) * seg + F1 if odd else m * seg - F1
    else:
        s0 = 2.0 * seg - F0
        s1 = (m + 1) * seg - F1 if odd else m * seg + F1
    return scale * s0, scale * s1


def initial_guess(points: ArrayLike) -> ElasticaParams:
    """Initial parameters ``(x0, y0, h, phi, z, q, k)`` for fitting a discrete elastica.

    Section 4.3 of Graiff Zurita, Kajiwara & Suzuki: discrete curvature (4.33),
    least squares (4.34) for ``mu1, mu2, A`` and ``phi``, (4.35) for ``B``, the
    case and ``k`` from (4.36)/(4.37), the number of monotone segments (4.38),
    ``q`` and ``z`` from (4.39)-(4.54), and ``x0, y0`` from (4.55).

    Parameters
    ----------
    points : (N, 2) array_like
        Data vertices in model order, roughly equally spaced, ``N >= 5``.

    Returns
    -------
    ElasticaParams
        Parameters with the continued modulus ``k`` (``k < 1`` case (ii), ``k > 1``
        case (i) with modulus ``1/k``; see :mod:`curvesmith.elastica.exact`).

    Raises
    ------
    CurveError
        On fewer than 5 points, non-finite values, zero-length edges, or
        collinear data (no curvature to fit).

    Examples
    --------
    >>> from curvesmith.elastica import sample
    >>> true = (1.0, 2.0, 0.05, 0.4, 0.04, 0.3, 0.6)
    >>> guess = initial_guess(sample(true, 120))
    >>> bool(abs(guess.k - 0.6) < 0.05 and abs(guess.phi - 0.4) < 0.05)
    True
    """
    p = as_points(points, min_points=5, distinct=True)
    return _initial_guess(p)


def _data_curvature(p: np.ndarray) -> tuple[float, np.ndarray]:
    """Mean edge length and discrete curvature (4.33) of data; refuses collinear data."""
    e = np.diff(p, axis=0)
    h = float(np.hypot(e[:, 0], e[:, 1]).mean())
    kappa = _curvature(p, h)  # kappa_1 .. kappa_{N-2}, eq. (4.33)
    extent = float((p.max(axis=0) - p.min(axis=0)).max())
    largest = float(np.max(np.abs(kappa)))  # NaN if any kappa is NaN
    if not math.isfinite(largest) or largest * extent < 1e-9:
        raise CurveError(
            "points are collinear (no curvature to fit): "
            f"max |kappa| = {largest:.3g} over an extent of {extent:.6g}"
        )
    return h, kappa


def _initial_guess(p: np.ndarray) -> ElasticaParams:
    return _guess_variants(p, variants=False)[0]


#: Moduli tried by :func:`_guess_variants` besides the estimate: near the separatrix.
_NEAR_SEPARATRIX = (0.97, 1.03)


def _guess_variants(p: np.ndarray, *, variants: bool = True) -> list[ElasticaParams]:
    """The guess of section 4.3 and, with `variants`, its alternatives for a multi-start search.

    The pseudo code makes three discrete choices that noise or model error can get wrong:
    the case (``k`` below or above 1, decided by the sign of ``Delta^2 - 4 mu``), the
    parity of the number ``m`` of monotone segments (from the end directions of ``u``) and,
    near ``k = 1``, the size of ``k``. The variants are: the estimate with the other parity
    of ``m``; the reciprocal modulus ``1/k`` (the other case, same ``Delta / 2 sqrt(mu)``
    distance from 1 on a log scale); and ``k`` = 0.97 and 1.03 (near the separatrix), each
    with both parities. The first entry is the guess of :func:`initial_guess`.
    """
    n_pts = p.shape[0]
    h, kappa = _data_curvature(p)
    mirrored = float(np.sum(kappa)) < 0.0
    q_pts = p * np.array([1.0, -1.0]) if mirrored else p
    kap = -kappa if mirrored else kappa
    base = _pseudo_code(q_pts, h, kap)
    ests = [base]
    if variants:
        ests.append(_pseudo_code(q_pts, h, kap, other_parity=True))
        for k in (1.0 / base.k, *_NEAR_SEPARATRIX):
            for other in (False, True):
                try:
                    ests.append(_pseudo_code(q_pts, h, kap, k=k, other_parity=other))
                except CurveError:
                    continue
    out = []
    for est in ests:
        if mirrored:
            est = est._replace(phi=-est.phi, z=-est.z, q=-est.q)
        gamma_hat = _positions(est._replace(x0=0.0, y0=0.0), n_pts)
        if not np.all(np.isfinite(gamma_hat)):
            continue
        x0, y0 = (p - gamma_hat).mean(axis=0)  # eq. (4.55)
        out.append(est._replace(x0=float(x0), y0=float(y0)))
    if not out:
        raise CurveError("points give no finite initial guess (section 4.3)")
    return out


def _pseudo_code(
    p: np.ndarray,
    h: float,
    kappa: np.ndarray,
    *,
    k: float | None = None,
    other_parity: bool = False,
) -> ElasticaParams:
    n_pts = p.shape[0]
    x, y = p[:, 0], p[:, 1]
    # (4.34): kappa_n = mu2 x_n - mu1 y_n + A, n = 1 .. N-2.
    # Solved on coordinates centred over n = 1 .. N-2: the constant column is then
    # orthogonal to the other two and (mu2, -mu1) solve the 2x2 normal equations.
    inner = p[1:-1]
    centre = inner.mean(axis=0)
    c = inner - centre
    (sxx, sxy), (_, syy) = (c.T @ c).tolist()
    det = sxx * syy - sxy * sxy
    if det > 1e-10 * sxx * syy:
        bx, by = (c.T @ kappa).tolist()
        mu2 = (syy * bx - sxy * by) / det
        mu1 = -(sxx * by - sxy * bx) / det
        cx, cy = centre.tolist()
        A = float(kappa.mean()) - mu2 * cx + mu1 * cy
    else:  # inner vertices (nearly) on a line: minimum-norm solution
        design = np.column_stack((-y[1:-1], x[1:-1], np.ones(n_pts - 2)))
        mu1, mu2, A = np.linalg.lstsq(design, kappa, rcond=None)[0].tolist()
    mu = math.hypot(mu1, mu2)
    if not mu > 0.0:
        raise CurveError("points have constant curvature: the elastica fit needs varying curvature")
    phi = math.atan2(mu2, mu1)
    u = math.sin(phi) * x - math.cos(phi) * y  # (4.13)-(4.14)
    edges = p[1:] - p[:-1]
    theta = np.arctan2(edges[:, 1], edges[:, 0])  # (4.32)
    sin_psi = np.cos(theta - phi)  # Psi_n = pi/2 + Theta_n - phi, (4.15)
    # (4.35) with the exact discrete law (4.21), averaged over n = 0 .. N-2.
    pair_sum = 2.0 * float(u.sum()) - float(u[0]) - float(u[-1])  # sum of u_{n+1} + u_n
    B = (float(sin_psi.sum()) - 0.5 * mu * float(u[1:] @ u[:-1]) - 0.5 * A * pair_sum) / (n_pts - 1)
    if k is None:
        delta2 = A * A - 2.0 * mu * (B - 1.0)
        delta = math.sqrt(max(delta2, 1e-300))
        k = delta / (2.0 * math.sqrt(mu))  # (4.36)/(4.37) as one continued modulus
    k = min(max(k, 1e-6), 1e6)
    if abs(k - 1.0) < 1e-6:
        k = 1.0 - 1e-6 if k < 1.0 else 1.0 + 1e-6
    case_ii = k < 1.0
    kq = k if case_ii else 1.0 / k  # the modulus of the printed case formulas
    ends = np.array([u[0], u[-1]])
    if case_ii:
        U = np.clip((mu * ends + A) / (2.0 * k * math.sqrt(mu)), -1.0, 1.0)  # (4.47)
        seg_len = 2.0 * ellipk(kq * kq)
    else:
        ratio = np.clip((mu * ends + A) / (2.0 * math.sqrt(mu) / kq), -1.0, 1.0)  # (4.39)
        U = np.clip(np.sqrt(1.0 - ratio * ratio) / kq, 0.0, 1.0)  # (4.40)
        seg_len = kq * ellipk(kq * kq)
    start_dir, end_dir = _end_directions(u)
    dec_start = start_dir < 0
    same = (start_dir == end_dir) != other_parity
    span = (n_pts - 1) * h * math.sqrt(mu)  # z ~ sqrt(mu) h, eq. (4.38)
    m_hat = int(np.floor(span / seg_len)) + 1
    pieces = _argument_pieces(float(U[0]), float(U[1]), kq, case_ii)
    best: tuple[float, float, float] | None = None
    for m in range(max(1, m_hat - 3), m_hat + 4):
        if (m % 2 == 1) != same:
            continue
        s0, s1 = _arguments(pieces, dec_start, m)
        miss = abs(s1 - s0 - span)
        if best is None or miss < best[0]:
            best = (miss, s0, s1)
    assert best is not None  # seven segment counts, one of each parity
    _, s0, s1 = best
    z = (s1 - s0) / (n_pts - 1)  # (4.54)
    return ElasticaParams(0.0, 0.0, h, phi, float(z), float(s0), k)
