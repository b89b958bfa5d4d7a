"""The shift bound's measure: GEOS' discrete Hausdorff distance, decided by a compiled search.

``geo.smooth(max_shift=...)`` asks, per feature and per strength tried, whether
``shapely.hausdorff_distance(input, output) <= max_shift``. GEOS answers by comparing
every vertex with every segment (Natural Earth's Russia: seconds per call);
``geo._shift`` must give the same answers, feature by feature, for every kind of geometry.
"""

from __future__ import annotations

import numpy as np
import pytest
import shapely
from hypothesis import given, settings
from hypothesis import strategies as st

from curvesmith import geo
from curvesmith.internals import geo_shift


def _blob(rng, n, cx, cy, r):
    t = np.sort(rng.uniform(0, 2 * np.pi, n))
    rr = r * (1 + 0.3 * rng.uniform(-1, 1, n))
    return np.c_[cx + rr * np.cos(t), cy + rr * np.sin(t)]


def _features(rng, n):
    """Polygons with holes, multipolygons, lines, multi-lines, points, collections, empties."""
    out = []
    for _ in range(n):
        kind = rng.integers(0, 8)
        c = rng.uniform(-1e3, 1e3, 2)
        cx, cy = c
        if kind == 0:
            out.append(shapely.Polygon(_blob(rng, int(rng.integers(3, 60)), cx, cy, 50)))
        elif kind == 1:
            hole = _blob(rng, 8, cx, cy, 5)
            out.append(shapely.Polygon(_blob(rng, 40, cx, cy, 50), [hole]))
        elif kind == 2:
            out.append(shapely.MultiPolygon([
                shapely.Polygon(_blob(rng, 12, cx, cy, 20)),
                shapely.Polygon(_blob(rng, 30, cx + 100, cy, 20)),
            ]))  # fmt: skip
        elif kind == 3:
            out.append(
                shapely.LineString(np.cumsum(rng.normal(size=(int(rng.integers(2, 40)), 2)), 0))
            )
        elif kind == 4:
            out.append(shapely.MultiLineString([
                np.cumsum(rng.normal(size=(5, 2)), 0) + c,
                np.cumsum(rng.normal(size=(9, 2)), 0) + c + 3,
            ]))  # fmt: skip
        elif kind == 5:
            out.append(shapely.GeometryCollection([
                shapely.Point(cx, cy),
                shapely.LineString(np.cumsum(rng.normal(size=(6, 2)), 0) + c),
            ]))  # fmt: skip
        elif kind == 6:
            out.append(shapely.Point(cx, cy))
        else:
            out.append(shapely.Polygon(_blob(rng, 25, cx, cy, 10)))
    return np.array(out, dtype=object)


def _moved(rng, geoms):
    """Each feature moved by noise of its own scale, some with fewer or more vertices."""
    out = []
    for g in geoms:
        scale = 10 ** rng.uniform(-3, 1)
        k, ph = rng.uniform(0.05, 3, 2), rng.uniform(0, 2 * np.pi, 2)

        def field(xy, s=scale, k=k, ph=ph):  # a function of position: rings stay closed
            return xy + s * np.c_[np.sin(k[0] * xy[:, 1] + ph[0]), np.cos(k[1] * xy[:, 0] + ph[1])]

        g2 = shapely.transform(g, field)
        if rng.uniform() < 0.3 and shapely.get_type_id(g) in (1, 3):
            g2 = shapely.segmentize(g2, float(rng.uniform(0.5, 5)))
        out.append(g2)
    return np.array(out, dtype=object)


def test_decides_geos_hausdorff_for_every_kind_of_geometry():
    rng = np.random.default_rng(11)
    a = _features(rng, 400)
    b = _moved(rng, a)
    hd = shapely.hausdorff_distance(a, b)
    before, after = geo_shift.Linework(a), geo_shift.Linework(b)
    for d in np.quantile(hd, [0.05, 0.2, 0.5, 0.8, 0.95]):
        got = geo_shift.shifts_within(before, after, d)
        assert got.tolist() == (hd <= d).tolist()
    # per-feature distances just below and above each shift (the two measures round
    # differently at the shift itself), and NaN for "not asked"
    d = hd * rng.choice([1 - 1e-9, 1 + 1e-9, 0.5, 2.0], len(hd))
    d[::7] = np.nan
    want = hd <= d  # NaN compares False
    assert geo_shift.shifts_within(before, after, d).tolist() == want.tolist()


def test_a_vertex_may_be_near_any_ring_of_the_other_feature():
    """Per feature, not per ring: the grown hole's corners are near the input's shell."""
    shell = [(0, 0), (10, 0), (10, 10), (0, 10)]
    a = shapely.Polygon(shell, [[(4, 4), (6, 4), (6, 6), (4, 6)]])
    b = shapely.Polygon(shell, [[(1, 1), (9, 1), (9, 9), (1, 9)]])  # the hole grown
    hd = shapely.hausdorff_distance(a, b)
    assert hd == 3.0  # (4, 4) to the grown hole's edge; its corner (1, 1) is 1 from the shell
    la, lb = geo_shift.Linework([a]), geo_shift.Linework([b])
    assert geo_shift.shifts_within(la, lb, 3.0 + 1e-12).tolist() == [True]
    assert geo_shift.shifts_within(la, lb, 3.0 - 1e-12).tolist() == [False]
    # hole against hole alone: the corner (1, 1) is sqrt(18) from the input's hole
    ha, hb = geo_shift.Linework([a.interiors[0]]), geo_shift.Linework([b.interiors[0]])
    assert shapely.hausdorff_distance(a.interiors[0], b.interiors[0]) == pytest.approx(18**0.5)
    assert geo_shift.shifts_within(ha, hb, 4.2).tolist() == [False]
    assert geo_shift.shifts_within(ha, hb, 4.25).tolist() == [True]


def test_missing_and_empty_features():
    a = np.array([None, shapely.Polygon(), shapely.box(0, 0, 1, 1), shapely.box(0, 0, 1, 1)])
    b = np.array([None, shapely.Polygon(), shapely.Polygon(), shapely.box(0, 0, 1, 1.5)])
    got = geo_shift.shifts_within(geo_shift.Linework(a), geo_shift.Linework(b), 1.0)
    # nothing against nothing is within; a square against nothing is not
    assert got.tolist() == [True, True, False, True]


@settings(max_examples=60, deadline=None)
@given(
    st.integers(0, 2**32 - 1),
    st.floats(1e-6, 1e6),
)
def test_excess_powers_is_ceil_log2(seed, bound):
    rng = np.random.default_rng(seed)
    a = _features(rng, 20)
    b = _moved(rng, a)
    hd = shapely.hausdorff_distance(a, b)
    got = geo_shift.excess_powers(geo_shift.Linework(a), geo_shift.Linework(b), bound)
    with np.errstate(divide="ignore"):
        want = np.maximum(np.ceil(np.log2(hd / bound)), 0)
    # at an exact power of 2 the two roundings may differ by one
    exact = np.isclose(hd / bound, 2.0 ** np.round(np.log2(np.maximum(hd, 1e-300) / bound)))
    assert np.array_equal(got[~exact], want[~exact])
    assert np.all(np.abs(got - want)[exact] <= 1)
    # the definition itself: within at 2**m, not at 2**(m - 1)
    assert np.all(hd <= bound * 2.0**got)
    assert np.all((got == 0) | (hd > bound * 2.0 ** (got - 1)))


def test_max_shift_on_a_large_ring_is_bounded():
    """A 3,000-vertex coastline (GEOS' quadratic measure took 4 s over the strengths)."""
    rng = np.random.default_rng(4)
    n = 3_000
    t = np.linspace(0, 2 * np.pi, n, endpoint=False)
    r = 5e4 * (1 + 0.05 * np.sin(37 * t)) + rng.normal(0, 30, n)
    coast = shapely.Polygon(np.c_[r * np.cos(t), r * np.sin(t)] + [5e5, 6e6])
    res = geo.smooth([coast], iterations=3, max_shift=25.0, full_output=True)
    out = res.geometry[0]
    assert res.n_unchanged == 0 and out is not coast
    assert shapely.hausdorff_distance(coast, out) <= 25.0
    assert shapely.is_valid(out)
    assert out.area == pytest.approx(coast.area, rel=1e-12)
