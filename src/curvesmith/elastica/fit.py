"""Fairing: the discrete elastica closest to given data, section 4.2.

Minimises eq. (4.8), ``L(p) = sum_n ||gamma_n(p) - zeta_n||^2 / 2``, over
``p = (x0, y0, h, phi, z, q, k)`` in ``U`` of eq. (4.7) (``h, k > 0``), with the
analytic Jacobian of eqs. (4.10)-(4.11), derivatives in ``k`` included
(``exact._positions_and_jacobian``; checked against finite differences in the
tests). Backends:

* ``method="lsq"`` (default): Levenberg-Marquardt on the residual vector with
  that Jacobian, MINPACK ``lmder`` through ``scipy.optimize.leastsq``
  (unbounded). Its result is accepted if it converged to a finite point inside
  ``U``; otherwise (a step through ``k = 0`` or ``h = 0`` lands on the mirror
  parametrisation of the curve, or no convergence) the bounded trust-region
  reflective solver ``scipy.optimize.least_squares(method="trf", bounds h, k >
  0)`` is run from the same start, so the result always lies in ``U``. Both
  reach the same optimum where both converge (tests: the cost to 1e-12, the
  parameters to 1e-9 of trf's optimum polished by Gauss-Newton steps; trf stops
  up to ~5e-8 short of it on ill-conditioned cases, LM ~1e-12). LM does less
  work per iteration (QR inside MINPACK; no bound handling or SVD in Python):
  about half the time of trf alone at ``N = 100`` in ``benchmarks/bench_elastica.py``.
* ``method="ipopt"``: the paper's backend, IPOPT through cyipopt (extra
  ``ipopt``) on the scalar objective (4.8) with gradient (4.9) and the
  limited-memory quasi-Newton Hessian, as in the paper, with the variables
  scaled by the Jacobian's column norms at the start (unscaled, as in the
  paper, L-BFGS diverged on a 1000-point curve in ``benchmarks/bench_elastica.py``).

Long curves with many loops: a single start from the guess of section 4.3 can
land in a wrong basin (the phase error of ``z`` grows along the curve). With
``continuation="auto"`` a fit that fails the basin check below is redone over
growing prefixes of the data, each stage starting from the previous optimum
(the parameters do not depend on ``N``), and the better of the two is kept.

Basin check (``success``): the solver must converge *and* the rms residual must
be within ``basin_factor`` times the data's local noise level (rms residual of
a sliding cubic Savitzky-Golay fit, which follows any smooth curve) plus
``1e-9`` of the data extent. A local minimum in the wrong basin leaves
systematic residuals far above that level and is reported as ``success=False``.
For data that are only approximately an elastica (model error well above the
noise) raise ``basin_factor``.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import least_squares, leastsq
from scipy.signal import savgol_coeffs
from scipy.special import ellipk

from .._validate import as_float, as_int, as_points
from ..errors import CurveError, require
from ..geometry import _resample_walk
from .exact import (
    ElasticaParams,
    _as_params,
    _jacobian_columns,
    _positions,
    _positions_and_jacobian,
    case_of,
)
from .guess import _data_curvature, _initial_guess

__all__ = ["PARAM_NAMES", "SPACING_TOL", "FitResult", "fit", "spacing_spread"]

#: Names of the parameters of eq. (4.5), in order.
PARAM_NAMES = ("x0", "y0", "h", "phi", "z", "q", "k")
_METHODS = ("lsq", "ipopt")
#: Default largest relative spread of the edge lengths that :func:`fit` accepts.
SPACING_TOL = 0.25
_GROWTH = 1.6


@dataclass(frozen=True)
class FitResult:
    """Result of :func:`fit`.

    Attributes
    ----------
    params : ElasticaParams
        Fitted ``(x0, y0, h, phi, z, q, k)`` (continued modulus ``k``).
    points : (N, 2) ndarray
        The fitted discrete elastica ``gamma_n(params)``, one vertex per data vertex.
    rms : float
        ``sqrt(mean_n ||gamma_n - zeta_n||^2)``.
    max_distance : float
        ``max_n ||gamma_n - zeta_n||``.
    iterations : int
        Solver iterations (Jacobian evaluations for ``lsq``, Levenberg-Marquardt
        plus the trf fallback where it ran), summed over the single start and,
        when it ran, every continuation stage.
    success : bool
        Solver converged and the fit passed the basin check (module docstring).
    message : str
        What happened, in words.
    case : str
        ``"ii"`` (inflections, ``k < 1``), ``"i"`` (``k > 1``) or ``"separatrix"``.
    start : ElasticaParams
        The starting point used (initial guess of section 4.3 unless given).
    cost : float
        Final value of eq. (4.8).
    noise : float
        Local noise level of the data used by the basin check.
    data : (N, 2) ndarray
        The data that was fitted (after resampling, if requested).
    method : str
        Backend used.
    stages : int
        1 for a single start, otherwise the number of continuation stages.
    """

    params: ElasticaParams
    points: np.ndarray = field(repr=False)
    rms: float
    max_distance: float
    iterations: int
    success: bool
    message: str
    case: str
    start: ElasticaParams
    cost: float
    noise: float
    data: np.ndarray = field(repr=False)
    method: str
    stages: int


def _check_fixed(fixed) -> dict[int, float]:
    if fixed is None:
        return {}
    if not isinstance(fixed, dict):
        raise CurveError(f"fixed must be a dict of parameter values, got {type(fixed).__name__}")
    out = {}
    for name, value in fixed.items():
        if name not in PARAM_NAMES:
            raise CurveError(f"fixed has unknown parameter {name!r}; names are {PARAM_NAMES}")
        low = 0.0 if name in ("h", "k") else None
        out[PARAM_NAMES.index(name)] = as_float(value, name=f"fixed[{name!r}]", low=low)
    if len(out) == 7:
        raise CurveError("fixed pins all 7 parameters; nothing left to fit")
    return out


def spacing_spread(points) -> float:
    """Relative spread of the edge lengths: ``std(l) / mean(l)``.

    :func:`fit` pairs data and model vertices by index, which needs roughly
    equal spacing. Noise of standard deviation ``sigma`` per coordinate on
    equal steps ``h`` gives a spread of about ``sqrt(2) sigma / h`` (0.14 at
    ``sigma = 0.1 h``); digitising at uneven steps gives much more (0.35 for
    steps growing like ``t^1.5``).

    Parameters
    ----------
    points : (N, 2) array_like
        Vertices, ``N >= 2``, no zero-length edges.

    Returns
    -------
    float
        The coefficient of variation of the edge lengths.

    Examples
    --------
    >>> spacing_spread([[0, 0], [1, 0], [2, 0], [4, 0]])
    0.3535533905932738
    """
    p = as_points(points, min_points=2, distinct=True)
    lengths = np.hypot(*np.diff(p, axis=0).T)
    return float(lengths.std() / lengths.mean())


def _spacing_check(p: np.ndarray, tol: float) -> None:
    e = p[1:] - p[:-1]
    lengths = np.hypot(e[:, 0], e[:, 1])
    mean = float(lengths.mean())
    dev = lengths - mean
    spread = math.sqrt(float(dev @ dev) / dev.size) / mean  # std / mean
    if spread > tol:
        raise CurveError(
            f"points are unevenly spaced: edge lengths from {lengths.min():.6g} to "
            f"{lengths.max():.6g}, relative spread std/mean = {spread:.3g} (allowed "
            f"spacing_tol = {tol:g}); the fit pairs data and model vertices by index, so "
            "resample to equal steps first: fit(..., resample=True) or curvesmith fair --resample"
        )


@functools.lru_cache(maxsize=4)
def _savgol(window: int, order: int) -> np.ndarray:
    return savgol_coeffs(window, order)


def _noise_level(p: np.ndarray) -> float:
    """Rms distance of the data from a sliding cubic fit (window 7), de-biased.

    Interior vertices only: ``p - S p`` with the Savitzky-Golay smoother ``S``; the
    residual variance of white noise is ``(1 - c_0) sigma^2`` (``c_0 = 1/3``, the
    centre weight), so dividing by ``1 - c_0`` gives back the per-vertex noise.
    """
    n = p.shape[0]
    window, order = (7, 3) if n >= 7 else (5, 2)
    coeffs = _savgol(window, order)
    z = np.ascontiguousarray(p).view(complex).ravel()  # x + iy: both columns in one convolution
    resid = (z[window // 2 : n - window // 2] - np.convolve(z, coeffs, mode="valid")).view(float)
    return float(np.sqrt((resid @ resid) / (n - window + 1) / (1.0 - coeffs[window // 2])))


class _Problem:
    """Residuals and Jacobian of eq. (4.8) with some parameters pinned."""

    def __init__(self, data: np.ndarray, base: np.ndarray, free: np.ndarray):
        self.data = data
        self.n = data.shape[0]
        self.base = base
        self.free = free

    def full(self, x: np.ndarray) -> ElasticaParams:
        p = self.base.copy()
        p[self.free] = x
        return ElasticaParams(*p.tolist())

    def residuals(self, x):
        return (_positions(self.full(x), self.n) - self.data).ravel()

    def jacobian(self, x):
        _, jac = _positions_and_jacobian(self.full(x), self.n)
        return jac[:, :, self.free].reshape(2 * self.n, -1)

    def objective(self, x):
        r = self.residuals(x)
        return 0.5 * float(r @ r)

    def gradient(self, x):
        pts, jac = _positions_and_jacobian(self.full(x), self.n)
        r = (pts - self.data).ravel()
        return jac[:, :, self.free].reshape(2 * self.n, -1).T @ r


def _bounds(free: np.ndarray):
    lo = np.full(7, -np.inf)
    lo[2] = lo[6] = 1e-12
    return lo[free], np.full(int(free.sum()), np.inf)


class _Memo:
    """Residuals and transposed Jacobian of a :class:`_Problem`, remembering the last point of each.

    ``leastsq`` evaluates both once at the start to check their shapes and MINPACK
    then asks again at the same point: the repeat is free. The Jacobian is handed
    over column by column (``col_deriv``): ``(n_free, 2N)``, with all seven
    parameters free a reshaped view of :func:`exact._jacobian_columns`.
    """

    def __init__(self, prob: _Problem):
        self.prob = prob
        self.all_free = bool(prob.free.all())
        self._r = self._j = (None, None)

    def _params(self, x: np.ndarray) -> ElasticaParams:
        return ElasticaParams._make(x.tolist()) if self.all_free else self.prob.full(x)

    def residuals(self, x: np.ndarray) -> np.ndarray:
        key = x.tobytes()
        last, r = self._r
        if key == last:
            return r
        prob = self.prob
        d = _positions(self._params(x), prob.n)
        d -= prob.data
        r = d.ravel()
        self._r = (key, r)
        return r

    def jacobian_columns(self, x: np.ndarray) -> np.ndarray:
        key = x.tobytes()
        last, j = self._j
        if key == last:
            return j
        prob = self.prob
        cols = _jacobian_columns(self._params(x), prob.n)
        j = cols.reshape(7, -1) if self.all_free else cols[prob.free].reshape(-1, 2 * prob.n)
        self._j = (key, j)
        return j


#: MINPACK lmder's ``info`` codes for convergence, in words: 1-4, and 6-8, which it
#: returns instead when ``tol`` is below the machine epsilon and the iteration has
#: reached machine precision.
_LM_CONVERGED = {
    1: "relative reduction of the sum of squares below tol",
    2: "relative step below tol",
    3: "relative reduction of the sum of squares and relative step below tol",
    4: "residuals orthogonal to the Jacobian columns within tol",
    6: "no further reduction of the sum of squares possible (tol below machine precision)",
    7: "no further improvement of the parameters possible (tol below machine precision)",
    8: "residuals orthogonal to the Jacobian columns to machine precision (tol below it)",
}


def _levenberg_marquardt(prob: _Problem, x0: np.ndarray, lo: np.ndarray, max_iter, tol):
    """MINPACK lmder (scipy ``leastsq``) from `x0`, unbounded: ``(x, njev, message, why_not)``.

    ``why_not`` is None (and ``message`` says how it converged) if it converged
    (``info`` 1-4, or 6-8) to a finite point inside the bounds `lo` (``h, k > 0``) with
    finite residuals; otherwise ``message`` is None and ``why_not`` the reason in words.
    Trial points outside ``U`` are evaluated as they come (``k <= 0`` mirrors the
    curve, ``k <= -1`` gives NaN residuals, which MINPACK rejects as a step);
    floating-point warnings there are expected and silenced.
    """
    memo = _Memo(prob)
    with np.errstate(all="ignore"):
        x, _, info, _, ier = leastsq(
            memo.residuals,
            x0,
            Dfun=memo.jacobian_columns,
            full_output=True,
            col_deriv=True,
            ftol=tol,
            xtol=tol,
            gtol=tol,
            maxfev=max_iter,
        )
    njev = int(info["njev"])
    if ier == 5:
        why = f"reached max_iter = {max_iter} function evaluations"
    elif ier not in _LM_CONVERGED:
        why = f"stopped with MINPACK info {ier}"
    elif not (np.all(np.isfinite(x)) and np.all(np.isfinite(info["fvec"]))):
        why = "ended with non-finite parameters or residuals"
    elif np.any(x < lo):
        names = [n for n, f in zip(PARAM_NAMES, prob.free, strict=True) if f]
        outside = ", ".join(f"{names[i]} = {x[i]:.3g}" for i in np.flatnonzero(x < lo))
        why = f"converged outside U ({outside})"
    else:
        return x, njev, f"Levenberg-Marquardt (MINPACK lmder): {_LM_CONVERGED[ier]}", None
    return x, njev, None, why


def _solve(data, start: ElasticaParams, pinned: dict[int, float], method: str, max_iter, tol):
    base = np.array(start, dtype=float)
    for i, v in pinned.items():
        base[i] = v
    free = np.ones(7, dtype=bool)
    free[list(pinned)] = False
    prob = _Problem(data, base, free)
    x0 = base[free]
    lo, hi = _bounds(free)
    x0 = np.clip(x0, lo, hi)
    if method == "lsq":
        x, lm_iters, msg, why_not = _levenberg_marquardt(prob, x0, lo, max_iter, tol)
        if why_not is None:
            return prob.full(x), lm_iters, True, msg
        # Fallback: bounded trust-region reflective from the same start (h, k > 0 kept).
        res = least_squares(
            prob.residuals,
            x0,
            jac=prob.jacobian,
            bounds=(lo, hi),
            method="trf",
            x_scale="jac",
            ftol=tol,
            xtol=tol,
            gtol=tol,
            max_nfev=max_iter,
        )
        ok = res.status > 0
        msg = (
            f"Levenberg-Marquardt {why_not}; bounded trust-region reflective "
            f"(least_squares trf) from the same start: {res.message}"
        )
        return prob.full(res.x), lm_iters + int(res.njev or res.nfev), ok, msg
    cyipopt = require("cyipopt", "ipopt", "fit(..., method='ipopt')")
    # Variables scaled by the column norms of the Jacobian at the start (what
    # least_squares does with x_scale="jac"): d gamma_n / dz grows like n, so
    # unscaled the quasi-Newton iteration can wander off on long curves.
    scale = np.linalg.norm(prob.jacobian(x0), axis=0)
    scale = np.where(scale > 0, scale, 1.0)
    # A diverging quasi-Newton run overflows in the objective before IPOPT gives up; that is
    # reported by its status (and the basin check), not as floating-point warnings.
    with np.errstate(over="ignore", invalid="ignore"):
        res = cyipopt.minimize_ipopt(
            lambda y: prob.objective(y / scale),
            x0 * scale,
            jac=lambda y: prob.gradient(y / scale) / scale,
            bounds=list(zip(lo * scale, hi * scale, strict=True)),
            options={
                "hessian_approximation": "limited-memory",
                "tol": tol,
                "max_iter": int(max_iter),
                "print_level": 0,
                "sb": "yes",
            },
        )
    # IPOPT status 0: solved; 1: solved to the "acceptable" level (it stalls within
    # acceptable_tol = 1e-6 of the scaled optimality error; the rms then agrees with lsq).
    ok = int(res.status) in (0, 1)
    msg = res.message.decode() if isinstance(res.message, bytes) else str(res.message)
    return prob.full(res.x / scale), int(res.nit), ok, msg


def _segment_index_length(p: ElasticaParams) -> float:
    """Number of vertices per monotone segment of u_n (half a period of kappa_n)."""
    seg = 2.0 * ellipk(p.k * p.k) if p.k < 1.0 else ellipk(1.0 / (p.k * p.k)) / p.k
    return float(seg / max(abs(p.z), 1e-300))


def fit(
    points,
    *,
    fixed: dict | None = None,
    method: str = "lsq",
    start=None,
    resample: bool | float = False,
    spacing_tol: float = SPACING_TOL,
    continuation: str | bool = "auto",
    basin_factor: float = 20.0,
    max_iter: int | None = None,
    tol: float | None = None,
) -> FitResult:
    """Fit a discrete elastica to data, minimising eq. (4.8) over ``U`` of eq. (4.7).

    Parameters
    ----------
    points : (N, 2) array_like
        Data ``zeta_n`` in model order, ``N >= 5``, roughly equally spaced (vertex
        ``n`` of the model is matched to data vertex ``n``).
    fixed : dict, optional
        Parameters to pin, by name (``"x0", "y0", "h", "phi", "z", "q", "k"``), e.g.
        ``{"x0": 0.0, "y0": 0.0}`` to pass through an inflection point (section 5.4).
    method : {"lsq", "ipopt"}, optional
        ``"lsq"`` (default): Levenberg-Marquardt (scipy ``leastsq``, MINPACK) with
        the analytic Jacobian, falling back to the bounded scipy ``least_squares``
        (trf) from the same start if it leaves ``U`` or does not converge (module
        docstring; ``message`` says which finished); ``"ipopt"``: IPOPT with a
        quasi-Newton Hessian (needs ``curvesmith[ipopt]``).
    start : sequence of 7 float, optional
        Starting parameters; default :func:`initial_guess` (section 4.3).
    resample : bool or float, optional
        If truthy, first resample the data to equal chords (step: the float
        given, or the mean edge length for True); the result's ``data`` holds it.
    spacing_tol : float, optional
        Largest allowed :func:`spacing_spread` (``std / mean`` of the edge lengths,
        default 0.25) without resampling; beyond it the index pairing is
        meaningless and a :class:`~curvesmith.errors.CurveError` points to resampling.
    continuation : {"auto", True, False}, optional
        Growing-prefix continuation for long curves: "auto" when a single start
        fails the basin check; True always as well; False never.
    basin_factor : float, optional
        Basin check: success needs ``rms <= basin_factor * noise + 1e-9 * extent``.
    max_iter : int, optional
        Limit per stage: function evaluations for lsq (default 400, for each of
        the two solvers), iterations for IPOPT (default 3000).
    tol : float, optional
        Solver tolerance: ``ftol = xtol = gtol`` for lsq (default 1e-12); IPOPT's
        scaled optimality error ``tol`` (default 1e-8, IPOPT's own default; with
        the variable scaling used here the rms then agrees with lsq to ~1e-12).

    Returns
    -------
    FitResult
        Parameters, fitted vertices, rms and max distance, iterations, success,
        message, case, start, ...

    Raises
    ------
    CurveError
        Fewer than 5 points, non-finite values, zero-length edges, uneven
        spacing without resampling, collinear data, bad `fixed`/`start`/`method`.

    Examples
    --------
    >>> from curvesmith.elastica import sample
    >>> true = (0.0, 0.0, 0.05, 0.3, 0.06, 0.4, 0.7)
    >>> res = fit(sample(true, 100))
    >>> bool(res.success), bool(res.rms < 1e-10), res.case
    (True, True, 'ii')
    >>> res = fit(sample(true, 100), fixed={"x0": 0.0, "y0": 0.0})
    >>> res.params.x0, res.params.y0
    (0.0, 0.0)
    """
    if method not in _METHODS:
        raise CurveError(f"method must be one of {_METHODS}, got {method!r}")
    if max_iter is None:
        max_iter = 400 if method == "lsq" else 3000
    max_iter = as_int(max_iter, name="max_iter", minimum=1)
    if tol is None:
        tol = 1e-12 if method == "lsq" else 1e-8
    tol = as_float(tol, name="tol", low=0.0)
    if continuation not in ("auto", True, False):
        raise CurveError(f"continuation must be 'auto', True or False, got {continuation!r}")
    data = as_points(points, min_points=5, distinct=True)
    spacing_tol = as_float(spacing_tol, name="spacing_tol", low=0.0)
    basin_factor = as_float(basin_factor, name="basin_factor", low=0.0)
    if resample is not False and resample is not None:
        if resample is True:
            step = float(np.hypot(*np.diff(data, axis=0).T).mean())
        else:
            step = as_float(resample, name="resample", low=0.0)
        data = _resample_walk(data, step)
        if data.shape[0] < 5:
            raise CurveError(
                f"resample step {step:.6g} leaves {data.shape[0]} points; need at least 5"
            )
    else:
        _spacing_check(data, spacing_tol)
    pinned = _check_fixed(fixed)
    if start is None:
        first = _initial_guess(data)
    else:
        first = _as_params(start)
        _data_curvature(data)  # the same input checks (collinear data) as without a start
    first = ElasticaParams(*[pinned.get(i, v) for i, v in enumerate(first)])
    noise = _noise_level(data)
    extent = float((data.max(axis=0) - data.min(axis=0)).max())
    allowed = basin_factor * noise + 1e-9 * extent

    params, iters, ok, msg = _solve(data, first, pinned, method, max_iter, tol)
    stages = 1
    n = data.shape[0]
    pts = _positions(params, n)
    dist, rms = _misfit(pts, data)
    seg = _segment_index_length(first)
    failed = not (ok and rms <= allowed)
    long_curve = start is None and n > 2 * max(10, 2 * seg)
    tried_continuation = continuation is True or (continuation == "auto" and failed and long_curve)
    if tried_continuation:
        cont = _continuation(data, first, pinned, method, max_iter, tol, seg, allowed)
        cont_pts = _positions(cont[0], n)
        cont_dist, cont_rms = _misfit(cont_pts, data)
        if cont_rms < rms:
            params, _, ok, msg, stages = cont
            pts, dist, rms = cont_pts, cont_dist, cont_rms
        iters += cont[1]  # count the work of both runs
    if not np.all(np.isfinite(pts)):
        ok, msg = False, "fit produced non-finite vertices"
    success = bool(ok and rms <= allowed)
    if ok and not success:
        msg = (
            f"fit rejected by the basin check: rms {rms:.3g} exceeds {basin_factor:g} x the "
            f"data's local noise level {noise:.3g} (+1e-9 x extent), i.e. a local minimum in a "
            "wrong basin, or data that are no discrete elastica within their noise; "
            + (
                "growing-prefix continuation did not help either; try another start or a "
                "larger basin_factor"
                if tried_continuation
                else "try another start, continuation=True or a larger basin_factor"
            )
        )
    elif not ok:
        msg = f"solver did not converge: {msg}"
    return FitResult(
        params=params,
        points=pts,
        rms=rms,
        max_distance=float(dist.max()),
        iterations=iters,
        success=success,
        message=msg,
        case=case_of(params.k),
        start=first,
        cost=0.5 * float(dist @ dist),
        noise=noise,
        data=data,
        method=method,
        stages=stages,
    )


def _misfit(pts: np.ndarray, data: np.ndarray) -> tuple[np.ndarray, float]:
    """Distances ``||gamma_n - zeta_n||`` and their rms."""
    d = pts - data
    dist = np.hypot(d[:, 0], d[:, 1])
    return dist, float(np.sqrt((dist @ dist) / dist.size))


def _rms(data: np.ndarray, p: ElasticaParams) -> float:
    d = _positions(p, data.shape[0]) - data
    return float(np.sqrt(np.mean(np.sum(d * d, axis=1))))


def _guess_or_none(prefix: np.ndarray, pinned: dict[int, float]) -> ElasticaParams | None:
    try:
        guess = _initial_guess(prefix)
    except CurveError:
        return None
    return ElasticaParams(*[pinned.get(j, v) for j, v in enumerate(guess)])


def _continuation(data, first, pinned, method, max_iter, tol, seg, allowed):
    """Fit growing prefixes: about two monotone segments first, then x1.6 per stage.

    The first stage starts from the guess of its prefix (then from `first`); each
    later stage from the previous optimum, and, if that fails the basin check,
    also from the guess of its own prefix. The better fit is carried on.
    """
    n = data.shape[0]
    size = int(min(n, max(10, np.ceil(2.0 * seg))))
    params = None
    total = 0
    stages = 0
    while True:
        prefix = data[:size]
        order = ("guess", "first") if params is None else ("previous", "guess")
        best = None
        for which in order:
            if which == "guess":
                start = _guess_or_none(prefix, pinned)
            else:
                start = first if which == "first" else params
            if start is None:
                continue
            cand = _solve(prefix, start, pinned, method, max_iter, tol)
            total += cand[1]
            r = _rms(prefix, cand[0])
            if best is None or r < best[0]:
                best = (r, cand)
            if r <= allowed:
                break
        params, _, ok, msg = best[1]
        stages += 1
        if size == n:
            return params, total, ok, msg, stages
        size = min(n, int(np.ceil(_GROWTH * size)))
