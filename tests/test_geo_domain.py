"""Longitude/latitude data stays on the map: vertices on ±180° / ±90° fixed, outputs inside the domain.

Natural Earth's countries (pyogrio's test fixture) cross the antimeridian (Fiji, Russia) and reach
the south pole (Antarctica); smoothing them in degrees without the guard moves coordinates past
±180° and below -90°, which projections then turn into inf.
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest

gpd = pytest.importorskip("geopandas", reason="needs the geo extra")
shapely = pytest.importorskip("shapely", reason="needs the geo extra")
pyogrio = pytest.importorskip("pyogrio", reason="needs the geo extra")

from curvesmith import geo  # noqa: E402
from curvesmith.errors import CurveError  # noqa: E402
from curvesmith.internals import geo_io  # noqa: E402

NE = Path(pyogrio.__file__).parent / "tests" / "fixtures" / "naturalearth_lowres"
NE = NE / "naturalearth_lowres.shp"


def _outside(xy):
    return np.maximum(np.abs(xy[:, 0]) - 180.0, np.abs(xy[:, 1]) - 90.0)


@pytest.fixture(scope="module")
def countries():
    return gpd.read_file(NE)


def test_unguarded_smoothing_leaves_the_map(countries):
    # the reason for the guard: plain planar smoothing in degrees (and it says so)
    with pytest.warns(geo.GeographicCRSWarning, match="moved vertices beyond"):
        out = geo.smooth(countries, iterations=3)
    assert (_outside(shapely.get_coordinates(out.geometry.values)) > 1e-6).sum() > 50


@pytest.mark.parametrize(
    "options",
    [{"iterations": 3}, {"iterations": 2, "equal_area": True}, {"iterations": 1, "coverage": True}],
    ids=["degrees", "equal-area", "coverage"],
)
def test_smooth_file_keeps_lonlat_data_on_the_map(countries, tmp_path, options):
    if options.get("coverage"):  # the world is no clean coverage; a continent's countries are
        src = countries[countries["continent"] == "Antarctica"]
        src = gpd.GeoDataFrame(
            geometry=[*src.geometry.values, shapely.box(-180, -60, 180, -55)], crs=countries.crs
        )
    else:
        src = countries
    path = tmp_path / "in.gpkg"
    src.to_file(path)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        geo_io.smooth_file(path, tmp_path / "out.gpkg", **options)
    out = gpd.read_file(tmp_path / "out.gpkg")
    xy0 = shapely.get_coordinates(src.geometry.values)
    xy = shapely.get_coordinates(out.geometry.values)
    assert _outside(xy).max() <= 0.0  # inside the domain, to the last bit
    # every input vertex on an edge is still there (Natural Earth's 180.00000000000006 on it)
    edge = _outside(xy0) >= -1e-9
    assert edge.sum() >= 2
    kept = np.clip(xy0[edge], [-180.0, -90.0], [180.0, 90.0])
    have = set(map(tuple, xy))
    assert all(tuple(p) in have for p in kept)
    assert shapely.is_valid(out.geometry.values).all()
    assert len(xy) > len(xy0)  # it did smooth
    # a projection of the whole sphere gives finite coordinates everywhere
    back = shapely.get_coordinates(out.to_crs("EPSG:8857").geometry.values)
    assert np.isfinite(back).all()


def test_domain_fixed_in_a_projection_judges_longitude_latitude():
    fixed = geo_io.domain_fixed("EPSG:4326", "+proj=laea +lat_0=-90 +lon_0=0")
    import pyproj

    t = pyproj.Transformer.from_crs("EPSG:4326", "+proj=laea +lat_0=-90 +lon_0=0", always_xy=True)
    x, y = t.transform([180.0, -180.0, 10.0, 0.0], [-80.0, 5.0, -90.0, -45.0])
    assert fixed(np.c_[x, y]).tolist() == [True, True, True, False]


def test_clamp_to_domain():
    g = np.array([shapely.Polygon([(179, 0), (180 + 6e-14, 0), (180 + 6e-14, 1)])], dtype=object)
    out = geo_io.clamp_to_domain(g, "f.gpkg")
    assert shapely.get_coordinates(out)[:, 0].max() == 180.0
    far = np.array([shapely.Polygon([(179, 0), (181, 0), (181, 1)])], dtype=object)
    with pytest.raises(CurveError, match=r"f.gpkg: feature 0: .*outside the longitude/latitude"):
        geo_io.clamp_to_domain(far, "f.gpkg")
    # an input edge vertex that an equal-area round trip moved by 1e-9 gets its bits back
    orig = np.array([shapely.Polygon([(170, -90), (180, -90), (180, -80)])], dtype=object)
    moved = np.array([shapely.Polygon([(170, -90), (180 - 1e-9, -90), (180, -80)])], dtype=object)
    back = geo_io.clamp_to_domain(moved, "f.gpkg", orig)
    assert shapely.get_coordinates(back).tolist() == shapely.get_coordinates(orig).tolist()


def test_readme_recipe_keeps_a_geodataframe_on_the_map(countries):
    out = geo.smooth(countries, iterations=2, fixed=geo.domain_fixed(countries.crs))
    out = geo.clamp_to_domain(out, "countries", countries)
    assert list(out.columns) == list(countries.columns)
    assert _outside(shapely.get_coordinates(out.geometry.values)).max() <= 0.0


@pytest.mark.parametrize(
    "options",
    [{"iterations": 2}, {"iterations": 2, "equal_area": True}, {"iterations": 1, "coverage": True}],
    ids=["degrees", "equal-area", "coverage"],
)
def test_chaikin_on_lonlat_files(countries, tmp_path, options):
    # smooth_file gave Chaikin the domain-edge anchors it cannot keep and failed ("fixed needs
    # method='cca'"); its points average neighbours, so it stays on the map without them
    src = (
        countries[countries["continent"] == "Antarctica"] if options.get("coverage") else countries
    )
    path = tmp_path / "in.gpkg"
    src.to_file(path)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        geo_io.smooth_file(path, tmp_path / "out.gpkg", method="chaikin", **options)
    out = gpd.read_file(tmp_path / "out.gpkg")
    xy = shapely.get_coordinates(out.geometry.values)
    assert _outside(xy).max() <= 0.0 and len(out) == len(src)
    assert len(xy) > len(shapely.get_coordinates(src.geometry.values))
    assert shapely.is_valid(out.geometry.values).all()
    # a mask the user gives still needs a method that keeps vertices
    with pytest.raises(CurveError, match="fixed needs method='cca'"):
        geo.smooth(src.geometry.values[:2], method="chaikin", fixed=lambda xy: xy[:, 0] > 0)
