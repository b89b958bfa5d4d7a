"""Stopping the command line when asked: SIGTERM and Ctrl-C act within a second.

A job scheduler's cancel, ``timeout`` and ``kill`` send SIGTERM; a user at a terminal
presses Ctrl-C (SIGINT). Python runs its signal handlers in the main thread between two
bytecodes, so while that thread is inside one long compiled call (the ragged engine on a
layer of a million polygons, a GEOS pass over all of them) a signal waits until the call
returns: seconds, minutes for the largest inputs.

Here the handler unwinds as before (SystemExit / KeyboardInterrupt: ``finally`` blocks run,
the temporary outputs go, exit status 128 + signal), and a watchdog thread, woken by the
byte that Python's C-level handler writes to its wakeup descriptor the moment the signal
arrives, waits :data:`GRACE` seconds for that unwinding. If the process is still running
then, the watchdog removes the temporary outputs in flight
(:func:`curvesmith.io._core.remove_in_flight`), stops the child processes (Dask
workers) and exits with the same status. Either way one line names the signal (a SIGINT
that Python unwinds by itself stays click's "Aborted!", exit status 1). The compiled
kernels release the GIL, so the watchdog gets to run while they work.
"""

from __future__ import annotations

import contextlib
import os
import signal
import socket
import sys
import threading
import time

#: Seconds the watchdog leaves the main thread to unwind by itself after a signal.
GRACE = 1.0

_installed = False
_said = threading.Lock()

#: Set when the watchdog has begun to stop the process: the main thread, failing because
#: the watchdog removed its temporary output, must not report that as an error of its own.
stopping = threading.Event()


def _take_open_line() -> bool:
    """Whether a progress bar's line (``batch``'s) is open on stderr; it counts as ended."""
    batch = sys.modules.get("curvesmith.batch")
    bar = getattr(batch, "_ProgressBar", None)
    if bar is not None and bar.line_open:
        bar.line_open = False
        return True
    return False


def end_open_line() -> None:
    """End a progress bar's line on stderr (``batch``'s), so that a message has its own."""
    if _take_open_line():
        sys.stderr.write("\n")


def _say_stopped(signum: int, fd: int | None = None) -> None:
    """One line on stderr (or descriptor `fd`), once per process: which signal stopped the run."""
    if _said.acquire(blocking=False):
        with contextlib.suppress(Exception):
            line = f"Error: stopped by {signal.Signals(signum).name}\n"
            if fd is None:
                end_open_line()
                sys.stderr.write(line)
                sys.stderr.flush()
            else:  # stderr is /dev/null by now: a progress bar's open line ends here
                os.write(fd, (("\n" if _take_open_line() else "") + line).encode())


def claim_last_line() -> bool:
    """Whether the main thread may write the run's last line (click's "Aborted!").

    False when the watchdog has written its line already: the process is then ending, and
    nothing more is said.
    """
    return _said.acquire(blocking=False)


def _on_sigterm(signum, frame):
    _say_stopped(signum)
    raise SystemExit(128 + signum)


def exit_cleanly_on_sigterm() -> None:
    """SIGTERM unwinds like an error: ``finally`` blocks run and temporary files go.

    Python's default for SIGTERM ends the process without running ``finally`` blocks, so
    the temporary output beside OUT would stay; as SystemExit it is removed like after any
    failed run (exit status 143).
    """
    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGTERM, _on_sigterm)


def install_watchdog() -> None:
    """Start the watchdog thread (once per process, from the main thread of a program)."""
    global _installed
    if _installed or threading.current_thread() is not threading.main_thread():
        return
    exit_cleanly_on_sigterm()
    wake, bell = socket.socketpair()
    bell.setblocking(False)
    try:
        signal.set_wakeup_fd(bell.fileno(), warn_on_full_buffer=False)
    except ValueError:  # not the main thread of the main interpreter
        wake.close()
        bell.close()
        return
    _installed = True
    watch = threading.Thread(target=_watch, args=(wake, bell), name="curvesmith-stop", daemon=True)
    watch.start()


def _watch(wake: socket.socket, bell: socket.socket) -> None:
    # `bell` is held here so that its descriptor, Python's wakeup fd, stays open
    stops = {int(signal.SIGTERM), int(signal.SIGINT)}
    while True:
        try:
            data = wake.recv(64)
        except OSError:
            return
        if not data:
            return
        hit = [b for b in data if b in stops]
        if hit:
            break
    signum = hit[0]
    time.sleep(GRACE)
    # still running: the main thread is inside a long compiled call
    _stop_now(signum)


def _stop_now(signum: int) -> None:
    from ..io._core import remove_in_flight

    stopping.set()
    err = None
    with contextlib.suppress(OSError):  # nothing more from the main thread, from now on
        err = os.dup(2)
        quiet = os.open(os.devnull, os.O_WRONLY)
        os.dup2(quiet, 1)
        os.dup2(quiet, 2)
    _say_stopped(signum, err)
    remove_in_flight()
    _stop_children()
    os._exit(128 + signum)


def wait_if_stopping() -> None:
    """In the main thread's error handling: leave the exit to the watchdog if it is stopping."""
    if stopping.is_set():
        time.sleep(30)  # the watchdog ends the process within moments


def _stop_children() -> None:
    """Terminate the child processes this program started (multiprocessing, Dask)."""
    import multiprocessing

    for child in multiprocessing.active_children():
        with contextlib.suppress(Exception):
            child.terminate()
    for child in multiprocessing.active_children():
        with contextlib.suppress(Exception):
            child.join(timeout=1.0)
            if child.is_alive():
                child.kill()
