"""Packets handed between the processes of one machine through shared memory.

A Dask worker sends its result to the client through a socket: pickled, copied into the
kernel, copied out again on the other side, each copy in memory that is new to the
process. A smoothed layer is several times the size of its input (CCA makes three points
per vertex and step: 2 iterations of 200,000 footprints are 272 MB of coordinates), and on
a 2-core machine those copies cost the worker a third of its time and the client more than
it spends building the output geometries.

Processes of one machine can do better: the worker writes a packet's coordinates into a
file of a folder in ``/dev/shm`` (memory, not disk) and sends only the file's name; the
client maps the file and reads the coordinates in place. A :class:`Handover` is such a
folder, made by the client for one run and removed with everything in it at the end (and
by the stop watchdog of the CLI). Whether a worker can use it is proven, not guessed: the
folder holds a random token, and a process that reads the same token from the same path
shares the machine's memory with the client.

Anything that cannot go this way goes the usual way, with the same bits: a machine without
``/dev/shm``, a worker on another machine, a full or read-only ``/dev/shm`` (a container's
is often 64 MB: a failed write is caught, never a SIGBUS, because files are written with
``write``, not through a mapping), and packets too small for a file to pay.
"""

from __future__ import annotations

import contextlib
import dataclasses
import mmap
import os
import secrets
import shutil
import tempfile
import threading
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ._packets import GeometryPacket

__all__ = [
    "Handover",
    "Shipped",
    "close",
    "discard",
    "land",
    "open_handover",
    "process_started",
    "reachable",
    "ship",
]

#: Where the folders are made: a tmpfs on Linux (memory, not disk).
SHARED_MEMORY = "/dev/shm"

#: Coordinate arrays smaller than this travel in the packet (a file costs tens of µs).
MIN_BYTES = 1 << 16

_TOKEN = "token"


@dataclass(frozen=True)
class Handover:
    """A folder in shared memory for one run, and the token that proves a process sees it.

    Attributes
    ----------
    folder : str
        The folder (in :data:`SHARED_MEMORY`).
    token : str
        The random contents of the folder's file ``token``.
    """

    folder: str
    token: str


@dataclass(frozen=True)
class Shipped:
    """A packet whose coordinates wait in a file of a :class:`Handover`.

    Attributes
    ----------
    packet : GeometryPacket
        The packet, its ``coords`` empty.
    path : str
        The file holding the coordinates (float64, C order).
    shape : tuple of int
        The shape of the coordinates.
    """

    packet: GeometryPacket
    path: str
    shape: tuple[int, ...]

    def __len__(self) -> int:
        return len(self.packet)


#: A folder whose maker is gone is removed by the next run once it has not changed for
#: this long (seconds): a run in another PID namespace that shares ``/dev/shm`` (where its
#: maker's pid means nothing here) writes a file per task, so its folder stays newer.
STALE_AFTER = 600.0

#: Free room a handover leaves in ``/dev/shm`` (bytes, and the fraction of its size, the
#: larger): other programs (multiprocessing's semaphores, Dask's restarts) need it too.
FREE_BYTES, FREE_FRACTION = 64 << 20, 0.05


def process_started(pid: int) -> str | None:
    """The start time of process `pid` (``/proc/PID/stat``), or None if there is none."""
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return None
    return stat.rsplit(")", 1)[-1].split()[19]  # field 22, after the command's parentheses


def _sweep() -> None:
    """Remove the handover folders that a killed run left (SIGKILL, the OOM killer)."""
    now = time.time()
    for folder in Path(SHARED_MEMORY).glob("curvesmith-*"):
        try:
            info = folder.stat()
            if info.st_uid != os.getuid() or now - info.st_mtime < STALE_AFTER:
                continue
            lines = (folder / _TOKEN).read_text().split()
        except (OSError, UnicodeDecodeError):
            lines = []  # no token: a folder being closed, or never opened
        if len(lines) == 3 and process_started(int(lines[1])) == lines[2]:
            continue  # its maker still runs
        shutil.rmtree(folder, ignore_errors=True)


def open_handover() -> Handover | None:
    """A new handover folder, or None where there is no usable shared memory.

    The folder's file ``token`` holds the token, the maker's pid and its start time, so
    that a folder left by a killed run is known as such and removed (:func:`_sweep`).
    """
    if not os.path.isdir(SHARED_MEMORY):
        return None
    with contextlib.suppress(OSError, ValueError, IndexError):
        _sweep()
    try:
        folder = tempfile.mkdtemp(prefix="curvesmith-", dir=SHARED_MEMORY)
    except OSError:
        return None
    token = secrets.token_hex(16)
    try:
        Path(folder, _TOKEN).write_text(f"{token}\n{os.getpid()} {process_started(os.getpid())}\n")
    except OSError:
        shutil.rmtree(folder, ignore_errors=True)
        return None
    return Handover(folder, token)


def close(handover: Handover | None) -> None:
    """Remove the folder and every file left in it.

    The token goes first: a worker still writing (a caller's cluster runs on after a
    failed run) then finds it gone and removes its own file (:func:`ship`).
    """
    if handover is not None:
        with contextlib.suppress(OSError):
            os.unlink(os.path.join(handover.folder, _TOKEN))
        shutil.rmtree(handover.folder, ignore_errors=True)


def _token_of(folder: str) -> str | None:
    try:
        return Path(folder, _TOKEN).read_text().split("\n", 1)[0]
    except (OSError, UnicodeDecodeError):
        return None


_seen: dict[Handover, bool] = {}
_seen_lock = threading.Lock()


def reachable(handover: Handover | None) -> bool:
    """Whether this process sees `handover`'s folder (the same machine as its maker)."""
    if handover is None:
        return False
    with _seen_lock:
        seen = _seen.get(handover)
        if seen is None:
            seen = _seen[handover] = _token_of(handover.folder) == handover.token
            if len(_seen) > 64:  # a long-lived worker serves many runs
                _seen.pop(next(iter(_seen)))
    return seen


def _room(folder: str, nbytes: int) -> bool:
    """Whether `nbytes` fit in the file system of `folder` and leave its free margin."""
    try:
        fs = os.statvfs(folder)
    except OSError:
        return False
    free, size = fs.f_bavail * fs.f_frsize, fs.f_blocks * fs.f_frsize
    return free - nbytes >= max(FREE_BYTES, FREE_FRACTION * size)


def ship(packet: GeometryPacket, handover: Handover | None, name: str) -> GeometryPacket | Shipped:
    """`packet` with its coordinates left in a file of `handover`, where worthwhile.

    The file's name starts with `name`. Returns `packet` itself when `handover` is None
    or not :func:`reachable`, when the coordinates are small, when ``/dev/shm`` has no
    room for them beside its free margin (:data:`FREE_BYTES`), or when the file cannot
    be written; the space is reserved before the write (``posix_fallocate``), so a full
    file system fails at once and leaves no partial file.
    """
    coords = packet.coords
    if coords.nbytes < MIN_BYTES or not reachable(handover):
        return packet
    assert handover is not None
    if not _room(handover.folder, coords.nbytes):
        return packet
    data = np.ascontiguousarray(coords, dtype=np.float64)
    path = os.path.join(handover.folder, f"{name}-{secrets.token_hex(8)}")
    try:
        fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
    except OSError:  # gone (the run ended), or (never seen) a name taken
        return packet
    try:
        with open(fd, "wb", closefd=True) as f:
            if hasattr(os, "posix_fallocate"):
                os.posix_fallocate(f.fileno(), 0, data.nbytes)
            f.write(data.data.cast("B"))
        if _token_of(handover.folder) != handover.token:  # closed meanwhile
            raise FileNotFoundError(path)
    except OSError:  # full or gone: the usual way
        with contextlib.suppress(OSError):
            os.unlink(path)  # this call's own file (O_EXCL)
        return packet
    empty = dataclasses.replace(packet, coords=np.empty((0, 2)))
    return Shipped(empty, path, tuple(data.shape))


def land(item: GeometryPacket | Shipped, *, remove: bool) -> GeometryPacket:
    """The packet of `item`; shipped coordinates are read in place from their file.

    The coordinates are a read-only view of the file's mapping, which lives as long as
    they do. With `remove`, the file is removed at once (its memory goes back to the
    system when the view goes).
    """
    if not isinstance(item, Shipped):
        return item
    from ..errors import CurveError

    try:
        f = open(item.path, "rb")  # noqa: SIM115 (closed below; the mapping outlives it)
    except OSError as exc:
        raise CurveError(
            f"the coordinates handed over in {item.path!r} cannot be read here "
            f"({exc.strerror}): the file is on the machine of the process that wrote it"
        ) from None
    with f:
        size = os.fstat(f.fileno()).st_size
        expected = 8 * int(np.prod(item.shape))
        if size != expected:
            raise CurveError(
                f"the coordinates handed over in {item.path!r} are {size} bytes, "
                f"expected {expected}"
            )
        if size:
            buffer = mmap.mmap(f.fileno(), 0, prot=mmap.PROT_READ)
            coords = np.frombuffer(buffer, dtype=np.float64).reshape(item.shape)
        else:
            coords = np.empty(item.shape)
    if remove:
        with contextlib.suppress(OSError):
            os.unlink(item.path)
    return dataclasses.replace(item.packet, coords=coords)


def discard(item: object) -> None:
    """Remove the file of a :class:`Shipped` item (a task's input, once its result is in)."""
    if isinstance(item, Shipped):
        with contextlib.suppress(OSError):
            os.unlink(item.path)
