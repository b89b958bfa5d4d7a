"""Z and M through every geo path (issue 14 part 3): XY as for 2D data, Z/M along the input.

The XY of the output must be bit-identical to smoothing ``shapely.force_2d(input)``; kept
vertices keep their Z exactly; new vertices get Z interpolated along the input edge they
were built from (so an affine Z, a tilted plane, is reproduced exactly at the foot point
of every vertex); shared coverage arcs and network pieces get identical Z.
"""

import itertools
from pathlib import Path

import geopandas as gpd
import numpy as np
import pyogrio
import pytest
import shapely
from click.testing import CliRunner

from curvesmith import geo
from curvesmith.cli import main
from curvesmith.errors import CurveError

OSM = Path(pyogrio.__file__).parent / "tests" / "fixtures" / "sample.osm.pbf"


def terrain(xy):
    """A smooth hilly surface in metres over projected metres (a few hundred m of relief)."""
    x, y = xy[:, 0], xy[:, 1]
    return 250.0 + 80.0 * np.sin(x / 23e3) * np.cos(y / 17e3) + 1e-3 * (x - y)


def with_z(geoms, fz=terrain):
    """`geoms` with Z = fz(XY) at every vertex (shared vertices get the same Z)."""
    geoms = np.asarray(geoms, dtype=object)
    xy = shapely.get_coordinates(geoms)
    return shapely.set_coordinates(shapely.force_3d(geoms), np.column_stack([xy, fz(xy)]))


def xyz(g):
    return shapely.get_coordinates(g, include_z=True)


def same_xy_as_2d(out, flat_out):
    a = shapely.get_coordinates(np.asarray(out, dtype=object))
    b = shapely.get_coordinates(np.asarray(flat_out, dtype=object))
    return a.shape == b.shape and np.array_equal(a, b)


def kept_z_exact(inp, out):
    """Every output vertex at an input vertex's XY has that vertex's Z; returns how many."""
    src = xyz(np.asarray(inp, dtype=object))
    table = {}
    for x, y, z in src:
        table.setdefault((x, y), set()).add(z)
    n = 0
    for x, y, z in xyz(np.asarray(out, dtype=object)):
        if (x, y) in table:
            assert z in table[(x, y)], (x, y, z, table[(x, y)])
            n += 1
    return n


def one_z_per_xy(out):
    """Every XY that occurs in several output features (or twice) has one Z, bit for bit."""
    seen = {}
    for x, y, z in xyz(np.asarray(out, dtype=object)):
        assert seen.setdefault((x, y), z) == z, (x, y, z, seen[(x, y)])
    return len(seen)


def shared_runs_identical(g1, g2):
    """Vertices of g1 on an edge that g2 also has (either way round) have the same Z in
    both; other common points (crossings: a bridge over a road) may differ. Returns the
    number of such vertices."""
    a, b = xyz(g1), xyz(g2)
    edges = {}
    for p, q in itertools.pairwise(b):
        for u, v in ((p, q), (q, p)):
            edges[(u[0], u[1], v[0], v[1])] = (u[2], v[2])
    n = 0
    for p, q in itertools.pairwise(a):
        z = edges.get((p[0], p[1], q[0], q[1]))
        if z is not None:
            assert z == (p[2], q[2]), (p, q, z)
            n += 1
    return n


def dist_to(line_or_ring, pts):
    return shapely.distance(shapely.points(pts), line_or_ring)


def noisy_ring(n=60, r=400.0, seed=0, origin=(512_000.0, 4_180_000.0)):
    rng = np.random.default_rng(seed)
    ang = np.sort(rng.uniform(0, 2 * np.pi, n))  # uneven spacing
    rad = r * (1 + 0.08 * rng.standard_normal(n))
    return np.column_stack([origin[0] + rad * np.cos(ang), origin[1] + rad * np.sin(ang)])


# ------------------------------------------------------------------------------ geo.smooth


def test_polygons_multipolygons_holes_lines_xy_bit_identical_and_kept_z_exact():
    shell = noisy_ring(80, 900.0, seed=1)
    hole = noisy_ring(30, 200.0, seed=2)[::-1]
    poly = shapely.Polygon(shell, [hole])
    far = shapely.Polygon(noisy_ring(25, 300.0, seed=3, origin=(515_000.0, 4_182_000.0)))
    multi = shapely.MultiPolygon([poly, far])
    line = shapely.LineString(noisy_ring(40, 700.0, seed=4)[:30])
    mline = shapely.MultiLineString([line, shapely.LineString(hole[:12])])
    geoms = with_z([poly, multi, line, mline, far])
    fixed = lambda xy: (xy[:, 0] > 512_500.0) & (xy[:, 1] > 4_180_000.0)  # noqa: E731
    for kwargs in ({"iterations": 1}, {"iterations": 3}, {"method": "chaikin", "iterations": 2}):
        out = geo.smooth(geoms, **kwargs)
        flat = geo.smooth(shapely.force_2d(geoms), **kwargs)
        assert same_xy_as_2d(out, flat)
        assert all(g.has_z for g in out)
        assert [g.geom_type for g in out] == [g.geom_type for g in flat]
        n_kept = kept_z_exact(geoms, out)
        assert n_kept >= 4  # the ends of the three lines
        z = xyz(out)[:, 2]
        assert np.isfinite(z).all()
        zin = xyz(geoms)[:, 2]
        assert zin.min() - 1e-9 <= z.min() and z.max() <= zin.max() + 1e-9  # convex combos
    out = geo.smooth(geoms, iterations=2, fixed=fixed)
    flat = geo.smooth(shapely.force_2d(geoms), iterations=2, fixed=fixed)
    assert same_xy_as_2d(out, flat)
    src = xyz(geoms)
    mask = fixed(src[:, :2])
    assert kept_z_exact(geoms, out) >= mask.sum() - 5  # every fixed vertex (closing ones once)
    o = xyz(out)
    for x, y, z in src[mask]:
        hit = (o[:, 0] == x) & (o[:, 1] == y)
        assert hit.any() and np.all(o[hit, 2] == z)


def test_geometry_collection_with_multipolygon():
    mp = shapely.MultiPolygon([shapely.Polygon(noisy_ring(20, 300.0, seed=8))])
    gc = with_z([shapely.GeometryCollection([mp, shapely.LineString(noisy_ring(15, 200.0)[:9])])])
    out = geo.smooth(gc, iterations=2)
    assert same_xy_as_2d(out, geo.smooth(shapely.force_2d(gc), iterations=2))
    q, src = xyz(out), xyz(gc)
    assert src[:, 2].min() <= q[:, 2].min() and q[:, 2].max() <= src[:, 2].max()
    assert kept_z_exact(gc, out) >= 2


def test_make_valid_bowtie_pairs_the_repaired_rings():
    """make_valid splits a bow-tie into two triangles; each gets Z from its own half."""
    bow = shapely.Polygon([(0, 0, 0), (200, 200, 20), (200, 0, 30), (0, 200, 10)])
    out = geo.smooth(bow, make_valid=True, iterations=2)
    assert same_xy_as_2d([out], [geo.smooth(shapely.force_2d(bow), make_valid=True, iterations=2)])
    assert out.geom_type == "MultiPolygon" and out.has_z
    for part in out.geoms:
        q = xyz(part.exterior)
        right = q[:, 0].mean() > 100  # (100, 100, 15) - (200, 200, 20) - (200, 0, 30)
        lo, hi = (15, 30) if right else (0, 15)
        assert lo <= q[:, 2].min() and q[:, 2].max() <= hi
        assert np.abs(np.diff(q[:, 2])).max() < 3.0  # no jump to the other half


def test_flat_z_stays_exact():
    """A polygon at one height (a lake, a flat roof) stays at that height bit for bit."""
    ring = noisy_ring(70, 500.0, seed=5)
    for g in (shapely.Polygon(ring), shapely.LineString(ring)):
        out = geo.smooth(shapely.force_3d(g, 250.0), iterations=3)
        assert np.all(xyz(out)[:, 2] == 250.0)


def test_gdf_mixed_2d_and_3d_none_and_empty():
    df = gpd.GeoDataFrame(
        {"name": ["a", "b", "c", "d"]},
        geometry=[
            shapely.Polygon(np.column_stack([noisy_ring(20), np.arange(20.0)])),
            shapely.box(0, 0, 10, 10),
            None,
            shapely.Polygon(),
        ],
        crs="EPSG:32633",
    )
    out = geo.smooth(df, iterations=2)
    assert list(out["name"]) == ["a", "b", "c", "d"] and out.crs == df.crs
    assert out.geometry[0].has_z and not out.geometry[1].has_z
    assert out.geometry[2] is None and out.geometry[3].is_empty
    assert same_xy_as_2d(
        out.geometry.values[:2], geo.smooth(shapely.force_2d(df.geometry.values[:2]), iterations=2)
    )


def test_tilted_plane_foot_points_exact():
    """z = a x + b y + c: every vertex gets the plane's value at its foot on the input.

    Linear interpolation of an affine function along a segment is exact, so:
    (1) vertices on an input edge (CCA's cut points, Chaikin's first pass) lie on the plane
    to rounding; (2) every vertex is off the plane by (a, b) . (Q - F), at most |(a, b)|
    times its distance to the input; after one CCA pass the augmentation apexes are the
    only vertices off the input, so at least 2/3 of the vertices are on it.
    """
    a, b, c = 0.031, -0.047, 812.5  # a 5.6 % slope
    grad = np.hypot(a, b)
    ring = noisy_ring(90, 600.0, seed=7)
    for shape in (shapely.Polygon(ring), shapely.LineString(ring[:70])):
        src = with_z([shape], lambda xy: a * xy[:, 0] + b * xy[:, 1] + c)[0]
        plane_scale = 1e-15 * 8 * (abs(a) * 6e5 + abs(b) * 4.2e6 + c)  # rounding of a x + b y + c
        for method, iters in (("cca", 1), ("cca", 3), ("chaikin", 1), ("chaikin", 2)):
            out = geo.smooth(src, method=method, iterations=iters)
            q = xyz(out)
            off = np.abs(q[:, 2] - (a * q[:, 0] + b * q[:, 1] + c))
            d = dist_to(
                shapely.force_2d(src).boundary
                if shape.geom_type == "Polygon"
                else shapely.force_2d(src),
                q[:, :2],
            )
            on_edge = d <= 1e-9
            assert np.all(off[on_edge] <= plane_scale + grad * 1e-9)
            assert np.all(off <= grad * d * (1 + 1e-9) + plane_scale)
            if method == "chaikin" and iters == 1:
                assert on_edge.all()
            elif iters == 1:
                assert on_edge.mean() >= 2 / 3 - 0.02
            assert off.max() > 0 or method == "chaikin"


def test_convex_ring_matches_nearest_point_reference():
    """On a convex ring the walk along the curve equals the plain nearest-point rule."""
    ang = np.linspace(0, 2 * np.pi, 37)[:-1] + 0.01 * np.sin(np.arange(36))
    xy = np.column_stack([3e5 + 1e3 * np.cos(ang), 5e6 + 700 * np.sin(ang)])
    zin = 100.0 + 50.0 * np.sin(3 * ang)  # not affine: interpolation is along the edges
    src = shapely.Polygon(np.column_stack([xy, zin]))
    out = geo.smooth(src, iterations=2)
    q = xyz(out)[:-1]
    ref = []
    for p in q[:, :2]:
        best = (np.inf, 0.0)
        for i in range(36):
            a, b = xy[i], xy[(i + 1) % 36]
            t = np.clip(np.dot(p - a, b - a) / np.dot(b - a, b - a), 0.0, 1.0)
            dd = np.linalg.norm(a + t * (b - a) - p)
            if dd < best[0]:
                best = (dd, (1 - t) * zin[i] + t * zin[(i + 1) % 36])
        ref.append(best[1])
    np.testing.assert_allclose(q[:, 2], ref, rtol=0, atol=1e-9)


def test_hairpin_never_takes_z_from_the_other_arm():
    """A thin switchback ramp: the arms are 2 m apart in XY and 40 m apart in Z."""
    s = np.linspace(0.0, 400.0, 81)
    up = np.column_stack([s, np.zeros_like(s), 0.1 * s])
    turn = np.array([[402.0, 1.0, 40.2]])
    down = np.column_stack([s[::-1], np.full_like(s, 2.0), 40.4 + 0.1 * (400 - s[::-1])])
    line = shapely.LineString(np.vstack([up, turn, down]) + np.array([4e5, 6e6, 0]))
    out = geo.smooth(line, iterations=3)
    q = xyz(out)
    dz = np.diff(q[:, 2])
    # the arms are 40 m apart in Z: a vertex attached to the other arm would jump by ~40 m;
    # the largest step is at the cut tip (0.06 m: the two sides of the cut corner project
    # 0.7 m apart along the input, at a 9 % grade)
    assert np.abs(dz).max() < 0.1
    assert np.all(dz >= -1e-9)  # the ramp climbs all the way


def test_m_and_zm_in_python():
    line = shapely.from_wkt(
        "LINESTRING ZM (0 0 10 0, 100 50 20 1, 200 0 30 2, 300 80 40 3, 400 0 50 4)"
    )
    out = geo.smooth(line, iterations=2)
    assert out.has_z and out.has_m
    c = shapely.get_coordinates(out, include_z=True, include_m=True)
    assert np.array_equal(
        c[:, :2], shapely.get_coordinates(geo.smooth(shapely.force_2d(line), iterations=2))
    )
    np.testing.assert_allclose(c[:, 3], (c[:, 2] - 10) / 10, atol=1e-12)  # M = (Z - 10) / 10
    assert tuple(c[0]) == (0, 0, 10, 0) and tuple(c[-1]) == (400, 0, 50, 4)
    poly = shapely.from_wkt(
        "MULTIPOLYGON M (((0 0 0, 10 0 1, 10 10 2, 0 10 3, 0 0 0), (2 2 9, 2 4 9, 4 4 9, 4 2 9, 2 2 9)))"
    )
    out = geo.smooth(poly, iterations=1)
    assert out.has_m and not out.has_z and out.geom_type == "MultiPolygon"
    c = shapely.get_coordinates(out, include_m=True)
    hole = shapely.get_coordinates(out.geoms[0].interiors[0], include_m=True)
    assert np.all(hole[:, 2] == 9.0)
    assert c[:, 2].min() >= 0 and c[:, 2].max() <= 9


# ------------------------------------------------------------------------------ coverage


@pytest.fixture(scope="module")
def kentucky():
    df = geo.us_counties(states=["21"]).to_crs("EPSG:5070")
    return df.assign(geometry=with_z(df.geometry.values))


def test_coverage_shared_arcs_identical_z(kentucky):
    res = geo.smooth_coverage(kentucky, iterations=2, full_output=True)
    flat = geo.smooth_coverage(shapely.force_2d(kentucky.geometry.values), iterations=2)
    out = res.geometry.geometry.values
    assert same_xy_as_2d(out, flat)
    assert res.coverage_valid
    n_xy = one_z_per_xy(out)
    assert n_xy > 50_000
    assert kept_z_exact(kentucky.geometry.values, out) >= res.n_nodes  # nodes keep their Z
    # interpolation: every polygon's Z stays within its input's range
    for g_in, g_out in zip(kentucky.geometry.values, out, strict=True):
        zi, zo = xyz(g_in)[:, 2], xyz(g_out)[:, 2]
        assert zi.min() <= zo.min() and zo.max() <= zi.max()


def test_coverage_island_loop_shared_by_hole_and_island():
    """A loop arc (an island inside a hole, no node) gets the same Z in both polygons,
    even when the two rings start at different vertices and run opposite ways."""
    isl = noisy_ring(40, 300.0, seed=11)
    outer = shapely.Polygon(noisy_ring(50, 1200.0, seed=12), [isl])
    island = shapely.Polygon(np.roll(isl[::-1], 7, axis=0))
    geoms = with_z([outer, island])
    out = geo.smooth_coverage(geoms, iterations=2)
    assert same_xy_as_2d(out, geo.smooth_coverage(shapely.force_2d(geoms), iterations=2))
    a = xyz(out[0].interiors[0])[:-1]
    b = xyz(out[1].exterior)[:-1]
    key = {(x, y): z for x, y, z in a}
    assert len(key) == len(b) and all(key[(x, y)] == z for x, y, z in b)


# ------------------------------------------------------------------------------ network


def test_network_shared_pieces_identical_z_and_ends_exact():
    base = noisy_ring(60, 800.0, seed=21)[:45]
    a = shapely.LineString(base)
    b = shapely.LineString(np.vstack([base[10:30][::-1], [[base[10, 0] - 300, base[10, 1] + 50]]]))
    c = shapely.LineString([base[30], base[30] + [250, 400], base[30] + [600, 500]])
    geoms = with_z([a, b, c])
    res = geo.smooth_network(geoms, iterations=3, full_output=True)
    flat = geo.smooth_network(shapely.force_2d(geoms), iterations=3)
    assert same_xy_as_2d(res.geometry, flat)
    kept_z_exact(geoms, res.geometry)
    # the shared piece (a's vertices 10..29, b backwards) is the same in both, with its Z
    pb = xyz(res.geometry[1])
    assert shared_runs_identical(res.geometry[0], res.geometry[1]) >= 3**3 * 19 // 2
    assert shared_runs_identical(res.geometry[1], res.geometry[0]) >= 3**3 * 19 // 2
    # b's tail crosses the shared stretch: there b is at two heights (it passes over itself)
    _, first, counts = np.unique(pb[:, :2], axis=0, return_index=True, return_counts=True)
    twice = pb[:, :2][first[counts == 2]]
    assert len(twice) == 1  # b's tail crosses the shared stretch: b is there at two heights
    zs = pb[np.all(pb[:, :2] == twice[0], axis=1), 2]
    assert zs[0] != zs[1]
    for g_in, g_out in zip(geoms, res.geometry, strict=True):
        assert tuple(xyz(g_in)[0]) == tuple(xyz(g_out)[0])
        assert tuple(xyz(g_in)[-1]) == tuple(xyz(g_out)[-1])


def test_network_osm_roads_z():
    pyogrio.set_gdal_config_options({"OSM_USE_CUSTOM_INDEXING": "NO"})
    df = pyogrio.read_dataframe(OSM, layer="lines").to_crs("EPSG:27700")
    df = df.assign(geometry=with_z(df.geometry.values, lambda xy: 40 + 1e-2 * (xy[:, 0] % 997)))
    out = geo.smooth_network(df, iterations=2)
    flat = geo.smooth_network(shapely.force_2d(df.geometry.values), iterations=2)
    assert same_xy_as_2d(out.geometry.values, flat)
    assert out.geometry.has_z.all()
    g = out.geometry.values
    n = sum(
        shared_runs_identical(g[i], g[j]) for i in range(len(g)) for j in range(len(g)) if i != j
    )
    assert n > 0
    assert kept_z_exact(df.geometry.values, out.geometry.values) >= 2 * len(df)


# ------------------------------------------------------------------------------ files


def test_cli_round_trip_gpkg_and_shp_with_z(tmp_path, kentucky):
    small = kentucky.iloc[:25]
    src = tmp_path / "z.gpkg"
    geo.write_file(small, src)
    ref = geo.smooth(small, iterations=2)
    for suffix in (".gpkg", ".shp"):
        out = tmp_path / f"out{suffix}"
        r = CliRunner().invoke(main, ["smooth", str(src), "-o", str(out), "--iterations", "2"])
        assert r.exit_code == 0, r.output
        back = geo.read_file(out)
        assert pyogrio.read_info(out)["geometry_type"].endswith("Z")
        got = shapely.normalize(back.geometry.values)
        exp = (
            shapely.normalize(shapely.force_3d(ref.geometry.values))
            if suffix == ".shp"
            else shapely.normalize(ref.geometry.values)
        )
        assert np.array_equal(xyz(got), xyz(exp))
    # coverage mode too
    out = tmp_path / "cov.gpkg"
    r = CliRunner().invoke(main, ["smooth", str(src), "-o", str(out), "--coverage"])
    assert r.exit_code == 0, r.output
    back = geo.read_file(out).geometry.values
    assert all(g.has_z for g in back)
    one_z_per_xy(back)


def test_cli_network_with_z(tmp_path):
    base = noisy_ring(60, 800.0, seed=21)[:45]
    lines = with_z([shapely.LineString(base), shapely.LineString(base[10:30][::-1])])
    src = tmp_path / "net.gpkg"
    geo.write_file(gpd.GeoDataFrame({"id": [1, 2]}, geometry=lines, crs="EPSG:32633"), src)
    out = tmp_path / "net_out.gpkg"
    r = CliRunner().invoke(
        main, ["smooth", str(src), "-o", str(out), "--network", "--iterations", "2"]
    )
    assert r.exit_code == 0, r.output
    back = geo.read_file(out).geometry.values
    exp = geo.smooth_network(lines, iterations=2)
    assert np.array_equal(xyz(back), xyz(exp))
    assert shared_runs_identical(back[1], back[0]) == len(xyz(back[1])) - 1


def test_m_files_keep_m_through_the_cli(tmp_path):
    """XYM GeoPackages: read and written through pyogrio's Arrow path, which keeps M.

    The fixture is a GeoPackage written by pyogrio, its geometry then replaced in SQLite by
    an ISO WKB LINESTRING M and its geometry column flagged m = 1 (GeoPackage 1.4, 2.1.3);
    pyogrio's default reader drops the M (read_info says "LineString"), its Arrow reader
    keeps it. Before, such files were refused rather than losing M.
    """
    import sqlite3
    import struct

    src = tmp_path / "m.gpkg"
    line = gpd.GeoDataFrame(
        {"id": [1]}, geometry=[shapely.LineString([(0, 0), (1, 1), (2, 0)])], crs="EPSG:3857"
    )
    line.to_file(src, layer="m", layer_options={"SPATIAL_INDEX": "NO"})
    wkb = shapely.to_wkb(shapely.from_wkt("LINESTRING M (0 0 5, 1 1 6, 2 0 7)"), flavor="iso")
    with sqlite3.connect(src) as con:
        srs, col = con.execute(
            "select srs_id, column_name from gpkg_geometry_columns where table_name = 'm'"
        ).fetchone()
        blob = b"GP" + bytes([0, 1]) + struct.pack("<i", srs) + wkb  # no envelope
        con.execute(f'update "m" set "{col}" = ?', (blob,))
        con.execute("update gpkg_geometry_columns set m = 1 where table_name = 'm'")
    with pytest.warns(UserWarning, match="Measured"):
        assert pyogrio.read_info(src)["geometry_type"] == "LineString"  # M dropped by pyogrio
    df = geo.read_file(src)
    assert shapely.has_m(df.geometry.values).all()
    np.testing.assert_array_equal(
        shapely.get_coordinates(df.geometry.values, include_m=True)[:, 2], [5, 6, 7]
    )
    out = tmp_path / "out.gpkg"
    r = CliRunner().invoke(main, ["smooth", str(src), "-o", str(out), "--iterations", "2"])
    assert r.exit_code == 0, r.output
    back = geo.read_file(out).geometry.values
    want = geo.smooth(df, iterations=2).geometry.values
    assert shapely.has_m(back).all()
    np.testing.assert_array_equal(
        shapely.get_coordinates(back, include_m=True), shapely.get_coordinates(want, include_m=True)
    )
    m = shapely.get_coordinates(back, include_m=True)[:, 2]
    assert m[0] == 5 and m[-1] == 7 and np.all((m >= 5) & (m <= 7))  # ends kept, interpolated
    # a Shapefile cannot hold them through pyogrio: one line, exit 1, nothing written
    shp = tmp_path / "out.shp"
    r = CliRunner().invoke(main, ["smooth", str(src), "-o", str(shp)])
    assert r.exit_code == 1
    assert r.output.count("\n") == 1 and "M (measure)" in r.output and "Traceback" not in r.output
    assert not shp.exists()


def test_equal_area_and_geographic_keep_z(tmp_path):
    df = geo.us_counties(states=["44"])  # Rhode Island, EPSG:4269
    df = df.assign(geometry=with_z(df.geometry.values, lambda xy: 30 + 10 * xy[:, 1]))
    src = tmp_path / "ri.gpkg"
    geo.write_file(df, src)
    flat = tmp_path / "ri2d.gpkg"
    geo.write_file(df.assign(geometry=shapely.force_2d(df.geometry.values)), flat)
    for extra in ([], ["--equal-area"]):
        out, out2 = tmp_path / "o.gpkg", tmp_path / "o2.gpkg"
        assert CliRunner().invoke(main, ["smooth", str(src), "-o", str(out), *extra]).exit_code == 0
        assert (
            CliRunner().invoke(main, ["smooth", str(flat), "-o", str(out2), *extra]).exit_code == 0
        )
        g, g2 = geo.read_file(out).geometry.values, geo.read_file(out2).geometry.values
        assert all(x.has_z for x in g)
        assert np.array_equal(shapely.get_coordinates(g), shapely.get_coordinates(g2))
        kept_z_exact(df.geometry.values, g)


def test_errors_still_one_line():
    with pytest.raises(CurveError, match=r"geometry\[0\] is a Point"):
        geo.smooth(shapely.Point(0, 0, 1))
