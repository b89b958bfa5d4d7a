"""Every polygon path gives valid output or says why not (issue 13.2).

Plain GeoJSON, CSV and SVG go through ring-by-ring smoothing, which knows nothing of a
polygon's other rings; the CLI checks every smoothed polygon with shapely and smooths the
invalid ones again through curvesmith.geo (conflicting pieces smoothed less, areas exact).
Data: US Census counties shipped by plotly-geo (a valid coverage).
"""

from __future__ import annotations

import json

import geopandas as gpd
import numpy as np
import pytest
import shapely
from click.testing import CliRunner

from curvesmith import cca, geo
from curvesmith import io as cio
from curvesmith.cli import main
from curvesmith.internals import geo_io

#: Counties of Washington (53) and Virginia (51): Grays Harbor, Thurston, Buena Vista and
#: Rockbridge come out invalid from one ring-by-ring CCA pass.
STATES = ["53", "51"]


def _shoelace(p):
    x, y = p[:, 0], p[:, 1]
    return 0.5 * float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))


@pytest.fixture(scope="module")
def counties_geojson(tmp_path_factory):
    df = geo.us_counties(states=STATES)
    path = tmp_path_factory.mktemp("counties") / "counties.geojson"
    df.to_crs("EPSG:4326").to_file(path, driver="GeoJSON")
    return path, df


def _valid_flags(path):
    text = json.loads(path.read_text())
    geoms = [shapely.geometry.shape(f["geometry"]) for f in text["features"]]
    return shapely.is_valid(np.array(geoms, dtype=object)), text["features"]


def test_ring_by_ring_smoothing_alone_breaks_some_counties(counties_geojson):
    path, df = counties_geojson
    assert shapely.is_valid(df.geometry.values).all()
    curves = cio.read_curves(path)
    out = [c.replace(cca.smooth(c.points, closed=True)) for c in curves]
    _, report = geo_io.keep_polygons_valid(curves, out, method="cca", iterations=1)
    names = set(df["NAME"].iloc[list(report.resmoothed)])
    assert {"Grays Harbor", "Thurston", "Buena Vista", "Rockbridge"} <= names
    assert report.n_polygons == len(df) and not report.still_invalid


def test_cli_geojson_counties_are_all_valid_and_keep_ring_areas(counties_geojson, tmp_path):
    path, df = counties_geojson
    out = tmp_path / "smooth.geojson"
    res = CliRunner().invoke(main, ["smooth", str(path), "-o", str(out)])
    assert res.exit_code == 0, res.output
    assert "polygon(s) smoothed less where their rings would cross, to stay valid" in res.output
    valid, features = _valid_flags(out)
    assert valid.all() and len(features) == len(df)
    before = cio.read_curves(path)
    after = cio.read_curves(out)
    assert [(c.feature, c.part, c.ring) for c in after] == [
        (c.feature, c.part, c.ring) for c in before
    ]
    for a, b in zip(before, after, strict=True):
        # exact up to rounding: the shoelace of small rings at lon -120 cancels ~1e-12 deg^2
        area = abs(_shoelace(a.points))
        assert abs(_shoelace(b.points)) == pytest.approx(area, rel=1e-9, abs=1e-11)
        assert len(b.points) >= len(a.points)


#: A ring with a neck 0.1 wide: CCA on the ring alone makes it cross itself.
NECK = np.array([[0, 0], [10, 0], [10, 1], [5.05, 1.0], [5.05, 9], [10, 9], [10, 10],
                 [0, 10], [0, 9], [4.95, 9], [4.95, 1.0], [0, 1]], dtype=float)  # fmt: skip


def test_cli_csv_rings_checked_too(tmp_path):
    neck = NECK
    assert not shapely.Polygon(cca.smooth(neck, closed=True, iterations=3)).is_valid
    src = tmp_path / "neck.csv"
    cio.write_curves([cio.Curve(neck, closed=True)], src)
    out = tmp_path / "o.csv"
    res = CliRunner().invoke(main, ["smooth", str(src), "-o", str(out), "--iterations", "3"])
    assert res.exit_code == 0, res.output
    (c,) = cio.read_curves(out)
    assert shapely.Polygon(c.points).is_valid
    assert _shoelace(c.points) == pytest.approx(_shoelace(neck), rel=1e-12)
    assert len(c.points) >= 3 * len(neck)


def test_invalid_input_polygons_are_refused_as_for_gis_output(tmp_path):
    # smoothed ring by ring a bow-tie stays crossed; the same file written to a GeoPackage
    # was refused while GeoJSON output exited 0 with a warning: one input, one answer
    bowtie = {"type": "Polygon", "coordinates": [[[0, 0], [2, 2], [2, 0], [0, 2], [0, 0]]]}
    good = {"type": "Polygon", "coordinates": [[[5, 0], [7, 0], [7, 2], [5, 2], [5, 0]]]}
    feats = [{"type": "Feature", "properties": {"n": k}, "geometry": g}
             for k, g in enumerate([good, bowtie, bowtie])]  # fmt: skip
    src = tmp_path / "bow.geojson"
    src.write_text(json.dumps({"type": "FeatureCollection", "features": feats}))
    for suffix in ("geojson", "gpkg"):
        out = tmp_path / f"o.{suffix}"
        res = CliRunner().invoke(main, ["smooth", str(src), "-o", str(out)])
        assert res.exit_code == 1, res.output
        lines = res.output.strip().splitlines()
        assert len(lines) == 1 or suffix == "gpkg", lines  # gpkg: also the CRS warning
        # the file's feature and the flag, in the command line's words on both paths
        assert "feature 1 is not valid" in lines[-1] or "feature 1 is not a valid" in lines[-1]
        assert "Self-intersection" in lines[-1] and "(and 1 more)" in lines[-1]
        assert "pass --make-valid to repair" in lines[-1]
        assert "make_valid=" not in res.output and "smooth_file(" not in res.output
        assert not out.exists()
        res = CliRunner().invoke(main, ["smooth", str(src), "-o", str(out), "--make-valid"])
        assert res.exit_code == 0, res.output
        back = gpd.read_file(out)
        assert back["n"].tolist() == [0, 1, 2]
        assert shapely.is_valid(back.geometry.values).all()
        # the repaired bow-tie is two triangles, their area kept by the smoothing
        assert back.geometry.values[1].area == pytest.approx(2.0, rel=1e-12)


def test_anchored_invalid_output_says_why(tmp_path):
    # geo.smooth has no fixed anchors, so an invalid anchored result is reported, not redone
    src = tmp_path / "neck.geojson"
    cio.write_curves([cio.Curve(NECK, closed=True, kind="Polygon")], src)
    out = tmp_path / "o.geojson"
    res = CliRunner().invoke(main, ["smooth", str(src), "-o", str(out), "--anchors", "0"])
    assert res.exit_code == 0, res.output
    (c,) = cio.read_curves(out)
    assert not shapely.Polygon(c.points).is_valid
    assert "1 polygon(s) are invalid after smoothing with --anchors (feature 0: " in res.output
