"""alpha-profiles of CCA1 (Gordon 2010, section 4, Table 1, eq. (4)-(5)).

``alpha`` is a float in (0, 1/3), a callable of the interior angle (radians, in
[0, pi]) returning values in [0, 1/3), or ``"regular"``: the PCHIP profile of
Table 1 (see the package notes of :mod:`curvesmith.cca`). The compiled 2D
kernel evaluates the regular profile from the same breakpoints and
coefficients (:func:`profile_tables`) by the same Horner scheme, so both give
the same bits.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from functools import lru_cache

import numpy as np
from numpy.typing import ArrayLike

from .._validate import as_float, as_int
from ..errors import CurveError

#: Limit of eq. (5) as the half-angle tends to pi/2: root of 8 a^2 + 4 a - 1 = 0.
LIMIT_ALPHA: float = (math.sqrt(3.0) - 1.0) / 4.0


def _triangle_alpha() -> float:
    # (3 sqrt3 - 4) a^2 + (6 - 3 sqrt3) a + sqrt3 - 2 = 0, positive root (section 4).
    s3 = math.sqrt(3.0)
    qa, qb, qc = 3.0 * s3 - 4.0, 6.0 - 3.0 * s3, s3 - 2.0
    return (2.0 * qc) / (-qb - math.sqrt(qb * qb - 4.0 * qa * qc))


#: alpha for the equilateral triangle (9-gon of aspect ratio 1), section 4: ~0.24443.
TRIANGLE_ALPHA: float = _triangle_alpha()


def solve_regular_alpha(beta: ArrayLike):
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


def alpha_profile(angle: ArrayLike):
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


def alpha_function(alpha) -> Callable[[np.ndarray], np.ndarray]:
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


def profile_tables() -> tuple[np.ndarray, np.ndarray]:
    """Breakpoints ``(7,)`` and Horner coefficients ``(4, 6)`` of the regular profile."""
    brk, coef = _profile_poly()
    return np.ascontiguousarray(brk), np.ascontiguousarray(coef)
