"""Input conversion and checking: the one place array_like input becomes float64.

Public functions call these helpers once at their boundary; internal functions
then trust their inputs.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from numbers import Integral, Real

import numpy as np

from .errors import CurveError, OutputSizeError

__all__ = [
    "BYTES_PER_VERTEX",
    "MAX_VERTICES",
    "as_bool",
    "as_choice",
    "as_float",
    "as_int",
    "as_points",
    "check_distinct",
    "check_growth",
    "check_layer_growth",
]

MAX_VERTICES = 2**27
"""Largest number of output vertices a refinement call may create (about 134 million;
2 GB for 2D float64 points). Every subdivision or CCA step multiplies the vertex count,
so a mistyped ``iterations=40`` would otherwise exhaust the memory instead of failing."""

BYTES_PER_VERTEX = 64
"""Memory a layer smoothed in one call holds at its peak, per output vertex, at least:
the coordinates, their geometries and the engine's buffers. Measured on 0.56 M vertices
of US counties, 3 iterations (15 M out): ``geo.smooth`` 66 bytes, ``smooth_coverage`` 74,
with ``min_segment`` 83; ``curvesmith smooth --coverage`` with its GeoPackage 78."""

MEMORY_CHECKED = 2**24
"""Output vertices (1 GB at :data:`BYTES_PER_VERTEX`) above which a layer's smoothing
first asks the system how much memory is available."""


def _shape_text(shape: Sequence[int]) -> str:
    return "(" + ", ".join(str(s) for s in shape) + ("," if len(shape) == 1 else "") + ")"


def as_points(
    points,
    *,
    name: str = "points",
    closed: bool = False,
    min_points: int = 2,
    dim: int | tuple[int, ...] | None = 2,
    distinct: bool = False,
    copy: bool = True,
) -> np.ndarray:
    """Convert array_like input to a new C-contiguous float64 ``(N, d)`` array and check it.

    Parameters
    ----------
    points : (N, d) array_like
        Vertices as rows.
    name : str, optional
        Argument name used in error messages.
    closed : bool, optional
        If True and the last row repeats the first exactly, the repeated
        closing vertex is dropped (once), following the ring convention of
        GeoJSON and shapely. Closedness is never guessed otherwise.
    min_points : int, optional
        Minimum number of vertices after dropping a closing vertex.
    dim : int or tuple of int or None, optional
        Allowed number(s) of columns; None allows any ``d >= 1``.
    distinct : bool, optional
        If True, consecutive vertices (and, when ``closed``, the last and the
        first) must differ, i.e. no zero-length edges.
    copy : bool, optional
        If False, an input that already is a float64 array is not copied (the
        result may share its memory, so the caller must not write into it); the
        copy of a long curve costs about as much as checking it.

    Returns
    -------
    (N, d) ndarray of float64
        A new array (with ``copy=False`` possibly a view of the input); the input
        is never modified.

    Raises
    ------
    CurveError
        If the input is not numeric, has the wrong shape, holds NaN or inf,
        has too few points, or (with ``distinct``) has zero-length edges.

    Examples
    --------
    >>> as_points([[0, 0], [1, 0], [1, 1], [0, 0]], closed=True).shape
    (3, 2)
    >>> as_points([[0, 0], [1, 0]], min_points=3)
    Traceback (most recent call last):
    ...
    curvesmith.errors.CurveError: points must have at least 3 points, got 2
    """
    if np.iscomplexobj(points):
        raise CurveError(f"{name} must be real coordinates, got a complex array")
    try:
        arr = np.array(points, dtype=np.float64, copy=True if copy else None)
    except (TypeError, ValueError) as exc:
        raise CurveError(f"{name} must be a numeric (N, d) array of coordinates: {exc}") from None
    if arr.ndim != 2 or arr.shape[1] < 1:
        want = f"(N, {dim})" if isinstance(dim, int) else "(N, d)"
        raise CurveError(f"{name} must have shape {want}, got {_shape_text(arr.shape)}")
    if dim is not None:
        allowed = (dim,) if isinstance(dim, int) else tuple(dim)
        if arr.shape[1] not in allowed:
            want = " or ".join(f"(N, {d})" for d in allowed)
            raise CurveError(f"{name} must have shape {want}, got {_shape_text(arr.shape)}")
    # Fast path: the sum is finite iff every entry is (NaN and inf propagate), unless
    # large finite values overflow, in which case the exact check below decides.
    with np.errstate(over="ignore", invalid="ignore"):
        total = arr.sum()
    if not np.isfinite(total) and not np.isfinite(arr).all():
        bad = np.flatnonzero(~np.isfinite(arr).all(axis=1))
        raise CurveError(
            f"{name} must be finite, got {arr[bad[0]].tolist()} at row {int(bad[0])}"
            + (f" ({bad.size} rows with NaN or inf)" if bad.size > 1 else "")
        )
    if closed and arr.shape[0] >= 2 and np.array_equal(arr[0], arr[-1]):
        arr = arr[:-1]
    if arr.shape[0] < min_points:
        ring = " distinct ring" if closed else ""
        raise CurveError(f"{name} must have at least {min_points}{ring} points, got {arr.shape[0]}")
    if distinct:
        check_distinct(arr, name=name, closed=closed)
    return np.ascontiguousarray(arr)


def check_distinct(points: np.ndarray, *, name: str = "points", closed: bool = False) -> None:
    """Raise `CurveError` if two consecutive vertices coincide (a zero-length edge).

    Parameters
    ----------
    points : (N, d) ndarray
        Already validated vertices.
    name : str, optional
        Argument name used in the message.
    closed : bool, optional
        Also check the closing edge from the last vertex to the first.
    """
    same = np.all(points[1:] == points[:-1], axis=1)
    if same.any():
        i = int(np.flatnonzero(same)[0])
        raise CurveError(
            f"{name} has a zero-length edge: vertices {i} and {i + 1} are both "
            f"{points[i].tolist()}; remove consecutive duplicate points"
        )
    if closed and points.shape[0] > 1 and np.array_equal(points[0], points[-1]):
        raise CurveError(
            f"{name} has a zero-length closing edge: the last vertex repeats the first "
            f"{points[0].tolist()} more than once"
        )


def as_bool(value, *, name: str) -> bool:
    """Check that `value` is a bool (``None`` and strings such as ``"no"`` are refused).

    Examples
    --------
    >>> as_bool("no", name="closed")
    Traceback (most recent call last):
    ...
    curvesmith.errors.CurveError: closed must be True or False, got 'no'
    """
    if not isinstance(value, bool | np.bool_):
        raise CurveError(f"{name} must be True or False, got {value!r}")
    return bool(value)


def as_choice(value, choices, *, name: str):
    """Check that `value` is one of `choices` and return it; the message lists the choices.

    The one check for string (and other enumerated) options, so that every message reads
    the same: ``method must be one of 'cca', 'chaikin', got 'spline'``.

    Examples
    --------
    >>> as_choice("golden", ("brent", "golden"), name="search")
    'golden'
    >>> as_choice("gold", ("brent", "golden"), name="search")
    Traceback (most recent call last):
    ...
    curvesmith.errors.CurveError: search must be one of 'brent', 'golden', got 'gold'
    """
    options = tuple(choices)

    def same(c) -> bool:  # True is not 1 here
        try:
            return bool(c == value) and isinstance(c, bool) == isinstance(value, bool)
        except (TypeError, ValueError):  # an array's ambiguous truth value
            return False

    if not any(same(c) for c in options):
        raise CurveError(f"{name} must be one of {', '.join(map(repr, options))}, got {value!r}")
    return value


def check_growth(n: int, iterations: int, step, *, limit: int = MAX_VERTICES) -> None:
    """Raise if `iterations` steps of ``n -> step(n)`` vertices exceed `limit` vertices."""
    for k in range(iterations):
        grown = step(n)
        if grown <= n:
            return  # the count no longer grows (a 2-point open line stays 2 points)
        n = grown
        if n > limit:
            raise OutputSizeError(
                f"iterations must be small enough for at most {limit} output vertices, "
                f"got {iterations} (step {k + 1} alone would give {n} vertices)"
            )


def available_memory() -> int | None:
    """Bytes of memory this process can still take, or None where that is unknown.

    Linux's ``MemAvailable`` (free memory and the caches it can drop), within the limit
    of the process's control group (a container's), whichever is smaller.
    """
    found = []
    try:
        with open("/proc/meminfo") as f:
            for line in f:
                if line.startswith("MemAvailable:"):
                    found.append(int(line.split()[1]) * 1024)
                    break
    except (OSError, ValueError, IndexError):
        pass
    for limit, usage in (
        ("/sys/fs/cgroup/memory.max", "/sys/fs/cgroup/memory.current"),  # cgroup v2
        (
            "/sys/fs/cgroup/memory/memory.limit_in_bytes",  # cgroup v1
            "/sys/fs/cgroup/memory/memory.usage_in_bytes",
        ),
    ):
        try:
            with open(limit) as f:
                cap = f.read().strip()
            with open(usage) as f:
                used = int(f.read().strip())
        except (OSError, ValueError):
            continue
        if cap.isdigit() and int(cap) < 2**60:  # "max", or v1's "unlimited" (2**63 - 4096)
            found.append(max(int(cap) - used, 0))
        break
    return min(found) if found else None


def check_layer_growth(
    n: int, iterations: int, growth: int, *, levels: bool = False, what: str = "vertices"
) -> None:
    """Refuse `iterations` steps that multiply `n` vertices by `growth` each beyond memory.

    For a layer smoothed in one call, whose output is held in memory at once: at most
    :data:`MAX_VERTICES` output vertices, and at most what the memory available now
    holds at :data:`BYTES_PER_VERTEX` each. With `levels`, every level up to `iterations`
    is held at once (``max_shift`` / ``min_segment``). The error names the most
    iterations that fit, so that a mistyped count fails at once with advice, not after
    minutes with the process killed by the system for want of memory.
    """

    def held(k: int) -> int:  # vertices held at the peak after k iterations
        out = n * growth**k
        return out * growth // (growth - 1) if levels and k > 0 and growth > 1 else out

    if growth <= 1 or n == 0:
        return
    need = held(iterations)
    if need <= MEMORY_CHECKED:  # a small call does not read the system's figures
        return
    free = available_memory()
    cap = MAX_VERTICES if free is None else min(MAX_VERTICES, free // BYTES_PER_VERTEX)
    if need <= cap:
        return
    most = 0
    while most < iterations and held(most + 1) <= cap:
        most += 1
    memory = (
        ""
        if free is None
        else (
            f", about {need * BYTES_PER_VERTEX / 1e9:.3g} GB of memory "
            f"({free / 1e9:.3g} GB available)"
        )
    )
    raise OutputSizeError(
        f"iterations {iterations} would turn {n} {what} into up to {need:.3g} (x{growth} per "
        f"iteration){memory}; one call holds at most {cap} here: use at most {most} "
        "iteration(s), or smooth fewer features at a time"
    )


def as_int(value, *, name: str, minimum: int | None = None, maximum: int | None = None) -> int:
    """Check that `value` is an integer within ``[minimum, maximum]`` and return it as int.

    Examples
    --------
    >>> as_int(3, name="iterations", minimum=0)
    3
    >>> as_int(-1, name="iterations", minimum=0)
    Traceback (most recent call last):
    ...
    curvesmith.errors.CurveError: iterations must be an integer >= 0, got -1
    """
    if isinstance(value, bool | np.bool_):
        raise CurveError(f"{name} must be an integer, got {value!r}")
    if not isinstance(value, Integral):
        if isinstance(value, Real) and float(value).is_integer():
            value = int(float(value))
        else:
            raise CurveError(f"{name} must be an integer, got {value!r}")
    value = int(value)
    if minimum is not None and value < minimum:
        bound = f">= {minimum}" if maximum is None else f"in [{minimum}, {maximum}]"
        raise CurveError(f"{name} must be an integer {bound}, got {value}")
    if maximum is not None and value > maximum:
        bound = f"<= {maximum}" if minimum is None else f"in [{minimum}, {maximum}]"
        raise CurveError(f"{name} must be an integer {bound}, got {value}")
    return value


def as_float(
    value,
    *,
    name: str,
    low: float | None = None,
    high: float | None = None,
    low_open: bool = True,
    high_open: bool = True,
) -> float:
    """Check that `value` is a finite real number in the given interval and return it as float.

    Parameters
    ----------
    value : real
        The value to check.
    name : str
        Argument name used in the message.
    low, high : float, optional
        Interval bounds; None means unbounded.
    low_open, high_open : bool, optional
        Whether the bounds are excluded (default) or included.

    Examples
    --------
    >>> as_float(2, name="gamma", low=1.0)
    2.0
    >>> as_float("2", name="gamma")
    Traceback (most recent call last):
    ...
    curvesmith.errors.CurveError: gamma must be a real number, got '2'
    >>> as_float(0.5, name="gamma", low=1.0)
    Traceback (most recent call last):
    ...
    curvesmith.errors.CurveError: gamma must be > 1, got 0.5
    """
    if isinstance(value, bool | np.bool_ | str | bytes) or not isinstance(value, Real):
        raise CurveError(f"{name} must be a real number, got {value!r}")
    value = float(value)
    if not math.isfinite(value):
        raise CurveError(f"{name} must be finite, got {value}")
    lo_ok = low is None or (value > low if low_open else value >= low)
    hi_ok = high is None or (value < high if high_open else value <= high)
    if not (lo_ok and hi_ok):
        if high is None:
            bound = f"{'>' if low_open else '>='} {low:g}"
        elif low is None:
            bound = f"{'<' if high_open else '<='} {high:g}"
        else:
            bound = f"in {'(' if low_open else '['}{low:g}, {high:g}{')' if high_open else ']'}"
        raise CurveError(f"{name} must be {bound}, got {value:g}")
    return value
