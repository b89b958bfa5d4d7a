import json

import numpy as np
import pytest

import curvesmith
from curvesmith import signed_area, subdivision
from curvesmith.cli import main

SQUARE = "x,y\n0,0\n4,0\n4,4\n0,4\n0,0\n"
TRACK = "x,y\n0,0\n1,1\n2,0\n3,1\n4,0\n"


def write(tmp_path, name, text):
    path = tmp_path / name
    path.write_text(text)
    return path


def read_csv_points(path):
    arr = np.genfromtxt(path, delimiter=",", names=True)
    return np.c_[arr["x"], arr["y"]]


def test_help_and_version(runner):
    res = runner.invoke(main, ["--help"])
    assert res.exit_code == 0
    for name in ("measure", "smooth", "demo"):
        assert name in res.output
    res = runner.invoke(main, ["--version"])
    assert res.exit_code == 0 and curvesmith.__version__ in res.output


def test_measure_json(runner, tmp_path):
    f = write(tmp_path, "sq.csv", SQUARE)
    res = runner.invoke(main, ["measure", str(f), "--json"])
    assert res.exit_code == 0, res.output
    (row,) = json.loads(res.output)["curves"]
    assert row["closed"] is True and row["points"] == 4
    assert row["length"] == 16.0 and row["signed_area"] == 16.0
    assert row["min_turning_angle"] == pytest.approx(np.pi / 2)
    assert row["max_turning_angle"] == pytest.approx(np.pi / 2)


def test_measure_table_open(runner, tmp_path):
    f = write(tmp_path, "t.csv", TRACK)
    res = runner.invoke(main, ["measure", str(f)])
    assert res.exit_code == 0, res.output
    line = res.output.splitlines()[1].split()
    assert line[1:3] == ["5", "no"]
    assert float(line[3]) == pytest.approx(4 * np.sqrt(2))
    assert float(line[5]) == pytest.approx(-90.0) and float(line[6]) == pytest.approx(90.0)


@pytest.mark.parametrize(
    ("method", "extra", "expected"),
    [
        ("chaikin", [], lambda p: subdivision.chaikin(p, closed=True, iterations=2)),
        (
            "derham",
            ["--gamma", "5"],
            lambda p: subdivision.de_rham(p, gamma=5, closed=True, iterations=2),
        ),
    ],
)
def test_smooth_linear_methods(runner, tmp_path, method, extra, expected):
    f = write(tmp_path, "sq.csv", SQUARE)
    out = tmp_path / "out.csv"
    res = runner.invoke(
        main, ["smooth", str(f), "-o", str(out), "--method", method, "--iterations", "2", *extra]
    )
    assert res.exit_code == 0, res.output
    got = read_csv_points(out)
    want = expected(np.array([[0, 0], [4, 0], [4, 4], [0, 4]], float))
    # Closed rings are written with the first point repeated.
    np.testing.assert_allclose(got[:-1], want)
    np.testing.assert_array_equal(got[0], got[-1])


def test_smooth_stdin_stdout(runner):
    res = runner.invoke(
        main,
        ["smooth", "-", "-o", "-", "--format", "csv", "--method", "chaikin", "--iterations", "1"],
        input=TRACK,
    )
    assert res.exit_code == 0, res.output
    lines = [ln for ln in res.output.splitlines() if ln.strip()]
    assert lines[0].lower().startswith("x,y")
    first = [float(v) for v in lines[1].split(",")[:2]]
    last = [float(v) for v in lines[-1].split(",")[:2]]
    assert first == [0.0, 0.0] and last == [4.0, 0.0]  # end points kept by default


def test_smooth_default_is_cca_and_keeps_area(runner, tmp_path):
    f = write(tmp_path, "sq.csv", SQUARE)
    out = tmp_path / "out.csv"
    res = runner.invoke(main, ["smooth", str(f), "-o", str(out)])
    assert res.exit_code == 0, res.output
    got = read_csv_points(out)
    assert len(got) > 5
    assert signed_area(got) == pytest.approx(16.0, rel=1e-12)


@pytest.mark.parametrize(
    ("args", "stdin", "message"),
    [
        (["measure", "{missing}"], None, "missing.csv"),
        (["measure", "{empty}"], None, "empty.csv"),
        (["smooth", "-", "-o", "{out}"], "x,y\n0,0\n", "--format is required"),
    ],
)
def test_data_errors_are_one_line_exit_1(runner, tmp_path, args, stdin, message):
    paths = {
        "missing": tmp_path / "missing.csv",
        "empty": write(tmp_path, "empty.csv", ""),
        "sq": write(tmp_path, "sq.csv", SQUARE),
        "out": tmp_path / "o.csv",
    }
    argv = [a.format(**paths) for a in args]
    res = runner.invoke(main, argv, input=stdin)
    assert res.exit_code == 1, res.output
    err = res.stderr if hasattr(res, "stderr") else res.output
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert len(lines) == 1 and lines[0].startswith("Error: ")
    assert message in lines[0]
    assert "Traceback" not in res.output


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--method", "derham", "--gamma", "0.5"], "'--gamma': 0.5 is not in the range x>1.0"),
        (
            ["--method", "chaikin", "--iterations", "-1"],
            "'--iterations': -1 is not in the range x>=0",
        ),
        (["--alpha", "big"], "'--alpha': 'big' is neither 'regular' nor a number"),
        (["--alpha", "0.5"], "'--alpha': '0.5' is not in the open interval (0, 1/3)"),
        (["--alpha", "nan"], "'--alpha': 'nan' is not in the open interval (0, 1/3)"),
        (
            ["--curves", "cubic", "--tolerance", "inf"],
            "'--tolerance': 'inf' is not a finite number",
        ),
        (["--anchors", "1,b"], "--anchors must be comma-separated integers, got '1,b'"),
    ],
)
def test_bad_option_values_are_one_line_usage_errors_exit_2(runner, tmp_path, args, message):
    out = tmp_path / "o.csv"
    res = runner.invoke(
        main, ["smooth", str(write(tmp_path, "sq.csv", SQUARE)), "-o", str(out), *args]
    )
    assert res.exit_code == 2, res.output
    err = res.stderr if hasattr(res, "stderr") else res.output
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert len(lines) == 1 and lines[0].startswith("Error: ")
    assert message in lines[0] and lines[0].endswith("(see 'main smooth --help')")
    assert not out.exists()


def test_usage_error_exit_2(runner):
    res = runner.invoke(main, ["smooth"])
    assert res.exit_code == 2
    res = runner.invoke(main, ["smooth", "a.csv", "-o", "b.csv", "--method", "bogus"])
    assert res.exit_code == 2


def test_demo_subdivision_section(runner, tmp_path):
    res = runner.invoke(main, ["demo", str(tmp_path / "d"), "--section", "subdivision"])
    assert res.exit_code == 0, res.output
    pngs = sorted(p.name for p in (tmp_path / "d").glob("*.png"))
    assert pngs == [
        "subdivision_area_loss.png",
        "subdivision_combs.png",
        "subdivision_overview.png",
    ]
    summary = json.loads((tmp_path / "d" / "summary.json").read_text())
    numbers = summary["sections"][0]["numbers"]
    # Linear corner cutting loses area: Chaikin x4 is strictly smaller than the input.
    assert numbers["area_Chaikin_x4"]["value"] < numbers["lake_area"]["value"]
    assert "Linear subdivision" in (tmp_path / "d" / "summary.md").read_text()
    res = runner.invoke(main, ["demo", str(tmp_path / "e"), "--section", "nope"])
    assert res.exit_code == 1 and "sections must be among" in res.output


def test_demo_section_of_a_missing_extra_is_reported_not_fatal(tmp_path, monkeypatch):
    import sys
    import types

    from curvesmith import demo
    from curvesmith.errors import MissingDependencyError

    fake = types.ModuleType("curvesmith.demo.fake_extra")
    fake.TITLE = "needs an extra"

    def run(ctx):
        raise MissingDependencyError("install it with: pip install 'curvesmith[geo]'")

    fake.run = run
    monkeypatch.setitem(sys.modules, "curvesmith.demo.fake_extra", fake)
    monkeypatch.setattr(demo, "SECTIONS", ["subdivision", "fake_extra"])
    summary = demo.run_demo(tmp_path, sections=["fake_extra", "subdivision"])
    assert [s["name"] for s in summary["sections"]] == ["fake_extra", "subdivision"]
    assert "Not run" in summary["sections"][0]["text"][0]
    assert "curvesmith[geo]" in (tmp_path / "summary.md").read_text()
    assert (tmp_path / "subdivision_overview.png").exists()


def test_measure_skips_geojson_features_without_curves(runner, tmp_path):
    # a NULL or empty geometry is data in GeoJSON (smooth writes it through); measure failed
    feats = [
        {"type": "Feature", "properties": {}, "geometry": None},
        {"type": "Feature", "properties": {}, "geometry": {"type": "Polygon", "coordinates": []}},
        {"type": "Feature", "properties": {},
         "geometry": {"type": "Polygon", "coordinates": [[[0, 0], [4, 0], [4, 3], [0, 0]]]}},
    ]  # fmt: skip
    src = tmp_path / "gaps.geojson"
    src.write_text(json.dumps({"type": "FeatureCollection", "features": feats}))
    res = runner.invoke(main, ["measure", str(src), "--json"])
    assert res.exit_code == 0, res.output
    (row,) = json.loads(res.stdout)["curves"]
    assert row["signed_area"] == 6.0 and row["feature"] == 2
    assert res.stderr.strip() == (
        "2 feature(s) without a curve geometry (NULL, empty, Point, MultiPoint) not measured"
    )


@pytest.mark.parametrize("name", ["folder", "folder.gpkg", "folder.csv", "folder.tif"])
@pytest.mark.parametrize(
    "command",
    [
        ["measure", "{src}"],
        ["smooth", "{src}", "-o", "{out}.csv"],
        ["smooth", "{src}", "-o", "{out}.gpkg"],
        ["smooth", "{src}", "-o", "{out}.gpkg", "--coverage"],
        ["smooth", "{src}", "-o", "{out}.gpkg", "--network"],
        ["batch", "smooth", "{src}", "-o", "{out}.gpkg"],
        ["affine", "{src}", "-o", "{out}.csv", "--vertices", "8"],
        ["fair", "{src}", "-o", "{out}.csv"],
        ["contours", "{src}", "-o", "{out}.gpkg", "--interval", "1"],
    ],
)
def test_a_directory_as_input_is_named_as_one(runner, tmp_path, name, command):
    # measure and smooth said "no file suffix" of a folder without one, and GDAL's "not
    # recognized as being in a supported file format" of one named like a GeoPackage
    src = tmp_path / name
    src.mkdir()
    args = [a.format(src=src, out=tmp_path / "out") for a in command]
    res = runner.invoke(main, args)
    assert res.exit_code == 1, res.output
    assert res.stderr == f"Error: {src}: is a directory, not a file\n"
    assert res.stdout == ""
    assert sorted(p.name for p in tmp_path.iterdir()) == [name]  # nothing written


def test_geo_read_file_names_a_directory(tmp_path):
    from curvesmith import geo
    from curvesmith.errors import CurveFormatError

    (tmp_path / "roads.gpkg").mkdir()
    with pytest.raises(CurveFormatError, match=r"roads\.gpkg: is a directory, not a file$"):
        geo.read_file(tmp_path / "roads.gpkg")


def test_geojson_to_geojson_says_what_the_gis_path_says(runner, tmp_path):
    # GeoJSON -> GeoJSON (ring by ring, curvesmith.io) printed no summary and no
    # geographic-CRS warning, where the same file to a GeoPackage printed both
    from curvesmith import geo

    df = geo.us_counties(states=["44"])  # NAD83 degrees: a crs member in the file
    src = tmp_path / "ri.geojson"
    df.to_file(src, driver="GeoJSON")
    gis = runner.invoke(main, ["smooth", str(src), "-o", str(tmp_path / "ri.gpkg")])
    plain = runner.invoke(main, ["smooth", str(src), "-o", str(tmp_path / "o.geojson")])
    assert gis.exit_code == plain.exit_code == 0, plain.output
    assert plain.stderr.splitlines() == gis.stderr.splitlines()  # the warning, 5 of 5 smoothed
    assert "(NAD83)" in plain.stderr and "5 of 5 feature(s) smoothed" in plain.stderr
    # RFC 7946 without a crs member is WGS 84; metres without one are not degrees
    for crs, said in (("EPSG:4326", "(WGS 84)"), ("EPSG:3857", None)):
        doc = json.loads(df.to_crs(crs).to_json())
        doc.pop("crs", None)
        src.write_text(json.dumps(doc))
        res = runner.invoke(main, ["smooth", str(src), "-o", str(tmp_path / "o.geojson")])
        lines = res.stderr.splitlines()
        assert lines[-1] == "5 of 5 feature(s) smoothed"
        assert (said in lines[0]) if said else len(lines) == 1


def test_format_is_the_format_of_standard_input_and_output(runner, tmp_path):
    # --format applied to both sides: `smooth - -o out.geojson --format csv` wrote CSV text
    # into out.geojson, and `smooth arc.csv -o - --format geojson` read arc.csv as JSON
    src = tmp_path / "arc.csv"
    src.write_text("x,y\n0,0\n1,2\n3,1\n4,4\n")
    out = tmp_path / "out.geojson"
    res = runner.invoke(
        main, ["smooth", "-", "-o", str(out), "--format", "csv"], input=src.read_text()
    )
    assert res.exit_code == 0, res.output
    res = runner.invoke(main, ["smooth", str(src), "-o", "-", "--format", "geojson"])
    assert res.exit_code == 0, res.output
    assert json.loads(out.read_text()) == json.loads(res.stdout)  # GeoJSON both times
