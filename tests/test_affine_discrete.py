"""Discrete affine geometry (Käferböck, sections 2-3): coordinates, lengths, curvature, conics."""

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from scipy.optimize import brentq

from curvesmith import affine
from curvesmith.errors import CurveError
from curvesmith.subdivision import chaikin, lane_riesenfeld
from oracles import det


def naive_coordinates(x):
    v = [x[i + 1] - x[i] for i in range(len(x) - 1)]
    a = [det(v[i - 1], v[i]) for i in range(1, len(v))]
    b = [det(v[i - 1], v[i + 1]) for i in range(1, len(v) - 1)]
    return np.array(a), np.array(b)


def random_convex_polyline(rng, n=12):
    """Points on a random convex spiral-ish arc (all A_i > 0)."""
    ang = np.cumsum(rng.uniform(0.1, 0.4, n))
    rad = rng.uniform(1.0, 2.0) * np.exp(np.cumsum(rng.uniform(-0.05, 0.05, n)))
    return np.c_[rad * np.cos(ang), rad * np.sin(ang)]


def aal_from_curvatures(k, area=0.3, start=None):
    """Affine arc length polyline with prescribed k_i via eq. (2) with B_i = A (2 - k_i)."""
    k = np.asarray(k, dtype=float)
    if start is None:
        start = np.array([[0.0, 0.0], [1.0, 0.0], [2.0, area]])
    a = np.full(k.size + 1, area)
    b = area * (2.0 - k)
    return affine.reconstruct(a, b, start)


# ---------------------------------------------------------------- conic constructions (Theorem 1)

CONICS = {
    "ellipse": (lambda th: np.array([3.0 * np.cos(th), 1.2 * np.sin(th)]), 0.0),
    "parabola": (lambda th: np.array([th, 0.7 * th**2]), -1.5),
    "hyperbola": (lambda th: np.array([0.8 * np.sinh(th), 2.0 * np.cosh(th)]), -1.0),
}


def construct_on_curve(f, th0, th1, area, count):
    """x_i = f(th_i) with det(x_{i-1} - x_{i-2}, x_i - x_{i-1}) = A, each root found by brentq."""
    ths = [th0, th1]
    xs = [f(th0), f(th1)]
    for _ in range(count - 2):
        w, xp, tp = xs[-1] - xs[-2], xs[-1], ths[-1]

        def g(th, w=w, xp=xp):
            return det(w, f(th) - xp) - area

        hi = tp + 1e-3
        while g(hi) < 0:
            hi = tp + 2 * (hi - tp)
        th = brentq(g, tp + 1e-12, hi, xtol=1e-15, rtol=1e-15)
        ths.append(th)
        xs.append(f(th))
    return np.array(xs)


@pytest.mark.parametrize("name", list(CONICS))
def test_theorem1_regular_discretisation_has_constant_curvature(name):
    f, th0 = CONICS[name]
    step = 0.15
    regular = np.array([f(th0 + i * step) for i in range(12)])
    a, _ = affine.coordinates(regular)
    assert np.ptp(a) <= 1e-12 * abs(a[0])  # affinely regular => affine arc length polyline
    k = affine.curvature(regular)
    assert np.ptp(k) < 1e-11
    expected = {
        "ellipse": 2 * (1 - math.cos(step)),
        "parabola": 0.0,
        "hyperbola": 2 * (1 - math.cosh(step)),
    }
    assert k[0] == pytest.approx(expected[name], abs=1e-12)


@pytest.mark.parametrize("name", list(CONICS))
@pytest.mark.parametrize("factor", [0.8, 0.93, 1.1])
def test_theorem1_curvatures_alternate_on_a_conic(name, factor):
    f, th0 = CONICS[name]
    step = 0.15
    x = [f(th0), f(th0 + step), f(th0 + 2 * step)]
    area = det(x[1] - x[0], x[2] - x[1])
    poly = construct_on_curve(f, th0, th0 + factor * step, area, 12)
    assert affine.is_affine_arc_length(poly, rtol=1e-9)
    k = affine.curvature(poly, rtol=1e-9)
    assert np.max(np.abs(k[2:] - k[:-2])) < 1e-8  # k_{i-1} = k_{i+1}
    assert abs(k[1] - k[0]) > 1e-3  # ... but not constant: not affinely regular


def conic_residual(points):
    """Relative smallest singular value of the 6x6 conic system: 0 iff the points share a conic."""
    p = (points - points.mean(axis=0)) / np.abs(points - points.mean(axis=0)).max()
    rows = np.c_[p[:, 0] ** 2, p[:, 0] * p[:, 1], p[:, 1] ** 2, p[:, 0], p[:, 1], np.ones(len(p))]
    s = np.linalg.svd(rows, compute_uv=False)
    return s[-1] / s[0]


def test_theorem1_converse_six_points_on_conic_iff_alternating():
    alternating = aal_from_curvatures([0.3, 0.5, 0.3, 0.5, 0.3])
    assert conic_residual(alternating[:6]) < 1e-12
    assert conic_residual(alternating[1:7]) < 1e-12
    broken = aal_from_curvatures([0.3, 0.5, 0.3, 0.55, 0.3])
    assert conic_residual(broken[:6]) < 1e-12  # k_1 = k_3
    assert conic_residual(broken[1:7]) > 1e-4  # k_2 != k_4


# ---------------------------------------------------------------- coordinates, reconstruction


def test_coordinates_match_naive_reference():
    rng = np.random.default_rng(3)
    x = rng.normal(size=(9, 2))
    a, b = affine.coordinates(x)
    na, nb = naive_coordinates(list(x))
    np.testing.assert_allclose(a, na, rtol=1e-14, atol=1e-14)
    np.testing.assert_allclose(b, nb, rtol=1e-14, atol=1e-14)


def test_coordinates_closed_are_cyclic():
    rng = np.random.default_rng(4)
    x = rng.normal(size=(7, 2))
    a, b = affine.coordinates(x, closed=True)
    ext = np.concatenate([x[-1:], x, x[:2]])  # x_{-1} .. x_{N+1}
    na, nb = naive_coordinates(list(ext))
    np.testing.assert_allclose(a, na[:7], atol=1e-13)
    np.testing.assert_allclose(b, nb[:7], atol=1e-13)


@given(st.integers(0, 10_000), st.floats(-2, 2), st.floats(0.2, 3))
def test_coordinates_equiaffine_invariant(seed, shear, stretch):
    rng = np.random.default_rng(seed)
    x = rng.normal(size=(8, 2))
    m = np.array([[stretch, shear], [0.0, 1.0 / stretch]])  # det 1
    y = x @ m.T + rng.normal(size=2)
    for u, v in zip(affine.coordinates(x), affine.coordinates(y), strict=True):
        np.testing.assert_allclose(u, v, atol=1e-9 * (1 + np.abs(u).max()))


@given(st.integers(0, 10_000))
def test_reconstruct_round_trip(seed):
    rng = np.random.default_rng(seed)
    x = random_convex_polyline(rng, 10)
    a, b = affine.coordinates(x)
    y = affine.reconstruct(a, b, x[:3])
    np.testing.assert_allclose(y, x, atol=1e-8 * np.abs(x).max())


def test_reconstruct_works_when_b_vanishes():
    # eq. (2) is solved for v_{i+1}: needs A_i != 0, not B_i != 0 as printed
    x = np.array([[0, 0], [1, 0], [1, 1], [0, 1], [-1, 0.5]], float)
    a, b = affine.coordinates(x)
    assert b[0] == 0.0
    np.testing.assert_allclose(affine.reconstruct(a, b, x[:3]), x, atol=1e-14)


def test_reconstruct_rejects_bad_input():
    with pytest.raises(CurveError, match="B must have len"):
        affine.reconstruct([1, 1, 1], [1], [[0, 0], [1, 0], [2, 1]])
    with pytest.raises(CurveError, match="A must be non-zero"):
        affine.reconstruct([1, 0], [1], [[0, 0], [1, 0], [2, 1]])
    with pytest.raises(CurveError, match="A_1 = 2"):
        affine.reconstruct([2, 1], [1], [[0, 0], [1, 0], [2, 1]])


# ---------------------------------------------------------------- lengths


def test_affine_length_l2_is_sum_of_cube_roots():
    x = np.array([[0, 0], [1, 0], [2, 1], [2, 9], [0, 12]], float)
    a, _ = affine.coordinates(x)
    assert affine.affine_length(x) == pytest.approx(np.sum(np.cbrt(a)), rel=1e-14)
    np.testing.assert_allclose(affine.affine_length_elements(x), np.cbrt(a), rtol=1e-14)


def test_affine_length_ln_in_r3_matches_definition():
    rng = np.random.default_rng(5)
    x = rng.normal(size=(7, 3))
    v = np.diff(x, axis=0)
    ref = [np.linalg.det(v[i : i + 3]) for i in range(len(v) - 2)]
    ref = np.sign(ref) * np.abs(ref) ** (1 / 6)
    np.testing.assert_allclose(affine.affine_length_elements(x), ref, rtol=1e-12)


def test_affine_length_of_sampled_parabola_equals_smooth_length():
    # (t, t^2): det(f', f'') = 2, smooth affine length over [0, T] is 2^(1/3) T
    t = np.linspace(0, 3, 31)
    x = np.c_[t, t**2]
    # L_2 counts N - 1 elements of length (2 h^3)^(1/3) = 2^(1/3) h
    assert affine.affine_length(x) == pytest.approx(2 ** (1 / 3) * 0.1 * 29, rel=1e-12)


def test_is_affine_arc_length_detects_constant_area():
    t = np.arange(8.0)
    assert affine.is_affine_arc_length(np.c_[t, t**2])
    y = np.c_[t, t**2]
    y[4, 1] += 1e-3
    assert not affine.is_affine_arc_length(y)
    assert affine.is_affine_arc_length(y, rtol=1e-2)


# ---------------------------------------------------------------- Chaikin and Lane-Riesenfeld


@given(st.integers(0, 10_000), st.integers(4, 15))
def test_chaikin_keeps_affine_length(seed, n):
    rng = np.random.default_rng(seed)
    x = rng.normal(size=(n, 2))
    y = chaikin(x, closed=False)
    assert y.shape[0] == 2 * (n - 1)  # x'_0 .. x'_{2N-1}
    assert affine.affine_length(y) == pytest.approx(affine.affine_length(x), rel=1e-9, abs=1e-12)
    # every A_i becomes two areas A_i / 8 (Fig. 7)
    a, _ = affine.coordinates(x)
    a2, _ = affine.coordinates(y)
    np.testing.assert_allclose(a2[0::2], a / 8, atol=1e-12)
    np.testing.assert_allclose(a2[1::2], a / 8, atol=1e-12)


def test_chaikin_maps_affine_arc_length_polyline_to_one_with_a_over_8():
    x = aal_from_curvatures([0.2, 0.4, -0.1, 0.3, 0.6, 0.1], area=0.5)
    y = chaikin(x, closed=False, iterations=2)
    assert affine.is_affine_arc_length(y, rtol=1e-10)
    a, _ = affine.coordinates(y)
    assert a[0] == pytest.approx(0.5 / 64, rel=1e-12)


@pytest.mark.parametrize("n", [2, 3, 4])
def test_theorem5_lane_riesenfeld_halves_ln(n):
    rng = np.random.default_rng(10 + n)
    x = rng.normal(size=(n + 5, n))
    y = lane_riesenfeld(x, degree=n)
    # Theorem 5 prints x'_0 .. x'_{N+1}; the doubled sequence has 2N + 2 entries and
    # mu^n removes n of them: 2N + 2 - n vertices for N + 1 input vertices
    big_n = x.shape[0] - 1
    assert y.shape[0] == 2 * big_n + 2 - n
    lx = affine.affine_length_elements(x)
    ly = affine.affine_length_elements(y)
    assert ly.size == 2 * lx.size
    np.testing.assert_allclose(ly[0::2], lx / 2, rtol=1e-9)  # eq. (10), every element
    np.testing.assert_allclose(ly[1::2], lx / 2, rtol=1e-9)
    assert affine.affine_length(y) == pytest.approx(affine.affine_length(x), rel=1e-9)


# ---------------------------------------------------------------- curvature, normals, evolute


def test_curvature_three_characterisations_agree():
    k_true = np.array([0.3, -0.2, 0.5, 0.1, 0.0, 0.8, 0.4])
    x = aal_from_curvatures(k_true, area=0.7)
    k = affine.curvature(x)
    np.testing.assert_allclose(k, k_true, atol=1e-12)
    n = affine.normals(x)  # n[j] = n_{j+1}
    a = 0.7
    for j in range(k.size):
        i = j + 1
        lhs = x[i + 2] - x[i - 1]
        np.testing.assert_allclose(lhs, (3 - k[j]) * (x[i + 1] - x[i]), atol=1e-12)  # first form
        assert det(n[j], n[j + 1]) / a == pytest.approx(k[j], abs=1e-12)  # second form
        d3 = x[i + 2] - 3 * x[i + 1] + 3 * x[i] - x[i - 1]  # definition d^3 x_{i-1} + k dx_i = 0
        np.testing.assert_allclose(d3 + k[j] * (x[i + 1] - x[i]), 0, atol=1e-12)


def test_curvature_rejects_non_affine_arc_length():
    with pytest.raises(CurveError, match="affine arc length polyline"):
        affine.curvature([[0, 0], [1, 0], [2, 1], [2, 5], [0, 7]])


def test_evolute_is_intersection_of_consecutive_normals():
    x = aal_from_curvatures([0.3, 0.5, -0.4, 0.2], area=0.4)
    xi = affine.evolute(x)
    n = affine.normals(x)
    k = affine.curvature(x)
    for j in range(xi.shape[0]):
        np.testing.assert_allclose(
            xi[j], x[j + 2] + n[j + 1] / k[j], atol=1e-11
        )  # second form of (5)
        # on both normal lines
        assert abs(det(xi[j] - x[j + 1], n[j])) < 1e-11
        assert abs(det(xi[j] - x[j + 2], n[j + 1])) < 1e-11


def test_evolute_of_affinely_regular_polygon_is_centre_and_parabola_raises():
    t = np.arange(9) * 2 * np.pi / 9
    xi = affine.evolute(np.c_[1 + 3 * np.cos(t), -2 + np.sin(t)], closed=True)
    np.testing.assert_allclose(xi, np.tile([1.0, -2.0], (9, 1)), atol=1e-12)
    s = np.arange(6.0)
    with pytest.raises(CurveError, match="at infinity"):
        affine.evolute(np.c_[s, s**2])


# ---------------------------------------------------------------- osculating conics (Theorem 2)


@pytest.mark.parametrize("k_values", [[0.3, 0.5, 0.2], [-0.4, -0.6, -0.3], [0.6, -0.5, 0.4]])
def test_theorem2_conic_curvatures_match_eq7(k_values):
    x = aal_from_curvatures(k_values, area=0.25)
    ko, ki, km = affine.osculating_curvatures(x)
    for j in range(len(k_values)):
        outer = affine.osculating_conic(x, j, kind="outer")
        inner = affine.osculating_conic(x, j, kind="inner")
        middle = affine.osculating_conic(x, j, kind="middle")
        assert outer.affine_curvature == pytest.approx(ko[j], rel=1e-8)
        assert inner.affine_curvature == pytest.approx(ki[j], rel=1e-8)
        assert middle.affine_curvature == pytest.approx(km[j], rel=1e-8)
        kind = "ellipse" if k_values[j] > 0 else "hyperbola"  # eq. (6)
        assert outer.kind == inner.kind == middle.kind == kind
        np.testing.assert_allclose(outer.centre, affine.evolute(x)[j], atol=1e-9)
        # outer passes through the four vertices, inner touches the edges at their midpoints
        quad = x[j : j + 4]
        scale = np.abs(outer.matrix).max() * np.abs(quad).max() ** 2
        assert np.abs(outer.evaluate(quad)).max() < 1e-10 * scale
        mids = 0.5 * (quad[:-1] + quad[1:])
        assert np.abs(inner.evaluate(mids)).max() < 1e-10 * scale


def test_theorem2_parabolic_quadruple():
    s = np.arange(5.0)
    x = np.c_[s, 0.5 * s**2]  # A = 2 lambda = 1, k = 0
    outer = affine.osculating_conic(x, 0, kind="outer")
    inner = affine.osculating_conic(x, 0, kind="inner")
    middle = affine.osculating_conic(x, 0, kind="middle")
    assert outer.kind == inner.kind == middle.kind == "parabola"
    assert outer.affine_curvature == inner.affine_curvature == middle.affine_curvature == 0.0
    # the inner parabola is the outer one translated by A/8 along the axis (proof of Theorem 2)
    probe = np.c_[np.linspace(0, 3, 4), 0.5 * np.linspace(0, 3, 4) ** 2]
    assert np.abs(outer.evaluate(probe)).max() < 1e-12
    assert np.abs(inner.evaluate(probe + np.array([0, 1 / 8]))).max() < 1e-12
    assert np.abs(middle.evaluate(probe + np.array([0, 1 / 16]))).max() < 1e-12


def test_conic_sample_points_lie_on_conic():
    x = aal_from_curvatures([0.3, -0.5, 0.2], area=0.25)
    for j in range(3):
        c = affine.osculating_conic(x, j, kind="middle")
        pts = c.sample(np.linspace(-1, 1, 7))
        assert np.abs(c.evaluate(pts)).max() < 1e-9
    s = np.arange(5.0)
    c = affine.osculating_conic(np.c_[s, s**2], 0, kind="outer")
    assert np.abs(c.evaluate(c.sample(np.linspace(-2, 2, 5)))).max() < 1e-9


def test_conic_ellipse_curvature_on_inscribed_regular_polygon():
    # on an ellipse the outer osculating conic of an affinely regular polygon is the ellipse itself
    t = np.arange(12) * np.pi / 6
    x = np.c_[2.5 * np.cos(t), 0.8 * np.sin(t)]
    ko, _, _ = affine.osculating_curvatures(x, closed=True)
    np.testing.assert_allclose(ko, (2.5 * 0.8) ** (-2 / 3), rtol=1e-12)


def test_osculating_conic_rejects_bad_arguments():
    s = np.arange(6.0)
    x = np.c_[s, s**2]
    with pytest.raises(CurveError, match="kind must be"):
        affine.osculating_conic(x, 0, kind="best")
    with pytest.raises(CurveError, match="index must be an integer in"):
        affine.osculating_conic(x, 3)


@pytest.mark.parametrize("n", [2, 3])
def test_theorem5_closed_polygon_keeps_ln(n):
    rng = np.random.default_rng(20 + n)
    x = rng.normal(size=(9, n))
    y = lane_riesenfeld(x, degree=n, closed=True)
    assert y.shape[0] == 18
    total = affine.affine_length(x, closed=True)
    assert affine.affine_length(y, closed=True) == pytest.approx(total, rel=1e-9)
