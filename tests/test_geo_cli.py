"""smooth_geofile: the GIS-file path of ``curvesmith smooth``."""

import numpy as np
import pandas as pd
import pytest
import shapely

from curvesmith import geo
from curvesmith.cli.geo import is_geofile, smooth_geofile
from curvesmith.errors import CurveError


def test_is_geofile():
    assert is_geofile("a.gpkg") and is_geofile("A.SHP") and is_geofile("x.fgb")
    assert not is_geofile("a.geojson") and is_geofile("a.geojson", coverage=True)
    assert not is_geofile("a.csv", coverage=True)


def test_smooth_geofile_coverage_with_summary(tmp_path, capsys):
    df = geo.us_counties(states=["44"])  # Rhode Island in NAD83 degrees
    src = tmp_path / "ri.gpkg"
    geo.write_file(df, src, layer="counties")
    out = tmp_path / "ri_out.gpkg"
    rep = smooth_geofile(
        str(src), str(out), coverage=True, layer="counties", alpha="0.2", iterations=2
    )
    err = capsys.readouterr().err
    assert "Warning:" in err and "geographic CRS" in err
    assert "5 of 5 feature(s) smoothed" in err and "coverage valid" in err
    assert rep.coverage_valid
    back = geo.read_file(out, layer="counties")
    np.testing.assert_allclose(
        shapely.area(back.geometry.values), shapely.area(df.geometry.values), rtol=1e-9
    )


def test_smooth_geofile_equal_area_no_warning(tmp_path, capsys):
    df = geo.us_counties(states=["44"])
    src = tmp_path / "ri.shp"
    geo.write_file(df, src)
    smooth_geofile(str(src), str(tmp_path / "o.fgb"), equal_area=True, layer="0")
    assert "Warning" not in capsys.readouterr().err


@pytest.mark.parametrize("command", [["smooth"], ["batch", "smooth", "--workers", "1"]])
def test_equal_area_names_a_feature_off_the_globe(tmp_path, command):
    # a vertex outside the CRS's area projects to inf: --equal-area ended in a traceback
    # (ValueError: cannot convert float NaN to integer) in the grouping of the features
    import geopandas as gpd
    from click.testing import CliRunner

    from curvesmith.cli import main

    boxes = [shapely.box(0, 0, 10, 10), shapely.box(1e9, 1e9, 1e9 + 10, 1e9 + 10)]
    src, out = tmp_path / "far.gpkg", tmp_path / "out.gpkg"
    gpd.GeoDataFrame({"k": [0, 1]}, geometry=boxes, crs="EPSG:32633").to_file(src)
    res = CliRunner().invoke(main, [*command, str(src), "-o", str(out), "--equal-area"])
    assert res.exit_code == 1
    assert "Traceback" not in res.output and res.output.count("\n") == 1, res.output
    assert "feature 1 cannot be placed on the globe" in res.output
    assert "(1.00000001e+09, 1e+09)" in res.output and "UTM zone 33N" in res.output
    assert not out.exists()
    res = CliRunner().invoke(main, [*command, str(src), "-o", str(out)])  # without: smoothed
    assert res.exit_code == 0, res.output


def test_smooth_geofile_bad_method_and_alpha(tmp_path):
    src = tmp_path / "x.gpkg"
    geo.write_file(geo.us_counties(states=["10"]), src)
    with pytest.raises(CurveError, match="--method derham is not available for GIS files"):
        smooth_geofile(str(src), str(tmp_path / "o.gpkg"), method="derham")
    with pytest.raises(CurveError, match="--alpha must be 'regular' or a number, got 'big'"):
        smooth_geofile(str(src), str(tmp_path / "o.gpkg"), alpha="big")


def test_curvesmith_smooth_routes_gis_files_through_geo(tmp_path):
    from click.testing import CliRunner

    from curvesmith.cli import main

    df = geo.us_counties(states=["44"])
    src = tmp_path / "ri.gpkg"
    geo.write_file(df, src, layer="counties")
    out = tmp_path / "ri_out.gpkg"
    runner = CliRunner()
    res = runner.invoke(
        main,
        [
            "smooth",
            str(src),
            "-o",
            str(out),
            "--coverage",
            "--layer",
            "counties",
            "--iterations",
            "2",
        ],
    )
    assert res.exit_code == 0, res.output
    assert "coverage valid" in res.output
    back = geo.read_file(out, layer="counties")
    assert list(back.columns) == list(df.columns)
    assert shapely.coverage_is_valid(back.geometry.values)
    np.testing.assert_allclose(
        shapely.area(back.geometry.values), shapely.area(df.geometry.values), rtol=1e-9
    )
    # GIS-only options on a plain curve file, and derham on a GIS file: one-line usage
    # errors, exit status 2 as the README's contract says (they exited 1 before)
    csv = tmp_path / "a.csv"
    csv.write_text("x,y\n0,0\n1,1\n2,0\n")
    res = runner.invoke(main, ["smooth", str(csv), "-o", str(tmp_path / "b.csv"), "--coverage"])
    assert res.exit_code == 2 and "apply to GIS files" in res.output
    res = runner.invoke(main, ["smooth", str(src), "-o", str(out), "--method", "derham"])
    assert res.exit_code == 2 and "not available for GIS files" in res.output


@pytest.mark.parametrize(
    "args",
    [
        ["--method", "derham"],
        ["--coverage", "--network"],
        ["--anchors", "1,2"],
        ["--curves", "quadratic"],
        ["--snap", "1"],
        ["--coverage", "--snap", "nan"],
    ],
)
def test_option_clashes_on_gis_files_are_usage_errors(tmp_path, args):
    # options that do not go together, or a bad value, are usage errors (exit 2, as the README
    # says); they exited 1, a data error. From Python they stay CurveErrors.
    from click.testing import CliRunner

    from curvesmith.cli import main

    src = tmp_path / "x.gpkg"
    geo.write_file(geo.us_counties(states=["10"]), src)
    out = tmp_path / "o.gpkg"
    res = CliRunner().invoke(main, ["smooth", str(src), "-o", str(out), *args])
    assert res.exit_code == 2, res.output
    assert res.output.startswith("Error: ") and len(res.output.strip().splitlines()) == 1
    assert not out.exists()


@pytest.mark.parametrize("command", [["smooth"], ["batch", "smooth", "--workers", "1"]])
def test_layer_by_index_or_name_writes_the_same_output_layer(tmp_path, command):
    # --layer 1 wrote the output layer under the output's stem, --layer two under "two"
    import pyogrio
    from click.testing import CliRunner

    from curvesmith.cli import main

    df = geo.us_counties(states=["44"]).to_crs("EPSG:32619")  # Rhode Island
    src = tmp_path / "two_layers.gpkg"
    geo.write_file(df.iloc[:2], src, layer="one")
    geo.write_file(df.iloc[2:], src, layer="two")
    names = []
    for k, layer in enumerate(["1", "two"]):
        out = tmp_path / f"out{k}.gpkg"
        res = CliRunner().invoke(main, [*command, str(src), "-o", str(out), "--layer", layer])
        assert res.exit_code == 0, res.output
        names.append([str(n) for n, _ in pyogrio.list_layers(out)])
        back = geo.read_file(out)
        assert len(back) == len(df) - 2
        np.testing.assert_allclose(
            shapely.area(back.geometry.values), shapely.area(df.geometry.values[2:]), rtol=1e-9
        )
    assert names == [["two"], ["two"]]


@pytest.mark.parametrize("command", [["smooth"], ["batch", "smooth", "--workers", "1"]])
def test_layer_replaced_in_place_keeps_its_place_in_the_list(tmp_path, command):
    # GDAL replaces a layer by deleting and creating it, which listed it last: the next
    # `--layer 1` then named another layer (and smoothed the smoothed one again)
    import pyogrio
    from click.testing import CliRunner

    from curvesmith.cli import main

    df = geo.us_counties(states=["44"]).to_crs("EPSG:32619")  # Rhode Island, 5 counties
    gpkg = tmp_path / "project.gpkg"
    for k, name in enumerate(["roads", "Parcels", "lakes"]):
        geo.write_file(df.iloc[k : k + 2], gpkg, layer=name)
    pyogrio.write_dataframe(pd.DataFrame({"owner": ["a", "b"]}), gpkg, layer="owners")
    before = [str(n) for n in pyogrio.list_layers(gpkg)[:, 0]]
    assert before == ["roads", "Parcels", "lakes", "owners"]
    for _ in range(2):  # the same index twice: the same layer, smoothed twice
        res = CliRunner().invoke(
            main, [*command, str(gpkg), "-o", str(gpkg), "--layer", "1", "--iterations", "1"]
        )
        assert res.exit_code == 0, res.output
        assert [str(n) for n in pyogrio.list_layers(gpkg)[:, 0]] == before
    twice = geo.smooth(geo.smooth(df.iloc[1:3], iterations=1), iterations=1)
    back = geo.read_file(gpkg, layer="Parcels")  # (a GeoPackage layer of one type: Multi)
    assert np.array_equal(
        shapely.get_coordinates(back.geometry.values),
        shapely.get_coordinates(twice.geometry.values),
    )
    for k, name in [(0, "roads"), (2, "lakes")]:  # the others as they were
        other = geo.read_file(gpkg, layer=name)
        assert np.array_equal(
            shapely.get_coordinates(other.geometry.values),
            shapely.get_coordinates(df.geometry.values[k : k + 2]),
        )
    assert list(pyogrio.read_dataframe(gpkg, layer="owners")["owner"]) == ["a", "b"]


def test_a_named_layer_into_a_damaged_or_empty_geopackage(tmp_path):
    # the layer order is read from the existing file: a damaged one is geo's error (the
    # CLI's one line), not sqlite's traceback; an empty file is a new GeoPackage
    from curvesmith.errors import CurveFormatError

    df = geo.us_counties(states=["44"]).to_crs("EPSG:32619")
    bad = tmp_path / "bad.gpkg"
    bad.write_bytes(b"not a database " * 100)
    with pytest.raises(CurveFormatError, match=r"cannot write .*bad\.gpkg.*not a database"):
        geo.write_file(df, bad, layer="x")
    assert bad.read_bytes() == b"not a database " * 100
    empty = tmp_path / "empty.gpkg"
    empty.touch()
    geo.write_file(df, empty, layer="x")
    assert len(geo.read_file(empty, layer="x")) == len(df)


@pytest.mark.parametrize("coverage", [False, True])
def test_iterations_zero_says_so_and_writes_the_input(tmp_path, coverage):
    from click.testing import CliRunner

    from curvesmith.cli import main

    df = geo.us_counties(states=["44"])  # Rhode Island's 5 counties
    src, out = tmp_path / "ri.gpkg", tmp_path / "ri_out.gpkg"
    geo.write_file(df, src)
    args = ["smooth", str(src), "-o", str(out), "--iterations", "0"]
    res = CliRunner().invoke(main, args + (["--coverage"] if coverage else []))
    assert res.exit_code == 0, res.output
    first = res.stderr.strip().split("; ")[0]
    assert first == f"{len(df)} feature(s) written as they were (--iterations 0)", res.stderr
    back, given = geo.read_file(out), geo.read_file(src)  # (both MultiPolygon layers)
    assert shapely.equals_exact(back.geometry.values, given.geometry.values, 0.0).all()
