"""Many small polygons: curvesmith's ragged engine against PostGIS ST_ChaikinSmoothing.

Seeded footprint-like polygons (``--n``, default 20,000; 5-12 vertices, metres in a
UTM-like frame, uneven spacing, both orientations), 2 iterations. In one run:

* ``geo.smooth`` (cca) on all polygons in one call, with the area check (max relative
  ring-area change) and ``shapely.is_valid`` on the output; ``geo.smooth`` method
  ``chaikin``; the engines alone (``cca.smooth_ragged``, ``subdivision.chaikin_ragged``)
  and, on a subset, ``cca.smooth`` called once per polygon (the old per-call cost);
* PostGIS ``ST_ChaikinSmoothing(geom, 2)`` for real: a throw-away PostgreSQL cluster
  (``initdb`` in a temporary folder, a unix socket in that folder, run as the
  ``postgres`` system user when started as root, stopped and removed at the end), the
  same polygons loaded as WKB, the smoothing timed in SQL (``EXPLAIN ANALYZE`` of
  ``SELECT ST_ChaikinSmoothing(geom, 2) FROM t``, and a full
  ``sum(ST_NPoints(ST_ChaikinSmoothing(geom, 2)))`` query), and the per-polygon ratio
  printed. Without PostgreSQL/PostGIS this says so in one line and times the rest;
* ``--footprints M`` (default 1,000,000; 0 to skip): M polygons written to a GeoPackage
  and smoothed by ``curvesmith smooth in.gpkg -o out.gpkg`` in a subprocess, timed with
  its peak memory (``resource.getrusage`` of the child) against the output's size;
* ``--dask``: ``curvesmith.batch.smooth_partitioned`` on ``--dask-n`` footprints (default
  200,000: the 20,000 of the set are 0.1 s of work, less than a cluster's start) with 1 and 2
  Dask workers (throughput, and the cores the workers got: their CPU seconds per wall
  second and their CPU affinity; and the caller's CPU seconds per wall second: it packs
  the partitions and builds the output geometries, on the same 2 cores). Beside it the
  ceiling: 1 and 2 independent processes (no Dask) smoothing a half each, with their share
  in memory before the clock starts and nothing sent back: what the machine's cores give
  this work when nothing else runs, against which the workers' throughput is read.

The machine these figures come from is shared (2 cores, several jobs): compare the
ratios of one run, not absolute times across runs.

* ``--ring N`` (default 1,000,000; 0 to skip): one ring of N vertices (wavy, jagged,
  noisy; metres), ``cca.smooth`` (default threads and 1 thread) against
  ``subdivision.chaikin`` at 1 and 3 iterations, CPU and user CPU per output vertex
  (the system time of touching fresh memory varies several times over on a loaded
  machine), and against a compiled Chaikin step written here (one loop, what a
  compiled Chaikin would cost: the library's is numpy);
* ``--counties``: the US county coverage (plotly-geo) through ``geo.smooth_coverage``
  with and without the output check, and its arc smoothing alone.

Every row gives wall and CPU time (``time.process_time``: user + system of this
process, so threads count); PostGIS's figure is its backend's execution time.

Run: ``python benchmarks/bench_many.py [--n N] [--footprints M] [--ring N] [--counties]
[--dask] [--quick]``.
"""

from __future__ import annotations

import argparse
import os
import re
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import shapely

from curvesmith import cca, geo, subdivision

PG_BIN = Path("/usr/lib/postgresql/15/bin")
ITER = 2


def footprints(n: int, seed: int) -> np.ndarray:
    """N valid polygons of 5-12 vertices, building-sized, in a 100 km square of metres."""
    rng = np.random.default_rng(seed)
    m = rng.integers(5, 13, size=n)
    off = np.concatenate([[0], np.cumsum(m)])
    t = rng.uniform(0, 2 * np.pi, size=off[-1])
    # sort the angles within each polygon: star-shaped rings, uneven spacing
    ids = np.repeat(np.arange(n), m)
    t = t[np.lexsort((t, ids))]
    r = np.repeat(rng.uniform(4, 25, size=n), m) * (1 + 0.3 * rng.uniform(size=off[-1]))
    cx = np.repeat(rng.uniform(4e5, 5e5, size=n), m)
    cy = np.repeat(rng.uniform(5.0e6, 5.1e6, size=n), m)
    xy = np.c_[cx + r * np.cos(t), cy + r * np.sin(t)]
    flip = rng.uniform(size=n) < 0.3  # some clockwise rings
    rows = np.arange(off[-1])
    rev = np.repeat(off[:-1] + off[1:] - 1, m) - rows
    rows = np.where(np.repeat(flip, m), rev, rows)
    xy = xy[rows]
    # close the rings: shapely's ring layout
    closed = np.empty((off[-1] + n, 2))
    coff = off + np.arange(n + 1)
    body = np.arange(off[-1]) + ids
    closed[body] = xy
    closed[coff[1:] - 1] = xy[off[:-1]]
    polys = shapely.polygons(shapely.linearrings(closed, indices=np.repeat(np.arange(n), m + 1)))
    ok = shapely.is_valid(polys)
    return polys[ok]


def best(fn, repeats: int):
    """Smallest wall time of ``repeats`` runs, and the output of the last."""
    t, _, out = best_cpu(fn, repeats)
    return t, out


def best_cpu(fn, repeats: int):
    """Smallest wall time, smallest CPU time (user + system, this process) and the output."""
    walls, cpus, out = [], [], None
    for _ in range(repeats):
        out = None  # the previous run's output is freed before, not inside, this run's timing
        c0 = time.process_time()
        t0 = time.perf_counter()
        out = fn()
        walls.append(time.perf_counter() - t0)
        cpus.append(time.process_time() - c0)
    return min(walls), min(cpus), out


# ------------------------------------------------------------------------------- PostGIS


class ThrowawayPostgres:
    """A temporary PostgreSQL 15 cluster with PostGIS on a unix socket; stopped on exit."""

    def __init__(self):
        self.dir = Path(tempfile.mkdtemp(prefix="cs_pg_"))
        self.data = self.dir / "data"
        self.as_user: list[str] = []
        if os.geteuid() == 0:  # postgres refuses to run as root
            self.as_user = ["runuser", "-u", "postgres", "--"]
            shutil.chown(self.dir, "postgres")
            os.chmod(self.dir, 0o700)
        self.started = False

    def _run(self, *args, **kw):
        return subprocess.run(
            [*self.as_user, *args], check=True, capture_output=True, text=True, **kw
        )

    def __enter__(self):
        self._run(str(PG_BIN / "initdb"), "-D", str(self.data), "-A", "trust", "-U", "bench")
        self._run(
            str(PG_BIN / "pg_ctl"), "-D", str(self.data), "-l", str(self.dir / "log"), "-w",
            "-o", f"-k {self.dir} -c listen_addresses='' -c jit=off", "start",
        )  # fmt: skip
        self.started = True
        self.psql("CREATE EXTENSION postgis;")
        return self

    def __exit__(self, *exc):
        if self.started:
            self._run(str(PG_BIN / "pg_ctl"), "-D", str(self.data), "-m", "fast", "-w", "stop")
        shutil.rmtree(self.dir, ignore_errors=True)

    def psql(self, sql: str, stdin: str | None = None) -> str:
        """Run one SQL command through psql on the socket; return its unaligned output."""
        cmd = [str(PG_BIN / "psql"), "-h", str(self.dir), "-U", "bench", "-d", "postgres"]
        cmd += ["-X", "-q", "-A", "-t", "-v", "ON_ERROR_STOP=1", "-c", sql]
        return self._run(*cmd, input=stdin).stdout


def postgis_available() -> str | None:
    """None if PostgreSQL 15 with PostGIS is installed, else the reason."""
    if not (PG_BIN / "initdb").exists():
        return f"PostgreSQL 15 not installed ({PG_BIN}/initdb missing)"
    ctl = Path("/usr/share/postgresql/15/extension/postgis.control")
    if not ctl.exists():
        return "PostGIS for PostgreSQL 15 not installed (postgis.control missing)"
    if os.geteuid() == 0 and shutil.which("runuser") is None:
        return "running as root without runuser (postgres refuses to run as root)"
    return None


def bench_postgis(polys: np.ndarray, repeats: int) -> dict[str, float] | None:
    reason = postgis_available()
    if reason is not None:
        print(f"PostGIS: skipped, {reason} (apt-get install postgresql-15-postgis-3)")
        return None
    with ThrowawayPostgres() as pg:
        pg.psql("CREATE TABLE t (id int, geom geometry);")
        data = "\n".join(
            f"{k}\t{h}" for k, h in enumerate(shapely.to_wkb(polys, hex=True, include_srid=False))
        )
        pg.psql("COPY t FROM STDIN;", stdin=data + "\n")
        pg.psql("VACUUM ANALYZE t;")
        version = pg.psql("SELECT postgis_lib_version();").strip()
        n_pg = int(pg.psql("SELECT count(*) FROM t;"))
        assert n_pg == len(polys)

        def explain(sql: str) -> float:
            out = pg.psql(f"EXPLAIN (ANALYZE, TIMING OFF) {sql}")
            return float(re.search(r"Execution Time: ([0-9.]+) ms", out).group(1)) / 1e3

        def timed_query(sql: str) -> float:
            t0 = time.perf_counter()
            pg.psql(sql)
            return time.perf_counter() - t0

        scan = min(explain("SELECT geom FROM t") for _ in range(repeats))
        smooth = min(
            explain(f"SELECT ST_ChaikinSmoothing(geom, {ITER}) FROM t") for _ in range(repeats)
        )
        full = min(
            timed_query(f"SELECT sum(ST_NPoints(ST_ChaikinSmoothing(geom, {ITER}))) FROM t")
            for _ in range(repeats)
        )
        nout = int(pg.psql(f"SELECT sum(ST_NPoints(ST_ChaikinSmoothing(geom, {ITER}))) FROM t"))
    return {"version": version, "scan": scan, "smooth": smooth, "full": full, "nout": nout}


# ------------------------------------------------------------------------------- long rings


def long_rings(n: int, seed: int) -> dict[str, np.ndarray]:
    """Rings of n vertices in metres: a wavy coastline, a jagged one and a noisy circle."""
    rng = np.random.default_rng(seed)
    t = np.sort(rng.uniform(0, 2 * np.pi, n))
    wavy = 1e4 * (1 + 0.05 * np.sin(40 * t) + 0.01 * np.sin(700 * t))
    jag = 1e4 * (1 + 0.02 * rng.choice([-1, 1], n) * rng.uniform(0.5, 1, n))
    noisy = 1e4 * (1 + 0.003 * rng.standard_normal(n))
    return {
        name: np.c_[r * np.cos(t), r * np.sin(t)] + np.array([5e5, 5e6])
        for name, r in (("wavy", wavy), ("jagged", jag), ("noisy", noisy))
    }


def best_user(fn, repeats: int):
    """Smallest wall, CPU (user + system) and user CPU time of ``repeats`` runs, and the output.

    The system time of a run that touches fresh memory (page faults, zeroing) varies
    several times over on a loaded machine; the user time is the kernel's own work.
    """
    walls, cpus, users, out = [], [], [], None
    for _ in range(repeats):
        out = None  # freed before, not inside, this run's timing
        r0 = resource.getrusage(resource.RUSAGE_SELF)
        c0 = time.process_time()
        t0 = time.perf_counter()
        out = fn()
        walls.append(time.perf_counter() - t0)
        cpus.append(time.process_time() - c0)
        users.append(resource.getrusage(resource.RUSAGE_SELF).ru_utime - r0.ru_utime)
    return min(walls), min(cpus), min(users), out


def _compiled_chaikin():
    """A compiled Chaikin step (one loop, output written once): how fast Chaikin can be.

    ``subdivision.chaikin`` is numpy (a few whole-array passes per coordinate); this is
    the floor a compiled Chaikin would reach, printed as a second peer so that the
    ratio against the library's Chaikin is read with it.
    """
    from numba import njit

    @njit(cache=True, nogil=True)
    def step(p, out):
        n = p.shape[0]
        for i in range(n):
            j = i + 1 if i + 1 < n else 0
            for d in range(2):
                s = 0.25 * (p[j, d] - p[i, d])
                out[2 * i, d] = p[i, d] + s
                out[2 * i + 1, d] = p[j, d] - s

    def chaikin(ring: np.ndarray, iterations: int) -> np.ndarray:
        p = np.ascontiguousarray(ring, dtype=float)
        for _ in range(iterations):
            out = np.empty((2 * p.shape[0], 2))
            step(p, out)
            p = out
        return p

    chaikin(np.zeros((3, 2)), 1)  # compile (or load from the cache) outside the timings
    return chaikin


def bench_ring(n: int, repeats: int) -> None:
    print(
        f"\n== one ring of {n} vertices: cca.smooth vs subdivision.chaikin (same run), "
        "CPU time per output vertex, best of the repeats (user: without the system time "
        "of touching fresh memory, which varies several times over on a loaded machine) =="
    )
    compiled = _compiled_chaikin()
    print(
        f"{'shape':>7} {'it':>3} {'cca ns':>7} {'user':>6} {'thr=1':>6} {'user':>6} "
        f"{'chaikin':>7} {'user':>6} {'nb':>5} {'x cpu':>6} {'x user':>6} {'thr=1 x':>7} "
        f"{'x nb':>5}  (cca threads default / 1; chaikin numpy / compiled; target x <= 2)"
    )
    for name, ring in long_rings(n, seed=5).items():
        for it in (1, 3):
            runs = {
                "cca": lambda ring=ring, it=it: cca.smooth(ring, closed=True, iterations=it),
                "cca1": lambda ring=ring, it=it: cca.smooth(
                    ring, closed=True, iterations=it, threads=1
                ),
                "ch": lambda ring=ring, it=it: subdivision.chaikin(
                    ring, closed=True, iterations=it
                ),
                "nb": lambda ring=ring, it=it: compiled(ring, it),
            }
            # the runs take turns, repeat by repeat: the other jobs of a shared machine load
            # every contender alike (run back to back, one could get a quiet spell)
            cpu, user, size = dict.fromkeys(runs, np.inf), dict.fromkeys(runs, np.inf), {}
            for _ in range(repeats):
                for key, fn in runs.items():
                    _, c, u, out = best_user(fn, 1)
                    cpu[key], user[key], size[key] = min(cpu[key], c), min(user[key], u), len(out)
            per = {key: (cpu[key] / size[key] * 1e9, user[key] / size[key] * 1e9) for key in runs}
            (cc, cu), (c1, u1), (hc, hu), (nc, _) = per["cca"], per["cca1"], per["ch"], per["nb"]
            print(
                f"{name:>7} {it:>3} {cc:>7.1f} {cu:>6.1f} {c1:>6.1f} {u1:>6.1f} {hc:>7.1f} "
                f"{hu:>6.1f} {nc:>5.1f} {cc / hc:>6.2f} {cu / hu:>6.2f} {c1 / hc:>7.2f} "
                f"{cc / nc:>5.1f}"
            )


# ------------------------------------------------------------------------------- counties


def bench_counties(repeats: int = 3) -> None:
    """The county coverage: the whole call, its phases, and GEOS' validity test as peer."""
    try:
        df = geo.us_counties().to_crs("EPSG:5070")
    except Exception as exc:  # plotly-geo missing
        print(f"\nUS counties: skipped ({type(exc).__name__}: {exc})")
        return
    from curvesmith.geo import _coverage as C
    from curvesmith.geo._coverage import smooth_arc_blocks

    g = np.asarray(df.geometry.values, dtype=object)
    nv = int(shapely.get_num_coordinates(g).sum())
    print(f"\n== coverage: {len(g)} US counties, {nv} vertices (EPSG:5070), 2 iterations ==")
    t0, c0 = time.perf_counter(), time.process_time()
    geo.smooth_coverage(g[:3])
    print(
        f"first call (numba kernels loaded from their cache): wall "
        f"{time.perf_counter() - t0:.2f} s, cpu {time.process_time() - c0:.2f} s"
    )
    for validate in (True, False):
        t, c, res = best_cpu(
            lambda v=validate: geo.smooth_coverage(
                g, iterations=ITER, validate=v, full_output=True
            ),
            repeats,
        )
        print(
            f"validate={validate!s:5}: wall {t:.2f} s, cpu {c:.2f} s (target < 1 s); "
            f"{res.n_arcs} arcs, {len(res.reductions)} reductions, max dA/A "
            f"{res.max_area_change:.1e}, coverage valid {res.coverage_valid}"
        )
    # the phases, and the GEOS peer of the two validity proofs
    topo = C.coverage_topology(g)
    uses = C._flat_uses(topo)
    smoothed, _ = C.smooth_arcs(topo, method="cca", iterations=ITER, alpha="regular")
    ragged = C._ragged(smoothed, topo.loops)
    coords, offs = C.ring_coordinates(topo, smoothed, uses, ragged)
    new = C.rebuild(topo, smoothed)
    phases = {
        "coverage_topology": lambda: C.coverage_topology(g),
        "input proof (certainly_valid)": lambda: C.certainly_valid(
            topo.arcs, topo.loops, uses, C._shells(topo), topo.ring_sign, g
        ),
        "  GEOS coverage_is_valid(input)": lambda: shapely.coverage_is_valid(g),
        "arc smoothing alone (one ragged call)": lambda: smooth_arc_blocks(
            topo.arcs, topo.loops, topo.frozen, method="cca", iterations=ITER, alpha="regular"
        ),
        "smoothing + conflict resolution": lambda: C.smooth_arcs(
            topo, method="cca", iterations=ITER, alpha="regular"
        ),
        "rebuild": lambda: C.rebuild(topo, smoothed),
        "output proof (_output_valid)": lambda: C._output_valid(
            topo, uses, smoothed, coords, offs, new, ragged
        ),
        "  GEOS coverage_is_valid(output)": lambda: shapely.coverage_is_valid(new),
    }
    for name, fn in phases.items():
        t, c, _ = best_cpu(fn, repeats)
        print(f"  {name:40} wall {t:.2f} s, cpu {c:.2f} s")


# ------------------------------------------------------------------------------- footprints


def bench_footprints(m: int) -> None:
    print(f"\n== {m} footprints: curvesmith smooth in.gpkg -o out.gpkg (subprocess) ==")
    import geopandas as gpd
    import pyogrio

    polys = footprints(int(m * 1.02), seed=99)[:m]
    with tempfile.TemporaryDirectory(prefix="cs_many_") as tmp:
        src, dst = Path(tmp) / "in.gpkg", Path(tmp) / "out.gpkg"
        t0 = time.perf_counter()
        gdf = gpd.GeoDataFrame({"id": np.arange(len(polys))}, geometry=polys, crs="EPSG:32633")
        pyogrio.write_dataframe(gdf, src, layer="footprints")
        del gdf
        print(f"written {len(polys)} polygons in {time.perf_counter() - t0:.1f} s")
        exe = shutil.which("curvesmith") or "curvesmith"
        cmd = [exe, "smooth", str(src), "-o", str(dst), "--iterations", str(ITER)]
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        t0 = time.perf_counter()
        proc = subprocess.run(cmd, capture_output=True, text=True)
        wall = time.perf_counter() - t0
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        if proc.returncode != 0:
            print(f"curvesmith smooth failed ({proc.returncode}): {proc.stderr.strip()[-400:]}")
            return
        peak = after.ru_maxrss * 1024  # kB on Linux; the largest child so far
        cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
        out = pyogrio.read_dataframe(dst, read_geometry=True)
        g = out.geometry.values
        nout = int(shapely.get_num_coordinates(g).sum())
        coords_bytes = nout * 16
        a0 = shapely.area(polys)
        a1 = shapely.area(g)
        print(
            f"wall {wall:.1f} s (cpu {cpu:.1f} s, incl. reading and writing); peak RSS "
            f"{peak / 2**20:.0f} MiB = {peak / coords_bytes:.2f} x the output coordinates "
            f"({coords_bytes / 2**20:.0f} MiB, {nout} vertices), "
            f"{peak / dst.stat().st_size:.2f} x the output file "
            f"({dst.stat().st_size / 2**20:.0f} MiB)"
        )
        print(
            f"max |dA|/A = {np.max(np.abs(a1 - a0) / a0):.2e}; invalid outputs: "
            f"{int((~shapely.is_valid(g)).sum())}; target: under 60 s on one core"
        )


# ------------------------------------------------------------------------------- Dask


def _ceiling_worker(conn) -> None:
    """A process of :func:`ceiling`: smooth its share on every "go", answer with the seconds."""
    os.environ["OMP_NUM_THREADS"] = "1"  # as in a Dask worker: the engine in one thread
    packet = conn.recv()
    from curvesmith.internals import geo_packets

    geoms = geo_packets.unpack(packet)
    geo.smooth(geoms[:500], iterations=ITER)  # warm: numba's cache, the heap
    conn.send("ready")
    while conn.recv() == "go":
        t0 = time.perf_counter()
        out = geo.smooth(geoms, iterations=ITER)
        conn.send(time.perf_counter() - t0)
        del out


def ceiling(polys: np.ndarray, k: int, repeats: int) -> float:
    """Polygons per second of ``k`` independent processes smoothing a k-th each, no Dask.

    The machine's own parallel capacity on this work: the processes get their share
    before the clock starts and send nothing back, so no transfer, no packing, no client
    and no scheduler share the cores. The processes start once; best of `repeats` rounds
    (at least 5: a round is about a second).
    """
    import multiprocessing as mp

    from curvesmith.internals import geo_packets

    ctx = mp.get_context("spawn")
    pipes, procs = [], []
    for part in np.array_split(polys, k):
        a, b = ctx.Pipe()
        proc = ctx.Process(target=_ceiling_worker, args=(b,))
        proc.start()
        a.send(geo_packets.pack(part))
        pipes.append(a)
        procs.append(proc)
    for a in pipes:
        a.recv()
    best = float("inf")
    for _ in range(max(5, repeats)):
        t0 = time.perf_counter()
        for a in pipes:
            a.send("go")
        for a in pipes:
            a.recv()
        best = min(best, time.perf_counter() - t0)
    for a in pipes:
        a.send("stop")
    for proc in procs:
        proc.join()
    return len(polys) / best


def _timed_on(client, run, repeats: int) -> tuple[float, float, float]:
    """Best wall time of ``run()`` over `repeats`, the workers' cores used then and the caller's."""
    wall = mine = used = float("inf")
    for _ in range(repeats):  # the best of `repeats` runs, and its CPU times
        cpu0 = client.run(time.process_time)
        t0, c0 = time.perf_counter(), time.process_time()
        run()
        t, c = time.perf_counter() - t0, time.process_time() - c0
        cpu1 = client.run(time.process_time)
        if t < wall:
            wall, mine = t, c
            used = sum(cpu1[k] - cpu0[k] for k in cpu1) / wall
    return wall, used, mine / wall


def bench_dask(polys: np.ndarray, repeats: int = 3) -> None:
    import distributed

    from curvesmith import batch

    try:
        import dask_geopandas
        import geopandas
    except ImportError:
        dask_geopandas = None
    print(f"\n== Dask: {len(polys)} polygons, {ITER} iterations ==")
    # what this machine gives k processes doing this work with nothing else running
    top = {k: ceiling(polys, k, repeats) for k in (1, 2)}
    print(
        "ceiling (k processes, a k-th each, no Dask, no transfer): "
        + ", ".join(f"{k}: {r:.0f} polygons/s" for k, r in top.items())
        + f" = {top[2] / top[1]:.2f}x for 2"
    )
    print(
        f"{'':<46} {'workers':>7} {'polygons/s':>11} {'x 1 worker':>10} {'cores used':>10} "
        f"{'client':>7} {'affinity':>9} {'x ceiling':>10} {'per core':>9} {'x 1 worker':>10}"
    )
    base: dict[str, float] = {}
    parquet = Path(tempfile.mkdtemp(prefix="bench_many_"))
    if dask_geopandas is not None:  # 16 GeoParquet files, as a Dask user's layer
        frame = geopandas.GeoDataFrame(geometry=polys, crs="EPSG:3857")
        dask_geopandas.from_geopandas(frame, npartitions=16).to_parquet(parquet / "in")
    for w in (1, 2):
        with (
            distributed.LocalCluster(
                n_workers=w, threads_per_worker=1, processes=True, dashboard_address=":0",
                silence_logs=40,
            ) as cluster,
            distributed.Client(cluster) as client,
        ):  # fmt: skip
            aff = client.run(lambda: sorted(os.sched_getaffinity(0)))
            cores = ",".join(str(v) for v in sorted({c for a in aff.values() for c in a}))
            size = max(500, len(polys) // (4 * w))
            runs = {}

            def gathered(geoms=polys, size=size):
                batch.smooth_partitioned(geoms, client=client, partition_size=size, iterations=ITER)

            runs["smooth_partitioned (client in, client out)"] = gathered
            if dask_geopandas is not None:
                # the layer on the workers, as read there: its partitions where the
                # scheduler put the reading tasks
                ddf = dask_geopandas.read_parquet(parquet / "in").persist()
                distributed.wait(ddf)

                def on_workers(ddf=ddf):
                    out = batch.smooth_collection(ddf, iterations=ITER).persist()
                    distributed.wait(out)  # smoothed where the partitions are; stays there
                    del out

                def pipeline():
                    # a Dask user's whole run: the workers read, smooth and write their parts
                    shutil.rmtree(parquet / "out", ignore_errors=True)
                    batch.smooth_collection(
                        dask_geopandas.read_parquet(parquet / "in"), iterations=ITER
                    ).to_parquet(parquet / "out")

                runs["smooth_collection (on the workers)"] = on_workers
                runs["read_parquet > smooth_collection > to_parquet"] = pipeline
            # a first run warms every worker: numba loads each kernel from its cache on
            # first use (seconds in all), and a new process grows its heap
            gathered(polys[: 2 * w * size // 4], size // 4)
            for name, run in runs.items():
                run()
                wall, used, mine = _timed_on(client, run, repeats)
                rate = len(polys) / wall
                per_core = rate / used  # polygons per CPU second the workers got
                b_rate = base.setdefault(name, rate)
                b_core = base.setdefault(name + "/core", per_core)
                print(
                    f"{name:<46} {w:>7} {rate:>11.0f} {rate / b_rate:>10.2f} {used:>10.2f} "
                    f"{mine:>7.2f} {cores:>9} {rate / top[w]:>10.2f} {per_core:>9.0f} "
                    f"{per_core / b_core:>10.2f}"
                )
    shutil.rmtree(parquet, ignore_errors=True)
    if dask_geopandas is None:
        print("(dask-geopandas is not installed: smooth_collection not timed)")
    print(
        "(cores used: the workers' CPU seconds per wall second; client: the caller's, which "
        "for smooth_partitioned packs the partitions and builds the output geometries as the "
        "results arrive, and for smooth_collection only submits the graph; x ceiling: the "
        "throughput against k processes smoothing alone (the pipeline reads and writes too); "
        "per core: polygons per CPU second of the workers, which is linear in workers when "
        "it stays the same)"
    )


# ------------------------------------------------------------------------------- main


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=20_000, help="polygons (default 20000)")
    ap.add_argument("--footprints", type=int, default=1_000_000, help="GeoPackage run; 0: skip")
    ap.add_argument("--dask", action="store_true", help="Dask throughput vs workers")
    ap.add_argument(
        "--dask-n", type=int, default=200_000, help="polygons of the Dask run (default 200000)"
    )
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--ring", type=int, default=1_000_000, help="long-ring vertices; 0: skip")
    ap.add_argument("--counties", action="store_true", help="US county coverage (plotly-geo)")
    ap.add_argument("--quick", action="store_true", help="--n 5000 --footprints 0 --ring 1e5")
    args = ap.parse_args()
    if args.quick:
        args.n, args.footprints, args.ring = 5_000, 0, 100_000
    if args.n == 0:  # --n 0: only the other parts asked for (e.g. --counties)
        print("machine: " + f"{os.cpu_count()} cores, load average {os.getloadavg()[0]:.1f}")
        if args.ring:
            bench_ring(args.ring, args.repeats)
        if args.counties:
            bench_counties(args.repeats)
        if args.footprints:
            bench_footprints(args.footprints)
        if args.dask:
            bench_dask(
                footprints(int(args.dask_n * 1.02) + 10, seed=7)[: args.dask_n], args.repeats
            )
        return
    polys = footprints(int(args.n * 1.02) + 10, seed=7)[: args.n]
    n = len(polys)
    nv = int(shapely.get_num_coordinates(polys).sum()) - n
    print(
        f"== {n} polygons, {nv} distinct vertices ({nv / n:.1f} per polygon), {ITER} iterations =="
    )
    print("machine: " + f"{os.cpu_count()} cores, load average {os.getloadavg()[0]:.1f}")

    t0 = time.perf_counter()
    cca.smooth([[0, 0], [1, 0], [0, 1]], closed=True)
    print(
        "first cca call in this process (numba cache load or compile): "
        f"{time.perf_counter() - t0:.2f} s"
    )

    rows = []
    xy = shapely.get_coordinates(polys)
    off = np.concatenate([[0], np.cumsum(shapely.get_num_coordinates(polys))])

    nan = float("nan")
    t, c, res = best_cpu(lambda: geo.smooth(polys, iterations=ITER, full_output=True), args.repeats)
    valid = bool(shapely.is_valid(res.geometry).all())
    rows.append(("geo.smooth (cca), one call", t, c, res.max_area_change, valid))
    t, c, out = best_cpu(lambda: geo.smooth(polys, method="chaikin", iterations=ITER), args.repeats)
    a0 = shapely.area(polys)
    rows.append(
        ("geo.smooth (chaikin), one call", t, c,
         float(np.max(np.abs(shapely.area(out) - a0) / a0)), bool(shapely.is_valid(out).all()))
    )  # fmt: skip
    t, c, _ = best_cpu(
        lambda: cca.smooth_ragged(xy, off, closed=True, iterations=ITER), args.repeats
    )
    rows.append(("cca.smooth_ragged (engine alone)", t, c, nan, None))
    t, c, _ = best_cpu(
        lambda: cca.smooth_ragged(xy, off, closed=True, iterations=ITER, threads=1), args.repeats
    )
    rows.append(("cca.smooth_ragged (engine alone, threads=1)", t, c, nan, None))
    t, c, _ = best_cpu(
        lambda: subdivision.chaikin_ragged(xy, off, closed=True, iterations=ITER), args.repeats
    )
    rows.append(("subdivision.chaikin_ragged (engine alone)", t, c, nan, None))
    k = min(n, 2000)
    t, c, _ = best_cpu(
        lambda: [
            cca.smooth(xy[off[i] : off[i + 1]], closed=True, iterations=ITER) for i in range(k)
        ],
        1,
    )
    rows.append(
        (f"cca.smooth once per polygon ({k} polygons, scaled)", t * n / k, c * n / k, nan, None)
    )

    pg = bench_postgis(polys, args.repeats)
    if pg is not None:
        # PostgreSQL's execution time: its backend is one process doing only this query
        rows.append(
            (f"PostGIS {pg['version']} ST_ChaikinSmoothing (EXPLAIN ANALYZE)", pg["smooth"],
             pg["smooth"], nan, None)
        )  # fmt: skip
        d = pg["smooth"] - pg["scan"]
        rows.append(("PostGIS same, minus the table scan", d, d, nan, None))
        rows.append(("PostGIS sum(ST_NPoints(..)) query, psql wall", pg["full"], nan, nan, None))
    ref, ref_cpu = rows[0][1], rows[0][2]
    peer = pg["smooth"] if pg is not None else None
    print(
        f"\n{'':<52} {'wall s':>7} {'cpu s':>7} {'us/poly':>8} {'cpu us':>7} "
        f"{'x PostGIS':>9} {'cpu x PG':>8} {'max|dA|/A':>10} {'valid':>5}"
    )
    for name, t, c, dA, ok in rows:
        px = f"{t / peer:>9.2f}" if peer else f"{'-':>9}"
        pc = f"{c / peer:>8.2f}" if peer and c == c else f"{'-':>8}"
        da = f"{dA:>10.1e}" if dA == dA else f"{'-':>10}"
        cs = f"{c:>7.3f}" if c == c else f"{'-':>7}"
        cu = f"{c / n * 1e6:>7.2f}" if c == c else f"{'-':>7}"
        print(
            f"{name:<52} {t:>7.3f} {cs} {t / n * 1e6:>8.2f} {cu} {px} {pc} {da} "
            f"{'-' if ok is None else ok!s:>5}"
        )
    if peer:
        print(
            f"\ngeo.smooth / PostGIS per polygon: {ref / peer:.2f} wall, {ref_cpu / peer:.2f} "
            f"cpu (target <= 3, aim 1); the engine alone: {rows[2][1] / peer:.2f} wall, "
            f"{rows[3][2] / peer:.2f} cpu (threads=1)"
        )
    if args.ring:
        bench_ring(args.ring, args.repeats)
    if args.counties:
        bench_counties(args.repeats)
    if args.footprints:
        bench_footprints(args.footprints)
    if args.dask:
        bench_dask(footprints(int(args.dask_n * 1.02) + 10, seed=7)[: args.dask_n], args.repeats)


if __name__ == "__main__":
    sys.exit(main())
