"""Tests of curvesmith.keyline (section 5 of Graiff Zurita, Kajiwara & Suzuki)."""

import itertools
import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from curvesmith import keyline, signed_area
from curvesmith.errors import CurveError


def rot2(a):
    return np.array([[math.cos(a), -math.sin(a)], [math.sin(a), math.cos(a)]])


def random_rotation3(rng):
    q, r = np.linalg.qr(rng.standard_normal((3, 3)))
    q = q * np.sign(np.diag(r))
    if np.linalg.det(q) < 0:
        q[:, 0] = -q[:, 0]
    return q


def dist_to_polyline(x, poly):
    """Plain reference: distance of each point of x to the polyline (loop over segments)."""
    best = np.full(len(x), np.inf)
    for a, b in itertools.pairwise(poly):
        d = b - a
        dd = float(d @ d)
        t = np.zeros(len(x)) if dd == 0 else np.clip((x - a) @ d / dd, 0.0, 1.0)
        best = np.minimum(best, np.linalg.norm(x - (a + t[:, None] * d), axis=1))
    return best


def naive_resample(poly, r):
    """Plain reference of the paper's rule: every circle/segment intersection, largest arc length
    beyond the current point wins; none -> stop."""
    s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(poly, axis=0), axis=1))])
    out, c, tc = [poly[0]], poly[0], 0.0
    while True:
        best = None
        for j in range(len(poly) - 1):
            a, d = poly[j], poly[j + 1] - poly[j]
            dd = float(d @ d)
            if dd == 0:
                continue
            w = a - c
            bq, cq = float(w @ d), float(w @ w) - r * r
            disc = bq * bq - dd * cq
            if disc < 0:
                continue
            for u in ((-bq - math.sqrt(disc)) / dd, (-bq + math.sqrt(disc)) / dd):
                if -1e-12 <= u <= 1 + 1e-12:
                    u = min(max(u, 0.0), 1.0)
                    t = s[j] + u * math.sqrt(dd)
                    if t > tc + 1e-9 * r and (best is None or t > best[0]):
                        best = (t, a + u * d)
        if best is None:
            return np.array(out)
        tc, c = best
        out.append(c)


# ------------------------------------------------------------------ resampling


def test_resample_zigzag_takes_the_cut_closest_to_the_right_end():
    # the circle of radius 1.5 around (0, 0) cuts this switchback three times:
    # (1.5, 0), (sqrt(1.25), 1) and (0.5, sqrt(2)); Fig. 12 takes the last one along the line.
    poly = np.array([[0.0, 0.0], [2.0, 0.0], [2.0, 1.0], [0.5, 1.0], [0.5, 2.0]])
    out = keyline.resample_equilateral(poly, 1.5)
    # from (0.5, sqrt 2) only the way back is at distance 1.5: stop point (Fig. 13)
    np.testing.assert_allclose(out, [[0.0, 0.0], [0.5, math.sqrt(2.0)]], atol=1e-15)


def test_resample_zigzag_several_steps_matches_hand_values():
    # a zig-zag of unit-slope teeth; the circle of radius 1.5 around each vertex cuts the
    # rising and the falling edge of a tooth: the cut farther along the line wins (Fig. 12)
    poly = np.array([[0, 0], [1, 1], [2, 0], [3, 1], [4, 0], [5, 1]], dtype=float)
    out = keyline.resample_equilateral(poly, 1.5)
    np.testing.assert_allclose(np.linalg.norm(np.diff(out, axis=0), axis=1), 1.5, atol=1e-14)
    np.testing.assert_allclose(out, naive_resample(poly, 1.5), atol=1e-13)
    # first step: x^2 + y^2 = 2.25 cuts (0,0)-(1,1) at x = 1.5/sqrt2 (arc 1.5) and
    # (1,1)-(2,0), y = 2 - x, at x^2 - 2x + 0.875 = 0, x = 1 + sqrt(0.125) (arc 1.91): take it
    x = 1.0 + math.sqrt(0.125)
    np.testing.assert_allclose(out[1], [x, 2.0 - x], atol=1e-15)
    # the end (5, 1) is 1.14 from the fourth vertex: that vertex is the stop point
    assert len(out) == 4


def test_resample_straight_line_and_stop_point():
    out = keyline.resample_equilateral([[0, 0, 0], [0, 0, 10]], 3.0)
    np.testing.assert_allclose(out[:, 2], [0, 3, 6, 9])


@given(
    st.integers(min_value=2, max_value=40),
    st.integers(min_value=0, max_value=2**31 - 1),
    st.floats(min_value=0.05, max_value=2.0),
    st.sampled_from([2, 3]),
)
def test_resample_equal_chords_on_polyline_and_matches_reference(n, seed, r, dim):
    rng = np.random.default_rng(seed)
    poly = np.cumsum(rng.normal(size=(n, dim)), axis=0)
    reach = np.linalg.norm(poly - poly[0], axis=1).max()
    if reach <= r:
        with pytest.raises(CurveError, match="step must be at most"):
            keyline.resample_equilateral(poly, r)
        return
    out = keyline.resample_equilateral(poly, r)
    chords = np.linalg.norm(np.diff(out, axis=0), axis=1)
    np.testing.assert_allclose(chords, r, rtol=0, atol=1e-12 * max(1.0, r))
    assert dist_to_polyline(out, poly).max() < 1e-12 * max(1.0, np.abs(poly).max())
    np.testing.assert_allclose(out, naive_resample(poly, r), atol=1e-10)


def test_resample_dense_noisy_scan():
    rng = np.random.default_rng(5)
    t = np.linspace(0.0, 300.0, 6001)
    scan = np.column_stack([t, 20 * np.sin(t / 40), 0.01 * rng.standard_normal(t.size)])
    out = keyline.resample_equilateral(scan, 1.0)
    np.testing.assert_allclose(np.linalg.norm(np.diff(out, axis=0), axis=1), 1.0, atol=1e-12)
    assert dist_to_polyline(out[::25], scan).max() < 1e-12 * 300
    # about the arc length of the (noisy) curve, in steps of 1
    assert 300 < len(out) < 400


def test_resample_allows_repeated_points():
    out = keyline.resample_equilateral([[0, 0], [0, 0], [4, 0], [4, 0], [4, 3]], 2.5)
    np.testing.assert_allclose(np.linalg.norm(np.diff(out, axis=0), axis=1), 2.5, atol=1e-14)


@pytest.mark.parametrize(
    ("points", "step", "match"),
    [
        ([[0, 0], [1, 0]], 0.0, "step must be > 0, got 0"),
        ([[0, 0], [1, 0]], -1.0, "step must be > 0"),
        ([[0, 0], [1, 0]], float("nan"), "step must be finite"),
        ([[0, 0], [1, 0]], 1.5, "step must be at most the largest distance 1 "),
        ([[0, 0], [1, 0], [0, 0.5]], 1.2, "step must be at most"),
        ([[0, 0], [np.nan, 0]], 0.5, "points must be finite"),
        ([[0, 0]], 0.5, "at least 2 points"),
        ([[1, 1], [1, 1]], 0.5, "must not all coincide"),
    ],
)
def test_resample_bad_input(points, step, match):
    with pytest.raises(CurveError, match=match):
        keyline.resample_equilateral(points, step)


# ------------------------------------------------------------------ plane fit


def tilted_planar_curve(rng, n, sigma):
    t = np.linspace(-1.0, 1.0, n)
    xy = np.column_stack([3.0 * t, 0.8 * np.sin(2.5 * t) + 0.3 * t**2])
    q = random_rotation3(rng)
    pts = np.column_stack([xy, np.zeros(n)]) @ q.T + rng.normal(size=3) * 10
    pts += sigma * rng.standard_normal(pts.shape)
    return pts, q[:, 2], xy, q


@pytest.mark.parametrize("seed", range(6))
def test_plane_fit_recovers_normal_of_tilted_noisy_plane(seed):
    rng = np.random.default_rng(seed)
    pts, normal, _, _ = tilted_planar_curve(rng, 2000, 0.01)
    pf = keyline.fit_plane(pts)
    angle = math.acos(min(1.0, abs(float(pf.normal @ normal))))
    # the normal is tilted by ~ sigma / (in-plane spread * sqrt(N)) ~ 1e-3; allow 5e-3
    assert angle < 5e-3
    np.testing.assert_allclose(pf.rms_distance, 0.01, rtol=0.1)
    np.testing.assert_allclose(np.sqrt(pf.eigenvalues[2]), pf.rms_distance, rtol=1e-10)
    # the paper's covariance C = (1/m) sum (p - p_bar)(p - p_bar)^t, eigenvalues descending,
    # eigenvectors e1, e2, e3 (reference: numpy's symmetric eigensolver on C itself)
    q = pts - pts.mean(axis=0)
    cov = q.T @ q / len(pts)
    lam, vec = np.linalg.eigh(cov)
    np.testing.assert_allclose(pf.eigenvalues, lam[::-1], rtol=1e-9, atol=1e-15)
    np.testing.assert_allclose(np.abs(pf.axes @ vec[:, ::-1]), np.eye(3), atol=1e-6)
    np.testing.assert_allclose(pf.centroid, pts.mean(axis=0), rtol=1e-14)


def test_plane_fit_exact_plane_and_in_plane_isometry():
    rng = np.random.default_rng(11)
    pts, normal, xy, _ = tilted_planar_curve(rng, 200, 0.0)
    pf = keyline.fit_plane(pts)
    assert math.acos(min(1.0, abs(float(pf.normal @ normal)))) < 1e-10
    assert np.abs(pf.coords[:, 2]).max() < 1e-12
    # 2D coordinates are an isometric copy of the generating curve
    d_in = np.linalg.norm(xy[:, None] - xy[None], axis=2)
    d_out = np.linalg.norm(pf.points2d[:, None] - pf.points2d[None], axis=2)
    np.testing.assert_allclose(d_out, d_in, atol=1e-11)
    np.testing.assert_allclose(pf.to_3d(pf.points2d), pts, atol=1e-11)


@pytest.mark.parametrize("seed", range(5))
def test_plane_fit_sign_convention(seed):
    rng = np.random.default_rng(100 + seed)
    pts, _, xy, q = tilted_planar_curve(rng, 300, 0.0)
    hint = rng.normal(size=3)
    pf = keyline.fit_plane(pts, normal_hint=hint)
    e1, e2, e3 = pf.axes
    assert e3 @ hint > 0
    assert e1 @ (pts[-1] - pts[0]) > 0
    np.testing.assert_allclose(np.cross(e1, e2), e3, atol=1e-14)
    np.testing.assert_allclose(pf.axes @ pf.axes.T, np.eye(3), atol=1e-14)
    # no mirror image: seen from the side of +normal the 2D curve has the generating
    # curve's orientation iff the generating normal q[:, 2] points to that side
    same_side = np.sign(q[:, 2] @ e3)
    area_in = signed_area(xy)
    area_out = signed_area(pf.points2d)
    np.testing.assert_allclose(area_out, same_side * area_in, rtol=1e-10)


def test_plane_fit_hint_orthogonal_falls_back_to_largest_component():
    t = np.linspace(0, 1, 20)
    pts = np.column_stack([t, np.zeros_like(t), t**2])  # the plane y = 0, normal +-y
    pf = keyline.fit_plane(pts)  # default hint +z is orthogonal to the normal
    np.testing.assert_allclose(pf.normal, [0, 1, 0], atol=1e-14)
    pf = keyline.fit_plane(pts, normal_hint=(0, -1, 0))
    np.testing.assert_allclose(pf.normal, [0, -1, 0], atol=1e-14)


@pytest.mark.parametrize(
    ("points", "kwargs", "match"),
    [
        ([[0, 0], [1, 0], [1, 1]], {}, r"points must have shape \(N, 3\), got \(3, 2\)"),
        ([[0, 0, 0], [1, 1, 1]], {}, "at least 3 points, got 2"),
        ([[0, 0, 0], [1, 1, 1], [2, 2, 2], [3, 3, 3]], {}, "all on one line"),
        ([[0, 0, 0], [1, 0, 0], [0, np.inf, 0]], {}, "points must be finite"),
        ([[0, 0, 0], [1, 0, 0], [0, 1, 0]], {"normal_hint": (0, 0, 0)}, "nonzero vector"),
    ],
)
def test_plane_fit_bad_input(points, kwargs, match):
    with pytest.raises(CurveError, match=match):
        keyline.fit_plane(points, **kwargs)


# ------------------------------------------------------------------ principal frame


def elongated(n=50):
    t = np.linspace(-2.0, 3.0, n)
    return np.column_stack([t, 0.3 * np.sin(2 * t)])


@pytest.mark.parametrize("angle", [-1.5, -0.7, 0.0, 0.4, 1.5, 1.7, 3.0, -2.5])
def test_principal_frame_sign_convention_and_invariance(angle):
    base = keyline.principal_frame(elongated())
    moved = elongated() @ rot2(angle).T + [5.0, -7.0]
    fr = keyline.principal_frame(moved)
    f1, f2 = fr.axes
    # section 5.3: the diagonal of (f1 f2) is positive, so (f1 f2) is a rotation
    assert f1[0] > 0 and f2[1] > 0
    np.testing.assert_allclose(np.linalg.det(fr.axes), 1.0, atol=1e-14)
    wrapped = (angle + base.angle + math.pi / 2) % math.pi - math.pi / 2
    np.testing.assert_allclose(fr.angle, wrapped, atol=1e-12)
    flip = 1.0 if abs(angle + base.angle) < math.pi / 2 else -1.0
    np.testing.assert_allclose(fr.coords, flip * base.coords, atol=1e-12)
    np.testing.assert_allclose(fr.centre, elongated().mean(axis=0) @ rot2(angle).T + [5, -7])
    np.testing.assert_allclose(fr.from_frame(fr.coords), moved, atol=1e-12)
    np.testing.assert_allclose(fr.to_frame(moved), fr.coords, atol=1e-12)
    np.testing.assert_allclose(fr.eigenvalues, base.eigenvalues, rtol=1e-12)


def test_principal_frame_vertical_tie():
    fr = keyline.principal_frame([[0, 0], [0, 1], [0, 2]])
    np.testing.assert_allclose(fr.axes, [[0, 1], [-1, 0]], atol=1e-15)


def test_principal_frame_bad_input():
    with pytest.raises(CurveError, match="must not all coincide"):
        keyline.principal_frame([[1, 2], [1, 2]])
    with pytest.raises(CurveError, match=r"shape \(N, 2\)"):
        keyline.principal_frame([[1, 2, 3], [1, 2, 4]])


# ------------------------------------------------------------------ inflection estimate


@given(
    st.floats(min_value=-1.0, max_value=1.0),
    st.floats(min_value=0.4, max_value=2.0),
    st.floats(min_value=0.4, max_value=2.0),
    st.floats(min_value=-math.pi, max_value=math.pi),
    st.integers(min_value=40, max_value=400),
)
def test_inflection_cubic_within_a_step(b, left, right, angle, n):
    # y = x^3/3 + b x^2 has its only inflection at x = -b; asymmetric span around it
    x = np.linspace(-b - left, -b + right, n)
    pts = np.column_stack([x, x**3 / 3 + b * x**2]) @ rot2(angle).T
    est = keyline.estimate_inflection(pts)
    true_index = int(np.argmin(np.abs(x + b)))
    assert abs(est.index - true_index) <= 1
    np.testing.assert_array_equal(est.point, pts[est.index])
    assert est.labels[-1] == est.index
    assert {est.labels[0], est.labels[1]} == {0, n - 1}


@pytest.mark.parametrize("seed", range(8))
def test_inflection_asymmetric_sine_keyline(seed):
    # a sine-like keyline: long shallow hump on the left, short deep valley on the right,
    # sampled by equal chords (as in the pipeline)
    rng = np.random.default_rng(seed)
    a_left, a_right = rng.uniform(0.5, 1.5), rng.uniform(1.5, 3.0)
    w_left, w_right = rng.uniform(4, 8), rng.uniform(2, 4)
    x = np.linspace(-w_left, w_right, 4001)
    y = np.where(
        x < 0, a_left * np.sin(math.pi * x / w_left), -a_right * np.sin(math.pi * x / w_right)
    )
    poly = keyline.resample_equilateral(np.column_stack([x, y]), 0.05)
    est = keyline.estimate_inflection(poly)
    true_index = int(np.argmin(np.abs(poly[:, 0])))
    assert abs(est.index - true_index) <= 2


@given(
    st.floats(min_value=0.05, max_value=0.85),
    st.floats(min_value=0.05, max_value=0.85),
    st.integers(min_value=15, max_value=200),
    st.integers(min_value=15, max_value=200),
    st.floats(min_value=0.1, max_value=0.95),
    st.floats(min_value=0.1, max_value=0.95),
    st.floats(min_value=-3.0, max_value=3.0),
)
def test_inflection_of_two_exact_elastica_halves(kl, kr, nl, nr, span_l, span_r, phi):
    # S curves made of two exact discrete elastica halves with kappa = 0 at the joint; each
    # half spans a fraction of the lobe (2K of argument), lobes turning by up to 2 asin(0.85)
    from scipy.special import ellipk

    zl = span_l * 2 * float(ellipk(kl**2)) / nl
    zr = span_r * 2 * float(ellipk(kr**2)) / nr
    syn = keyline.synthetic_keyline(
        left=(zl, None, kl), right=(zr, None, kr), n_left=nl, n_right=nr, phi=phi
    )
    est = keyline.estimate_inflection(syn.vertices)
    assert abs(est.index - syn.joint) <= 1


def test_inflection_dense_polyline():
    # 20001 vertices: step (1) measures convexity on 1024 sampled vertices
    x = np.linspace(-1.0, 2.5, 20001)
    est = keyline.estimate_inflection(np.column_stack([x, x**3 / 3 - 0.4 * x**2]))
    assert abs(x[est.index] - 0.4) <= x[1] - x[0] + 1e-12


def test_inflection_follows_fig14_steps_on_a_cubic():
    x = np.linspace(-1.5, 2.0, 301)
    est = keyline.estimate_inflection(np.column_stack([x, x**3 / 3 - 0.3 * x**2]))
    # step (1): point 3 is where the tangent is parallel to the end chord, x^2 - 0.6x = slope
    slope = ((2**3 / 3 - 0.3 * 4) - (-(1.5**3) / 3 - 0.3 * 1.5**2)) / 3.5
    x3 = 0.3 - math.sqrt(0.09 + slope)
    assert abs(x[est.labels[2]] - x3) <= 0.5 * (x[1] - x[0]) + 1e-12
    # point 3 is on the left lobe, so the inflection side (point 2) is the right end
    assert est.labels[:2] == (0, 300)
    # the numbered points close in on x = 0.3 from both sides
    xs = x[list(est.labels[2:])]
    assert np.all(np.diff(np.abs(xs - 0.3)[::2]) <= 0)
    assert abs(x[est.index] - 0.3) <= x[1] - x[0]


@pytest.mark.parametrize(
    ("points", "match"),
    [
        (np.column_stack([np.linspace(0, 1, 9), np.linspace(0, 1, 9) ** 2]), "convex arc"),
        (np.column_stack([np.linspace(0, 1, 9), np.linspace(0, 2, 9)]), "straight line"),
        ([[0, 0], [1, 1], [2, -1], [3, 0]], "at least 5 points, got 4"),
        ([[0, 0], [1, 1], [2, -1], [3, 0], [4, np.nan]], "finite"),
    ],
)
def test_inflection_bad_input(points, match):
    with pytest.raises(CurveError, match=match):
        keyline.estimate_inflection(points)


# ------------------------------------------------------------------ canonical parameters


@pytest.mark.parametrize(
    "params",
    [
        (0.0, 0.0, 1.0, 7.0, -0.015, -1.64 - 2 * 1.6399998658645112, 0.4),
        (1.0, -2.0, 0.5, -4.0, 0.03, 25.0, 0.7),
        (0.0, 0.0, 0.2, 0.3, -0.05, -3.0, 0.95),
        (0.0, 0.0, 0.2, 0.3, 0.05, 9.0, 2.5),
        (0.0, 0.0, 0.2, -3.5, -0.04, -7.0, 1.8),
    ],
)
def test_canonical_params_draw_the_same_vertices(params):
    from curvesmith import elastica

    can = keyline.canonical_params(params)
    np.testing.assert_allclose(elastica.sample(can, 60), elastica.sample(params, 60), atol=1e-9)
    assert -math.pi < can[3] <= math.pi
    if can[6] < 1:
        assert can[4] >= 0
        assert 0 <= can[5] < 4 * 1.1 * math.pi
    assert keyline.canonical_params(can) == pytest.approx(can, abs=1e-12)


# ------------------------------------------------------------------ end to end


def truth_and_fit(syn, res):
    tl, tr = syn.params_in(res)
    rows = res.table()
    return [
        (
            np.array(keyline.canonical_params(t)[2:]),
            np.array([row[c] for c in ["h", "phi", "z", "q", "k"]]),
        )
        for t, row in zip((tl, tr), rows, strict=True)
    ]


def test_end_to_end_exact_halves_recover_parameters():
    syn = keyline.synthetic_keyline()  # tilted plane, no noise, asymmetric halves
    res = keyline.fit(syn.points, step=1.0)
    assert res.success
    assert res.inflection.index == syn.joint
    np.testing.assert_allclose(np.linalg.norm(np.diff(res.points, axis=0), axis=1), 1.0, atol=1e-12)
    # the resampled polygon reproduces the generating vertices (the step is their edge)
    gen = np.vstack([syn.params_in(res)[0][:2]])
    np.testing.assert_allclose(res.points[syn.joint], gen[0], atol=1e-9)
    for truth, fitted in truth_and_fit(syn, res):
        np.testing.assert_allclose(fitted, truth, atol=1e-7)
    assert res.left.rms < 1e-9 and res.right.rms < 1e-9
    rows = res.table()
    assert [r["side"] for r in rows] == ["left", "right"]
    assert rows[0]["n_points"] == syn.joint + 1
    assert rows[1]["phi_deg"] == pytest.approx(math.degrees(rows[1]["phi"]))
    assert set(rows[0]) == set(keyline.TABLE_COLUMNS)
    # the fitted curves map back onto the scan's plane, through the joint
    back = res.to_input_frame(res.right.points)
    np.testing.assert_allclose(back[0], syn.offset, atol=1e-9)
    assert np.abs((back - res.plane.centroid) @ res.plane.normal).max() < 1e-9


@pytest.mark.parametrize("seed", [0, 1])
def test_end_to_end_noisy_tilted_scan_close_to_truth(seed):
    sigma = 0.01  # 1 % of the step, like 10 um on the paper's 1 mm step
    syn = keyline.synthetic_keyline(noise=sigma, seed=seed)
    res = keyline.fit(syn.points, step=1.0)
    assert res.success
    # the noise moves the inflection estimate by a few vertices at most
    assert abs(res.inflection.index - syn.joint) <= 5
    for truth, fitted in truth_and_fit(syn, res):
        h, phi, z, q, k = fitted - truth
        assert abs(h) < 1e-3
        assert abs(phi) < 0.15
        assert abs(z) < 0.1 * truth[2]
        # q is the phase at the pinned vertex: off by (index error) * z plus noise
        assert abs(q) < 5 * truth[2] + 0.1
        assert abs(k) < 0.08
    assert res.left.rms < 2 * sigma and res.right.rms < 2 * sigma


def test_fit_accepts_2d_input_and_reversed_order():
    syn = keyline.synthetic_keyline(n_left=60, n_right=50, left=(0.02, None, 0.3))
    xy = syn.vertices
    a = keyline.fit(xy, step=1.0)
    b = keyline.fit(xy[::-1], step=1.0)
    assert a.plane is None and a.success
    assert a.inflection.index == syn.joint
    np.testing.assert_allclose(b.points, a.points, atol=1e-9)
    for truth, fitted in truth_and_fit(syn, a):
        np.testing.assert_allclose(fitted, truth, atol=1e-7)


def test_fit_default_step_is_extent_over_200():
    syn = keyline.synthetic_keyline(n_left=60, n_right=50, left=(0.02, None, 0.3))
    res = keyline.fit(syn.points)
    extent = np.ptp(keyline.fit_plane(syn.points).points2d[:, 0])
    assert res.step == pytest.approx(extent / keyline.DEFAULT_STEPS)
    np.testing.assert_allclose(
        np.linalg.norm(np.diff(res.points, axis=0), axis=1), res.step, atol=1e-12
    )


@pytest.mark.parametrize(
    ("points", "kwargs", "match"),
    [
        ([[0, 0, 0], [1, 1, 0], [2, 0, 0], [3, 1, 0]], {}, "at least 5 points, got 4"),
        ([[0, 0, 0], [1, 1, 0], [2, 0, 0], [3, 1, 0], [4, np.nan, 0]], {}, "finite"),
        (np.zeros((6, 4)), {}, r"shape \(N, 2\) or \(N, 3\)"),
        ("sine", {"step": 0.0}, "step must be > 0, got 0"),
        ("sine", {"step": -2.0}, "step must be > 0"),
        ("sine", {"step": 50.0}, "step must be at most the largest distance"),
        ("sine", {"step": 2.0}, "step must leave at least 9 vertices"),
        ("arc", {"step": 0.05}, "convex arc"),
        ("early", {"step": 0.05}, "inflection away from the ends"),
        ("sine", {"min_side_points": 3}, "min_side_points must be an integer >= 5"),
        ("sine", {"inflection": 5000}, r"inflection must be an integer in \[0, "),
        ("sine", {"inflection": 2}, "3 vertices on the left side"),
    ],
)
def test_fit_bad_input(points, kwargs, match):
    t = np.linspace(0.0, 2 * math.pi, 200)
    if isinstance(points, str):
        y = {"sine": np.sin(t), "arc": -((t - math.pi) ** 2), "early": (t - 0.1) ** 3}[points]
        points = np.column_stack([t, y, 0.1 * t])
    with pytest.raises(CurveError, match=match):
        keyline.fit(points, **kwargs)


# ------------------------------------------------------------------ CLI


def _scan_files(tmp_path):
    syn = keyline.synthetic_keyline(
        n_left=80, n_right=70, left=(0.015, None, 0.3), noise=0.005, seed=2
    )
    np.savetxt(tmp_path / "a.xyz", syn.points)
    with (tmp_path / "b.csv").open("w") as fh:
        fh.write("x,y,z\n")
        np.savetxt(fh, syn.points, delimiter=",")
    (tmp_path / "bad.txt").write_text("1 2 3\n4 5\n")
    return syn


def test_cli_keyline_processes_good_files_and_reports_bad_ones(tmp_path):
    import json

    from click.testing import CliRunner

    from curvesmith.cli.keyline import TABLE_FIELDS, keyline_command
    from curvesmith.io import read_curves

    _scan_files(tmp_path)
    out = tmp_path / "out"
    files = [str(tmp_path / n) for n in ("a.xyz", "bad.txt", "b.csv", "missing.csv")]
    result = CliRunner().invoke(keyline_command, [*files, "-o", str(out), "--step", "1"])
    assert result.exit_code == 1, result.output
    assert "fitted 2 keyline(s) from 4 file(s)" in result.output
    assert "2 keyline(s) failed" in result.output
    rows = json.loads((out / "keyline_table.json").read_text())["rows"]
    assert [(Path(r["file"]).name, r["side"]) for r in rows] == [
        ("a.xyz", "left"),
        ("a.xyz", "right"),
        ("bad.txt", ""),
        ("b.csv", "left"),
        ("b.csv", "right"),
        ("missing.csv", ""),
    ]
    assert "bad.txt: line 2: expected 3 numbers (x y [z]) like every row, got 2" in rows[2]["error"]
    assert rows[2]["success"] is False and rows[5]["success"] is False
    for r in (rows[0], rows[1], rows[3], rows[4]):
        assert r["success"] is True and r["error"] == ""
        assert r["h"] == pytest.approx(1.0, abs=1e-3)
        assert set(r) == set(TABLE_FIELDS)
    # the same scan as .xyz and as CSV gives the same table
    for a, b in ((rows[0], rows[3]), (rows[1], rows[4])):
        assert a["k"] == pytest.approx(b["k"], rel=1e-9)
    csv_text = (out / "keyline_table.csv").read_text().splitlines()
    assert csv_text[0] == ",".join(TABLE_FIELDS) and len(csv_text) == 7
    curves = read_curves(out / "a_fit.csv")
    assert [c.properties["id"] for c in curves] == ["keyline", "left", "right"]
    np.testing.assert_allclose(
        np.linalg.norm(np.diff(curves[0].points, axis=0), axis=1), 1.0, atol=1e-9
    )


def test_cli_keyline_bundled_scan_and_multi_curve_csv(tmp_path):
    import json

    from click.testing import CliRunner

    from curvesmith import data
    from curvesmith.cli.keyline import keyline_command

    pts = data.load_points("keyline_scan_b.csv")
    with (tmp_path / "two.csv").open("w") as fh:
        fh.write("id,x,y,z\n")
        for tag in ("upper", "lower"):
            for x, y, z in pts[::2].tolist():
                fh.write(f"{tag},{x!r},{y!r},{z + (5.0 if tag == 'upper' else 0.0)!r}\n")
    out = tmp_path / "o"
    args = [str(data.path("keyline_scan_b.csv")), str(tmp_path / "two.csv"), "-o", str(out)]
    result = CliRunner().invoke(keyline_command, [*args, "--step", "1.0"])
    assert result.exit_code == 0, result.output
    table = json.loads((out / "keyline_table.json").read_text())
    rows = table["rows"]
    names = ["keyline_scan_b", "two_upper", "two_lower"]
    assert [r["curve"] for r in rows] == [n for n in names for _ in range(2)]
    for s, side in enumerate(("left", "right")):
        summ = table["summary"][side]
        vals = np.array([r["k"] for r in rows[s::2]])
        assert summ["count"] == 3
        assert summ["mean"]["k"] == pytest.approx(vals.mean(), rel=1e-12)
        assert summ["std"]["k"] == pytest.approx(vals.std(), rel=1e-9, abs=1e-15)
    assert all(r["success"] for r in rows)
    assert (out / "two_upper_fit.csv").is_file() and (out / "two_lower_fit.csv").is_file()
    # the bundled scan's truth (PROVENANCE_keyline.md): k = 0.28 left, 0.42 right
    assert rows[0]["k"] == pytest.approx(0.28, abs=0.05)
    assert rows[1]["k"] == pytest.approx(0.42, abs=0.05)
    assert rows[1]["z"] == pytest.approx(0.016, rel=0.1)


def test_cli_keyline_summary_leaves_circles_out_of_the_means(tmp_path):
    """A circular arc fits as the degenerate circle (k = 1e8 stands for infinity): it is
    counted, and the means and deviations of the side are over the elasticae alone."""
    import json

    from click.testing import CliRunner

    from curvesmith import data
    from curvesmith.cli.keyline import keyline_command

    rng = np.random.default_rng(4)
    t = np.linspace(0.3, 2.2, 300)  # an 80 mm arc, scanned with 0.02 mm noise
    arc = np.c_[80 * np.cos(t), 80 * np.sin(t), np.zeros_like(t)] + rng.normal(0, 0.02, (300, 3))
    t = np.linspace(0.2, 1.4, 300)  # a quarter of an ellipse: convex, not a circle
    oval = np.c_[120 * np.cos(t), 60 * np.sin(t), np.zeros_like(t)] + rng.normal(0, 0.02, (300, 3))
    for name, pts in (("arc", arc), ("oval", oval)):
        with (tmp_path / f"{name}.csv").open("w") as fh:
            fh.write("x,y,z\n")
            fh.writelines(f"{x!r},{y!r},{z!r}\n" for x, y, z in pts.tolist())
    (tmp_path / "short.csv").write_text("x,y,z\n0,0,0\n1,0,0\n2,1,0\n")  # an error row
    out = tmp_path / "o"
    names = [
        str(data.path("keyline_scan_b.csv")),
        *(str(tmp_path / f) for f in ("arc.csv", "oval.csv")),
    ]
    args = [*names, str(tmp_path / "short.csv"), "-o", str(out)]
    result = CliRunner().invoke(keyline_command, args)
    assert result.exit_code == 1, result.output  # the short scan failed, the others not
    table = json.loads((out / "keyline_table.json").read_text())
    rows = table["rows"]
    assert [(r["curve"], r["side"], r["case"]) for r in rows] == [
        ("keyline_scan_b", "left", "ii"),
        ("keyline_scan_b", "right", "ii"),
        ("arc", "whole", "circle"),
        ("oval", "whole", "i"),
        ("short", "", ""),
    ]
    assert rows[4]["success"] is False and rows[4]["error"]
    rows = rows[:4]
    assert rows[2]["k"] == 1e8 and rows[2]["success"] and rows[3]["success"]
    whole = table["summary"]["whole"]
    assert whole["count"] == 1 and whole["degenerate"] == {"circle": 1}
    assert whole["mean"]["k"] == rows[3]["k"] and whole["std"]["k"] == 0.0  # the oval alone
    for side, row in zip(("left", "right"), rows, strict=False):
        assert table["summary"][side]["count"] == 1 and "degenerate" not in table["summary"][side]
        assert table["summary"][side]["mean"]["k"] == row["k"]
    with (out / "keyline_table.csv").open() as fh:
        header = fh.readline().strip().split(",")
    assert header[header.index("success") + 1] == "case"


@pytest.mark.parametrize(
    ("args", "code", "text"),
    [
        (["--step", "0"], 2, "Invalid value for '--step'"),
        (["--step", "-1"], 2, "Invalid value for '--step'"),
        ([], 2, "Missing option '-o'"),
        (["--normal", "1,2"], 2, "--normal must be 3 comma-separated numbers, got '1,2'"),
        (["--normal", "0,0,0"], 2, "--normal must be a nonzero vector"),
    ],
)
def test_cli_keyline_usage_errors(tmp_path, args, code, text):
    from click.testing import CliRunner

    from curvesmith.cli.keyline import keyline_command

    _scan_files(tmp_path)
    out = [] if "Missing" in text else ["-o", str(tmp_path / "o")]
    result = CliRunner().invoke(keyline_command, [str(tmp_path / "a.xyz"), *out, *args])
    assert result.exit_code == code
    assert text in result.output


def test_cli_keyline_normal_flips_the_view(tmp_path):
    import json

    from click.testing import CliRunner

    from curvesmith.cli.keyline import keyline_command

    _scan_files(tmp_path)
    tables = []
    for normal in ("0,0,1", "0,0,-1"):
        out = tmp_path / normal.replace(",", "_")
        args = [str(tmp_path / "a.xyz"), "-o", str(out), "--step", "1", "--normal", normal]
        result = CliRunner().invoke(keyline_command, args)
        assert result.exit_code == 0, result.output
        tables.append(json.loads((out / "keyline_table.json").read_text())["rows"])
    # seen from the other side the keyline is mirrored about x'': the mirror image of the
    # elastica (phi, z, q, k) is (-phi, -z, -q, k), canonically (-phi, z, q - 2K, k)
    from scipy.special import ellipk

    for a, b in zip(*tables, strict=True):
        assert b["k"] == pytest.approx(a["k"], rel=1e-6)
        assert b["z"] == pytest.approx(a["z"], rel=1e-6)
        assert b["h"] == pytest.approx(a["h"], rel=1e-9)
        assert b["phi"] == pytest.approx(-a["phi"], abs=1e-6)
        big_k = float(ellipk(a["k"] ** 2))
        assert b["q"] == pytest.approx((a["q"] - 2 * big_k) % (4 * big_k), abs=1e-5)


def test_fit_with_given_inflection_matches_the_estimate_when_equal():
    syn = keyline.synthetic_keyline(n_left=60, n_right=50, left=(0.02, None, 0.3))
    auto = keyline.fit(syn.points, step=1.0)
    given_ = keyline.fit(syn.points, step=1.0, inflection=auto.inflection.index)
    assert given_.inflection.labels == ()
    assert given_.table() == auto.table()
    shifted = keyline.fit(syn.points, step=1.0, inflection=auto.inflection.index + 3)
    assert shifted.inflection.index == syn.joint + 3
    assert shifted.table()[1]["n_points"] == auto.table()[1]["n_points"] - 3
    # pinned 3 vertices into the right half: the right side is still one exact elastica
    assert shifted.right.rms < 1e-8


def test_cli_keyline_non_converged_side_is_reported_and_exits_1(tmp_path, monkeypatch):
    import dataclasses
    import json

    from click.testing import CliRunner

    from curvesmith.cli.keyline import keyline_command

    _scan_files(tmp_path)
    real_fit = keyline.fit

    def right_fails(*args, **kwargs):
        res = real_fit(*args, **kwargs)
        failed = dataclasses.replace(res.right, success=False, message="did not converge")
        return dataclasses.replace(res, right=failed)

    monkeypatch.setattr(keyline, "fit", right_fails)
    out = tmp_path / "o"
    args = [str(tmp_path / "a.xyz"), str(tmp_path / "b.csv"), "-o", str(out), "--step", "1"]
    result = CliRunner().invoke(keyline_command, args)
    assert result.exit_code == 1
    assert "fitted 2 keyline(s)" in result.output
    assert "fit did not converge" in result.output
    table = json.loads((out / "keyline_table.json").read_text())
    assert [(r["side"], r["success"], r["error"]) for r in table["rows"][:2]] == [
        ("left", True, ""),
        ("right", False, "right fit: did not converge"),
    ]
    assert table["summary"]["left"]["count"] == 2 and table["summary"]["right"]["count"] == 0
    assert (out / "a_fit.csv").is_file() and (out / "b_fit.csv").is_file()


@pytest.mark.parametrize(
    ("content", "message"),
    [
        (bytes(range(128, 256)), "garbage.xyz: not a text table of numbers"),
        (b"", "garbage.xyz: the file is empty"),
        (b"# comment only\n\n", "garbage.xyz: the file is empty"),
        (b"1 2 3\n4 5 6\n7 8 x\n", "garbage.xyz: line 3: 'x' is not a number"),
        (b"1 2 3 4\n", "garbage.xyz: line 1: expected 2 or 3 numbers"),
    ],
)
def test_read_scan_errors_name_file_and_line(tmp_path, content, message):
    # Regression: a binary .xyz file crashed the keyline command with a UnicodeDecodeError
    # traceback; an empty one said "got row widths []".
    from curvesmith.cli.keyline import read_scan

    path = tmp_path / "garbage.xyz"
    path.write_bytes(content)
    with pytest.raises(CurveError, match=message):
        read_scan(path)


def test_read_scan_skips_a_header_row(tmp_path):
    from curvesmith.cli.keyline import read_scan

    path = tmp_path / "scan.xyz"
    path.write_bytes(b"\xef\xbb\xbf//X //Y //Z\r\n1 2 3\r\n4 5 6\r\n")
    ((name, pts),) = read_scan(path)
    assert name == "scan" and pts.tolist() == [[1, 2, 3], [4, 5, 6]]


# ------------------------------------------------------------------ issue 11: real scans


def _c_section_scan(rng, noise=0.005):
    """A tilted 3D C-shaped section (no inflection), 1.5 m in mm, uneven spacing."""
    from curvesmith import elastica

    flat = elastica.sample((0.0, 0.0, 2.0, 0.05, 0.0012, 0.25, 3.0), 751)
    q = random_rotation3(rng)
    pts = np.column_stack([flat, np.zeros(len(flat))]) @ q.T + [300.0, -120.0, 45.0]
    keep = np.sort(rng.choice(len(pts), 600, replace=False))
    keep[0], keep[-1] = 0, len(pts) - 1
    return pts[keep] + noise * rng.standard_normal((600, 3)), q


def test_cli_keyline_fits_a_scan_without_inflection_in_scan_coordinates(tmp_path):
    import json

    from click.testing import CliRunner

    from curvesmith.cli.keyline import keyline_command
    from curvesmith.io import read_curves

    rng = np.random.default_rng(21)
    scan, q = _c_section_scan(rng)
    np.savetxt(tmp_path / "c.xyz", scan)
    out = tmp_path / "o"
    result = CliRunner().invoke(
        keyline_command,
        [str(tmp_path / "c.xyz"), "-o", str(out), "--step", "2", "--max-iterations", "900"],
    )
    assert result.exit_code == 0, result.output
    rows = json.loads((out / "keyline_table.json").read_text())["rows"]
    assert [r["side"] for r in rows] == ["whole"] and rows[0]["success"] is True
    assert rows[0]["k"] == pytest.approx(3.0, rel=0.05)
    curves = read_curves(out / "c_fit.csv")
    assert [c.properties["id"] for c in curves] == ["keyline", "whole"]
    fitted = curves[1].points
    assert fitted.shape[1] == 3
    # in scan coordinates: every fitted vertex within 0.05 mm of the scan polyline
    assert dist_to_polyline(fitted, scan).max() < 0.05
    tr = json.loads((out / "c_fit_transform.json").read_text())
    assert abs(abs(np.dot(tr["plane"]["normal"], q[:, 2])) - 1) < 1e-6
    # the transform maps the 2D resampled keyline to the 3D one written
    res = keyline.fit(scan, step=2.0, single_if_convex=True)
    back = np.asarray(tr["origin"]) + res.points @ np.asarray(tr["axes"])
    np.testing.assert_allclose(back, curves[0].points, atol=1e-9)


def test_self_intersecting_curve_is_walked_not_short_cut():
    """A loop: the paper's rule jumps across the crossing and loses the loop; the pipeline
    then resamples by the walk and keeps every part of the curve."""
    t = np.linspace(-2.2, 2.2, 3000)
    loop = np.column_stack([t**2, t**3 - 3 * t])  # a node at t = +-sqrt(3)
    curve = np.column_stack([loop, 0.01 * t])
    with pytest.raises(CurveError):  # no inflection on the loop: refused, not truncated
        keyline.fit(curve, step=0.05)
    res = keyline.fit(curve, step=0.05, single_if_convex=True)
    assert res.resampling == "walk"
    length = float(np.hypot(*np.diff(loop, axis=0).T).sum())
    assert res.points.shape[0] >= int(length / 0.05) - 2  # nothing dropped
    paper = keyline.resample_equilateral(loop, 0.05)
    assert paper.shape[0] < 0.5 * res.points.shape[0]  # the paper's rule short-cuts


def test_closed_curve_gets_a_true_message():
    t = np.linspace(0, 2 * math.pi, 400)
    ring = np.column_stack([np.cos(t), 0.6 * np.sin(t), 0.1 * np.cos(t)])
    with pytest.raises(CurveError, match="closed curve .* split the closed curve"):
        keyline.fit(ring, step=0.02)


def test_cli_step_nan_is_a_usage_error_before_any_work(tmp_path):
    # --step nan was a data error per scan: a table written, then two Error lines
    from click.testing import CliRunner

    from curvesmith.cli import main

    scan = tmp_path / "k.csv"
    t = np.linspace(0, 1, 50)
    np.savetxt(scan, np.c_[100 * t, 10 * np.sin(3 * t), 0 * t], delimiter=",", header="x,y,z")
    out = tmp_path / "out"
    res = CliRunner().invoke(main, ["keyline", str(scan), "-o", str(out), "--step", "nan"])
    assert res.exit_code == 2 and res.output.count("Error:") == 1, res.output
    assert "'nan' is not a finite number" in res.output and not out.exists()


@pytest.mark.parametrize("seed", range(4))
@pytest.mark.parametrize("shape", ["spiral", "ellipse"])
def test_fit_keeps_a_noisy_convex_arc_whole(shape, seed):
    # the RDP estimate of section 5.3 assumes an inflection and found one in the noise of
    # convex arcs: a spiral was cut at vertex 218 of 223, a quarter ellipse in some noise
    # draws; with single_if_convex they are one elastica, fitted to the noise level
    rng = np.random.default_rng(seed)
    if shape == "spiral":  # curvature 0.004 -> 0.022 per mm over 120 mm
        s = np.linspace(0.0, 120.0, 400)
        turn = np.cumsum(0.004 + 0.00015 * s) * (s[1] - s[0])
        xy = np.c_[np.cumsum(np.cos(turn)), np.cumsum(np.sin(turn))] * (s[1] - s[0])
    else:
        t = np.linspace(0.2, 1.4, 300)
        xy = np.c_[120 * np.cos(t), 60 * np.sin(t)]
    pts = np.c_[xy, np.zeros(len(xy))] + rng.normal(0.0, 0.02, (len(xy), 3))
    assert keyline.estimate_inflections(pts[:, :2]) == ()
    res = keyline.fit(pts, single_if_convex=True)
    assert res.left is None and res.right is None and res.whole.success
    assert res.whole.rms < 3 * 0.02  # the noise, not a misfit
