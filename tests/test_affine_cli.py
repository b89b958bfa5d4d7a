"""The ``curvesmith affine`` command."""

import numpy as np
import pytest
from click.testing import CliRunner

from curvesmith import affine
from curvesmith.cli import main
from curvesmith.cli.affine import affine_command
from curvesmith.data import load_points
from curvesmith.io import Curve, read_curves, write_curves
from curvesmith.io.svg import read_quadratic_path

if "affine" not in main.commands:  # registered by the lead in cli/__init__.py
    main.add_command(affine_command)


@pytest.fixture
def inputs(tmp_path):
    u = np.linspace(0, 2 * np.pi, 600, endpoint=False)
    ring = Curve(np.c_[3 * np.cos(u), np.sin(u)], closed=True, kind="Polygon", feature=0)
    pts = affine.bezier_curve(load_points("affine_bezier8.csv"), np.linspace(0, 1, 600))
    arc = Curve(pts, closed=False, feature=1)
    path = tmp_path / "in.geojson"
    write_curves([ring, arc], path)
    return path


def test_affine_command_writes_control_polygons_and_svg(inputs, tmp_path):
    out, svg = tmp_path / "out.geojson", tmp_path / "s.svg"
    result = CliRunner().invoke(
        main, ["affine", str(inputs), "-o", str(out), "--vertices", "24", "--spline-svg", str(svg)]
    )
    assert result.exit_code == 0, result.output
    curves = read_curves(out)
    assert len(curves) == 2
    ring, arc = curves
    assert ring.closed and ring.points.shape == (24, 2)
    assert not arc.closed and arc.points.shape == (24, 2)
    assert affine.is_affine_arc_length(ring.points, closed=True, rtol=1e-6)
    assert affine.is_affine_arc_length(arc.points, rtol=1e-8)
    assert ring.properties["affine_area"] == pytest.approx(
        affine.coordinates(ring.points, closed=True)[0][0]
    )
    assert ring.properties["affine_closing_error"] < 1e-6
    back, closed = read_quadratic_path(svg)  # first path: the closed ring
    assert closed
    np.testing.assert_allclose(back, ring.points, atol=1e-9)


def test_affine_command_open_flag_and_errors(inputs, tmp_path):
    out = tmp_path / "out.csv"
    result = CliRunner().invoke(
        main, ["affine", str(inputs), "-o", str(out), "--vertices", "20", "--open"]
    )
    assert result.exit_code == 0, result.output
    assert not any(c.closed for c in read_curves(out))
    result = CliRunner().invoke(main, ["affine", str(inputs), "-o", str(out), "--vertices", "3"])
    assert result.exit_code == 2  # a bad option value is a usage error
    assert "Invalid value for '--vertices': 3 is not in the range x>=4" in result.output
    result = CliRunner().invoke(main, ["affine", str(inputs), "-o", str(out)])
    assert result.exit_code == 2  # --vertices is required


def test_a_spline_svg_that_cannot_be_written_leaves_no_output(inputs, tmp_path):
    # the control polygons were written, then --spline-svg failed: exit 1 with a file
    out = tmp_path / "a.csv"
    args = ["affine", str(inputs), "-o", str(out), "--vertices", "24"]
    args += ["--spline-svg", str(tmp_path / "no/s.svg")]
    res = CliRunner().invoke(main, args)
    assert (
        res.exit_code == 1 and res.output.startswith("Error: ") and "does not exist" in res.output
    )
    assert res.output.count("\n") == 1 and not out.exists()


@pytest.mark.parametrize("command", [["affine", "--vertices", "10"], ["fair"]])
def test_geojson_features_without_a_curve_pass_through_as_in_smooth(tmp_path, command):
    # fair and affine refused a feature with "geometry": null (RFC 7946 allows it), which
    # smooth and measure write through
    import json

    t = np.linspace(0, 1, 200)
    line = np.c_[100 * t, 20 * t**2 + 0.01 * np.sin(40 * t)]
    doc = {"type": "FeatureCollection", "features": [
        {"type": "Feature", "properties": {"n": 1},
         "geometry": {"type": "LineString", "coordinates": line.tolist()}},
        {"type": "Feature", "properties": {"n": 2}, "geometry": None},
    ]}  # fmt: skip
    src, out = tmp_path / "l.geojson", tmp_path / "o.geojson"
    src.write_text(json.dumps(doc))
    res = CliRunner().invoke(main, [command[0], str(src), "-o", str(out), *command[1:]])
    assert res.exit_code == 0, res.output
    assert "1 feature(s) without a curve geometry" in res.stderr
    back = json.loads(out.read_text())["features"]
    assert [(f["properties"]["n"], f["geometry"] is None) for f in back] == [(1, False), (2, True)]


def test_an_error_is_the_runs_only_line(inputs, tmp_path):
    # the curves' progress lines came before the error: stderr was not one line
    res = CliRunner().invoke(
        main, ["affine", str(inputs), "-o", str(tmp_path / "no" / "a.csv"), "--vertices", "24"]
    )
    assert res.exit_code == 1 and res.output.count("\n") == 1 and "does not exist" in res.output
    svg = tmp_path / "two.svg"
    svg.write_text(
        '<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 100 100"><circle cx="50" cy="50" '
        'r="30"/><rect x="10" y="10" width="80" height="50"/></svg>'
    )
    res = CliRunner().invoke(
        main, ["smooth", str(svg), "-o", str(tmp_path / "q.svg"), "--curves", "quadratic"]
    )
    assert res.exit_code == 1 and res.output.count("\n") == 1, res.output
    assert res.output.startswith("Error: curve 1: ") and not (tmp_path / "q.svg").exists()
