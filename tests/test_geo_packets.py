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
