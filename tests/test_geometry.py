import itertools
import math

import numpy as np
import pytest
from hypothesis import example, given
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from curvesmith import CurveError, curve_length, geometry, signed_area
from curvesmith.internals import signed_area_unchecked


def naive_area(p):
    s = 0.0
    n = len(p)
    for i in range(n):
        x0, y0 = p[i]
        x1, y1 = p[(i + 1) % n]
        s += x0 * y1 - x1 * y0
    return s / 2


def naive_length(p, closed):
    pts = list(p) + ([p[0]] if closed else [])
    return sum(math.dist(a, b) for a, b in itertools.pairwise(pts))


coords = st.floats(-1e3, 1e3, allow_nan=False, allow_infinity=False)
polygons = arrays(np.float64, st.tuples(st.integers(3, 30), st.just(2)), elements=coords)


@given(polygons)
def test_signed_area_matches_plain_loop(p):
    q = p[:-1] if np.array_equal(p[0], p[-1]) else p  # a closing repeat is dropped once
    if len(q) < 3:
        with pytest.raises(CurveError, match="at least 3 distinct ring points"):
            signed_area(p)
        return
    assert signed_area(p) == pytest.approx(naive_area(q), rel=1e-9, abs=1e-6)


@given(polygons, st.booleans())
def test_length_matches_plain_loop(p, closed):
    assert curve_length(p, closed=closed) == pytest.approx(naive_length(p, closed), rel=1e-12)


def test_area_orientation_and_translation_invariance():
    sq = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], float)
    assert signed_area(sq) == 1.0
    assert signed_area(sq[::-1]) == -1.0
    assert geometry.orientation(sq) == 1 and geometry.orientation(sq[::-1]) == -1
    # Far from the origin the shifted shoelace keeps full precision.
    far = sq * 0.001 + 1e7
    assert signed_area(far) == pytest.approx(1e-6, rel=1e-9)


@pytest.mark.parametrize("offset", [(0.0, 0.0), (5e5, 4e6)])
def test_signed_area_of_a_long_ring_to_rounding(offset):
    # Regression: the area as a difference of two dot products lost ~9 digits on long rings
    # (13.5 M vertices: 4e-9 relative; here 2 M vertices: ~1e-10). Coordinates on the 2^-20
    # grid make every product exact, so math.fsum gives the exact area.
    rng = np.random.default_rng(3)
    n = 2_000_000
    t = np.sort(rng.uniform(0.0, 2 * np.pi, n))
    r = 1.0 + 0.05 * rng.normal(size=n)
    p = np.round(np.c_[r * np.cos(t), r * np.sin(t)] * 2.0**20) / 2.0**20
    x, y = p[:, 0], p[:, 1]
    exact = 0.5 * math.fsum(np.concatenate([x * np.roll(y, -1), -np.roll(x, -1) * y]))
    assert signed_area(p + np.array(offset)) == pytest.approx(exact, rel=1e-14)


def test_figure_eight_area_cancels():
    fig8 = [[0, 0], [1, 1], [1, 0], [0, 1]]
    assert signed_area(fig8) == 0.0
    assert geometry.orientation(fig8) == 0


def test_regular_polygon_area_and_turning():
    n = 7
    t = 2 * np.pi * np.arange(n) / n
    p = np.c_[np.cos(t), np.sin(t)]
    assert signed_area(p) == pytest.approx(0.5 * n * math.sin(2 * math.pi / n), rel=1e-14)
    tau = geometry.turning_angles(p, closed=True)
    np.testing.assert_allclose(tau, 2 * np.pi / n, rtol=1e-13)
    ang = geometry.interior_angles(p, closed=True)
    np.testing.assert_allclose(ang, np.pi - 2 * np.pi / n, rtol=1e-13)
    assert geometry.is_convex(p)
    assert not geometry.is_convex(np.r_[p[:3], [[0.0, 0.0]], p[3:]])


def naive_turn(a, b, c):
    # exact rationals: no underflow of the products at 1e-241 (floats gave atan2(0, -0) = pi)
    from fractions import Fraction as F

    u = (F(b[0]) - F(a[0]), F(b[1]) - F(a[1]))
    v = (F(c[0]) - F(b[0]), F(c[1]) - F(b[1]))
    cross, dot = u[0] * v[1] - u[1] * v[0], u[0] * v[0] + u[1] * v[1]
    if cross == 0 and dot == 0:
        return 0.0
    scale = max(abs(cross), abs(dot))
    return math.atan2(float(cross / scale), float(dot / scale))


@given(arrays(np.float64, st.tuples(st.integers(3, 20), st.just(2)), elements=coords))
@example(np.array([[3.61878656e-241, 0.0], [0.0, 3.61878656e-241], [0.0, 0.0]]))  # underflow
@example(np.array([[1e200, 0.0], [0.0, 1e200], [0.0, 0.0]]))  # overflow of the products
@example(np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [0.0, 0.0]]))  # a closing vertex
@example(np.array([[0.0, 0.0], [1.0, 0.0], [0.5, 0.0], [0.0, 0.0], [1.0, 0.0], [0.0, 0.0]]))
def test_turning_angles_match_plain_loop(p):
    # note: edge differences are rounded to floats in the function; for coordinates with
    # no cancellation (these strategies) that rounding changes the angle by ~1e-16
    # the ring convention (_validate.as_points): a last vertex repeating the first is the
    # closing vertex, dropped once; what is left must be >= 3 points, no zero-length edge
    ring = p[:-1] if np.all(p[0] == p[-1]) else p
    if (
        len(ring) < 3
        or np.any(np.all(ring[1:] == ring[:-1], axis=1))
        or np.all(ring[0] == ring[-1])
    ):
        with pytest.raises(CurveError, match="zero-length|distinct ring"):
            geometry.turning_angles(p, closed=True)
        return
    got = geometry.turning_angles(p, closed=True)
    if len(ring) < len(p):  # the closing vertex was dropped: the angles are the ring's
        assert np.array_equal(got, geometry.turning_angles(ring, closed=True))
        p = ring
    n = len(p)
    want = [naive_turn(p[i - 1], p[i], p[(i + 1) % n]) for i in range(n)]

    def wrapped(x, y):  # a full reversal is pi or -pi, by the sign of a zero cross product
        return np.abs(np.angle(np.exp(1j * (np.asarray(x) - np.asarray(y)))))

    assert wrapped(got, want).max() <= 1e-12
    assert wrapped(geometry.turning_angles(p, closed=False), want[1:-1]).max(initial=0) <= 1e-12
    assert np.all(np.abs(got) <= np.pi)


def test_interior_angles_any_dimension():
    p3 = np.array([[0, 0, 0], [1, 0, 0], [1, 0, 1], [1, 1, 1]], float)
    np.testing.assert_allclose(geometry.interior_angles(p3), [np.pi / 2, np.pi / 2])
    straight = [[0, 0], [1, 0], [2, 0]]
    assert geometry.interior_angles(straight)[0] == pytest.approx(np.pi)
    # Spike: tiny angles are accurate (no arccos cancellation).
    spike = [[0, 0], [1, 0], [0, 1e-9]]
    assert geometry.interior_angles(spike)[0] == pytest.approx(1e-9, rel=1e-6)


def test_edges_and_lengths():
    p = [[0, 0], [3, 4], [3, 0]]
    np.testing.assert_array_equal(geometry.edge_vectors(p), [[3, 4], [0, -4]])
    np.testing.assert_array_equal(geometry.edge_lengths(p, closed=True), [5, 4, 3])
    assert curve_length([[0, 0, 0], [1, 2, 2]]) == 3.0


def test_line_intersection_and_parallel_error():
    pt = geometry.line_intersection(
        [[0, 0], [0, 1]], [[1, 0], [1, 0]], [[2, -1], [5, 0]], [[0, 1], [0, 1]]
    )
    np.testing.assert_allclose(pt, [[2, 0], [5, 1]])
    with pytest.raises(CurveError, match="parallel"):
        geometry.line_intersection([0, 0], [1, 1], [1, 0], [2, 2])


def naive_segments_intersect(a0, a1, b0, b1):
    def orient(p, q, r):
        p, q, r = (tuple(float(c) for c in x) for x in (p, q, r))
        v = (q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0])
        return (v > 0) - (v < 0)

    def on_seg(p, q, r):
        return min(p[0], r[0]) <= q[0] <= max(p[0], r[0]) and min(p[1], r[1]) <= q[1] <= max(
            p[1], r[1]
        )

    o1, o2, o3, o4 = orient(a0, a1, b0), orient(a0, a1, b1), orient(b0, b1, a0), orient(b0, b1, a1)
    if o1 != o2 and o3 != o4:
        return True
    return (
        (o1 == 0 and on_seg(a0, b0, a1))
        or (o2 == 0 and on_seg(a0, b1, a1))
        or (o3 == 0 and on_seg(b0, a0, b1))
        or (o4 == 0 and on_seg(b0, a1, b1))
    )


@given(arrays(np.float64, (4, 2), elements=st.integers(-4, 4).map(float)))
def test_segment_intersection_matches_orientation_test(q):
    a0, a1, b0, b1 = q
    hit, pt = geometry.segment_intersection(a0, a1, b0, b1)
    assert bool(hit) == naive_segments_intersect(a0, a1, b0, b1)
    if hit:
        # The reported point lies on both segments.
        for s0, s1 in ((a0, a1), (b0, b1)):
            d = s1 - s0
            assert abs(geometry.det2(d, pt - s0)) <= 1e-9
            lo, hi = np.minimum(s0, s1) - 1e-9, np.maximum(s0, s1) + 1e-9
            assert np.all(pt >= lo) and np.all(pt <= hi)


def test_menger_curvature_circle_and_sign():
    t = np.linspace(0, 2 * np.pi, 50, endpoint=False)
    circle = np.c_[3 * np.cos(t), 3 * np.sin(t)]
    np.testing.assert_allclose(geometry.menger_curvature(circle, closed=True), 1 / 3, rtol=1e-12)
    np.testing.assert_allclose(
        geometry.menger_curvature(circle[::-1], closed=True), -1 / 3, rtol=1e-12
    )
    assert geometry.menger_curvature([[0, 0], [1, 0], [2, 0]])[0] == 0.0


@pytest.mark.parametrize(
    ("fn", "arg", "match"),
    [
        (signed_area, [[0, 0], [1, 1]], "at least 3"),
        (signed_area, [[0, 0], [1, 1], [2, np.nan]], "finite"),
        (curve_length, [[0, 0]], "at least 2"),
        (geometry.turning_angles, [[0, 0], [0, 0], [1, 1]], "zero-length"),
        (signed_area, np.zeros((5, 3)), r"shape \(N, 2\)"),
    ],
)
def test_bad_input(fn, arg, match):
    with pytest.raises(CurveError, match=match):
        fn(arg)


def test_resample_rules_on_a_curve_that_comes_back_near_itself():
    # A loop whose end comes back within the step of its start: the paper's rule (closest
    # to the right end) short-cuts to the end, the walk follows the loop.
    t = np.linspace(0, 1.95 * np.pi, 400)
    loop = np.c_[np.cos(t), np.sin(t)]
    walk = geometry.resample_equilateral(loop, 0.3, rule="walk")
    paper = geometry.resample_equilateral(loop, 0.3, rule="paper")
    for out in (walk, paper):
        np.testing.assert_allclose(np.linalg.norm(np.diff(out, axis=0), axis=1), 0.3, rtol=1e-12)
    assert len(walk) >= 19  # about 1.9 pi / 0.3 chords around the loop
    assert len(paper) < len(walk) / 2  # jumped across the gap to the other end
    with pytest.raises(CurveError, match="rule must be one of 'paper', 'walk', got 'x'"):
        geometry.resample_equilateral(loop, 0.3, rule="x")


def test_private_ring_area_of_nothing_is_zero():
    # io and geo call the private helper on rings they build; an empty one has no area
    assert signed_area_unchecked(np.zeros((0, 2))) == 0.0
    assert signed_area_unchecked(np.ones((1, 2))) == 0.0


@pytest.mark.parametrize("block", [7, 1 << 12])
def test_orientation_is_the_exact_sign(monkeypatch, block):
    """Random, huge, tiny and nearly degenerate rings, one block and many: the exact sign."""
    from oracles import exact_area_sign

    monkeypatch.setattr(geometry, "ORIENTATION_BLOCK", block)
    rng = np.random.default_rng(block)
    for scale in (1e-300, 1e-8, 1.0, 6e6, 1e300):
        for _ in range(20):
            n = int(rng.integers(3, 60))
            ring = rng.normal(size=(n, 2)) * scale
            assert geometry.orientation(ring) == exact_area_sign(ring)
    # a sliver whose float shoelace sum is dominated by round-off: only exact arithmetic decides
    base = np.array([[0.0, 0.0], [1e8, 1.0], [2e8, 2.0 + 2**-25], [1e8 + 0.5, 1.0]])
    for ring in (base, base[::-1], base + np.array([7e5, 5e6])):
        assert geometry.orientation(ring) == exact_area_sign(ring) != 0
    assert geometry.orientation([[0, 0], [1, 1], [2, 2], [3, 3]]) == 0
