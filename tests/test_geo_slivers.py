"""Slivers whose vertices floating point cannot separate: kept as they are, never an error.

``shapely.make_valid`` of a bow-tie with a 5e-324 coordinate leaves a triangle of area 2.5e-324;
CCA's steps see two of its vertices as one (their squared distance underflows) and refuse the
ring, and GEOS' remove_repeated_points drops the vertex and collapses the ring. Such curves pass
through unchanged, and every other curve of the layer is smoothed as it would be alone.
"""

from __future__ import annotations

import numpy as np
import pytest

shapely = pytest.importorskip("shapely", reason="curvesmith.geo needs the geo extra")

from curvesmith import geo  # noqa: E402
from curvesmith.internals import geo_engine, geo_smooth  # noqa: E402

SLIVER = shapely.Polygon([(4, -5e-324), (4, 0), (5, 0)])  # valid, area 2.5e-324
BOWTIE = shapely.from_wkt("POLYGON ((6 1, -4 0, 5 0, 4 -5e-324, 6 1))")


def _footprints(n, seed):
    rng = np.random.default_rng(seed)
    out = []
    for k in range(n):
        m = int(rng.integers(5, 12))
        t = np.sort(rng.uniform(0, 2 * np.pi, m))
        r = rng.uniform(5, 15) * (1 + 0.2 * rng.uniform(size=m))
        xy = np.c_[r * np.cos(t), r * np.sin(t)] + [4.5e5 + 40 * k, 5.2e6]
        out.append(shapely.Polygon(xy))
    return out


@pytest.mark.parametrize("method", ["cca", "chaikin"])
def test_a_sliver_passes_unchanged_and_the_others_are_smoothed_as_alone(method):
    polys = _footprints(6, 1)
    layer = np.array([*polys[:3], SLIVER, *polys[3:]], dtype=object)
    res = geo.smooth(layer, method=method, iterations=2, full_output=True)
    out = res.geometry
    assert shapely.equals_exact(out[3], SLIVER, tolerance=0.0)
    alone = geo.smooth(np.array(polys, dtype=object), method=method, iterations=2)
    for a, b in zip(np.r_[out[:3], out[4:]], alone, strict=True):
        np.testing.assert_array_equal(shapely.get_coordinates(a), shapely.get_coordinates(b))
    assert shapely.is_valid(out).all()
    if method == "cca":
        assert res.max_area_change < 1e-9  # round-off of areas at UTM coordinates


def test_make_valid_slivers_and_collapsing_repeats_stay_valid():
    res = geo.smooth(BOWTIE, make_valid=True, iterations=2, full_output=True)
    fixed = shapely.make_valid(BOWTIE, method="structure", keep_collapsed=False)
    assert shapely.is_valid(res.geometry)
    assert shapely.area(res.geometry) == pytest.approx(shapely.area(fixed), rel=1e-12)
    assert res.max_area_change < 1e-12
    # a valid triangle with a repeated vertex that GEOS' repeated-point removal collapses
    t = shapely.Polygon([(4, 0), (4, 0), (5, 0), (4, -5e-324)])
    assert shapely.is_valid(t) and not shapely.is_valid(shapely.remove_repeated_points(t, 0.0))
    out = geo.smooth(t, iterations=3)
    assert shapely.is_valid(out) and shapely.equals_exact(out, t, tolerance=0.0)


@pytest.mark.parametrize("close_rings", [False, True])
def test_smooth_batch_with_refused_curves_is_curve_by_curve(close_rings):
    """The engine's batch: refused curves as at iterations 0, the others bit for bit as alone,
    with anchors, open and closed curves mixed."""
    rng = np.random.default_rng(7)
    curves, closed = [], []
    for k in range(8):
        n = int(rng.integers(6, 15))
        p = rng.normal(size=(n, 2)).cumsum(axis=0) * 10
        if k in (2, 5):  # two vertices 5e-324 apart in a 3-vertex curve: refused
            p = np.array([[4.0, -5e-324], [4.0, 0.0], [5.0, 0.0]])
        curves.append(p)
        closed.append(k % 2 == 0)
    closed = np.array(closed)
    xy = np.concatenate(curves)
    off = np.r_[0, np.cumsum([len(c) for c in curves])]
    mask = np.zeros(len(xy), dtype=bool)
    mask[off[1] + 2] = True  # an anchor in curve 1
    level = geo_engine.Level(2)
    out, oo = geo_smooth.smooth_batch(
        "cca", "regular", xy, off, closed, level, mask, close_rings=close_rings
    )
    assert len(oo) == len(curves) + 1
    for k, c in enumerate(curves):
        m = mask[off[k] : off[k + 1]]
        lev = geo_engine.Level(0) if k == 2 else level  # the open one keeps 2 points: smoothed
        want, _ = geo_smooth.smooth_batch(
            "cca", "regular", c, np.array([0, len(c)]), closed[k:k + 1], lev, m,
            close_rings=close_rings,
        )  # fmt: skip
        np.testing.assert_array_equal(out[oo[k] : oo[k + 1]], want)


def _refusal_reference(coords, offsets, closed):
    """The refusal scan in plain numpy, row by row as written in _cca_refused's notes."""
    from curvesmith.internals import cca_input

    cand = []
    for k in range(len(offsets) - 1):
        p = coords[offsets[k] : offsets[k + 1]]
        short = len(p) < (4 if closed[k] else 2)
        gaps = len(p) > 1 and bool(cca_input.zero_gap(p[1:] - p[:-1]).any())
        ends = bool(
            closed[k]
            and len(p) > 1
            and cca_input.zero_gap((p[-1] - p[0])[None])[0]
            and np.any(p[-1] != p[0])
        )
        cand.append(short or gaps or ends)
    return np.array(cand, dtype=bool)


@pytest.mark.parametrize("seed", range(12))
def test_refusal_scan_kernel_matches_the_reference(seed):
    # repeated rows, gaps of 5e-324 and 1e-170 (squares underflow), 1e-150 (they do not),
    # ring ends almost equal or equal, NaN, empty and short curves, open and closed
    from curvesmith.internals import cca_kernel

    rng = np.random.default_rng(seed)
    pieces, closed = [], []
    for _ in range(60):
        n = int(rng.integers(0, 9))
        p = rng.uniform(-1, 1, (n, 2)) * 10.0 ** rng.integers(-160, 6)
        if n > 1 and rng.uniform() < 0.5:
            i = int(rng.integers(1, n))
            p[i] = p[i - 1] + rng.choice([0.0, 5e-324, 1e-170, 1e-150]) * rng.choice([1, -1])
        ring = bool(rng.uniform() < 0.6)
        if ring and n > 1:
            p[-1] = p[0] + rng.choice([0.0, 0.0, 5e-324, 1e-3]) * rng.integers(0, 2, 2)
        if n and rng.uniform() < 0.05:
            p[int(rng.integers(n))] = np.nan
        pieces.append(p)
        closed.append(ring)
    coords = np.concatenate(pieces) if pieces else np.empty((0, 2))
    offsets = np.concatenate([[0], np.cumsum([len(p) for p in pieces])]).astype(np.int64)
    closed = np.array(closed)
    got = cca_kernel.refusal_candidates(np.ascontiguousarray(coords), offsets, closed)
    want = _refusal_reference(coords, offsets, closed)
    assert got.tolist() == want.tolist()
    assert 0 < want.sum() < len(want)
