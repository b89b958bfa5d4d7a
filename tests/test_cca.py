"""Tests for curvesmith.cca (Gordon 2010, corner cutting and augmentation)."""

import math
import os
from dataclasses import FrozenInstanceError

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from scipy.interpolate import PchipInterpolator

from curvesmith import cca
from curvesmith.errors import CurveError
from curvesmith.geometry import interior_angles, is_convex
from curvesmith.internals import (
    cca_api,
    cca_blocks,
    cca_chunks,
    cca_input,
    cca_kernel,
    cca_restrict,
    cca_smooth_one,
    cca_stepnd,
    validate,
)
from oracles import exact_area

# --------------------------------------------------------------------------- helpers


def area_scale(points):
    """Sum of the absolute shoelace terms about the centroid: the area's natural scale."""
    q = np.asarray(points, dtype=float)
    q = q - q.mean(axis=0)
    return 0.5 * float(
        np.abs(q[:, 0] * np.roll(q[:, 1], -1) - np.roll(q[:, 0], -1) * q[:, 1]).sum()
    )


def assert_area_kept(before, after, rtol=1e-12):
    a0, a1 = exact_area(before), exact_area(after)
    # Relative to |A| (the guarantee); a zero-area figure-eight is measured against its scale,
    # and a figure with no area at all (an anchored piece that is one straight edge) against
    # the rounding of the output's coordinates: moving each vertex by up to eps |coordinate|
    # changes the shoelace area by up to eps * max|coordinate| * perimeter.
    q = np.asarray(after, dtype=float)
    perimeter = float(np.hypot(*(np.roll(q, -1, axis=0) - q).T).sum())
    rounding = np.finfo(float).eps * float(np.abs(q).max()) * perimeter
    tol = rtol * abs(a0) + 1e-14 * area_scale(before) + rounding
    assert abs(a1 - a0) <= tol, (a0, a1, (a1 - a0) / (abs(a0) or 1.0))


def vector_area(points):
    p = np.asarray(points, dtype=float)
    p = p - p[0]
    return 0.5 * np.cross(p, np.roll(p, -1, axis=0)).sum(axis=0)


def regular(n, r=1.0, phase=0.0):
    t = phase + 2 * np.pi * np.arange(n) / n
    return np.column_stack([r * np.cos(t), r * np.sin(t)])


def reference_step(p, alpha, closed):
    """Plain per-vertex CCA1 (no restrictions), written from section 3 of the paper."""
    p = np.asarray(p, dtype=float)
    n = len(p)
    ends = set() if closed else {0, n - 1}
    out, cut = [], {}
    for i in range(n):
        if i in ends:
            cut[i] = (p[i], p[i], 0.0)
            continue
        a_, v, b_ = p[i - 1], p[i], p[(i + 1) % n]
        l1, l2 = np.linalg.norm(v - a_), np.linalg.norm(b_ - v)
        u1, u2 = (v - a_) / l1, (b_ - v) / l2
        ang = math.atan2(abs(u1[0] * u2[1] - u1[1] * u2[0]), -(u1 @ u2))
        al = alpha(ang) if callable(alpha) else alpha
        a = al * min(l1, l2)
        k = 0.5 * a * a * (u1[0] * u2[1] - u1[1] * u2[0])  # signed cut area
        cut[i] = (v - a * u1, v + a * u2, k)
    for i in range(n if closed else n - 1):
        j = (i + 1) % n
        li, ri, ki = cut[i]
        lj, _, kj = cut[j]
        out += [li] if i in ends else [li, ri]
        base = lj - ri
        w = np.linalg.norm(base) / 2
        u = base / (2 * w)
        net = 0.5 * (ki + kj)  # signed area of the augmenting triangle
        out.append((ri + lj) / 2 + net / w * np.array([u[1], -u[0]]))
    if not closed:
        out.append(p[-1])
    return np.array(out)


class _LibmTrig:
    """numpy, except arctan2 and tan from the C library (the functions the kernel calls)."""

    arctan2 = staticmethod(np.vectorize(math.atan2, otypes=[float]))
    tan = staticmethod(np.vectorize(math.tan, otypes=[float]))

    def __getattr__(self, name):
        return getattr(np, name)


def numpy_reference(points, *, closed, iterations=1, libm=False, **kwargs):
    """The reference engine: cca's N-d numpy step, curve by curve (not the compiled kernel).

    numpy's arctan2 and tan (SIMD) may differ from the C library's in the last ulp; with
    ``libm=True`` the reference takes the C library's, and the compiled kernel must then
    give the same bits.
    """

    if libm:
        saved = cca_stepnd.np, cca_restrict.np
        cca_stepnd.np = cca_restrict.np = _LibmTrig()
        try:
            return numpy_reference(points, closed=closed, iterations=iterations, **kwargs)
        finally:
            cca_stepnd.np, cca_restrict.np = saved

    args = {
        "alpha": "regular",
        "anchors": None,
        "corner_ratio": 2.0,
        "inflection_ratio": 0.5,
        "restrict": True,
        "tilt": np.pi / 8,
        "balance_tol": 1e-9,
        "max_passes": 16,
        "min_factor": 0.0,
        "threads": 1,
    }
    args.update(kwargs)
    return cca_smooth_one(points, closed=closed, iterations=iterations, engine="numpy", **args)


# --------------------------------------------------------------------------- strategies

coord = st.floats(-10, 10, allow_nan=False, allow_infinity=False)


@st.composite
def random_polygons(draw, min_n=3, max_n=10):
    n = draw(st.integers(min_n, max_n))
    pts = np.array(draw(st.lists(st.tuples(coord, coord), min_size=n, max_size=n)))
    edges = np.linalg.norm(np.roll(pts, -1, axis=0) - pts, axis=1)
    if edges.min() < 1e-3 or area_scale(pts) < 1e-2:
        pts = regular(n, 3.0) + 0.01 * pts
    return pts


@st.composite
def star_polygons(draw, min_n=5, max_n=14):
    n = draw(st.integers(min_n, max_n))
    radii = np.array(draw(st.lists(st.floats(0.3, 3.0), min_size=n, max_size=n)))
    return regular(n) * radii[:, None]


@st.composite
def convex_polygons(draw, min_n=3, max_n=12):
    n = draw(st.integers(min_n, max_n))
    gaps = np.array(draw(st.lists(st.floats(0.2, 1.0), min_size=n, max_size=n)))
    t = np.cumsum(gaps) / gaps.sum() * 2 * np.pi
    ax = draw(st.floats(0.3, 3.0))
    p = np.column_stack([ax * np.cos(t), np.sin(t)])
    return p


# --------------------------------------------------------------------------- Table 1 / eq. (5)


@pytest.mark.parametrize(
    ("value", "printed", "digits"),
    [
        # Table 1 of Gordon (2010), alpha row; digits as printed in the paper
        (lambda: cca.regular_alpha(4), 0.211325, 6),
        (lambda: cca.regular_alpha(6), 0.194774, 6),
        (lambda: cca.regular_alpha(12), 0.185845, 6),
        (lambda: cca.LIMIT_ALPHA, 0.1830127, 7),
        (lambda: cca.TRIANGLE_ALPHA, 0.24443, 5),
        # section 4 text: eq. (5) with beta = 30 degrees
        (lambda: cca.regular_alpha(3), 0.23915, 5),
    ],
)
def test_table1_values(value, printed, digits):
    assert round(value(), digits) == printed


@pytest.mark.parametrize(
    ("deg", "printed", "digits"),
    [
        (0, 0.0, 6),
        (40, 0.211325, 6),
        (60, 0.24443, 5),
        (90, 0.211325, 6),
        (120, 0.194774, 6),
        (150, 0.185845, 6),
        (180, 0.1830127, 7),
    ],
)
def test_profile_passes_through_table1(deg, printed, digits):
    assert round(cca.alpha_profile(np.deg2rad(deg)), digits) == printed


def test_profile_is_pchip_with_maximum_at_60_degrees():
    x, y = cca.profile_nodes()
    ref = PchipInterpolator(x, y)
    t = np.linspace(0, np.pi, 2001)
    got = cca.alpha_profile(t)
    np.testing.assert_allclose(got, ref(t), rtol=0, atol=1e-15)
    assert got.max() <= cca.TRIANGLE_ALPHA
    assert cca.alpha_profile(np.pi / 3) == pytest.approx(cca.TRIANGLE_ALPHA, abs=1e-15)
    assert t[np.argmax(got)] == pytest.approx(np.pi / 3, abs=np.pi / 2000)
    assert np.all(got >= 0) and np.all(got < 1 / 3)


def test_eq5_limit_and_closed_form():
    # the limit 8a^2 + 4a - 1 = 0 as beta -> pi/2
    assert cca.solve_regular_alpha(np.pi / 2 - 1e-7) == pytest.approx(cca.LIMIT_ALPHA, abs=1e-7)
    assert abs(8 * cca.LIMIT_ALPHA**2 + 4 * cca.LIMIT_ALPHA - 1) < 1e-15
    # the root solves eq. (5) as printed
    for beta in np.linspace(np.pi / 6, np.pi / 2 - 0.01, 9):
        a = cca.solve_regular_alpha(beta)
        g = (beta + np.pi) / 3
        assert (4 - 2 * np.tan(g) * np.sin(2 * beta)) * a * a - 4 * a + 1 == pytest.approx(
            0, abs=1e-12
        )
        assert 0 < a < 1 / 3
    s3 = math.sqrt(3)
    ta = cca.TRIANGLE_ALPHA
    assert (3 * s3 - 4) * ta**2 + (6 - 3 * s3) * ta + s3 - 2 == pytest.approx(0, abs=1e-15)


@pytest.mark.parametrize("n", [4, 6, 12, 24])
def test_eq5_gives_regular_apex_angles(n):
    """Independent check of eqs. (4)-(5): every apex gets the angle of a regular 3n-gon."""
    p = regular(n)
    out = cca.smooth(p, closed=True, alpha=cca.regular_alpha(n), restrict=False)
    ang = interior_angles(out, closed=True)
    np.testing.assert_allclose(ang[2::3], np.pi * (3 * n - 2) / (3 * n), atol=1e-12)
    if n == 4:  # the square becomes a regular 12-gon (section 4)
        np.testing.assert_allclose(ang, 5 * np.pi / 6, atol=1e-12)
        e = np.linalg.norm(np.roll(out, -1, axis=0) - out, axis=1)
        np.testing.assert_allclose(e, e[0], rtol=1e-13)


def test_triangle_alpha_gives_unit_aspect_ratio():
    out = cca.smooth(regular(3, phase=np.pi / 2), closed=True, alpha=cca.TRIANGLE_ALPHA)
    assert np.ptp(out[:, 0]) / np.ptp(out[:, 1]) == pytest.approx(1.0, abs=1e-13)
    other = cca.smooth(regular(3, phase=np.pi / 2), closed=True, alpha=cca.regular_alpha(3))
    assert abs(np.ptp(other[:, 0]) / np.ptp(other[:, 1]) - 1) > 5e-3  # "visibly not regular"


def test_solve_regular_alpha_rejects_out_of_range():
    with pytest.raises(CurveError, match="beta must be in"):
        cca.solve_regular_alpha(0.1)
    with pytest.raises(CurveError, match="angle must be in"):
        cca.alpha_profile(-0.5)
    with pytest.raises(CurveError, match="n must be an integer >= 3"):
        cca.regular_alpha(2)


# --------------------------------------------------------------------------- CCA1 vs reference


@pytest.mark.parametrize("closed", [True, False])
@pytest.mark.parametrize("alpha", [0.2, "regular", 0.3])
def test_matches_plain_reference_step(closed, alpha):
    rng = np.random.default_rng(7)
    p = rng.normal(size=(9, 2))
    al = cca.alpha_profile if alpha == "regular" else alpha
    ref = reference_step(p, al, closed)
    got = cca.smooth(p, closed=closed, alpha=alpha, restrict=False)
    np.testing.assert_allclose(got, ref, rtol=0, atol=1e-13)


def test_vertex_counts():
    p = regular(7)
    for it in range(4):
        assert cca.smooth(p, closed=True, iterations=it).shape == (7 * 3**it, 2)
    q = np.array([[0, 0], [1, 0.3], [2, -0.2], [3, 0.5], [4, 0.1]], dtype=float)
    n = len(q)
    for _ in range(3):
        q2 = cca.smooth(q, closed=False)
        assert q2.shape[0] == 3 * n - 3 + cca.smooth_with_info(q, closed=False).fig11_edges
        q, n = q2, q2.shape[0]


# --------------------------------------------------------------------------- area guarantees


@given(random_polygons(), st.integers(1, 5))
def test_area_preserved_random_polygons(p, iterations):
    """Convex, non-convex and self-intersecting polygons alike."""
    out = cca.smooth(p, closed=True, iterations=iterations)
    assert np.isfinite(out).all()
    assert_area_kept(p, out)


@given(star_polygons(), st.integers(1, 5))
def test_area_preserved_star_polygons(p, iterations):
    assert_area_kept(p, cca.smooth(p, closed=True, iterations=iterations))


@given(random_polygons(min_n=2, max_n=9), st.integers(1, 5))
def test_open_polyline_area_against_chord(p, iterations):
    out = cca.smooth(p, closed=False, iterations=iterations)
    np.testing.assert_array_equal(out[0], p[0])
    np.testing.assert_array_equal(out[-1], p[-1])
    assert_area_kept(p, out)  # the polygon closed by the chord


def test_area_of_plot_integral_preserved():
    x = np.linspace(0, 10, 21)
    y = np.sin(x) + 0.3 * np.cos(3 * x)
    p = np.column_stack([x, y])
    out = cca.smooth(p, closed=False, iterations=4)
    # integral under the plot against the chord, via the closed polygon area
    assert_area_kept(p, out)


def test_self_intersecting_figure_eight():
    p = np.array([[0, 0], [2, 2], [4, 0], [4, 2], [2, 0], [0, 2.0]])
    out = cca.smooth(p, closed=True, iterations=5)
    assert exact_area(out) == pytest.approx(exact_area(p), abs=1e-13)


# --------------------------------------------------------------------------- convexity (Lemma 4/6)


def _half_angles(p):
    return 0.5 * interior_angles(p, closed=True)


@given(convex_polygons(), st.integers(1, 4))
def test_convex_stays_convex_and_angles_grow(p, iterations):
    cur = p
    for _ in range(iterations):
        nxt = cca.smooth(cur, closed=True)
        assert is_convex(nxt, strict=True)
        n = len(cur)
        assert nxt.shape[0] == 3 * n
        old = interior_angles(cur, closed=True)
        new = interior_angles(nxt, closed=True)
        # Lemma 4, (2)-(3): cut points L_i, R_i have larger angles than V_i
        assert np.all(new[0::3] > old) and np.all(new[1::3] > old)
        # Lemma 4, (1): the apex on edge i beats both neighbouring old angles
        assert np.all(new[2::3] > np.maximum(old, np.roll(old, -1)))
        cur = nxt


@given(convex_polygons(), st.floats(1.1, 4.0))
def test_definition2_apex_condition(p, c):
    """tan(gamma) >= c tan(beta_i) at every apex (Definition 2, condition 2)."""
    out = cca.smooth(p, closed=True, corner_ratio=c)
    gamma = _half_angles(out)[2::3]
    beta = _half_angles(p)
    lhs = np.tan(gamma)
    rhs = c * np.tan(np.maximum(beta, np.roll(beta, -1)))
    assert np.all(lhs >= rhs * (1 - 1e-9))


@given(random_polygons(), st.integers(1, 3))
def test_edges_shrink(p, iterations):
    """Lemma 6: every new edge is shorter than the edge it comes from (here <= 2/3 of it)."""
    cur = p
    for _ in range(iterations):
        info = cca.smooth_with_info(cur, closed=True)
        nxt, n = info.points, len(cur)
        # Fig. 11 edges are built by another construction (two triangles), which can keep
        # 3 vertices per edge while changing their lengths: Lemma 6 is about CCA1's cuts
        if nxt.shape[0] != 3 * n or info.fig11_edges:
            break
        old = np.linalg.norm(np.roll(cur, -1, axis=0) - cur, axis=1)
        new = np.linalg.norm(np.roll(nxt, -1, axis=0) - nxt, axis=1).reshape(n, 3)
        # L_i R_i (cut) comes from both edges at V_i; R_i G_i and G_i L_{i+1} from edge i
        assert np.all(new[:, 0] <= 2 / 3 * np.minimum(old, np.roll(old, 1)) * (1 + 1e-12))
        assert np.all(new[:, 1] <= 2 / 3 * old * (1 + 1e-12))
        assert np.all(new[:, 2] <= 2 / 3 * old * (1 + 1e-12))
        cur = nxt


def test_lemma6_factor_for_obtuse_polygons():
    cur = regular(9) * np.array([1.3, 1.0])
    for _ in range(4):
        assert interior_angles(cur, closed=True).min() > np.pi / 2
        nxt = cca.smooth(cur, closed=True)
        lmax = np.linalg.norm(np.roll(cur, -1, axis=0) - cur, axis=1).max()
        assert np.linalg.norm(np.roll(nxt, -1, axis=0) - nxt, axis=1).max() < lmax / np.sqrt(2)
        cur = nxt


def test_fig12_obtuse_angle_forces_local_reduction():
    # a nearly straight vertex (angle close to pi) next to sharp corners
    p = np.array([[0, 0], [4, 0], [4, 1], [2, 1.002], [0, 1]], dtype=float)
    res = cca.smooth_with_info(p, closed=True)
    assert res.reductions >= 2 and res.success
    assert is_convex(res.points, strict=True)
    plain = cca.smooth(p, closed=True, restrict=False)
    assert not is_convex(plain, strict=True)  # without the restriction convexity is lost
    assert_area_kept(p, res.points)
    assert_area_kept(p, plain)


def test_inflection_restriction_fig10():
    # big cut at A (sharp corner) against a small cut at B on an inflection edge AB
    p = np.array([[-1, -3], [0, 0], [3, 0], [4, 0.05], [5, 0.05]], dtype=float)
    C = 0.5
    ang0 = interior_angles(p, closed=False)  # angles at vertices 1, 2, 3
    res = cca.smooth_with_info(p, closed=False, inflection_ratio=C)
    plain = cca.smooth(p, closed=False, restrict=False)
    assert res.reductions >= 1
    # layout: V0, G0, L1, R1, G1, L2, R2, G2, L3, R3, G3, V4 -> the cut point L2 (index 5)
    # sits next to B = vertex 2, the minor cut of inflection edge 1
    old_b = ang0[1]
    new_plain = interior_angles(plain, closed=False)[5 - 1]
    new_res = interior_angles(res.points, closed=False)[5 - 1]
    assert new_plain < old_b  # the situation of Fig. 10: a new angle smaller than the old
    assert new_res > old_b  # fixed by decreasing the dominant alpha (epsilon <= C gamma)
    # epsilon (base angle of the augmenting triangle) <= C * |tau_B| / 2
    r1, g1, l2 = res.points[3], res.points[4], res.points[5]
    base = l2 - r1
    gr = g1 - r1
    h = abs(base[0] * gr[1] - base[1] * gr[0]) / np.linalg.norm(base)
    eps = math.atan2(h, np.linalg.norm(base) / 2)
    assert eps <= C * (np.pi - old_b) / 2 * (1 + 1e-9)
    assert_area_kept(p, res.points)


# --------------------------------------------------------------------------- Fig. 11


def test_fig11_balanced_inflection_edges_shrink():
    # a symmetric zigzag: every inner edge is an inflection edge with equal cuts
    x = np.arange(8, dtype=float)
    y = np.where(np.arange(8) % 2 == 0, 0.0, 1.0)
    p = np.column_stack([x, y])
    res = cca.smooth_with_info(p, closed=False, iterations=1, tilt=0.2)
    k = res.fig11_edges
    assert k == 5  # the inner edges 1..5 are balanced inflection edges
    out = res.points
    assert out.shape[0] == 3 * 8 - 3 + k
    assert_area_kept(p, out)
    # the two apexes A', B' and the mid point M of R..L are collinear, tilt = 0.2 / 2
    # unbalanced (perturbed) zigzag: one apex per edge again
    q = p + 0.05 * np.sin(np.arange(8.0))[:, None]
    assert cca.smooth_with_info(q, closed=False).fig11_edges == 0
    assert cca.smooth(q, closed=False).shape[0] == 3 * 8 - 3
    lens = np.linalg.norm(np.diff(out, axis=0), axis=1)
    # longest edge shrinks: original inner edges have length sqrt(2)
    assert lens.max() < np.sqrt(2) * 0.6
    # check one Fig. 11 edge explicitly: edge 2 (vertices 2 -> 3)
    # V0, G0 | L1, R1, A'1, B'1 | L2, R2, A'2, B'2 | L3 ...
    r2, a_, b_, l3 = out[7], out[8], out[9], out[10]
    m = 0.5 * (r2 + l3)
    am, bm = a_ - m, b_ - m
    assert abs(am[0] * bm[1] - am[1] * bm[0]) < 1e-12
    d = l3 - r2
    ab = b_ - a_
    tilt = math.atan2(abs(d[0] * ab[1] - d[1] * ab[0]), d @ ab)
    assert tilt == pytest.approx(0.1, rel=1e-9)
    assert np.linalg.norm(b_ - a_) < 0.55 * np.linalg.norm(d)


def test_fig11_tilts_halve_per_iteration():
    x = np.arange(6, dtype=float)
    p = np.column_stack([x, np.where(np.arange(6) % 2 == 0, 0.0, 1.0)])
    infos = [cca.smooth_with_info(p, closed=False, iterations=k) for k in (1, 2, 3)]
    for r in infos:
        assert_area_kept(p, r.points)
    assert infos[0].fig11_edges > 0
    assert infos[2].fig11_edges >= infos[1].fig11_edges >= infos[0].fig11_edges


# --------------------------------------------------------------------------- local control


@pytest.mark.parametrize("restrict", [False, True])
def test_local_control(restrict):
    n, j = 16, 7
    p = regular(n, 2.0) * np.array([1.0, 0.8])
    q = p.copy()
    q[j] += [0.05, -0.03]
    a = cca.smooth(p, closed=True, restrict=restrict)
    b = cca.smooth(q, closed=True, restrict=restrict)
    assert a.shape == b.shape == (3 * n, 2)
    changed = np.flatnonzero(np.any(a != b, axis=1))
    # outputs per vertex i: 3i (L_i), 3i + 1 (R_i), 3i + 2 (apex on edge i)
    allowed = set()
    for i in (j - 1, j, j + 1):  # cut points of the three vertices touching the moved edges
        allowed |= {3 * i, 3 * i + 1}
    for e in (j - 2, j - 1, j, j + 1):  # apexes on the four nearest edges
        allowed.add(3 * e + 2)
    assert set(changed.tolist()) <= allowed
    assert len(changed) >= 8


# --------------------------------------------------------------------------- anchors


def test_anchors_fixed_and_pieces_independent():
    rng = np.random.default_rng(3)
    p = regular(12, 3.0) + 0.4 * rng.normal(size=(12, 2))
    anchors = [2, 7, 10]
    out = cca.smooth(p, closed=True, iterations=3, anchors=anchors)
    assert_area_kept(p, out)
    for a in anchors:
        assert np.any(np.all(out == p[a], axis=1))
    # each piece equals the independent smoothing of that piece as a polyline
    pieces = [p[2:8], p[7:11], np.vstack([p[10:], p[:3]])]
    ref = [cca.smooth(s, closed=False, iterations=3) for s in pieces]
    starts = [int(np.flatnonzero(np.all(out == p[a], axis=1))[0]) for a in anchors]
    for s0, r in zip(starts, ref, strict=True):
        seg = np.roll(out, -s0, axis=0)[: len(r)]
        np.testing.assert_allclose(seg, r, rtol=0, atol=1e-12)
        assert_area_kept(pieces[starts.index(s0)], seg)  # each piece against its chord


def test_anchors_on_open_polyline_and_single_anchor_ring():
    x = np.linspace(0, 6, 13)
    p = np.column_stack([x, np.sin(2 * x)])
    out = cca.smooth(p, closed=False, iterations=2, anchors=[4, 8])
    assert_area_kept(p, out)
    k4 = int(np.flatnonzero(np.all(out == p[4], axis=1))[0])
    k8 = int(np.flatnonzero(np.all(out == p[8], axis=1))[0])
    assert_area_kept(p[4:9], out[k4 : k8 + 1])
    ring = cca.smooth(regular(6), closed=True, iterations=2, anchors=[0])
    np.testing.assert_array_equal(ring[0], regular(6)[0])
    assert_area_kept(regular(6), ring)
    assert ring.shape[0] == 3 * (3 * 6 - 1) - 1


# --------------------------------------------------------------------------- 3D


def _rotation(seed):
    q, _ = np.linalg.qr(np.random.default_rng(seed).normal(size=(3, 3)))
    return q


@pytest.mark.parametrize("closed", [True, False])
def test_planar_3d_equals_2d(closed):
    rng = np.random.default_rng(11)
    p2 = rng.normal(size=(10, 2))
    rot = _rotation(5)
    shift = np.array([3.0, -1.0, 2.0])
    p3 = np.column_stack([p2, np.zeros(10)]) @ rot.T + shift
    out3 = cca.smooth(p3, closed=closed, iterations=3)
    out2 = cca.smooth(p2, closed=closed, iterations=3)
    back = np.column_stack([out2, np.zeros(len(out2))]) @ rot.T + shift
    np.testing.assert_allclose(out3, back, rtol=0, atol=1e-12)


def test_nonplanar_3d_keeps_vector_area():
    rng = np.random.default_rng(2)
    t = np.linspace(0, 2 * np.pi, 11)[:-1]
    p = np.column_stack([np.cos(t), np.sin(t), 0.4 * np.sin(3 * t)]) + 0.05 * rng.normal(
        size=(10, 3)
    )
    for it in (1, 3, 5):
        out = cca.smooth(p, closed=True, iterations=it)
        assert out.shape == (10 * 3**it, 3)
        np.testing.assert_allclose(vector_area(out), vector_area(p), rtol=0, atol=1e-13)


def test_3d_equal_cuts_use_the_bisecting_plane():
    # A B C D with equal cut areas at B and C, half-planes H1, H2 at 90 degrees (Fig. 15)
    p = np.array([[0, 1, 0], [0, 0, 0], [1, 0, 0], [1, 0, 1]], dtype=float)
    out = cca.smooth(p, closed=False, alpha=0.2, restrict=False)
    g = out[4]  # V0, G0, L1, R1, G1 (apex on BC), ...
    n1, n2 = np.array([0, 1.0, 0]), np.array([0, 0, 1.0])
    m = g - np.array([0.5, 0, 0])
    assert m[0] == pytest.approx(0, abs=1e-15)
    # the apex lies in the bisecting plane, on the side away from both cuts
    np.testing.assert_allclose(m / np.linalg.norm(m), -(n1 + n2) / np.sqrt(2), atol=1e-14)
    # and its area equals half the sum of the cut areas projected onto that plane
    a = 0.2
    cut = 0.5 * a * a
    w = 0.5 * (1 - 2 * a)
    assert w * np.linalg.norm(m) == pytest.approx(cut * np.cos(np.pi / 4), rel=1e-13)


# --------------------------------------------------------------------------- degenerate input


def test_collinear_vertices_square_with_midpoints():
    sq = np.array([[0, 0], [1, 0], [2, 0], [2, 1], [2, 2], [1, 2], [0, 2], [0, 1]], dtype=float)
    for it in (1, 3, 5):
        out = cca.smooth(sq, closed=True, iterations=it)
        assert np.isfinite(out).all()
        assert_area_kept(sq, out)


def test_duplicate_points_are_removed():
    p = regular(6)
    dup = np.vstack([p[:2], p[1:2], p[2:], p[:1], p[:1]])
    np.testing.assert_allclose(
        cca.smooth(dup, closed=True, iterations=2), cca.smooth(p, closed=True, iterations=2)
    )
    q = np.array([[0, 0], [1, 1], [1, 1], [2, 0], [3, 1]], dtype=float)
    out = cca.smooth(q, closed=False, iterations=2, anchors=[2])
    assert np.any(np.all(out == [1, 1], axis=1))
    assert_area_kept(q, out)


@pytest.mark.parametrize("scale", [1e-8, 1e-3, 1.0, 1e3, 1e8])
def test_scales(scale):
    rng = np.random.default_rng(5)
    p = (regular(9, 2.0) + 0.5 * rng.normal(size=(9, 2))) * scale
    for it in (1, 3, 5):
        out = cca.smooth(p, closed=True, iterations=it)
        assert np.isfinite(out).all()
        assert_area_kept(p, out)


def test_far_from_origin_and_near_zero_edges():
    p = regular(8, 10.0) + np.array([5e5, -3e5])
    out = cca.smooth(p, closed=True, iterations=3)
    assert_area_kept(p, out, rtol=1e-9)  # coordinates at 5e5 keep ~1e-11 absolute precision
    q = regular(8)
    q = np.insert(q, 3, q[2] + [1e-13, 1e-13], axis=0)  # a near-zero edge
    for it in (1, 4):
        out = cca.smooth(q, closed=True, iterations=it)
        assert np.isfinite(out).all()
        assert_area_kept(q, out)


def test_spike_and_zero_area_polygons():
    spike = np.array([[0, 0], [2, 0], [1, 0], [1, -1]], dtype=float)  # angle 0 at (2, 0)
    for it in (1, 3):
        out = cca.smooth(spike, closed=True, iterations=it)
        assert np.isfinite(out).all()
        assert_area_kept(spike, out)
    flat = np.array([[0, 0], [1, 0], [3, 0]], dtype=float)
    out = cca.smooth(flat, closed=True, iterations=3)
    assert np.isfinite(out).all() and abs(exact_area(out)) < 1e-15


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"points": [[0, 0], [1, 1], [0, 0]], "closed": True}, "at least 3 distinct"),
        ({"points": [[1, 1], [1, 1], [1, 1], [1, 1]], "closed": True}, "at least 3 distinct"),
        ({"points": [[1, 1], [1, 1]], "closed": False}, "at least 2 distinct"),
        ({"points": [[0, 0, 0, 0]] * 4, "closed": True}, r"shape \(N, 2\) or \(N, 3\)"),
        ({"points": [[0, 0], [1, np.nan], [0, 1]], "closed": True}, "finite"),
        ({"alpha": 0.4}, r"alpha must be in \(0, 0.333333\), got 0.4"),
        ({"alpha": 0.0}, "alpha must be in"),
        ({"alpha": "circle"}, "alpha must be 'regular'"),
        ({"alpha": lambda t: 0.5 + 0 * t}, r"alpha\(angle\) must be in \[0, 1/3\), got 0.5"),
        ({"anchors": [9]}, r"anchors must be vertex indices in \[0, 4\), got 9"),
        ({"anchors": [1.5]}, "anchors must be integer"),
        ({"iterations": -1}, "iterations must be an integer >= 0, got -1"),
        ({"corner_ratio": 1.0}, "corner_ratio must be > 1, got 1"),
        ({"inflection_ratio": 1.0}, r"inflection_ratio must be in \(0, 1\), got 1"),
        ({"tilt": 2.0}, "tilt must be in"),
    ],
)
def test_bad_input_raises(kwargs, match):
    args = {"points": regular(4), "closed": True, **kwargs}
    with pytest.raises(CurveError, match=match):
        cca.smooth(**args)


# --------------------------------------------------------------------------- API details


def test_alpha_callables_and_constant():
    p = regular(7) * [1.0, 0.6]
    vec = cca.smooth(p, closed=True, alpha=cca.alpha_profile)
    scalar = cca.smooth(p, closed=True, alpha=lambda t: float(cca.alpha_profile(float(t))))
    reg = cca.smooth(p, closed=True)
    np.testing.assert_allclose(vec, reg, atol=1e-15)
    np.testing.assert_allclose(scalar, reg, atol=1e-15)
    const = cca.smooth(p, closed=True, alpha=0.25, restrict=False)
    np.testing.assert_allclose(const, reference_step(p, 0.25, True), atol=1e-14)


def test_result_is_frozen_and_consistent():
    p = regular(5)
    res = cca.smooth_with_info(p, closed=True, iterations=2)
    np.testing.assert_array_equal(res.points, cca.smooth(p, closed=True, iterations=2))
    assert res.iterations == 2 and len(res.reductions_per_step) == 2
    assert res.reductions == sum(res.reductions_per_step)
    assert res.success and res.unsatisfied == 0 and "2 CCA1 step(s)" in res.message
    with pytest.raises(FrozenInstanceError):
        res.iterations = 3  # type: ignore[misc]


def test_zero_iterations_and_input_untouched():
    p = regular(5)
    before = p.copy()
    out = cca.smooth(np.vstack([p, p[:1]]), closed=True, iterations=0)
    np.testing.assert_array_equal(out, p)
    cca.smooth(p, closed=True, iterations=2)
    np.testing.assert_array_equal(p, before)


@pytest.mark.parametrize(
    ("points", "closed", "kwargs"),
    [
        (np.random.default_rng(4).normal(size=(12, 2)), True, {}),
        (np.random.default_rng(5).normal(size=(12, 2)), False, {"anchors": [4, 7]}),
        (np.column_stack([np.arange(7.0), np.arange(7) % 2]), False, {}),  # Fig. 11 edges
        (np.array([[0, 0], [4, 0], [4, 1], [2, 1.002], [0, 1]]), True, {"alpha": 0.3}),
    ],
)
def test_compiled_2d_kernel_matches_numpy_step(points, closed, kwargs):
    lean = cca.smooth_with_info(points, closed=closed, iterations=3, **kwargs)
    generic = numpy_reference(points, closed=closed, iterations=3, **kwargs)
    np.testing.assert_allclose(lean.points, generic.points, rtol=0, atol=1e-13)
    assert lean.reductions == generic.reductions
    assert lean.fig11_edges == generic.fig11_edges


def test_min_factor_floor_reports_unsatisfied():
    p = np.array([[0, 0], [4, 0], [4, 1], [2, 1.002], [0, 1]], dtype=float)
    strict = cca.smooth_with_info(p, closed=True, iterations=2)
    floored = cca.smooth_with_info(p, closed=True, iterations=2, min_factor=0.9)
    assert strict.success and strict.unsatisfied == 0
    assert not floored.success and floored.unsatisfied > 0
    assert "restrictions not met" in floored.message
    assert_area_kept(p, floored.points)
    # the floor is honoured: the first step's cut at the sharp corner (4, 0) stays >= 0.9 alpha
    one = cca.smooth(p, closed=True, min_factor=0.9)
    a_profile = cca.alpha_profile(np.pi / 2) * 1.0  # shorter edge at (4, 0) has length 1
    cut = np.linalg.norm(one[4] - p[1])  # R_1 = V_1 + a u_1
    assert cut >= 0.9 * a_profile * (1 - 1e-12)
    with pytest.raises(CurveError, match=r"min_factor must be in \[0, 1\), got 1"):
        cca.smooth(p, closed=True, min_factor=1.0)


def test_end_edge_fig9_half_cut_and_shrinking():
    p = np.array([[0, 0], [3, 0], [4, 2]], dtype=float)
    out = cca.smooth(p, closed=False, alpha=0.25, restrict=False)
    # layout: A = V0, G (apex on the end edge), L1, R1, apex on edge 1, V2
    a_, g, l1, r1 = out[0], out[1], out[2], out[3]
    v = p[1]
    cut = 0.5 * ((v - l1)[0] * (r1 - l1)[1] - (v - l1)[1] * (r1 - l1)[0])  # signed cut at B
    aug = 0.5 * ((g - a_)[0] * (l1 - g)[1] - (g - a_)[1] * (l1 - g)[0])  # triangle A G C
    assert aug == pytest.approx(cut / 2, rel=1e-13)  # half the cut area (Fig. 9)
    assert g[1] < 0 < r1[1]  # on the opposite side of AB to the cut corner
    assert np.linalg.norm(g - a_) == pytest.approx(np.linalg.norm(g - l1), rel=1e-13)  # isosceles
    # Lemmas 12-13: end edges shrink geometrically (eventually by < 1/sqrt(2) per step)
    cur, lens = p, []
    for _ in range(6):
        cur = cca.smooth(cur, closed=False)
        lens.append(np.linalg.norm(cur[1] - cur[0]))
    ratios = np.array(lens[1:]) / np.array(lens[:-1])
    assert np.all(ratios < 1 / np.sqrt(2))


@given(random_polygons(min_n=4, max_n=9), st.data())
def test_random_anchors_keep_every_piece(p, data):
    n = len(p)
    anchors = sorted(
        set(data.draw(st.lists(st.integers(0, n - 1), min_size=1, max_size=3), label="anchors"))
    )
    out = cca.smooth(p, closed=True, iterations=2, anchors=anchors)
    assert_area_kept(p, out)
    # Anchors stay in place and in order; find each after the previous one (two anchors may
    # share coordinates, e.g. a repeated vertex).
    pos = []
    for a in anchors:
        start = pos[-1] + 1 if pos else 0
        pos.append(start + int(np.flatnonzero(np.all(out[start:] == p[a], axis=1))[0]))
    for k, a in enumerate(anchors):  # each piece against its own chord
        b = anchors[(k + 1) % len(anchors)]
        piece = p[a : b + 1] if b > a else np.vstack([p[a:], p[: b + 1]])
        s0, s1 = pos[k], pos[(k + 1) % len(pos)]
        seg = out[s0 : s1 + 1] if s1 > s0 else np.vstack([out[s0:], out[: s1 + 1]])
        assert_area_kept(piece, seg)


@given(random_polygons(min_n=3, max_n=8), st.data())
def test_duplicates_and_collinear_insertions(p, data):
    rows = []
    for i in range(len(p)):
        rows.append(p[i])
        kind = data.draw(st.sampled_from(["none", "dup", "mid"]), label=f"insert {i}")
        if kind == "dup":
            rows.append(p[i].copy())
        elif kind == "mid":
            rows.append(0.5 * (p[i] + p[(i + 1) % len(p)]))
    q = np.array(rows)
    out = cca.smooth(q, closed=True, iterations=3)
    assert np.isfinite(out).all()
    assert_area_kept(p, out)


@given(st.lists(st.tuples(coord, coord, coord), min_size=4, max_size=8), st.integers(1, 4))
def test_3d_vector_area_random(pts, iterations):
    p = np.array(pts)
    if np.linalg.norm(np.diff(p, axis=0), axis=1).min() < 1e-3:
        p = p + np.arange(len(p))[:, None] * np.array([1.0, 0.5, -0.25])
    out = cca.smooth(p, closed=True, iterations=iterations)
    assert np.isfinite(out).all()
    va0, va1 = vector_area(p), vector_area(out)
    scale = np.abs(p - p.mean(axis=0)).max() ** 2 * len(p)
    np.testing.assert_allclose(va1, va0, rtol=0, atol=1e-13 * scale)


def test_anchor_on_repeated_closing_vertex():
    ring = np.vstack([regular(6), regular(6)[:1]])
    a = cca.smooth(ring, closed=True, iterations=2, anchors=[6])
    b = cca.smooth(regular(6), closed=True, iterations=2, anchors=[0])
    np.testing.assert_array_equal(a, b)
    with pytest.raises(CurveError, match=r"anchors must be vertex indices in \[0, 6\), got 6"):
        cca.smooth(regular(6), closed=True, anchors=[6])


def test_subnormal_bend_does_not_overflow():
    # Regression (found by the geo property tests): a vertex bent by a subnormal offset made
    # tan(beta) overflow in the restriction pass, a RuntimeWarning (an error under pytest).
    p = np.array([[0, 0], [1, 2.2e-309], [2, 0], [3, 0]])
    out = cca.smooth(p, closed=False)
    assert np.isfinite(out).all()
    assert_area_kept(p, out)
    ring = np.array([[0, 0], [1, 2.2e-309], [2, 0], [2, 1]])
    out = cca.smooth(ring, closed=True, iterations=3)
    assert np.isfinite(out).all()
    assert_area_kept(ring, out)


def _jagged_ring(n, seed, spikes=0):
    rng = np.random.default_rng(seed)
    t = 2 * np.pi * np.arange(n) / n
    r = 1 + 0.3 * rng.uniform(size=n)
    r[rng.integers(0, n, spikes)] += 2.0  # a few sharp spikes among gentle wiggles
    return np.column_stack([r * np.cos(t), r * np.sin(t)])


@pytest.mark.parametrize(
    ("points", "closed", "kwargs"),
    [
        # many decreases (masked whole-array passes), then few (gathered edge subsets)
        (_jagged_ring(3000, 11), True, {}),
        (regular(3000) * (1 + 0.02 * np.sin(np.arange(3000))[:, None]), True, {}),
        # a few decreases among many vertices, some stuck at the floor (unsatisfied > 0)
        (np.vstack([regular(2500), [[0.0, 0.0]]]), True, {"min_factor": 0.5}),
        (_jagged_ring(2000, 12, spikes=5), False, {"anchors": [100, 900]}),
        (_jagged_ring(2000, 13), True, {"max_passes": 2}),
    ],
)
def test_compiled_2d_kernel_matches_numpy_step_large(points, closed, kwargs):
    # the compiled kernel against the whole-array numpy step: the same arithmetic, so with
    # the same atan2 and tan the same bits (numpy's SIMD atan2 may differ in the last ulp,
    # which the ill-conditioned decrease of an inflection edge can amplify to 1e-12)
    lean = cca.smooth_with_info(points, closed=closed, iterations=3, **kwargs)
    generic = numpy_reference(points, closed=closed, iterations=3, libm=True, **kwargs)
    assert lean.points.shape == generic.points.shape
    np.testing.assert_array_equal(lean.points, generic.points)
    assert lean.reductions_per_step == generic.reductions_per_step
    assert lean.fig11_edges == generic.fig11_edges
    assert lean.unsatisfied == generic.unsatisfied
    assert lean.reductions > 0


def test_profile_fast_path_matches_piecewise_evaluation():
    # large arrays take the scalar last-piece path; compare with scipy's PCHIP itself
    theta = np.concatenate(
        [np.linspace(0.0, np.pi, 5001), cca.profile_nodes()[0], np.full(70, 5 * np.pi / 6)]
    )
    x, y = cca.profile_nodes()
    ref = PchipInterpolator(x, y)(theta)
    got = cca.alpha_profile(theta)
    np.testing.assert_allclose(got, ref, rtol=0, atol=1e-15)
    small = np.array([cca.alpha_profile(float(t)) for t in theta[::97]])
    np.testing.assert_array_equal(small, got[::97])


def test_closed_must_be_a_bool_and_iterations_are_capped(monkeypatch):
    # Regressions from acceptance testing: closed="no" was truthy (smoothed as a ring) and
    # iterations=30 tried to build 3^30 vertices instead of failing.
    p = [[0, 0], [1, 2], [2, 0], [3, 1], [4, 0]]
    for bad in ("no", None, 1):
        with pytest.raises(CurveError, match="closed must be True or False"):
            cca.smooth(p, closed=bad)
    monkeypatch.setattr(validate, "MAX_VERTICES", 100)
    assert cca.smooth(p, closed=True, iterations=2).shape[0] <= 100
    with pytest.raises(CurveError, match=r"at most 100 output vertices, got 3 \(step 3"):
        cca.smooth(p, closed=True, iterations=3)


# --------------------------------------------------------------------------- long curves, threads


def _noisy_line(n, seed):
    rng = np.random.default_rng(seed)
    return np.column_stack([np.arange(n) * 1.0, np.cumsum(rng.normal(size=n))])


@pytest.mark.parametrize(
    ("points", "closed", "kwargs"),
    [
        (_jagged_ring(1500, 21, spikes=6), True, {}),
        (_jagged_ring(1500, 22), True, {"min_factor": 0.9}),  # floors: unsatisfied edges
        (_jagged_ring(1300, 23), True, {"max_passes": 2}),
        (_jagged_ring(1200, 24), True, {"anchors": [0, 5, 640, 1199]}),
        (_jagged_ring(1000, 25), True, {"alpha": 0.3}),
        (regular(900) * (1 + 0.05 * np.sin(np.arange(900))[:, None]), True, {}),
        (_noisy_line(1400, 26), False, {}),
        (_noisy_line(1100, 27), False, {"anchors": [300, 301, 700]}),
        # zigzag: every edge an inflection edge with balanced cuts (Fig. 11)
        (np.column_stack([np.arange(1000.0), np.arange(1000) % 2]), False, {}),
        (np.column_stack([np.arange(1000.0), np.arange(1000) % 2]), True, {}),
    ],
)
def test_kernel_matches_numpy_step_on_long_curves(points, closed, kwargs):
    # compiled kernel against the numpy reference on long curves with floors, pass limits,
    # anchors and Fig. 11 edges: the same counts and (with the same trig) the same bits
    res = cca.smooth_with_info(points, closed=closed, iterations=3, threads=1, **kwargs)
    ref = numpy_reference(points, closed=closed, iterations=3, libm=True, **kwargs)
    assert res.points.shape == ref.points.shape
    np.testing.assert_array_equal(res.points, ref.points)
    assert res.reductions_per_step == ref.reductions_per_step
    assert res.fig11_edges == ref.fig11_edges
    assert res.unsatisfied == ref.unsatisfied
    if "min_factor" in kwargs:
        assert res.unsatisfied > 0
    if "alpha" not in kwargs and "anchors" not in kwargs:
        assert res.reductions > 0 or res.fig11_edges > 0


def test_thread_groups_are_bit_identical(monkeypatch):
    # a batch split into groups of whole curves, one per thread: the same bits and counts

    curves = [_jagged_ring(300 + 7 * k, 40 + k, spikes=2) for k in range(9)]
    xy = np.concatenate(curves)
    off = np.concatenate([[0], np.cumsum([len(c) for c in curves])])
    one = cca.smooth_ragged_with_info(xy, off, closed=True, iterations=2, threads=1)
    monkeypatch.setattr(cca_api, "THREAD_MIN", 100)
    assert len(cca_chunks(off, 3)) == 3
    three = cca.smooth_ragged_with_info(xy, off, closed=True, iterations=2, threads=3)
    np.testing.assert_array_equal(three.coords, one.coords)
    np.testing.assert_array_equal(three.offsets, one.offsets)
    np.testing.assert_array_equal(three.reductions, one.reductions)
    assert one.reductions.sum() > 0


def test_threads_is_validated():
    with pytest.raises(CurveError, match="threads must be an integer >= 1, got 0"):
        cca.smooth(regular(5), closed=True, threads=0)
    with pytest.raises(CurveError, match="threads must be an integer"):
        cca.smooth(regular(5), closed=True, threads=1.5)
    assert 1 <= cca_input.default_threads() <= 4


def test_default_threads_respects_omp_num_threads(monkeypatch):
    monkeypatch.setenv("OMP_NUM_THREADS", "1")
    assert cca_input.default_threads() == 1
    monkeypatch.setenv("OMP_NUM_THREADS", "64")
    assert cca_input.default_threads() == min(4, len(os.sched_getaffinity(0)))
    monkeypatch.setenv("OMP_NUM_THREADS", "auto")  # not a count: ignored
    assert cca_input.default_threads() == min(4, len(os.sched_getaffinity(0)))


def _restriction_inputs(p):
    """Per-vertex inputs of the restriction pass for a closed polygon, in plain numpy."""
    e = np.roll(p, -1, axis=0) - p
    length = np.hypot(e[:, 0], e[:, 1])
    u = e / length[:, None]
    up = np.roll(u, 1, axis=0)
    cr = up[:, 0] * u[:, 1] - up[:, 1] * u[:, 0]
    dot = np.sum(up * u, axis=1)
    alpha = cca.alpha_profile(np.arctan2(np.abs(cr), -dot))
    short = np.minimum(length, np.roll(length, 1))
    return alpha, 0.5 * short * short, cr, np.abs(cr), dot, short, length


def _violated_edges(alpha, half_a2, cr, scross, dot, short, length, c, C, rtol):
    """Edges of a closed polygon that break Definition 2 / section 3.2 by more than rtol."""
    n = len(alpha)
    a = alpha * short
    K = alpha * alpha * half_a2 * cr
    tanb = [(1 + dot[i]) / scross[i] if scross[i] > 0 else 0.0 for i in range(n)]
    count = 0
    for i in range(n):
        j = (i + 1) % n
        w = 0.5 * (length[i] - a[i] - a[j])
        net = abs(K[i] + K[j])
        if K[i] * K[j] > 0 and w * w < 0.5 * c * max(tanb[i], tanb[j]) * net * (1 - rtol):
            count += 1
        if K[i] * K[j] < 0:
            m = j if abs(K[j]) <= abs(K[i]) else i
            tau = math.atan2(scross[m], dot[m])
            count += net > 2 * w * w * math.tan(0.5 * C * tau) * (1 + rtol)
    return count


@pytest.mark.parametrize("seed", [60, 61, 62, 63])
def test_unsatisfied_counts_every_violated_edge(seed):
    # Regression: an edge stuck at the floor while other vertices still moved was not
    # rechecked and dropped from the count (seed 60: 33 violated edges reported as 0).
    rng = np.random.default_rng(seed)
    t = 2 * np.pi * np.arange(167) / 167
    r = 1 + 0.3 * rng.uniform(size=167)
    r[rng.integers(0, 167, 3)] += 2.0
    r[rng.integers(0, 167, 5)] *= 0.2
    p = np.column_stack([r * np.cos(t), r * np.sin(t)])
    inputs = _restriction_inputs(p)
    fixed = np.zeros(167, dtype=bool)
    on, limits = np.ones(167, dtype=bool), (16, 0.95)
    with np.errstate(all="ignore"):
        alpha, _, generic, _, _ = cca_restrict.restrict_passes(
            inputs[0], inputs[1], [inputs[2]], *inputs[3:], fixed, on, 2.0, 0.5, limits
        )
    lean = cca_kernel.restrict_curve(*inputs, fixed, True, 2.0, 0.5, limits)
    np.testing.assert_array_equal(lean[0], alpha)
    strict = _violated_edges(alpha, *inputs[1:], 2.0, 0.5, rtol=1e-9)
    loose = _violated_edges(alpha, *inputs[1:], 2.0, 0.5, rtol=-1e-9)
    assert strict == loose  # no edge within 1e-9 of its bound: the count is unambiguous
    assert generic == lean[2] == strict
    res = cca.smooth_with_info(p, closed=True, min_factor=0.95)
    assert res.unsatisfied == strict and res.success == (strict == 0)
    if seed == 60:
        assert strict == 33 and not res.success


@pytest.mark.parametrize("scale", [1e-170, 1e-300, 1e200, 1e300])
def test_extreme_scales_are_smoothed_like_unit_scale(scale):
    # Regression: at 1e-170 every squared edge length underflowed to 0, the step saw
    # zero-length edges that compacting could not remove, and recursed without end.
    # Such inputs are scaled by a power of two (exact), which CCA1 commutes with.
    t = 2 * np.pi * np.arange(60) / 60
    p = np.c_[np.cos(t), np.sin(t)] * (1 + 0.2 * np.sin(5 * t))[:, None] * scale
    e = math.frexp(float(np.abs(p).max()))[1]
    out = cca.smooth(p, closed=True, iterations=2)
    np.testing.assert_array_equal(
        out, np.ldexp(cca.smooth(np.ldexp(p, -e), closed=True, iterations=2), e)
    )
    assert np.isfinite(out).all() and out.shape == (540, 2)
    assert_area_kept(np.ldexp(p, -e), np.ldexp(out, -e))
    line = cca.smooth(p[:20], closed=False, anchors=[7], iterations=2)
    np.testing.assert_array_equal(line[[0, -1]], p[[0, 19]])  # fixed vertices bit-exact


def test_edge_whose_square_underflows_counts_as_a_duplicate():
    # Two vertices 1e-170 apart on a unit ring: the steps see a zero-length edge, so the
    # duplicate removal must too (it compared coordinates for equality and kept both).
    t = 2 * np.pi * np.arange(40) / 40
    p = np.c_[np.cos(t), np.sin(t)]
    q = np.insert(p, 6, p[6] + [1e-170, 0.0], axis=0)
    np.testing.assert_array_equal(
        cca.smooth(q, closed=True, iterations=2), cca.smooth(p, closed=True, iterations=2)
    )
    ring = np.array([[0.0, 0.0], [1e-170, 0.0], [1.0, 0.0], [1.0, 1.0]])  # via the origin
    out = cca.smooth(ring, closed=True, iterations=3)
    assert np.isfinite(out).all()
    assert_area_kept(ring, out)


@pytest.mark.parametrize(
    ("points", "closed", "kwargs"),
    [
        (_jagged_ring(1500, 21, spikes=6), True, {}),
        (_jagged_ring(1500, 22), True, {"min_factor": 0.9}),  # floors: unsatisfied edges
        (_jagged_ring(1300, 23), True, {"max_passes": 2}),
        (_jagged_ring(1200, 24), True, {"anchors": [0, 5, 640, 1199]}),
        (_jagged_ring(1000, 25), True, {"alpha": 0.3}),
        (_jagged_ring(1000, 30), True, {"alpha": lambda ang: 0.1 + 0.05 * np.cos(ang)}),
        (_noisy_line(1400, 26), False, {}),
        (_noisy_line(1100, 27), False, {"anchors": [300, 301, 700]}),
        (np.column_stack([np.arange(1000.0), np.arange(1000) % 2]), False, {}),  # Fig. 11
        (np.column_stack([np.arange(1000.0), np.arange(1000) % 2]), True, {}),
    ],
)
def test_blocks_of_long_curves_are_bit_identical(monkeypatch, points, closed, kwargs):
    # Blocks of 128 core vertices (halos of max_passes + 8) instead of 32768: the same
    # arithmetic element by element, so the same bits and counts, in 1 or 3 threads.

    whole = cca.smooth_with_info(points, closed=closed, iterations=3, **kwargs)
    monkeypatch.setattr(cca_api, "BLOCK", 128)
    monkeypatch.setattr(cca_api, "THREAD_MIN", 100)
    for workers in (1, 3):
        res = cca.smooth_with_info(points, closed=closed, iterations=3, threads=workers, **kwargs)
        np.testing.assert_array_equal(res.points, whole.points)
        assert res.reductions_per_step == whole.reductions_per_step
        assert res.fig11_edges == whole.fig11_edges
        assert res.unsatisfied == whole.unsatisfied
    assert len(cca_blocks(np.array([0, len(points)]), np.array([closed]), 24)[1]) > 5


def test_blocks_with_zero_length_edges(monkeypatch):
    # a duplicate vertex is removed before blocking; a ring passing twice through one
    # point gives a block whose own wrap edge has zero length: the whole curve runs

    p = _jagged_ring(900, 28)
    dup = np.insert(p, 300, p[300], axis=0)
    twice = p.copy()
    twice[279] = twice[104]
    wants = [cca.smooth(q, closed=True, iterations=2) for q in (dup, twice)]
    monkeypatch.setattr(cca_api, "BLOCK", 128)
    for q, want in zip((dup, twice), wants, strict=True):
        np.testing.assert_array_equal(cca.smooth(q, closed=True, iterations=2), want)
    xy = np.concatenate([dup, p[:50], twice])
    off = np.array([0, len(dup), len(dup) + 50, len(xy)])
    out, oo = cca.smooth_ragged(xy, off, closed=True, iterations=2, close_rings=True)
    np.testing.assert_array_equal(out[oo[0] : oo[1] - 1], wants[0])
    np.testing.assert_array_equal(out[oo[2] : oo[3] - 1], wants[1])
    assert (out[oo[1:] - 1] == out[oo[:-1]]).all()


def test_blocks_with_an_edge_of_zero_length_only_in_the_curves_frame(monkeypatch):
    # two vertices 1e-11 apart near the origin coincide once the first vertex (1e6 away)
    # is subtracted: the input check does not see the edge, a block does and gives up,
    # and the whole curve runs (compacting it), as without blocks

    p = _jagged_ring(900, 28)
    p[0] = [1e6, 0.0]
    p[301] = p[300] + [1e-11, 0.0]
    want = cca.smooth_with_info(p, closed=True, iterations=2)
    monkeypatch.setattr(cca_api, "BLOCK", 128)
    monkeypatch.setattr(cca_api, "THREAD_MIN", 100)
    for workers in (1, 2):
        res = cca.smooth_with_info(p, closed=True, iterations=2, threads=workers)
        np.testing.assert_array_equal(res.points, want.points)
        assert res.reductions_per_step == want.reductions_per_step
    out, _ = cca.smooth_ragged(p, [0, len(p)], closed=True, iterations=2)
    np.testing.assert_array_equal(out, want.points)


def test_thread_group_with_a_few_fig11_edges(monkeypatch):
    # A rectangle whose bottom side has a step: the step's edge is a balanced inflection
    # edge (Fig. 11: two rows instead of one), in the first thread group. That group gets
    # the rows of the common case only, so it stops at the block that does not fit, whose
    # rest runs into a buffer of its own; the next group's rows move to later rows to make
    # room (in place) and the rest is copied in: the same bits as one thread, no blocks.

    bottom = np.c_[np.arange(600.0), (np.arange(600) > 300).astype(float)]
    right = np.c_[np.full(100, 600.0), np.linspace(0.0, 100.0, 100, endpoint=False) + 1]
    top = np.c_[np.arange(600.0, 0.0, -1.0), np.full(600, 101.0)]
    left = np.c_[np.zeros(100), np.linspace(101.0, 1.0, 100)]
    ring = np.concatenate([bottom, right, top, left])
    want = cca.smooth_with_info(ring, closed=True, iterations=2, threads=1)
    assert want.fig11_edges > 0
    monkeypatch.setattr(cca_api, "BLOCK", 128)
    monkeypatch.setattr(cca_api, "THREAD_MIN", 100)
    for workers in (2, 3):
        res = cca.smooth_with_info(ring, closed=True, iterations=2, threads=workers)
        np.testing.assert_array_equal(res.points, want.points)
        assert res.fig11_edges == want.fig11_edges
        xy = np.concatenate([ring, ring[:7]])
        out, oo = cca.smooth_ragged(
            xy, [0, len(ring), len(xy)], closed=True, iterations=2, threads=workers,
            close_rings=True,
        )  # fmt: skip
        np.testing.assert_array_equal(out[oo[0] : oo[1] - 1], want.points)
        assert (out[oo[1:] - 1] == out[oo[:-1]]).all()


@pytest.mark.parametrize("iterations", [0, 1])
def test_input_is_read_not_copied_nor_shared(iterations):
    # smooth reads a float64 input in place (no copy of a long curve); the result never
    # shares its memory, also with 0 steps and a repeated closing vertex; the input is
    # unchanged, and a read-only input works too

    a = np.array([[0.0, 0.0], [2.0, 0.0], [2.0, 1.0], [0.0, 1.0], [0.0, 0.0]])
    before = a.copy()
    out = cca.smooth(a, closed=True, iterations=iterations)
    assert not np.shares_memory(out, a)
    np.testing.assert_array_equal(a, before)
    a.setflags(write=False)
    np.testing.assert_array_equal(cca.smooth(a, closed=True, iterations=iterations), out)


def test_import_does_not_load_numba():
    # the kernel is compiled (or loaded from numba's cache) on first use, not at import:
    # `import curvesmith` and `curvesmith --help` stay fast
    import subprocess
    import sys

    code = (
        "import sys, curvesmith, curvesmith.cca, curvesmith.subdivision\n"
        "import curvesmith.cli, curvesmith.geo\n"
        "assert 'numba' not in sys.modules, 'numba imported'\n"
    )
    subprocess.run([sys.executable, "-c", code], check=True, timeout=120)


@pytest.mark.parametrize("alpha", ["regular", 0.2])
@pytest.mark.parametrize("restrict", [True, False])
def test_kernel_step_is_the_numpy_step_on_curves_of_one_to_five_vertices(alpha, restrict):
    # In a tiny curve every vertex is the first or the last one (or both), whose cuts the
    # kernel computes apart from the middle ones' (their neighbours wrap around): each
    # unit of 1-5 vertices, open and closed, with anchors, repeated points, sharp turns
    # and inflections, gives the numpy step's bits and counts.
    rng = np.random.default_rng(17)
    alpha_fn = cca_api.alpha_function(alpha)
    brk, coef = cca_api.profile_tables()
    if alpha == "regular":
        mode, const = cca_kernel.MODE_REGULAR, 0.0
    else:
        mode, const = cca_kernel.MODE_CONSTANT, float(alpha)
    saved = cca_stepnd.np, cca_restrict.np
    cca_stepnd.np = cca_restrict.np = _LibmTrig()  # the C library's atan2 and tan
    emitted = 0
    try:
        for trial in range(400):
            n = 1 + trial % 5
            closed = bool(trial // 5 % 2)
            P = rng.normal(size=(n, 2)) * 10.0 ** float(rng.integers(-3, 4))
            if trial % 3 == 0 and n > 2:
                P[rng.integers(1, n)] = P[0]  # a repeated point: the curve is compacted
            fixed = rng.random(n) < 0.15
            table = cca_kernel.curve_units(np.array([0, n]), np.array([closed]))
            out, out_fixed = cca_api.output_buffers(4 * n + 2)
            zero = np.zeros((1, 2))
            res = cca_kernel.step_units(
                P, fixed, np.zeros(0), zero, zero, table, mode, const, brk, coef, restrict,
                2.0, 0.5, np.pi / 16, 1e-9, 16, 0.0, out, out_fixed, False, False,
            )  # fmt: skip
            assert res[7] == cca_kernel.DONE
            with np.errstate(all="ignore"):
                cols, f, nred, nfig, nunsat = cca_stepnd.step(
                    [P[:, 0].copy(), P[:, 1].copy()], fixed, closed, alpha_fn, restrict,
                    2.0, 0.5, np.pi / 16, 1e-9, (16, 0.0),
                )  # fmt: skip
            np.testing.assert_array_equal(res[0][: res[2]], np.column_stack(cols), str(trial))
            np.testing.assert_array_equal(res[1][: res[2]], f)
            assert (res[4][0], res[5][0], res[6][0]) == (nred, nfig, nunsat)
            emitted += res[2] > n  # some vertex was cut
    finally:
        cca_stepnd.np, cca_restrict.np = saved
    assert emitted > 200  # the cuts ran, not only kept vertices


def test_first_pass_filter_keeps_every_edge_near_the_inflection_bounds():
    # The first restriction pass checks only the edges that a vector loop marks: those
    # whose |K1 + K2| a lower bound of tan(C/2 tau) does not clear. Inflection edges placed
    # within a few ulps of that bound, and of the rule's own bound 2 w^2 tan(C/2 tau), are
    # decided as numpy's restriction decides them (small turns: the two bounds are close).
    rng = np.random.default_rng(23)
    saved = cca_stepnd.np, cca_restrict.np
    cca_stepnd.np = cca_restrict.np = _LibmTrig()
    decided = 0
    try:
        for trial in range(1200):
            n = int(rng.choice([3, 4, 7, 12]))
            cr = 10.0 ** rng.uniform(-9, -0.3, n) * np.where(np.arange(n) % 2, -1.0, 1.0)
            dot = np.sqrt(1 - cr * cr) * np.where(rng.random(n) < 0.9, 1.0, -1.0)
            scross = np.abs(cr)
            alpha = rng.uniform(0.05, 0.3, n)
            short = rng.uniform(0.5, 2.0, n)
            half = 0.5 * short * short
            a, K = alpha * short, alpha * alpha * half * cr
            length = 2.0 * short + rng.uniform(0, 1, n)
            C = float(rng.choice([0.5, 1.0, rng.uniform(0.05, 1.0)]))
            for i in range(n):
                j = (i + 1) % n
                if not K[i] * K[j] < 0:
                    continue
                m = j if abs(K[j]) <= abs(K[i]) else i
                sm, dm = scross[m], dot[m]
                low = 0.5 * C * (sm / (dm + sm) if dm > 0.0 else np.pi / 2)
                th = math.tan(0.5 * C * math.atan2(sm, dm))
                bound = [low * (1.0 - 1e-9), th * (1.0 + 1e-12), th][trial % 3]
                w = math.sqrt(abs(K[i] + K[j]) / (2.0 * bound))
                edge = 2.0 * w + a[i] + a[j]
                for _ in range(int(rng.integers(0, 5))):
                    edge = np.nextafter(edge, np.inf if rng.random() < 0.5 else -np.inf)
                length[i] = edge
                decided += 1
            fixed = np.zeros(n, dtype=bool)
            limits = (16, 0.0)
            lean = cca_kernel.restrict_curve(
                alpha, half, cr, scross, dot, short, length, fixed, True, 2.0, C, limits
            )
            with np.errstate(all="ignore"):
                ref, nred, nunsat, _, _ = cca_restrict.restrict_passes(
                    alpha.copy(), half, [cr], scross, dot, short, length, fixed,
                    np.ones(n, dtype=bool), 2.0, C, limits,
                )  # fmt: skip
            np.testing.assert_array_equal(lean[0], ref, str(trial))
            assert lean[1:] == (nred, nunsat), trial
    finally:
        cca_stepnd.np, cca_restrict.np = saved
    assert decided > 3000
