"""Glyph refitting on the fonts matplotlib ships: G2 TrueType contours, areas and metrics kept."""

import json
import os

import matplotlib
import numpy as np
import pytest
from click.testing import CliRunner

from curvesmith import curves, glyphs
from curvesmith.cli import main
from curvesmith.errors import CurveError
from curvesmith.io import fonts

TTF = os.path.join(matplotlib.get_data_path(), "fonts", "ttf")
SANS = os.path.join(TTF, "DejaVuSans.ttf")
SERIF = os.path.join(TTF, "DejaVuSerif.ttf")


def render_ink(path, text):
    import matplotlib.ft2font as ft

    f = ft.FT2Font(path)
    f.set_size(64, 72)
    f.set_text(text, 0.0, flags=ft.LoadFlags.NO_HINTING)
    f.draw_glyphs_to_bitmap(antialiased=True)
    return float(np.asarray(f.get_image(), float).sum())


def signed_area(points):
    x, y = points[:, 0], points[:, 1]
    return 0.5 * np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y)


@pytest.fixture(scope="module")
def sans():
    return fonts.open_font(SANS)


def test_contour_sampling_is_exact_and_finds_corners(sans):
    outline = fonts.read_glyph(sans, sans.getBestCmap()[ord("D")])
    assert len(outline.contours) == 2 and outline.advance == sans["hmtx"]["D"][0]
    for c in outline.contours:
        pts, corners = c.sample(1.0)
        # the polygon of dense samples has nearly the exact area (chord error only)
        assert signed_area(pts) == pytest.approx(c.area(), rel=1e-5)
        assert len(corners) == 4  # the stem's corners and the line/bowl joints
    # a quadratic's exact area: Gauss-Legendre against 2/3 of the control triangle
    q = fonts.Contour((np.array([[0.0, 0], [2, 0]]), np.array([[2.0, 0], [1, 2], [0, 0]])))
    assert q.area() == pytest.approx(4 / 3, rel=1e-14)  # counter-clockwise


@pytest.mark.parametrize("char", ["o", "S", "g", "D"])
def test_refit_glyph_is_g2_within_tolerance_and_keeps_area(sans, char):
    name = sans.getBestCmap()[ord(char)]
    rep = glyphs.refit_glyph(sans, name, tolerance=2.0)
    outline = fonts.read_glyph(sans, name)
    assert rep.max_deviation <= 2.0
    assert abs(rep.area_change) < 1e-12
    assert rep.g2_defect < 1e-8
    for seg, contour in zip(rep.segments, outline.contours, strict=True):
        # contour direction kept
        assert np.sign(curves.bezier_area(seg)) == np.sign(contour.area())
    if char == "D":  # the corners of the stem stay on-curve points
        on = np.concatenate([s[:, 0] for s in rep.segments])
        for cx, cy in [(201, 0), (201, 1493)]:
            assert np.min(np.hypot(on[:, 0] - cx, on[:, 1] - cy)) < 1e-9


@pytest.mark.parametrize("char", ["N", "x", "W", "k", "E"])
def test_glyphs_of_straight_lines_only_are_their_polygons(sans, char):
    # Regression: a contour of lines only (N, x, W ...) had no curved piece to take the
    # rounding of the area sums, and the affine construction divided by A = 0
    name = sans.getBestCmap()[ord(char)]
    rep = glyphs.refit_glyph(sans, name, tolerance=2.0)
    outline = fonts.read_glyph(sans, name)
    assert rep.segments_after == rep.segments_before  # one straight segment per line
    assert rep.max_deviation < 1e-9 and abs(rep.area_change) < 1e-12
    for seg, contour in zip(rep.segments, outline.contours, strict=True):
        on = seg[:, 0]  # on-curve points: the outline's corners, in order
        pts, corners = contour.sample(2.0)
        assert len(on) == len(corners)
        assert np.min(np.hypot(*(on[:, None] - pts[corners][None]).T), axis=0).max() < 1e-9


def test_a_straight_run_has_no_affine_arc_length_polygon():
    from curvesmith import affine

    line = np.c_[np.linspace(0, 10, 50), np.linspace(0, 5, 50)]
    with pytest.raises(CurveError, match="no affine arc length"):
        affine.approximate(line, vertices=8)


@pytest.mark.slow
def test_written_font_keeps_names_metrics_and_renders(tmp_path):
    out = tmp_path / "out.ttf"
    reports = glyphs.refit_font(SERIF, out, glyphs="a,g,S", tolerance=2.0)
    assert [r.name for r in reports] == ["a", "g", "S"]
    src, new = fonts.open_font(SERIF), fonts.open_font(out)
    assert new.getGlyphOrder() == src.getGlyphOrder()
    assert new.getBestCmap() == src.getBestCmap()
    for name in [*src.getGlyphOrder()[:200], "a", "g", "S"]:
        assert new["hmtx"][name][0] == src["hmtx"][name][0]
    # hinting dropped cleanly
    assert not {"fpgm", "prep", "cvt "} & set(new.keys())
    assert all(
        not getattr(new["glyf"][n], "program", None) or not new["glyf"][n].program.getBytecode()
        for n in new.getGlyphOrder()[:300]
    )
    for tag in ("GSUB", "GPOS", "kern"):
        assert (tag in new) == (tag in src)
    # the refitted glyphs: directions kept, areas within the rounding of integer coordinates
    for r in reports:
        written = fonts.read_glyph(new, r.name)
        assert len(written.contours) == r.contours
        for w, seg in zip(written.contours, r.segments, strict=True):
            assert np.sign(w.area()) == np.sign(curves.bezier_area(seg))
            assert w.area() == pytest.approx(curves.bezier_area(seg), rel=2e-3)
        # G2 up to the rounding of the control points to integers (measured 3-4 %)
        assert glyphs.written_g2_defect(new, r.name) < 0.1
    # it renders like the source (FreeType via matplotlib, no hinting): same ink to 0.5 %
    assert render_ink(os.fspath(out), "agS") == pytest.approx(render_ink(SERIF, "agS"), rel=5e-3)


def _cff_font(path, names):
    """An OpenType-CFF font built from DejaVu Sans glyphs (cubic outlines, exact elevation)."""
    from fontTools.fontBuilder import FontBuilder
    from fontTools.pens.t2CharStringPen import T2CharStringPen

    src = fonts.open_font(SANS)
    order = [".notdef", *names]
    gs = src.getGlyphSet()
    charstrings = {}
    for n in order:
        pen = T2CharStringPen(src["hmtx"][n][0], gs)
        gs[n].draw(pen)
        charstrings[n] = pen.getCharString()
    fb = FontBuilder(2048, isTTF=False)
    fb.setupGlyphOrder(order)
    cmap = {u: n for u, n in src.getBestCmap().items() if n in names}
    fb.setupCharacterMap(cmap)
    fb.setupCFF("TestCFF", {"FullName": "TestCFF"}, charstrings, {})
    fb.setupHorizontalMetrics({n: src["hmtx"][n] for n in order})
    fb.setupHorizontalHeader(ascent=1901, descent=-483)
    fb.setupNameTable({"familyName": "TestCFF", "styleName": "Regular"})
    fb.setupOS2()
    fb.setupPost()
    fb.save(path)


@pytest.mark.slow
def test_cff_input_becomes_truetype(tmp_path):
    cff = tmp_path / "test.otf"
    _cff_font(cff, ["o", "S"])
    font = fonts.open_font(cff)
    assert "CFF " in font
    outline = fonts.read_glyph(font, "S")
    assert all(len(s) in (2, 4) for c in outline.contours for s in c.segments)  # cubics, lines
    out = tmp_path / "out.ttf"
    reports = glyphs.refit_font(cff, out, tolerance=2.0)
    assert {r.name for r in reports} == {".notdef", "o", "S"}
    for r in reports:
        assert r.max_deviation <= 2.0 and abs(r.area_change) < 1e-12 and r.g2_defect < 1e-8
    new = fonts.open_font(out)
    assert "glyf" in new and "CFF " not in new
    assert new["hmtx"]["S"][0] == font["hmtx"]["S"][0]


def test_ufo_input(tmp_path):
    from fontTools.pens.pointPen import SegmentToPointPen
    from fontTools.ufoLib import UFOWriter

    src = fonts.open_font(SANS)
    ufo = tmp_path / "test.ufo"
    writer = UFOWriter(os.fspath(ufo))
    gs = src.getGlyphSet()
    glyph_set = writer.getGlyphSet()

    class G:
        pass

    for n, u in (("o", 0x6F), ("S", 0x53)):
        g = G()
        g.width, g.unicodes = src["hmtx"][n][0], [u]
        glyph_set.writeGlyph(n, g, lambda pen, n=n: gs[n].draw(SegmentToPointPen(pen)))
    glyph_set.writeContents()
    writer.writeLayerContents()
    info = G()
    info.unitsPerEm, info.familyName, info.ascender, info.descender = 2048, "UFOTest", 1556, -492
    writer.writeInfo(info)
    writer.writeLib({"public.glyphOrder": ["o", "S"]})
    font = fonts.open_font(ufo)
    assert fonts.resolve_glyphs(font, "S,o") == ["S", "o"]
    out = tmp_path / "ufo.ttf"
    reports = glyphs.refit_font(ufo, out, tolerance=2.0)
    assert [r.name for r in reports] == ["o", "S"]
    new = fonts.open_font(out)
    assert new["hmtx"]["S"][0] == src["hmtx"]["S"][0]
    assert all(r.g2_defect < 1e-8 and abs(r.area_change) < 1e-12 for r in reports)


def test_glyph_selection_errors(sans):
    assert fonts.resolve_glyphs(sans, "a,g") == ["a", "g"]
    assert fonts.resolve_glyphs(sans, "%") == ["percent"]
    with pytest.raises(CurveError, match="'nosuchglyph' is neither a glyph name nor a character"):
        fonts.resolve_glyphs(sans, "a,nosuchglyph")


def test_cli_glyphs_report_and_errors(tmp_path):
    runner = CliRunner()
    out = tmp_path / "o.ttf"
    r = runner.invoke(main, ["glyphs", SANS, "-o", str(out), "--glyphs", "o", "--json"])
    assert r.exit_code == 0, r.output
    row = json.loads(r.output)["glyphs"][0]
    assert row["glyph"] == "o" and row["segments_before"] == 16
    assert row["max_deviation"] <= 2.048 and row["g2_defect"] < 1e-8
    r = runner.invoke(main, ["glyphs", SANS, "-o", str(out), "--glyphs", "nosuch"])
    assert r.exit_code == 1 and "nosuch" in r.output and "Traceback" not in r.output
    r = runner.invoke(main, ["glyphs", SANS, "-o", str(tmp_path / "x.otf"), "--glyphs", "o"])
    assert r.exit_code == 1 and "OUT must be a .ttf file or a .ufo" in r.output
    not_font = tmp_path / "x.ttf"
    not_font.write_text("hello")
    r = runner.invoke(main, ["glyphs", str(not_font), "-o", str(tmp_path / "y.ttf")])
    assert r.exit_code == 1 and "not a TrueType/OpenType font" in r.output
    assert not (tmp_path / "y.ttf").exists()


def test_a_glyph_without_a_fit_is_written_as_it_was(tmp_path, monkeypatch):
    # one hard glyph must not cost the whole font: it is copied unchanged, reported, and the
    # command exits 1 naming it (as batch does for features it could not smooth)
    real = glyphs.refit_glyph

    def refit(font, name, **kw):
        if name == "o":
            raise CurveError(f"glyph {name}, contour 0: deviation 9 (tolerance 2.05)")
        return real(font, name, **kw)

    monkeypatch.setattr(glyphs, "refit_glyph", refit)
    out = tmp_path / "o.ttf"
    r = CliRunner().invoke(main, ["glyphs", SANS, "-o", str(out), "--glyphs", "o,N", "--json"])
    assert r.exit_code == 1
    rows = {row["glyph"]: row for row in json.loads(r.stdout)["glyphs"]}
    assert rows["o"]["refitted"] is False and rows["o"]["g2_defect"] is None
    assert rows["N"]["refitted"] is True and rows["N"]["segments_after"] == 10
    assert r.stderr.strip() == (
        "Error: 1 of 2 glyph(s) have no G2 fit within the tolerance 2.048 and were written "
        "as they were (o); the first: glyph o, contour 0: deviation 9 (tolerance 2.05)"
    )
    source, written = fonts.open_font(SANS), fonts.open_font(str(out))
    a, b = fonts.read_glyph(source, "o"), fonts.read_glyph(written, "o")
    for ca, cb in zip(a.contours, b.contours, strict=True):  # the source's outline, exactly
        assert all(np.array_equal(x, y) for x, y in zip(ca.segments, cb.segments, strict=True))


@pytest.mark.slow
def test_ufo_output_is_exactly_g2(tmp_path):
    out = tmp_path / "out.ufo"
    reports = glyphs.refit_font(SANS, out, glyphs="S,o", tolerance=2.0)
    ufo = fonts.open_font(out)
    src = fonts.open_font(SANS)
    assert ufo.getGlyphOrder() == src.getGlyphOrder()
    assert ufo.advance("S") == src["hmtx"]["S"][0] and ufo.units_per_em == 2048
    for r in reports:
        assert glyphs.written_g2_defect(ufo, r.name) < 1e-8  # floats: no rounding
        written = fonts.read_glyph(ufo, r.name)
        for w, seg in zip(written.contours, r.segments, strict=True):
            assert w.area() == pytest.approx(curves.bezier_area(seg), rel=1e-12)
    with pytest.raises(CurveError, match="exists"):
        glyphs.refit_font(SANS, out, glyphs="o", tolerance=2.0)


@pytest.mark.parametrize(
    "name",
    ["percent", "two", "onequarter", "onehalf", "threequarters", "uni0188", "uni01B7", "uni01B8"],
)
def test_glyphs_once_reported_unfittable_fit_within_the_tolerance(sans, name):
    # Regression: these 8 of DejaVu Sans' first 400 glyphs were kept as drawn. The cause was the
    # deviation measurement (nearest sampled path vertices next to a corner of a short, densely
    # sampled side and a long one: 15.8 font units for an exact parallelogram), not the fit
    rep = glyphs.refit_glyph(sans, name, tolerance=2.048)
    pts = [c.sample(2.048)[0] for c in fonts.read_glyph(sans, name).contours]
    for seg, p in zip(rep.segments, pts, strict=True):
        assert curves.bezier_deviation(seg, p, closed=True) <= 2.048
        assert brute_deviation(seg, p) <= 2.048
    assert rep.max_deviation <= 2.048 and abs(rep.area_change) < 1e-12


def brute_deviation(seg, points):
    """Both-way distance of the path (48 samples per segment) and the closed polyline, brute force."""

    def dist(query, poly):
        a, b = poly, np.roll(poly, -1, axis=0)
        out = np.empty(len(query))
        for i in range(0, len(query), 256):
            q = query[i : i + 256, None]
            t = np.clip(np.sum((q - a) * (b - a), -1) / np.sum((b - a) ** 2, -1), 0, 1)
            out[i : i + 256] = np.hypot(*(q - a - t[..., None] * (b - a)).transpose(2, 0, 1)).min(1)
        return out.max()

    path = curves.sample_segments(seg, 48)[:-1]
    return max(dist(points, path), dist(path, points))


# ------------------------------------------------------------ TrueType rounding


def plain_jumps(ctrl):
    """Relative curvature jumps at the implied points of an all-off-curve closed run.

    Reference formula: at the midpoint of edge e_k = c_(k+1) - c_k the curvature is
    det(e_(k-1), e_k) / |e_k|^3 on the left and det(e_k, e_(k+1)) / |e_k|^3 on the right.
    """
    e = np.roll(ctrl, -1, axis=0) - ctrl
    prev = np.roll(e, 1, axis=0)
    area = prev[:, 0] * e[:, 1] - prev[:, 1] * e[:, 0]  # A_k at vertex c_k
    a_left, a_right = area, np.roll(area, -1)
    return np.abs(a_left - a_right) / np.maximum(np.abs(a_left), np.abs(a_right))


def test_rounding_search_is_the_exact_minimax_on_a_small_contour():
    # an ellipse as 7 G2 quadratics (all on-curve points implied): the dynamic programme's
    # largest jump equals the least one over all 4^7 roundings (brute force, plain formula)
    import itertools

    u = np.linspace(0, 2 * np.pi, 7, endpoint=False) + 0.3
    ctrl = np.c_[41.3 * np.cos(u) + 100.2, 23.7 * np.sin(u) - 50.6]
    mid = 0.5 * (ctrl + np.roll(ctrl, -1, axis=0))
    seg = np.stack([np.roll(mid, 1, axis=0), ctrl, mid], axis=1)
    tc = fonts.truetype_contour(seg)
    assert len(tc.points) == 7 and not tc.on.any() and tc.smooth.all()
    assert plain_jumps(ctrl).max() < 1e-12  # a regular 7-gon's affine image: G2
    q = fonts.round_contour(tc)
    got = plain_jumps(q.astype(float)).max()
    assert got == pytest.approx(fonts.joint_jumps(tc.segments(q.astype(float)), tc.smooth).max())
    base = np.floor(ctrl)
    best = min(
        plain_jumps(base + np.array(c)).max()
        for c in itertools.product([(0, 0), (1, 0), (0, 1), (1, 1)], repeat=7)
    )
    assert got == pytest.approx(best, rel=1e-12)
    assert got < plain_jumps(np.floor(ctrl + 0.5)).max()
    assert np.all(np.abs(q - ctrl) < 1)


@pytest.fixture(scope="module")
def rounded_reports(sans):
    serif = fonts.open_font(SERIF)
    out = []
    for font in (sans, serif):
        for char in "aeRSg&":
            name = font.getBestCmap()[ord(char)]
            for grid in (1, 8):
                out.append(
                    (font, name, grid, glyphs.refit_glyph(font, name, tolerance=2.048, grid=grid))
                )
    return out


def test_rounded_contours_are_within_the_tolerance_and_keep_area_and_direction(rounded_reports):
    for font, name, grid, rep in rounded_reports:
        outline = fonts.read_glyph(font, name)
        for w, c in zip(rep.written, outline.contours, strict=True):
            assert np.array_equal(w, np.round(w * 2) / 2)  # integers and implied half-integers
            pts = c.sample(2.048)[0]
            # measured geometrically, brute force, on the integer outline in source units
            assert brute_deviation(w / grid, pts) <= 2.048
            assert np.sign(curves.bezier_area(w)) == np.sign(c.area())
        # the area changes by the rounding only (measured up to 2e-3 at grid 1, 3e-4 at 8)
        assert abs(rep.area_written / rep.area_before - 1) < (3e-3 if grid == 1 else 4e-4)


def test_rounding_search_beats_plain_rounding_on_real_glyphs(rounded_reports):
    # the numbers measured on these 12 glyphs of DejaVu Sans and Serif (tolerance 2.048, 1/1000
    # em): largest jump with plain rounding 2.8-18 % (grid 1) and 0.4-3.1 % (grid 8); the
    # search: 1.0-5.1 % and 0.13-0.65 %, 1.4-7.5 times smaller; tangent breaks at explicit
    # smooth points 0.5-1.8 degrees plain, 0.15-0.8 searched (grid 1), 0.02-0.07 (grid 8)
    for _, name, grid, rep in rounded_reports:
        tc_jumps = rep.jumps_written
        assert tc_jumps.size and rep.g2_written == tc_jumps.max()
        assert rep.g2_written <= rep.g2_plain / 1.4, (name, grid)
        assert rep.g2_written <= (0.06 if grid == 1 else 0.007), (name, grid)
        assert rep.g2_plain > (0.025 if grid == 1 else 0.004), (name, grid)
        # explicit smooth on-curve points: the tangent break, plain 0.5-1.8 degrees (grid 1)
        assert rep.g1_written <= rep.g1_plain / 1.4 or rep.g1_plain == 0, (name, grid)
        assert rep.g1_written <= np.radians(0.8 if grid == 1 else 0.07), (name, grid)


@pytest.mark.slow
def test_finer_units_per_em_scales_every_metric(tmp_path):
    out = tmp_path / "fine.ttf"
    reports = glyphs.refit_font(
        SANS, out, glyphs="a,S,percent", tolerance=2.048, units_per_em=16384
    )
    src, new = fonts.open_font(SANS), fonts.open_font(out)
    assert new["head"].unitsPerEm == 16384
    for name in [*src.getGlyphOrder()[:100], "a", "S"]:
        assert new["hmtx"][name][0] == round(src["hmtx"][name][0] * 8)
    assert new["hhea"].ascent == src["hhea"].ascent * 8
    assert new["OS/2"].sTypoAscender == src["OS/2"].sTypoAscender * 8
    assert src["head"].unitsPerEm == 2048  # the source's tables are not scaled with it
    # an unchanged glyph: its points times 8
    a = fonts.read_glyph(src, "B").contours[0].segments
    b = fonts.read_glyph(new, "B").contours[0].segments
    assert all(np.array_equal(8 * x, y) for x, y in zip(a, b, strict=True))
    for r in reports:
        written = fonts.read_glyph(new, r.name)
        for w, seg in zip(written.contours, r.written, strict=True):
            assert w.area() == pytest.approx(curves.bezier_area(seg), rel=1e-12)
        assert glyphs.written_g2_defect(new, r.name) <= r.g2_written < 0.002
    assert render_ink(os.fspath(out), "aS%") == pytest.approx(render_ink(SANS, "aS%"), rel=5e-3)
    r = CliRunner().invoke(
        main, ["glyphs", SANS, "-o", str(tmp_path / "x.ufo"), "--units-per-em", "4096"]
    )
    assert r.exit_code == 1 and "--units-per-em applies to .ttf output" in r.output
    r = CliRunner().invoke(
        main, ["glyphs", SANS, "-o", str(tmp_path / "y.ttf"), "--units-per-em", "20000"]
    )
    assert r.exit_code == 2 and not (tmp_path / "y.ttf").exists()


def test_cli_reports_the_written_rounding(tmp_path):
    runner = CliRunner()
    rows = {}
    for rounding in ("search", "plain"):
        out = tmp_path / f"{rounding}.ttf"
        r = runner.invoke(
            main,
            ["glyphs", SANS, "-o", str(out), "--glyphs", "R", "--rounding", rounding, "--json"],
        )
        assert r.exit_code == 0, r.output
        rows[rounding] = json.loads(r.output)["glyphs"][0]
        # the report is what the file holds: implied points read back from the font
        written = glyphs.written_g2_defect(fonts.open_font(out), "R")
        assert written <= rows[rounding]["g2_defect_written"] + 1e-12
    s, p = rows["search"], rows["plain"]
    assert p["g2_defect_written"] == pytest.approx(p["g2_plain_rounding"], rel=1e-12)
    assert s["g2_plain_rounding"] == p["g2_plain_rounding"]
    assert s["g2_defect_written"] < p["g2_defect_written"] / 2
    assert s["g1_written"] < p["g1_written"] / 2
    assert s["deviation_written"] <= 2.048 and abs(s["area_change_written"]) < 2e-3
    r = runner.invoke(main, ["glyphs", SANS, "-o", str(tmp_path / "x.ttf"), "--rounding", "best"])
    assert r.exit_code == 2 and "best" in r.output


@pytest.mark.parametrize("damage", ["truncated", "glyf bytes"])
def test_cli_damaged_font_one_line_no_output(tmp_path, damage):
    # fontTools reads a table (a glyph's bytes) when first used: a cut file or damaged glyph
    # data must fail at the start with one line, not with fontTools' traceback mid-way
    from fontTools.ttLib import TTFont

    with open(SANS, "rb") as fh:
        data = bytearray(fh.read())
    if damage == "truncated":
        data = data[:20000]
    else:
        e = TTFont(SANS).reader.tables["glyf"]
        for i in range(e.offset + 1000, e.offset + e.length, 997):
            data[i] ^= 0xFF
    bad = tmp_path / "bad.ttf"
    bad.write_bytes(bytes(data))
    out = tmp_path / "out.ttf"
    r = CliRunner().invoke(main, ["glyphs", str(bad), "-o", str(out), "--glyphs", "S"])
    assert r.exit_code == 1, r.output
    assert "Traceback" not in r.output and len(r.output.strip().splitlines()) == 1
    assert "not a TrueType/OpenType font, or a damaged one" in r.output
    if damage == "truncated":
        assert "runs past the end of the file" in r.output
    assert not out.exists()


def test_small_tolerance_does_not_sample_finer_than_the_floor(sans, monkeypatch):
    # the samples grew as 1 / tolerance (1e-5 font units: 24 GB for one glyph); now the
    # spacing stops at MIN_SPACING_EM, and the fit is asked to pass that close to them
    seen = []

    def fit(points, **kw):
        seen.append((len(points), kw["tolerance"]))
        raise CurveError("stop here")

    monkeypatch.setattr(glyphs.curves, "fit", fit)
    with pytest.raises(CurveError, match="stop here"):
        glyphs.refit_glyph(sans, "S", tolerance=1e-9)
    n, tol = seen[0]
    outline = fonts.read_glyph(sans, "S")
    length = sum(
        float(np.sum(np.hypot(*np.diff(s, axis=0).T))) for c in outline.contours for s in c.segments
    )
    finest = glyphs.MIN_SPACING_EM * 2048
    assert tol == 1e-9 and length / finest * 0.9 < n <= length / finest + 4 * 28
    with pytest.raises(CurveError, match=r"spacing must be >= 0.2048 font units .* got 0.01"):
        glyphs.refit_glyph(sans, "S", tolerance=1.0, spacing=0.01)


def test_ttf_tolerance_below_the_integer_grid_says_so(sans):
    # the rounding retries lowered the fit's tolerance below 0 and showed the fit's own
    # "tolerance must be > 0, got -1.4"; now the grid is named as the reason
    with pytest.raises(CurveError) as err:
        glyphs.refit_glyph(sans, "S", tolerance=0.1, grid=1.0)
    msg = str(err.value)
    assert "the integer grid (1 per source unit) cannot keep it that close" in msg
    assert "must be > 0" not in msg


def test_ttf_table_shows_the_written_area_change(tmp_path):
    runner = CliRunner()
    out = tmp_path / "o.ttf"
    r = runner.invoke(main, ["glyphs", SANS, "-o", str(out), "--glyphs", "o", "--json"])
    row = json.loads(r.output)["glyphs"][0]
    assert abs(row["area_change"]) < 1e-12 and abs(row["area_change_written"]) > 1e-5
    r = runner.invoke(main, ["glyphs", SANS, "-o", str(tmp_path / "p.ttf"), "--glyphs", "o"])
    assert r.exit_code == 0, r.output
    line = next(ln for ln in r.output.splitlines() if ln.startswith("o "))
    assert f"{row['area_change_written']:.2e}" in line.split()


def test_a_piece_ending_on_the_last_arc_is_fitted(tmp_path):
    # DejaVu Sans' uni03D7 (and a 24 px heart icon at --tolerance 0.01) crashed the fit:
    # a piece's affine-length search asked for the arcs lo .. lo + 1 with lo the last
    # vertex, past the end of the cumulative table (IndexError, a traceback)
    out = tmp_path / "one.ttf"
    res = CliRunner().invoke(main, ["glyphs", SANS, "-o", str(out), "--glyphs", "uni03D7"])
    assert res.exit_code == 0, res.output
    assert res.output.splitlines()[1].split()[0] == "uni03D7" and out.is_file()
    icon = tmp_path / "heart.svg"
    icon.write_text(
        '<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 24 24"><g transform="translate(1'
        ' 1) scale(0.9)"><path d="M12 21.35l-1.45-1.32C5.4 15.36 2 12.28 2 8.5 2 5.42 4.42 3 '
        "7.5 3c1.74 0 3.41.81 4.5 2.09C13.09 3.81 14.76 3 16.5 3 19.58 3 22 5.42 22 8.5c0 "
        '3.78-3.4 6.86-8.55 11.54L12 21.35z"/><path d="M2 22 C 6 14, 10 14, 14 18 S 20 22, '
        '22 16" fill="none"/><circle cx="12" cy="12" r="5"/></g></svg>'
    )
    args = ["smooth", str(icon), "-o", str(tmp_path / "o.svg"), "--curves", "cubic"]
    res = CliRunner().invoke(main, [*args, "--tolerance", "0.01"])
    assert res.exit_code == 0, res.output
    assert res.output.count("(tolerance 0.01)") == 3


def test_an_output_in_a_missing_folder_is_named_not_its_temporary_file(tmp_path):
    out = tmp_path / "no" / "x.ttf"
    res = CliRunner().invoke(main, ["glyphs", SANS, "-o", str(out), "--glyphs", "o"])
    assert res.exit_code == 1 and ".part" not in res.output
    assert res.output == (
        f"Error: {out}: cannot write the file: the directory {str(out.parent)!r} does not exist\n"
    )
