"""Clearance margin of the back-off: smoothed pieces that do not touch in the input keep a gap.

Backing off "to stay valid" used to stop at the first level at which two pieces no longer
met, which could leave them a rounding error apart (valid as written, invalid after an
ordinary reprojection). The engine now also treats two pieces that do not touch in the
input as conflicting when they come closer than
``min(MARGIN_EDGE * l, MARGIN_GAP * d)`` (``l`` the longer mean input edge length, ``d``
their input distance). These tests build near-touching rings and lines (the old code left
about a third of them closer than that margin, the closest at 0.5 % of the input gap) and
check every mode, then Natural Earth edge by edge.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

shapely = pytest.importorskip("shapely")
gpd = pytest.importorskip("geopandas")
pyogrio = pytest.importorskip("pyogrio")

from curvesmith import geo  # noqa: E402
from curvesmith.internals import clearance_kernel, geo_engine, geo_io  # noqa: E402

NE = Path(pyogrio.__file__).parent / "tests" / "fixtures" / "naturalearth_lowres"
NE = NE / "naturalearth_lowres.shp"


def _near_rings(rng):
    """A wavy star-shaped shell and a hole offset inwards by 1e-7..1e-2 (radially)."""
    n = int(rng.integers(30, 300))
    th = np.sort(rng.uniform(0, 2 * np.pi, n))
    r = 1 + 0.05 * rng.standard_normal(n)
    gap = 10 ** rng.uniform(-7, -2) * (1 + 2 * rng.uniform(size=n))
    shell = np.c_[r * np.cos(th), r * np.sin(th)]
    hole = np.c_[(r - gap) * np.cos(th), (r - gap) * np.sin(th)]
    return shell, hole


def _margin(a_in, b_in):
    """The smallest clearance the engine guarantees between two input lines/rings."""

    def min_edge(g):
        xy = shapely.get_coordinates(g)
        return float(np.min(np.linalg.norm(np.diff(xy, axis=0), axis=1)))

    d_in = float(shapely.distance(a_in, b_in))
    ell = max(min_edge(a_in), min_edge(b_in))  # a piece's mean edge is at least this
    return min(geo_engine.MARGIN_EDGE * ell, geo_engine.MARGIN_GAP * d_in), d_in


def _ring_area(g):
    return shapely.area(shapely.polygons(g))


def test_hole_near_shell_keeps_margin():
    rng = np.random.default_rng(5)
    reduced = 0
    for _ in range(40):
        shell, hole = _near_rings(rng)
        p = shapely.Polygon(shell, [hole])
        assert p.is_valid
        res = geo.smooth(p, iterations=int(rng.integers(1, 4)), full_output=True)
        out = res.geometry
        assert out.is_valid
        reduced += bool(res.reductions)
        (a, b), (ai, bi) = shapely.get_rings(out), shapely.get_rings(p)
        margin, d_in = _margin(ai, bi)
        assert float(shapely.distance(a, b)) >= margin, (d_in, float(shapely.distance(a, b)))
        np.testing.assert_allclose(_ring_area(a), _ring_area(ai), rtol=1e-12)
        np.testing.assert_allclose(_ring_area(b), _ring_area(bi), rtol=1e-12)
    assert reduced >= 30  # the hole does run into the shell: the back-off is exercised


def test_two_parts_near_each_other_keep_margin():
    rng = np.random.default_rng(8)
    for _ in range(20):
        shell, hole = _near_rings(rng)
        # the annulus cut in two along the x axis: two parts, near each other along the cut
        ring = shapely.Polygon(shell, [hole])
        top = shapely.intersection(ring, shapely.box(-2, 1e-3, 2, 2))
        bot = shapely.intersection(ring, shapely.box(-2, -2, 2, -1e-3))
        parts = [g for g in (top, bot) if g.geom_type == "Polygon"]
        if len(parts) < 2:
            continue
        mp = shapely.MultiPolygon(parts)
        assert mp.is_valid
        out = geo.smooth(mp, iterations=2)
        assert out.is_valid
        margin, _ = _margin(parts[0].exterior, parts[1].exterior)
        assert float(shapely.distance(out.geoms[0], out.geoms[1])) >= margin


def test_coverage_island_near_boundary_keeps_margin():
    rng = np.random.default_rng(11)
    for _ in range(15):
        shell, hole = _near_rings(rng)
        cov = np.array([shapely.Polygon(shell, [hole]), shapely.Polygon(hole)])
        assert shapely.coverage_is_valid(cov)
        res = geo.smooth_coverage(cov, iterations=2, full_output=True)
        assert res.coverage_valid
        a, b = shapely.get_rings(res.geometry[0])
        margin, _ = _margin(shapely.LinearRing(shell), shapely.LinearRing(hole))
        assert float(shapely.distance(a, b)) >= margin
        # the annulus is the difference of two rings of area ~3: round-off of those
        np.testing.assert_allclose(
            shapely.area(res.geometry), shapely.area(cov), rtol=1e-12, atol=1e-14
        )


def test_network_near_parallel_lines_keep_margin():
    rng = np.random.default_rng(3)
    for _ in range(15):
        n = int(rng.integers(40, 200))
        x = np.sort(rng.uniform(0, 10, n))
        y = np.cumsum(0.05 * rng.standard_normal(n))
        gap = 10 ** rng.uniform(-7, -2) * (1 + rng.uniform(size=n))
        a_in = shapely.LineString(np.c_[x, y])
        b_in = shapely.LineString(np.c_[x, y + gap])
        assert not a_in.intersects(b_in)
        a, b = geo.smooth_network([a_in, b_in], iterations=2)
        assert not a.intersects(b)
        margin, _ = _margin(a_in, b_in)
        assert float(shapely.distance(a, b)) >= margin


def _edge_clearance_violations(g_in, g_out, margin_edge, margin_gap):
    """Pairs of output edges that do not touch in the input and are closer than the margin.

    Every output edge is mapped to the input edges it runs along (its end points projected
    on the input ring, the arc between them): two output edges touch in the input when
    those input pieces meet (distance 0, e.g. the two edges beside a cut corner). For the
    others the margin is ``min(margin_edge * l, margin_gap * d)``, ``l`` the longer input
    edge and ``d`` the input distance of the two pieces.
    """
    rings_in, rings_out = [], []
    for p_in, p_out in zip(shapely.get_parts(g_in), shapely.get_parts(g_out), strict=True):
        rings_in += list(shapely.get_rings(p_in))
        rings_out += list(shapely.get_rings(p_out))
    assert len(rings_in) == len(rings_out)
    segs, sup, sup_len = [], [], []
    hmax = 0.0
    for ring, new in zip(rings_in, rings_out, strict=True):
        xin, xo = shapely.get_coordinates(ring), shapely.get_coordinates(new)
        n = len(xin) - 1
        edge = np.linalg.norm(np.diff(xin, axis=0), axis=1)
        cum = np.concatenate([[0.0], np.cumsum(edge)])
        total = cum[-1]
        s = shapely.line_locate_point(ring, shapely.points(xo))
        hmax = max(hmax, float(shapely.hausdorff_distance(ring, new)))
        s0, s1 = s[:-1], s[1:]
        wrap = np.abs(s1 - s0) > total / 2
        lo = np.where(wrap, np.maximum(s0, s1), np.minimum(s0, s1))
        hi = np.where(wrap, np.minimum(s0, s1) + total, np.maximum(s0, s1))
        e_lo = np.maximum(np.searchsorted(cum, lo, side="left") - 1, 0)
        cum2 = np.concatenate([cum[:-1], cum[:-1] + total, [2 * total]])
        e_hi = np.searchsorted(cum2, hi, side="right") - 1
        for i in range(len(s0)):
            idx = np.arange(e_lo[i], e_hi[i] + 2) % n
            sup.append(shapely.linestrings(xin[idx]))
            sup_len.append(edge[idx[:-1]].max())
        segs.append(shapely.linestrings(np.stack([xo[:-1], xo[1:]], axis=1)))
    segs = np.concatenate(segs)
    sup = np.array(sup, dtype=object)
    sup_len = np.array(sup_len)
    # a pair closer than margin_gap * d moved by more than (1 - margin_gap) * d in all
    radius = 2 * hmax * margin_gap / (1 - margin_gap)
    i, j = shapely.STRtree(segs).query(segs, predicate="dwithin", distance=radius)
    i, j = i[i < j], j[i < j]
    d_in = shapely.distance(sup[i], sup[j])
    d_out = shapely.distance(segs[i], segs[j])
    margin = np.minimum(margin_edge * np.maximum(sup_len[i], sup_len[j]), margin_gap * d_in)
    return int(np.count_nonzero((d_in > 0) & (d_out < margin))), len(i)


@pytest.mark.slow
def test_natural_earth_keeps_clearance_and_stays_valid_in_web_mercator():
    df = gpd.read_file(NE)
    valid_in = df.is_valid.values
    res = geo.smooth(
        df, iterations=2, make_valid=True, full_output=True, fixed=geo_io.domain_fixed(df.crs)
    )
    out = res.geometry
    assert out.is_valid.all()
    assert res.max_area_change < 1e-9  # tiny islands in degrees: ulps of the coordinates
    # valid in Web Mercator wherever the input is (input: one country, Sudan, is not)
    ok_3857_in = df.to_crs(3857).is_valid.values
    ok_3857_out = out.to_crs(3857).is_valid.values
    assert ok_3857_in.sum() == len(df) - 1
    assert ok_3857_out[ok_3857_in].all()
    checked = 0
    for k in np.flatnonzero(valid_in):
        bad, n_pairs = _edge_clearance_violations(
            df.geometry.values[k],
            out.geometry.values[k],
            geo_engine.MARGIN_EDGE,
            geo_engine.MARGIN_GAP,
        )
        assert bad == 0, df.name[k]
        checked += n_pairs
    assert checked > 10_000


def _within_reference(a, b, r):
    """Plain reference of the screening: some segment pair crosses or is within r.

    Written from the definition (orientations for the crossing, point-to-segment distances
    of the four end points), one pair of segments at a time, without boxes or sorting.
    """

    def orient(p, q, s):
        return (q[0] - p[0]) * (s[1] - p[1]) - (q[1] - p[1]) * (s[0] - p[0])

    def dist2(p, s0, s1):
        d = s1 - s0
        ll = float(d @ d)
        t = 0.0 if ll == 0 else min(1.0, max(0.0, float((p - s0) @ d) / ll))
        e = s0 + t * d - p
        return float(e @ e)

    for i in range(len(a) - 1):
        for j in range(len(b) - 1):
            p0, p1, q0, q1 = a[i], a[i + 1], b[j], b[j + 1]
            if orient(p0, p1, q0) * orient(p0, p1, q1) <= 0 and (
                orient(q0, q1, p0) * orient(q0, q1, p1) <= 0
            ):
                return True
            if (
                min(dist2(p0, q0, q1), dist2(p1, q0, q1), dist2(q0, p0, p1), dist2(q1, p0, p1))
                < r * r
            ):
                return True
    return False


def test_clearance_screening_equals_the_plain_reference():
    """The sorted search of geo._clearance_kernel gives the plain pairwise answer, pair by pair.

    Random walks, noisy nested loops and integer grids (collinear overlaps, shared vertices,
    zero-length segments) at distances from 1e-9 to 1.
    """

    rng = np.random.default_rng(11)
    checked = close = 0
    for _ in range(60):
        polys = []
        for _ in range(int(rng.integers(2, 7))):
            m = int(rng.integers(2, 40))
            kind = rng.integers(3)
            if kind == 0:
                p = np.cumsum(rng.normal(0, 1, (m, 2)), axis=0)
            elif kind == 1:
                t = np.linspace(0, 2 * np.pi, m)
                p = rng.uniform(1, 3) * np.c_[np.cos(t), np.sin(t)] + rng.normal(0, 0.05, (m, 2))
            else:
                p = rng.integers(-3, 4, (m, 2)).astype(float)
            polys.append(p)
        X = np.concatenate(polys)
        off = np.r_[0, np.cumsum([len(p) for p in polys])].astype(np.int64)
        pa = rng.integers(0, len(polys), 12)
        pb = rng.integers(0, len(polys), 12)
        d = 10.0 ** rng.uniform(-9, 0, 12)
        got = clearance_kernel.polylines_within(X, off, pa, pb, d)
        want = [_within_reference(polys[i], polys[j], r) for i, j, r in zip(pa, pb, d, strict=True)]
        assert got.tolist() == want
        checked += len(want)
        close += sum(want)
    assert 0.2 * checked < close < 0.9 * checked  # both answers are exercised


def test_nested_contour_loops_are_screened_right():
    """40 nested wavy loops of 20,000 vertices, neighbours 1/40 apart, screened at 1e-4 and 0.03."""

    t = np.linspace(0, 2 * np.pi, 20_000)
    polys = [
        np.c_[R * np.cos(t), R * np.sin(t) * (1 + 0.3 * np.sin(5 * t))]
        for R in np.linspace(1, 2, 40)
    ]
    X = np.concatenate(polys)
    off = np.arange(41, dtype=np.int64) * 20_000
    pa = np.arange(39)
    assert not clearance_kernel.polylines_within(X, off, pa, pa + 1, np.full(39, 1e-4)).any()
    assert clearance_kernel.polylines_within(X, off, pa, pa + 1, np.full(39, 0.03)).all()
