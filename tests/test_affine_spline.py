"""Uniform B-splines of control polylines (Käferböck, section 2.5, Theorem 4), Bézier and SVG."""

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from curvesmith import affine
from curvesmith.errors import CurveError, CurveFormatError
from curvesmith.io.svg import quadratic_path_data, read_quadratic_path


def naive_basis(j, k, t):
    """B_j^k(t) on integer knots by the recursion printed in the proof of Theorem 4."""
    if k == 0:
        return 1.0 if j <= t < j + 1 else 0.0
    return (t - j) / k * naive_basis(j, k - 1, t) + (j + k + 1 - t) / k * naive_basis(
        j + 1, k - 1, t
    )


def aal_polyline(k, area=0.5):
    k = np.asarray(k, dtype=float)
    return affine.reconstruct(
        np.full(k.size + 1, area), area * (2.0 - k), [[0, 0], [1, 0], [2, area]]
    )


def aal_polyline_3d(count, det_value, rng):
    """Polyline in R^3 with det(dx_i, dx_{i+1}, dx_{i+2}) = det_value for all i (eq. 9)."""
    v = [np.array([1.0, 0.0, 0.0]), np.array([0.3, 1.0, 0.0])]
    while len(v) < count - 1:
        w = rng.normal(size=3)
        normal = np.cross(v[-2], v[-1])
        w += (det_value - normal @ w) / (normal @ normal) * normal
        v.append(w)
    return np.concatenate([[np.zeros(3)], np.cumsum(v, axis=0)])


@pytest.mark.parametrize("degree", [2, 3])
def test_bspline_matches_naive_recursion(degree):
    rng = np.random.default_rng(degree)
    x = rng.normal(size=(7, 2))
    s = affine.bspline(x, degree=degree)
    for t in np.linspace(s.t[degree], s.t[-degree - 1] - 1e-9, 13):
        ref = sum(naive_basis(i, degree, t) * x[i] for i in range(len(x)))
        np.testing.assert_allclose(s(t), ref, atol=1e-12)


def test_quadratic_segments_match_section_2_5_parametrisation():
    # p_1(t) = x_1 - (1-t)^2/2 v_0 + t^2/2 v_1 on the first segment
    x = np.array([[0, 0], [2, 0], [3, 2], [2, 4]], float)
    s = affine.bspline(x)
    seg = affine.bezier_segments(x)
    v0, v1 = x[1] - x[0], x[2] - x[1]
    for t in np.linspace(0, 1, 5):
        p1 = x[1] - (1 - t) ** 2 / 2 * v0 + t**2 / 2 * v1
        np.testing.assert_allclose(s(2 + min(t, 1 - 1e-15)), p1, atol=1e-12)
        bez = (1 - t) ** 2 * seg[0, 0] + 2 * t * (1 - t) * seg[0, 1] + t**2 * seg[0, 2]
        np.testing.assert_allclose(bez, p1, atol=1e-12)


def test_closed_bspline_is_periodic():
    t = np.arange(6) * np.pi / 3
    x = np.c_[np.cos(t), np.sin(t)]
    s = affine.bspline(x, closed=True)
    a, b = s.t[2], s.t[-3]
    assert b - a == 6
    np.testing.assert_allclose(s(a), s(b - 1e-12), atol=1e-9)
    assert affine.bezier_segments(x, closed=True).shape == (6, 3, 2)


def test_g2_iff_affine_arc_length_control_polygon():
    x = aal_polyline([0.3, -0.2, 0.5, 0.1, 0.6])
    left, right = affine.joint_curvatures(x)
    assert left.size == x.shape[0] - 3
    np.testing.assert_allclose(left, right, rtol=1e-10)
    # curvature at the joint is A |v_i|^-3 from both sides (section 2.5)
    v = np.diff(x, axis=0)
    np.testing.assert_allclose(left, 0.5 / np.linalg.norm(v[1:-1], axis=1) ** 3, rtol=1e-10)
    y = x.copy()
    y[3] += [0.05, -0.02]  # breaks A_2 = A_3 = A_4
    a, _ = affine.coordinates(y)
    left, right = affine.joint_curvatures(y)
    jumps = np.abs(left - right) > 1e-6
    np.testing.assert_array_equal(jumps, np.abs(a[:-1] - a[1:]) > 1e-9)


@given(st.integers(0, 10_000))
def test_g2_joint_curvature_ratio_is_area_ratio(seed):
    rng = np.random.default_rng(seed)
    ang = np.cumsum(rng.uniform(0.2, 0.6, 8))
    x = np.c_[np.cos(ang), np.sin(ang)] * rng.uniform(1, 3, (8, 1))
    a, _ = affine.coordinates(x)
    left, right = affine.joint_curvatures(x)
    np.testing.assert_allclose(left / right, a[:-1] / a[1:], rtol=1e-8)


def test_theorem4_torsion_continuous_iff_equal_volumes_in_r3():
    rng = np.random.default_rng(7)
    x = aal_polyline_3d(9, 0.8, rng)
    assert affine.is_affine_arc_length(x, rtol=1e-10)
    left, right = affine.joint_curvatures(x, degree=3)
    np.testing.assert_allclose(left, right, rtol=1e-9)
    y = x + rng.normal(scale=0.05, size=x.shape)
    left, right = affine.joint_curvatures(y, degree=3)
    assert np.min(np.abs(left - right) / np.abs(right)) > 1e-4
    # the first Frenet curvature is continuous for any control polygon (C^2 cubic)
    s = affine.bspline(y, degree=3)
    d1, d2 = s.derivative(1), s.derivative(2)
    for t in np.arange(4, 7):
        k_lo = (
            np.linalg.norm(np.cross(d1(t - 1e-9), d2(t - 1e-9))) / np.linalg.norm(d1(t - 1e-9)) ** 3
        )
        k_hi = np.linalg.norm(np.cross(d1(t), d2(t))) / np.linalg.norm(d1(t)) ** 3
        assert k_lo == pytest.approx(k_hi, rel=1e-6)


def test_theorem4_torsion_formula_matches_classical_torsion():
    rng = np.random.default_rng(8)
    x = rng.normal(size=(6, 3))
    _, right = affine.joint_curvatures(x, degree=3)
    s = affine.bspline(x, degree=3)
    d = [s.derivative(k) for k in (1, 2, 3)]
    t = 4.0
    f1, f2, f3 = (dk(t) for dk in d)
    tau = np.linalg.det(np.array([f1, f2, f3])) / np.linalg.norm(np.cross(f1, f2)) ** 2
    assert right[0] == pytest.approx(tau, rel=1e-10)


def test_theorem4_in_r4():
    rng = np.random.default_rng(9)
    v = [np.eye(4)[i] + 0.1 * rng.normal(size=4) for i in range(3)]
    while len(v) < 9:
        m = np.array(v[-3:])
        cof = np.array(
            [np.linalg.det(np.vstack([m, np.eye(4)[i]])) for i in range(4)]
        )  # det([m; w]) = cof @ w
        w = rng.normal(size=4)
        w += (1.0 - cof @ w) / (cof @ cof) * cof
        v.append(w)
    x = np.concatenate([[np.zeros(4)], np.cumsum(v, axis=0)])
    assert affine.is_affine_arc_length(x, rtol=1e-8)
    left, right = affine.joint_curvatures(x, degree=4)
    np.testing.assert_allclose(left, right, rtol=1e-7)


def test_bezier_segments_and_svg_round_trip(tmp_path):
    x = aal_polyline([0.3, 0.5, 0.1, 0.4])
    d = quadratic_path_data(x)
    assert d.startswith("M ") and d.count("Q") == x.shape[0] - 2
    back, closed = read_quadratic_path(d)
    assert not closed
    np.testing.assert_allclose(back, x, atol=1e-13)
    f = tmp_path / "s.svg"
    f.write_text(f'<svg xmlns="http://www.w3.org/2000/svg"><path d="{d}"/></svg>', encoding="utf-8")
    back, _ = read_quadratic_path(f)
    np.testing.assert_allclose(back, x, atol=1e-12)
    t = np.arange(7) * 2 * np.pi / 7
    ring = np.c_[np.cos(t), 2 * np.sin(t)]
    dc = quadratic_path_data(ring, closed=True)
    assert dc.endswith("Z")
    back, closed = read_quadratic_path(dc)
    assert closed
    np.testing.assert_allclose(back, ring, atol=1e-13)


def test_svg_read_rejects_non_bspline_paths():
    with pytest.raises(CurveFormatError, match="quadratic Bezier"):
        read_quadratic_path("M 0 0 L 1 1")
    with pytest.raises(CurveFormatError, match="not a uniform quadratic B-spline"):
        read_quadratic_path("M 0 0 Q 1 0 1 1 Q 5 5 6 6")


def test_spline_curvature_matches_formula_on_segments():
    x = np.array([[0, 0], [1, 0], [2, 1], [3, 3]], float)
    t, k = affine.spline_curvature(x, per_segment=5)
    s = affine.bspline(x)
    d1, d2 = s.derivative(1), s.derivative(2)
    inner = (t > s.t[2]) & (t < s.t[-3]) & (np.abs(t - np.round(t)) > 1e-9)
    a, b = d1(t[inner]), d2(t[inner])
    ref = (a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]) / np.linalg.norm(a, axis=1) ** 3
    np.testing.assert_allclose(k[inner], ref, rtol=1e-12)


def test_spline_errors():
    with pytest.raises(CurveError, match="degree must be an integer >= 1"):
        affine.bspline([[0, 0], [1, 1]], degree=0)
    with pytest.raises(CurveError, match="at least 4 points"):
        affine.joint_curvatures([[0, 0], [1, 0], [1, 1]])
