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

Global search (default, ``continuation="auto"``). Eq. (4.8) has many local minima: the
phase error of ``z`` grows along the curve, and on noisy or only roughly elastic data
(a scan with model error) the guess of section 4.3 can pick the wrong case, the wrong
parity of the number of monotone segments or a ``k`` on the wrong side of the
separatrix. The default fit therefore

1. orients the data canonically (the end with the lexicographically smaller
   coordinates first; the result is mapped back to the given order), so the result does
   not depend on the point order;
2. fits a coarse subsample (every ``m``-th vertex, ~60 vertices, where the discrete
   curvature that the guess reads is ``m^2`` times less noisy) from the guess and its
   variants (other parity, other case, ``k`` near 1; :func:`guess._guess_variants`) and
   from the guess of the reversed data, keeps the two best minima, and refines them on
   all vertices, through an intermediate level for long data (parameters rescaled:
   ``h / m``, ``z / m``);
3. adds the degenerate elasticae (line, circle; :mod:`._degenerate`) as candidates;
4. for long curves with many loops whose best fit is still far above the noise level,
   also runs the growing-prefix continuation (each stage starts from the previous
   optimum);

and keeps the candidate of least cost. A start from the guess that already fits at the
noise level ends the search early.

The solves of step 2 (without pinned parameters, or with only ``x0, y0`` pinned) run by
variable projection (:mod:`._varpro`): ``x0, y0, h, phi`` enter eq. (4.4) linearly as
``gamma_0 + h e^{i phi} W_n`` and are solved in closed form, Levenberg-Marquardt works on
``(z, q, k)`` in coordinates that follow the curvature extremum near the separatrix, and
the paper's seven-parameter LM polishes the optimum (it then stops after 1-5 Jacobian
evaluations). On a 1.5 m uneven section scan near the separatrix (``k = 1.0014``) the
seven-parameter solves crawled along a curved valley for 16,000 evaluations (10 s); the
projected ones need 12. The single start (``continuation=False``, ``start=``), the
growing-prefix continuation and the degenerate probe keep the seven-parameter solves: the
projected problem has other basins on long many-loop curves near ``k = 1``, where the
continuation is what finds the right one. A projected solve that reaches or crosses
``k = 1`` with a period shift (singular coordinates there, :mod:`._varpro`) is redone in
the seven parameters from the same start. While exploring, a solve that has not converged
after ``_PROBE_CAP`` evaluations goes on only if its rms is within the runner-up margin of
the best converged start so far (a worse one is never refined).

Verdict and quality are separate. ``success`` says that the solver converged (to the
best minimum of the search, unless a single start was asked for). How close the curve
is to an elastica is measured, not judged: ``rms`` (index-paired, eq. (4.8)),
``max_deviation`` and ``rms_deviation`` (geometric: each input point to the fitted
polyline), against ``noise``, the data's local noise level (rms residual of a sliding
cubic Savitzky-Golay fit, which follows any smooth curve), and ``within_tolerance`` when
a tolerance is given. The message says which it is ("converged; rms 0.28 is model error,
350 x the noise level 0.0008"). A resampled fit is judged by the input points instead: their
rms distance from the fit against their own noise (distances to neighbour chords, which
need no equal spacing), since resampling averages noise away and its walk drifts along the
curve. Fewer than :data:`MIN_NOISE_POINTS` points measure their bending, not their noise:
``noise`` is NaN then and the message says so.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike
from scipy.optimize import least_squares, leastsq
from scipy.special import ellipk

from .._rich import RichRepr
from .._validate import as_choice, as_float, as_int, as_points
from ..errors import CurveError, require
from ..geometry import _resample_walk
from . import _degenerate, _geom, _varpro
from .exact import (
    ElasticaParams,
    _as_params,
    _jacobian_columns,
    _positions,
    _positions_and_jacobian,
    case_of,
)
from .guess import _data_curvature, _guess_variants, _initial_guess

__all__ = [
    "PARAM_NAMES",
    "SPACING_TOL",
    "FitResult",
    "fit",
    "needs_resampling",
    "spacing_spread",
]

#: Names of the parameters of eq. (4.5), in order.
PARAM_NAMES = ("x0", "y0", "h", "phi", "z", "q", "k")
_METHODS = ("lsq", "ipopt")
#: Default largest relative spread of the edge lengths that :func:`fit` accepts.
SPACING_TOL = 0.25
_GROWTH = 1.6


@dataclass(frozen=True)
class FitResult(RichRepr):
    """Result of :func:`fit`.

    Attributes
    ----------
    params : ElasticaParams
        Fitted ``(x0, y0, h, phi, z, q, k)`` (continued modulus ``k``).
    points : (N, 2) ndarray
        The fitted discrete elastica ``gamma_n(params)``, one vertex per data vertex.
    rms : float
        ``sqrt(mean_n ||gamma_n - zeta_n||^2)`` over the fitted `data` (index-paired).
    max_distance : float
        ``max_n ||gamma_n - zeta_n||`` (index-paired; see `max_deviation`).
    iterations : int
        Solver iterations (Jacobian evaluations for ``lsq``, Levenberg-Marquardt
        plus the trf fallback where it ran) of the solve from `start` that gave the
        result; `total_iterations` counts the whole search.
    success : bool
        The solver converged; with the global search (default) to the best minimum
        among all starts. Says nothing about how well an elastica describes the data:
        see `rms`, `max_deviation`, `noise`, `within_tolerance`.
    message : str
        What happened, in words: the solver's stopping reason, the search, and the
        rms against the noise level (and the tolerance, if given).
    case : str
        ``"ii"`` (inflections, ``k < 1``), ``"i"`` (``k > 1``), ``"separatrix"``,
        or the degenerate ``"line"`` (``z = 0``) and ``"circle"`` (``k = 1e8``).
    start : ElasticaParams
        The starting point of the solve that gave the result.
    cost : float
        Final value of eq. (4.8).
    noise : float
        Local noise level of the data (module docstring). NaN when the data are too
        few to tell their noise from their bending (fewer than :data:`MIN_NOISE_POINTS`
        points); the message then says so instead of comparing with it.
    data : (N, 2) ndarray
        The data that was fitted (after resampling, if requested), in the given order.
    method : str
        Backend used.
    stages : int
        Number of successive fits on the path to the result: 1 for a single start,
        the number of resolution levels for coarse-to-fine, or of growing prefixes.
    max_deviation : float
        Geometric: the largest distance from an input point (before resampling) to
        the fitted polyline.
    rms_deviation : float
        Geometric: rms of those distances.
    tolerance : float or None
        The tolerance given, if any.
    within_tolerance : bool or None
        ``max_deviation <= tolerance``; None without a tolerance.
    total_iterations : int
        Solver iterations of the whole search (all starts and levels).
    starts : int
        Number of starts tried.
    deviation : (M,) ndarray
        Distance of every input point to the fitted polyline.
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
    max_deviation: float = float("nan")
    rms_deviation: float = float("nan")
    tolerance: float | None = None
    within_tolerance: bool | None = None
    total_iterations: int = 0
    starts: int = 1
    deviation: np.ndarray | None = field(default=None, repr=False)


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


def spacing_spread(points: ArrayLike) -> float:
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


#: :func:`needs_resampling`: a drift beyond this many noise levels (a vertex's rms
#: displacement, ``sqrt(2) sigma``) is not the noise's. Noise alone drifts the vertices by
#: the largest of N Gaussian displacements along the curve, each of one level: about 3.5
#: levels for N = 400, 4.3 for 10,000 (``sqrt(2 ln N)``).
DRIFT_LEVELS = 5.0
#: ... plus this many times ``sqrt(2 N) sigma^2 / h``: noise across the curve lengthens
#: each chord by ``d^2 / 2h`` (``d`` the difference of two neighbours' offsets), a
#: positive bias whose fluctuation adds up along the arc like a random walk. On straight
#: lines and circles of 400 to 10,000 equal steps with ``sigma / h`` of 0.05 to 0.5, 60
#: runs each: no false alarm at 1.5 (at 0, 16 of 40 at N = 400, ``sigma = 0.3 h``).
DRIFT_WALK = 2.0


def needs_resampling(points: ArrayLike) -> bool:
    """Whether `points` should be resampled to equal chords before :func:`fit`.

    :func:`fit` pairs data vertex ``n`` with model vertex ``n``, which sits ``n h``
    along the model from its start. Data whose vertices drift from equal steps pull
    the pairs apart along the curve, and the fit bends to follow: on 1.5 m section
    curves of 400 points with 0.05 mm noise, a smoothly varying speed of +-5 % (a
    spacing spread of 0.035) made the worst deviation of the fit 1.3-2.9 mm against
    0.6-2.3 mm resampled, +-12 % (spread 0.085) 3.1-4.6 mm, well inside the spread
    that :func:`fit` accepts. The test is the drift itself: the largest distance
    along the data between a vertex and the best equal steps, ``max_n |s_n - (a +
    n b)|`` (``s_n`` the arc length to vertex ``n``, ``a + n b`` its least-squares
    line: the start and the step are the fit's to choose), against what the data's
    noise explains (:data:`DRIFT_LEVELS` noise levels, the noise measured from the
    distances to neighbour chords, which needs no equal spacing, and the random
    walk that noise across the curve adds to the chords' lengths,
    :data:`DRIFT_WALK`). Noisy data on equal steps stays as it is; repeated points,
    and a spacing spread over :data:`SPACING_TOL` (which :func:`fit` refuses as
    given), always need resampling.

    Parameters
    ----------
    points : (N, 2) array_like
        Vertices, ``N >= 2``.

    Returns
    -------
    bool

    Examples
    --------
    >>> t = np.linspace(0, 1, 200)
    >>> needs_resampling(np.c_[np.cos(t), np.sin(t)])
    False
    >>> needs_resampling(np.c_[np.cos(t**1.2), np.sin(t**1.2)])
    True
    """
    p = as_points(points, min_points=2)
    e = np.hypot(*np.diff(p, axis=0).T)
    if np.any(e == 0):
        return True
    arc = np.concatenate([[0.0], np.cumsum(e)])
    n = np.arange(arc.size, dtype=float) - 0.5 * (arc.size - 1)  # centred: a, b independent
    b = float(n @ arc) / float(n @ n)
    drift = float(np.max(np.abs(arc - arc.mean() - b * n)))
    sigma, step = _scan_noise(p), float(e.mean())
    walk = math.sqrt(2.0 * arc.size) * sigma * sigma / step
    allowed = DRIFT_LEVELS * math.sqrt(2.0) * sigma + DRIFT_WALK * walk + 1e-9 * float(arc[-1])
    if drift > allowed:
        return True
    # what fit refuses as given (a spread over SPACING_TOL) is always resampled
    return bool(float(e.std() / e.mean()) > SPACING_TOL)


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
    """Savitzky-Golay smoothing weights: the centre row of the least-squares polynomial fit.

    Equal to ``scipy.signal.savgol_coeffs(window, order)`` (symmetric, so the convolution
    order does not matter; test), without importing ``scipy.signal`` (1.7 s at start-up).
    """
    t = np.arange(window, dtype=float) - window // 2
    return np.linalg.pinv(np.vander(t, order + 1, increasing=True))[0]


def _sliding_residuals(
    p: np.ndarray, window: int = 7, order: int = 3
) -> tuple[np.ndarray, int, float]:
    """``p - S p`` at the interior vertices (complex ``x + iy``), the window, ``1 - c_0``.

    ``S`` is the Savitzky-Golay smoother of a sliding polynomial of `order` over `window`
    points (a cubic over 7 by default; 5 and a quadratic for fewer points), ``c_0`` its
    centre weight.
    """
    n = p.shape[0]
    if n < window:
        window, order = (7, 3) if n >= 7 else (5, 2)
    coeffs = _savgol(window, order)
    z = np.ascontiguousarray(p).view(complex).ravel()  # x + iy: both columns in one convolution
    r = z[window // 2 : n - window // 2] - np.convolve(z, coeffs, mode="valid")
    return r, window, 1.0 - float(coeffs[window // 2])


def _level(r: np.ndarray, gain: float) -> float:
    resid = r.view(float)
    return float(np.sqrt((resid @ resid) / (resid.size // 2) / gain))


def _noise_level(p: np.ndarray) -> float:
    """Rms distance of the data from a sliding cubic fit (window 7), de-biased.

    Interior vertices only: ``p - S p`` with the Savitzky-Golay smoother ``S``; the
    residual variance of white noise is ``(1 - c_0) sigma^2`` (``c_0 = 1/3``, the
    centre weight), so dividing by ``1 - c_0`` gives back the per-vertex noise.
    """
    r, _, gain = _sliding_residuals(p)
    return _level(r, gain)


#: Residual squares of the noise level's sliding fit beyond this many times their median
#: (residuals 10 times the typical one) are glitches, left out: white noise (chi-square of 2
#: degrees of freedom, median 2 ln 2) puts none there (``exp(-100 ln 2)``), and the texture
#: of real data (chords of a resampled circle, a scan's surface) rarely does.
GLITCH_CUT = 100.0
#: At most this many glitches (or 2 % of the residuals) are left out; more residuals beyond
#: the cut are the data's own.
GLITCH_MAX = 3


#: The noise level needs this many points: a sliding fit over fewer spans so much of the
#: curve that its residuals are the curve's bending (8 points on a 600 mm S elastica with
#: 0.01 mm noise gave a "noise level" of 14 mm, and a fit 16.6 mm off the points read as
#: "at the noise level").
MIN_NOISE_POINTS = 20
#: A sliding cubic whose residuals exceed a sliding quintic's this many times measures the
#: bending of sparse points, not their noise (white noise gives both the same level: at
#: 20 points the ratio stayed below 1.55 in 2,000 draws); the quintic's, which follows the
#: bending further, is used then.
BENDING_RATIO = 2.0


def _measured_noise(p: np.ndarray) -> float:
    """The level :func:`fit`'s verdict quotes: :func:`_glitch_free_noise`, where measurable.

    NaN for fewer than :data:`MIN_NOISE_POINTS` points. Where the sliding cubic follows the
    bending of the points less well than white noise would let it
    (:data:`BENDING_RATIO`), the level of a sliding quintic (window 9) instead.
    """
    if p.shape[0] < MIN_NOISE_POINTS:
        return math.nan
    level = _glitch_free_noise(p)
    finer = _glitch_free_noise(p, window=9, order=5)
    return finer if level > BENDING_RATIO * finer else level


def _glitch_free_noise(p: np.ndarray, window: int = 7, order: int = 3) -> float:
    """:func:`_noise_level` without the residuals of glitches: the level the verdict quotes.

    Interior vertices only: ``p - S p`` with the Savitzky-Golay smoother ``S``; for white
    noise of ``sigma`` per coordinate each residual has the variance ``(1 - c_0) sigma^2``
    per coordinate (``c_0 = 1/3``, the centre weight), so its squared length is
    ``(1 - c_0) sigma^2`` times a chi-square of 2 degrees of freedom. The level is
    ``sqrt(2) sigma`` (a vertex's rms displacement): the mean of the squares over
    ``1 - c_0``, without those beyond :data:`GLITCH_CUT` times their median when they are
    few (:data:`GLITCH_MAX` glitches' windows, or 2 % of the residuals). A glitch of
    a scan (one point 5 % of the curve off) made the level 0.52 on an exact elastica, so
    that the fit through the glitch read as "at the noise level"; left out, it does not
    count.
    """
    r, window, gain = _sliding_residuals(p, window, order)
    sq = r.real * r.real + r.imag * r.imag
    # the squares beyond GLITCH_CUT medians are glitches (white noise puts none there); the
    # mean of the others is the level, as for data without glitches
    keep = sq <= GLITCH_CUT * float(np.median(sq))
    # a glitch is rare: a few points, each spoiling the residuals of one window; many
    # residuals out there mean data that are not white noise (a scan's texture): all count
    if keep.size - np.count_nonzero(keep) > max(GLITCH_MAX * window, 0.02 * keep.size):
        return _level(r, gain)
    return _level(r[keep], gain)


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
        self._r: tuple[bytes | None, Any] = (None, None)
        self._j: tuple[bytes | None, Any] = (None, None)

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


def _levenberg_marquardt(prob: _Problem, x0: np.ndarray, lo: np.ndarray, max_iterations, tol):
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
            maxfev=max_iterations,
        )
    njev = int(info["njev"])
    if ier == 5:
        why = f"reached max_iterations = {max_iterations} function evaluations"
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


def _solve(
    data,
    start: ElasticaParams,
    pinned: dict[int, float],
    method: str,
    max_iterations,
    tol,
    fallback=True,
):
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
        x, lm_iters, msg, why_not = _levenberg_marquardt(prob, x0, lo, max_iterations, tol)
        if why_not is None:
            return prob.full(x), lm_iters, True, msg
        if not fallback and why_not.startswith("reached max_iterations"):
            return prob.full(x), lm_iters, False, f"Levenberg-Marquardt {why_not}"
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
            max_nfev=max_iterations,
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
                "max_iter": int(max_iterations),  # IPOPT's own option name
                "print_level": 0,
                "sb": "yes",
                "acceptable_iter": 0,  # no "acceptable" stop short of tol (see below)
            },
        )
    # IPOPT status 0: solved to `tol`. Its "acceptable" stop (status 1: 15 iterates within
    # acceptable_tol = 1e-6) is off (acceptable_iter 0): with numpy 2.4.6 / scipy 1.17.1 /
    # cyipopt-wheels 1.7.0.dev0 it stopped there on an 80-point fit with the rms 4e-8 above
    # the optimum (lsq's); run on to `tol` it agrees to 3e-12, 158 iterations against 115
    ok = int(res.status) == 0
    msg = res.message.decode() if isinstance(res.message, bytes) else str(res.message)
    return prob.full(res.x / scale), int(res.nit), ok, msg


def _segment_index_length(p: ElasticaParams) -> float:
    """Number of vertices per monotone segment of u_n (half a period of kappa_n)."""
    if p.k >= _degenerate.CIRCLE_K or p.z == 0.0:
        return math.inf
    seg = 2.0 * ellipk(p.k * p.k) if p.k < 1.0 else ellipk(1.0 / (p.k * p.k)) / p.k
    return float(seg / max(abs(p.z), 1e-300))


#: Default ``max_iterations`` per solve: function evaluations for lsq, iterations for IPOPT.
DEFAULT_MAX_ITERATIONS = {"lsq": 5000, "ipopt": 3000}
#: Vertices of the coarsest level of the global search.
_COARSE_POINTS = 60
#: Ratio of successive levels of the global search.
_LEVEL_RATIO = 8
#: A line or circle within this factor of the early-exit level ends the search.
_DEGENERATE_EARLY = 2.5
#: The default resampling chord is at least this many noise levels of the input.
_NOISE_STEPS = 20.0


def _scan_noise(p: np.ndarray) -> float:
    """Robust per-coordinate noise of unevenly spaced points: distances to neighbour chords.

    The distance of ``p_i`` from the line through ``p_{i-1}, p_{i+1}`` has variance
    ``1.5 sigma^2`` for white noise on a straight piece (weights 1, 1/2, 1/2); the median
    absolute value over the curve, ``/ 0.6745``, ignores glitches and curved stretches.
    Unlike the Savitzky-Golay level it needs no equal spacing (clustered scan points).
    """
    if p.shape[0] < 3:
        return 0.0
    a, b, c = p[:-2], p[1:-1], p[2:]
    e = c - a
    norm = np.hypot(e[:, 0], e[:, 1])
    ok = norm > 0
    if not ok.any():
        return 0.0
    w = b[ok] - a[ok]
    d = np.abs(e[ok, 0] * w[:, 1] - e[ok, 1] * w[:, 0]) / norm[ok]
    return float(np.median(d) / 0.6745 / math.sqrt(1.5))


#: A start whose fit has an rms within this many noise levels ends the search.
_AT_NOISE = 1.3


def _reverse_params(p: ElasticaParams, n: int) -> ElasticaParams:
    """Parameters of the same discrete elastica traversed backwards.

    ``sample(_reverse_params(p, n), n) == sample(p, n)[::-1]`` to rounding.

    Vertex ``n`` becomes ``N - 1 - n``: ``s'_n = s_{N-1-n}`` gives ``z' = -z`` and
    ``q' = q + z (N-1)``; the tangents turn by pi (``phi' = phi + pi``); the start is the
    old last vertex.
    """
    last = _positions(p, n)[-1]
    return ElasticaParams(
        float(last[0]),
        float(last[1]),
        p.h,
        math.remainder(p.phi + math.pi, 2.0 * math.pi),
        -p.z,
        p.q + p.z * (n - 1),
        p.k,
    )


def _scaled(p: ElasticaParams, ratio: float) -> ElasticaParams:
    """A fit of every ``m``-th vertex as a start for every ``m / ratio``-th: ``h, z / ratio``."""
    return p._replace(h=p.h / ratio, z=p.z / ratio)


def _levels(data: np.ndarray, pinned: dict[int, float]) -> list[int]:
    """Subsampling factors of the global search, coarsest first, ending with 1."""
    n = data.shape[0]
    m = n // _COARSE_POINTS
    if m < 2 or 2 in pinned or 4 in pinned:  # h or z pinned: no rescaling
        return [1]
    # keep the turning per coarse edge small (<= 0.5 rad): loops need their vertices
    while m >= 2:
        e = np.diff(data[::m], axis=0)
        ang = np.arctan2(e[:, 1], e[:, 0])
        turn = np.abs(np.angle(np.exp(1j * np.diff(ang))))
        if turn.size == 0 or float(turn.max()) <= 0.5:
            break
        m //= 2
    if m < 2:
        return [1]
    if m <= _LEVEL_RATIO:
        return [m, 1]
    mid = m // _LEVEL_RATIO
    return [mid * _LEVEL_RATIO, mid, 1] if mid >= 2 else [m, 1]


class _Search:
    """Bookkeeping of the global search: every solve, the total work, the best result."""

    def __init__(self, method: str, max_iterations: int, tol: float):
        self.method, self.max_iterations, self.tol = method, max_iterations, tol
        self.total = 0
        self.tried = 0

    def solve(self, data, start, pinned, cap=None, reduced=True, bar=math.inf):
        limit = self.max_iterations if cap is None else min(cap, self.max_iterations)
        reduced = reduced and _VARPRO and self.method == "lsq" and set(pinned) in (set(), {0, 1})
        out = self._reduced(data, start, pinned, limit, bar) if reduced else None
        if out is None and reduced and cap is not None and limit > _PROBE_CAP:
            # a projected solve that failed, while exploring: the seven-parameter solve gets
            # _PROBE_CAP evaluations first and the rest only if it is then within `bar`
            # (the runner-up margin of the best so far; worse candidates are never refined;
            # the projected solves are probed the same way)
            out = _solve(data, start, pinned, self.method, _PROBE_CAP, self.tol, fallback=False)
            with np.errstate(all="ignore"):
                r = _rms(data, out[0])
            if not out[2] and r <= bar:
                more = _solve(
                    data, out[0], pinned, self.method, limit - _PROBE_CAP, self.tol, False
                )
                out = (more[0], out[1] + more[1], more[2], more[3])
        if out is None:
            out = _solve(data, start, pinned, self.method, limit, self.tol, fallback=cap is None)
        params, iters, ok, msg = out
        self.total += iters
        self.tried += 1
        with np.errstate(all="ignore"):
            r = _rms(data, params)
        if not math.isfinite(r):
            ok, r = False, math.inf
        return {
            "params": params,
            "iters": iters,
            "ok": ok,
            "msg": msg,
            "rms": r,
            "start": start,
            "capped": cap is not None and limit < self.max_iterations,
        }

    def _reduced(self, data, start, pinned, limit, bar=math.inf):
        """Variable projection (:mod:`._varpro`), then the paper's LM on all seven parameters.

        Returns ``_solve``'s tuple, or None when the reduced solve failed (the caller then
        runs ``_solve`` from `start`). A reduced optimum that the polish cannot finish within
        ``_POLISH_CAP`` evaluations stays the result, as converged (its message says so).
        """
        anchor = complex(pinned[0], pinned[1]) if pinned else None
        if math.isfinite(bar) and limit > _PROBE_CAP:  # exploring: _PROBE_CAP first (solve)
            params, iters, status = _varpro.solve(data, start, anchor, _PROBE_CAP, self.tol)
            if status == "cap":
                with np.errstate(all="ignore"):
                    r = _rms(data, params)
                if r <= bar:
                    more = _varpro.solve(data, params, anchor, limit - _PROBE_CAP, self.tol)
                    if more[0] is not None:
                        params, status = more[0], more[2]
                    iters += more[1]
        else:
            params, iters, status = _varpro.solve(data, start, anchor, limit, self.tol)
        if status == "failed":
            self.total += iters
            return None
        if status == "cap":
            return (
                params,
                iters,
                False,
                f"Levenberg-Marquardt on (z, q, k) reached max_iterations = {limit} evaluations",
            )
        polished, more, ok, msg = _solve(
            data, params, pinned, "lsq", _POLISH_CAP, self.tol, fallback=False
        )
        with np.errstate(all="ignore"):
            better = ok and _rms(data, polished) <= _rms(data, params) * (1 + 1e-9)
        if better:
            return polished, iters + more, True, msg
        return (
            params,
            iters + more,
            True,
            (
                "Levenberg-Marquardt (MINPACK lmder) on (z, q, k) with (x0, y0, h, phi) in closed "
                "form (variable projection): converged"
            ),
        )

    def explore(self, data, starts, pinned, early):
        """Solve from each start with the exploration cap; stop at the first at the noise level."""
        out = []
        seen = set()
        for s in starts:
            key = tuple(round(v, 12) for v in s)
            if key in seen:
                continue
            seen.add(key)
            best = min((c["rms"] for c in out if c["ok"]), default=math.inf)
            c = self.solve(data, s, pinned, cap=_EXPLORE_CAP, bar=_RUNNER_UP * best)
            out.append(c)
            if c["ok"] and c["rms"] <= early:
                break
        return sorted((c for c in out if math.isfinite(c["rms"])), key=lambda c: c["rms"])

    def finish(self, data, cand, pinned):
        """Carry on a candidate that stopped at the exploration cap, with the full limit."""
        if cand["ok"] or not cand["capped"]:
            return cand
        more = self.solve(data, cand["params"], pinned)
        more["iters"] += cand["iters"]
        more["start"] = cand["start"]
        return more if more["rms"] <= cand["rms"] or more["ok"] else cand


#: Function evaluations (lsq) or iterations (IPOPT) per start while exploring.
_EXPLORE_CAP = 300
#: Function evaluations of the seven-parameter LM that polishes a variable-projection optimum.
_POLISH_CAP = 100
#: Function evaluations after which an exploring solve that has not converged must be within
#: the runner-up margin of the best converged start so far to go on.
_PROBE_CAP = 60
#: The global search solves by variable projection (:mod:`._varpro`); False gives the
#: seven-parameter solves throughout (``benchmarks/bench_elastica_global.py`` times both).
_VARPRO = True
#: A runner-up of the coarse level is refined only if its rms is within this factor of the best.
_RUNNER_UP = 1.5


def _pinned_at(pinned: dict[int, float], m: int) -> dict[int, float]:
    return {i: (v * m if i in (2, 4) else v) for i, v in pinned.items()}


def _starts(d: np.ndarray) -> list[ElasticaParams]:
    """The guess and its variants for `d`, then for `d` reversed (mapped back)."""
    out: list[ElasticaParams] = []
    n = d.shape[0]
    for rev in (False, True):
        try:
            gs = _guess_variants(d[::-1] if rev else d)
        except CurveError:
            continue
        out.extend(_reverse_params(g, n) if rev else g for g in gs)
    # the two guesses first, then the variants
    return sorted(out, key=lambda g: 0 if g is out[0] else 1)


def _distinct_best(cands: list[dict], count: int) -> list[dict]:
    """The best `count` candidates of distinct rms; runners-up only within 1.5 x the best."""
    keep: list[dict] = []
    for c in cands:
        if keep and (c["rms"] > _RUNNER_UP * keep[0]["rms"] or not c["ok"]):
            continue
        if all(abs(c["rms"] - k["rms"]) > 1e-6 * k["rms"] for k in keep):
            keep.append(c)
        if len(keep) == count:
            break
    return keep


#: A converged candidate wins over a lower-rms one that stopped at the iteration cap only
#: when its rms is within this relative margin: a closed-form circle (always "converged")
#: must not beat an elastica 35x closer to the data that merely needed more iterations.
_CONVERGED_SLACK = 1e-3


def _best(cands: list[dict]) -> dict:
    """The lowest rms; among candidates as good as that (within the slack), a converged one."""
    finite = [c for c in cands if math.isfinite(c["rms"])] or list(cands)
    low = min(finite, key=lambda c: c["rms"])
    bar = low["rms"] * (1 + _CONVERGED_SLACK)
    good = [c for c in finite if c["ok"] and c["rms"] <= bar]
    return min(good, key=lambda c: c["rms"]) if good else low


def _global_search(data, pinned, search: _Search, early: float):
    """Coarse-to-fine multi-start search (module docstring); returns the best candidate dict."""
    levels = _levels(data, pinned)
    finals: list[dict[str, Any]] = []
    if not pinned:  # the degenerate elasticae first: data on a line or circle end the search
        for make in (_degenerate.line_fit, _degenerate.circle_fit):
            p = make(data)
            if p is None:
                continue
            with np.errstate(all="ignore"):
                r = _rms(data, p)
            if math.isfinite(r):
                finals.append(
                    {
                        "params": p,
                        "iters": 0,
                        "ok": True,
                        "msg": f"closed-form {_degenerate.degenerate_case(p)} fit",
                        "rms": r,
                        "start": p,
                        "stages": 1,
                    }
                )
        if finals and min(c["rms"] for c in finals) <= _DEGENERATE_EARLY * early:
            # a line or circle within ~3 noise levels: unless the guess of section 4.3 does
            # better in one capped solve, the search ends (it would only crawl to k -> inf)
            deg = _best(finals)
            try:
                probe = search.solve(
                    data, _initial_guess(data), pinned, cap=_EXPLORE_CAP, reduced=False
                )
            except CurveError:
                probe = None
            if probe is None or not (probe["ok"] and probe["rms"] < deg["rms"] - 0.01 * early):
                return deg, [1]
            probe["stages"] = 1
            finals.append(probe)
    if levels == [1]:
        explored = search.explore(data, _starts(data), pinned, early)
        for c in _distinct_best(explored, 2):
            c = search.finish(data, c, pinned)
            c["stages"] = 1
            finals.append(c)
    else:
        m0 = levels[0]
        d0 = data[::m0]
        noise0 = _noise_level(d0)
        extent0 = float((d0.max(axis=0) - d0.min(axis=0)).max())
        early0 = _AT_NOISE * noise0 + 1e-9 * extent0
        explored = search.explore(d0, _starts(d0), _pinned_at(pinned, m0), early0)
        for rank, c in enumerate(_distinct_best(explored, 2)):
            params, m_prev, stages = c["params"], m0, 1
            cand = c
            for m in levels[1:]:
                start = _scaled(params, m_prev / m)
                pin = _pinned_at(pinned, m)
                if rank == 0:
                    cand = search.finish(data[::m], search.solve(data[::m], start, pin), pin)
                else:  # a runner-up gets the exploration budget per level
                    cand = search.solve(data[::m], start, pin, cap=_EXPLORE_CAP)
                params, m_prev, stages = cand["params"], m, stages + 1
            cand["stages"] = stages
            finals.append(cand)
            if cand["ok"] and cand["rms"] <= early:
                break
    if not finals:
        _initial_guess(data)  # raises the guess's reason (collinear data, ...)
        raise CurveError("no start of the global search gave a finite fit")
    best = _best(finals)
    if not best["ok"] and math.isfinite(best["rms"]):
        # the best basin stopped at the cap: one more full solve from where it stopped
        more = search.solve(data, best["params"], pinned)
        if more["rms"] <= best["rms"] * (1 + _CONVERGED_SLACK):
            more["iters"] += best["iters"]
            more["start"], more["stages"] = best["start"], best.get("stages", 1)
            best = more
    return best, levels


def _prepare(points, *, resample, spacing_tol, reverse_ok):
    """Validate, orient canonically (`reverse_ok`), resample: ``(input, data, reversed)``."""
    raw = as_points(points, min_points=5)
    if resample is not False and resample is not None:
        raw = _geom.drop_repeats(raw)
        if raw.shape[0] < 2:
            raise CurveError(f"points must not all coincide, got every point at {raw[0].tolist()}")
    else:
        raw = as_points(raw, min_points=5, distinct=True)
    rev = bool(reverse_ok and tuple(raw[-1].tolist()) < tuple(raw[0].tolist()))
    work = raw[::-1] if rev else raw
    if resample is not False and resample is not None:
        if resample is True:
            # the mean edge, but at least _NOISE_STEPS noise levels: on a scan whose noise
            # exceeds its spacing, shorter chords zig-zag along the noise and the progress
            # per chord, which the index pairing assumes equal, varies
            step = float(np.hypot(*np.diff(work, axis=0).T).mean())
            if work.shape[0] >= MIN_NOISE_POINTS:  # (fewer: the chord distances are bending)
                step = max(step, _NOISE_STEPS * _scan_noise(work))
            data = _geom.walk_to_end(np.ascontiguousarray(work), step)
        else:
            step = as_float(resample, name="resample", low=0.0)
            data = _resample_walk(np.ascontiguousarray(work), step)
        if data.shape[0] < 5:
            raise CurveError(
                f"resample step {step:.6g} leaves {data.shape[0]} points; need at least 5"
            )
    else:
        _spacing_check(work, spacing_tol)
        data = np.ascontiguousarray(work)
    return raw, data, rev


def _verdict(rms, noise, extent, *, single, basin_factor, n) -> str:
    floor = 1e-9 * extent
    # the index-paired rms (vertex n to point n, what the fit minimises): it can exceed the
    # geometric max deviation printed beside it, so it is named as what it is
    if math.isnan(noise):
        return (
            f"paired rms {rms:.3g}; {n} points are too few to tell the data's noise from "
            f"its bending (at least {MIN_NOISE_POINTS}): judge the fit by its max deviation"
        )
    if rms <= _AT_NOISE * noise + floor:
        return f"paired rms {rms:.3g} is at the noise level {noise:.3g} of the data"
    ratio = f"{rms / noise:.3g} x " if noise > 0 else "above "
    text = f"paired rms {rms:.3g} is model error, {ratio}the noise level {noise:.3g} of the data"
    if single and rms > basin_factor * noise + floor:
        text += (
            " (a single start was tried: this may be a local minimum in a wrong basin; "
            "the default global search tries several)"
        )
    return text


def _geometric_verdict(rms_dev, level, extent, m) -> str:
    """The verdict of a resampled fit: the input points' distances against their noise.

    `level` is ``sqrt(2)`` times the input's noise per coordinate (a vertex's rms
    displacement, as :func:`_verdict`'s); a point's distance from the curve is the
    displacement across it, of rms ``level / sqrt(2)``.
    """
    across = level / math.sqrt(2.0)
    floor = 1e-9 * extent
    head = f"rms distance {rms_dev:.3g} of the {m} input points from the fit"
    if rms_dev <= _AT_NOISE * across + floor:
        return f"{head} is at their noise level {across:.3g} per coordinate"
    ratio = f"{rms_dev / across:.3g} x " if across > 0 else "above "
    return f"{head} is model error, {ratio}their noise level {across:.3g} per coordinate"


def fit(
    points: ArrayLike,
    *,
    fixed: dict | None = None,
    method: Literal["lsq", "ipopt"] = "lsq",
    start: ArrayLike | None = None,
    resample: bool | float = False,
    spacing_tol: float = SPACING_TOL,
    continuation: str | bool = "auto",
    basin_factor: float = 20.0,
    max_iterations: int | None = None,
    tol: float | None = None,
    tolerance: float | None = None,
) -> FitResult:
    """Fit a discrete elastica to data, minimising eq. (4.8) over ``U`` of eq. (4.7).

    Parameters
    ----------
    points : (N, 2) array_like
        Data ``zeta_n`` in order along the curve, ``N >= 5``, roughly equally spaced
        (vertex ``n`` of the model is matched to data vertex ``n``) unless resampled.
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
        Starting parameters: a single solve from there (no global search).
    resample : bool or float, optional
        If truthy, first drop repeated points and resample the data to equal chords:
        True picks the chord nearest ``max(mean edge, 20 x noise per coordinate)`` that
        ends exactly on the last point (the fit spans the data end to end); a float
        is the chord itself (the walk stops where less than a chord is left). The
        result's ``data`` holds it. The verdict of a resampled fit is geometric: the
        rms distance of the input points from the fit against their noise (the
        resampled points carry less noise, averaged along the chords, and their
        index pairing adds the walk's drift along the curve to the paired rms).
    spacing_tol : float, optional
        Largest allowed :func:`spacing_spread` (``std / mean`` of the edge lengths,
        default 0.25) without resampling; beyond it the index pairing is
        meaningless and a :class:`~curvesmith.errors.CurveError` points to resampling.
    continuation : {"auto", True, False}, optional
        "auto" (default): the global search of the module docstring (coarse-to-fine
        multi-start, degenerate candidates, and the growing-prefix continuation for
        long curves with many loops when the best fit is far above the noise);
        True: the same, the growing-prefix continuation always; False: a single solve
        from the guess of section 4.3, as in the paper.
    basin_factor : float, optional
        An rms above ``basin_factor * noise`` is far above the noise: it triggers the
        growing-prefix continuation (``"auto"``) and, for a single start, the warning
        that the minimum may be in a wrong basin. It does not decide ``success``.
    max_iterations : int, optional
        Limit per solve: function evaluations for lsq (default 5000, for each of
        the two solvers), iterations for IPOPT (default 3000).
    tol : float, optional
        Solver tolerance: ``ftol = xtol = gtol`` for lsq (default 1e-12); IPOPT's
        scaled optimality error ``tol`` (default 1e-8, IPOPT's own default; with
        the variable scaling used here the rms then agrees with lsq to ~1e-12).
    tolerance : float, optional
        Largest acceptable geometric deviation (input point to fitted polyline), in
        data units: sets ``within_tolerance``.

    Returns
    -------
    FitResult
        Parameters, fitted vertices, rms, geometric deviations, iterations, success,
        message, case, start, ...

    Raises
    ------
    CurveError
        Fewer than 5 points, non-finite values, zero-length edges (without
        resampling), uneven spacing without resampling, bad `fixed`/`start`/`method`.

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

    A circular arc and a straight line are discrete elasticae too (degenerate ones):

    >>> t = np.linspace(0.0, 2.0, 40)
    >>> arc = fit(np.column_stack((np.cos(t), np.sin(t))))
    >>> arc.case, bool(arc.max_deviation < 1e-12)
    ('circle', True)
    """
    as_choice(method, _METHODS, name="method")
    if max_iterations is None:
        max_iterations = DEFAULT_MAX_ITERATIONS[method]
    max_iterations = as_int(max_iterations, name="max_iterations", minimum=1)
    if tol is None:
        tol = 1e-12 if method == "lsq" else 1e-8
    tol = as_float(tol, name="tol", low=0.0)
    as_choice(continuation, ("auto", True, False), name="continuation")
    spacing_tol = as_float(spacing_tol, name="spacing_tol", low=0.0)
    basin_factor = as_float(basin_factor, name="basin_factor", low=0.0)
    if tolerance is not None:
        tolerance = as_float(tolerance, name="tolerance", low=0.0)
    pinned = _check_fixed(fixed)
    single = start is not None or continuation is False
    raw, data, rev = _prepare(
        points, resample=resample, spacing_tol=spacing_tol, reverse_ok=not single and not pinned
    )
    n = data.shape[0]
    noise = _noise_level(data)  # the search's thresholds
    level = _measured_noise(data)  # what the verdict compares with, and reports
    extent = float((data.max(axis=0) - data.min(axis=0)).max())
    floor = 1e-9 * extent
    search = _Search(method, max_iterations, tol)
    if single:
        if start is None:
            first = _initial_guess(data)
        else:
            first = _as_params(start)
            _data_curvature(data)  # the same input checks (collinear data) as without a start
        first = ElasticaParams(*[pinned.get(i, v) for i, v in enumerate(first)])
        best = search.solve(data, first, pinned, reduced=False)  # the paper's route
        best["stages"] = 1
        how, closed_form = "", 0
    else:
        best, levels = _global_search(data, pinned, search, _AT_NOISE * noise + floor)
        closed_form = 0 if pinned else 2  # the line and the circle of closed form, first
        how = f"best of {search.tried + closed_form} starts" + (
            f", coarse-to-fine over {len(levels)} levels" if len(levels) > 1 else ""
        )
        seg = _segment_index_length(best["params"])
        long_curve = n > 2 * max(10, 2 * seg)
        far = best["rms"] > basin_factor * noise + floor
        if continuation is True or (far and long_curve):
            try:
                first = ElasticaParams(
                    *[pinned.get(i, v) for i, v in enumerate(_initial_guess(data))]
                )
            except CurveError:
                first = best["params"]
            cont = _continuation(data, first, pinned, search, _segment_index_length(first))
            as_good = cont["rms"] <= best["rms"] * (1 + _CONVERGED_SLACK)
            if cont["rms"] < best["rms"] or (cont["ok"] and not best["ok"] and as_good):
                best = cont
                how += f"; growing-prefix continuation over {cont['stages']} stages"
    params, ok, msg = best["params"], best["ok"], best["msg"]
    if rev:
        params = _reverse_params(params, n)
        best["start"] = _reverse_params(best["start"], n)
        data = data[::-1].copy()
    pts = _positions(params, n)
    if not np.all(np.isfinite(pts)):
        ok, msg = False, "fit produced non-finite vertices"
    dist, rms = _misfit(pts, data)
    deviation = _geom.point_polyline_distance(raw, pts) if ok else np.full(raw.shape[0], np.inf)
    max_dev = float(deviation.max())
    rms_dev = float(np.sqrt(np.mean(deviation**2)))
    within = None if tolerance is None else bool(ok and max_dev <= tolerance)
    resampled = resample is not False and resample is not None
    if resampled and raw.shape[0] >= MIN_NOISE_POINTS:
        # the input's noise, to compare with the input's distances from the fit
        level = math.sqrt(2.0) * _scan_noise(raw)
    if ok:
        parts = [msg, f"converged{'; ' + how if how else ''}"]
        if resampled and raw.shape[0] >= MIN_NOISE_POINTS:
            parts.append(_geometric_verdict(rms_dev, level, extent, raw.shape[0]))
        else:
            parts.append(
                _verdict(rms, level, extent, single=single, basin_factor=basin_factor, n=n)
            )
    else:
        parts = [f"solver did not converge: {msg}"]
    if tolerance is not None and ok:
        word = "within" if within else "exceeds"
        parts.append(f"max deviation {max_dev:.3g} {word} the tolerance {tolerance:g}")
    degenerate = _degenerate.degenerate_case(params)
    return FitResult(
        params=params,
        points=pts,
        rms=rms,
        max_distance=float(dist.max()),
        iterations=int(best["iters"]),
        success=bool(ok),
        message="; ".join(parts),
        case=degenerate or case_of(params.k),
        start=best["start"],
        cost=0.5 * float(dist @ dist),
        noise=level,
        data=data,
        method=method,
        stages=int(best["stages"]),
        max_deviation=max_dev,
        rms_deviation=rms_dev,
        tolerance=tolerance,
        within_tolerance=within,
        total_iterations=search.total,
        starts=search.tried + closed_form,
        deviation=deviation,
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


def _continuation(data, first, pinned, search: _Search, seg):
    """Fit growing prefixes: about two monotone segments first, then x1.6 per stage.

    The first stage starts from the guess of its prefix (then from `first`); each
    later stage from the previous optimum, and also from the guess of its own prefix.
    The better fit is carried on. Returns a candidate dict of :class:`_Search`.
    """
    n = data.shape[0]
    size = int(min(n, max(10, np.ceil(2.0 * min(seg, n)))))
    params = None
    stages = 0
    while True:
        prefix = data[:size]
        order = ("guess", "first") if params is None else ("previous", "guess")
        best: dict[str, Any] | None = None
        for which in order:
            if which == "guess":
                start = _guess_or_none(prefix, pinned)
            else:
                start = first if which == "first" else params
            if start is None:
                continue
            cand = search.solve(prefix, start, pinned, reduced=False)
            if best is None or cand["rms"] < best["rms"]:
                best = cand
        assert best is not None  # "first" or "previous" always starts a solve
        params = best["params"]
        stages += 1
        if size == n:
            best["stages"] = stages
            return best
        size = min(n, int(np.ceil(_GROWTH * size)))
