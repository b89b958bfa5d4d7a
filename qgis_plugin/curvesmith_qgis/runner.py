"""Finding and running the ``curvesmith`` program: progress, cancellation, one-line errors.

QGIS runs on its own Python with its own numpy, shapely and GDAL, usually older than
curvesmith needs, so the plugin never imports curvesmith: it runs the ``curvesmith``
command of the environment where curvesmith is installed, as the GRASS, SAGA and
WhiteboxTools providers run their programs. This module imports nothing from QGIS.
"""

from __future__ import annotations

import codecs
import contextlib
import os
import queue
import re
import shutil
import signal
import subprocess
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

__all__ = [
    "NOT_FOUND",
    "Cancelled",
    "CliError",
    "CliResult",
    "CurvesmithNotFound",
    "child_env",
    "error_message",
    "find_curvesmith",
    "run_cli",
]

NOT_FOUND = "curvesmith not found: set its path in Processing > Options > Providers"

# Dask's progress bar (``curvesmith batch smooth``): "[####    ] | 42% Completed |  1.2s"
_PROGRESS = re.compile(r"\|\s*(\d{1,3})% Completed")
_NO_OPTION = re.compile(r"No such option:? '?(--[\w-]+)'?")


class CurvesmithNotFound(Exception):
    """The ``curvesmith`` program is neither at the configured path nor on PATH."""


class CliError(Exception):
    """``curvesmith`` exited with an error; the message is its one-line error."""


class Cancelled(Exception):
    """The run was cancelled and the program stopped."""


def _names() -> tuple[str, ...]:
    return ("curvesmith.exe",) if os.name == "nt" else ("curvesmith",)


def find_curvesmith(configured: str | None = None) -> str:
    """The ``curvesmith`` program to run.

    Parameters
    ----------
    configured : str, optional
        The path set in Processing > Options > Providers > curvesmith: the program, or
        a folder holding it (a virtual environment, its ``bin``/``Scripts`` folder).
        Empty: ``curvesmith`` on PATH, then ``~/.local/bin`` (pipx).

    Returns
    -------
    str
        Absolute path of the program.

    Raises
    ------
    CurvesmithNotFound
        With :data:`NOT_FOUND` and where it looked.
    """
    if configured and configured.strip():
        path = Path(configured.strip()).expanduser()
        candidates = [path]
        if path.is_dir():
            candidates = [d / n for d in (path, path / "bin", path / "Scripts") for n in _names()]
        for c in candidates:
            if c.is_file() and os.access(c, os.X_OK):
                return str(c.resolve())
        raise CurvesmithNotFound(f"{NOT_FOUND} (no curvesmith program at {str(path)!r})")
    found = shutil.which("curvesmith")
    if found:
        return found
    local = Path.home() / ".local" / "bin" / "curvesmith"
    if local.is_file() and os.access(local, os.X_OK):
        return str(local)
    raise CurvesmithNotFound(f"{NOT_FOUND} (not on PATH)")


def child_env() -> dict[str, str]:
    """The environment for ``curvesmith``: QGIS's own, without its Python settings.

    QGIS (on Windows and macOS) sets PYTHONHOME and PYTHONPATH for its own Python; the
    program's Python (another version, another environment) must not see them.
    """
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONHOME", "PYTHONPATH")}
    env["PYTHONIOENCODING"] = "utf-8"
    env["PYTHONUNBUFFERED"] = "1"
    return env


@dataclass
class CliResult:
    """What a finished run printed.

    Attributes
    ----------
    returncode : int
        Exit status.
    stdout, stderr : list of str
        Lines printed (progress bar updates excluded).
    """

    returncode: int
    stdout: list[str] = field(default_factory=list)
    stderr: list[str] = field(default_factory=list)


_HELP_HINT = re.compile(r"\s*\(see '[^']*--help'\)$")


def error_message(result: CliResult, executable: str = "curvesmith") -> str:
    """The one readable line that says why `result` failed.

    The CLI prints its errors as one ``Error: ...`` line on stderr (usage errors end with
    ``(see 'curvesmith CMD --help')``, which is dropped here; older versions printed a usage
    block first); an option that the installed version lacks is said so.
    """
    lines = [s.strip() for s in result.stderr if s.strip()]
    errors = [s for s in lines if s.startswith("Error:")]
    text = (errors or lines or [f"exited with status {result.returncode}"])[-1]
    text = _HELP_HINT.sub("", text.removeprefix("Error:")).strip()
    missing = _NO_OPTION.search(text)
    if missing:
        return (
            f"the installed curvesmith ({executable}) has no option {missing.group(1)}: "
            f"this algorithm needs a newer curvesmith; update it (pip install -U curvesmith)"
        )
    return text


def _reader(stream, name: str, out: queue.Queue) -> None:
    """Queue a pipe's lines, split at newlines and carriage returns, and its progress.

    A progress bar redraws itself after a carriage return, so its latest state is the
    unfinished last line: its percentage is queued as soon as it arrives (each value once).
    """
    decoder = codecs.getincrementaldecoder("utf-8")(errors="replace")
    pending, last = "", None

    def progress(text):
        nonlocal last
        match = _PROGRESS.search(text)
        if match and match.group(1) != last:
            last = match.group(1)
            out.put(("progress", min(100.0, float(last))))
        return match is not None

    for chunk in iter(lambda: stream.read1(4096), b""):
        pending += decoder.decode(chunk)
        parts = re.split(r"[\r\n]", pending)
        pending = parts.pop()
        for p in parts:
            if not progress(p):
                out.put((name, p))
        progress(pending)
    pending += decoder.decode(b"", final=True)
    if pending and not progress(pending):
        out.put((name, pending))
    out.put((name, None))


def _kill(proc: subprocess.Popen) -> None:
    """Stop the program and everything it started (Dask workers), if still running."""
    if os.name == "nt":
        if proc.poll() is None:
            subprocess.run(
                ["taskkill", "/F", "/T", "/PID", str(proc.pid)], capture_output=True, check=False
            )
    else:
        # the program leads its own process group (start_new_session): the group outlives
        # the program while any of its children does
        with contextlib.suppress(ProcessLookupError, PermissionError):
            os.killpg(proc.pid, signal.SIGKILL)
    proc.wait()


def run_cli(
    argv: list[str],
    *,
    is_canceled: Callable[[], bool],
    on_progress: Callable[[float], None],
    on_line: Callable[[str, str], None],
    poll: float = 0.05,
) -> CliResult:
    """Run `argv`, reporting its output as it comes, and stop it when cancelled.

    Parameters
    ----------
    argv : list of str
        Program and arguments.
    is_canceled : callable
        Polled every `poll` seconds; when it returns true the program and its children
        (its own process group) are killed and :class:`Cancelled` is raised.
    on_progress : callable
        Called with a percentage in [0, 100] for every progress bar update.
    on_line : callable
        Called with ``("stdout" | "stderr", line)`` for every other line.
    poll : float
        Seconds between checks.

    Returns
    -------
    CliResult
        Also when the program failed (check ``returncode``).

    Notes
    -----
    The callbacks run in the calling thread (the reader threads only queue lines), so they
    may call into QGIS's feedback object.
    """
    kwargs = {}
    if os.name == "nt":
        kwargs["creationflags"] = (
            subprocess.CREATE_NEW_PROCESS_GROUP | subprocess.CREATE_NO_WINDOW  # type: ignore[attr-defined]
        )
    else:
        kwargs["start_new_session"] = True
    proc = subprocess.Popen(
        argv,
        stdin=subprocess.DEVNULL,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        env=child_env(),
        **kwargs,
    )
    lines: queue.Queue = queue.Queue()
    threads = [
        threading.Thread(target=_reader, args=(s, n, lines), daemon=True)
        for s, n in ((proc.stdout, "stdout"), (proc.stderr, "stderr"))
    ]
    for t in threads:
        t.start()
    result = CliResult(returncode=-1)
    open_streams = 2
    exited = None  # when the program exited; its children may still hold the pipes
    try:
        while open_streams or proc.poll() is None:
            if exited is None and proc.poll() is not None:
                exited = time.monotonic()
            elif exited is not None and time.monotonic() - exited > 5.0:
                break
            if is_canceled():
                _kill(proc)
                raise Cancelled("cancelled, the program was stopped and no output written")
            try:
                name, line = lines.get(timeout=poll)
            except queue.Empty:
                continue
            if line is None:
                open_streams -= 1
                continue
            if name == "progress":
                on_progress(line)
            elif line.strip():
                getattr(result, name).append(line)
                on_line(name, line)
    finally:
        _kill(proc)
        for t in threads:
            t.join(timeout=5)
        for s in (proc.stdout, proc.stderr):
            s.close()
    result.returncode = proc.returncode
    return result
