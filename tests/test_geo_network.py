"""curvesmith.geo.smooth_network: junctions fixed, shared pieces once, no new contacts, exact areas."""

import itertools
from pathlib import Path

import geopandas as gpd
import numpy as np
import pyogrio
import pytest
import shapely
from click.testing import CliRunner
from hypothesis import given, settings
from hypothesis import strategies as st

import oracles
from curvesmith import geo
from curvesmith.cli import main
from curvesmith.errors import CurveError
from oracles import exact_area_fraction

OSM = Path(pyogrio.__file__).parent / "tests" / "fixtures" / "sample.osm.pbf"


def osm_roads():
    """The 36 ways (roads, paths, a motorway) of pyogrio's OSM fixture, in British National Grid."""
    pyogrio.set_gdal_config_options({"OSM_USE_CUSTOM_INDEXING": "NO"})
    return pyogrio.read_dataframe(OSM, layer="lines").to_crs("EPSG:27700")


def area_between(line_in, line_out):
    """Exact signed area of the closed polygon input line + reversed output line."""
    a = shapely.get_coordinates(line_in)
    b = shapely.get_coordinates(line_out)
    assert np.array_equal(a[0], b[0]) and np.array_equal(a[-1], b[-1])
    return exact_area_fraction(np.vstack([a, b[::-1][1:-1]]))


def roundoff_bound(line):
    """Area error of float coordinates of a shapely line (:func:`oracles.roundoff_bound`)."""
    return oracles.roundoff_bound(shapely.get_coordinates(line), shapely.length(line))


def contacts(geoms):
    """{(i, j): intersection} for every touching pair of lines."""
    g = np.asarray(geoms, dtype=object)
    i, j = shapely.STRtree(g).query(g, predicate="intersects")
    keep = i < j
    return {
        (int(a), int(b)): shapely.intersection(g[a], g[b])
        for a, b in zip(i[keep], j[keep], strict=True)
    }


def assert_no_new_contacts(before, after, tol=1e-7):
    """Same touching pairs; where inputs met in points, the outputs meet at the same points."""
    c0, c1 = contacts(before), contacts(after)
    assert set(c0) == set(c1)
    for key, x0 in c0.items():
        if shapely.get_dimensions(x0) == 0:
            x1 = c1[key]
            assert shapely.get_dimensions(x1) == 0, key
            p0 = np.unique(shapely.get_coordinates(x0), axis=0)
            p1 = np.unique(shapely.get_coordinates(x1), axis=0)
            assert p0.shape == p1.shape, key
            assert (
                shapely.hausdorff_distance(shapely.multipoints(p0), shapely.multipoints(p1)) < tol
            )


def assert_areas_exact(before, after):
    for a, b in zip(before, after, strict=True):
        for pa, pb in zip(shapely.get_parts(a), shapely.get_parts(b), strict=True):
            if pa.is_closed:
                d = exact_area_fraction(shapely.get_coordinates(pb)[:-1]) - exact_area_fraction(
                    shapely.get_coordinates(pa)[:-1]
                )
            else:
                d = area_between(pa, pb)
            assert abs(float(d)) <= roundoff_bound(pa), (float(d), roundoff_bound(pa))


# --- small exact cases ---------------------------------------------------------------------


def test_end_on_a_vertex_free_segment_and_self_crossing():
    # a's vertices (1, 2) and (5, 2) lie on the interiors of b's segments: inserted into b
    a = shapely.LineString([(0, 0), (1, 2), (3, 3), (5, 2), (6, 0)])
    b = shapely.LineString([(0, 3), (2, 1), (4, 1), (6, 3)])
    res = geo.smooth_network([a, b], iterations=2, full_output=True)
    assert res.n_inserted == 2
    assert shapely.equals(shapely.intersection(*res.geometry), shapely.MultiPoint([(1, 2), (5, 2)]))
    # a figure eight crosses itself twice: both crossings fixed, still the only self-contacts
    eight = shapely.LineString([(0, 0), (2, 2), (4, 0), (4, 2), (2, 0), (0, 2)])
    res = geo.smooth_network([eight], iterations=2, full_output=True)
    assert res.n_inserted == 4 and res.n_arcs == 5
    out = res.geometry[0]
    assert_areas_exact([eight], [out])
    ring = shapely.get_parts(shapely.polygonize([shapely.union_all(out)]))
    assert len(ring) == 2  # the two lobes, as in the input
    assert (1.0, 1.0) in list(out.coords) and (3.0, 1.0) in list(out.coords)


def test_t_junction_ends_and_junction_fixed():
    main_road = shapely.LineString([(0, 0), (2, 1), (4, 0), (6, 1), (8, 0)])
    side = shapely.LineString([(4, 0), (5, -2), (4, -4)])
    res = geo.smooth_network([main_road, side], iterations=3, full_output=True)
    out = res.geometry
    assert (res.n_nodes, res.n_arcs, res.n_lines, res.n_inserted) == (4, 3, 2, 0)
    # ends and the junction (4, 0) are vertices of the output, bit for bit
    assert out[0].coords[0] == (0.0, 0.0) and out[0].coords[-1] == (8.0, 0.0)
    assert (4.0, 0.0) in list(out[0].coords)
    assert out[1].coords[0] == (4.0, 0.0) and out[1].coords[-1] == (4.0, -4.0)
    # smoothed: more vertices, and the two lines still meet only at the junction
    assert len(out[0].coords) > 20
    assert shapely.equals(shapely.intersection(*out), shapely.Point(4, 0))
    assert_areas_exact([main_road, side], out)
    assert res.max_open_area < 1e-14


def test_crossing_is_inserted_and_fixed():
    a = shapely.LineString([(0, 0), (1, 2), (3, 3), (5, 2), (6, 0)])
    b = shapely.LineString([(0, 2.5), (2, 0.5), (4, 0.5), (6, 2.5)])
    x0 = shapely.intersection(a, b)
    assert len(shapely.get_parts(x0)) == 2  # they cross twice, never at a vertex
    assert not set(shapely.get_coordinates(x0).ravel()) & {0.5, 1.0, 2.0, 5.0, 6.0}
    res = geo.smooth_network([a, b], iterations=2, full_output=True)
    assert res.n_inserted == 4  # each crossing becomes a vertex of both lines
    assert res.n_nodes == 4 + 2
    assert_no_new_contacts([a, b], res.geometry, tol=1e-12)
    assert_areas_exact([a, b], res.geometry)
    # each crossing is a vertex of both outputs
    for p in shapely.get_coordinates(x0):
        for line in res.geometry:
            assert np.min(np.abs(shapely.get_coordinates(line) - p).max(axis=1)) < 1e-12


def test_shared_piece_is_identical_in_both_lines():
    # two rivers joining upstream and running together over (3,0)..(6,1) with different
    # vertices on the shared stretch (one has an extra vertex, the other is reversed)
    shared = [(3, 0), (4, 0.75), (5, 0.25), (6, 1)]
    a = shapely.LineString([(0, 2), (1.5, 1), *shared, (8, 3)])
    b = shapely.LineString([(8, -2), (6, 1), (5.5, 0.625), (5, 0.25), (4, 0.75), (3, 0), (1, -1)])
    res = geo.smooth_network([a, b], iterations=2, full_output=True)
    assert res.n_inserted == 1  # b's (5.5, 0.625) lies on a's edge (5, 0.25)-(6, 1)
    oa, ob = res.geometry
    common = shapely.intersection(oa, ob)
    assert shapely.get_dimensions(common) == 1
    # the shared stretch is the same smoothed polyline in both (b runs it backwards)
    ca, cb = shapely.get_coordinates(oa), shapely.get_coordinates(ob)
    ia = np.nonzero(np.all(ca == (3, 0), axis=1))[0][0]
    ja = np.nonzero(np.all(ca == (6, 1), axis=1))[0][0]
    ib = np.nonzero(np.all(cb == (6, 1), axis=1))[0][0]
    jb = np.nonzero(np.all(cb == (3, 0), axis=1))[0][0]
    assert ja - ia > 3 * 3  # really smoothed
    np.testing.assert_array_equal(ca[ia : ja + 1], cb[ib : jb + 1][::-1])
    assert_areas_exact([a, b], [oa, ob])


def test_closed_line_keeps_its_area_and_touch_point():
    ring = shapely.LineString([(0, 0), (4, 0), (5, 3), (2, 5), (-1, 3), (0, 0)])
    road = shapely.LineString([(5, 3), (8, 4), (9, 7)])
    res = geo.smooth_network([ring, road], iterations=3, full_output=True)
    r = res.geometry[0]
    assert r.is_closed and r.coords[0] == (5.0, 3.0)  # starts at its node
    a0, a1 = (
        exact_area_fraction(shapely.get_coordinates(ring)[:-1]),
        exact_area_fraction(shapely.get_coordinates(r)[:-1]),
    )
    assert abs(float(a1 - a0)) <= roundoff_bound(ring)
    assert res.max_area_change < 1e-14
    assert shapely.equals(shapely.intersection(*res.geometry), shapely.Point(5, 3))


def test_lone_closed_line_is_smoothed_as_a_ring():
    t = np.linspace(0, 2 * np.pi, 9)[:-1]
    xy = np.c_[100 * np.cos(t), 60 * np.sin(t)] + (5e5, 2e5)
    ring = shapely.LineString(np.vstack([xy, xy[:1]]))
    out = geo.smooth_network([ring], iterations=2)[0]
    assert len(out.coords) - 1 == 8 * 9
    a0 = exact_area_fraction(shapely.get_coordinates(ring)[:-1])
    assert abs(
        float(exact_area_fraction(shapely.get_coordinates(out)[:-1]) - a0)
    ) <= roundoff_bound(ring)
    # no fixed vertex: no original vertex survives (the start is not a junction)
    assert not any(np.all(shapely.get_coordinates(out) == v, axis=1).any() for v in xy)


def test_fixed_points_become_nodes():
    line = shapely.LineString([(0, 0), (1, 1), (2, 0), (3, 1), (4, 0)])
    free = geo.smooth_network([line], iterations=2)[0]
    pinned = geo.smooth_network([line], iterations=2, fixed_points=[(2, 0)])[0]
    assert (2.0, 0.0) not in list(free.coords)
    assert (2.0, 0.0) in list(pinned.coords)
    pinned2 = geo.smooth_network([line], iterations=2, fixed_points=[shapely.Point(2, 0)])[0]
    assert shapely.equals_exact(pinned, pinned2, 0.0)


def test_conflicts_resolved_locally_where_per_line_smoothing_crosses():
    # a square wave (a field boundary) and a short fence 0.03 above one of its tops: the
    # augmenting triangle CCA builds on that top (height 0.077 for alpha 0.211) crosses it
    wave = [(0.0, 0.0)]
    for k in range(15):
        wave += [(2 * k + 1.0, 0.0), (2 * k + 1.0, 1.0), (2 * k + 2.0, 1.0), (2 * k + 2.0, 0.0)]
    a = shapely.LineString(wave)
    b = shapely.LineString([(13.2, 1.03), (13.8, 1.03)])
    per_line = geo.smooth([a, b], iterations=2)
    assert shapely.intersects(*per_line)
    res = geo.smooth_network([a, b], iterations=2, full_output=True)
    out_a, out_b = res.geometry
    assert not shapely.intersects(out_a, out_b)
    assert shapely.equals(out_b, b)  # a straight two-point line has nothing to smooth
    # reduced locally: one piece of the wave around the fence, the rest at full strength
    assert len(res.reductions) >= 1
    assert all(r.features == (0,) and r.stop - r.start <= 16 for r in res.reductions)
    assert all(r.iterations < 2 or r.alpha_scale < 1 for r in res.reductions)
    full = geo.smooth_network([a], iterations=2)[0]
    for far in (shapely.box(-1, -1, 6.5, 2), shapely.box(17.5, -1, 31, 2)):
        d = shapely.hausdorff_distance(
            shapely.intersection(out_a, far), shapely.intersection(full, far)
        )
        assert d < 1e-12
    assert_areas_exact([a, b], res.geometry)


def test_duplicate_lines_stay_identical():
    a = shapely.LineString([(0, 0), (1, 2), (2, 0), (3, 2)])
    res = geo.smooth_network([a, a.reverse()], iterations=2, full_output=True)
    assert res.n_arcs == 1
    assert shapely.equals_exact(res.geometry[0], res.geometry[1].reverse(), 0.0)


def test_multilinestring_and_linearring_types_kept():
    mls = shapely.MultiLineString([[(0, 0), (1, 1), (2, 0)], [(2, 0), (3, -1), (4, 0)]])
    lr = shapely.LinearRing([(10, 0), (12, 0), (12, 2), (10, 2)])
    out = geo.smooth_network([mls, None, shapely.LineString(), lr], iterations=1)
    assert out[0].geom_type == "MultiLineString" and len(out[0].geoms) == 2
    assert out[0].geoms[0].coords[-1] == out[0].geoms[1].coords[0] == (2.0, 0.0)
    assert out[1] is None and out[2].is_empty
    assert out[3].geom_type == "LinearRing"
    assert out[3].is_valid and abs(shapely.Polygon(out[3]).area - 4.0) < 1e-14


def test_iterations_zero_and_chaikin():
    a = shapely.LineString([(0, 0), (1, 2), (2, 0), (3, 2)])
    b = shapely.LineString([(1.5, -1), (1.5, 3)])
    res0 = geo.smooth_network([a, b], iterations=0, full_output=True)
    assert res0.n_inserted == 2
    assert shapely.equals(res0.geometry[0], a) and shapely.equals(res0.geometry[1], b)
    ch = geo.smooth_network([a, b], method="chaikin", iterations=3)
    assert_no_new_contacts([a, b], ch, tol=1e-12)
    assert ch[0].coords[0] == (0.0, 0.0) and ch[0].coords[-1] == (3.0, 2.0)


def test_errors():
    with pytest.raises(CurveError, match=r"geometry\[1\] is a Polygon"):
        geo.smooth_network([shapely.LineString([(0, 0), (1, 1)]), shapely.box(0, 0, 1, 1)])
    z = geo.smooth_network([shapely.LineString([(0, 0, 1), (1, 1, 2)])])  # Z kept (14.3)
    assert shapely.get_coordinates(z, include_z=True).tolist() == [[0, 0, 1], [1, 1, 2]]
    with pytest.raises(CurveError, match="fewer than 2 distinct points"):
        geo.smooth_network([shapely.LineString([(1, 1), (1, 1)])])
    with pytest.raises(CurveError, match="method must be"):
        geo.smooth_network([shapely.LineString([(0, 0), (1, 1)])], method="derham")
    with pytest.raises(CurveError, match=r"fixed_points must have shape \(K, 2\)"):
        geo.smooth_network([shapely.LineString([(0, 0), (1, 1)])], fixed_points=[1, 2, 3])


# --- real data ----------------------------------------------------------------------------


def test_osm_network_no_new_contacts_and_exact_areas():
    df = osm_roads()
    res = geo.smooth_network(df, iterations=3, full_output=True)
    out = res.geometry
    assert isinstance(out, gpd.GeoDataFrame)
    assert list(out.columns) == list(df.columns) and out.crs == df.crs
    assert (out["osm_id"] == df["osm_id"]).all()
    assert res.n_lines == 36 and res.n_nodes > 36
    before, after = df.geometry.values, out.geometry.values
    assert_no_new_contacts(before, after)
    assert_areas_exact(before, after)
    assert shapely.get_num_coordinates(after).sum() > 5 * shapely.get_num_coordinates(before).sum()
    # every node of the network is a vertex of the output
    topo_nodes = shapely.multipoints(
        geo.network_topology(
            [shapely.get_coordinates(g) for g in before], np.zeros(len(before), dtype=bool)
        ).nodes
    )
    out_vertices = shapely.multipoints(shapely.get_coordinates(after))
    assert shapely.covers(out_vertices, topo_nodes)


def test_natural_earth_borders_as_lines_shared_borders_identical():
    """Country outlines (pyogrio's naturalearth_lowres) as lines: shared borders are shared arcs."""
    path = OSM.parent / "naturalearth_lowres" / "naturalearth_lowres.shp"
    df = gpd.read_file(path)
    lines = df.set_geometry(df.boundary)
    res = geo.smooth_network(lines, iterations=2, full_output=True)
    before, after = lines.geometry.values, res.geometry.geometry.values
    assert res.n_lines == 289 and res.n_arcs > 500
    assert list(res.geometry["name"]) == list(df["name"])
    assert_no_new_contacts(before, after)
    assert_areas_exact(before, after)
    c0, c1 = contacts(before), contacts(after)
    borders = [k for k, x in c0.items() if shapely.get_dimensions(x) == 1]
    assert len(borders) > 250
    for k in borders:
        # the shared border is one smoothed polyline, identical in both countries
        assert shapely.get_dimensions(c1[k]) == 1
        assert shapely.hausdorff_distance(c1[k], c0[k]) < 1.0  # degrees; edges are longer
    # the faces between the outlines (noded and deduplicated by union_all): as many as before
    # (no slivers between two versions of a border), with the same total area
    f0 = shapely.get_parts(shapely.polygonize(shapely.get_parts(shapely.union_all(before))))
    f1 = shapely.get_parts(shapely.polygonize(shapely.get_parts(shapely.union_all(after))))
    assert len(f1) == len(f0) > 177
    assert abs(shapely.area(f1).sum() - shapely.area(f0).sum()) < 1e-9


def test_osm_per_line_smoothing_changes_contacts():
    """The peers: smoothing line by line moves junctions and makes roads cross."""
    df = osm_roads()
    before = df.geometry.values
    c0 = contacts(before)
    for method in ("cca", "chaikin"):
        per_line = geo.smooth(df, method=method, iterations=3).geometry.values
        c1 = contacts(per_line)
        moved = [k for k in c0 if k not in c1 or shapely.hausdorff_distance(c0[k], c1[k]) > 1e-3]
        assert len(moved) >= 10, (method, len(moved))


def test_cli_smooth_network(tmp_path):
    src = tmp_path / "roads.gpkg"
    osm_roads().to_file(src)
    out = tmp_path / "smooth.gpkg"
    r = CliRunner().invoke(
        main, ["smooth", str(src), "-o", str(out), "--network", "--iterations", "2"]
    )
    assert r.exit_code == 0, r.output
    assert "36 lines smoothed as one network" in r.output
    df0, df1 = gpd.read_file(src), gpd.read_file(out)
    assert len(df1) == 36 and list(df1["osm_id"]) == list(df0["osm_id"])
    assert_no_new_contacts(df0.geometry.values, df1.geometry.values)
    geojson = tmp_path / "smooth.geojson"
    r = CliRunner().invoke(main, ["smooth", str(src), "-o", str(geojson), "--network"])
    assert r.exit_code == 0 and len(gpd.read_file(geojson)) == 36
    r = CliRunner().invoke(main, ["smooth", str(src), "-o", str(out), "--network", "--coverage"])
    assert r.exit_code == 2 and "Error: --network" in r.output  # a usage error
    assert "Traceback" not in r.output


# --- properties ---------------------------------------------------------------------------


@st.composite
def networks(draw):
    """Random walks on a jittered lattice in map units, some ending on other lines."""
    seed = draw(st.integers(0, 2**32 - 1))
    n_lines = draw(st.integers(2, 8))
    rng = np.random.default_rng(seed)
    scale = draw(st.sampled_from([1.0, 37.5, 1e4]))
    origin = draw(st.sampled_from([(0.0, 0.0), (4.5e5, 1.2e6)]))
    lines = []
    for _ in range(n_lines):
        k = int(rng.integers(3, 30))
        steps = rng.normal(size=(k, 2))
        xy = np.cumsum(steps, axis=0) + rng.uniform(-3, 3, size=2)
        lines.append(xy)
    # a line starting on a vertex of another one (a junction)
    if draw(st.booleans()):
        other = lines[0]
        lines.append(np.vstack([other[len(other) // 2], other[len(other) // 2] + (2.0, -1.5)]))
    # a line running along a stretch of another one, backwards (a shared piece)
    if draw(st.booleans()) and len(lines[1]) >= 4:
        run = lines[1][1:4][::-1]
        lines.append(np.vstack([run[0] + (1.0, 1.0), run, run[-1] + (-1.0, 0.5)]))
    return [shapely.LineString(xy * scale + origin) for xy in lines]


@settings(deadline=None)
@given(networks(), st.integers(1, 2))
def test_property_no_new_contacts_areas_exact_nodes_fixed(lines, iterations):
    lines = np.array(lines, dtype=object)
    simple = shapely.is_simple(lines)
    res = geo.smooth_network(lines, iterations=iterations, full_output=True)
    out = np.asarray(res.geometry, dtype=object)
    scale = max(np.abs(shapely.get_coordinates(lines)).max(), 1.0)
    assert_no_new_contacts(lines, out, tol=1e-9 * scale)
    assert_areas_exact(lines, out)
    # lines that did not cross themselves still do not
    assert (shapely.is_simple(out) | ~simple).all()
    # lines sharing a stretch still share it (the same smoothed piece in both)
    for (a, b), x0 in contacts(lines).items():
        if shapely.get_dimensions(x0) == 1:
            x1 = shapely.intersection(out[a], out[b])
            assert shapely.get_dimensions(x1) == 1
            assert abs(shapely.length(x1) - shapely.length(x0)) <= 0.5 * shapely.length(x0)
    # ends fixed bit for bit
    for a, b in zip(lines, out, strict=True):
        assert a.coords[0] == b.coords[0] and a.coords[-1] == b.coords[-1]


@pytest.mark.slow
def test_demo_network_section(tmp_path):
    from curvesmith import demo

    summary = demo.run_demo(tmp_path, sections=["network"])
    (section,) = summary["sections"]
    files = {f["file"] for f in section["figures"]}
    assert files == {"network_roads.png", "network_contours.png", "network_steep.png"}
    assert all((tmp_path / f).stat().st_size > 10_000 for f in files)
    num = {k: v["value"] for k, v in section["numbers"].items()}
    assert num["network_roads"] == 36 and num["network_reductions"] == 0
    assert num["network_max_shift"] > 4.0 and 0.9 < num["network_max_shift_bounded"] <= 1.0
    assert num["contours_level_contacts_network"] == 0
    assert num["steep_crossing_points_cca_network"] == 0
    assert num["steep_crossing_points_cca_line_by_line"] > 0
    assert num["steep_crossing_points_chaikin_line_by_line"] > 0
    assert "| cca network (smooth_network) | 0 |" in (tmp_path / "summary.md").read_text()


# --- strength and vertex budget in map units (issue 14.5, network mode) --------------------


def jacksboro_contours():
    """Raw 50 m contours of matplotlib's Jacksboro DEM, in its own degrees (766 lines)."""
    from matplotlib import cbook

    grid = geo.read_grid(cbook.get_sample_data("jacksboro_fault_dem.npz", asfileobj=False))
    return geo.contours(grid, interval=50.0, iterations=0)


def test_max_shift_bounds_every_line_of_a_real_network():
    """OSM roads (metres): every line moves at most max_shift, still smoothed, nothing else lost.

    Unbounded, 3 passes move the roads up to 4.4 m (19 of the 36 lines move; the others
    are straight); with the bound each piece between junctions takes the strongest level
    within it, so the network keeps its junctions, gets no new contact, keeps the exact
    area balance, and the same 19 lines are still smoothed.
    """
    df = osm_roads()
    before = df.geometry.values
    free = shapely.hausdorff_distance(before, geo.smooth_network(df, iterations=3).geometry.values)
    assert free.max() > 4.0
    for max_shift in (0.5, 2.0):
        res = geo.smooth_network(df, iterations=3, max_shift=max_shift, full_output=True)
        after = res.geometry.geometry.values
        shift = shapely.hausdorff_distance(before, after)
        assert shift.max() <= max_shift
        assert ((shift > 0) == (free > 0)).all()
        assert_no_new_contacts(before, after)
        assert_areas_exact(before, after)
        for a, b in zip(before, after, strict=True):
            assert a.coords[0] == b.coords[0] and a.coords[-1] == b.coords[-1]


def test_min_segment_is_a_vertex_budget_per_piece():
    """With min_segment every piece that was smoothed has a mean edge of at least L."""
    df = osm_roads()
    n_free = shapely.get_num_coordinates(geo.smooth_network(df, iterations=3).geometry.values)
    res = geo.smooth_network(df, iterations=3, min_segment=8.0, full_output=True)
    after = res.geometry.geometry.values
    assert shapely.get_num_coordinates(after).sum() < 0.5 * n_free.sum()
    assert_no_new_contacts(df.geometry.values, after)
    assert_areas_exact(df.geometry.values, after)
    # piece by piece: cut both networks at their (shared, fixed) nodes
    before_lines = [shapely.get_coordinates(g) for g in df.geometry.values]
    topo = geo.network_topology(before_lines, np.zeros(len(before_lines), dtype=bool))
    nodes = {tuple(p) for p in topo.nodes.tolist()}
    for a, b in zip(df.geometry.values, after, strict=True):
        xy = shapely.get_coordinates(b)
        cut = [k for k, p in enumerate(xy.tolist()) if tuple(p) in nodes]
        for s, e in itertools.pairwise(cut):
            piece = xy[s : e + 1]
            mean_edge = np.linalg.norm(np.diff(piece, axis=0), axis=1).sum() / (e - s)
            unchanged = shapely.covers(shapely.buffer(a, 1e-9), shapely.LineString(piece))
            assert unchanged or mean_edge >= 8.0 * (1 - 1e-12)


def test_contours_in_degrees_keep_their_levels_apart_within_max_shift():
    """Jacksboro's contours in degrees: no line moves more than 1e-4 deg (about 10 m).

    Unbounded, 2 passes move lines up to 1.8e-4 deg; with the bound no two levels touch,
    every line stays within it and most are still smoothed.
    """
    raw = jacksboro_contours()
    res = geo.smooth_network(raw, iterations=2, max_shift=1e-4, full_output=True)
    after = res.geometry.geometry.values
    shift = shapely.hausdorff_distance(raw.geometry.values, after)
    assert shift.max() <= 1e-4 and (shift > 0).mean() > 0.9
    assert geo.level_contacts(after, raw["level"].to_numpy()) == 0
    closed = shapely.is_closed(raw.geometry.values)
    assert closed.sum() > 500
    for a, b in zip(raw.geometry.values[closed], after[closed], strict=True):
        # areas of 1e-13 to 1e-5 deg^2 at longitude -84: shoelace relative to the first vertex
        p, q = shapely.get_coordinates(a), shapely.get_coordinates(b)
        p, q = p - p[0], q - p[0]
        area = [0.5 * np.sum(x[:-1, 0] * x[1:, 1] - x[1:, 0] * x[:-1, 1]) for x in (p, q)]
        assert abs(area[1] - area[0]) <= roundoff_bound(a)


def test_shift_test_is_geos_hausdorff():
    """geo._coverage.shifts_within decides GEOS' hausdorff_distance <= D, arc by arc."""
    from curvesmith.internals import coverage_ragged as _ragged
    from curvesmith.internals import geo_coverage

    rng = np.random.default_rng(3)
    arcs = [np.cumsum(rng.normal(size=(int(rng.integers(2, 50)), 2)), axis=0) for _ in range(300)]
    moved = [a + rng.normal(0, 10 ** rng.uniform(-3, 0), a.shape) for a in arcs]
    moved = [m[:: int(rng.integers(1, 3))] if len(m) > 4 else m for m in moved]
    loops = rng.uniform(size=300) < 0.3
    line = lambda x, r: shapely.LineString(np.vstack([x, x[:1]]) if r else x)  # noqa: E731
    hd = np.array(
        [
            shapely.hausdorff_distance(line(a, r), line(m, r))
            for a, m, r in zip(arcs, moved, loops, strict=True)
        ]
    )
    for d in (1e-3, 0.05, 0.3, 1.0, 3.0):
        got = geo_coverage.shifts_within(_ragged(arcs, loops), _ragged(moved, loops), d)
        assert got.tolist() == (hd <= d).tolist()
    assert 0 < (hd <= 0.3).sum() < 300


def test_cli_network_bounds(tmp_path):
    src = tmp_path / "roads.gpkg"
    osm_roads().to_file(src)
    out = tmp_path / "out.gpkg"
    r = CliRunner().invoke(
        main,
        ["smooth", str(src), "-o", str(out), "--network", "--iterations", "3", "--max-shift", "1"],
    )
    assert r.exit_code == 0, r.output
    assert "smoothed less to stay within the bounds" in r.output
    want = geo.smooth_network(gpd.read_file(src), iterations=3, max_shift=1.0).geometry
    got = gpd.read_file(out).geometry
    assert all(a.equals_exact(b, 0.0) for a, b in zip(got, want, strict=True))


@settings(deadline=None, max_examples=40)
@given(networks(), st.integers(1, 3), st.floats(0.01, 0.5))
def test_property_max_shift_holds_with_no_new_contacts(lines, iterations, shift):
    lines = np.array(lines, dtype=object)
    scale = float(np.median(shapely.length(lines) / (shapely.get_num_coordinates(lines) - 1)))
    res = geo.smooth_network(lines, iterations=iterations, max_shift=shift * scale)
    out = np.asarray(res, dtype=object)
    assert (shapely.hausdorff_distance(lines, out) <= shift * scale).all()
    top = max(np.abs(shapely.get_coordinates(lines)).max(), 1.0)
    assert_no_new_contacts(lines, out, tol=1e-9 * top)
    assert_areas_exact(lines, out)
    for a, b in zip(lines, out, strict=True):
        assert a.coords[0] == b.coords[0] and a.coords[-1] == b.coords[-1]
