"""The star-shaped fast path of geo's simplicity proof (simple_kernel._star_simple) against GEOS.

A ring is cleared when every edge turns one strict way about a centre (the area centroid
or the vertex mean) and the direction from the centre passes the +x ray exactly once. A
false "simple" would let an invalid polygon through ``geo.smooth``, so every case is
compared with :func:`shapely.is_valid` (GEOS): wild star rings, rings winding two or three
times about a point, a vertex moved onto another edge (on it, 1e-12 / 1e-9 / one ulp off,
or onto a vertex), point-symmetric integer rings whose centroid is exactly 0 (vertices on
the +x ray, edges through the centre, a vertex at the centre, ulp moves), an edge put
onto a ray from the centre (orientation zero or a few ulps, sometimes a step back),
all of them smoothed by CCA too, and scaled to huge and tiny coordinates. The star
test alone and the whole proof must both have 0 false clearances, and the star test
must clear most smoothed footprints (it is what makes the proof cheap).
"""

from __future__ import annotations

import itertools
import sys
from pathlib import Path

import numpy as np
import pytest

shapely = pytest.importorskip("shapely")
pytest.importorskip("numba")

from curvesmith import cca  # noqa: E402
from curvesmith.internals import geo_simple, simple_kernel  # noqa: E402

rings_certainly_simple = geo_simple.rings_certainly_simple


def _ring(xy):
    return np.vstack([xy, xy[:1]])


def _star_rings(rng, n_rings, center=(4e5, 5e6), scale=1.0):
    """Star-shaped-ish rings: sorted angles, random radii (some wild), around a centre."""
    out = []
    for _ in range(n_rings):
        n = int(rng.integers(3, 60))
        th = np.sort(rng.uniform(0, 2 * np.pi, n))
        r = rng.uniform(0.05, 1, n) ** rng.choice([0.2, 1, 3])
        xy = np.c_[r * np.cos(th), r * np.sin(th)] * scale + np.asarray(center)
        out.append(_ring(xy))
    return out


def _winding_rings(rng, n_rings, scale=1.0):
    """Rings that turn monotonically around a point two or three times (never simple)."""
    out = []
    for _ in range(n_rings):
        turns = int(rng.integers(2, 4))
        n = int(rng.integers(5, 40))
        th = np.sort(rng.uniform(0, 2 * np.pi * turns, n))
        # no angular gap of pi or more (else the turn is not monotone)
        th = np.linspace(0, 2 * np.pi * turns, n, endpoint=False) + rng.uniform(0, 0.3, n)
        r = rng.uniform(0.5, 1, n) * (1 + 0.5 * np.sin(th / turns * rng.uniform(0.5, 2)))
        xy = np.c_[r * np.cos(th), r * np.sin(th)] * scale + rng.uniform(-1e3, 1e3, 2) * scale
        out.append(_ring(xy))
    return out


def _near_touch_rings(rng, n_rings, center=(4e5, 5e6)):
    """Star rings with a vertex moved onto a non-adjacent edge, or 1e-12 / 1e-9 / one ulp off."""
    out = []
    for _ in range(n_rings):
        n = int(rng.integers(4, 40))
        th = np.sort(rng.uniform(0, 2 * np.pi, n))
        r = rng.uniform(0.3, 1, n)
        xy = np.c_[r * np.cos(th), r * np.sin(th)] + np.asarray(center)
        i = int(rng.integers(0, n))
        j = (i + int(rng.integers(2, n - 1))) % n if n > 3 else (i + 2) % n
        t = rng.uniform()
        p = xy[j] * (1 - t) + xy[(j + 1) % n] * t
        mode = rng.integers(0, 4)
        if mode == 1:
            p = p + rng.choice([1e-12, 1e-9]) * rng.standard_normal(2)
        elif mode == 2:
            p = np.nextafter(p, p + rng.choice([-1, 1], 2) * np.inf)
        elif mode == 3:  # onto the neighbour's vertex: a pinch
            p = xy[j].copy()
        xy[i] = p
        out.append(_ring(xy))
    return out


def _through_centre_rings(rng, n_rings):
    """Integer rings symmetric about the origin (the centroid is exactly 0): vertices on the
    +x ray, edges through the centroid or an ulp off, pinches at the centroid."""
    out = []
    for _ in range(n_rings):
        k = int(rng.integers(2, 7))
        half = rng.integers(-8, 9, (k, 2)).astype(float)
        half = half[np.argsort(np.arctan2(half[:, 1], half[:, 0]))]
        pts = np.vstack([half, -half])  # point-symmetric: centroid (0, 0) exactly
        if rng.uniform() < 0.3:
            pts[int(rng.integers(0, len(pts)))] = [rng.integers(1, 9), 0.0]  # on the +x ray
        if rng.uniform() < 0.2:
            pts[int(rng.integers(0, len(pts)))] = [0.0, 0.0]
        if rng.uniform() < 0.3:
            m = int(rng.integers(0, len(pts)))
            pts[m] = np.nextafter(pts[m], pts[m] + rng.choice([-1, 1], 2) * np.inf)
        pts = pts[rng.permutation(len(pts))] if rng.uniform() < 0.2 else pts
        out.append(_ring(pts))
    return out


def _scaled(rings, factor):
    return [r * factor for r in rings]


def _ragged(rings):
    xy = np.concatenate(rings)
    off = np.zeros(len(rings) + 1, dtype=np.int64)
    np.cumsum([len(r) for r in rings], out=off[1:])
    return xy, off


def _geos_valid(rings):
    with np.errstate(all="ignore"):
        polys = shapely.polygons([shapely.linearrings(r) for r in rings])
    return shapely.is_valid(polys)


def _centroid(xy):
    """The star proof's centre, with the kernel's arithmetic (first vertex frame)."""
    o = xy[0]
    p = xy[-1] - o
    acc = sx = sy = 0.0
    for q in xy - o:
        cr = p[0] * q[1] - q[0] * p[1]
        acc += cr
        sx += (p[0] + q[0]) * cr
        sy += (p[1] + q[1]) * cr
        p = q
    return np.array([o[0] + sx / (3 * acc), o[1] + sy / (3 * acc)])


def _radial_rings(rng, n_rings, center=(4e5, 5e6)):
    """Star rings with an edge put onto (or an ulp beside) a ray from the centroid: the
    orientation about the centre is zero or a few ulps; sometimes the edge steps back."""
    out = []
    for _ in range(n_rings):
        n = int(rng.integers(4, 30))
        th = np.sort(rng.uniform(0, 2 * np.pi, n))
        r = rng.uniform(0.3, 1, n)
        xy = np.c_[r * np.cos(th), r * np.sin(th)] + np.asarray(center)
        i = int(rng.integers(0, n))
        j = (i + 1) % n
        for _ in range(2):
            c = _centroid(xy)
            xy[j] = c + (xy[i] - c) * rng.uniform(0.5, 1.5)
        if rng.uniform() < 0.5:
            xy[j] = np.nextafter(xy[j], xy[j] + rng.choice([-1, 1], 2) * np.inf)
        if rng.uniform() < 0.3:  # a step backwards past the ray
            xy[j] = xy[j] + (xy[j] - xy[(j + 1) % n]) * 1e-9
        out.append(_ring(xy))
    return out


def _smoothed(rings):
    """CCA (2 iterations) of the rings CCA accepts (3 distinct points, no repeated vertex)."""
    ok = [
        r
        for r in rings
        if np.all(np.any(r[1:] != r[:-1], axis=1)) and len(np.unique(r, axis=0)) >= 3
    ]
    xy, off = _ragged(ok)
    with np.errstate(all="ignore"):
        s_xy, s_off = cca.smooth_ragged(xy, off, closed=True, iterations=2, close_rings=True)
    return [s_xy[a:b] for a, b in itertools.pairwise(s_off)]


def _check(rings):
    """(star-cleared, proof-cleared, GEOS-valid); fails on any clearance GEOS rejects."""
    xy, off = _ragged(rings)
    star = simple_kernel.rings_star(np.ascontiguousarray(xy), off, True)
    full = rings_certainly_simple(xy, off, True)
    valid = _geos_valid(rings)
    for name, got in (("star", star), ("proof", full)):
        wrong = np.flatnonzero(got & ~valid)
        assert wrong.size == 0, (name, [rings[k].tolist() for k in wrong[:2]])
    assert np.all(full[star])  # the proof takes every star clearance
    return star, full, valid


def _generated(seed):
    rng = np.random.default_rng(seed)
    sets = {
        "star": _star_rings(rng, 2000),
        "winding": _winding_rings(rng, 1000),
        "near_touch": _near_touch_rings(rng, 2000),
        "centre": _through_centre_rings(rng, 2000),
        "radial": _radial_rings(rng, 2000),
    }
    for name in ("star", "near_touch", "centre", "radial"):
        sets[name + " smoothed"] = _smoothed(sets[name])
    for name in ("star", "centre"):
        for label, f in (
            ("1e140", 1e140), ("2**400", 2.0**400), ("2**490", 2.0**490), ("1e200", 1e200),
            ("1e-140", 1e-140), ("2**-480", 2.0**-480),
        ):  # fmt: skip
            sets[f"{name} x {label}"] = _scaled(sets[name][:500], f)
    return sets


@pytest.mark.parametrize("seed", [0, 1])
def test_star_proof_never_clears_a_ring_geos_rejects(seed):
    counts = {name: _check(rings) for name, rings in _generated(seed).items()}
    star = {name: int(c[0].sum()) for name, c in counts.items()}
    valid = {name: int(c[2].sum()) for name, c in counts.items()}
    # rings that wind two or three times about a point (a few, with steps of pi or more
    # about it, are simple after all)
    assert valid["winding"] <= 5 and star["winding"] <= valid["winding"]
    # the star path is exercised on every family that has star-shaped members
    for name in ("star", "centre", "radial", "star smoothed", "centre smoothed"):
        assert star[name] > 0.15 * valid[name], name
    assert star["centre x 2**490"] > 0.5 * valid["centre x 2**490"]  # 2**490
    assert star["star x 1e140"] > 0  # the vertex mean when the centroid overflows


def test_star_proof_clears_most_footprints_and_real_layers():
    gpd = pytest.importorskip("geopandas")
    pyogrio = pytest.importorskip("pyogrio")
    from curvesmith import geo

    sys.path.insert(0, str(Path(__file__).parents[1] / "benchmarks"))
    from bench_many import footprints

    polys = footprints(3000, seed=5)
    rings = [shapely.get_coordinates(p) for p in polys]
    star, full, valid = _check(rings)
    assert valid.all() and full.all() and star.mean() > 0.9
    star, full, valid = _check(_smoothed(rings))
    assert star.mean() > 0.85 and full.sum() >= 0.99 * valid.sum()
    ne = Path(pyogrio.__file__).parent / "tests" / "fixtures" / "naturalearth_lowres"
    df = gpd.read_file(ne / "naturalearth_lowres.shp")
    for layer in (
        df.geometry.values,
        geo.smooth(df.geometry.values, iterations=2, make_valid=True),
    ):
        rings = [
            shapely.get_coordinates(r)
            for p in layer
            for q in shapely.get_parts(p)
            for r in shapely.get_rings(q)
        ]
        star, full, valid = _check(rings)
        assert star.sum() > 0.1 * valid.sum()


def test_star_proof_degenerate_cases():
    sq = np.array([[-1.0, -1], [1, -1], [1, 1], [-1, 1], [-1, -1]])
    cases = {
        "square": (sq, True),
        "square with a vertex on the +x ray": (
            np.array([[-1.0, -1], [1, -1], [1, 0], [1, 1], [-1, 1], [-1, -1]]),
            True,
        ),
        "square reversed": (sq[::-1].copy(), True),
        "pinched at the centre": (
            np.array([[0.0, 0], [2, -1], [2, 1], [0, 0], [-2, 1], [-2, -1], [0, 0]]),
            False,
        ),
        "bow-tie": (np.array([[0.0, 0], [2, 2], [2, 0], [0, 2], [0, 0]]), False),
        "twice around": (
            np.array(
                [[np.cos(t), np.sin(t)] for t in np.linspace(0, 4 * np.pi, 13)[:-1]] + [[1.0, 0.0]]
            ),
            False,
        ),
        "repeated vertex": (np.array([[0.0, 0], [1, 0], [1, 0], [0, 1], [0, 0]]), False),
        "collinear": (np.array([[0.0, 0], [1, 1], [2, 2], [0, 0]]), False),
        "not closed": (np.array([[0.0, 0], [1, 0], [0, 1], [0, 0.5]]), False),
        "nan": (np.array([[0.0, 0], [np.nan, 0], [0, 1], [0, 0]]), False),
        "inf": (np.array([[0.0, 0], [np.inf, 0], [0, 1], [0, 0]]), False),
        "underflow": (np.array([[0.0, 0], [1e-300, 0], [0, 1e-300], [0, 0]]), False),
        "overflow": (np.array([[0.0, 0], [1e300, 1], [1, 1e300], [0, 0]]), False),
    }
    for name, (ring, expected) in cases.items():
        xy, off = _ragged([ring])
        got = bool(simple_kernel.rings_star(np.ascontiguousarray(xy), off, True)[0])
        assert got is expected, name


def test_given_centres_never_clear_a_ring_geos_rejects_and_are_written_back():
    """The hint of ``rings_certainly_simple(..., centres)`` can be any point (a smoothed
    ring's input centre, a vertex, a point on an edge, far away, NaN, inf, huge)."""
    rng = np.random.default_rng(7)
    rings = (
        _star_rings(rng, 1500)
        + _near_touch_rings(rng, 1500)
        + _radial_rings(rng, 1500)
        + _through_centre_rings(rng, 1500)
        + _winding_rings(rng, 500)
    )
    rings = rings + _smoothed(rings[:3000])
    xy, off = _ragged(rings)
    valid = _geos_valid(rings)
    own = np.full((len(rings), 2), np.nan)
    cleared = rings_certainly_simple(xy, off, True, own)
    assert not np.any(cleared & ~valid)
    star = simple_kernel.rings_star(np.ascontiguousarray(xy), off, True)
    assert np.array_equal(np.isfinite(own).all(axis=1), star)  # written back for star proofs
    assert np.isnan(own[~star]).all()
    hints = {
        "own": own,
        "vertex": np.array([r[int(rng.integers(0, len(r) - 1))] for r in rings]),
        "on an edge": np.array([0.5 * (r[0] + r[1]) for r in rings]),
        "random near": np.array([r.mean(axis=0) + rng.normal(0, 0.3, 2) for r in rings]),
        "far": np.array([r[0] + 1e6 for r in rings]),
        "huge": np.full((len(rings), 2), 1e300),
        "inf": np.full((len(rings), 2), np.inf),
    }
    for name, h in hints.items():
        h = np.ascontiguousarray(h, dtype=float)
        got = rings_certainly_simple(xy, off, True, h.copy())
        assert not np.any(got & ~valid), name
        assert np.all(got[cleared]), name  # a hint never loses a proof
    # a hint about which the ring is star-shaped proves it in the one pass
    again = own.copy()
    assert np.array_equal(rings_certainly_simple(xy, off, True, again), cleared)
    with pytest.raises(ValueError, match="centres"):
        rings_certainly_simple(xy, off, True, np.zeros((3, 2)))
