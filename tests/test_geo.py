"""curvesmith.geo.smooth: shapely geometries, GeoSeries and GeoDataFrames."""

import geopandas as gpd
import numpy as np
import pytest
import shapely
from hypothesis import given
from hypothesis import strategies as st

from curvesmith import cca, geo
from curvesmith.errors import CurveError

SHELL = [(0, 0), (10, 0), (10, 10), (0, 10)]


def ring_areas(geom):
    """Signed areas of every ring (exterior first), by the shoelace formula."""
    out = []
    for part in shapely.get_parts(geom):
        for ring in shapely.get_rings(part):
            xy = shapely.get_coordinates(ring)
            out.append(0.5 * np.sum(xy[:-1, 0] * xy[1:, 1] - xy[1:, 0] * xy[:-1, 1]))
    return np.array(out)


def chord_area(xy):
    xy = np.asarray(xy)
    return 0.5 * np.sum(xy[:, 0] * np.roll(xy[:, 1], -1) - np.roll(xy[:, 0], -1) * xy[:, 1])


def star(n, r_in, r_out, phase=0.0, centre=(0.0, 0.0)):
    t = phase + np.linspace(0, 2 * np.pi, 2 * n, endpoint=False)
    r = np.where(np.arange(2 * n) % 2 == 0, r_out, r_in)
    return np.column_stack([centre[0] + r * np.cos(t), centre[1] + r * np.sin(t)])


# --- polygons ----------------------------------------------------------------------------


@pytest.mark.parametrize("iterations", [1, 2, 3])
@pytest.mark.parametrize("ccw", [True, False])
def test_polygon_with_holes_keeps_every_ring_area_and_orientation(iterations, ccw):
    hole1 = star(5, 1.0, 2.0, centre=(3, 3))[::-1]
    hole2 = star(4, 0.5, 1.2, centre=(7, 6))[::-1]
    poly = shapely.Polygon(SHELL, [hole1, hole2])
    if not ccw:
        poly = shapely.orient_polygons(poly, exterior_cw=True)
    out = geo.smooth(poly, iterations=iterations)
    assert isinstance(out, shapely.Polygon)
    assert shapely.is_valid(out)
    assert len(out.interiors) == 2
    a0, a1 = ring_areas(poly), ring_areas(out)
    np.testing.assert_allclose(a1, a0, rtol=1e-9)  # sign included: orientation kept
    assert out.exterior.is_ccw == poly.exterior.is_ccw
    assert [h.is_ccw for h in out.interiors] == [h.is_ccw for h in poly.interiors]
    assert len(out.exterior.coords) - 1 == 4 * 3**iterations


def test_rings_equal_plain_cca_when_nothing_conflicts():
    """Reference: without conflicts every ring is exactly cca.smooth of that ring."""
    hole = star(6, 1.0, 2.0, centre=(5, 5))[::-1]
    poly = shapely.Polygon(SHELL, [hole])
    res = geo.smooth(poly, iterations=2, full_output=True)
    assert res.reductions == ()
    assert res.n_curves == 2
    ext = cca.smooth(np.array(SHELL, float), closed=True, iterations=2)
    inn = cca.smooth(hole, closed=True, iterations=2)
    np.testing.assert_array_equal(shapely.get_coordinates(res.geometry.exterior)[:-1], ext)
    np.testing.assert_array_equal(shapely.get_coordinates(res.geometry.interiors[0])[:-1], inn)


def test_slit_polygon_is_repaired_locally_and_reported():
    # a 0.1 wide slit: the augmenting triangles of its long sides would cross the slit
    slit = shapely.Polygon(
        [(0, 0), (10, 0), (10, 10), (5.05, 10), (5.05, 1), (4.95, 1), (4.95, 10), (0, 10)]
    )
    raw = cca.smooth(np.array(slit.exterior.coords), closed=True, iterations=1)
    assert not shapely.Polygon(raw).is_valid  # the plain result self-intersects
    res = geo.smooth(slit, iterations=1, full_output=True)
    assert shapely.is_valid(res.geometry)
    assert len(res.reductions) >= 1
    assert all(r.feature == 0 and r.ring == 0 for r in res.reductions)
    assert res.max_area_change < 1e-12
    assert res.geometry.area == pytest.approx(slit.area, rel=1e-12)


def slit_square_with_wavy_bottom(n=200):
    """The slit square with its bottom edge replaced by an n-vertex sine wave."""
    x = np.linspace(0, 10, n)
    wave = np.column_stack([x, -0.3 * np.sin(3 * x)])
    top = [(10, 10), (5.05, 10), (5.05, 1), (4.95, 1), (4.95, 10), (0, 10)]
    return shapely.Polygon(np.vstack([wave, top]))


def test_reduction_is_local_on_a_long_ring():
    poly = slit_square_with_wavy_bottom()
    n = len(poly.exterior.coords) - 1
    raw = cca.smooth(np.array(poly.exterior.coords), closed=True, iterations=2)
    assert not shapely.Polygon(raw).is_valid
    res = geo.smooth(poly, iterations=2, full_output=True)
    assert shapely.is_valid(res.geometry)
    assert res.reductions
    reduced = sum(r.stop - r.start for r in res.reductions)
    assert reduced <= 0.25 * n  # only pieces next to the slit
    assert res.max_area_change < 1e-9
    # most of the ring still got both iterations (9x vertices)
    assert len(res.geometry.exterior.coords) > 0.7 * 9 * n


def test_hole_near_shell_corner_is_kept_off_the_shell():
    poly = shapely.Polygon(SHELL, [[(0.3, 0.3), (3, 0.6), (0.6, 3)]])
    raw = [
        cca.smooth(np.array(r.coords), closed=True, iterations=2) for r in shapely.get_rings(poly)
    ]
    assert not shapely.Polygon(raw[0], [raw[1]]).is_valid  # hole would cross the shell
    res = geo.smooth(poly, iterations=2, full_output=True)
    assert shapely.is_valid(res.geometry)
    assert not shapely.intersects(res.geometry.exterior, res.geometry.interiors[0])
    assert {r.ring for r in res.reductions} <= {0, 1}
    assert res.reductions
    np.testing.assert_allclose(ring_areas(res.geometry), ring_areas(poly), rtol=1e-9)


def test_multipolygon_parts_stay_apart():
    a = shapely.box(0, 0, 1, 1)
    b = shapely.box(1.02, 0, 2, 1)  # 0.02 apart: the bulging edges would overlap
    mp = shapely.MultiPolygon([a, b])
    raw = shapely.MultiPolygon(
        [shapely.Polygon(cca.smooth(np.array(p.exterior.coords), closed=True)) for p in (a, b)]
    )
    assert not raw.is_valid
    res = geo.smooth(mp, full_output=True)
    assert isinstance(res.geometry, shapely.MultiPolygon)
    assert shapely.is_valid(res.geometry)
    assert res.reductions
    np.testing.assert_allclose(ring_areas(res.geometry), ring_areas(mp), rtol=1e-9)


@given(
    n=st.integers(3, 9),
    r_in=st.floats(0.2, 0.9),
    phase=st.floats(0, 2 * np.pi),
    iterations=st.integers(1, 3),
    hole_scale=st.floats(0.05, 0.18),
)
def test_property_star_with_hole_valid_and_area_exact(n, r_in, phase, iterations, hole_scale):
    shell = star(n, r_in, 1.0, phase)
    hole = star(3, hole_scale * 0.5, hole_scale, phase)[::-1]
    poly = shapely.Polygon(shell, [hole])
    if not poly.is_valid:
        return
    res = geo.smooth(poly, iterations=iterations, full_output=True)
    assert shapely.is_valid(res.geometry)
    np.testing.assert_allclose(ring_areas(res.geometry), ring_areas(poly), rtol=1e-9)
    assert res.max_area_change < 1e-9


# --- lines and other types ---------------------------------------------------------------


def test_linestring_keeps_ends_and_chord_area():
    xy = np.array([(0, 0), (1, 2), (2, -1), (3, 1), (4, 0)], float)
    out = geo.smooth(shapely.LineString(xy), iterations=3)
    oxy = shapely.get_coordinates(out)
    np.testing.assert_array_equal(oxy[[0, -1]], xy[[0, -1]])
    assert chord_area(oxy) == pytest.approx(chord_area(xy), rel=1e-12)
    np.testing.assert_allclose(oxy, cca.smooth(xy, closed=False, iterations=3), atol=1e-12)


def test_hairpin_line_stays_simple():
    xy = np.array(
        [(0, 0), (10, 0), (10, 10), (5.05, 10), (5.05, 1), (4.95, 1), (4.95, 10), (0, 10)], float
    )
    assert not shapely.LineString(cca.smooth(xy, closed=False)).is_simple
    res = geo.smooth(shapely.LineString(xy), full_output=True)
    assert res.geometry.is_simple
    assert res.reductions
    assert chord_area(shapely.get_coordinates(res.geometry)) == pytest.approx(chord_area(xy))


def test_linearring_multilinestring_and_collection():
    ring = shapely.LinearRing(star(5, 0.5, 1.0))
    out = geo.smooth(ring, iterations=2)
    assert isinstance(out, shapely.LinearRing) and out.is_valid
    assert shapely.Polygon(out).area == pytest.approx(shapely.Polygon(ring).area, rel=1e-12)

    mls = shapely.MultiLineString([[(0, 0), (1, 1), (2, 0)], [(0, 5), (1, 6), (2, 5), (3, 6)]])
    out = geo.smooth(mls)
    assert isinstance(out, shapely.MultiLineString)
    for a, b in zip(mls.geoms, out.geoms, strict=True):
        assert chord_area(b.coords) == pytest.approx(chord_area(a.coords), rel=1e-12)

    gc = shapely.GeometryCollection(
        [shapely.box(0, 0, 1, 1), shapely.LineString([(0, 0), (1, 1), (2, 0)])]
    )
    out = geo.smooth(gc)
    assert isinstance(out, shapely.GeometryCollection)
    assert out.geoms[0].area == pytest.approx(1.0, rel=1e-12)


def test_none_and_empty_pass_through():
    arr = [shapely.box(0, 0, 1, 1), None, shapely.Polygon(), shapely.LineString()]
    out = geo.smooth(arr)
    assert isinstance(out, np.ndarray) and len(out) == 4
    assert out[1] is None
    assert out[2].is_empty and out[3].is_empty
    assert out[0].area == pytest.approx(1.0)


def test_geodataframe_keeps_index_columns_crs():
    df = gpd.GeoDataFrame(
        {"name": ["a", "b", "c"], "value": [1.5, 2.5, 3.5]},
        geometry=[shapely.box(0, 0, 1, 1), shapely.box(2, 0, 4, 3), None],
        index=[10, 7, 3],
        crs="EPSG:3857",
    )
    out = geo.smooth(df, iterations=2)
    assert isinstance(out, gpd.GeoDataFrame)
    assert list(out.index) == [10, 7, 3]
    assert list(out["name"]) == ["a", "b", "c"]
    assert out.crs == df.crs
    np.testing.assert_allclose(out.area.values[:2], [1.0, 6.0], rtol=1e-12)
    assert out.geometry.iloc[2] is None
    assert df.geometry.iloc[0].equals(shapely.box(0, 0, 1, 1))  # input untouched

    s = geo.smooth(df.geometry)
    assert isinstance(s, gpd.GeoSeries) and s.crs == df.crs and list(s.index) == [10, 7, 3]


def test_chaikin_method_shrinks():
    res = geo.smooth(shapely.box(0, 0, 2, 2), method="chaikin", iterations=1)
    assert res.area == pytest.approx(4.0 - 4 * 0.5 * 0.5 * 0.5)  # four 0.5 x 0.5 corners / 2


def test_iterations_zero_is_identity():
    p = shapely.Polygon(star(5, 0.5, 1.0))
    assert geo.smooth(p, iterations=0).equals_exact(p, 0.0)


# --- bad input ---------------------------------------------------------------------------


def test_points_are_rejected():
    with pytest.raises(CurveError, match=r"geometry\[1\] is a Point"):
        geo.smooth([shapely.box(0, 0, 1, 1), shapely.Point(0, 0)])


def test_invalid_polygon_needs_make_valid():
    bowtie = shapely.Polygon([(0, 0), (2, 2), (2, 0), (0, 2)])
    with pytest.raises(CurveError, match=r"geometry\[0\] is not valid \(Self-intersection"):
        geo.smooth(bowtie)
    out = geo.smooth(bowtie, make_valid=True)
    assert shapely.is_valid(out)
    assert isinstance(out, shapely.MultiPolygon) and len(out.geoms) == 2  # two triangles
    assert out.area == pytest.approx(2.0, rel=1e-12)


def test_z_and_bad_options_rejected():
    z = geo.smooth(shapely.LineString([(0, 0, 1), (1, 1, 1), (2, 0, 1)]))  # Z: kept (issue 14.3)
    assert z.has_z and set(shapely.get_coordinates(z, include_z=True)[:, 2]) == {1.0}
    with pytest.raises(CurveError, match="method must be one of 'cca', 'chaikin', got 'spline'"):
        geo.smooth(shapely.box(0, 0, 1, 1), method="spline")
    with pytest.raises(CurveError, match="iterations"):
        geo.smooth(shapely.box(0, 0, 1, 1), iterations=-1)
    with pytest.raises(CurveError, match=r"alpha must be in \(0, 1/3\), got 0.5"):
        geo.smooth(shapely.box(0, 0, 1, 1), alpha=0.5)
    with pytest.raises(CurveError, match="must be a shapely geometry or None, got str"):
        geo.smooth(["POLYGON"])


def test_geographic_data_moved_off_the_map_is_warned():
    # naturalearth in EPSG:4326: vertices on the antimeridian and the South Pole moved to
    # -180.12 and -90.003 without a word; fixed=domain_fixed(crs) keeps them (as the CLI does)
    import os
    import warnings

    import geopandas as gpd
    import pyogrio
    import shapely

    shp = os.path.join(
        os.path.dirname(pyogrio.__file__), "tests", "fixtures", "naturalearth_lowres",
        "naturalearth_lowres.shp",
    )  # fmt: skip
    df = gpd.read_file(shp)
    with pytest.warns(geo.GeographicCRSWarning, match="moved vertices beyond ±180°/±90°"):
        out = geo.smooth(df, iterations=2)
    x0, y0, x1, y1 = shapely.total_bounds(out.geometry.values)
    assert x0 < -180 and y0 < -90
    with warnings.catch_warnings():
        warnings.simplefilter("error", geo.GeographicCRSWarning)
        fixed = geo.smooth(df, iterations=2, fixed=geo.domain_fixed(df.crs))
    x0, y0, x1, y1 = shapely.total_bounds(fixed.geometry.values)
    a0, b0, a1, _ = shapely.total_bounds(df.geometry.values)  # 180.00000000000006 itself
    assert x0 >= min(-180, a0) and x1 <= max(180, a1) and y0 >= min(-90, b0) and y1 <= 90


def test_iterations_zero_gives_the_input_back_as_it_was():
    """Not cleaned of repeated vertices, not rebuilt from a coverage's arcs: as given."""
    p = shapely.Polygon([(0, 0), (1, 0), (1, 0), (1, 1), (0, 1)])  # a repeated vertex
    q = shapely.Polygon([(2, 1), (1, 1), (1, 0), (2, 0)])  # starts elsewhere than GEOS would
    z = shapely.Polygon([(0, 0, 5), (1, 0, 6), (1, 0, 6), (1, 1, 7)])
    assert geo.smooth(p, iterations=0).equals_exact(p, 0.0)
    assert geo.smooth(z, iterations=0).equals_exact(z, 0.0) and geo.smooth(z, iterations=0).has_z
    out = geo.smooth_coverage([p, q], iterations=0, full_output=True)
    assert all(a.equals_exact(b, 0.0) for a, b in zip(out.geometry, [p, q], strict=True))
    assert out.coverage_valid
    with pytest.raises(CurveError, match="not valid"):  # still checked
        geo.smooth(shapely.Polygon([(0, 0), (1, 1), (1, 0), (0, 1)]), iterations=0)
