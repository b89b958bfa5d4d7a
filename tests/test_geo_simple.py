"""The compiled sufficient simplicity test of geo (_simple): it never clears a ring GEOS rejects.

``rings_certainly_simple`` lets ``geo.smooth`` skip GEOS ``is_valid`` on single-ring
polygons, on its input and its output. A false "simple" would let an invalid polygon
through, so every case compares with :func:`shapely.is_valid` (GEOS, exact predicates):
random rings (most self-intersecting), integer grids (touches, collinear overlaps,
vertical edges), star-shaped rings in UTM metres with a vertex moved onto another edge
or 1e-12 / 1e-9 off it, quadrilaterals with a vertex exactly on an edge or one ulp off,
bow-ties through a repeated vertex, NaN / inf / tiny / huge coordinates, Natural Earth
and smoothed footprints. It must also clear nearly every valid ring without a vertical
edge, or it saves nothing.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

shapely = pytest.importorskip("shapely")
pytest.importorskip("numba")

from curvesmith import geo  # noqa: E402
from curvesmith.internals import geo_simple, geo_smooth  # noqa: E402

rings_certainly_simple = geo_simple.rings_certainly_simple


def _check(rings):
    """(certified, GEOS-valid) per ring; fails on any ring certified but not valid."""
    polys = shapely.polygons(rings)
    xy, idx = shapely.get_coordinates(polys, return_index=True)
    off = np.concatenate([[0], np.cumsum(np.bincount(idx, minlength=len(polys)))])
    fast = rings_certainly_simple(xy, off, True)
    valid = shapely.is_valid(polys)
    wrong = np.flatnonzero(fast & ~valid)
    assert wrong.size == 0, [shapely.to_wkt(polys[k]) for k in wrong[:3]]
    return fast, valid


def test_random_rings_never_wrongly_cleared_and_valid_ones_cleared():
    rng = np.random.default_rng(0)
    rings = [shapely.linearrings(rng.uniform(0, 1, (int(rng.integers(3, 12)), 2))) for _ in range(5000)]  # fmt: skip
    fast, valid = _check(rings)
    assert 0.15 < valid.mean() < 0.35  # mostly self-intersecting
    assert np.array_equal(fast, valid)  # no vertical edges: every valid ring is proven


def test_integer_grid_rings():
    rng = np.random.default_rng(1)
    rings = [
        shapely.linearrings(rng.integers(0, 4, (int(rng.integers(3, 9)), 2)).astype(float))
        for _ in range(5000)
    ]
    fast, valid = _check(rings)
    assert fast.sum() > 300 and valid.sum() > fast.sum()  # vertical edges go to GEOS


def test_near_touching_star_rings_in_utm():
    rng = np.random.default_rng(2)
    rings = []
    for _ in range(5000):
        n = int(rng.integers(3, 40))
        th = np.sort(rng.uniform(0, 2 * np.pi, n))
        r = rng.uniform(0.1, 1, n)
        xy = np.c_[r * np.cos(th), r * np.sin(th)] + np.array([4e5, 5e6])
        if rng.uniform() < 0.7:  # a vertex onto (or next to) a non-adjacent edge
            i = int(rng.integers(0, n))
            j = (i + int(rng.integers(2, max(3, n - 1)))) % n
            t = rng.uniform()
            p = xy[j] * (1 - t) + xy[(j + 1) % n] * t
            xy[i] = p + rng.choice([0, 1e-12, -1e-12, 1e-9]) * rng.standard_normal(2)
        rings.append(shapely.linearrings(xy))
    fast, valid = _check(rings)
    assert fast.sum() >= 0.99 * valid.sum()


def test_vertex_on_edge_or_one_ulp_off():
    rng = np.random.default_rng(3)
    rings = []
    for _ in range(5000):
        a = rng.uniform(-1, 1, 2) * 10 ** rng.uniform(-3, 6)
        b = a + rng.uniform(-1, 1, 2) * 10 ** rng.uniform(-3, 3)
        t = rng.uniform()
        p = a * (1 - t) + b * t
        if rng.uniform() < 0.5:
            p = np.nextafter(p, p + rng.choice([-1, 1], 2) * np.inf)
        c = 0.5 * (a + b) + np.array([-(b - a)[1], (b - a)[0]]) * rng.uniform(0.1, 2)
        rings.append(shapely.linearrings(np.array([a, b, c, p])[rng.permutation(4)]))
    fast, valid = _check(rings)
    assert fast.sum() > 0.8 * valid.sum()


def test_degenerate_rings_are_left_to_geos():
    rings = [
        [(0, 0), (2, 2), (2, 0), (0, 2), (0, 0)],  # bow-tie
        [(0, 0), (2, 0), (1, 1), (2, 2), (0, 2), (1, 1), (0, 0)],  # touches itself at (1, 1)
        [(0, 0), (3, 0), (1, 0), (1, 1), (0, 0)],  # spike back along an edge
        [(0, 0), (1, 1), (2, 2), (0, 0)],  # collinear
        [(0, 0), (1, 0), (1, 0), (0, 1), (0, 0)],  # repeated vertex (valid, doubtful)
        [(0, 0), (np.nan, 0), (0, 1), (0, 0)],
        [(0, 0), (np.inf, 0), (0, 1), (0, 0)],
        [(0, 0), (1e-300, 0), (0, 1e-300), (0, 0)],  # products underflow
        [(0, 0), (1e300, 1), (1, 1e300), (0, 0)],  # products overflow
    ]
    xy = np.concatenate([np.array(r, dtype=float) for r in rings])
    off = np.concatenate([[0], np.cumsum([len(r) for r in rings])])
    assert not rings_certainly_simple(xy, off, True).any()
    finite = [shapely.Polygon(r) for r in rings[:5] + rings[7:]]
    assert not shapely.is_valid(finite[:4]).any()
    # not closed, or too short
    assert not rings_certainly_simple(np.array([[0.0, 0], [1, 0], [0, 1]]), np.array([0, 3]), True)[
        0
    ]
    tri = np.array([[0.0, 0], [1, 0], [0.5, 1]])
    assert rings_certainly_simple(tri, np.array([0, 3]), False)[0]
    assert not rings_certainly_simple(np.array([[0.0, 0], [1, 0]]), np.array([0, 2]), False)[0]


def test_real_layers():
    gpd = pytest.importorskip("geopandas")
    pyogrio = pytest.importorskip("pyogrio")
    ne = Path(pyogrio.__file__).parent / "tests" / "fixtures" / "naturalearth_lowres"
    df = gpd.read_file(ne / "naturalearth_lowres.shp")
    sys.path.insert(0, str(Path(__file__).parents[1] / "benchmarks"))
    from bench_many import footprints

    polys = footprints(3000, seed=3)
    for layer in (
        df.geometry.values,
        geo.smooth(df.geometry.values, iterations=2, make_valid=True),
        polys,
        geo.smooth(polys, iterations=2),
    ):
        rings = [r for p in layer for q in shapely.get_parts(p) for r in shapely.get_rings(q)]
        fast, valid = _check(rings)
        assert fast.sum() >= 0.85 * valid.sum()


# ----------------------------------------------------------------- nesting of disjoint rings


def _disjoint_rings(rng, n, scale, origin):
    """Up to n polygonal circles in metres whose rings do not meet (GEOS), nested or apart."""
    out = []
    for _ in range(40 * n):
        c = rng.uniform(0, scale, 2)
        r = rng.uniform(0.02, 0.4) * scale
        t = np.sort(rng.uniform(0, 2 * np.pi, rng.integers(5, 40)))
        ring = origin + c + r * np.c_[np.cos(t), np.sin(t)]
        if shapely.LinearRing(ring).is_simple and not any(
            shapely.intersects(shapely.LinearRing(ring), shapely.LinearRing(o)) for o in out
        ):
            out.append(ring)
        if len(out) == n:
            break
    return out


@pytest.mark.parametrize("seed", range(40))
def test_nesting_of_disjoint_rings_agrees_with_geos(seed):
    # random (Multi)Polygons made of disjoint rings given random roles (shell or hole,
    # of any part): holes outside their shell or inside another hole, shells inside
    # another part or inside its hole; proven exactly when GEOS calls them valid
    rng = np.random.default_rng(seed)
    feats, expected = [], []
    for _ in range(30):
        origin = np.array([rng.uniform(3e5, 7e5), rng.uniform(4e6, 5e6)])  # UTM metres
        rings = _disjoint_rings(rng, int(rng.integers(2, 7)), 1e4, origin)
        cuts = np.sort(
            rng.choice(np.arange(1, len(rings)), rng.integers(0, len(rings)), replace=False)
        )
        parts = [
            shapely.Polygon(rs[0], rs[1:])
            for rs in np.split(np.arange(len(rings)), cuts)
            if len(rs)
            for rs in [[rings[i] for i in rs]]
        ]
        g = parts[0] if len(parts) == 1 and rng.uniform() < 0.5 else shapely.MultiPolygon(parts)
        feats.append(g)
        expected.append(bool(shapely.is_valid(g)))
    feats = np.array(feats, dtype=object)
    was_polygon = shapely.get_type_id(feats) == shapely.GeometryType.POLYGON
    xy, ring_off, part_off, feat_off = geo_smooth.polygon_ragged(feats, was_polygon)
    got = geo_simple.nesting_certainly_valid(xy, ring_off, part_off, feat_off)
    assert got.tolist() == expected
    assert 0 < sum(expected) < len(expected)  # both kinds occur


def test_nesting_doubtful_signs_are_not_proven():
    # a hole's first vertex on a sloping edge of its shell (the rings meet: the caller's
    # rule broken; its side is not certain) or NaN
    shell = [(0, 0), (10, 0), (10, 10), (0, 10)]
    on_edge = shapely.Polygon(shell, [[(10, 5), (9, 6), (9, 4)]])
    fine = shapely.Polygon(shell, [[(5, 1), (6, 2), (4, 2)]])
    feats = np.array([on_edge, fine, fine], dtype=object)
    xy, ring_off, part_off, feat_off = geo_smooth.polygon_ragged(feats, np.ones(3, dtype=bool))
    xy[ring_off[3]] = xy[ring_off[4] - 1] = (np.nan, 5.0)  # the hole of the second one
    assert geo_simple.nesting_certainly_valid(xy, ring_off, part_off, feat_off).tolist() == [
        False,
        False,
        True,
    ]
    # above the budget of rings x vertices a feature is not tested (the third has 2 x 9)
    got = geo_simple.nesting_certainly_valid(xy, ring_off, part_off, feat_off, budget=17)
    assert got.tolist() == [False, False, False]
    got = geo_simple.nesting_certainly_valid(xy, ring_off, part_off, feat_off, budget=18)
    assert got.tolist() == [False, False, True]
