"""Geometry packets (curvesmith.geo._packets): what Dask moves between the client and workers.

Every feature must come back as it went: type (Polygon vs MultiPolygon of one part),
coordinates to the bit (WKB-identical), ring order and orientation, NULL and empty.
"""

import numpy as np
import pytest
import shapely
from hypothesis import given, settings
from hypothesis import strategies as st

from curvesmith.internals import geo_packets

LINES, OBJECTS, POLYGONS, WKB = (
    geo_packets.LINES,
    geo_packets.OBJECTS,
    geo_packets.POLYGONS,
    geo_packets.WKB,
)
pack, unpack = geo_packets.pack, geo_packets.unpack


def _same(a, b) -> bool:
    if len(a) != len(b):
        return False
    for x, y in zip(a, b, strict=True):
        if (x is None) != (y is None):
            return False
        if x is not None and (x.geom_type != y.geom_type or shapely.to_wkb(x) != shapely.to_wkb(y)):
            return False
    return True


def _ring(rng, cx, cy, r, n, cw=False):
    t = np.sort(rng.uniform(0, 2 * np.pi, n))
    xy = np.c_[cx + r * np.cos(t), cy + r * np.sin(t)] * (1 + 0.2 * rng.uniform(size=(n, 1)))
    return xy[::-1] if cw else xy


def _feature(rng, kind, family):
    x, y = rng.uniform(4e5, 5e5), rng.uniform(5e6, 5.1e6)  # metres, a UTM-like frame
    if kind == "none":
        return None
    if family == "polygons":
        if kind == "empty":
            return shapely.Polygon() if rng.uniform() < 0.5 else shapely.MultiPolygon()
        shell = _ring(rng, x, y, 30, int(rng.integers(3, 40)), cw=rng.uniform() < 0.3)
        hole = [_ring(rng, x, y, 5, 6)] if kind == "holed" else []
        poly = shapely.Polygon(shell, hole)
        if kind == "multi1":
            return shapely.MultiPolygon([poly])
        if kind == "multi":
            far = shapely.Polygon(_ring(rng, x + 500, y, 20, 7))
            return shapely.MultiPolygon([poly, far])
        return poly
    if kind == "empty":
        return shapely.LineString() if rng.uniform() < 0.5 else shapely.MultiLineString()
    n = int(rng.integers(2, 30))
    line = np.c_[np.linspace(x, x + 100, n), y + rng.normal(0, 3, n)]
    if kind in ("multi", "multi1"):
        parts = [line] if kind == "multi1" else [line, line[::-1] + np.array([0.0, 50.0])]
        return shapely.MultiLineString(parts)
    return shapely.LineString(line)


@settings(max_examples=60, deadline=None)
@given(
    family=st.sampled_from(["polygons", "lines"]),
    kinds=st.lists(
        st.sampled_from(["plain", "holed", "multi", "multi1", "empty", "none"]), max_size=40
    ),
    seed=st.integers(0, 2**32 - 1),
)
def test_ragged_round_trip_is_exact(family, kinds, seed):
    rng = np.random.default_rng(seed)
    geoms = np.array([_feature(rng, k, family) for k in kinds], dtype=object)
    packet = pack(geoms)
    lines = family == "lines" and any(k != "none" for k in kinds)
    assert packet.kind == (LINES if lines else POLYGONS)  # no feature: either will do
    assert packet.data is None  # plain arrays only
    assert _same(unpack(packet), geoms)


@pytest.mark.parametrize(
    ("geoms", "kind"),
    [
        ([shapely.box(0, 0, 1, 1), shapely.LineString([(0, 0), (1, 1)])], WKB),  # mixed
        ([shapely.Point(1, 2), None], WKB),
        ([shapely.Polygon([(0, 0, 1), (1, 0, 2), (1, 1, 3)])], WKB),  # Z
        ([shapely.from_wkt("LINESTRING M (0 0 1, 1 1 2)")], WKB),  # M
        ([shapely.GeometryCollection([shapely.box(0, 0, 1, 1)])], WKB),
        ([shapely.LinearRing([(0, 0), (1, 0), (1, 1)]), shapely.box(0, 0, 1, 1)], OBJECTS),
        ([None, None], POLYGONS),
        ([], POLYGONS),
    ],
)
def test_other_layers_travel_as_wkb_or_objects(geoms, kind):
    geoms = np.array(geoms, dtype=object)
    packet = pack(geoms)
    assert packet.kind == kind
    assert _same(unpack(packet), geoms)
    if kind == OBJECTS:
        assert isinstance(unpack(packet)[0], shapely.LinearRing)


def test_packet_is_cheaper_than_wkb_and_pickles_as_buffers():
    # what Dask sends: the pickled packet holds the coordinates as one buffer (protocol 5)
    import pickle

    rng = np.random.default_rng(3)
    geoms = np.array([_feature(rng, "plain", "polygons") for _ in range(500)], dtype=object)
    packet = pack(geoms)
    buffers = []
    pickle.dumps(packet, protocol=5, buffer_callback=buffers.append)
    sizes = sorted(b.raw().nbytes for b in buffers)
    assert sizes[-1] == packet.coords.nbytes == 16 * shapely.get_num_coordinates(geoms).sum()


def _footprints(n: int, seed: int) -> np.ndarray:
    """Valid rings of 5-12 vertices in metres at uneven angles, both orientations; some
    smoothed rings cross themselves (the conflict resolution then reduces them)."""
    rng = np.random.default_rng(seed)
    out = []
    while len(out) < n:
        m = int(rng.integers(5, 13))
        t = np.sort(rng.uniform(0, 2 * np.pi, m))
        r = rng.uniform(4, 25) * (1 + 0.3 * rng.uniform(size=m))
        ring = np.c_[r * np.cos(t), r * np.sin(t)] + rng.uniform([4e5, 5e6], [5e5, 5.1e6])
        poly = shapely.Polygon(ring[::-1] if rng.uniform() < 0.3 else ring)
        if poly.is_valid:
            out.append(poly)
    return np.asarray(out, dtype=object)


def _packets_equal(p, q) -> bool:
    return (
        p.kind == q.kind
        and np.array_equal(p.types, q.types)
        and np.array_equal(p.filled, q.filled)
        and np.array_equal(p.coords, q.coords)
        and len(p.offsets) == len(q.offsets)
        and all(np.array_equal(a, b) for a, b in zip(p.offsets, q.offsets, strict=True))
    )


@pytest.mark.parametrize("method", ["cca", "chaikin"])
@pytest.mark.parametrize("iterations", [1, 2, 3])
def test_smooth_to_packet_is_the_packet_of_smooth(method, iterations):
    from curvesmith import geo
    from curvesmith.internals import geo_smooth

    polys = _footprints(8000, iterations)
    res = geo.smooth(polys, method=method, iterations=iterations, full_output=True)
    packet, reductions = geo_smooth.smooth_to_packet(polys, method=method, iterations=iterations)
    assert _packets_equal(packet, pack(res.geometry))
    assert reductions == res.reductions
    if method == "cca":
        assert len(reductions) > 0  # the spliced-in reduced rings are compared too
    assert _same(unpack(packet), res.geometry)


def test_smooth_to_packet_in_chunks(monkeypatch):
    from curvesmith import geo
    from curvesmith.internals import geo_smooth

    polys = _footprints(2000, 7)
    monkeypatch.setattr(geo_smooth, "CHUNK_VERTICES", 1000)  # about 100 chunks
    res = geo.smooth(polys, iterations=2, full_output=True)
    packet, reductions = geo_smooth.smooth_to_packet(polys, iterations=2)
    assert _packets_equal(packet, pack(res.geometry))
    assert reductions == res.reductions


#: Features that make a layer other than Polygons without holes (Z: a WKB packet).
ODD = {
    "none": None,
    "empty": shapely.Polygon(),
    "multi": shapely.MultiPolygon([shapely.box(0, 0, 1, 1)]),
    "hole": shapely.box(0, 0, 9, 9).difference(shapely.box(3, 3, 4, 4)),
    "z": shapely.Polygon([(0, 0, 1), (1, 0, 1), (0, 1, 1)]),
    "repeated": shapely.Polygon([(0, 0), (1, 0), (1, 0), (1, 1), (0, 1)]),
    "line": shapely.LineString([(0, 0), (1, 1), (2, 0)]),
}


@pytest.mark.parametrize("odd", ODD.values(), ids=ODD.keys())
def test_smooth_to_packet_declines_other_layers(odd):
    from curvesmith.internals import geo_smooth

    polys = np.append(_footprints(20, 1), np.array([odd], dtype=object)[:1])
    assert geo_smooth.smooth_to_packet(polys, iterations=2) is None
    assert geo_smooth.smooth_to_packet(polys[:0], iterations=2) is None


def test_smooth_to_packet_refuses_invalid_input_as_smooth_does():
    from curvesmith import geo
    from curvesmith.errors import CurveError
    from curvesmith.internals import geo_smooth

    bowtie = shapely.Polygon([(0, 0), (2, 2), (2, 0), (0, 2)])
    polys = np.append(_footprints(5, 2), np.array([bowtie], dtype=object))
    with pytest.raises(CurveError, match=r"\[5\] is not valid"):
        geo.smooth(polys)
    with pytest.raises(CurveError, match=r"\[5\] is not valid"):
        geo_smooth.smooth_to_packet(polys)


def _doubtful(rng) -> shapely.Polygon:
    """A valid ring that is not star-shaped (a comb): the compiled proof leaves it to GEOS."""
    x0, y0 = rng.uniform([4e5, 5e6], [5e5, 5.1e6])
    teeth = int(rng.integers(2, 6))
    pts = [(0.0, 0.0), (2.0 * teeth, 0.0)]
    for k in range(teeth, 0, -1):
        pts += [(2.0 * k, 6.0), (2.0 * k - 1, 6.0), (2.0 * k - 1, 1.0), (2.0 * k - 2, 1.0)]
    return shapely.Polygon(np.array(pts[:-1]) * rng.uniform(1, 5) + (x0, y0))


@pytest.mark.parametrize("method", ["cca", "chaikin"])
@pytest.mark.parametrize("iterations", [1, 2, 3])
def test_smooth_packet_is_smooth_to_packet_of_its_polygons(method, iterations):
    # the worker's way, from the packet's rings: the same bits as building the polygons
    from curvesmith.internals import geo_smooth

    rng = np.random.default_rng(iterations)
    polys = _footprints(3000, iterations + 10)
    combs = np.array([_doubtful(rng) for _ in range(40)], dtype=object)
    assert shapely.is_valid(combs).all()
    polys = np.concatenate([polys, combs])[rng.permutation(3040)]
    packet = pack(polys)
    ref = geo_smooth.smooth_to_packet(unpack(packet), method=method, iterations=iterations)
    got = geo_smooth.smooth_packet(packet, method=method, iterations=iterations)
    assert ref is not None and got is not None
    assert _packets_equal(got[0], ref[0]) and got[1] == ref[1]
    # from a read-only view (a mapped file of the handover) as well
    coords = packet.coords.copy()
    coords.flags.writeable = False
    again = geo_smooth.smooth_packet(
        geo_packets.GeometryPacket(
            packet.kind, packet.types, packet.filled, coords, packet.offsets
        ),
        method=method,
        iterations=iterations,
    )
    assert _packets_equal(again[0], ref[0])


def test_smooth_packet_in_chunks(monkeypatch):
    from curvesmith.internals import geo_smooth

    polys = pack(_footprints(2000, 7))
    monkeypatch.setattr(geo_smooth, "CHUNK_VERTICES", 1000)
    ref = geo_smooth.smooth_to_packet(unpack(polys), iterations=2)
    got = geo_smooth.smooth_packet(polys, iterations=2)
    assert _packets_equal(got[0], ref[0]) and got[1] == ref[1]


@pytest.mark.parametrize(
    "odd",
    [*ODD.values(), shapely.Polygon([(0, 0), (2, 2), (2, 0), (0, 2)])],  # + invalid: an error
    ids=[*ODD.keys(), "bowtie"],
)
def test_smooth_packet_declines_what_smooth_does_more_with(odd):
    # the usual way then says why (an invalid polygon) or repairs first (repeated vertex)
    from curvesmith.internals import geo_smooth

    polys = np.append(_footprints(20, 1), np.array([odd], dtype=object)[:1])
    assert geo_smooth.smooth_packet(pack(polys), iterations=2) is None
