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
    def full(fd, offset, length):
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(geo_handover.os, "posix_fallocate", full)
    big = geo_packets.pack(_footprints(600))
    assert geo_handover.ship(big, handover, "out-0") is big
    assert os.listdir(handover.folder) == ["token"]


def test_a_really_full_shared_memory(tiny_disk, monkeypatch):
    # a 512 KiB tmpfs for /dev/shm, no margin: a packet that fits is shipped, one that
    # does not fails at once (posix_fallocate) and travels inline, leaving no file
    monkeypatch.setattr(geo_handover, "SHARED_MEMORY", str(tiny_disk))
    monkeypatch.setattr(geo_handover, "FREE_BYTES", -(1 << 30))  # a margin that lets all try
    monkeypatch.setattr(geo_handover, "FREE_FRACTION", 0.0)
    h = geo_handover.open_handover()
    assert h is not None and Path(h.folder).parent == tiny_disk
    try:
        fits = geo_packets.pack(_footprints(600))
        big = geo_packets.pack(_footprints(6000))
        assert fits.coords.nbytes < (256 << 10) < (512 << 10) < big.coords.nbytes
        assert isinstance(geo_handover.ship(fits, h, "out-0"), geo_handover.Shipped)
        assert geo_handover.ship(big, h, "out-1") is big
        assert sorted(p.name.split("-")[0] for p in Path(h.folder).iterdir()) == ["out", "token"]
    finally:
        geo_handover.close(h)


def test_a_nearly_full_shared_memory_keeps_its_margin(handover, monkeypatch):
    big = geo_packets.pack(_footprints(600))
    real = os.statvfs(handover.folder)

    class Nearly:  # 1,000 pages of 4 KiB in all, the packet's size plus 16 MiB free
        f_frsize, f_blocks = 4096, 1000
        f_bavail = (big.coords.nbytes + (16 << 20)) // 4096

    monkeypatch.setattr(geo_handover.os, "statvfs", lambda path: Nearly)
    assert geo_handover.ship(big, handover, "out-0") is big  # 64 MiB stay free
    monkeypatch.setattr(geo_handover.os, "statvfs", lambda path: real)
    assert isinstance(geo_handover.ship(big, handover, "out-0"), geo_handover.Shipped)


def test_a_taken_name_is_not_overwritten_nor_removed(handover, monkeypatch):
    big = geo_packets.pack(_footprints(600))
    monkeypatch.setattr(geo_handover.secrets, "token_hex", lambda n: "same")
    first = geo_handover.ship(big, handover, "in")
    assert isinstance(first, geo_handover.Shipped)
    assert geo_handover.ship(big, handover, "in") is big  # the same name: inline
    back = geo_handover.land(first, remove=True)  # the first file is still there, whole
    assert back.coords.tobytes() == big.coords.tobytes()


def test_a_closed_handover_takes_no_more_files(monkeypatch):
    h = geo_handover.open_handover()
    big = geo_packets.pack(_footprints(600))
    assert geo_handover.reachable(h)  # seen before the run ended
    geo_handover.close(h)
    assert not Path(h.folder).exists()
    assert geo_handover.ship(big, h, "out-0") is big
    # a worker that wrote its file while the folder was being removed takes it back
    os.makedirs(h.folder)
    try:
        assert geo_handover.ship(big, h, "out-0") is big
        assert os.listdir(h.folder) == []
    finally:
        os.rmdir(h.folder)


def test_folders_of_killed_runs_are_swept(monkeypatch):
    import subprocess
    import time

    dead = subprocess.Popen(["true"])
    dead.wait()
    old = time.time() - 2 * geo_handover.STALE_AFTER
    made = []
    for name, pid, started, age in [
        ("dead", dead.pid, "1", old),  # its maker is gone: swept
        ("alive", os.getpid(), geo_handover.process_started(os.getpid()), old),
        ("recent", dead.pid, "1", time.time()),  # changed lately: another namespace's, kept
        ("tokenless", None, None, old),  # a folder never opened or half closed: swept
    ]:
        folder = Path(geo_handover.SHARED_MEMORY) / f"curvesmith-test-{name}-{os.getpid()}"
        folder.mkdir()
        if pid is not None:
            (folder / "token").write_text(f"{'0' * 32}\n{pid} {started}\n")
        os.utime(folder, (age, age))
        made.append(folder)
    try:
        h = geo_handover.open_handover()
        geo_handover.close(h)
        assert [f.exists() for f in made] == [False, True, True, False]
    finally:
        for f in made:
            if f.exists():
                for child in f.iterdir():
                    child.unlink()
                f.rmdir()


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
    # a caller's own local cluster: the results come back through shared memory (each
    # worker reads the token), and so do the inputs (the scheduler is on 127.0.0.1)
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
    """A local cluster's Nanny sets OMP_NUM_THREADS=1, MALLOC_TRIM_THRESHOLD_ and
    PYTHONHASHSEED in the process that starts it."""
    for name in ("OMP_NUM_THREADS", "MALLOC_TRIM_THRESHOLD_"):
        monkeypatch.delenv(name, raising=False)
    monkeypatch.setenv("PYTHONHASHSEED", "random")
    polys = _footprints(200)
    out, errors, _, _ = batch.smooth_partitioned(polys, workers=1, iterations=1)
    assert errors == () and _wkb(out) == _wkb(geo.smooth(polys, iterations=1))
    assert "OMP_NUM_THREADS" not in os.environ and "MALLOC_TRIM_THRESHOLD_" not in os.environ
    assert os.environ["PYTHONHASHSEED"] == "random"


def test_inputs_go_through_shared_memory_only_from_a_loopback_scheduler(client):
    from curvesmith.internals import batch_local_scheduler

    assert batch_local_scheduler(client)  # tcp://127.0.0.1:...

    class Remote:
        class scheduler:
            address = "tcp://10.0.0.5:8786"  # only a string: nothing is sent there

    assert not batch_local_scheduler(Remote)
    Remote.scheduler.address = "tls://scheduler.example.org:8786"
    assert not batch_local_scheduler(Remote)
    Remote.scheduler.address = "inproc://192.168.1.5/123/1"
    assert batch_local_scheduler(Remote)
