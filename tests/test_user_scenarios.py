"""Acceptance scenarios: a new user runs the CLI on real-world and broken files.

Every broken input must give exactly one line ``Error: ...`` naming the file and the
problem, exit status 1 and no traceback; usage errors exit 2.
"""

import json

import numpy as np
import pytest

from curvesmith import io as cio
from curvesmith import signed_area
from curvesmith.cli import main

GEOJSON = {
    "type": "FeatureCollection",
    "name": "parcels",
    "features": [
        {
            "type": "Feature",
            "id": 17,
            "properties": {"id": "lake", "name": "Lake Ünter", "tags": ["water"]},
            "geometry": {
                "type": "Polygon",
                "coordinates": [
                    [[0, 0], [10, 0], [10, 10], [0, 10], [0, 0]],
                    [[2, 2], [2, 4], [4, 4], [4, 2], [2, 2]],
                ],
            },
        },
        {
            "type": "Feature",
            "properties": {"name": "islands"},
            "geometry": {
                "type": "MultiPolygon",
                "coordinates": [
                    [[[20, 0], [22, 0], [21, 2], [20, 0]]],
                    [[[30, 0], [34, 0], [34, 4], [30, 4], [30, 0]]],
                ],
            },
        },
    ],
}

SVG = """<?xml version="1.0" encoding="UTF-8"?>
<svg xmlns="http://www.w3.org/2000/svg" xmlns:xlink="http://www.w3.org/1999/xlink"
     width="210mm" height="297mm" viewBox="0 0 210 297">
  <defs><path id="star" d="m 0,-10 3,7 7,0 -5,5 2,8 -7,-5 -7,5 2,-8 -5,-5 7,0 z"/></defs>
  <g transform="translate(10,20)">
    <path id="donut" d="M 10 50 L 60 50 L 60 80 Z M 20 60 L 50 60 L 50 70 L 20 70 Z"/>
    <path id="arc" d="M 100 50 a 20 10 30 1 1 40 0 l 10 10 h 20 v -15 q 10 -10 20 0 t 20 0"/>
    <use xlink:href="#star" x="150" y="200"/>
    <use xlink:href="#star" x="50" y="200"/>
  </g>
</svg>
"""


def one_line_error(res, *fragments):
    assert res.exit_code == 1, res.output
    assert res.exception is None or isinstance(res.exception, SystemExit)
    lines = [line for line in res.output.splitlines() if line.strip()]
    assert len(lines) == 1 and lines[0].startswith("Error: "), res.output
    for fragment in fragments:
        assert fragment in lines[0], lines[0]


def test_geojson_with_holes_and_id_property_converts_to_csv(runner, tmp_path):
    # Regression: 'id properties must be present and distinct' for a polygon with a hole
    src = tmp_path / "parcels.geojson"
    src.write_text(json.dumps(GEOJSON))
    out = tmp_path / "out.csv"
    res = runner.invoke(main, ["smooth", str(src), "-o", str(out), "--method", "chaikin"])
    assert res.exit_code == 0, res.output
    curves = cio.read_csv(out)
    assert [c.properties["id"] for c in curves] == ["lake#0", "lake#1", 2, 3]
    assert [c.properties.get("name") for c in curves] == ["Lake Ünter"] * 2 + ["islands"] * 2
    assert all(c.closed for c in curves)


def test_geojson_smoothing_keeps_structure_orientation_and_properties(runner, tmp_path):
    src = tmp_path / "parcels.geojson"
    src.write_text(json.dumps(GEOJSON))
    for method in ("chaikin", "derham"):
        out = tmp_path / f"{method}.geojson"
        res = runner.invoke(main, ["smooth", str(src), "-o", str(out), "--method", method])
        assert res.exit_code == 0, res.output
        doc = json.loads(out.read_text())
        lake, islands = doc["features"]
        assert lake["id"] == 17 and lake["properties"] == GEOJSON["features"][0]["properties"]
        rings = [np.array(r) for r in lake["geometry"]["coordinates"]]
        assert [r[0].tolist() == r[-1].tolist() for r in rings] == [True, True]
        areas = [int(np.sign(signed_area(r[:-1]))) for r in rings]
        assert areas == [1, -1]  # RFC 7946: exterior CCW, hole CW
        assert islands["geometry"]["type"] == "MultiPolygon"
        assert len(islands["geometry"]["coordinates"]) == 2


def test_inkscape_like_svg_to_csv_and_back(runner, tmp_path):
    # Regression: a compound path (two subpaths) or two <use> of one symbol share an id
    src = tmp_path / "drawing.svg"
    src.write_text(SVG)
    out = tmp_path / "out.csv"
    res = runner.invoke(main, ["smooth", str(src), "-o", str(out), "--method", "chaikin"])
    assert res.exit_code == 0, res.output
    ids = [c.properties["id"] for c in cio.read_csv(out)]
    assert ids == ["donut#0", "donut#1", "arc", "star#0", "star#1"]
    stars = [c for c in cio.read_svg(src) if c.properties.get("id") == "star"]
    # the two uses are the same star shifted by (100, 0)
    assert np.allclose(stars[0].points - stars[1].points, [100.0, 0.0])


def test_messy_csv_bom_crlf_semicolons_trailing_blank_lines(runner, tmp_path):
    src = tmp_path / "messy.csv"
    src.write_bytes(
        b"\xef\xbb\xbfID;X;Y;name\r\na;0;0;one\r\na;1;0;one\r\na;1;1;one\r\n"
        b"b;5;5;two\r\nb;6.5;5;two\r\n\r\n\r\n"
    )
    res = runner.invoke(main, ["measure", str(src), "--json"])
    assert res.exit_code == 0, res.output
    rows = json.loads(res.output)["curves"]
    assert [r["points"] for r in rows] == [3, 2]
    assert [r["length"] for r in rows] == [2.0, 1.5]


@pytest.mark.parametrize(
    ("name", "content", "fragments"),
    [
        ("empty.csv", b"", ["empty.csv", "empty"]),
        ("header.csv", b"x,y\n", ["header.csv", "no data rows"]),
        ("garbage.csv", bytes(range(128, 256)), ["garbage.csv", "not UTF-8"]),
        ("trunc.geojson", b'{"type": "FeatureCollection", "features": [{"type":', ["line 1"]),
        ("notgeo.json", b'{"hello": [1, 2]}', ["notgeo.json", "'type'"]),
        (
            "point.geojson",
            b'{"type": "Point", "coordinates": [1, 2]}',
            ["point.geojson", "Point is not a curve"],
        ),
        (
            "nodraw.svg",
            b'<svg xmlns="http://www.w3.org/2000/svg"><text>hi</text></svg>',
            ["nodraw.svg", "no drawable"],
        ),
        ("notxml.svg", b"this is not xml <<", ["notxml.svg", "malformed XML"]),
        ("nonnum.csv", b"x,y\n0,0\n1,abc\n", ["nonnum.csv", "line 3", "'abc'"]),
        ("nan.csv", b"x,y\n0,0\n1,NaN\n2,2\n", ["nan.csv", "line 3", "not finite"]),
        ("single.csv", b"x,y\n0,0\n", ["single.csv", "at least 2 points"]),
        ("curve.dat", b"x,y\n0,0\n1,1\n", ["curve.dat", "'.dat'", "--format"]),
    ],
)
def test_bad_input_files(runner, tmp_path, name, content, fragments):
    path = tmp_path / name
    path.write_bytes(content)
    for args in (["measure", str(path)], ["smooth", str(path), "-o", str(tmp_path / "o.csv")]):
        one_line_error(runner.invoke(main, args), *fragments)


def test_bad_output_paths(runner, tmp_path):
    src = tmp_path / "ok.csv"
    src.write_text("x,y\n0,0\n1,1\n2,0\n")
    missing = tmp_path / "no" / "such" / "dir" / "out.csv"
    res = runner.invoke(main, ["smooth", str(src), "-o", str(missing), "--method", "chaikin"])
    one_line_error(res, str(missing), "does not exist")
    (tmp_path / "d.csv").mkdir()
    # a folder where the output file should go is a bad option value: a usage error, exit 2
    for command in (["smooth"], ["batch", "smooth"], ["fair"], ["affine"]):
        res = runner.invoke(main, [*command, str(src), "-o", str(tmp_path / "d.csv")])
        assert res.exit_code == 2, res.output
        assert res.output.strip().count("\n") == 0 and "d.csv' is a directory" in res.output
    res = runner.invoke(main, ["smooth", str(src), "-o", str(tmp_path / "out.xyz")])
    one_line_error(res, "out.xyz", "--format")
    res = runner.invoke(main, ["measure", str(tmp_path / "missing.csv")])
    one_line_error(res, "missing.csv", "no such file")


def test_runaway_iterations_are_an_error_not_an_out_of_memory(runner, tmp_path):
    src = tmp_path / "ok.csv"
    src.write_text("x,y\n0,0\n1,1\n2,0\n")
    res = runner.invoke(
        main, ["smooth", str(src), "-o", str(tmp_path / "o.csv"), "--method", "chaikin",
               "--iterations", "40"]
    )  # fmt: skip
    one_line_error(res, "iterations", "40")


def test_duplicated_points_are_kept_not_dropped(runner, tmp_path):
    src = tmp_path / "dups.csv"
    src.write_text("x,y\n0,0\n0,0\n1,1\n1,1\n2,0\n")
    res = runner.invoke(main, ["measure", str(src), "--json"])
    assert res.exit_code == 0
    (row,) = json.loads(res.output)["curves"]
    assert row["points"] == 5 and row["zero_length_edges"] == 2
    out = tmp_path / "o.csv"
    res = runner.invoke(main, ["smooth", str(src), "-o", str(out), "--method", "chaikin"])
    assert res.exit_code == 0
    assert np.isfinite(cio.read_csv(out)[0].points).all()


@pytest.mark.parametrize(
    "args",
    [
        ["smooth"],
        ["smooth", "x.csv"],
        ["smooth", "x.csv", "-o", "y.csv", "--method", "bezier"],
        ["smooth", "x.csv", "-o", "y.csv", "--iterations", "three"],
        ["nosuchcommand"],
    ],
)
def test_usage_errors_exit_2(runner, args):
    res = runner.invoke(main, args)
    assert res.exit_code == 2


def test_affine_errors_name_the_file_and_the_curve(runner, tmp_path):
    # Regression: "Error: samples must have at least 2 * vertices = 8 points ..." did not say
    # which file or curve
    src = tmp_path / "shapes.csv"
    t = np.linspace(0.0, np.pi, 200)
    rows = [f"a,{x!r},{y!r}" for x, y in zip(np.cos(t).tolist(), np.sin(t).tolist(), strict=True)]
    rows += ["b,0,0", "b,1,0", "b,1,1", "b,0,1"]
    src.write_text("id,x,y\n" + "\n".join(rows) + "\n")
    res = runner.invoke(
        main, ["affine", str(src), "-o", str(tmp_path / "o.csv"), "--vertices", "4"]
    )
    assert res.exit_code == 1
    *progress, last = res.output.splitlines()
    assert progress == [line for line in progress if line.startswith("curve 0: constructed")]
    assert last.startswith("Error: ") and "shapes.csv: curve 1:" in last
    assert "at least 2 * vertices = 8 points" in last


def test_stdin_that_is_not_utf8_is_reported_as_such(runner):
    # Regression: the message showed surrogate escapes ('\udc85...') and a bogus field count
    res = runner.invoke(main, ["measure", "-", "--format", "csv"], input=bytes(range(128, 256)))
    one_line_error(res, "<stdin>", "not UTF-8")
    res = runner.invoke(main, ["measure", "-", "--format", "csv"], input="x,y\n0,0\n1,oops\n")
    one_line_error(res, "<stdin>: line 3", "'oops'")


def test_measure_refuses_to_print_overflowed_numbers(runner, tmp_path, recwarn):
    # Regression: measure printed length inf and turning angles nan, with RuntimeWarnings
    src = tmp_path / "huge.svg"
    src.write_text(
        '<svg xmlns="http://www.w3.org/2000/svg"><path d="M0 0 L 1e308 1e308 L -1e308 0"/></svg>'
    )
    res = runner.invoke(main, ["measure", str(src)])
    one_line_error(res, "curve 0 of", "huge.svg", "overflow", "scale them down")
    for method in ("chaikin", "derham"):
        out = str(tmp_path / "o.svg")
        res = runner.invoke(main, ["smooth", str(src), "-o", out, "--method", method])
        one_line_error(res, "curve 0 of", "huge.svg", "overflow", "scale them down")
    # cca works at any scale (it rescales by a power of two), so the smoothed curve is
    # finite; an SVG cannot hold an extent beyond the largest float, a CSV can
    out = tmp_path / "o.csv"
    res = runner.invoke(main, ["smooth", str(src), "-o", str(out), "--method", "cca"])
    assert res.exit_code == 0, res.output
    smoothed = cio.read_csv(out)[0].points
    assert np.isfinite(smoothed).all() and np.abs(smoothed).max() == 1e308
    res = runner.invoke(main, ["smooth", str(src), "-o", str(tmp_path / "o.svg")])
    one_line_error(res, "o.svg", "extent overflows", "scale them down")
    assert not [w for w in recwarn if issubclass(w.category, RuntimeWarning)]


def test_measure_says_which_feature_part_and_hole_a_row_is(runner, tmp_path):
    # A GIS user could not tell the rows of holes and parts apart
    src = tmp_path / "parcels.geojson"
    src.write_text(json.dumps(GEOJSON))
    res = runner.invoke(main, ["measure", str(src)])
    assert res.exit_code == 0, res.output
    wheres = [line.split("  ")[-1] for line in res.output.splitlines()[1:]]
    assert wheres == [
        "feature 0 (lake)",
        "feature 0 (lake) hole 1",
        "feature 1 part 0",
        "feature 1 part 1",
    ]
    rows = json.loads(runner.invoke(main, ["measure", str(src), "--json"]).output)["curves"]
    assert [(r["feature"], r["kind"], r["part"], r["ring"], r["id"]) for r in rows] == [
        (0, "Polygon", 0, 0, "lake"),
        (0, "Polygon", 0, 1, "lake"),
        (1, "MultiPolygon", 0, 0, None),
        (1, "MultiPolygon", 1, 0, None),
    ]
    assert [r["signed_area"] for r in rows] == [100.0, -4.0, 2.0, 16.0]


def test_write_errors_name_the_output_file(runner, tmp_path):
    # Regression: "Error: SVG is planar: curve 2 has 3D points" did not say which file
    src = tmp_path / "river.geojson"
    src.write_text(
        '{"type": "LineString", "coordinates": [[0, 0, 400], [1, 1, 398.5], [2, 0, 397]]}'
    )
    out = tmp_path / "river.svg"
    res = runner.invoke(main, ["smooth", str(src), "-o", str(out), "--method", "chaikin"])
    one_line_error(res, f"{out}: SVG is planar: curve 0 has 3D points")
    res = runner.invoke(main, ["smooth", str(src), "-o", str(tmp_path / "nodir" / "r.csv")])
    one_line_error(res, "nodir", "does not exist")


def _ellipse_ring(cx, cy, a, b, n=200, reverse=False):
    t = np.linspace(0.0, 2.0 * np.pi, n, endpoint=False)
    ring = np.c_[cx + a * np.cos(t), cy + b * np.sin(t)]
    ring = ring[::-1] if reverse else ring
    return [*ring.tolist(), ring[0].tolist()]


def test_affine_on_polygons_with_holes_and_multipolygons(runner, tmp_path):
    # Regression: per-curve results as properties made the GeoJSON writer refuse the rings of
    # one feature ("its curves have different properties"), and --open turned a hole into a
    # LineString with ring 1 ("ring must be 0 for a LineString, got 1").
    doc = {
        "type": "FeatureCollection",
        "features": [
            {
                "type": "Feature",
                "properties": {"n": 1},
                "geometry": {
                    "type": "Polygon",
                    "coordinates": [
                        _ellipse_ring(0, 0, 10, 8),
                        _ellipse_ring(0, 0, 2, 1, reverse=True),
                    ],
                },
            },
            {
                "type": "Feature",
                "properties": {"n": 2},
                "geometry": {
                    "type": "MultiPolygon",
                    "coordinates": [[_ellipse_ring(30, 0, 10, 8)], [_ellipse_ring(-30, 0, 9, 8)]],
                },
            },
        ],
    }
    src = tmp_path / "lakes.geojson"
    src.write_text(json.dumps(doc))
    out = tmp_path / "out.geojson"
    res = runner.invoke(main, ["affine", str(src), "-o", str(out), "--vertices", "12"])
    assert res.exit_code == 0, res.output
    lake, pair = json.loads(out.read_text())["features"]
    assert lake["geometry"]["type"] == "Polygon" and len(lake["geometry"]["coordinates"]) == 2
    areas = lake["properties"]["affine_area"]
    assert len(areas) == 2 and areas[0] > 0 > areas[1]  # the hole winds clockwise
    assert lake["properties"]["n"] == 1 and len(pair["properties"]["affine_pieces"]) == 2
    res = runner.invoke(main, ["affine", str(src), "-o", str(out), "--vertices", "12", "--open"])
    assert res.exit_code == 0, res.output
    kinds = [f["geometry"]["type"] for f in json.loads(out.read_text())["features"]]
    assert kinds == ["MultiLineString", "MultiLineString"]


def test_old_geojson_crs_is_reported_not_silently_dropped(runner, tmp_path):
    # A projected crs (QGIS exports it) would silently turn into WGS 84 in the written file.
    # Issue 13: GeoJSON output now keeps it; a format without a place for it says so.
    doc = dict(GEOJSON, crs={"type": "name", "properties": {"name": "urn:ogc:def:crs:EPSG::2056"}})
    src = tmp_path / "swiss.geojson"
    src.write_text(json.dumps(doc))
    out = tmp_path / "out.geojson"
    res = runner.invoke(main, ["smooth", str(src), "-o", str(out), "--method", "chaikin"])
    n = len(GEOJSON["features"])
    assert res.exit_code == 0 and res.output == f"{n} of {n} feature(s) smoothed\n"
    assert json.loads(out.read_text())["crs"] == doc["crs"]
    res = runner.invoke(
        main, ["smooth", str(src), "-o", str(tmp_path / "o.csv"), "--method", "chaikin"]
    )
    assert res.exit_code == 0, res.output
    line, summary = [ln for ln in res.output.splitlines() if ln.strip()]
    assert line.startswith("Warning: ") and "EPSG::2056" in line and "not kept" in line
    assert summary == f"{n} of {n} feature(s) smoothed"  # in metres: no geographic warning
    wgs = dict(doc, crs={"type": "name", "properties": {"name": "urn:ogc:def:crs:OGC:1.3:CRS84"}})
    src.write_text(json.dumps(wgs))
    res = runner.invoke(main, ["smooth", str(src), "-o", str(out), "--method", "chaikin"])
    # kept without a word; in degrees, the GIS path's warning
    assert res.exit_code == 0 and res.output == (
        f"Warning: {str(src)!r} is in a geographic CRS (WGS 84): smoothing keeps planar areas "
        f"in degrees, not ground areas; --equal-area smooths in an equal-area projection\n"
        f"{n} of {n} feature(s) smoothed\n"
    )


def test_smooth_cli_on_coordinates_of_1e_170(runner, tmp_path):
    # Regression (acceptance testing): squared edge lengths underflowed and cca recursed until
    # Python's recursion limit; the CLI printed a traceback.
    src = tmp_path / "tiny.csv"
    src.write_text("x,y\n0,0\n1e-170,0\n1e-170,1e-170\n0,1e-170\n")
    out = tmp_path / "out.csv"
    res = runner.invoke(main, ["smooth", str(src), "-o", str(out), "--iterations", "3"])
    assert res.exit_code == 0, res.output
    pts = cio.read_csv(out)[0].points
    assert pts.shape == (69, 2) and np.isfinite(pts).all()  # 3 steps: 4 -> 9 -> 24 -> 69
    np.testing.assert_array_equal(pts[[0, -1]], [[0.0, 0.0], [0.0, 1e-170]])  # ends kept
