"""Jacobi elliptic functions for every real parameter, and their parameter derivative.

``scipy.special.ellipj`` covers ``0 <= m <= 1`` only (nan outside) and, for
``1 - 1e-9 < m < 1``, switches to a first-order expansion about ``m = 1`` that is
wrong once the argument approaches the quarter period (at ``m = 1 - 1e-10``,
``u = 30`` it returns ``sn`` off by 1e2; measured against mpmath at 40 digits).
This module wraps it with

* the reciprocal-modulus transformation (DLMF 22.17.2-4) for ``m > 1``:
  ``sn(u|m) = sn(sqrt(m) u | 1/m) / sqrt(m)``, ``cn(u|m) = dn(sqrt(m) u | 1/m)``,
  ``dn(u|m) = cn(sqrt(m) u | 1/m)``;
* the negative-parameter transformation (DLMF 22.17.6-8) for ``m < 0``;
* its own arithmetic-geometric-mean (descending Landen) evaluation for
  ``1 - 1e-9 <= m < 1``, and the exact ``tanh``/``sech`` forms at ``m = 1``.

The parameter derivative of the amplitude uses the identity, derived here and
checked against finite differences in the tests,

    d am(u|m) / dm = -dn(u|m) / 2 * I(u|m),   I(u|m) = int_0^u sd(t|m)^2 dt,

which is regular at ``m = 0`` and ``m = 1`` (the textbook form with
``E(am u|m) / (m (1-m))`` cancels catastrophically at both ends). ``I`` is
evaluated as ``(u - D(am u|m) - sn cd) / (1 - m)`` with Legendre's ``D``
integral in Carlson form (no cancellation at ``m -> 0``).
"""

from __future__ import annotations

import numpy as np
from scipy.special import ellipj as _scipy_ellipj
from scipy.special import elliprd

__all__ = ["amplitude_dm", "ellipj", "ellipj_am", "sd2_integral"]

#: Below ``1 - m`` of this size scipy's expansion branch is replaced by the AGM.
_AGM_BAND = 1e-9


def sech(x):
    """``1 / cosh(x)`` without overflow for large ``|x|``."""
    e = np.exp(-np.abs(x))
    return 2.0 * e / (1.0 + e * e)


def _agm_ellipj(u: np.ndarray, m: np.ndarray):
    """Jacobi functions by the arithmetic-geometric mean (Abramowitz & Stegun 16.4), 0 < m < 1."""
    a = np.ones_like(m)
    b = np.sqrt(1.0 - m)
    c = np.sqrt(m)
    cs = [c]
    as_ = [a]
    for _ in range(40):
        if np.all(np.abs(c) <= 1e-17 * np.abs(a)):
            break
        a, b, c = 0.5 * (a + b), np.sqrt(a * b), 0.5 * (a - b)
        as_.append(a)
        cs.append(c)
    n = len(as_) - 1
    phi = (2.0**n) * as_[-1] * u
    for j in range(n, 0, -1):
        phi = 0.5 * (phi + np.arcsin(np.clip(cs[j] / as_[j] * np.sin(phi), -1.0, 1.0)))
    sn = np.sin(phi)
    cn = np.cos(phi)
    dn = np.sqrt(cn * cn + (1.0 - m) * sn * sn)
    return sn, cn, dn, phi


def _ellipj_unit(u: np.ndarray, m: np.ndarray):
    """Jacobi functions for 0 <= m <= 1 with the guard near m = 1."""
    sn, cn, dn, ph = _scipy_ellipj(u, m)
    band = (m >= 1.0 - _AGM_BAND) & (m < 1.0)
    if np.any(band):
        ub, mb = np.broadcast_to(u, sn.shape)[band], np.broadcast_to(m, sn.shape)[band]
        sn[band], cn[band], dn[band], ph[band] = _agm_ellipj(ub, mb)
    one = m == 1.0
    if np.any(one):
        u1 = np.broadcast_to(u, sn.shape)[one]
        sn[one] = np.tanh(u1)
        cn[one] = dn[one] = sech(u1)
        ph[one] = 2.0 * np.arctan(np.tanh(0.5 * u1))  # Gudermannian
    return sn, cn, dn, ph


def ellipj(u, m):
    """Jacobi ``sn, cn, dn`` for real argument and any real parameter ``m = k**2``.

    Parameters
    ----------
    u : array_like
        Argument.
    m : array_like
        Parameter (square of the modulus); any real value, broadcast with `u`.

    Returns
    -------
    sn, cn, dn : ndarray
        The three functions, broadcast shape of `u` and `m`.

    Examples
    --------
    >>> sn, cn, dn = ellipj(0.5, 4.0)   # modulus 2, via the reciprocal modulus
    >>> round(float(sn), 12), round(float(cn), 12), round(float(dn), 12)
    (0.411317789065, 0.911492005669, 0.568568998095)
    """
    u, m = np.broadcast_arrays(np.asarray(u, dtype=float), np.asarray(m, dtype=float))
    u = np.array(u)
    m = np.array(m)
    sn = np.empty_like(u)
    cn = np.empty_like(u)
    dn = np.empty_like(u)
    unit = (m >= 0.0) & (m <= 1.0)
    if np.any(unit):
        sn[unit], cn[unit], dn[unit], _ = _ellipj_unit(u[unit], m[unit])
    big = m > 1.0
    if np.any(big):
        k = np.sqrt(m[big])
        s, c, d, _ = _ellipj_unit(k * u[big], 1.0 / m[big])
        sn[big], cn[big], dn[big] = s / k, d, c
    neg = m < 0.0
    if np.any(neg):
        # DLMF 22.17.6-8 with mu = -m / (1 - m) in [0, 1).
        mm = m[neg]
        root = np.sqrt(1.0 - mm)
        s, c, d, _ = _ellipj_unit(root * u[neg], -mm / (1.0 - mm))
        sn[neg], cn[neg], dn[neg] = s / (root * d), c / d, 1.0 / d
    return sn, cn, dn


def ellipj_am(u, m):
    """``sn, cn, dn, am`` for ``0 <= m <= 1`` (guarded near 1), arrays broadcast.

    Parameters
    ----------
    u, m : array_like
        Argument and parameter, ``0 <= m <= 1``.

    Returns
    -------
    sn, cn, dn, am : ndarray
        Jacobi functions and the amplitude.
    """
    u, m = np.broadcast_arrays(np.asarray(u, dtype=float), np.asarray(m, dtype=float))
    return _ellipj_unit(np.array(u), np.array(m))


def _legendre_d(phi: np.ndarray, m) -> np.ndarray:
    """Legendre's ``D(phi|m) = int_0^phi sin^2 / sqrt(1 - m sin^2)``, any real phi, 0 <= m < 1."""
    j = np.round(phi / np.pi)
    r = phi - j * np.pi
    s = np.sin(r)
    c = np.cos(r)
    part = s**3 * elliprd(c * c, 1.0 - m * s * s, 1.0) / 3.0
    if np.ndim(m) == 0:
        return part + (2.0 / 3.0) * float(elliprd(0.0, 1.0 - m, 1.0)) * j
    return part + (2.0 / 3.0) * elliprd(0.0, 1.0 - m, 1.0) * j


def sd2_integral(u, m) -> np.ndarray:
    """``I(u|m) = int_0^u sd(t|m)^2 dt`` for ``0 <= m < 1``.

    Parameters
    ----------
    u : array_like
        Upper limit.
    m : array_like
        Parameter, ``0 <= m < 1`` (closer to 1 the evaluation loses about
        ``log10(1 / (1 - m))`` digits; callers use a difference quotient there).

    Returns
    -------
    ndarray
        The integral, by ``(u - D(am u|m) - sn cd) / (1 - m)``.

    Examples
    --------
    >>> round(float(sd2_integral(1.0, 0.0)), 10)   # int_0^1 sin^2 = 1/2 - sin(2)/4
    0.2726756433
    """
    u, m = np.broadcast_arrays(np.asarray(u, dtype=float), np.asarray(m, dtype=float))
    return _sd2_integral(u, m, *_scipy_ellipj(u, m))


def _sd2_integral(u, m, sn, cn, dn, ph):
    """``I(u|m)`` from precomputed ``sn, cn, dn, am`` (scipy values, 0 <= m < 1 - 1e-9)."""
    return (u - _legendre_d(ph, m) - sn * cn / dn) / (1.0 - m)


def amplitude_dm(u, m) -> np.ndarray:
    """Parameter derivative ``d am(u|m) / dm = -dn(u|m) I(u|m) / 2`` for ``0 <= m < 1``.

    Parameters
    ----------
    u : array_like
        Argument.
    m : array_like
        Parameter, ``0 <= m < 1``.

    Returns
    -------
    ndarray
        The derivative at fixed `u`.

    Examples
    --------
    >>> round(float(amplitude_dm(1.0, 0.0)), 12)   # -(u/2 - sin(2u)/4)/2 at m = 0
    -0.136337821647
    """
    u, m = np.broadcast_arrays(np.asarray(u, dtype=float), np.asarray(m, dtype=float))
    _, _, dn, _ = _scipy_ellipj(u, m)
    return -0.5 * dn * sd2_integral(u, m)
