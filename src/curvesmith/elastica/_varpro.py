"""Variable projection for the global search: eq. (4.8) over ``(z, q, k)`` alone.

The vertices of eq. (4.4) are ``gamma_n = gamma_0 + h e^{i phi} W_n`` (complex notation)
with ``W_n = sum_{j<n} E_j E_{j+1}``, ``E_n = C_n + i S_n`` of eq. (4.3): affine in the
complex numbers ``gamma_0 = x0 + i y0`` and ``w = h e^{i phi}``. For given ``(z, q, k)`` the
best ``gamma_0`` and ``w`` are a complex linear regression of the data on ``(1, W)``
(closed form), which leaves a least-squares problem in three unknowns (Golub & Pereyra's
variable projection, with Kaufman's Jacobian ``P_perp w dW/dtheta`` built from the
analytic derivatives of eqs. (4.10)-(4.11)). Its minima are exactly the minima of eq. (4.8)
with ``h = |w| > 0`` (the bound of eq. (4.7) holds by construction).

The three unknowns are also re-coordinated, because near the separatrix the printed
parameters make Levenberg-Marquardt crawl along a curved valley (a 1.5 m section scan,
``k = 1.0014``: 11,500 evaluations in ``(x0, ..., k)``, 7 here):

* ``Z = k z`` and ``Q = k (q + z c) - j P(k)``, the argument ``u = k s`` (the one the Jacobi
  functions take for ``k > 1``) at the middle vertex ``c = (N - 1) / 2``, reduced by ``j``
  periods ``P`` of the curve in ``u``: ``2 K(1/k^2)`` for ``k > 1`` (``E`` changes sign,
  ``T_n = E_n E_{n+1}`` does not) and ``4 k K(k^2)`` for ``k < 1``. With ``j`` fixed during a
  solve, changing ``k`` at fixed ``Q`` keeps the curvature extremum near the data in place,
  where changing it at fixed ``q`` moves it by ``j dP/dk``, which grows like ``1/|1 - k|``.
  Centring on the middle vertex decorrelates the phase from the step ``Z``. With ``j != 0``
  these coordinates are singular at ``k = 1`` (``P`` diverges, by different formulas on
  either side), so a solve that ends within 1e-4 of it or crosses it is reported failed and
  the caller solves in the seven parameters from the same start (with ``j = 0`` instead,
  smooth through ``k = 1``, such solves crawl and miss the basin that the seven-parameter
  solve finds on a nearly straight keyline piece: rms 0.237 instead of 0.049 mm).

The fit polishes the result with the paper's Levenberg-Marquardt on all seven parameters
(``fit._solve``), so the reported optimum and message are those of eq. (4.8) itself.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.optimize import leastsq
from scipy.special import ellipe, ellipk

from .exact import ElasticaParams, _family, _half_angles, _progression

#: Residual of a trial point outside ``k > 0`` or with a degenerate basis: MINPACK rejects it.
_PENALTY = 1e30
#: With ``j != 0``, a solve ending this close to ``k = 1`` is handed back (module docstring).
_NEAR_ONE = 1e-4


def _period(k: float) -> float:
    """Period of the curve in ``u = k s``: ``2 K(1/k^2)`` (k > 1), ``4 k K(k^2)`` (k < 1)."""
    if k > 1.0:
        return 2.0 * float(ellipk(1.0 / (k * k)))
    if 0.0 < k < 1.0:
        return 4.0 * k * float(ellipk(k * k))
    return math.inf


def _dk_dm(m: float) -> float:
    """``dK/dm = (E - (1 - m) K) / (2 m (1 - m))``, by its series below m = 1e-3 (cancellation)."""
    if m < 1e-3:
        return 0.5 * math.pi * (0.25 + m * (9.0 / 32.0 + m * 75.0 / 256.0))
    return (float(ellipe(m)) - (1.0 - m) * float(ellipk(m))) / (2.0 * m * (1.0 - m))


def _period_dk(k: float) -> float:
    """``dP/dk`` of :func:`_period`."""
    if k > 1.0:
        return 2.0 * _dk_dm(1.0 / (k * k)) * (-2.0 / k**3)
    return 4.0 * float(ellipk(k * k)) + 8.0 * k * k * _dk_dm(k * k)


class Reduced:
    """Residuals and Kaufman Jacobian of eq. (4.8) with ``gamma_0, w`` projected out.

    Parameters
    ----------
    data : (N, 2) ndarray
        The data ``zeta_n``.
    start : ElasticaParams
        Gives ``j`` (the period count of the middle vertex) and the starting ``theta``.
    anchor : complex or None
        A pinned start vertex ``gamma_0`` (section 5.4), else None (free).
    """

    def __init__(
        self, data: np.ndarray, start: ElasticaParams, anchor: complex | None, periods=True
    ):
        self.zeta = np.ascontiguousarray(data).view(complex).ravel()
        self.n = self.zeta.size
        self.zeta_mean = self.zeta.sum() / self.n
        self.c = 0.5 * (self.n - 1)
        self.anchor = anchor
        k = start.k
        period = _period(k)
        u_mid = k * (start.q + start.z * self.c)
        finite = periods and math.isfinite(period) and math.isfinite(u_mid)
        self.j = round(u_mid / period) if finite else 0
        self._key: tuple | None = None
        self._cache: tuple | None = None

    def theta(self, p: ElasticaParams) -> np.ndarray:
        """``(Z, Q, k)`` of parameters `p`."""
        k = p.k
        shift = self.j * _period(k) if self.j else 0.0
        return np.array([k * p.z, k * (p.q + p.z * self.c) - shift, k])

    def zqk(self, theta: np.ndarray) -> tuple[float, float, float]:
        Z, Q, k = (float(v) for v in theta)
        shift = self.j * _period(k) if self.j else 0.0
        z = Z / k
        return z, (Q + shift) / k - z * self.c, k

    def _basis(self, theta: np.ndarray, derivatives: bool):
        z, q, k = self.zqk(theta)
        s, jf = _progression(z, q, self.n, k)
        if derivatives:
            S, C, a_s, a_k = _family(s, k, jf)
        else:
            S, C = _half_angles(s, k, jf)
        E = np.empty(self.n, dtype=complex)
        E.real = C
        E.imag = S
        T = E[:-1] * E[1:]
        W = np.empty(self.n, dtype=complex)
        W[0] = 0.0
        np.add.accumulate(T, out=W[1:])
        if not derivatives:
            return W, None
        rates = np.empty((3, self.n))
        np.multiply(a_s, np.arange(self.n, dtype=float), out=rates[0])
        rates[1] = a_s
        rates[2] = a_k
        steps = (rates[:, :-1] + rates[:, 1:]) * (1j * T)
        dW = np.empty((3, self.n), dtype=complex)
        dW[:, 0] = 0.0
        np.add.accumulate(steps, axis=1, out=dW[:, 1:])
        # chain rule to (Z, Q, k): z = Z/k, q = (Q + j P(k))/k - z c
        dq_dk = (self.j * _period_dk(k) - q) / k if self.j else -q / k
        out = np.empty_like(dW)
        out[0] = (dW[0] - self.c * dW[1]) / k
        out[1] = dW[1] / k
        out[2] = dW[2] - (z / k) * dW[0] + dq_dk * dW[1]
        return W, out

    def _linear(self, W: np.ndarray):
        """``(gamma_0, w, e)``: regression of the data on ``(1, W)``, unit basis vector of ``W``."""
        if self.anchor is None:
            Wm = W.sum() / self.n
            Wc = W - Wm
            zm = self.zeta_mean
        else:
            Wc = W
            zm = self.anchor
        norm2 = float(np.vdot(Wc, Wc).real)
        if not (math.isfinite(norm2) and norm2 > 0.0):
            return None
        w = np.vdot(Wc, self.zeta - zm) / norm2
        g0 = zm - w * Wm if self.anchor is None else self.anchor
        return g0, w, Wc / math.sqrt(norm2)

    def _eval(self, theta: np.ndarray, derivatives: bool):
        key = (theta.tobytes(), derivatives)
        if key == self._key:
            return self._cache
        out: tuple | None = None
        if theta[2] > 0.0 and math.isfinite(theta[0] + theta[1] + theta[2]):
            W, dW = self._basis(theta, derivatives)
            lin = self._linear(W)  # None also for non-finite W (its norm is not finite)
            if lin is not None:
                out = (W, dW, *lin)
        self._key, self._cache = key, out
        return out

    def residuals(self, theta: np.ndarray) -> np.ndarray:
        ev = self._eval(theta, False)
        if ev is None:
            return np.full(2 * self.n, _PENALTY)
        W, _, g0, w, _ = ev
        r = g0 + w * W - self.zeta
        return r.view(float)

    def jacobian_columns(self, theta: np.ndarray) -> np.ndarray:
        ev = self._eval(theta, True)
        if ev is None:  # not reached: MINPACK asks for the Jacobian at accepted points only
            return np.zeros((3, 2 * self.n))
        _, dW, _, w, e = ev
        D = w * dW
        if self.anchor is None:
            D -= D.sum(axis=1, keepdims=True) / self.n
        D -= e[None, :] * (np.conj(e)[None, :] @ D.T).T
        return np.ascontiguousarray(D).view(float).reshape(3, -1)

    def params(self, theta: np.ndarray) -> ElasticaParams | None:
        """The seven parameters at `theta` (``h = |w|``, ``phi = arg w``), None if degenerate."""
        ev = self._eval(np.asarray(theta, dtype=float), False)
        if ev is None:
            return None
        _, _, g0, w, _ = ev
        z, q, k = self.zqk(theta)
        h = abs(w)
        if not (h > 0.0 and math.isfinite(h)):
            return None
        return ElasticaParams(
            float(g0.real), float(g0.imag), h, math.atan2(w.imag, w.real), z, q, k
        )


def solve(data, start: ElasticaParams, anchor: complex | None, max_iterations: int, tol: float):
    """Levenberg-Marquardt (MINPACK lmder) on the reduced problem from `start`.

    Returns ``(params, njev, status)``: ``status`` is ``"converged"``, ``"cap"`` (stopped
    at `max_iterations` function evaluations) or ``"failed"`` (params may then be None), also for
    a solve with ``j != 0`` that reaches or crosses ``k = 1``.
    """
    params, njev, status = _solve(data, start, anchor, max_iterations, tol, True)
    return params, njev, "failed" if status == "singular" else status


def _solve(data, start, anchor, max_iterations, tol, periods):
    prob = Reduced(data, start, anchor, periods)
    with np.errstate(all="ignore"):
        theta0 = prob.theta(start)
        if prob.residuals(theta0)[0] == _PENALTY:
            return None, 0, "failed"
        x, _, info, _, ier = leastsq(
            prob.residuals,
            theta0,
            Dfun=prob.jacobian_columns,
            full_output=True,
            col_deriv=True,
            ftol=tol,
            xtol=tol,
            gtol=tol,
            maxfev=max_iterations,
        )
        params = prob.params(x) if np.all(np.isfinite(x)) and x[2] > 0.0 else None
    njev = int(info["njev"])
    if params is None or not np.all(np.isfinite(info["fvec"])) or info["fvec"][0] == _PENALTY:
        return params, njev, "failed"
    if prob.j and ((params.k - 1.0) * (start.k - 1.0) <= 0.0 or abs(params.k - 1.0) < _NEAR_ONE):
        # with a period count j != 0 the coordinates are singular at k = 1 (P(k) -> inf, and
        # its two formulas differ across): a solve that reaches or crosses it is not trusted
        return params, njev, "singular"
    if ier == 5:
        return params, njev, "cap"
    if ier in (1, 2, 3, 4, 6, 7, 8):
        return params, njev, "converged"
    return params, njev, "failed"
