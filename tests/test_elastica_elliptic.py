"""Guarded Jacobi elliptic functions against mpmath at 40 digits (reference computed here)."""

import mpmath as mp
import numpy as np
import pytest
from scipy.special import ellipj as scipy_ellipj

from curvesmith.internals import amplitude_dm, ellipj, ellipj_am, sd2_integral

mp.mp.dps = 40

ARGS = [0.1, 1.0, 3.0, 7.0, 15.0, 30.0, -4.0]
PARAMS = [-3.0, -0.5, 0.0, 1e-12, 0.3, 0.9, 1 - 1e-6, 1 - 1e-10, 1 - 1e-12, 1 - 1e-15, 1.0]
PARAMS += [1 + 1e-12, 1 + 1e-6, 1.5, 4.0, 100.0]


def reference(u, m):
    return [mp.ellipfun(f, u, m=mp.mpf(m)) for f in ("sn", "cn", "dn")]


@pytest.mark.parametrize("m", PARAMS)
def test_ellipj_matches_mpmath_for_every_parameter(m):
    u = np.array(ARGS)
    got = ellipj(u, m)
    for j, uj in enumerate(ARGS):
        ref = reference(uj, m)
        # absolute accuracy; the AGM phase error grows like eps |u|. Near m = 1 the functions
        # are ill-conditioned in m itself (d sn/dm ~ e^|u| / 8, so one rounding of m costs
        # ~1e-11 at u = 15), whence the looser bound there.
        tol = 1e-13 * max(1.0, abs(uj)) if abs(1 - m) > 1e-9 or m == 1 else 1e-11
        tol = tol if abs(1 - m) > 1e-3 or abs(uj) < 10 else max(tol, 1e-11)
        for g, r in zip(got, ref, strict=True):
            assert abs(g[j] - float(mp.re(r))) < tol, (m, uj)


def test_guard_is_needed_near_one():
    """scipy's m -> 1 expansion branch is far off at u = 30, m = 1 - 1e-10; the guard is not."""
    m, u = 1 - 1e-10, 30.0
    ref = float(reference(u, m)[0])
    assert abs(scipy_ellipj(u, m)[0] - ref) > 1.0
    assert abs(ellipj(u, m)[0] - ref) < 1e-12


def test_ellipj_broadcasts_mixed_parameters():
    u = np.array([0.5, 0.5, 0.5, 0.5])
    m = np.array([-1.0, 0.5, 1.0, 3.0])
    sn, cn, dn = ellipj(u, m)
    for j in range(4):
        ref = reference(0.5, m[j])
        np.testing.assert_allclose(
            [sn[j], cn[j], dn[j]], [float(mp.re(r)) for r in ref], atol=1e-15
        )
    np.testing.assert_allclose(sn * sn + cn * cn, 1.0, atol=1e-15)
    np.testing.assert_allclose(dn * dn + m * sn * sn, 1.0, atol=1e-14)


@pytest.mark.parametrize("m", [0.0, 0.2, 1 - 1e-10, 1.0])
def test_amplitude(m):
    u = np.array([0.3, 2.0, 9.0])
    sn, cn, dn, am = ellipj_am(u, m)
    np.testing.assert_allclose(np.sin(am), sn, atol=1e-13)
    np.testing.assert_allclose(np.cos(am), cn, atol=1e-13)
    if m < 1:
        for uj, aj, dj in zip(u, am, dn, strict=True):
            # F(am u) = u; dF/dphi = 1/dn amplifies the rounding of am near m = 1
            assert abs(float(mp.ellipf(aj, m)) - uj) < 1e-13 * max(1.0, uj) / dj


def mp_amplitude_dm(u, m):
    def am(mm):
        return mp.findroot(lambda ph: mp.ellipf(ph, mm) - u, u)

    return float(mp.diff(am, mp.mpf(m)))


@pytest.mark.parametrize("m", [1e-8, 0.3, 0.9, 0.999, 1 - 1e-5])
@pytest.mark.parametrize("u", [0.5, 2.0, 9.0, -3.0])
def test_amplitude_derivative_in_m(m, u):
    """d am / dm = -dn I / 2 with I = int_0^u sd^2: regular at both ends, against mpmath."""
    ref = mp_amplitude_dm(u, m)
    got = float(amplitude_dm(u, m))
    tol = 1e-12 * max(1.0, abs(ref)) / min(1.0, 1e3 * (1 - m))
    assert abs(got - ref) < tol


def test_sd2_integral_at_zero_parameter_is_sin_squared():
    u = np.linspace(-7, 7, 29)
    np.testing.assert_allclose(sd2_integral(u, 0.0), u / 2 - np.sin(2 * u) / 4, atol=1e-14)


def test_separatrix_large_arguments_do_not_overflow():
    """m = 1: sn = tanh, cn = dn = sech, evaluated without overflow (RuntimeWarning is an error)."""
    sn, cn, dn = ellipj(np.array([800.0, -900.0, 0.5]), 1.0)
    np.testing.assert_allclose(sn, [1.0, -1.0, np.tanh(0.5)], rtol=1e-15)
    np.testing.assert_allclose(cn, [0.0, 0.0, 1 / np.cosh(0.5)], rtol=1e-15, atol=1e-300)
    np.testing.assert_array_equal(cn, dn)
