"""curves.fit: fewest G2 quadratic (cubic) Bézier segments within a tolerance, areas exact."""

import json

import numpy as np
import pytest
from click.testing import CliRunner
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.integrate import quad

from curvesmith import affine, cca, curves, signed_area
from curvesmith.cli import main
from curvesmith.errors import CurveError
from curvesmith.internals import CurvePiece, distance_to_polyline
from curvesmith.io.svg import bezier_path_data, path_document, read_bezier_paths


def naive_area(segments, closed):
    """1/2 of the integral of det(B, B') along the path, by quadrature (plain reference)."""
    from math import comb

    total = 0.0
    for s in np.asarray(segments, float):
        d = len(s) - 1

        def integrand(t, s=s, d=d):
            b = sum(comb(d, i) * t**i * (1 - t) ** (d - i) * s[i] for i in range(d + 1))
            db = sum(
                d * comb(d - 1, i) * t**i * (1 - t) ** (d - 1 - i) * (s[i + 1] - s[i])
                for i in range(d)
            )
            return 0.5 * (b[0] * db[1] - b[1] * db[0])

        total += quad(integrand, 0, 1, epsabs=1e-13)[0]
    if not closed:  # close along the chord from the end back to the start
        a, b = segments[-1][-1], segments[0][0]
        total += 0.5 * (a[0] * b[1] - a[1] * b[0])
    return total


def ellipse(n=800, a=30.0, b=20.0):
    u = np.linspace(0, 2 * np.pi, n, endpoint=False)
    return np.c_[a * np.cos(u), b * np.sin(u)]


def test_bezier_area_matches_quadrature_for_quadratics_and_cubics():
    rng = np.random.default_rng(4)
    q = rng.normal(size=(5, 3, 2))
    q[1:, 0] = q[:-1, 2]
    for closed in (False, True):
        if closed:
            q[-1, 2] = q[0, 0]
        ref = naive_area(q, closed)
        assert curves.bezier_area(q, closed=closed) == pytest.approx(ref, rel=1e-12, abs=1e-13)
        assert curves.bezier_area(curves.elevate(q), closed=closed) == pytest.approx(ref, rel=1e-12)


def test_elevation_is_exact():
    q = np.random.default_rng(2).normal(size=(4, 3, 2))
    np.testing.assert_allclose(
        curves.sample_segments(curves.elevate(q), 7), curves.sample_segments(q, 7), atol=1e-14
    )


def test_closed_ellipse_fewest_segments_area_exact_and_g2():
    p = ellipse()
    counts = []
    for tol in (0.5, 0.05, 0.005):
        f = curves.fit(p, closed=True, tolerance=tol)
        assert f.success and f.deviation <= tol
        assert abs(f.area / f.target_area - 1) < 1e-12
        assert f.g2_defect < 1e-9 and f.inflections.size == 0
        assert affine.is_affine_arc_length(f.controls[0], closed=True, rtol=1e-8)
        counts.append(f.count)
        # one segment fewer does not meet the tolerance (the affine construction with one
        # control vertex less)
        try:
            seg, _, _ = CurvePiece(p, "ring").build(f.count - 1)
        except CurveError:  # 4 vertices do not close on this ellipse
            continue
        assert curves.bezier_deviation(seg, p, closed=True) > tol
    assert counts == sorted(counts) and counts[0] <= 6 and counts[-1] <= 16


def test_quarter_circle_ends_on_its_corners_and_is_g2():
    t = np.linspace(0, np.pi / 2, 400)
    p = 100 * np.c_[np.cos(t), np.sin(t)]
    f = curves.fit(p, closed=False, tolerance=0.01)
    assert f.success and f.count <= 8  # without the outward offset rounds: 52
    np.testing.assert_allclose(f.segments[0, 0], p[0], atol=1e-12)
    np.testing.assert_allclose(f.segments[-1, -1], p[-1], atol=1e-12)
    assert f.g2_defect < 1e-8
    assert abs(f.area / f.target_area - 1) < 1e-12  # area against the chord
    # the end segments: same curvature as their neighbours (the 1/sqrt 2 construction)
    left, right = curves.joint_curvatures(f.segments, closed=False)
    np.testing.assert_allclose(left, right, rtol=1e-8)
    np.testing.assert_allclose(np.abs(left), 1 / 100, rtol=0.05)  # 7 parabolas on a circle


def test_cubic_output_is_the_same_curve():
    p = ellipse(600, 5.0, 3.0)
    q = curves.fit(p, closed=True, tolerance=1e-3)
    c = curves.fit(p, closed=True, tolerance=1e-3, degree=3)
    assert c.segments.shape == (q.count, 4, 2)
    np.testing.assert_allclose(curves.elevate(q.segments), c.segments, atol=1e-12)
    assert c.area == pytest.approx(c.target_area, rel=1e-12)
    assert c.g2_defect < 1e-9


@pytest.mark.slow
def test_closed_curve_with_inflections_and_cca_input_keeps_area():
    th = np.linspace(0, 2 * np.pi, 1000, endpoint=False)
    r = 1 + 0.35 * np.cos(2 * th)
    bean = 50 * np.c_[r * np.cos(th), 0.7 * r * np.sin(th)]
    # by default the nearly straight stretches around the inflections become lines
    lined = curves.fit(bean, closed=True, tolerance=0.5)
    assert lined.success and lined.deviation <= 0.5 and lined.corners.size == 8
    assert abs(lined.area / lined.target_area - 1) < 1e-12
    # without lines, the inflections are joints of the spline
    f = curves.fit(bean, closed=True, tolerance=0.5, lines=False)
    assert f.success and f.deviation <= 0.5
    assert lined.count < f.count
    assert abs(f.area / f.target_area - 1) < 1e-12
    assert f.inflections.size == 8  # two joints at each of the 4 inflections
    assert 1 < f.inflection_jump <= 2
    # G2 at every joint away from the inflections (measured 6e-11): the pieces of the
    # construction join on the curve, and the closing vertex lands on the start
    left, right = curves.joint_curvatures(f.segments, closed=True)
    jump = np.abs(left - right) / np.maximum(np.abs(left), np.abs(right))
    keep = np.ones(jump.size, bool)
    keep[f.inflections - 1] = False
    assert jump[keep].max() < 1e-8
    assert f.g2_defect == pytest.approx(jump[keep].max())
    assert np.all(jump[~keep] > 1e-3)


def test_anchors_stay_corners_and_pieces_keep_area():
    # a cca-smoothed "D": the two corners of the straight side are anchors
    d = np.array([[0, 0], [4, 0], [7, 1], [8, 4], [7, 7], [4, 8], [0, 8]], float) * 10
    smooth = cca.smooth(d, closed=True, iterations=4, anchors=[0, 6])
    a0 = int(np.flatnonzero(np.all(smooth == d[0], axis=1))[0])
    a6 = int(np.flatnonzero(np.all(smooth == d[6], axis=1))[0])
    f = curves.fit(smooth, closed=True, tolerance=0.2, anchors=[a0, a6])
    assert f.success, f.message
    on = f.segments[:, 0]
    assert any(np.array_equal(o, d[0]) for o in on) and any(np.array_equal(o, d[6]) for o in on)
    assert f.corners.size >= 2  # the anchors, and the ends of the straight runs of cca's output
    # the tangent is free at a corner: the directions differ
    kept = [c for c in f.corners if any(np.array_equal(f.segments[c, 0], d[i]) for i in (0, 6))]
    assert len(kept) == 2
    for c in kept:
        t_in = f.segments[c - 1, -1] - f.segments[c - 1, -2]
        t_out = f.segments[c, 1] - f.segments[c, 0]
        cos = t_in @ t_out / np.hypot(*t_in) / np.hypot(*t_out)
        assert cos < 0.99
    assert abs(f.area / f.target_area - 1) < 1e-12
    assert f.area == pytest.approx(
        cca.signed_area(d)
        if hasattr(cca, "signed_area")
        else 0.5 * np.sum(d[:, 0] * np.roll(d[:, 1], -1) - np.roll(d[:, 0], -1) * d[:, 1]),
        rel=1e-12,
    )


def test_svg_path_round_trip():
    f = curves.fit(ellipse(), closed=True, tolerance=0.05)
    for seg in (f.segments, curves.elevate(f.segments)):
        doc = path_document([bezier_path_data(seg, closed=True)], ((-30, -20), (30, 20)))
        ((back, closed),) = read_bezier_paths(doc)
        assert closed
        np.testing.assert_array_equal(back, seg)


@settings(max_examples=8, deadline=None)
@given(st.integers(0, 10_000), st.floats(0.05, 2.0))
def test_property_random_convex_closed_curves(seed, tol):
    rng = np.random.default_rng(seed)
    m = rng.normal(size=(2, 2)) + 2 * np.eye(2)
    p = ellipse(500, 20, 20) @ m.T + rng.uniform(-1e3, 1e3, 2)
    f = curves.fit(p, closed=True, tolerance=tol)
    assert f.success and f.deviation <= tol
    assert abs(f.area / f.target_area - 1) < 1e-12
    assert f.g2_defect < 1e-7


def test_bad_arguments():
    p = ellipse()
    with pytest.raises(CurveError, match="tolerance must be > 0, got 0"):
        curves.fit(p, closed=True, tolerance=0)
    with pytest.raises(CurveError, match="degree must be 2 or 3, got 4"):
        curves.fit(p, closed=True, tolerance=1, degree=4)
    with pytest.raises(CurveError, match="anchors must be vertex indices"):
        curves.fit(p, closed=True, tolerance=1, anchors=[5000])
    # a straight open curve is one straight segment; a curved one needs affine arc length
    line = curves.fit(np.c_[np.arange(50.0), 2 * np.arange(50.0)], closed=False, tolerance=0.1)
    assert line.count == 1 and line.deviation < 1e-12


# ---------------------------------------------------------------- CLI


STAR = (
    '<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 200 200">'
    '<polygon id="star" points="100,10 120,70 190,75 135,115 155,185 100,145 45,185 65,115 '
    '10,75 80,70"/></svg>'
)


LOGO = """<?xml version="1.0" encoding="UTF-8"?>
<svg xmlns="http://www.w3.org/2000/svg" width="200" height="120" viewBox="0 0 200 120">
  <title>logo</title>
  <defs><linearGradient id="g"><stop offset="0" stop-color="red"/></linearGradient></defs>
  <g id="shapes" transform="translate(10,5) scale(2)">
    <polygon id="star" class="brand" fill="url(#g)" stroke="navy" points="20,2 26,18 44,18
      30,28 35,45 20,35 5,45 10,28 -4,18 14,18"/>
    <path id="wave" fill="none" stroke="green" d="M 50 10 L 60 20 L 70 8 L 80 22 L 90 6"/>
  </g>
  <text x="10" y="110" font-family="sans-serif">Curvesmith</text>
</svg>
"""


@pytest.mark.parametrize("kind", ["quadratic", "cubic"])
def test_cli_smooth_curves_keeps_the_svg_document(tmp_path, kind):
    # --curves wrote a new document of bare paths: ids, classes, paint, the group's
    # transform, text and defs were lost, where plain smooth keeps them
    import xml.etree.ElementTree as ET

    from curvesmith.io import read_curves

    src, out = tmp_path / "logo.svg", tmp_path / "out.svg"
    src.write_text(LOGO)
    args = ["smooth", str(src), "-o", str(out), "--curves", kind, "--iterations", "5"]
    r = CliRunner().invoke(main, args)
    assert r.exit_code == 0, r.output
    ns = {"s": "http://www.w3.org/2000/svg"}
    root = ET.parse(out).getroot()
    assert root.get("viewBox") == "0 0 200 120" and root.find("s:title", ns).text == "logo"
    assert root.find("s:defs/s:linearGradient", ns).get("id") == "g"
    assert root.find("s:text", ns).text == "Curvesmith"
    group = root.find("s:g", ns)
    assert group.get("id") == "shapes" and group.get("transform") == "translate(10,5) scale(2)"
    star, wave = group.findall("s:path", ns)
    assert (star.get("id"), star.get("class"), star.get("fill"), star.get("stroke")) == (
        "star",
        "brand",
        "url(#g)",
        "navy",
    )
    assert (wave.get("id"), wave.get("fill"), wave.get("stroke")) == ("wave", "none", "green")
    cmd = "Q" if kind == "quadratic" else "C"
    assert cmd in star.get("d") and " L" not in star.get("d") and star.get("d").endswith("Z")
    # in the elements' own coordinates: read back through the transform, each path is the
    # smoothed curve within the tolerance (default 1/1000 of the diagonal), area exact
    smoothed = [cca.smooth(c.points, closed=c.closed, iterations=5) for c in read_curves(src)]
    tol = 1e-3 * float(np.hypot(*np.ptp(np.vstack(smoothed), axis=0)))
    back = read_curves(out)
    assert [c.closed for c in back] == [True, False]
    for b, ref in zip(back, smoothed, strict=True):
        # the paths are flattened again on reading (to SVG's default tolerance)
        assert distance_to_polyline(b.points, ref, b.closed) <= 1.05 * tol
    area = signed_area(smoothed[0])
    assert abs(signed_area(back[0].points)) == pytest.approx(abs(area), rel=1e-3)


@pytest.mark.slow
def test_cli_smooth_curves_svg_and_geojson(tmp_path):
    src = tmp_path / "star.svg"
    src.write_text(STAR)
    runner = CliRunner()
    out = tmp_path / "out.svg"
    r = runner.invoke(
        main,
        [
            "smooth",
            str(src),
            "-o",
            str(out),
            "--curves",
            "quadratic",
            "--iterations",
            "4",
            "--tolerance",
            "0.5",
        ],
    )
    assert r.exit_code == 0, r.output
    ((seg, closed),) = read_bezier_paths(out)
    assert closed and seg.shape[1:] == (3, 2)
    star = np.array(
        [
            [100, 10],
            [120, 70],
            [190, 75],
            [135, 115],
            [155, 185],
            [100, 145],
            [45, 185],
            [65, 115],
            [10, 75],
            [80, 70],
        ],
        float,
    )
    exact = 0.5 * np.sum(
        star[:, 0] * np.roll(star[:, 1], -1) - np.roll(star[:, 0], -1) * star[:, 1]
    )
    assert abs(curves.bezier_area(seg, closed=True)) == pytest.approx(abs(exact), rel=1e-12)
    gj = tmp_path / "out.geojson"
    r = runner.invoke(
        main,
        [
            "smooth",
            str(src),
            "-o",
            str(gj),
            "--curves",
            "cubic",
            "--iterations",
            "4",
            "--tolerance",
            "0.5",
        ],
    )
    assert r.exit_code == 0, r.output
    props = json.loads(gj.read_text())["features"][0]["properties"]
    assert props["degree"] == 3 and props["deviation"] <= 0.5 and props["segments"] == seg.shape[0]
    assert props["g2_defect"] < 1e-8  # every smooth joint G2 (corners: ends of straight runs)
    r = runner.invoke(
        main, ["smooth", str(src), "-o", str(out), "--curves", "quadratic", "--tolerance", "-1"]
    )
    assert r.exit_code == 2  # a bad option value is a usage error
    assert "Invalid value for '--tolerance': -1.0 is not in the range x>0" in r.output


@pytest.mark.slow
def test_demo_section_records_the_comb_numbers(tmp_path):
    from curvesmith import demo

    summary = demo.run_demo(tmp_path, sections=["curves"])
    numbers = summary["sections"][0]["numbers"]
    assert numbers["area_change"]["value"] < 1e-12
    assert numbers["deviation"]["value"] <= numbers["tolerance"]["value"]
    assert numbers["g2_after"]["value"] < 1e-8 < 0.01 < numbers["g2_before"]["value"]
    assert (tmp_path / "curves_comb.png").exists()


def test_open_curve_with_straight_runs_keeps_its_chord_area():
    # a cca-smoothed zigzag: straight runs become lines, their area goes to the curves
    zig = np.array([[10, 190], [50, 160], [90, 190], [130, 160], [170, 190]], float)
    smooth = cca.smooth(zig, closed=False, iterations=4)
    f = curves.fit(smooth, closed=False, tolerance=0.2)
    assert f.success and f.deviation <= 0.2
    assert abs(f.area / f.target_area - 1) < 1e-12
    np.testing.assert_array_equal(f.segments[0, 0], zig[0])
    np.testing.assert_array_equal(f.segments[-1, -1], zig[-1])


def brute_distance(query, poly, closed):
    """Distance of every query point to every edge of the polyline (plain reference)."""
    a = poly if closed else poly[:-1]
    b = np.roll(poly, -1, axis=0) if closed else poly[1:]
    ab = b - a
    t = np.einsum("qej,ej->qe", query[:, None] - a[None], ab) / np.einsum("ej,ej->e", ab, ab)
    foot = a[None] + np.clip(t, 0, 1)[..., None] * ab[None]
    return np.hypot(*(query[:, None] - foot).transpose(2, 0, 1)).min(axis=1)


@settings(max_examples=40, deadline=None)
@given(st.integers(0, 2**31 - 1), st.booleans())
def test_polyline_distance_is_exact_on_uneven_sampling(seed, closed):
    # edges from 1e-3 to 1e3 of each other: the nearest vertices of a query point need not
    # lie on its nearest edge (a dense short side next to a long one)
    rng = np.random.default_rng(seed)
    steps = rng.normal(size=(int(rng.integers(3, 40)), 2)) * 10.0 ** rng.uniform(-3, 3, (1, 1))
    steps *= 10.0 ** rng.uniform(-3, 0, (len(steps), 1))
    poly = np.cumsum(steps, axis=0) + rng.uniform(-1e4, 1e4, 2)
    span = np.ptp(poly, axis=0).max()
    query = poly.mean(axis=0) + rng.uniform(-span, span, (300, 2))
    query = np.vstack([query, poly[: len(poly) // 2] + 1e-3 * span * rng.normal(size=(1, 2))])
    ref = brute_distance(query, poly, closed).max()
    # the coordinates sit up to 1e4 from the origin: differences of them (in the oracle as in
    # the function) are only good to their ulps, which can exceed 1e-9 of a tiny span
    roundoff = 16 * np.spacing(np.abs(query).max())
    assert distance_to_polyline(query, poly, closed) == pytest.approx(
        ref, rel=1e-12, abs=1e-9 * span + roundoff
    )


def test_deviation_next_to_a_corner_of_a_long_and_a_short_line():
    # Regression: DejaVu Sans' fraction slash (in percent, onehalf, ...) is a parallelogram of
    # two short and two long sides; its fit is the parallelogram itself, deviation 0, but the
    # nearest-vertex measurement gave 15.8 font units and the glyph was reported unfittable
    q = np.array([[1360, 1520], [1520, 1520], [586, -29], [426, -29]], float)
    seg = np.stack([q, 0.5 * (q + np.roll(q, -1, 0)), np.roll(q, -1, 0)], axis=1)
    dense = curves.sample_segments(seg, 400)[:-1]
    assert curves.bezier_deviation(seg, dense, closed=True) < 1e-9
    fit = curves.fit(dense, closed=True, tolerance=2.048, anchors=[0, 400, 800, 1200])
    assert fit.success and fit.count == 4 and fit.deviation < 1e-9


@pytest.mark.parametrize(
    ("pts", "closed"),
    [
        ([[0, 0], [3, 4]], False),
        ([[0, 0], [3, 4], [6, 0]], False),
        ([[0, 0], [3, 4], [6, 0]], True),
    ],
)
def test_a_curve_of_fewer_than_4_vertices_is_its_polyline(pts, closed):
    # a line or a triangle of a drawing (an SVG <line>, a 3-point <polyline>) failed the
    # whole `smooth --curves` run with "points must have at least 4 points"
    p = np.array(pts, float)
    f = curves.fit(p, closed=closed, tolerance=0.01, degree=3)
    assert f.success and f.count == len(p) - (0 if closed else 1)
    assert np.array_equal(f.segments[:, 0], p[: f.count])
    assert f.deviation < 1e-12
    if closed:
        assert f.area == pytest.approx(signed_area(p), rel=1e-12)


RECT = (
    '<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 100 100">'
    '<rect id="r" x="10" y="10" width="80" height="60" fill="blue"/>'
    '<line id="l" x1="5" y1="90" x2="95" y2="95" stroke="black"/></svg>'
)


def test_cli_curves_keep_the_corners_that_keep_angle_keeps(tmp_path):
    # a rectangle (27 of the 33 SVGs that installed packages ship have one) could not be
    # written as curves: the corners that --keep-angle kept in place were not corners of
    # the fit, which tried to round them within the tolerance and failed; a <line> (two
    # points) failed --keep-angle and --curves alike
    src, out = tmp_path / "rect.svg", tmp_path / "out.svg"
    src.write_text(RECT)
    args = ["smooth", str(src), "-o", str(out), "--curves", "cubic"]
    res = CliRunner().invoke(main, [*args, "--keep-angle", "45"])
    assert res.exit_code == 0, res.output
    paths = read_bezier_paths(out)
    rect = paths[0][0]
    assert rect.shape == (4, 4, 2)  # four straight sides
    assert np.array_equal(rect[:, 0], [[10, 10], [90, 10], [90, 70], [10, 70]])
    side, ctrl = rect[:, 3] - rect[:, 0], rect[:, 1] - rect[:, 0]
    assert np.allclose(side[:, 0] * ctrl[:, 1] - side[:, 1] * ctrl[:, 0], 0)
    line = paths[1][0].reshape(-1, 2)  # the line: straight, end to end
    assert np.array_equal(line[[0, -1]], [[5, 90], [95, 95]])
    off = line - line[0]
    assert np.allclose(off[:, 0] * 5 - off[:, 1] * 90, 0, atol=1e-9)
    # without it, the run fails in one line that says what to do
    res = CliRunner().invoke(main, args)
    assert res.exit_code == 1
    assert len(res.output.strip().splitlines()) == 1
    assert "turns by 90 degrees at vertex" in res.output and "--keep-angle" in res.output
