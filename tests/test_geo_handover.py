"""Packets handed over through shared memory (curvesmith.geo._handover) between Dask's processes.

The coordinates that go through a file must come back to the bit, the files must be gone
after a run (and after a failed one), and whatever cannot use shared memory (a worker on
another machine, a full /dev/shm, small packets) must travel inline with the same result.
"""

import errno
import os
from pathlib import Path

import distributed
import numpy as np
import pytest
import shapely

from curvesmith import batch, geo
from curvesmith.errors import CurveError
from curvesmith.internals import BatchWorkers, batch_smooth_partition, geo_handover, geo_packets

pytestmark = pytest.mark.skipif(
    not os.path.isdir(geo_handover.SHARED_MEMORY), reason="needs /dev/shm (Linux)"
)


def _footprints(n, seed=3):
    rng = np.random.default_rng(seed)
    cx, cy = rng.uniform(4e5, 5e5, n), rng.uniform(5e6, 5.1e6, n)
    polys = []
    for x, y in zip(cx, cy, strict=True):
        m = int(rng.integers(5, 13))
        t = np.sort(rng.uniform(0, 2 * np.pi, m))
        r = rng.uniform(4, 25) * (1 + 0.3 * rng.uniform(size=m))
        ring = np.c_[x + r * np.cos(t), y + r * np.sin(t)]
        polys.append(shapely.Polygon(ring if rng.uniform() < 0.7 else ring[::-1]))
    polys = np.array(polys, dtype=object)
    return polys[shapely.is_valid(polys)]


def _wkb(geoms):
    return [shapely.to_wkb(g) for g in geoms]


@pytest.fixture
def handover():
    h = geo_handover.open_handover()
    assert h is not None and Path(h.folder).parent == Path(geo_handover.SHARED_MEMORY)
    try:
        yield h
    finally:
        geo_handover.close(h)
    assert not Path(h.folder).exists()


def test_shipped_coordinates_land_to_the_bit(handover):
    polys = _footprints(600)
    packet = geo_packets.pack(polys)
    assert packet.coords.nbytes >= geo_handover.MIN_BYTES
    item = geo_handover.ship(packet, handover, "out-0")
    assert isinstance(item, geo_handover.Shipped) and len(item) == len(polys)
    assert item.packet.coords.size == 0  # only the file carries them
    path = Path(item.path)
    assert path.parent == Path(handover.folder) and path.stat().st_size == packet.coords.nbytes
    back = geo_handover.land(item, remove=True)
    assert not path.exists()  # removed at once; the mapping lives on with the array
    assert back.coords.tobytes() == packet.coords.tobytes() and not back.coords.flags.writeable
    for a, b in zip(back.offsets, packet.offsets, strict=True):
        assert np.array_equal(a, b)
    assert _wkb(geo_packets.unpack(back)) == _wkb(polys)


def test_land_keeps_an_input_file_until_discarded(handover):
    packet = geo_packets.pack(_footprints(600))
    item = geo_handover.ship(packet, handover, "in-0")
    first = geo_handover.land(item, remove=False)
    again = geo_handover.land(item, remove=False)  # a task that Dask runs a second time
    assert first.coords.tobytes() == again.coords.tobytes() == packet.coords.tobytes()
    geo_handover.discard(item)
    assert not Path(item.path).exists()
    geo_handover.discard(item)  # twice is harmless
    geo_handover.discard(packet)  # and so is a packet that travelled inline


def test_what_stays_inline(handover, monkeypatch):
    small = geo_packets.pack(_footprints(20))
    assert small.coords.nbytes < geo_handover.MIN_BYTES
    assert geo_handover.ship(small, handover, "x") is small
    big = geo_packets.pack(_footprints(600))
    assert geo_handover.ship(big, None, "x") is big  # no shared memory
    # a worker on another machine: it reads no such token (here: another token)
    elsewhere = geo_handover.Handover(handover.folder, "0" * 32)
    assert not geo_handover.reachable(elsewhere)
    assert geo_handover.ship(big, elsewhere, "x") is big
    gone = geo_handover.Handover(handover.folder + "-gone", handover.token)
    assert not geo_handover.reachable(gone) and geo_handover.ship(big, gone, "x") is big
    assert geo_handover.land(big, remove=True) is big
    assert os.listdir(handover.folder) == ["token"]


def test_a_full_shared_memory_falls_back_inline_and_leaves_no_file(handover, monkeypatch):
    real_open = open

    class Full:
        def __init__(self, path, mode):
            self.f = real_open(path, mode)

        def __enter__(self):
            return self

        def __exit__(self, *exc):
            self.f.close()

        def write(self, data):
            self.f.write(bytes(data)[:4096])
            raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(geo_handover, "open", Full, raising=False)
    big = geo_packets.pack(_footprints(600))
    assert geo_handover.ship(big, handover, "out-0") is big
    assert os.listdir(handover.folder) == ["token"]


def test_a_damaged_file_is_an_error_naming_it(handover):
    item = geo_handover.ship(geo_packets.pack(_footprints(600)), handover, "out-0")
    with open(item.path, "r+b") as f:
        f.truncate(1000)
    with pytest.raises(CurveError, match=r"handed over in .*out-0.* are 1000 bytes, expected \d+"):
        geo_handover.land(item, remove=True)


def test_a_file_on_another_machine_is_an_error_naming_it(handover):
    item = geo_handover.ship(geo_packets.pack(_footprints(600)), handover, "in-0")
    geo_handover.discard(item)
    with pytest.raises(CurveError, match=r"in-0.* cannot be read here .*machine of the process"):
        geo_handover.land(item, remove=False)


def test_no_shared_memory_no_handover(monkeypatch, tmp_path):
    monkeypatch.setattr(geo_handover, "SHARED_MEMORY", str(tmp_path / "missing"))
    assert geo_handover.open_handover() is None
    assert not geo_handover.reachable(None)


def test_a_task_ships_its_result_only_where_the_folder_is_seen(handover):
    polys = _footprints(600)
    options = {"method": "cca", "iterations": 2, "alpha": "regular", "make_valid": False}
    ref = geo.smooth(polys, iterations=2)
    shipped_in = geo_handover.ship(geo_packets.pack(polys), handover, "in-0")
    here, errors, _ = batch_smooth_partition(shipped_in, 0, options, None, handover)
    assert errors == [] and isinstance(here, geo_handover.Shipped)
    elsewhere = geo_handover.Handover(handover.folder, "f" * 32)
    inline, _, _ = batch_smooth_partition(geo_packets.pack(polys), 0, options, None, elsewhere)
    assert isinstance(inline, geo_packets.GeometryPacket)
    out = geo_packets.unpack(geo_handover.land(here, remove=True))
    assert _wkb(out) == _wkb(ref) == _wkb(geo_packets.unpack(inline))


@pytest.fixture(scope="module")
def client():
    with (
        distributed.LocalCluster(
            host="127.0.0.1", n_workers=2, threads_per_worker=1, processes=True,
            dashboard_address=":0", silence_logs=40, timeout="60s",
        ) as cluster,
        distributed.Client(cluster) as c,
    ):  # fmt: skip
        yield c


def _folders():
    return {p for p in os.listdir(geo_handover.SHARED_MEMORY) if p.startswith("curvesmith-")}


def test_partitioned_run_hands_over_and_cleans_up(client, monkeypatch):
    polys = _footprints(3000)
    seen = []
    land = geo_handover.land

    def spy(item, *, remove):
        seen.append(type(item).__name__)
        return land(item, remove=remove)

    monkeypatch.setattr(geo_handover, "land", spy)
    shipped = []
    ship = geo_handover.ship
    monkeypatch.setattr(
        geo_handover, "ship", lambda p, h, name: shipped.append(ship(p, h, name)) or shipped[-1]
    )
    before = _folders()
    out, errors, n_tasks, _ = batch.smooth_partitioned(
        polys, client=client, partition_size=500, iterations=2
    )
    assert errors == () and n_tasks == -(-len(polys) // 500)
    assert _wkb(out) == _wkb(geo.smooth(polys, iterations=2))
    # every input and every result went through shared memory (a local cluster)
    assert seen == ["Shipped"] * n_tasks
    assert [type(s).__name__ for s in shipped] == ["Shipped"] * n_tasks
    assert _folders() == before  # the run's folder is gone
    assert not any(Path(s.path).exists() for s in shipped)


def test_a_failed_run_removes_its_folder(client):
    before = _folders()
    with pytest.raises(RuntimeError, match="stop"), BatchWorkers(client, None, None) as pool:
        h, ship_inputs = pool.handover()
        assert ship_inputs and Path(h.folder).is_dir()
        geo_handover.ship(geo_packets.pack(_footprints(600)), h, "in-0")
        raise RuntimeError("stop")
    assert _folders() == before


def test_batch_leaves_the_callers_environment_as_it_was(monkeypatch):
    """A local cluster's Nanny sets OMP_NUM_THREADS=1 in the process that starts it."""
    monkeypatch.delenv("OMP_NUM_THREADS", raising=False)
    monkeypatch.setenv("MALLOC_TRIM_THRESHOLD_", "131072")
    polys = _footprints(200)
    out, errors, _, _ = batch.smooth_partitioned(polys, workers=1, iterations=1)
    assert errors == () and _wkb(out) == _wkb(geo.smooth(polys, iterations=1))
    assert "OMP_NUM_THREADS" not in os.environ
    assert os.environ["MALLOC_TRIM_THRESHOLD_"] == "131072"
