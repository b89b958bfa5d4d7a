"""Smoothing GIS files at scale on Dask (the ``dask`` extra: ``dask[distributed]``).

Features are cut into partitions of ``partition_size`` consecutive features (by default
about 16 partitions, see :func:`features_per_task`); every partition is one task (not one
task per feature) run by a Dask cluster: a local cluster of worker processes by default,
or an existing scheduler given by its address. The output has exactly the input's
features in the input's order. A feature whose smoothing fails is written unchanged and
listed, with the reason, in the errors report — never dropped.

A layer that lives on the workers already (a dask-geopandas collection, read by them
with ``dask_geopandas.read_parquet`` or ``read_file``) is smoothed where it is by
:func:`smooth_collection`: lazily, partition by partition, nothing passing through the
client, so that the throughput grows with the workers.

In coverage mode the arc-node structure is built once (on the client), the arcs are cut
into chunks smoothed in parallel, and conflicts between arcs are resolved on the client
(:func:`curvesmith.geo.smooth_coverage` with a parallel ``map_arcs``). Network mode
(``network=True``) does the same for a line network (:func:`curvesmith.geo.smooth_network`):
it is not partitioned by features, because lines that do not touch must still not come to
touch, so noding and conflict resolution need the whole network.
"""

from __future__ import annotations

import contextlib
import json
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ._validate import as_bool, as_int
from .errors import CurveError, OutputSizeError, require
from .methods import GisMethod

__all__ = ["BatchReport", "FeatureError", "smooth_collection", "smooth_file", "smooth_partitioned"]


@dataclass(frozen=True)
class FeatureError:
    """A feature that could not be smoothed and was written unchanged.

    Attributes
    ----------
    index : int
        Position of the feature in the input (0-based).
    reason : str
        The error message.
    """

    index: int
    reason: str


@dataclass(frozen=True)
class BatchReport:
    """What :func:`smooth_file` did.

    Attributes
    ----------
    n_features : int
        Features read and written (the same, in the same order).
    n_partitions : int
        Tasks submitted (feature partitions, or arc chunks in coverage mode).
    errors : tuple of FeatureError
        Features written unchanged, with the reason.
    errors_path : str or None
        Where the errors report (JSON) was written.
    n_reductions : int
        Pieces smoothed less to keep the output valid.
    seconds : float
        Wall-clock time of the smoothing (reading and writing excluded).
    coverage_valid : bool or None
        Coverage mode: :func:`shapely.coverage_is_valid` on the output.
    geographic : bool
        The input is in longitude/latitude (then, in coverage mode, the arcs are smoothed
        on the client: those on the antimeridian and the poles stay put).
    not_equal_area : tuple of int
        With ``equal_area``: the features smoothed in the file's CRS instead, as in
        :class:`curvesmith.geo.FileSmoothReport` (the projection would fold them).
    network : tuple of int or None
        Network mode: ``(n_lines, n_arcs, n_nodes, n_inserted)`` of
        :class:`curvesmith.geo.NetworkResult`.
    snap_area_change : float
        Coverage mode with ``snap``: the largest relative area change the snapping made
        before the smoothing; 0 without.
    """

    n_features: int
    n_partitions: int
    errors: tuple[FeatureError, ...]
    errors_path: str | None
    n_reductions: int
    seconds: float
    coverage_valid: bool | None
    geographic: bool = False
    not_equal_area: tuple[int, ...] = ()
    network: tuple[int, int, int, int] | None = None
    snap_area_change: float = 0.0


# ---------------------------------------------------------------------------- tasks


def _smooth_partition(
    packet: Any,
    start: int,
    options: dict[str, Any],
    labels: np.ndarray | None = None,
    handover: Any = None,
) -> tuple[Any, list[tuple[int, str]], int]:
    """Smooth one partition; a failing feature is kept unchanged and reported.

    Geometries travel both ways as packets (:mod:`curvesmith.geo._packets`: the ragged
    coordinate arrays of a layer of polygons or lines, WKB or the objects for others),
    their coordinates through shared memory where the client's `handover` folder is on
    this machine (:mod:`curvesmith.geo._handover`). Errors are reported at ``start + k``;
    their messages name the file's feature, ``start + k`` or, when given, ``labels[k]``.
    """
    from . import geo
    from .geo._handover import land, ship
    from .geo._packets import pack, unpack
    from .geo._smooth import smooth_packet

    packet = land(packet, remove=False)
    plain = set(options) <= {"method", "iterations", "alpha", "make_valid"}
    if plain:
        # a layer of Polygons without holes (footprints, parcels): smoothed from the
        # packet's rings to the output's packet, building no polygons on either side
        with contextlib.suppress(Exception):  # (else the usual way, which says why)
            done = smooth_packet(packet, **options)
            if done is not None:
                return ship(done[0], handover, f"out-{start}"), [], len(done[1])
    geoms = unpack(packet)  # any other layer (smooth_packet declines what it cannot do)
    del packet  # a shipped input's mapping
    try:
        res = geo.smooth(geoms, full_output=True, **options)
        return ship(pack(res.geometry), handover, f"out-{start}"), [], len(res.reductions)
    except OutputSizeError:  # feature by feature, the same output would be held
        raise
    except Exception:  # retried in parts below, to isolate the failing ones
        pass
    out, errors, n_red = _smooth_isolating(geoms, options, start, labels)
    return ship(pack(out), handover, f"out-{start}"), errors, n_red


def _smooth_isolating(
    geoms: np.ndarray, options: dict[str, Any], start: int, labels: np.ndarray | None
) -> tuple[np.ndarray, list[tuple[int, str]], int]:
    """:func:`curvesmith.geo.smooth` of features one call failed on; the failing ones kept.

    The features are halved, and each half smoothed in one call, until the halves that
    fail are single features (written unchanged and reported at ``start + k``, named by
    ``labels[k]`` when given): one bad feature among 20,000 costs about two calls' work,
    where a call per feature cost 12-18 times one call. Every feature is smoothed as in
    any other call (a feature's result does not depend on the others).
    """
    from . import geo

    out = np.array(geoms, dtype=object, copy=True)
    errors: list[tuple[int, str]] = []
    n_red = 0
    mid = len(geoms) // 2
    parts = [(mid, len(geoms)), (0, mid)] if len(geoms) > 1 else [(0, len(geoms))]
    while parts:
        a, b = parts.pop()
        if a == b:
            continue
        try:
            res = geo.smooth(geoms[a:b], full_output=True, **options)
        except Exception as exc:  # (one feature's too large output, too)
            if b - a > 1:
                mid = (a + b) // 2
                parts += [(mid, b), (a, mid)]
                continue
            feature = start + a if labels is None else labels[a]  # the file's index, a label
            reason = str(exc).replace("geometry[0]", f"feature {feature}", 1)
            errors.append((start + a, f"{type(exc).__name__}: {reason}"))
            continue
        out[a:b] = res.geometry
        n_red += len(res.reductions)
    return out, errors, n_red


def _smooth_arc_chunk(
    arcs: list[np.ndarray], loops: np.ndarray, frozen: np.ndarray, options: dict[str, Any]
) -> tuple[list[np.ndarray], list[tuple[int, str]]]:
    """Full-strength smoothing of a chunk of coverage arcs; failing arcs stay unchanged."""
    from .geo._coverage import smooth_arc_blocks

    return smooth_arc_blocks(arcs, loops, frozen, **options)


def _smooth_network_chunk(
    arcs: list[np.ndarray], loops: np.ndarray, options: dict[str, Any]
) -> list[np.ndarray]:
    """Full-strength smoothing of a chunk of network arcs.

    The chunks are whole blocks of the one-process run, so the result is the same bit
    for bit.
    """
    from .geo._network import _initial
    from .geo._smooth import make_smoother

    smoother = make_smoother(options["method"], options["alpha"])
    frozen = np.zeros(len(arcs), dtype=bool)
    return _initial(arcs, loops, frozen, smoother=smoother, **options)


# ---------------------------------------------------------------------------- cluster


class _Cluster:
    """A distributed Client on a new local cluster or on an existing scheduler."""

    def __init__(self, workers: int | None, scheduler: str | None):
        distributed = require("distributed", "dask", "batch smoothing")
        self.cluster: Any = None
        self.client: Any = None
        self._environ: _Environ | None = None
        if scheduler is not None:
            try:
                self.client = distributed.Client(scheduler, timeout="20s")
            except OSError as exc:
                raise CurveError(
                    f"cannot connect to the Dask scheduler at {scheduler!r}: {exc}"
                ) from exc
        else:
            import dask

            n = 2 if workers is None else workers
            _quiet_resource_tracker()
            # the Nanny sets its workers' environment in this process's (see _Environ)
            names = [*dask.config.get("distributed.nanny.pre-spawn-environ"), "PYTHONHASHSEED"]
            self._environ = _Environ(names)
            self.cluster = distributed.LocalCluster(
                n_workers=0,
                threads_per_worker=1,
                processes=True,
                dashboard_address=":0",
                silence_logs=40,
                preload=[__name__],  # dask_setup below, in each worker process
            )
            self.client = None
            try:  # a stop or a failure while starting closes what has started, quietly
                self.client = distributed.Client(self.cluster)
                _spawn_deaf_to_ctrl_c(self.cluster, n)
                try:
                    self.client.wait_for_workers(n, timeout=120)
                except TimeoutError as exc:
                    raise CurveError(
                        f"the {n} local Dask worker(s) did not start within 120 s: {exc}"
                    ) from exc
            except BaseException:
                self.close(quiet=True)
                raise
            finally:
                self._environ.restore()

    def close(self, *, quiet: bool = False) -> None:
        """Close the client and the cluster this started.

        `quiet` (the run failed or was stopped): the tasks still in flight lose their
        connections as the cluster goes, and tornado and the scheduler would log an error
        for each; that is not news to the user, whose one line says why the run ended.
        """
        import logging

        level = logging.root.manager.disable
        if quiet:  # tornado's tracebacks, the scheduler's "Couldn't gather keys"
            logging.disable(logging.CRITICAL)
            if self.cluster is not None and self.client is not None:
                with contextlib.suppress(Exception):  # the workers' "failed during get data"
                    self.client.run(_quiet_logs, wait=False)
        try:
            if self.client is not None:
                self.client.close()
            if self.cluster is not None:
                self.cluster.close()
        finally:
            logging.disable(level)
            if self._environ is not None:  # a worker that its Nanny restarted
                self._environ.restore()


class _Environ:
    """The caller's values of the variables a Nanny sets in its own process.

    A Nanny sets ``distributed.nanny.pre-spawn-environ`` (``OMP_NUM_THREADS=1``, malloc
    settings) and ``PYTHONHASHSEED`` in the ``os.environ`` of the process it runs in before
    it spawns its worker: with a local cluster, the caller's. ``default_threads`` of
    :mod:`curvesmith.cca` reads ``OMP_NUM_THREADS``, so everything the caller smoothed after
    a batch run (the arcs of a longitude/latitude coverage, the next call) ran in one
    thread, and the caller's later child processes had a fixed hash seed. :meth:`restore`
    puts the caller's values back.
    """

    def __init__(self, names: Any) -> None:
        import os

        self._saved = {k: os.environ.get(k) for k in names}

    def restore(self) -> None:
        import os

        for k, v in self._saved.items():
            if v is None:
                os.environ.pop(k, None)
            else:
                os.environ[k] = v


def _quiet_resource_tracker() -> None:
    """In the command line: start multiprocessing's resource tracker with its warnings off.

    The tracker (a process of its own) removes the semaphores of worker processes that
    ended without releasing them, and warns of each on stderr; a run stopped by a signal
    (``cli._stop``) ends its workers so, after its one line, which the warning would follow.
    """
    import sys
    from multiprocessing import resource_tracker

    stop = sys.modules.get("curvesmith.cli._stop")
    if not getattr(stop, "_installed", False):  # a library caller's process: its tracker
        return
    saved = list(sys.warnoptions)
    sys.warnoptions.append("ignore::UserWarning")  # the tracker's flags are taken from these
    try:
        resource_tracker.ensure_running()
    finally:
        sys.warnoptions[:] = saved


def _spawn_deaf_to_ctrl_c(cluster: Any, n: int) -> None:
    """Start `n` worker processes of `cluster` that do not hear Ctrl-C.

    Ctrl-C at a terminal is sent to the whole process group: the workers too, and each
    would print a traceback (a worker still starting prints several); the client stops the
    run with one line and closes its cluster, which ends them. SIGINT is ignored while the
    processes are spawned, so that they inherit the ignored disposition through ``exec``
    (Python then installs no handler of its own), and restored as soon as they exist:
    a Ctrl-C in those few milliseconds is lost, none after them.
    """
    import multiprocessing
    import signal
    import threading
    import time

    if (
        threading.current_thread() is not threading.main_thread()  # a library caller's thread
        or signal.getsignal(signal.SIGINT) is None  # a handler not from Python: kept as it is
    ):
        cluster.scale(n)
        return

    def spawned() -> int:
        return sum(
            p.pid not in before and p.name.startswith("Dask Worker")
            for p in multiprocessing.active_children()
        )

    before = {p.pid for p in multiprocessing.active_children()}
    handler = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        cluster.scale(n)
        deadline = time.monotonic() + 10.0
        while spawned() < n and time.monotonic() < deadline:  # else wait_for_workers says
            time.sleep(0.002)
    finally:
        signal.signal(signal.SIGINT, handler)


async def _quiet_logs() -> None:
    """In a worker of a cluster that is being closed after a failure or a stop."""
    import logging

    logging.disable(logging.CRITICAL)


def dask_setup(worker: Any) -> None:
    """Dask's preload hook, in each worker process of a cluster that batch starts itself.

    The worker ignores SIGINT (see :func:`_spawn_deaf_to_ctrl_c`), also when its Nanny
    restarts it after the spawn.
    """
    import signal
    import threading

    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGINT, signal.SIG_IGN)


def _local_scheduler(client: Any) -> bool:
    """Whether `client`'s scheduler listens on a loopback address (or in this process)."""
    import ipaddress
    from urllib.parse import urlsplit

    try:
        address = str(client.scheduler.address)
    except AttributeError:
        return False
    if address.startswith("inproc://"):
        return True
    host = urlsplit(address).hostname or ""
    if host == "localhost":
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False


class _Workers:
    """The Dask client of one batch run: the caller's, or a cluster started when first needed.

    ``with _Workers(client, workers, scheduler) as pool: ... pool.client ...``; a cluster
    this started is closed at the end. Started lazily, so the runs that end up not mapping
    anything (the map-unit bounds, which try every level on the client) start none.
    """

    def __init__(self, client: Any, workers: int | None, scheduler: str | None):
        self._client, self._workers, self._scheduler = client, workers, scheduler
        self._own: _Cluster | None = None
        self._handover: Any = None
        self._ship_inputs = False
        self._stack = contextlib.ExitStack()

    @property
    def client(self) -> Any:
        if self._client is None:
            self._own = _Cluster(self._workers, self._scheduler)
            self._client = self._own.client
        return self._client

    def handover(self) -> tuple[Any, bool]:
        """The run's shared-memory folder (:mod:`curvesmith.geo._handover`), made at first use.

        Returns the folder (None where there is no shared memory) and whether the inputs
        may travel through it too: only when every worker, also one that joins later, is
        on this machine, which a scheduler on a loopback address proves (a local
        cluster: remote workers cannot reach it). Each worker decides for its results
        itself (the folder's token).
        """
        from .geo import _handover
        from .io._core import in_flight

        client = self.client
        if self._handover is None:
            self._handover = _handover.open_handover()
            if self._handover is not None:
                self._stack.callback(_handover.close, self._handover)
                self._stack.enter_context(in_flight(self._handover.folder))
                self._ship_inputs = _local_scheduler(client)
        return self._handover, self._ship_inputs

    def __enter__(self) -> _Workers:
        return self

    def __exit__(self, *exc) -> None:
        try:
            if self._own is not None:
                self._own.close(quiet=exc[0] is not None)
        finally:  # after the workers: none writes into the folder any more
            self._stack.close()


def _run(
    client,
    fn: Callable,
    args: Iterable[tuple],
    progress: bool,
    on_result: Callable[[int, Any], None] | None = None,
    *,
    total: int | None = None,
) -> list[Any]:
    """Submit one task per argument tuple, show a progress bar, return the results in order.

    `args` may be a generator: each task is submitted as soon as its arguments exist, so
    the workers start on the first partition while the client still packs the others.
    Results are taken as they arrive, in whatever order the tasks finish; with
    `on_result`, each is handed to ``on_result(k, result)`` (task ``k``) at once and
    released, so the client decodes results while the workers still compute, and the
    list returned is empty. The progress bar (`total` tasks, default ``len(args)``) is
    drawn by the client as results arrive, in Dask's format
    (``[####    ] | 42% Completed |  1.2s``, which the QGIS plugin reads).
    """
    distributed = require("distributed", "dask", "batch smoothing")
    n = len(args) if total is None else total  # type: ignore[arg-type]
    bar = _ProgressBar(n) if progress else None
    arriving = distributed.as_completed(with_results=True)
    task: dict[str, int] = {}
    for k, a in enumerate(args):
        future = client.submit(fn, *a, pure=False)
        task[future.key] = k
        arriving.add(future)
        del future
    results: list[Any] = [None] * len(task) if on_result is None else []
    try:
        for future, result in arriving:
            k = task.pop(future.key)
            if on_result is None:
                results[k] = result
            else:
                on_result(k, result)
            del future, result
            if bar is not None:
                bar.step()
    finally:  # a failed task's error, or a stop, is then a line of its own
        if bar is not None:
            bar.close()
    return results


class _ProgressBar:
    """A text progress bar on stderr, redrawn after a carriage return (Dask's format).

    ``line_open`` is True while a bar's line has no newline yet: a message written then
    (the CLI's error line, the watchdog's stop line) starts a line of its own.
    """

    WIDTH = 40
    line_open = False

    def __init__(self, total: int) -> None:
        import time

        self.total, self.done, self.t0 = max(int(total), 1), 0, time.perf_counter()
        self._draw()

    def step(self) -> None:
        self.done += 1
        self._draw()

    def close(self) -> None:
        import sys

        if _ProgressBar.line_open:
            sys.stderr.write("\n")
            sys.stderr.flush()
            _ProgressBar.line_open = False

    def _draw(self) -> None:
        import sys
        import time

        frac = min(self.done / self.total, 1.0)
        bar = "#" * round(frac * self.WIDTH)
        took = time.perf_counter() - self.t0
        sys.stderr.write(
            f"\r[{bar:<{self.WIDTH}}] | {int(100 * frac):3d}% Completed | {took:4.1f}s"
        )
        sys.stderr.flush()
        _ProgressBar.line_open = True


# ---------------------------------------------------------------------------- API

#: Tasks a layer is cut into by default (:func:`features_per_task`): enough for the
#: workers to share the load when tasks take unequal times, few enough that Dask's cost per
#: task (scheduling, a transfer each way) stays small beside the smoothing.
AUTO_TASKS = 16

#: Bounds of the default partition size, in features. Measured on 398,222 footprints
#: (2 workers, 2 iterations): 1,000 per task (399 tasks) smoothed in 12.6 s, 20,000 per
#: task in 7.7 s.
MIN_PARTITION, MAX_PARTITION = 1000, 50_000


def features_per_task(partition_size: int | None, n: int) -> int:
    """The partition size: `partition_size` as given, else about :data:`AUTO_TASKS` tasks."""
    if partition_size is not None:
        return as_int(partition_size, name="partition_size", minimum=1)
    return int(min(max(-(-n // AUTO_TASKS), MIN_PARTITION), MAX_PARTITION))


def smooth_partitioned(
    geometry: Any,
    *,
    method: GisMethod = "cca",
    iterations: int = 1,
    alpha: Any = "regular",
    make_valid: bool = False,
    partition_size: int | None = None,
    workers: int | None = None,
    scheduler: str | None = None,
    client: Any = None,
    progress: bool = False,
    fixed: Any = None,
    keep_angle: float | None = None,
    max_shift: float | None = None,
    min_segment: float | None = None,
) -> tuple[Any, tuple[FeatureError, ...], int, int]:
    """Smooth features (array, GeoSeries or GeoDataFrame) on Dask, partition by partition.

    Parameters
    ----------
    geometry : sequence of shapely geometries, GeoSeries or GeoDataFrame
        The features; the output has the same type, order, index, columns and CRS.
    method, iterations, alpha, make_valid
        As in :func:`curvesmith.geo.smooth`.
    partition_size : int, optional
        Features per task. Default: about :data:`AUTO_TASKS` tasks, of
        :data:`MIN_PARTITION` to :data:`MAX_PARTITION` features each.
    workers : int, optional
        Worker processes of the local cluster (default 2).
    scheduler : str, optional
        Address of an existing Dask scheduler (e.g. ``"tcp://127.0.0.1:8786"``).
    client : distributed.Client, optional
        An existing client (then ``workers``/``scheduler`` are ignored).
    progress : bool
        Show a progress bar on the terminal.
    fixed : bool mask or callable, optional
        Vertices that stay put, as in :func:`curvesmith.geo.smooth` (a callable is sent to
        every partition; a mask over the whole input is not supported here).
    keep_angle : float, optional
        Keep sharp corners (radians), as in :func:`curvesmith.geo.smooth`.
    max_shift, min_segment : float, optional
        Strength and vertex budget per feature, as in :func:`curvesmith.geo.smooth`.

    Returns
    -------
    smoothed : object
        Same type as the input.
    errors : tuple of FeatureError
        Features written unchanged.
    n_partitions : int
        Tasks submitted.
    n_reductions : int
        Pieces smoothed less to keep features valid.
    """
    from .geo._smooth import as_geometry_array, check_layer_size, check_method

    iterations = check_method(method, iterations, alpha)
    make_valid = as_bool(make_valid, name="make_valid")
    geoms, wrap = as_geometry_array(geometry)
    # the output is gathered here: the whole layer's, as geo.smooth would hold it
    bounded = max_shift is not None or min_segment is not None
    check_layer_size(geoms, method, iterations, levels=bounded)
    partition_size = features_per_task(partition_size, len(geoms))
    if workers is not None:
        workers = as_int(workers, name="workers", minimum=1)
    options = {"method": method, "iterations": iterations, "alpha": alpha, "make_valid": make_valid}
    if fixed is not None:
        options["fixed"] = fixed
    # corners and bounds partition by partition: they are per feature anyway
    for key, value in (
        ("keep_angle", keep_angle),
        ("max_shift", max_shift),
        ("min_segment", min_segment),
    ):
        if value is not None:
            options[key] = value
    from .geo._handover import discard, land, ship
    from .geo._packets import pack, unpack

    starts = list(range(0, len(geoms), partition_size))
    out = np.array(geoms, dtype=object, copy=True)
    errors: list[FeatureError] = []
    n_red = 0
    inputs: dict[int, Any] = {}

    def take(k: int, result) -> None:
        nonlocal n_red
        packet, errs, nr = result
        out[starts[k] : starts[k] + len(packet)] = unpack(land(packet, remove=True))
        discard(inputs.pop(k))
        errors.extend(FeatureError(i, r) for i, r in errs)
        n_red += nr

    with _Workers(client, workers, scheduler) as pool:
        if starts:
            handover, ship_inputs = pool.handover()

            def submitted():  # packed as submitted, while the workers start on the first
                for k, s in enumerate(starts):
                    packet = pack(geoms[s : s + partition_size])
                    inputs[k] = ship(packet, handover if ship_inputs else None, f"in-{s}")
                    yield inputs[k], s, options, None, handover

            _run(
                pool.client, _smooth_partition, submitted(), progress, on_result=take,
                total=len(starts),
            )  # fmt: skip
    errors.sort(key=lambda e: e.index)
    return wrap(out), tuple(errors), len(starts), n_red


def smooth_collection(
    frame: Any,
    *,
    method: GisMethod = "cca",
    iterations: int = 1,
    alpha: Any = "regular",
    make_valid: bool = False,
    fixed: Any = None,
    keep_angle: float | None = None,
    max_shift: float | None = None,
    min_segment: float | None = None,
    errors: str | None = "smooth_error",
) -> Any:
    """Smooth a dask-geopandas GeoDataFrame or GeoSeries: lazily, each partition where it is.

    The Dask way of :func:`smooth_partitioned`, for layers that live on the workers (read
    by them with ``dask_geopandas.read_parquet`` or ``read_file``, written by them with
    ``to_parquet``): every partition is smoothed by the worker that holds it, as
    :func:`smooth_partitioned` smooths one, and nothing passes through the client, so
    the throughput grows with the workers. The result is lazy, like every Dask
    collection: ``.persist()``, ``.compute()`` or ``.to_parquet(...)`` runs it.

    Parameters
    ----------
    frame : dask_geopandas.GeoDataFrame or dask_geopandas.GeoSeries
        The features (``dask_geopandas.from_geopandas(df, npartitions=...)`` makes one
        of a GeoDataFrame in memory).
    method, iterations, alpha, make_valid, fixed, keep_angle, max_shift, min_segment
        As in :func:`smooth_partitioned` (``fixed``: None or a callable, sent to every
        partition). They are checked here, before anything runs: one square is smoothed
        with them (a callable runs on it). In a geographic CRS (longitude/latitude)
        ``fixed`` defaults to :func:`curvesmith.geo.domain_fixed` (with cca the
        antimeridian and the poles stay put, as ``curvesmith smooth`` keeps them), the
        output is put back inside ±180° / ±90° where rounding took it a hair beyond
        (:func:`curvesmith.geo.clamp_to_domain`), and a
        :class:`~curvesmith.geo.GeographicCRSWarning` says that the smoothing works in
        degrees.
    errors : str or None
        Name of a column added to the result: the reason a feature was left unchanged
        (as :class:`FeatureError` says it), None where it was smoothed. With None, no
        column is added and a feature that fails makes the computation raise its error.

    Returns
    -------
    dask_geopandas.GeoDataFrame
        The input's partitions, index, columns and CRS, the geometries smoothed (a
        GeoSeries becomes a frame of its one column; Points and MultiPoints pass through
        unchanged, as in ``smooth_file``), and the `errors` column.

    Raises
    ------
    CurveError
        `frame` is not a dask-geopandas collection (or has no active geometry), an
        option is invalid, or `errors` is not a new column's name.
    OutputSizeError
        `iterations` would give even one square more vertices than a call may hold.
    """
    dask_geopandas = require("dask_geopandas", "dask", "smoothing a Dask collection")
    from .geo._smooth import check_method

    iterations = check_method(method, iterations, alpha)
    if isinstance(frame, dask_geopandas.GeoSeries):
        frame = frame.to_frame()
    if not isinstance(frame, dask_geopandas.GeoDataFrame):
        raise CurveError(
            f"frame must be a dask_geopandas GeoDataFrame or GeoSeries, got "
            f"{type(frame).__name__} (in memory: smooth_partitioned, or "
            f"dask_geopandas.from_geopandas(df, npartitions=...))"
        )
    try:
        frame._meta.geometry  # noqa: B018 (geopandas raises without an active geometry)
    except AttributeError:
        raise CurveError(
            f"frame has no active geometry column (columns {list(frame.columns)}): choose "
            f"one with frame.set_geometry(name)"
        ) from None
    if fixed is not None and not callable(fixed):
        raise CurveError(
            f"fixed must be None or a callable here (a mask over the whole layer cannot "
            f"be cut into the partitions), got {type(fixed).__name__}"
        )
    if errors is not None and not (isinstance(errors, str) and errors):
        raise CurveError(f"errors must be a column name (a str) or None, got {errors!r}")
    if errors is not None and errors in frame.columns:
        raise CurveError(f"errors names a column of the frame already: {errors!r}")
    options: dict[str, Any] = {
        "method": method, "iterations": iterations, "alpha": alpha,
        "make_valid": as_bool(make_valid, name="make_valid"),
    }  # fmt: skip
    for key, value in (
        ("fixed", fixed),
        ("keep_angle", keep_angle),
        ("max_shift", max_shift),
        ("min_segment", min_segment),
    ):
        if value is not None:
            options[key] = value
    crs = frame.crs
    geographic = bool(crs is not None and crs.is_geographic and iterations > 0)
    if geographic:
        import warnings

        from . import methods
        from .geo._io import GeographicCRSWarning, domain_fixed

        cca_like = methods.get(method).keeps_vertices  # (Chaikin's averages stay inside)
        if fixed is None:  # as curvesmith smooth and smooth_file do for such layers
            options["fixed"] = domain_fixed(crs)
        what = "keeps planar areas in degrees, not ground areas" if cca_like else "works in degrees"
        kept = "; vertices on the antimeridian and the poles stay put" * (cca_like and not fixed)
        warnings.warn(
            f"the frame is in a geographic CRS ({crs.name}): smoothing {what} (smooth "
            f"frame.to_crs(an equal-area CRS) for ground areas){kept}",
            GeographicCRSWarning,
            stacklevel=2,
        )
    _try_options(options, geographic)
    meta = frame._meta.copy()
    if errors is not None:
        meta[errors] = _reasons([], 0)
    return frame.map_partitions(_smooth_frame, options, errors, geographic, meta=meta)


def _try_options(options: dict[str, Any], geographic: bool) -> None:
    """Smooth one small square with `options`, so that bad options fail before any task.

    Every option is checked by :func:`curvesmith.geo.smooth` as it runs; a callable
    ``alpha`` or ``fixed`` runs too, and iterations whose output no feature could hold
    (even a square's) are refused.
    """
    import shapely

    from . import geo

    square = shapely.box(10.0, 10.0, 11.0, 11.0) if geographic else shapely.box(0, 0, 1, 1)
    try:
        geo.smooth(np.array([square], dtype=object), **options)
    except OutputSizeError as exc:
        raise OutputSizeError(f"{exc} (tried on one square before anything runs)") from None
    except CurveError as exc:
        raise CurveError(f"{exc} (tried on one square before anything runs)") from None
    except Exception as exc:  # a callable of the caller's that fails
        raise CurveError(
            f"the options fail on one square before anything runs: {type(exc).__name__}: {exc}"
        ) from exc


def _smooth_frame(part: Any, options: dict[str, Any], errors: str | None, geographic: bool) -> Any:
    """One partition of :func:`smooth_collection`, smoothed as :func:`smooth_partitioned`'s.

    Points and MultiPoints pass through unchanged (nothing to smooth), as ``smooth_file``
    and ``curvesmith smooth`` pass them; in lon/lat, vertices a rounding error beyond
    ±180° / ±90° are put back on the edge (:func:`curvesmith.geo.clamp_to_domain`).
    """
    import shapely

    from .geo._packets import pack, unpack

    geoms = np.asarray(part.geometry.values, dtype=object)
    points = np.isin(shapely.get_type_id(geoms), (0, 4))  # Point, MultiPoint
    work = geoms
    if points.any():
        work = geoms.copy()
        work[points] = None
    packet, failed, _ = _smooth_partition(pack(work), 0, options, part.index.to_numpy())
    if errors is None and failed:
        reason = failed[0][1]
        raise CurveError(reason.removeprefix(f"{CurveError.__name__}: "))
    smoothed = unpack(packet)
    if points.any():
        smoothed = np.where(points, geoms, smoothed)
    if geographic:
        from .geo._io import clamp_to_domain

        smoothed = clamp_to_domain(smoothed, "the frame", geoms)
    out = part.copy()
    out[part.geometry.name] = smoothed
    if errors is not None:
        out[errors] = _reasons(failed, len(part), part.index)
    return out


def _reasons(failed: list[tuple[int, str]], n: int, index: Any = None) -> Any:
    """The errors column of :func:`smooth_collection`: strings, missing where none failed."""
    import pandas as pd

    reasons = np.full(n, None, dtype=object)
    for k, reason in failed:
        reasons[k] = reason
    return pd.Series(reasons, index=index, dtype="string")


def smooth_file(
    in_path: str | Path,
    out_path: str | Path,
    *,
    method: GisMethod = "cca",
    iterations: int = 1,
    alpha: Any = "regular",
    layer: str | int | None = None,
    coverage: bool = False,
    network: bool = False,
    equal_area: bool = False,
    make_valid: bool = False,
    snap: float | None = None,
    partition_size: int | None = None,
    workers: int | None = None,
    scheduler: str | None = None,
    client: Any = None,
    progress: bool = True,
    errors_path: str | Path | None = None,
    keep_angle: float | None = None,
    max_shift: float | None = None,
    min_segment: float | None = None,
) -> BatchReport:
    """Smooth a GIS file on Dask and write the result and an errors report.

    Parameters
    ----------
    in_path, out_path : str or Path
        GeoPackage, Shapefile, GeoJSON or FlatGeobuf (see :func:`curvesmith.geo.read_file`).
    method, iterations, alpha, make_valid
        As in :func:`curvesmith.geo.smooth`.
    layer : str or int, optional
        Input layer.
    coverage : bool
        Coverage mode (:func:`curvesmith.geo.smooth_coverage`), parallel over arcs.
    network : bool
        Line network mode (:func:`curvesmith.geo.smooth_network`): the whole network is
        noded and cut into arcs on the client (a network cannot be cut into independent
        parts by features: lines that do not touch still must not come to touch), the
        full-strength smoothing of the arcs runs in parallel in chunks of whole blocks
        (the same bits as one process), and conflicts are resolved on the client. The
        output equals ``curvesmith smooth --network``.
    equal_area : bool
        Smooth in an equal-area projection and transform back.
    snap : float, optional
        Coverage mode: snapping distance for :func:`shapely.coverage_clean`.
    partition_size : int, optional
        Features per task, by default as in :func:`smooth_partitioned`; arcs per task in
        coverage and network mode (default :data:`MIN_PARTITION`).
    workers : int, optional
        Worker processes of the local cluster (default 2).
    scheduler : str, optional
        Address of an existing Dask scheduler instead of a local cluster.
    client : distributed.Client, optional
        An existing client.
    progress : bool
        Show a progress bar on the terminal.
    keep_angle : float, optional
        Keep sharp corners (radians), as in :func:`curvesmith.geo.smooth`.
    max_shift, min_segment : float, optional
        Strength and vertex budget, as in :func:`curvesmith.geo.smooth` (per feature),
        :func:`curvesmith.geo.smooth_coverage` and :func:`curvesmith.geo.smooth_network`
        (per arc; there every level of all arcs is tried in one ragged call on the client).
    errors_path : str or Path, optional
        Where to write the errors report (JSON list of ``{"index", "reason"}``);
        default ``OUT.errors.json`` beside the output. Always written.

    Returns
    -------
    BatchReport
    """
    import time
    import warnings

    import shapely

    from . import geo
    from .geo._io import (
        GeographicCRSWarning,
        _write_file,
        check_layers_kept,
        check_network_back,
        clamp_to_domain,
        densify_tolerance,
        domain_fixed,
        feature_ids,
        geographic_message,
        input_layer_name,
        is_equal_area_crs,
        projected_budget,
        put_points_back,
        set_points_aside,
        to_one_equal_area,
    )

    if partition_size is not None:
        partition_size = as_int(partition_size, name="partition_size", minimum=1)
    make_valid = as_bool(make_valid, name="make_valid")
    from .io._core import check_destination

    if errors_path is None:
        errors_path = Path(str(out_path) + ".errors.json")
    check_destination(errors_path)  # before the work: a report that cannot be written
    out_layer = input_layer_name(in_path, layer)
    check_layers_kept(out_path, out_layer)  # nor a GeoPackage whose other layers would go
    budget = {k: v for k, v in (("max_shift", max_shift), ("min_segment", min_segment)) if v}
    if network and (coverage or make_valid or snap is not None):
        what = "coverage" if coverage else ("make_valid" if make_valid else "snap")
        raise CurveError(f"network mode does not take {what} (it smooths lines, not polygons)")
    df = geo.read_file(in_path, layer=layer)
    ids = feature_ids(in_path, layer) if str(out_path).lower().endswith(".gpkg") else None
    crs = df.crs
    # points have nothing to smooth: set aside like NULLs, written back unchanged (as geo's
    # smooth_file does; a network's points stay in it, as its nodes)
    df, kept, points = set_points_aside(df, keep=not network)
    # an empty geometry is written back as it was read, as geo's smooth_file does (GDAL
    # stores POLYGON EMPTY of a MultiPolygon layer as MULTIPOLYGON(POLYGON EMPTY))
    untouched = points | shapely.is_empty(kept)
    if equal_area and crs is None:
        raise CurveError(f"equal_area needs a CRS, but {str(in_path)!r} has none")
    if equal_area and is_equal_area_crs(crs):
        equal_area = False  # already in an equal-area projection: smoothed in it
    if crs is not None and crs.is_geographic and not equal_area and iterations > 0:
        message = geographic_message(str(in_path), crs.name)
        warnings.warn(message, GeographicCRSWarning, stacklevel=2)
    # feature by feature, equal-area smoothing is per region (geo's smooth_file): one
    # projection for the world folds some features and distorts ground areas far away
    regional = equal_area and not (coverage or network)
    work = df
    if equal_area and not regional:  # one projection for the whole coverage or network
        tolerance = densify_tolerance(max_shift)  # max_shift in ground metres: as geo's
        work = to_one_equal_area(
            df, mode="network" if network else "coverage", name=str(in_path), tolerance=tolerance
        )
        if max_shift:
            budget["max_shift"] = projected_budget(work.geometry.values, max_shift, tolerance)
    t0 = time.perf_counter()
    not_equal_area: tuple[int, ...] = ()
    network_counts: tuple[int, int, int, int] | None = None
    snap_change = 0.0
    if regional:
        if snap is not None:
            raise CurveError("snap applies to coverage mode only (coverage=True)")
        out, errors, n_tasks, n_red, not_equal_area = _equal_area_on_dask(
            df,
            options={"method": method, "iterations": iterations, "alpha": alpha}
            | ({} if keep_angle is None else {"keep_angle": keep_angle})
            | budget,
            make_valid=make_valid,
            partition_size=partition_size,
            workers=workers,
            scheduler=scheduler,
            client=client,
            progress=progress,
        )
        valid = None
    elif network:
        out, n_tasks, n_red, network_counts = _network_on_dask(
            work,
            method=method,
            iterations=iterations,
            alpha=alpha,
            keep_angle=keep_angle,
            budget=budget,
            chunk=partition_size or MIN_PARTITION,
            workers=workers,
            scheduler=scheduler,
            client=client,
            progress=progress,
        )
        errors, valid = (), None
    elif coverage:
        out, errors, n_tasks, n_red, valid, snap_change = _coverage_on_dask(
            work,
            method=method,
            iterations=iterations,
            alpha=alpha,
            make_valid=make_valid,
            snap=snap,
            keep_angle=keep_angle,
            budget=budget,
            chunk=partition_size or MIN_PARTITION,
            workers=workers,
            scheduler=scheduler,
            client=client,
            progress=progress,
            # lon/lat: the antimeridian and the poles stay put, as in geo's smooth_file
            # (smooth_coverage then smooths the arcs on the client)
            fixed=domain_fixed(crs, work.crs) if crs is not None and crs.is_geographic else None,
        )
    else:
        if snap is not None:
            raise CurveError("snap applies to coverage mode only (coverage=True)")
        out, errors, n_tasks, n_red = smooth_partitioned(
            work,
            method=method,
            iterations=iterations,
            alpha=alpha,
            make_valid=make_valid,
            partition_size=partition_size,
            workers=workers,
            scheduler=scheduler,
            client=client,
            progress=progress,
            # lon/lat: the antimeridian and the poles stay put (as in geo's smooth_file)
            fixed=domain_fixed(crs, work.crs) if crs is not None and crs.is_geographic else None,
            keep_angle=keep_angle,
            **budget,
        )
        valid = None
    seconds = time.perf_counter() - t0
    if equal_area and not regional:
        out = out.to_crs(crs)
        if network:
            check_network_back(df.geometry, out.geometry, name=str(in_path))
    if crs is not None and crs.is_geographic:
        out = out.copy()
        out.geometry = clamp_to_domain(out.geometry, str(in_path), df.geometry)
    out = put_points_back(out, kept, untouched)
    del kept
    _write_file(out, out_path, layer=out_layer, fids=ids)  # the GeoPackage's ids kept
    Path(errors_path).write_text(
        json.dumps([{"index": e.index, "reason": e.reason} for e in errors], indent=1) + "\n"
    )
    return BatchReport(
        n_features=len(out),
        n_partitions=n_tasks,
        errors=tuple(errors),
        errors_path=str(errors_path),
        n_reductions=n_red,
        seconds=seconds,
        coverage_valid=valid,
        geographic=bool(crs is not None and crs.is_geographic),
        not_equal_area=not_equal_area,
        network=network_counts,
        snap_area_change=snap_change,
    )


def _equal_area_on_dask(
    df: Any,
    *,
    options: dict[str, Any],
    make_valid: bool,
    partition_size: int | None,
    workers: int | None,
    scheduler: str | None,
    client: Any,
    progress: bool,
) -> tuple[Any, tuple[FeatureError, ...], int, int, tuple[int, ...]]:
    """Per-region equal-area smoothing (geo's) with each region's features smoothed on Dask.

    The regions, projections and the checks back home are geo's (the same result as
    :func:`curvesmith.geo.smooth_file` with ``equal_area=True``, feature for feature);
    the projected features of every region go to the workers in partitions.
    """
    from .geo._handover import discard, land, ship
    from .geo._io import _smooth_equal_area
    from .geo._packets import pack, unpack
    from .geo._smooth import check_method

    check_method(options["method"], options["iterations"], options["alpha"])
    errors: list[tuple[int, str]] = []
    n_tasks = 0
    pool = _Workers(client, workers, scheduler)

    def smoother(jobs):
        nonlocal n_tasks
        # the client and the handover folder only when there is something to send
        handover, ship_inputs = pool.handover() if any(len(j[0]) for j in jobs) else (None, False)
        args, where = [], []
        for k, (geoms, labels, extra) in enumerate(jobs):
            size = features_per_task(partition_size, len(geoms))
            for s in range(0, len(geoms), size):
                opts = {**options, "make_valid": make_valid, **extra}
                part = ship(pack(geoms[s : s + size]), handover if ship_inputs else None, "in")
                args.append((part, s, opts, labels[s : s + size], handover))
                where.append((k, s))
        n_tasks += len(args)
        outs = [[np.array(g, dtype=object, copy=True), 0, []] for g, _, _ in jobs]

        def take(t: int, result) -> None:
            (k, s), (packet, errs, nr) = where[t], result
            outs[k][0][s : s + len(packet)] = unpack(land(packet, remove=True))
            discard(args[t][0])
            outs[k][1] += nr
            outs[k][2] += errs

        if args:
            _run(pool.client, _smooth_partition, args, progress, on_result=take)
        return [(out, n_red, sorted(errs)) for out, n_red, errs in outs]

    with pool:
        out, n_red, _, planar = _smooth_equal_area(
            df, make_valid=make_valid, smoother=smoother, errors=errors, **options
        )
    errs = tuple(FeatureError(i, r) for i, r in sorted(errors))
    return out, errs, n_tasks, n_red, tuple(planar)


def _coverage_on_dask(
    df,
    *,
    method,
    iterations,
    alpha,
    make_valid,
    snap,
    chunk,
    workers,
    scheduler,
    client,
    progress,
    keep_angle=None,
    budget=None,
    fixed=None,
):
    from . import geo

    pool = _Workers(client, workers, scheduler)
    arc_errors: list[tuple[int, str]] = []
    n_tasks = 0
    seen: dict[str, Any] = {}

    def map_arcs(topo) -> list[np.ndarray]:
        nonlocal n_tasks
        seen["topo"] = topo
        from .geo._coverage import ARC_BLOCK

        options = {"method": method, "iterations": iterations, "alpha": alpha}
        step = -(-chunk // ARC_BLOCK) * ARC_BLOCK  # whole blocks: same result as 1 process
        starts = list(range(0, len(topo.arcs), step))
        args = [
            (
                list(topo.arcs[s : s + step]),
                topo.loops[s : s + step],
                topo.frozen[s : s + step],
                options,
            )
            for s in starts
        ]
        n_tasks = len(args)
        results = _run(pool.client, _smooth_arc_chunk, args, progress)
        out: list[np.ndarray] = []
        for s, (arcs, errs) in zip(starts, results, strict=True):
            out += arcs
            arc_errors.extend((s + k, r) for k, r in errs)
        return out

    with pool:
        res = geo.smooth_coverage(
            df,
            method=method,
            iterations=iterations,
            alpha=alpha,
            snap=snap,
            make_valid=make_valid,
            full_output=True,
            map_arcs=map_arcs,
            keep_angle=keep_angle,
            fixed=fixed,
            **(budget or {}),
        )
    errors: list[FeatureError] = []
    if arc_errors:
        import shapely

        geoms = np.asarray(df.geometry.values, dtype=object)
        present = np.array([g is not None and not shapely.is_empty(g) for g in geoms])
        idx = np.nonzero(present)[0]  # smooth_coverage numbers the non-empty features
        for arc, reason in arc_errors:
            for p in seen["topo"].arc_polygons[arc]:
                errors.append(FeatureError(int(idx[p]), f"arc {arc} left unchanged: {reason}"))
        errors.sort(key=lambda e: e.index)
    return (
        res.geometry, tuple(errors), n_tasks, len(res.reductions), res.coverage_valid,
        float(res.snap_area_change),
    )  # fmt: skip


def _network_on_dask(
    df,
    *,
    method,
    iterations,
    alpha,
    chunk,
    workers,
    scheduler,
    client,
    progress,
    keep_angle=None,
    budget=None,
):
    from . import geo
    from .geo._network import ARC_BLOCK

    pool = _Workers(client, workers, scheduler)
    n_tasks = 0

    def map_arcs(topo, frozen) -> list[np.ndarray]:
        nonlocal n_tasks
        options = {"method": method, "iterations": iterations, "alpha": alpha}
        loops = np.asarray(topo.loops, dtype=bool)
        todo = ~np.asarray(frozen, dtype=bool)
        groups = []
        if method == "cca":  # open arcs are smoothed in blocks of ARC_BLOCK: chunks of whole ones
            step = -(-chunk // ARC_BLOCK) * ARC_BLOCK
            open_idx, loop_idx = np.flatnonzero(todo & ~loops), np.flatnonzero(todo & loops)
            groups += [open_idx[s : s + step] for s in range(0, len(open_idx), step)]
        else:
            loop_idx = np.flatnonzero(todo)  # one arc at a time anyway
        groups += [loop_idx[s : s + chunk] for s in range(0, len(loop_idx), chunk)]
        args = [([topo.arcs[k] for k in g], loops[g], options) for g in groups]
        n_tasks = len(args)
        out = list(topo.arcs)
        for g, arcs in zip(
            groups, _run(pool.client, _smooth_network_chunk, args, progress), strict=True
        ):
            for k, xy in zip(g, arcs, strict=True):
                out[k] = xy
        return out

    with pool:
        res = geo.smooth_network(
            df,
            method=method,
            iterations=iterations,
            alpha=alpha,
            full_output=True,
            map_arcs=None if budget else map_arcs,  # the bounds try every level at once
            keep_angle=keep_angle,
            **(budget or {}),
        )
    counts = (res.n_lines, res.n_arcs, res.n_nodes, res.n_inserted)
    return res.geometry, n_tasks, len(res.reductions), counts
