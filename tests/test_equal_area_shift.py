"""--equal-area --max-shift D: no feature moves farther than D metres on the ground.

Data in lon/lat draw their edges straight in lon/lat. Projected vertex by vertex, a long
edge became the chord between its ends' images, kilometres from the edge: smoothed there
with --max-shift 500 and projected back, QGIS's world map had Canada's border moved 4.9
km, the United States' 4.1 km, Algeria's 3.6 km. Edges are now divided before projecting
(geo._densify), and the budget allows for the projection's scale.

The shift is measured as a user sees it: both outlines divided along lon/lat-straight
edges, each part in a Lambert azimuthal projection centred on it (scale 1 there), the
largest distance of either outline from the other.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pyogrio
import pyproj
import pytest
import shapely
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial import cKDTree

from curvesmith import geo
from curvesmith.internals import geo_io

NATURAL_EARTH = (
    Path(pyogrio.__file__).parent / "tests" / "fixtures" / "naturalearth_lowres"
    / "naturalearth_lowres.shp"
)  # fmt: skip

#: spacing (m) of the points the distances are measured between: a distance to a polyline
#: through points this far apart is overestimated by at most sqrt(d**2 + 50**2) - d
STEP = 100.0


def _projected(geom, lon, lat):
    laea = pyproj.Transformer.from_crs(
        "EPSG:4326", f"+proj=laea +lat_0={lat} +lon_0={lon} +units=m", always_xy=True
    )
    return shapely.transform(geom, lambda xy: np.c_[laea.transform(xy[:, 0], xy[:, 1])])


def ground_shift(before, after) -> float:
    """Largest distance (m) between the outlines of two lon/lat geometries, part by part."""
    a = shapely.segmentize(before.boundary, 0.005)  # edges straight in lon/lat
    b = shapely.segmentize(after.boundary, 0.005)
    worst = 0.0
    for source, other in ((a, b), (b, a)):
        for part in shapely.get_parts(source):
            c = part.centroid
            mine = _projected(part, c.x, c.y)
            theirs = _projected(other, c.x, c.y)
            p = shapely.get_coordinates(shapely.segmentize(mine, STEP))
            q = shapely.get_coordinates(shapely.segmentize(theirs, STEP))
            q = q[np.isfinite(q).all(axis=1)]
            worst = max(worst, float(cKDTree(q).query(p)[0].max()))
    return worst


def _slack(d: float) -> float:
    return float(np.hypot(d, STEP / 2) - d) + 1e-6


@pytest.fixture(scope="module")
def world():
    df = pyogrio.read_dataframe(NATURAL_EARTH)
    return df[df.geometry.notna()].reset_index(drop=True)


def test_world_within_max_shift_on_the_ground(world, tmp_path, max_shift=500.0):
    src, out = tmp_path / "world.gpkg", tmp_path / "out.gpkg"
    pyogrio.write_dataframe(world, src)
    geo.smooth_file(src, out, equal_area=True, max_shift=max_shift, iterations=3)
    res = pyogrio.read_dataframe(out)
    shifts = np.array(
        [
            ground_shift(a, b)
            for a, b in zip(world.geometry.values, res.geometry.values, strict=True)
        ]
    )
    worst = int(np.argmax(shifts))
    assert shifts[worst] <= max_shift + _slack(max_shift), (world.name[worst], shifts[worst])
    # and the bound is used, not met by smoothing nothing: most countries move a good part of it
    assert np.median(shifts) > 0.2 * max_shift


def test_the_49th_parallel_stays_straight(tmp_path):
    """Canada and the United States along one edge of 28 degrees: shared, and kept straight."""
    canada = shapely.Polygon([(-123, 49), (-95, 49), (-95, 60), (-123, 60)])
    usa = shapely.Polygon([(-123, 49), (-123, 40), (-95, 40), (-95, 49)])
    import geopandas as gpd

    src = tmp_path / "two.gpkg"
    gpd.GeoDataFrame({"n": ["ca", "us"]}, geometry=[canada, usa], crs="EPSG:4326").to_file(src)
    for coverage in (False, True):
        out = tmp_path / f"out{coverage}.gpkg"
        geo.smooth_file(src, out, equal_area=True, max_shift=500.0, iterations=2, coverage=coverage)
        res = pyogrio.read_dataframe(out)
        for a, b in zip((canada, usa), res.geometry.values, strict=True):
            assert ground_shift(a, b) <= 500.0 + _slack(500.0)
        # the border, away from the corners, is still the parallel: to the 25 m of the
        # division's tolerance (500 / 20), not the kilometres of a projected chord
        border = shapely.intersection(
            res.geometry.values[0].boundary, shapely.box(-115, 48, -103, 50)
        )
        lats = shapely.get_coordinates(border)[:, 1]
        assert np.abs(lats - 49.0).max() * 111_700 < 25.0, np.abs(lats - 49.0).max()
        if coverage:
            assert shapely.coverage_is_valid(res.geometry.values)


def test_coverage_max_shift_is_ground_metres(world, tmp_path):
    """South America as a coverage in its one projection: within the bound, still a coverage."""
    south = world[world.continent == "South America"].reset_index(drop=True)
    assert shapely.coverage_is_valid(south.geometry.values)
    src, out = tmp_path / "south.gpkg", tmp_path / "out.gpkg"
    pyogrio.write_dataframe(south, src)
    geo.smooth_file(src, out, equal_area=True, coverage=True, max_shift=2000.0, iterations=2)
    res = pyogrio.read_dataframe(out)
    assert shapely.coverage_is_valid(res.geometry.values)
    pairs = zip(south.geometry.values, res.geometry.values, strict=True)
    shifts = np.array([ground_shift(a, b) for a, b in pairs])
    assert shifts.max() <= 2000.0 + _slack(2000.0)
    assert np.median(shifts) > 0.2 * 2000.0


# ---------------------------------------------------------------------------- _densify


@settings(max_examples=50, deadline=None)
@given(
    st.floats(-170, 170), st.floats(-70, 70), st.floats(0.5, 30), st.floats(0.5, 15),
    st.floats(0.1, 100.0),
)  # fmt: skip
def test_densified_edges_are_straight_and_shared_alike(lon, lat, width, height, tol):
    """Each piece's image is within the tolerance; a shared edge gets the same points."""
    left = shapely.box(lon, lat, lon + width, lat + height)
    right = shapely.box(lon + width, lat, lon + 2 * width, lat + height)
    laea = f"+proj=laea +lat_0={lat} +lon_0={lon + width} +units=m"
    tr = pyproj.Transformer.from_crs("EPSG:4326", laea, always_xy=True)
    a, b = geo_io.densified([left, right], "EPSG:4326", laea, tol)
    assert shapely.coverage_is_valid([a, b])  # the shared meridian: the very same points
    assert shapely.equals(a, left) or shapely.get_num_coordinates(a) > 5
    # every piece's midpoint image within tol (and a bit of the quadratic estimate's slack)
    for g in (a, b):
        xy = shapely.get_coordinates(g)
        p, q = xy[:-1], xy[1:]
        px, py = tr.transform(p[:, 0], p[:, 1])
        qx, qy = tr.transform(q[:, 0], q[:, 1])
        mx, my = tr.transform((p[:, 0] + q[:, 0]) / 2, (p[:, 1] + q[:, 1]) / 2)
        dx, dy = qx - px, qy - py
        dev = np.abs(dx * (my - py) - dy * (mx - px)) / np.hypot(dx, dy)
        assert dev.max() <= tol * 1.01


def test_densify_keeps_what_it_need_not_divide():
    short = shapely.Polygon([(10, 50), (10.001, 50), (10.001, 50.001)])
    line_z = shapely.LineString([(0, 0, 100), (40, 0, 140)])
    point = shapely.Point(1, 2)
    laea = "+proj=laea +lat_0=10 +lon_0=20 +units=m"
    out = geo_io.densified(
        np.array([short, line_z, point, None], dtype=object), "EPSG:4326", laea, 1.0
    )
    assert out[0] is short and out[2] is point and out[3] is None
    z = shapely.get_coordinates(out[1], include_z=True)
    assert len(z) > 10 and z[0, 2] == 100.0 and z[-1, 2] == 140.0
    assert np.allclose(z[:, 2], 100.0 + z[:, 0])  # Z along the edge, as the line's


def test_densify_leaves_m_values_alone():
    """A line with M stays as it is: divided through shapely's ragged arrays, M became Z."""
    line_m = shapely.from_wkt("LINESTRING M (0 0 1, 40 0 2)")
    laea = "+proj=laea +lat_0=10 +lon_0=20 +units=m"
    (out,) = geo_io.densified(np.array([line_m], dtype=object), "EPSG:4326", laea, 1.0)
    assert out is line_m and shapely.has_m(out) and not shapely.has_z(out)
