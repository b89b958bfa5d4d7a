"""curvesmith.geo.smooth_coverage: shared arcs, exact areas, no gaps or overlaps."""

import geopandas as gpd
import numpy as np
import pytest
import shapely
from hypothesis import given
from hypothesis import strategies as st

from curvesmith import cca, geo
from curvesmith.errors import CurveError
from curvesmith.internals import (
    coverage_flat_uses,
    coverage_patched,
    coverage_ragged,
    coverage_shells,
    coverage_valid_by_proof,
    geo_coverage,
    geo_simple,
)

rebuild = geo_coverage.rebuild


def lattice_coverage(blocks=3, k=4, jitter=0.25, seed=0):
    """A blocks x blocks coverage of k x k cells on a jittered lattice (exact shared vertices)."""
    rng = np.random.default_rng(seed)
    n = blocks * k
    pts = np.stack(np.meshgrid(np.arange(n + 1.0), np.arange(n + 1.0), indexing="ij"), axis=-1)
    pts += rng.uniform(-jitter, jitter, size=pts.shape)
    polys = []
    for bi in range(blocks):
        for bj in range(blocks):
            i0, j0 = bi * k, bj * k
            path = [pts[i, j0] for i in range(i0, i0 + k)]
            path += [pts[i0 + k, j] for j in range(j0, j0 + k)]
            path += [pts[i, j0 + k] for i in range(i0 + k, i0, -1)]
            path += [pts[i0, j] for j in range(j0 + k, j0, -1)]
            polys.append(shapely.Polygon(path))
    return np.array(polys, dtype=object)


def geos_arcs(polys):
    """Reference arcs: GEOS noding + merging of all boundaries."""
    return shapely.get_parts(shapely.line_merge(shapely.union_all(shapely.boundary(polys))))


def topology_lines(topo):
    return np.array(
        [
            shapely.LineString(np.vstack([a, a[:1]]) if loop else a)
            for a, loop in zip(topo.arcs, topo.loops, strict=True)
        ],
        dtype=object,
    )


def same_arc_sets(mine, ref):
    if len(mine) != len(ref):
        return False
    qi, qj = shapely.STRtree(ref).query(mine, predicate="covered_by")
    eq = shapely.equals(mine[qi], ref[qj])
    return len(np.unique(qi[eq])) == len(mine) and len(np.unique(qj[eq])) == len(ref)


def check_result(src, res, rtol=1e-9):
    out = res.geometry if hasattr(res, "geometry") else res
    if isinstance(out, gpd.GeoDataFrame):
        out = out.geometry.values
    out = np.asarray(out, dtype=object)
    assert shapely.is_valid(out).all()
    assert shapely.coverage_is_valid(out)
    np.testing.assert_allclose(shapely.area(out), shapely.area(src), rtol=rtol)


# --- topology ----------------------------------------------------------------------------


def test_lattice_topology_counts_and_matches_geos():
    polys = lattice_coverage()
    assert shapely.coverage_is_valid(polys)
    topo = geo.coverage_topology(polys)
    # 4 inner junctions (degree 4) + 8 on the outer boundary (degree 3)
    assert topo.n_nodes == 12
    # 12 shared arcs between blocks + 8 pieces of the outer boundary
    assert len(topo.arcs) == 20
    assert sum(len(p) == 2 for p in topo.arc_polygons) == 12
    assert same_arc_sets(topology_lines(topo), geos_arcs(polys))


def test_rebuild_from_unsmoothed_arcs_is_identity():
    polys = lattice_coverage(seed=3)
    topo = geo.coverage_topology(polys)
    back = rebuild(topo, list(topo.arcs))
    assert all(shapely.equals(a, b) for a, b in zip(back, polys, strict=True))


def test_island_is_a_loop_arc():
    outer = shapely.Polygon(
        [(0, 0), (10, 0), (10, 10), (0, 10)], [[(3, 3), (3, 7), (7, 7), (7, 5), (7, 3)]]
    )
    island = shapely.Polygon([(3, 3), (7, 3), (7, 5), (7, 7), (3, 7)])
    topo = geo.coverage_topology([outer, island])
    assert list(topo.loops) == [True, True]
    assert topo.n_nodes == 0
    assert topo.rings == (((0, True),), ((1, True),), ((1, False),))
    res = geo.smooth_coverage([outer, island], iterations=3, full_output=True)
    check_result(np.array([outer, island]), res)
    assert res.n_arcs == 2
    assert len(res.geometry[1].exterior.coords) - 1 == 5 * 27


def test_real_topology_matches_geos_on_iowa():
    df = geo.us_counties(states=["19"])
    topo = geo.coverage_topology(df.geometry.values)
    assert same_arc_sets(topology_lines(topo), geos_arcs(df.geometry.values))


# --- smoothing ---------------------------------------------------------------------------


@pytest.mark.parametrize("iterations", [1, 2, 3])
def test_lattice_coverage_areas_exact_and_valid(iterations):
    polys = lattice_coverage(seed=iterations)
    res = geo.smooth_coverage(polys, iterations=iterations, full_output=True)
    check_result(polys, res)
    assert res.coverage_valid is True and res.input_coverage_valid is True
    assert res.max_area_change < 1e-12
    assert res.invalid_edges == {}
    # every polygon really changed shape
    assert not any(shapely.equals(a, b) for a, b in zip(polys, res.geometry, strict=True))


def test_shared_arc_is_smoothed_once_with_cca():
    """Reference: a shared arc is exactly cca.smooth of the arc, ends fixed."""
    polys = lattice_coverage(blocks=2, k=5, seed=7)
    topo = geo.coverage_topology(polys)
    res = geo.smooth_coverage(polys, iterations=2, full_output=True)
    assert res.reductions == ()
    shared = [i for i, p in enumerate(topo.arc_polygons) if p == (0, 1)]
    assert len(shared) == 1
    arc = topo.arcs[shared[0]]
    expected = cca.smooth(arc, closed=False, iterations=2)
    b0 = shapely.get_coordinates(res.geometry[0].exterior)
    b1 = shapely.get_coordinates(res.geometry[1].exterior)
    for ring in (b0, b1):
        hits = [np.all(np.isclose(ring, e, rtol=0, atol=1e-12).all(axis=1).any()) for e in expected]
        assert all(hits)


@given(
    seed=st.integers(0, 10_000),
    iterations=st.integers(1, 3),
    jitter=st.one_of(st.just(0.0), st.floats(1e-6, 0.3)),
)
def test_property_lattice_coverage(seed, iterations, jitter):
    polys = lattice_coverage(blocks=2, k=3, jitter=jitter, seed=seed)
    res = geo.smooth_coverage(polys, iterations=iterations, full_output=True)
    check_result(polys, res)


def test_narrow_bay_arc_is_reduced_not_crossed():
    # polygon b lies on top of polygon a and fills its 0.1 wide slit: the shared arc runs
    # along the top and down and up the slit; its corners at the slit mouth are cut deep
    a = shapely.Polygon(
        [(0, 0), (10, 0), (10, 10), (5.05, 10), (5.05, 1), (4.95, 1), (4.95, 10), (0, 10)]
    )
    b = shapely.Polygon(
        [(0, 10), (4.95, 10), (4.95, 1), (5.05, 1), (5.05, 10), (10, 10), (10, 11), (0, 11)]
    )
    polys = np.array([a, b])
    assert shapely.coverage_is_valid(polys)
    topo = geo.coverage_topology(polys)
    u = next(x for x, p in zip(topo.arcs, topo.arc_polygons, strict=True) if p == (0, 1))
    assert not shapely.LineString(cca.smooth(u, closed=False)).is_simple
    res = geo.smooth_coverage(polys, full_output=True)
    check_result(polys, res)
    assert res.reductions
    assert all(r.polygons == (0, 1) for r in res.reductions)


def test_real_coverage_nebraska_kansas():
    df = geo.us_counties(states=["31", "20"])
    polys = df.geometry.values
    assert len(polys) == 198
    topo = geo.coverage_topology(polys)
    # naive smoothing (every arc at full strength, no conflict check) breaks the coverage
    arcs = zip(topo.arcs, topo.loops, strict=True)
    naive = rebuild(topo, [cca.smooth(a, closed=bool(lp)) for a, lp in arcs])
    assert not (shapely.is_valid(naive).all() and shapely.coverage_is_valid(naive))
    res = geo.smooth_coverage(df, full_output=True)
    assert isinstance(res.geometry, gpd.GeoDataFrame)
    assert list(res.geometry["NAME"]) == list(df["NAME"])
    assert res.geometry.crs == df.crs
    check_result(polys, res)
    assert res.reductions
    names = {df["NAME"].iloc[p] for r in res.reductions for p in r.polygons}
    assert {"Dundy", "Hitchcock", "Rawlins"} <= names


@pytest.mark.slow
def test_real_coverage_all_us_counties():
    df = geo.us_counties()
    assert len(df) == 3233
    res = geo.smooth_coverage(df, full_output=True)
    assert res.coverage_valid is True
    assert res.max_area_change < 1e-9
    out = res.geometry.geometry.values
    assert shapely.is_valid(out).all()
    np.testing.assert_allclose(shapely.area(out), shapely.area(df.geometry.values), rtol=1e-9)


# --- imperfect coverages -----------------------------------------------------------------


def test_t_junction_is_reported_and_left_alone():
    # the top cell lacks the vertex (1, 1) that its two neighbours have: not edge-matched
    cells = np.array(
        [
            shapely.Polygon([(0, 0), (0.5, -0.2), (1, 0), (1, 1), (0, 1)]),
            shapely.Polygon([(1, 0), (1.5, 0.2), (2, 0), (2, 1), (1, 1)]),
            shapely.Polygon([(0, 1), (2, 1), (2, 2), (1, 2.3), (0, 2)]),
        ]
    )
    assert not shapely.coverage_is_valid(cells)
    res = geo.smooth_coverage(cells, iterations=2, full_output=True)
    assert res.input_coverage_valid is False
    assert set(res.invalid_edges) == {0, 1, 2}
    np.testing.assert_allclose(sorted(res.invalid_edges.values()), [1.0, 1.0, 2.0])
    out = res.geometry
    assert shapely.is_valid(out).all()
    np.testing.assert_allclose(shapely.area(out), shapely.area(cells), rtol=1e-12)
    # the border y = 1 is untouched, so no gap or overlap appeared there
    for p in out:
        on_border = shapely.get_coordinates(p)[:, 1] == 1.0
        assert on_border.sum() >= 2
    assert shapely.area(shapely.union_all(out)) == pytest.approx(shapely.area(out).sum())


def test_snapping_cleans_a_sliver_gap():
    left = shapely.Polygon([(0, 0), (1, 0), (1.2, 0.5), (1, 1), (0, 1)])
    right = shapely.Polygon([(1 + 1e-7, 0), (2, 0), (2, 1), (1 + 1e-7, 1), (1.2 + 1e-7, 0.5)])
    polys = np.array([left, right])
    res = geo.smooth_coverage(polys, full_output=True, gap_width=1e-6)
    assert set(res.invalid_edges) == {0, 1}
    snapped = geo.smooth_coverage(polys, snap=1e-6, full_output=True)
    assert snapped.input_coverage_valid is True
    assert snapped.invalid_edges == {}
    assert snapped.coverage_valid is True
    clean = shapely.coverage_clean(polys, snapping_distance=1e-6)
    np.testing.assert_allclose(shapely.area(snapped.geometry), shapely.area(clean), rtol=1e-12)
    # the snapping's own area change is reported (the smoothing's is measured after it)
    moved = np.abs(shapely.area(clean) - shapely.area(polys)) / shapely.area(polys)
    assert snapped.snap_area_change == pytest.approx(float(moved.max()), rel=1e-9)
    assert snapped.snap_area_change > 1e-8 and snapped.max_area_change < 1e-12
    assert res.snap_area_change == 0.0  # no snap, no change


def test_the_command_line_reports_what_the_snap_changed(tmp_path):
    # Before, `--coverage --snap` said nothing of the areas the snapping changed, beside
    # the smoothing's promise of exact areas
    import geopandas as gpd
    from click.testing import CliRunner

    from curvesmith.cli import main

    left = shapely.Polygon([(0, 0), (100, 0), (120, 50), (100, 100), (0, 100)])
    right = shapely.Polygon([(100.4, 0), (200, 0), (200, 100), (100.4, 100), (120.4, 50)])
    src, out = tmp_path / "pair.gpkg", tmp_path / "out.gpkg"
    gpd.GeoDataFrame(geometry=[left, right], crs="EPSG:32633").to_file(src)
    res = CliRunner().invoke(
        main, ["smooth", str(src), "-o", str(out), "--coverage", "--snap", "1"]
    )
    assert res.exit_code == 0, res.output
    clean = shapely.coverage_clean(np.array([left, right]), snapping_distance=1.0)
    moved = np.abs(shapely.area(clean) - shapely.area([left, right])) / shapely.area([left, right])
    assert f"--snap changed feature areas by up to {100 * moved.max():.3g} % before" in res.output
    assert "coverage valid" in res.output
    res = CliRunner().invoke(main, ["smooth", str(src), "-o", str(out), "--coverage"])
    assert "--snap changed" not in res.output


def _wavy_pair(width):
    """Two polygons in UTM metres sharing a wavy border, `width` and 2.5 x `width` wide."""
    y = np.linspace(0.0, 300.0, 31)
    x = 500_000.0 + width + 8.0 * np.sin(y / 25.0)
    border = np.c_[x, 5_000_000.0 + y]
    left = shapely.Polygon(
        np.vstack([[[500_000.0, 5_000_300.0], [500_000.0, 5_000_000.0]], border])
    )
    right_x = 500_000.0 + 3.5 * width
    right = shapely.Polygon(
        np.vstack([border[::-1], [[right_x, 5_000_000.0], [right_x, 5_000_300.0]]])
    )
    return np.array([left, right], dtype=object)


@pytest.mark.parametrize(("snap", "gone"), [(200.0, 1), (1000.0, 2)])
def test_a_snap_as_wide_as_a_feature_is_refused(snap, gone):
    # a user's two parcels (100 and 250 m wide) with --snap 200: the cleaned coverage had a
    # feature without rings, which the compiled nesting test read out of bounds (SIGSEGV);
    # --snap 1000 ended in a traceback. Snapping a feature away is refused in one line.
    polys = _wavy_pair(100.0)
    assert shapely.coverage_is_valid(polys)
    with pytest.raises(CurveError, match=rf"snap {snap:g} removes {gone} feature\(s\) entirely"):
        geo.smooth_coverage(polys, snap=snap)
    res = geo.smooth_coverage(polys, snap=1.0, full_output=True)  # a snap well below: fine
    assert res.coverage_valid and shapely.is_valid(res.geometry).all()


def test_nesting_of_a_feature_without_rings_is_not_proven():
    xy = np.zeros((10, 2))
    empty = np.zeros(0, dtype=np.int64)
    got = geo_simple.nesting_certainly_valid_rows(xy, empty, empty, [0, 0], [0, 1])
    assert got.tolist() == [False]


def test_real_imperfect_coverage_adds_no_new_invalid_edges():
    df = geo.us_counties(year=2010, states=["19", "31"])
    polys = df.geometry.values
    before = shapely.coverage_invalid_edges(polys)
    flagged = set(np.nonzero(~shapely.is_empty(before))[0])
    assert flagged  # the Iowa-Nebraska border is not edge-matched in this file
    res = geo.smooth_coverage(df, full_output=True)
    assert set(res.invalid_edges) == flagged
    out = res.geometry.geometry.values
    after = shapely.coverage_invalid_edges(out)
    assert set(np.nonzero(~shapely.is_empty(after))[0]) == flagged
    np.testing.assert_allclose(shapely.length(after), shapely.length(before), rtol=1e-12)
    np.testing.assert_allclose(shapely.area(out), shapely.area(polys), rtol=1e-9)
    assert shapely.is_valid(out).all()


# --- bad input ---------------------------------------------------------------------------


def test_coverage_bad_inputs():
    with pytest.raises(
        CurveError, match=r"polygons\[1\] is a LineString: a coverage contains only"
    ):
        geo.smooth_coverage([shapely.box(0, 0, 1, 1), shapely.LineString([(0, 0), (1, 1)])])
    bowtie = shapely.Polygon([(0, 0), (2, 2), (2, 0), (0, 2)])
    with pytest.raises(CurveError, match=r"polygons\[0\] is not valid"):
        geo.smooth_coverage([bowtie])
    with pytest.raises(CurveError, match="snap must be >= 0, got -1.0"):
        geo.smooth_coverage([shapely.box(0, 0, 1, 1)], snap=-1)
    with pytest.raises(CurveError, match=r"polygons\[0\] is a Point"):
        geo.smooth_coverage([shapely.Point(0, 0)])


INVALID = {
    "bowtie": [(0, 0), (2, 2), (2, 0), (0, 2)],
    "spike": [(0, 0), (2, 0), (2, 2), (1, 2), (1, 3), (1, 2), (0, 2)],
    # a ring through one vertex twice: its two arcs (both from that node back to it) meet
    # only at their end node, so the coverage proof passes; the ring is not simple
    "pinch": [(0, 0), (2, 0), (1, 1), (2, 2), (0, 2), (1, 1)],
    "flat": [(0, 0), (1, 0), (2, 0)],
}


@pytest.mark.parametrize("name", INVALID)
@pytest.mark.parametrize("position", [0, 2])
def test_an_invalid_polygon_in_a_valid_looking_coverage_is_refused(name, position):
    """The coverage proof proves one-ring polygons valid only when their ring passes no
    node twice; an invalid one gets prepare's error, and make_valid repairs it as
    geo.smooth does."""
    polys = [shapely.box(10, 0, 11, 1), shapely.box(11, 0, 12, 1)]
    polys.insert(position, shapely.Polygon(INVALID[name]))
    with pytest.raises(CurveError, match=rf"polygons\[{position}\] is not valid"):
        geo.smooth_coverage(polys, iterations=2)
    res = geo.smooth_coverage(polys, iterations=2, make_valid=True, full_output=True)
    repaired = shapely.make_valid(polys[position], method="structure", keep_collapsed=False)
    assert res.geometry[position].area == pytest.approx(repaired.area, rel=1e-12, abs=1e-15)
    assert shapely.is_valid(res.geometry).all() and res.coverage_valid


def test_the_pinched_ring_passes_the_arc_proof_but_not_the_polygon_proof():
    pinch = shapely.Polygon(INVALID["pinch"])
    g = np.array([pinch, shapely.box(10, 0, 11, 1)], dtype=object)
    topo = geo_coverage.coverage_topology(g)
    uses = coverage_flat_uses(topo)
    shells = coverage_shells(topo)
    assert geo_coverage.certainly_valid(topo.arcs, topo.loops, uses, shells, topo.ring_sign, g)
    assert list(coverage_valid_by_proof(topo, uses, g)) == [False, True]


def test_polygons_with_holes_and_parts_are_proven_valid_without_geos(monkeypatch):
    # a donut, its island filling the hole, a MultiPolygon of two squares (one inside a
    # hole of the donut's neighbour), and a hole touching its shell at a node (the ring
    # passes the node twice: GEOS decides)
    donut = shapely.Polygon(
        [(0, 0), (10, 0), (10, 10), (0, 10)], [[(3, 3), (3, 7), (7, 7), (7, 3)]]
    )
    island = shapely.Polygon([(3, 3), (7, 3), (7, 7), (3, 7)])
    frame = shapely.Polygon(
        [(10, 0), (30, 0), (30, 10), (10, 10)], [[(12, 2), (12, 8), (18, 8), (18, 2)]]
    )
    multi = shapely.MultiPolygon([shapely.box(12, 2, 18, 8), shapely.box(40, 0, 42, 2)])
    touching = shapely.Polygon(
        [(50, 0), (60, 0), (60, 10), (50, 10), (50, 5)], [[(50, 5), (55, 3), (55, 7)]]
    )
    g = np.array([donut, island, frame, multi, touching], dtype=object)
    assert shapely.is_valid(g).all() and shapely.coverage_is_valid(g)
    topo = geo_coverage.coverage_topology(g)
    uses = coverage_flat_uses(topo)
    shells = coverage_shells(topo)
    assert geo_coverage.certainly_valid(topo.arcs, topo.loops, uses, shells, topo.ring_sign, g)
    assert list(coverage_valid_by_proof(topo, uses, g)) == [True, True, True, True, False]
    # smoothed: the output proof needs GEOS for the touching one only
    asked = []
    real = shapely.is_valid

    def counting(geoms, **kwargs):
        asked.append(len(np.atleast_1d(geoms)))
        return real(geoms, **kwargs)

    monkeypatch.setattr(shapely, "is_valid", counting)
    res = geo.smooth_coverage(g, iterations=2, full_output=True)
    monkeypatch.undo()
    assert res.coverage_valid and sum(asked) == 2  # the touching polygon, in and out
    assert all(shapely.is_valid(res.geometry))
    np.testing.assert_allclose(shapely.area(res.geometry), shapely.area(g), rtol=1e-12)


def test_coverage_passes_none_and_empty_through():
    polys = [shapely.box(0, 0, 1, 1), None, shapely.Polygon()]
    out = geo.smooth_coverage(polys)
    assert out[1] is None and out[2].is_empty
    assert out[0].area == pytest.approx(1.0)


def _gaps_and_overlaps(polys):
    """Holes of the union (gaps) and the area counted twice (overlaps)."""
    union = shapely.union_all(polys)
    holes = [shapely.Polygon(r) for p in getattr(union, "geoms", [union]) for r in p.interiors]
    overlap = float(shapely.area(polys).sum() - union.area)
    return np.array([h.area for h in holes]), overlap


def test_real_imperfect_coverage_makes_no_gap_or_overlap_larger():
    # Kentucky and West Virginia counties of 2010 (plotly-geo), in degrees: 41 slivers
    # between counties that are not edge-matched. Smoothing keeps every polygon valid and its
    # area exact, leaves the invalid edges as they are (reported), and the gaps and overlaps
    # of the output are no larger than the input's (measured: 41 gaps -> 17, total gap area
    # 2.5e-15 -> 1.1e-15 deg2, overlap ~0 before and after)
    df = geo.us_counties(year=2010, states=["21", "54"])
    polys = df.geometry.values
    assert not shapely.coverage_is_valid(polys)
    res = geo.smooth_coverage(df, iterations=2, full_output=True)
    out = res.geometry.geometry.values
    assert shapely.is_valid(out).all() and res.invalid_edges  # reported
    np.testing.assert_allclose(shapely.area(out), shapely.area(polys), rtol=1e-12)
    gaps0, over0 = _gaps_and_overlaps(polys)
    gaps1, over1 = _gaps_and_overlaps(out)
    assert len(gaps0) == 41 and len(gaps1) <= len(gaps0)
    assert gaps1.sum() <= gaps0.sum() * (1 + 1e-9) and gaps1.max() <= gaps0.max() * (1 + 1e-9)
    scale = 1e-12 * float(shapely.area(polys).sum())  # rounding of the area sums
    assert over1 <= max(over0, 0.0) + scale


@pytest.mark.parametrize("reduced", [[], [0], [3, 4], [0, 9], list(range(10))])
def test_patched_ragged_is_the_ragged_of_the_arcs(reduced):
    # the smoothed arcs' ragged copy from the full-strength one with the reduced arcs put
    # in (runs of unchanged arcs copied as blocks): the same arrays as concatenating all
    rng = np.random.default_rng(len(reduced))
    loops = np.array([k % 3 == 0 for k in range(10)])
    full = [rng.normal(size=(int(rng.integers(3, 9)), 2)) for _ in range(10)]
    xy, off = coverage_ragged(full, loops)
    rag = {"xy": xy, "off": off}
    # the full-strength arcs as smooth_arc_blocks hands them over: views of their rows
    ends = zip(off[:-1], off[1:], loops, strict=True)
    initial = [xy[a : b - 1] if lp else xy[a:b] for a, b, lp in ends]
    arcs = list(initial)
    for k in reduced:
        arcs[k] = rng.normal(size=(int(rng.integers(3, 12)), 2))
    arcs[5] = initial[5].copy()  # not the initial array: put in too (the same rows)
    got = coverage_patched(rag, arcs, initial, loops, set(reduced))
    want_xy, want_off = coverage_ragged(arcs, loops)
    np.testing.assert_array_equal(got["off"], want_off)
    np.testing.assert_array_equal(got["xy"], want_xy)
