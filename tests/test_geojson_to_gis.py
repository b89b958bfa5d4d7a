"""GeoJSON in, GIS files out, and one policy for NULL and Point features (issue 13).

A plain GeoJSON file written to ``.gpkg``/``.shp``/``.fgb`` goes through curvesmith.geo
(attributes and CRS kept, output valid); its ``"geometry": null`` features are data
(RFC 7946), whichever path reads them, while NULLs in a GeoPackage or Shapefile stay an
error unless ``--allow-null`` (a damaged file reads as NULLs). Points and MultiPoints
have nothing to smooth: both paths write them through unchanged.
"""

from __future__ import annotations

import json
from pathlib import Path

import geopandas as gpd
import numpy as np
import pyogrio
import pytest
import shapely
from click.testing import CliRunner

from curvesmith.cli import main

NATURAL_EARTH = (
    Path(pyogrio.__file__).parent / "tests" / "fixtures" / "naturalearth_lowres"
) / "naturalearth_lowres.shp"


def _mixed_layer(tmp_path: Path, point: bool = True) -> Path:
    """Ten countries of Natural Earth as GeoJSON, plus a NULL and a Point feature."""
    world = gpd.read_file(NATURAL_EARTH).iloc[[4, 8, 20, 30, 43, 55, 61, 97, 120, 150]]
    fc = json.loads(world.to_json())
    fc["features"].insert(3, {"type": "Feature", "properties": {"name": "nul"}, "geometry": None})
    fc["features"] += [
        {
            "type": "Feature",
            "properties": {"name": "capital"},
            "geometry": {"type": "Point", "coordinates": [2.35, 48.86]},
        }
    ][: int(point)]
    src = tmp_path / "mixed.geojson"
    src.write_text(json.dumps(fc))
    return src


@pytest.mark.parametrize("suffix", [".gpkg", ".shp", ".fgb"])
def test_plain_geojson_to_a_gis_file_keeps_everything(tmp_path, suffix):
    src = _mixed_layer(tmp_path, point=suffix != ".shp")  # a Shapefile has one geometry type
    out = tmp_path / f"out{suffix}"
    res = CliRunner().invoke(main, ["smooth", str(src), "-o", str(out), "--iterations", "2"])
    assert res.exit_code == 0, res.output
    assert "1 without geometry (NULL)" in res.stderr
    assert ("1 Point/MultiPoint feature(s) written through" in res.stderr) == (suffix != ".shp")
    before, after = gpd.read_file(src), gpd.read_file(out)
    assert after.crs.equals(before.crs)
    assert after["name"].tolist() == before["name"].tolist()
    assert after["pop_est"].fillna(-1).tolist() == before["pop_est"].fillna(-1).tolist()
    assert after.geometry.iloc[3] is None
    if suffix != ".shp":  # the Point
        assert after.geometry.iloc[-1].equals(before.geometry.iloc[-1])
    poly = before.geom_type.isin(["Polygon", "MultiPolygon"]).to_numpy()
    a0 = shapely.area(before.geometry.values[poly])
    a1 = shapely.area(after.geometry.values[poly])
    assert np.max(np.abs(a1 / a0 - 1)) < 1e-9  # cca: areas exact (in degrees, no --equal-area)
    assert shapely.is_valid(after.geometry.values[poly]).all()
    assert (
        shapely.get_num_coordinates(after.geometry.values[poly])
        > 2 * shapely.get_num_coordinates(before.geometry.values[poly])
    ).all()


def test_geojson_nulls_are_data_in_both_paths_but_gis_nulls_need_allow_null(tmp_path):
    src = _mixed_layer(tmp_path)
    runner = CliRunner()
    plain = runner.invoke(main, ["smooth", str(src), "-o", str(tmp_path / "o.geojson")])
    coverage = runner.invoke(
        main, ["smooth", str(src), "-o", str(tmp_path / "c.gpkg"), "--coverage"]
    )
    assert plain.exit_code == 0 and coverage.exit_code == 0, plain.output + coverage.output
    assert json.loads((tmp_path / "o.geojson").read_text())["features"][3]["geometry"] is None
    assert gpd.read_file(tmp_path / "c.gpkg").geometry.iloc[3] is None
    # the same NULL in a GeoPackage: maybe a damaged file, an error without --allow-null
    gpkg = tmp_path / "mixed.gpkg"
    gpd.read_file(src).to_file(gpkg)
    res = runner.invoke(main, ["smooth", str(gpkg), "-o", str(tmp_path / "g.gpkg")])
    assert res.exit_code == 1 and "1 of 12 features have no geometry" in res.stderr
    assert not (tmp_path / "g.gpkg").exists()
    res = runner.invoke(main, ["smooth", str(gpkg), "-o", str(tmp_path / "g.gpkg"), "--allow-null"])
    assert res.exit_code == 0, res.output


def test_curves_from_csv_to_a_gis_file_get_a_true_message(tmp_path):
    src = tmp_path / "sq.csv"
    src.write_text("x,y\n0,0\n4,0\n4,3\n0,3\n")
    res = CliRunner().invoke(main, ["smooth", str(src), "-o", str(tmp_path / "sq.gpkg")])
    assert res.exit_code == 1
    assert res.stderr.strip() == (
        f"Error: {tmp_path / 'sq.gpkg'}: GIS files (.gpkg, .shp, .fgb) are written from GIS "
        f"or GeoJSON input; {src} is not one: write .geojson, .csv or .svg"
    )
    assert not (tmp_path / "sq.gpkg").exists()


def test_empty_geometries_pass_through_in_both_paths(tmp_path):
    # an empty Polygon was an error written to GeoJSON ("the geometry is empty") and passed
    # through written to a GeoPackage; it is data in both, like a NULL
    src = _mixed_layer(tmp_path, point=False)
    fc = json.loads(src.read_text())
    empty = {"type": "Feature", "properties": {"name": "void"},
             "geometry": {"type": "Polygon", "coordinates": []}}  # fmt: skip
    fc["features"].insert(5, empty)
    src.write_text(json.dumps(fc))
    runner = CliRunner()
    for suffix in ("geojson", "gpkg"):
        out = tmp_path / f"o.{suffix}"
        res = runner.invoke(main, ["smooth", str(src), "-o", str(out)])
        assert res.exit_code == 0, res.output
        back = gpd.read_file(out)
        assert back["name"].tolist() == [f["properties"]["name"] for f in fc["features"]]
        g = back.geometry.iloc[5]  # a GeoPackage layer of Polygons and MultiPolygons: Multi
        assert g.is_empty and g.geom_type in ("Polygon", "MultiPolygon")
    assert json.loads((tmp_path / "o.geojson").read_text())["features"][5] == empty
    assert "10 of 12 feature(s) smoothed; 1 without geometry (NULL) and 1 empty" in res.stderr


@pytest.mark.parametrize(
    "option", [["--make-valid"], ["--allow-null"], ["--equal-area"], ["--max-shift", "0.5"]]
)
def test_gis_options_on_geojson_to_geojson_go_through_geo(tmp_path, option):
    # these were refused for GeoJSON output with a message that listed GeoJSON as allowed
    src = _mixed_layer(tmp_path, point=False)
    out = tmp_path / "o.geojson"
    res = CliRunner().invoke(main, ["smooth", str(src), "-o", str(out), *option])
    assert res.exit_code == 0, res.output
    assert "10 of 11 feature(s) smoothed" in res.stderr
    before, after = gpd.read_file(src), gpd.read_file(out)
    assert after["name"].tolist() == before["name"].tolist()
    poly = ~before.geometry.isna().to_numpy()
    assert shapely.is_valid(after.geometry.values[poly]).all()
    if option[0] != "--equal-area":  # planar areas in degrees exact; equal-area: ground areas
        a0, a1 = (
            shapely.area(before.geometry.values[poly]),
            shapely.area(after.geometry.values[poly]),
        )
        assert np.max(np.abs(a1 / a0 - 1)) < 1e-9


def test_xyz_geojson_gives_the_same_answer_whichever_output(tmp_path):
    # the ring by ring path smoothed an XYZ GeoJSON in 3D: written as .geojson its XY were
    # 1.65 m from the .gpkg answer and its Z left the input's range (99.98-140.0066 for
    # 100-140); now it is smoothed in XY with Z interpolated, as GIS data are
    t = np.linspace(0, 2 * np.pi, 40)[:-1]
    r = 50 + 8 * np.sin(5 * t)
    ring = np.c_[5e5 + r * np.cos(t), 5e6 + r * np.sin(t), 100 + 40 * t / t[-1]]
    ring = np.vstack([ring, ring[:1]])
    line = np.c_[
        np.linspace(5e5, 5e5 + 300, 30),
        5e6 + 20 * np.sin(np.arange(30.0)),
        np.linspace(200, 300, 30),
    ]
    doc = {
        "type": "FeatureCollection",
        "crs": {"type": "name", "properties": {"name": "urn:ogc:def:crs:EPSG::32633"}},
        "features": [
            {"type": "Feature", "properties": {"name": "zpoly"},
             "geometry": {"type": "Polygon", "coordinates": [ring.tolist()]}},
            {"type": "Feature", "properties": {"name": "zline"},
             "geometry": {"type": "LineString", "coordinates": line.tolist()}},
        ],
    }  # fmt: skip
    src = tmp_path / "z.geojson"
    src.write_text(json.dumps(doc))
    outs = {}
    for suffix in (".geojson", ".gpkg"):
        out = tmp_path / f"out{suffix}"
        res = CliRunner().invoke(main, ["smooth", str(src), "-o", str(out), "--iterations", "2"])
        assert res.exit_code == 0, res.output
        outs[suffix] = gpd.read_file(out)
    a, b = outs[".geojson"], outs[".gpkg"]
    assert list(a["name"]) == ["zpoly", "zline"]
    for ga, gb, z in zip(a.geometry, b.geometry, ([100, 140], [200, 300]), strict=True):
        ca = shapely.get_coordinates(ga, include_z=True)
        assert np.array_equal(ca, shapely.get_coordinates(gb, include_z=True))
        assert z[0] <= ca[:, 2].min() and ca[:, 2].max() <= z[1]
    assert a.geometry[0].area == pytest.approx(shapely.Polygon(ring[:, :2]).area, rel=1e-12)
