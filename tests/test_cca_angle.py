"""The profile's interior angle: fdlibm's atan in numpy and compiled, the same bits, < 1.6 ulp."""

import math
from itertools import pairwise

import mpmath
import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from curvesmith.internals import cca_angle, cca_kernel


def _ulp_error(got: np.ndarray, y: np.ndarray, d: np.ndarray) -> np.ndarray:
    """|got - atan2(y, -d)| in ulps of the exact value (mpmath at 120 bits)."""
    mpmath.mp.prec = 120
    out = np.zeros(got.size)
    for k, (g, p, q) in enumerate(zip(got, y, d, strict=True)):
        exact = mpmath.atan2(mpmath.mpf(float(p)), -mpmath.mpf(float(q)))
        if exact != 0:
            out[k] = abs(float((mpmath.mpf(float(g)) - exact) / math.ulp(float(exact))))
    return out


def _sample(seed: int, n: int) -> tuple[np.ndarray, np.ndarray]:
    # |cross| and dot of unit vectors (every range of the reduction), near pi (smooth
    # curves), near 0 (spikes), and scaled pairs over the whole exponent range
    rng = np.random.default_rng(seed)
    y = np.abs(rng.standard_normal(4 * n))
    d = rng.standard_normal(4 * n)
    nrm = np.hypot(y, d)
    y, d = y / nrm, d / nrm
    phi = np.abs(rng.normal(0.0, 1e-2, n))
    y[n : 2 * n], d[n : 2 * n] = np.sin(phi), np.cos(phi)  # turn phi: angle pi - phi
    y[2 * n : 3 * n], d[2 * n : 3 * n] = np.sin(phi), -np.cos(phi)
    y[3 * n :] *= 10.0 ** rng.uniform(-150, 150, n)
    d[3 * n :] *= 10.0 ** rng.uniform(-150, 150, n)
    return y, d


def test_interior_angle_is_within_1_6_ulp_of_the_exact_angle():
    y, d = _sample(3, 1500)
    err = _ulp_error(cca_angle.interior_angle(y, d), y, d)
    assert err.max() < 1.2
    assert np.median(err) < 0.35
    # the angles of smooth curves (near pi) are rounded as a correct rounding would be
    # but for the last ulp's half
    assert err[1500:3000].max() < 0.51
    # the worst case: a sharp angle just below a power of two, its ratio |cross| / |dot|
    # just above it (the ratio's rounding is then up to one ulp of the angle; a reviewer's
    # find: 1.51 ulp at the first pair)
    rng = np.random.default_rng(4)
    th = np.ldexp(1.0 - rng.uniform(0, 1e-3, 600), rng.integers(-12, 1, 600))
    y = np.r_[0.12415253443286078, np.sin(th)]
    d = np.r_[-0.9922631446314517, -np.cos(th)]
    err = _ulp_error(cca_angle.interior_angle(y, d), y, d)
    assert err[0] > 1.5 and err.max() < 1.6


def test_interior_angle_edge_cases_match_atan2():
    # dot = 0, zero cross, subnormal and huge ratios, exact right angles
    y = np.array([0.0, 0.0, 0.0, 1.0, 1e-320, 1.0, 1.0, 1e-300, 1e300, 1.0, 0.5])
    d = np.array([0.0, 1.0, -1.0, 0.0, 1.0, 1e-320, -1e-320, -1e300, 1e-300, 1.0, -0.5])
    got = cca_angle.interior_angle(y, d)
    ref = np.array([math.atan2(p, -q) for p, q in zip(y, d, strict=True)])
    np.testing.assert_array_max_ulp(got, ref, maxulp=1)
    assert got[0] == math.pi and got[3] == 0.5 * math.pi  # atan2(+0, -0), atan2(1, 0)
    nan_y, nan_d = np.array([np.nan, 1.0, np.nan]), np.array([1.0, np.nan, 0.0])
    assert np.isnan(cca_angle.interior_angle(nan_y, nan_d)).all()
    assert all(np.isnan(cca_kernel.interior_angle(p, q)) for p, q in zip(nan_y, nan_d, strict=True))


finite = st.floats(0.0, 1e300, allow_nan=False, allow_infinity=False, allow_subnormal=True)
signed = st.floats(-1e300, 1e300, allow_nan=False, allow_infinity=False, allow_subnormal=True)


def test_compiled_interior_angle_gives_the_numpy_bits_in_every_range():
    y, d = _sample(5, 20_000)
    t = y / np.abs(d)
    # every range of the reduction is well sampled (the tiny and huge ones by the ratios)
    bounds = [2.0**-27, 0.4375, 0.6875, 1.1875, 2.4375, 2.0**66]
    assert all(np.count_nonzero((t >= lo) & (t < hi)) > 500 for lo, hi in pairwise(bounds))
    got = np.array([cca_kernel.interior_angle(p, q) for p, q in zip(y, d, strict=True)])
    np.testing.assert_array_equal(got, cca_angle.interior_angle(y, d))


@given(st.lists(st.tuples(finite, signed), min_size=1, max_size=40))
def test_compiled_interior_angle_gives_the_numpy_bits(pairs):
    y = np.array([p for p, _ in pairs])
    d = np.array([q for _, q in pairs])
    ref = cca_angle.interior_angle(y, d)
    got = np.array([cca_kernel.interior_angle(p, q) for p, q in pairs])
    np.testing.assert_array_equal(got, ref)


@pytest.mark.parametrize("t", [0.0, 2.0**-27, 0.4375, 0.6875, 1.1875, 2.4375, 2.0**66, np.inf])
def test_atan_at_the_reduction_bounds(t):
    # each bound and its neighbours fall on the range fdlibm assigns them
    for x in (np.nextafter(t, -np.inf) if t > 0 else t, t, np.nextafter(t, np.inf)):
        got = float(cca_angle.atan_nonneg(np.array([x]))[0])
        assert got == cca_kernel.interior_angle(x, -1.0)
        if np.isfinite(x):
            np.testing.assert_array_max_ulp(got, math.atan(x), maxulp=1)
