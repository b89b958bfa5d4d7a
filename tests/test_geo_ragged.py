"""geo.smooth and geo.smooth_coverage on the ragged engine: one call for all features, fixed=."""

import numpy as np
import pytest

shapely = pytest.importorskip("shapely")

from curvesmith import geo  # noqa: E402
from curvesmith.errors import CurveError  # noqa: E402
from curvesmith.internals import geo_chunks, geo_engine, geo_smooth  # noqa: E402


def _footprints(n, seed):
    """Building-like polygons in metres: 5-12 vertices, jittered, some with a courtyard."""
    rng = np.random.default_rng(seed)
    out = []
    for k in range(n):
        m = int(rng.integers(5, 13))
        t = np.sort(rng.uniform(0, 2 * np.pi, m))
        r = rng.uniform(5, 30) * (1 + 0.25 * rng.uniform(size=m))
        cx, cy = rng.uniform(4e5, 6e5), rng.uniform(5.0e6, 5.2e6)  # UTM-like
        shell = np.c_[cx + r * np.cos(t), cy + r * np.sin(t)]
        poly = shapely.Polygon(shell if k % 3 else shell[::-1])
        if k % 7 == 0:  # a small courtyard, where it fits
            a = np.arange(4) * np.pi / 2
            hole = np.c_[cx + 1.5 * np.cos(a), cy + 1.5 * np.sin(a)][::-1]
            with_hole = shapely.Polygon(shell, [hole])
            poly = with_hole if with_hole.is_valid else poly
        if poly.is_valid:
            out.append(poly)
    return out


def test_one_call_equals_feature_by_feature():
    polys = _footprints(300, 1)
    polys.append(shapely.MultiPolygon([shapely.box(0, 0, 1, 1), shapely.box(3, 0, 4, 2)]))
    polys.append(None)
    polys.append(shapely.LineString([(0, 0), (1, 1), (2, 0), (3, 1)]))
    res = geo.smooth(np.array(polys, dtype=object), iterations=2, full_output=True)
    a0, a1 = shapely.area(polys[:-3]), shapely.area(res.geometry[:-3])
    # exact up to the rounding of coordinates ~5e6 m (ulp 1e-9 m) on rings of a few m^2
    assert np.max(np.abs(a1 - a0) / a0) < 1e-9
    assert len(res.reductions) >= 1  # a few slivers were re-smoothed locally
    for k, p in enumerate(polys):
        if p is None:
            assert res.geometry[k] is None
            continue
        alone = geo.smooth(p, iterations=2)
        np.testing.assert_array_equal(
            shapely.get_coordinates(res.geometry[k]), shapely.get_coordinates(alone)
        )
    assert shapely.is_valid(res.geometry[:-2]).all()


def test_chunks_give_the_same_bits(monkeypatch):
    """A layer goes through the engine in chunks of vertices: chunk size changes nothing."""
    polys = _footprints(300, 1)  # has slivers re-smoothed locally
    polys.insert(7, shapely.LineString([(0, 0), (1, 1), (2, 0), (3, 1)]))
    polys.insert(9, shapely.MultiLineString([[(0, 0), (1, 2), (2, 0)], [(5, 5), (6, 7), (7, 5)]]))
    arr = np.array(polys, dtype=object)
    whole = geo.smooth(arr, iterations=2, full_output=True)
    monkeypatch.setattr(geo_smooth, "CHUNK_VERTICES", 37)
    assert len(geo_chunks(shapely.get_num_coordinates(arr))) > 50
    parts = geo.smooth(arr, iterations=2, full_output=True)
    for a, b in zip(whole.geometry, parts.geometry, strict=True):
        np.testing.assert_array_equal(shapely.get_coordinates(a), shapely.get_coordinates(b))
        assert a.geom_type == b.geom_type
    assert whole.reductions == parts.reductions and len(whole.reductions) >= 1
    assert whole.n_curves == parts.n_curves
    assert whole.max_area_change == parts.max_area_change


def test_fixed_mask_keeps_antimeridian_vertices_and_areas():
    # lon/lat cells cut at the antimeridian: vertices on lon = 180 must stay there
    cells = [
        shapely.Polygon([(170, -5), (180, -6), (180, 4), (172, 6), (168, 0)]),
        shapely.Polygon([(175, 10), (180, 9), (180, 15), (176, 14.5)]),
        shapely.Polygon([(160, 20), (165, 21), (164, 25), (159, 24)]),  # no vertex on 180
    ]
    xy = shapely.get_coordinates(cells)
    mask = xy[:, 0] == 180.0
    out = geo.smooth(cells, iterations=3, fixed=mask)
    by_fn = geo.smooth(cells, iterations=3, fixed=lambda c: c[:, 0] == 180.0)
    for a, b in zip(out, by_fn, strict=True):
        np.testing.assert_array_equal(shapely.get_coordinates(a), shapely.get_coordinates(b))
    for before, after in zip(cells, out, strict=True):
        c0, c1 = shapely.get_coordinates(before), shapely.get_coordinates(after)
        on = c0[c0[:, 0] == 180.0]
        for p in on:  # every fixed vertex is still there, bit for bit
            assert (c1 == p).all(axis=1).any()
        assert len(c1) > 3 * len(c0)  # and the rest was smoothed
        assert abs(after.area - before.area) <= 1e-12 * before.area
        assert (c1[:, 0] <= 180.0).all()  # nothing crosses the antimeridian
    # the cell without fixed vertices is smoothed as without the option
    np.testing.assert_array_equal(
        shapely.get_coordinates(out[2]), shapely.get_coordinates(geo.smooth(cells[2], iterations=3))
    )


def test_fixed_keeps_sharp_corners():
    # an L-shaped footprint: keep its right-angle corners, smooth the rest
    p = shapely.Polygon([(0, 0), (10, 0), (10, 4), (4, 4), (4, 10), (0, 10)])
    p = shapely.segmentize(p, 2.0)
    xy = shapely.get_coordinates(p)
    corner = np.isin(xy[:, 0] + 1j * xy[:, 1], [0, 10, 10 + 4j, 4 + 4j, 4 + 10j, 10j])
    res = geo.smooth(p, iterations=2, fixed=corner, full_output=True)
    c1 = shapely.get_coordinates(res.geometry)
    for q in xy[corner]:
        assert (c1 == q).all(axis=1).any()
    assert res.max_area_change < 1e-13 and res.geometry.is_valid


def test_coverage_fixed_boundary_vertices():
    # a 4 x 4 grid of jittered cells; fix the vertices on the outer frame x = 0
    rng = np.random.default_rng(5)
    g = np.stack(np.meshgrid(np.arange(5.0), np.arange(5.0)), axis=-1)
    g[1:-1, 1:-1] += rng.uniform(-0.2, 0.2, size=(3, 3, 2))

    def edge(a, b):  # 4 points per shared edge, computed the same way from both sides
        (i, j), (k, m) = a, b
        flip = (i, j) > (k, m)
        (i, j), (k, m) = sorted([a, b])
        pts = g[i, j] + (g[k, m] - g[i, j]) * np.linspace(0, 1, 5)[:-1, None]
        pts = np.vstack([pts, g[k, m]])
        return (pts[::-1] if flip else pts)[:-1]

    cells = []
    for i in range(4):
        for j in range(4):
            ring = [(i, j), (i, j + 1), (i + 1, j + 1), (i + 1, j)]
            cells.append(
                shapely.Polygon(np.vstack([edge(ring[q], ring[(q + 1) % 4]) for q in range(4)]))
            )
    assert shapely.coverage_is_valid(cells)
    res = geo.smooth_coverage(cells, iterations=2, fixed=lambda c: c[:, 0] == 0.0, full_output=True)
    assert res.coverage_valid and res.max_area_change < 1e-12
    before = shapely.get_coordinates(cells)
    after = shapely.get_coordinates(res.geometry)
    on = np.unique(before[before[:, 0] == 0.0], axis=0)
    for q in on:
        assert (after == q).all(axis=1).any()
    assert np.all(after[:, 0] >= 0.0)  # the fixed frame edge stays straight, nothing outside
    free = geo.smooth_coverage(cells, iterations=2)
    assert shapely.get_coordinates(free)[:, 0].min() < 0.0  # without fixed= it bulges out


def test_fixed_bad_input():
    p = shapely.box(0, 0, 1, 1)
    with pytest.raises(CurveError, match=r"fixed must be a boolean mask .* \(shape \(5,\)\)"):
        geo.smooth(p, fixed=np.ones(3, dtype=bool))
    with pytest.raises(CurveError, match="fixed needs method='cca'"):
        geo.smooth(p, method="chaikin", fixed=np.ones(5, dtype=bool))
    with pytest.raises(CurveError, match=r"fixed callable must return a boolean mask of shape"):
        geo.smooth(p, fixed=lambda c: c[:, 0])


@pytest.mark.parametrize("closed", [True, False])
def test_batch_smoother_equals_one_call_per_piece(closed):
    """The resolution smooths the pieces of a round through the smoother's batch: the same
    curves, bit for bit, as one call per piece (levels with fewer iterations and a smaller
    alpha, fixed vertices, pieces of 2 to 60 vertices in metres at UTM offsets)."""
    Level, FixedVertices = geo_engine.Level, geo_smooth.FixedVertices
    make_smoother = geo_smooth.make_smoother

    rng = np.random.default_rng(11)
    pieces = []
    for _ in range(80):
        m = int(rng.integers(3 if closed else 2, 60))
        t = np.sort(rng.uniform(0, 2 * np.pi, m))
        r = rng.uniform(1, 40) * (1 + 0.2 * rng.uniform(size=m))
        xy = np.c_[r * np.cos(t), r * np.sin(t)] + rng.uniform([4e5, 5e6], [6e5, 5.2e6])
        pieces.append(xy if closed else xy[: max(2, m // 2)])
    every = np.concatenate(pieces)
    fixed_xy = every[rng.uniform(size=len(every)) < 0.05]
    for fixed in (None, FixedVertices(lambda q: np.isin(q[:, 0], fixed_xy[:, 0]), None)):
        f = make_smoother("cca", "regular", fixed)
        for level in (Level(2), Level(1), Level(1, 0.25)):
            many = f.batch(pieces, closed, level)
            assert len(many) == len(pieces)
            for p, got in zip(pieces, many, strict=True):
                np.testing.assert_array_equal(got, f(p, closed, level))


def test_assemble_polygons_is_from_ragged_array():
    """Polygons (with holes) and MultiPolygons from ragged rings: each of its own type, the
    coordinates of shapely's ragged layout bit for bit."""
    polygon_ragged, assemble_polygons = geo_smooth.polygon_ragged, geo_smooth.assemble_polygons

    polys = _footprints(60, 4)
    polys += [
        shapely.MultiPolygon([p, shapely.box(*(np.array(p.bounds) + 100))]) for p in polys[:9]
    ]
    g = np.array(polys, dtype=object)[np.random.default_rng(2).permutation(len(polys))]
    T = shapely.GeometryType
    for sub in (
        g,
        g[shapely.get_type_id(g) == T.POLYGON],
        g[shapely.get_num_interior_rings(g) == 0],
    ):
        was_polygon = shapely.get_type_id(sub) == T.POLYGON
        xy, ring_off, poly_off, geom_off = polygon_ragged(sub, was_polygon)
        _, xy2, offsets = shapely.to_ragged_array(sub)
        np.testing.assert_array_equal(xy, xy2)
        np.testing.assert_array_equal(ring_off, offsets[0])
        out = assemble_polygons(xy, ring_off, poly_off, geom_off, was_polygon)
        assert (shapely.get_type_id(out) == shapely.get_type_id(sub)).all()
        assert shapely.equals_identical(out, sub).all()


def test_single_ring_layer_takes_prepares_arrays_in_chunks_and_repeats_change_nothing(
    monkeypatch,
):
    """A layer of Polygons without holes reuses _prepare's coordinates and star centres
    (no second get_coordinates); chunks, a repeated vertex (the layer then takes the
    general path) and a None change no bit of any feature."""
    polys = [p for p in _footprints(400, 2) if not len(p.interiors)]
    arr = np.array(polys, dtype=object)
    general = geo_smooth.polygon_ragged

    def refuse(*args):
        raise AssertionError("the single-ring layer must not read its coordinates again")

    monkeypatch.setattr(geo_smooth, "polygon_ragged", refuse)
    whole = geo.smooth(arr, iterations=2, full_output=True)
    monkeypatch.setattr(geo_smooth, "CHUNK_VERTICES", 41)
    parts = geo.smooth(arr, iterations=2, full_output=True)
    monkeypatch.setattr(geo_smooth, "polygon_ragged", general)
    xy = shapely.get_coordinates(arr[5])
    rep = arr.copy()
    rep[5] = shapely.Polygon(np.insert(xy, 2, xy[2], axis=0))  # vertex 2 twice
    with_none = np.concatenate([rep[:9], [None], rep[9:]])
    other = geo.smooth(with_none, iterations=2, full_output=True)
    assert other.geometry[9] is None
    other_geoms = np.delete(np.asarray(other.geometry, dtype=object), 9)
    for res in (parts, other):
        assert res.n_curves == whole.n_curves
        assert res.max_area_change == whole.max_area_change
    assert parts.reductions == whole.reductions
    assert [(r.ring, r.start, r.stop, r.iterations) for r in other.reductions] == [
        (r.ring, r.start, r.stop, r.iterations) for r in whole.reductions
    ]
    for a, b, c in zip(whole.geometry, parts.geometry, other_geoms, strict=True):
        assert a.geom_type == b.geom_type == c.geom_type == "Polygon"
        np.testing.assert_array_equal(shapely.get_coordinates(a), shapely.get_coordinates(b))
        np.testing.assert_array_equal(shapely.get_coordinates(a), shapely.get_coordinates(c))


@pytest.mark.parametrize("seed", range(3))
def test_assemble_polygons_gives_back_every_geometry(seed):
    """Polygons (with and without holes) and MultiPolygons of 1-3 parts, mixed, and
    geometries without parts: assembled from their ragged rings, each comes back with
    its type and its coordinates, in order."""
    rng = np.random.default_rng(seed)
    fp = list(_footprints(60, seed))
    geoms = []
    for k in range(40):
        kind = rng.integers(0, 4)
        if kind == 0:
            geoms.append(fp[k])
        else:
            geoms.append(shapely.multipolygons(fp[k : k + int(kind)]))
    geoms = np.asarray(geoms, dtype=object)
    _, xy, (ring_off, poly_off, geom_off) = shapely.to_ragged_array(
        shapely.multipolygons(shapely.get_parts(geoms), indices=np.repeat(
            np.arange(len(geoms)), shapely.get_num_geometries(geoms)))
    )  # fmt: skip
    was_polygon = shapely.get_type_id(geoms) == shapely.GeometryType.POLYGON
    got = geo_smooth.assemble_polygons(xy, ring_off, poly_off, geom_off, was_polygon)
    assert list(shapely.get_type_id(got)) == list(shapely.get_type_id(geoms))
    assert all(shapely.to_wkb(got) == shapely.to_wkb(geoms))
    # a geometry without parts (between others) comes back empty, of its type
    geom_off2 = np.insert(geom_off, 3, geom_off[3])
    was2 = np.insert(was_polygon, 3, [False])
    got2 = geo_smooth.assemble_polygons(xy, ring_off, poly_off, geom_off2, was2)
    assert got2[3].is_empty and got2[3].geom_type == "MultiPolygon"
    assert all(shapely.to_wkb(np.delete(got2, 3)) == shapely.to_wkb(geoms))


def _close_reference(xy, off, closed):
    """The plain loop: every curve, and the first vertex again after a closed non-empty one."""
    rows, lens = [], []
    for k in range(len(off) - 1):
        cur = [xy[i] for i in range(off[k], off[k + 1])]
        if closed[k] and cur:
            cur.append(xy[off[k]])
        rows += cur
        lens.append(len(cur))
    out_off = np.concatenate([[0], np.cumsum(lens)]).astype(np.int64)
    return np.array(rows, dtype=float).reshape(-1, xy.shape[1]), out_off


@pytest.mark.parametrize("seed", range(8))
def test_close_ragged_equals_the_plain_loop(seed):
    """The compiled closing of ragged curves: empty curves, mixed flags, 2 and 3 columns."""
    from curvesmith.internals import close_ragged

    rng = np.random.default_rng(seed)
    n = int(rng.integers(1, 60))
    lens = rng.integers(0, 9, n)
    lens[rng.random(n) < 0.2] = 0  # empty curves stay empty, closed or not
    off = np.concatenate([[0], np.cumsum(lens)]).astype(np.int64)
    dim = 2 + seed % 2
    xy = rng.normal(scale=1e5, size=(int(off[-1]), dim)) + 6e6  # UTM-like metres
    closed = rng.random(n) < 0.6
    got, got_off = close_ragged(xy, off, closed)
    want, want_off = _close_reference(xy, off, closed)
    np.testing.assert_array_equal(got_off, want_off)
    np.testing.assert_array_equal(got, want)
    assert got.shape == (int(want_off[-1]), dim)


def test_engine_closed_lines_are_geos_is_closed():
    """The first round's closed flags, read from coordinates, are GEOS' is_closed."""
    from curvesmith.internals import engine_closed_lines, engine_lines

    rng = np.random.default_rng(3)
    curves = []
    for k in range(200):
        m = int(rng.integers(2, 12))
        c = rng.normal(size=(m, 2)).round(1)
        if k % 3 == 0:
            c = np.vstack([c, c[:1]])  # a loop closed by its first vertex
        if k % 7 == 0:
            c[-1] = c[0] + [0.0, 5e-324]  # off by the smallest step: not closed
        curves.append(c)
    curves.append(np.array([[1.0, 2.0], [1.0, 2.0]]))  # two equal points: closed for GEOS
    off = np.concatenate([[0], np.cumsum([len(c) for c in curves])]).astype(np.int64)
    rag = {"xy": np.concatenate(curves), "off": off}
    got = engine_closed_lines(rag)
    want = shapely.is_closed(engine_lines(rag))
    np.testing.assert_array_equal(got, want)
    assert 0 < got.sum() < len(curves)


def test_piece_table_renewal_keeps_old_rows_and_takes_new_ones():
    """A round's table: kept rows from the old one (by index), new pieces from themselves."""
    from curvesmith.internals import EnginePiece, EnginePieceTable

    old = [
        EnginePiece(0, 0, 9, False, 0),
        EnginePiece(1, 0, 5, True, 0),
        EnginePiece(2, 0, 30, False, 1),
    ]
    table = EnginePieceTable.of(old, np.array([False, True, False]))
    # piece 2 is cut in two, piece 0 goes one level down; piece 1 is kept
    new = [EnginePiece(0, 0, 9, False, 1), old[1], EnginePiece(2, 0, 15, False, 1, True),
           EnginePiece(2, 15, 30, False, 1, True)]  # fmt: skip
    src = np.array([-1, 1, -1, -1])
    changed = [0, 2, 3]
    renewed = table.renewed(src, changed, [new[k] for k in changed], np.array([False, False, True]))
    want = EnginePieceTable.of(new, np.array([False, True, False, True]))
    for a, b in zip(renewed._columns(), want._columns(), strict=True):
        np.testing.assert_array_equal(a, b)
        assert a.dtype == b.dtype


@pytest.mark.parametrize("courtyards", [False, True])
def test_output_proof_beside_geos_changes_nothing(monkeypatch, courtyards):
    # the output's proof and areas in a thread beside GEOS building the polygons, and the
    # input's proof beside the type checks: the same geometries, reductions and area
    # check as proving after the build and before the checks
    polys = _footprints(2500, 5)
    if not courtyards:
        polys = [shapely.Polygon(p.exterior) for p in polys]
    polys = np.array(polys, dtype=object)
    started = []
    real = geo_smooth.in_background

    def counting(fn, *args):
        started.append(fn)
        return real(fn, *args)

    monkeypatch.setattr(geo_smooth, "in_background", counting)
    runs = {}
    for beside in (False, True):
        monkeypatch.setattr(geo_smooth, "beside_worthwhile", lambda n, b=beside: b)
        res = geo.smooth(polys, iterations=2, full_output=True)
        runs[beside] = (shapely.to_wkb(res.geometry).tolist(), res.reductions, res.max_area_change)
    # one run in threads: the input's proof, then the output's proof and areas
    assert [fn.__name__ for fn in started] == ["rings_certainly_simple", "proof_and_areas"]
    assert runs[True] == runs[False]
    assert runs[True][1]  # some features were re-smoothed less (the check found them)
    assert runs[True][2] < 1e-9


def test_output_proof_beside_geos_only_when_worthwhile(monkeypatch):
    monkeypatch.setattr(geo_smooth, "BACKGROUND_MIN", 100)
    monkeypatch.setenv("OMP_NUM_THREADS", "1")
    assert not geo_smooth.beside_worthwhile(10**6)
    monkeypatch.setenv("OMP_NUM_THREADS", "2")
    assert not geo_smooth.beside_worthwhile(99)
