import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays
from scipy.interpolate import BSpline
from scipy.spatial import ConvexHull, cKDTree

from curvesmith import CurveError, geometry, signed_area, subdivision
from curvesmith.subdivision import chaikin, de_rham, lane_riesenfeld


def naive_de_rham(p, gamma, closed):
    """Merrien section 2, written as a plain loop over sides."""
    beta = 1 / (gamma + 2)
    alpha = 1 - beta
    n = len(p)
    sides = range(n) if closed else range(n - 1)
    out = []
    for i in sides:
        a, b = p[i], p[(i + 1) % n]
        out.append([alpha * a[k] + beta * b[k] for k in range(len(a))])
        out.append([beta * a[k] + alpha * b[k] for k in range(len(a))])
    return np.array(out)


def test_postgis_reference_triangle():
    # ST_ChaikinSmoothing documentation: closed triangle, one iteration, area 64 -> 52.
    tri = [[0, 0], [8, 8], [0, 16], [0, 0]]
    out = chaikin(tri, closed=True)
    np.testing.assert_array_equal(out, [[2, 2], [6, 6], [6, 10], [2, 14], [0, 12], [0, 4]])
    assert signed_area(tri) == 64.0 and signed_area(out) == 52.0


@given(
    arrays(
        np.float64, st.tuples(st.integers(3, 12), st.integers(1, 4)), elements=st.floats(-100, 100)
    ),
    st.floats(1.0001, 50),
    st.booleans(),
)
def test_de_rham_matches_plain_loop(p, gamma, closed):
    q = p[:-1] if closed and np.array_equal(p[0], p[-1]) else p  # closing repeat dropped once
    if len(q) < 3 and closed:
        with pytest.raises(CurveError, match="at least 3 distinct ring points"):
            de_rham(p, gamma=gamma, closed=closed)
        return
    got = de_rham(p, gamma=gamma, closed=closed)
    np.testing.assert_allclose(got, naive_de_rham(q, gamma, closed), rtol=1e-13, atol=1e-12)
    assert len(got) == (2 * len(q) if closed else 2 * (len(q) - 1))


def test_de_rham_ratio_one_gamma_one():
    # Each side is cut into parts proportional to 1 : gamma : 1.
    out = de_rham([[0, 0], [10, 0]], gamma=3.0)
    np.testing.assert_allclose(out, [[2, 0], [8, 0]])
    assert np.allclose(
        chaikin([[0, 0], [4, 0], [4, 4]], closed=False), de_rham([[0, 0], [4, 0], [4, 4]], gamma=2)
    )


def test_iterations_and_counts():
    p = np.random.default_rng(1).normal(size=(5, 2))
    assert chaikin(p, closed=True, iterations=0).shape == (5, 2)
    assert chaikin(p, closed=True, iterations=3).shape == (40, 2)
    assert chaikin(p, closed=False, iterations=2).shape == (2 * (2 * 4 - 1), 2)
    kept = chaikin(p, closed=False, iterations=2, preserve_endpoints=True)
    np.testing.assert_array_equal(kept[[0, -1]], p[[0, -1]])
    np.testing.assert_allclose(
        chaikin(p, closed=True, iterations=2), chaikin(chaikin(p, closed=True), closed=True)
    )


def test_any_dimension_and_input_untouched():
    p = np.random.default_rng(2).normal(size=(6, 3))
    before = p.copy()
    out = de_rham(p, gamma=4.0, closed=True, iterations=2)
    assert out.shape == (24, 3)
    np.testing.assert_array_equal(p, before)
    # Planar input embedded in 3D gives the 2D result in the first two coordinates.
    q = np.c_[p[:, :2], np.zeros(6)]
    np.testing.assert_allclose(
        de_rham(q, gamma=4.0, closed=True)[:, :2], de_rham(p[:, :2], gamma=4.0, closed=True)
    )


def convex_polygons():
    return (
        arrays(np.float64, st.tuples(st.integers(3, 40), st.just(2)), elements=st.floats(-50, 50))
        .map(lambda pts: pts[ConvexHull(pts).vertices] if _hull_ok(pts) else None)
        .filter(lambda v: v is not None and len(v) >= 3 and geometry.is_convex(v))
    )


def _hull_ok(pts):
    try:
        return ConvexHull(pts).volume > 1e-3
    except Exception:
        return False


@given(convex_polygons(), st.floats(1.05, 30), st.integers(1, 4))
def test_closed_convex_stays_convex_and_inside(poly, gamma, its):
    out = de_rham(poly, gamma=gamma, closed=True, iterations=its)
    assert geometry.is_convex(out)
    # Inside the input: on the left of every CCW edge (ConvexHull returns CCW vertices).
    e = np.roll(poly, -1, axis=0) - poly
    side = geometry.det2(e[None, :, :], out[:, None, :] - poly[None, :, :])
    scale = np.abs(poly).max()
    assert np.all(side >= -1e-9 * scale * scale)
    assert abs(signed_area(out)) <= abs(signed_area(poly)) * (1 + 1e-12)


def test_lane_riesenfeld_output_counts_theorem5():
    # Theorem 5 prints x'_0 .. x'_{N+1}; mu^n of the doubled sequence (2N + 2 entries)
    # has 2N + 2 - n.
    p = np.random.default_rng(3).normal(size=(7, 2))  # N = 6
    for n in range(1, 8):
        assert lane_riesenfeld(p, degree=n).shape == (2 * 6 + 2 - n, 2)
        assert lane_riesenfeld(p, degree=n, closed=True).shape == (14, 2)


def naive_lr(p, n):
    q = [v for v in p for _ in range(2)]
    for _ in range(n):
        q = [(q[i] + q[i + 1]) / 2 for i in range(len(q) - 1)]
    return np.array(q)


@pytest.mark.parametrize("degree", [1, 2, 3, 4, 5])
def test_lane_riesenfeld_matches_plain_definition(degree):
    p = np.random.default_rng(degree).normal(size=(6, 3))
    np.testing.assert_allclose(lane_riesenfeld(p, degree=degree), naive_lr(p, degree), rtol=1e-14)
    # Closed: away from the seam the cyclic and open steps agree index for index.
    closed = lane_riesenfeld(p, degree=degree, closed=True)
    opened = naive_lr(p, degree)
    np.testing.assert_allclose(
        closed[: len(opened) - degree], opened[: len(opened) - degree], rtol=1e-14
    )
    assert np.allclose(lane_riesenfeld(p, degree=2, closed=True), chaikin(p, closed=True))


@given(st.integers(1, 5), st.integers(0, 10_000))
def test_lane_riesenfeld_halves_affine_length(n, seed):
    # Kaeferboeck eq. (10): L_n of the first/second n+1 new vertices is half of L_n of x_0..x_n,
    # i.e. the determinant of n consecutive edges scales by 2^{-n(n+1)/2}.
    x = np.random.default_rng(seed).normal(size=(n + 1, n))
    d0 = np.linalg.det(np.diff(x, axis=0))
    xp = lane_riesenfeld(x, degree=n)
    factor = 2.0 ** (-n * (n + 1) / 2)
    for start in (0, 1):
        d1 = np.linalg.det(np.diff(xp[start : start + n + 1], axis=0))
        assert d1 == pytest.approx(factor * d0, rel=1e-9, abs=1e-12 * abs(d0) + 1e-15)
    if d0 > 0:
        L = d0 ** (2 / (n * (n + 1)))
        L1 = np.linalg.det(np.diff(xp[: n + 1], axis=0)) ** (2 / (n * (n + 1)))
        assert pytest.approx(L / 2, rel=1e-9) == L1


@pytest.mark.parametrize("degree", [2, 3, 4])
def test_lane_riesenfeld_converges_to_uniform_bspline(degree):
    ctrl = np.random.default_rng(7).normal(size=(12, 2))
    refined = lane_riesenfeld(ctrl, degree=degree, iterations=9)
    spline = BSpline(np.arange(len(ctrl) + degree + 1, dtype=float), ctrl, degree)
    u = np.linspace(degree, len(ctrl), 200_001)
    curve = spline(u)
    # Every refined vertex is close to the limit curve (distance ~ 4^-iterations).
    d, _ = cKDTree(curve).query(refined)
    core = slice(2**9, -(2**9))
    assert d[core].max() < 2e-4


@pytest.mark.parametrize(
    ("call", "match"),
    [
        (lambda: de_rham([[0, 0], [1, 1]], gamma=1.0), "gamma must be > 1, got 1"),
        (lambda: de_rham([[0, 0], [1, 1]], gamma=0.5), "gamma must be > 1, got 0.5"),
        (
            lambda: chaikin([[0, 0], [1, 1]], closed=False, iterations=-1),
            "iterations must be an integer >= 0, got -1",
        ),
        (
            lambda: lane_riesenfeld([[0, 0], [1, 1]], degree=0),
            "degree must be an integer >= 1, got 0",
        ),
        (lambda: chaikin([[0, 0], [1, np.nan]], closed=False), "finite"),
        (lambda: chaikin([1, 2, 3], closed=False), "shape"),
        (lambda: chaikin([[0, 0], [1, 1]], closed=True), "at least 3 distinct ring points, got 2"),
        (lambda: chaikin([[0, 0]], closed=False), "at least 2 points, got 1"),
        (lambda: lane_riesenfeld([[0, 0], [1, 1]], degree=7), "degree 7"),
    ],
)
def test_bad_input(call, match):
    with pytest.raises(CurveError, match=match):
        call()


def test_duplicate_points_are_tolerated_by_linear_schemes():
    # Linear corner cutting needs no directions: a consecutive duplicate is a zero-length side
    # whose two cut points coincide with it.
    p = np.array([[0, 0], [1, 0], [1, 0], [1, 1]], float)
    out = chaikin(p, closed=False)
    np.testing.assert_array_equal(out, naive_de_rham(p, 2.0, closed=False))
    np.testing.assert_array_equal(out[2:4], [[1, 0], [1, 0]])


@pytest.mark.parametrize(
    "call",
    [
        lambda: subdivision.chaikin([[0, 0], [1, 1], [2, 0]], closed=False, iterations=40),
        lambda: subdivision.de_rham(
            [[0, 0], [1, 0], [0, 1]], gamma=3.0, closed=True, iterations=30
        ),
        lambda: subdivision.lane_riesenfeld(
            [[0, 0], [1, 1], [2, 0], [3, 1]], degree=3, iterations=27
        ),
    ],
)
def test_runaway_iterations_raise_instead_of_exhausting_memory(call):
    # Regression: `curvesmith smooth --iterations 40` allocated until the machine ran out of
    # memory (3 * 2**40 vertices).
    with pytest.raises(CurveError, match=r"iterations must be small enough .* got (40|30|27)"):
        call()


def test_vertex_limit_is_exact(monkeypatch):
    monkeypatch.setattr(subdivision, "MAX_VERTICES", 24)
    tri = [[0, 0], [1, 0], [0, 1]]
    assert chaikin(tri, closed=True, iterations=3).shape == (24, 2)
    with pytest.raises(CurveError, match="at most 24 output vertices, got 4 .step 4 alone"):
        chaikin(tri, closed=True, iterations=4)
    # open, ends kept: 3 -> 6 -> 12 -> 24; Lane-Riesenfeld degree 3 open: 4 -> 5 -> 7 -> 11 -> 19
    assert chaikin(tri, closed=False, iterations=3, preserve_endpoints=True).shape == (24, 2)
    quad = [[0, 0], [1, 1], [2, 0], [3, 1]]
    assert lane_riesenfeld(quad, degree=3, iterations=3).shape == (11, 2)
    with pytest.raises(CurveError, match="got 5 .step 5 alone would give 35"):
        lane_riesenfeld(quad, degree=3, iterations=5)
    # a 2-point open line does not grow, so many steps are fine
    assert chaikin([[0, 0], [1, 1]], closed=False, iterations=100).shape == (2, 2)


@pytest.mark.parametrize(
    ("n", "degree", "iterations", "shape", "message"),
    [
        (2, 2, 5, (2, 2), None),
        (3, 3, 4, (3, 2), None),
        (3, 4, 1, (2, 2), None),
        (2, 3, 1, None, "at least 3 points for an open Lane-Riesenfeld step of degree 3, got 2"),
        (3, 5, 1, None, "at least 4 points .* degree 5, got 3"),
        (3, 4, 2, None, "iterations must be at most 1 for an open polyline of 3 points"),
    ],
)
def test_open_lane_riesenfeld_never_returns_fewer_than_two_points(
    n, degree, iterations, shape, message
):
    # Regression: an open step leaves 2 n - degree vertices (the docstring said 2 n + 2 -
    # degree), so 2 points of degree 3 gave 1 point and further steps an empty array.
    pts = [[float(i), float(i * i)] for i in range(n)]
    if message is None:
        assert lane_riesenfeld(pts, degree=degree, iterations=iterations).shape == shape
    else:
        with pytest.raises(CurveError, match=message):
            lane_riesenfeld(pts, degree=degree, iterations=iterations)


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (lambda p: chaikin(p.T, closed=False), r"got \(2, 5\): 5 points with 2 coordinates"),
        (lambda p: de_rham(p.T, gamma=3.0, closed=True), r"look transposed \(pass points.T\)"),
        (lambda p: lane_riesenfeld(p.T, degree=3), r"got \(2, 5\)"),
        (lambda p: chaikin(p, closed=None), "closed must be True or False, got None"),
        (lambda p: chaikin(p, closed="yes"), "closed must be True or False, got 'yes'"),
        (
            lambda p: chaikin(p, closed=False, preserve_endpoints="no"),
            "preserve_endpoints must be True or False, got 'no'",
        ),
        (
            lambda p: lane_riesenfeld(p, degree=2, preserve_endpoints=0),
            "preserve_endpoints must be True or False, got 0",
        ),
    ],
)
def test_api_misuse_is_refused_with_the_argument_and_value(call, message):
    # Regression: a (2, N) array was smoothed as 2 points in N dimensions, closed=None was
    # taken as open, and preserve_endpoints="no" kept the end points (a truthy string).
    p = np.array([[0, 0], [1, 2], [2, 0], [3, 1], [4, 0]], dtype=float)
    with pytest.raises(CurveError, match=message):
        call(p)


def test_accepted_input_forms_agree():
    # lists of tuples, integer arrays, numpy bools and a repeated closing vertex
    ref = chaikin(np.array([[0.0, 0.0], [4.0, 0.0], [4.0, 4.0]]), closed=True, iterations=2)
    for pts, closed in [
        ([(0, 0), (4, 0), (4, 4)], True),
        (np.array([[0, 0], [4, 0], [4, 4]], dtype=np.int32), np.bool_(True)),
        ([[0, 0], [4, 0], [4, 4], [0, 0]], True),
    ]:
        assert np.array_equal(chaikin(pts, closed=closed, iterations=2), ref)
    # 2 points in 3D and 4 points in 5D are genuine rows, not transposed arrays
    assert chaikin([[0, 0, 0], [1, 1, 1]], closed=False).shape == (2, 3)
    assert lane_riesenfeld(np.eye(5)[:4], degree=2).shape == (6, 5)
