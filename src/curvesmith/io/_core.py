"""The data model of curvesmith's file formats and the registry that dispatches on them.

:class:`Curve` is what every reader returns and every writer takes. :class:`Format` describes one
file format (its name, suffixes, reader and writer); each format module registers one with
:func:`register`, and :func:`read_curves`, :func:`write_curves` and :func:`detect_format` (and the
CLI's ``--format`` choices) are driven by the registry, so adding a format is one module that
calls :func:`register` and one import in ``curvesmith/io/__init__.py``.
"""

from __future__ import annotations

import contextlib
import dataclasses
import inspect
import os
import re
import shutil
import tempfile
from collections.abc import Callable, Iterable, Iterator, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, TextIO

import numpy as np
import orjson
from numpy.typing import ArrayLike

from .._validate import as_choice, as_points
from ..errors import CurveError, CurveFormatError

__all__ = [
    "KINDS",
    "Curve",
    "Format",
    "atomic_path",
    "check_destination",
    "detect_format",
    "formats",
    "open_destination",
    "read_curves",
    "register",
    "write_curves",
]

KINDS = ("LineString", "Polygon", "MultiLineString", "MultiPolygon")
"""Geometry kinds a :class:`Curve` can come from (GeoJSON geometry type names)."""

_POLYGON_KINDS = ("Polygon", "MultiPolygon")
_STREAM = "<stream>"

Source = str | os.PathLike | TextIO


@dataclass(frozen=True, eq=False)
class Curve:
    """One polyline or polygon ring read from (or to be written to) a file.

    Parameters
    ----------
    points : (N, 2) or (N, 3) array_like
        Vertices as rows. Stored as a new read-only float64 array. With
        ``closed=True`` a repeated closing vertex is dropped once.
    closed : bool
        Whether the curve is a closed ring (an edge joins the last vertex to
        the first). Closed curves need at least 3 distinct-ring vertices, open
        ones at least 2.
    properties : Mapping[str, Any], optional
        Feature properties (GeoJSON), per-curve constant columns and the id
        (CSV), the element ``id`` (SVG). Stored as a new dict.
    feature : int, optional
        Index of the source feature (GeoJSON), id group (CSV) or element (SVG).
    part : int, optional
        Index inside a MultiLineString or MultiPolygon.
    ring : int, optional
        0 for a line or an exterior ring, k >= 1 for the k-th hole of a polygon.
    kind : str, optional
        Source geometry type, one of :data:`KINDS`. Polygon kinds require
        ``closed=True``.
    member : int or None, optional
        Index of the geometry inside a GeoJSON GeometryCollection, None when
        the feature's geometry is not a collection.
    feature_id : str or int or None, optional
        The GeoJSON Feature ``id`` member, None when absent.
    style : Mapping[str, str] or None, optional
        SVG presentation attributes of the source element (``fill``, ``stroke``,
        ``opacity``, ...), as read by :func:`read_svg`; :func:`write_svg` writes them back
        on the curve's path. Other formats ignore it.

    Notes
    -----
    Curves are frozen; derive new ones with :meth:`replace`. They compare by
    identity (an array has no single truth value): compare ``points`` with
    :func:`numpy.array_equal` and the other fields directly.

    Examples
    --------
    >>> c = Curve([[0, 0], [1, 0], [0, 1], [0, 0]], closed=True, kind="Polygon")
    >>> c.points.shape
    (3, 2)
    >>> c.replace([[0, 0], [2, 0], [0, 2]]).points[1].tolist()
    [2.0, 0.0]
    """

    points: np.ndarray
    closed: bool
    properties: Mapping[str, Any] = field(default_factory=dict)
    feature: int = 0
    part: int = 0
    ring: int = 0
    kind: str = "LineString"
    member: int | None = None
    feature_id: str | int | None = None
    style: Mapping[str, str] | None = None

    def __post_init__(self) -> None:
        if not isinstance(self.closed, bool | np.bool_):
            raise CurveError(f"closed must be True or False, got {self.closed!r}")
        closed = bool(self.closed)
        points = as_points(self.points, closed=closed, min_points=3 if closed else 2, dim=(2, 3))
        points.setflags(write=False)
        object.__setattr__(self, "points", points)
        object.__setattr__(self, "closed", closed)
        if not isinstance(self.properties, Mapping):
            raise CurveError(f"properties must be a mapping, got {type(self.properties).__name__}")
        object.__setattr__(self, "properties", dict(self.properties))
        if self.style is not None:
            if not isinstance(self.style, Mapping):
                raise CurveError(
                    f"style must be a mapping or None, got {type(self.style).__name__}"
                )
            object.__setattr__(self, "style", {str(k): str(v) for k, v in self.style.items()})
        for name in ("feature", "part", "ring"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, int | np.integer) or value < 0:
                raise CurveError(f"{name} must be an integer >= 0, got {value!r}")
            object.__setattr__(self, name, int(value))
        if self.member is not None:
            m = self.member
            if isinstance(m, bool) or not isinstance(m, int | np.integer) or m < 0:
                raise CurveError(f"member must be None or an integer >= 0, got {m!r}")
            object.__setattr__(self, "member", int(m))
        as_choice(self.kind, KINDS, name="kind")
        if self.kind in _POLYGON_KINDS and not closed:
            raise CurveError(f"a {self.kind} ring must be closed, got closed=False")
        if self.kind in ("LineString", "Polygon") and self.part != 0:
            raise CurveError(f"part must be 0 for a {self.kind}, got {self.part}")
        if self.kind in ("LineString", "MultiLineString") and self.ring != 0:
            raise CurveError(f"ring must be 0 for a {self.kind}, got {self.ring}")

    @property
    def dim(self) -> int:
        """Number of coordinates per vertex, 2 or 3."""
        return int(self.points.shape[1])

    def replace(
        self, points: ArrayLike | None = None, *, closed: bool | None = None, **changes: Any
    ) -> Curve:
        """Return a new curve with other points (and optionally other fields).

        Parameters
        ----------
        points : (M, 2) or (M, 3) array_like, optional
            New vertices; default: the current ones.
        closed : bool, optional
            New closedness; default: unchanged. Turning a Polygon ring open
            also needs ``kind=`` a line kind.
        **changes
            Other fields to change (``properties``, ``feature``, ...), as in
            :func:`dataclasses.replace`.

        Returns
        -------
        Curve
            The new curve; this one is unchanged.
        """
        if points is not None:
            changes["points"] = points
        if closed is not None:
            changes["closed"] = closed
        return dataclasses.replace(self, **changes)


# ----------------------------------------------------------------------------------------------
# sources, destinations, dispatch


@dataclass(frozen=True)
class Format:
    """One file format of :func:`read_curves` / :func:`write_curves`.

    Parameters
    ----------
    name : str
        The name accepted by ``format=`` (and the CLI's ``--format``).
    label : str
        How messages name the format (``"CSV"``).
    suffixes : tuple of str
        File suffixes, lower case with the dot (``(".csv", ".txt")``).
    read : callable
        ``read(source, **options) -> list[Curve]``.
    write : callable
        ``write(curves, dest, **options) -> None``.
    aliases : tuple of str, optional
        Other names accepted by ``format=`` (``"json"`` for GeoJSON).
    """

    name: str
    label: str
    suffixes: tuple[str, ...]
    read: Callable[..., list[Curve]]
    write: Callable[..., None]
    aliases: tuple[str, ...] = ()

    @property
    def read_options(self) -> frozenset[str]:
        """Keyword options the reader takes."""
        params = inspect.signature(self.read).parameters.values()
        return frozenset(p.name for p in params if p.kind is inspect.Parameter.KEYWORD_ONLY)


REGISTRY: dict[str, Format] = {}


def register(fmt: Format) -> Format:
    """Add a file format to the registry (returns it, so a module can keep it as a constant).

    Raises
    ------
    CurveError
        If the name, an alias or a suffix is taken by another format.
    """
    if not isinstance(fmt, Format):
        raise CurveError(f"fmt must be a Format, got {type(fmt).__name__}")
    for other in REGISTRY.values():
        if other.name == fmt.name:
            continue
        taken = ({other.name, *other.aliases} & {fmt.name, *fmt.aliases}) or (
            set(other.suffixes) & set(fmt.suffixes)
        )
        if taken:
            raise CurveError(
                f"format {fmt.name!r}: {sorted(taken)} already belong to {other.name!r}"
            )
    REGISTRY[fmt.name] = fmt
    return fmt


def formats() -> tuple[str, ...]:
    """Names of the registered formats, in registration order."""
    return tuple(REGISTRY)


def _format_named(name: str) -> Format:
    key = str(name).lower()
    for fmt in REGISTRY.values():
        if key == fmt.name or key in fmt.aliases:
            return fmt
    raise CurveFormatError(f"format must be one of {', '.join(REGISTRY)}, got {name!r}")


def _suffix_text() -> str:
    return ", ".join(f"{', '.join(f.suffixes)} ({f.label})" for f in REGISTRY.values())


def _name_of(source) -> str:
    if isinstance(source, str | os.PathLike):
        return os.fspath(source)
    name = getattr(source, "name", None)
    return name if isinstance(name, str) else _STREAM


def _read_text(source: Source) -> tuple[str, str]:
    """Return the whole text of `source` and the name used in messages."""
    name = _name_of(source)
    if isinstance(source, str | os.PathLike):
        path = Path(source)
        data: bytes | str
        try:
            data = path.read_bytes()
        except FileNotFoundError:
            raise CurveFormatError(f"{name}: no such file") from None
        except IsADirectoryError:
            raise CurveFormatError(f"{name}: is a directory, not a file") from None
        except OSError as exc:
            raise CurveFormatError(f"{name}: cannot read the file: {exc.strerror}") from None
    elif hasattr(source, "read"):
        data = source.read()
    else:
        raise CurveFormatError(
            f"source must be a path or a text file object, got {type(source).__name__}"
        )
    if isinstance(data, bytes | bytearray):
        try:
            text = bytes(data).decode("utf-8-sig")
        except UnicodeDecodeError as exc:
            raise CurveFormatError(
                f"{name}: not UTF-8 text ({exc.reason} at byte {exc.start})"
            ) from None
    elif isinstance(data, str):
        text = data.removeprefix("\ufeff")
    else:
        raise CurveFormatError(f"{name}: read() returned {type(data).__name__}, not text")
    if not text.strip():
        raise CurveFormatError(f"{name}: the file is empty")
    return text, name


def check_destination(dest: str | os.PathLike) -> Path:
    """Check, before any work is done, that a file can be written at `dest`.

    The folder must exist and be writable, and `dest` must not be a folder. Returns `dest`
    as a :class:`~pathlib.Path`.

    Raises
    ------
    CurveFormatError
        Naming the file and what is wrong.
    """
    path = Path(dest)
    name = os.fspath(dest)
    parent = path.parent
    if path.is_dir():
        raise CurveFormatError(f"{name}: is a directory, not a file")
    if not parent.is_dir():
        # (a file where the folder should be: -o mixed.geojson/x.gpkg)
        what = "is a file, not a directory" if parent.exists() else "does not exist"
        raise CurveFormatError(
            f"{name}: cannot write the file: the directory {os.fspath(parent)!r} {what}"
        )
    if not os.access(parent, os.W_OK | os.X_OK):
        raise CurveFormatError(
            f"{name}: cannot write the file: the directory {os.fspath(parent)!r} is not writable"
        )
    return path


#: Temporary files and folders of outputs being written. A run that must stop at once,
#: inside a compiled call that Python's unwinding would wait for (the command line's
#: SIGTERM watchdog, :mod:`curvesmith.cli._stop`), removes them before it exits.
_IN_FLIGHT: set[Path] = set()


@contextlib.contextmanager
def in_flight(path: str | os.PathLike) -> Iterator[Path]:
    """Register `path` (a temporary file or folder) as in flight while the block runs."""
    path = Path(path)
    _IN_FLIGHT.add(path)
    try:
        yield path
    finally:
        _IN_FLIGHT.discard(path)


def remove_in_flight() -> None:
    """Remove every temporary file and folder in flight (see :func:`in_flight`)."""
    for path in list(_IN_FLIGHT):
        if path.is_dir():
            shutil.rmtree(path, ignore_errors=True)
        else:
            with contextlib.suppress(OSError):
                path.unlink()


@contextlib.contextmanager
def atomic_path(dest: str | os.PathLike, *, stale: Iterable[str] = ()) -> Iterator[Path]:
    """Write a file under a temporary name in its own folder; rename it into place on success.

    Yields a path ``<folder>/.<name>.<random>.tmp/<name>`` (a private folder next to `dest`,
    so on the same file system). When the ``with`` block ends without an exception, every
    file written into that private folder (the file and, for a Shapefile, its sidecars of the
    same stem) is renamed over the file of the same name next to `dest`, the main file last,
    and files next to `dest` with the same stem and a suffix in `stale` that the new output
    does not have are removed (an old ``.prj`` must not describe a new Shapefile). On an
    exception nothing next to `dest` changes: the previous file, if any, stays as it was,
    and the temporary folder is removed. The caller verifies the written file inside the
    block (so that a file that cannot be read back never replaces a good one).

    Parameters
    ----------
    dest : str or path-like
        Final path.
    stale : iterable of str, optional
        Sidecar suffixes (``".prj"``) to remove when the new output has no such file.

    Raises
    ------
    CurveFormatError
        When the folder is missing or not writable, or `dest` is a folder.
    """
    path = check_destination(dest)
    parent = path.parent
    try:
        tmpdir = Path(tempfile.mkdtemp(prefix=f".{path.name}.", suffix=".tmp", dir=parent))
    except OSError as exc:
        raise CurveFormatError(
            f"{os.fspath(dest)}: cannot write the file: {exc.strerror or exc}"
        ) from None
    _IN_FLIGHT.add(tmpdir)
    try:
        yield tmpdir / path.name
        written = sorted(tmpdir.iterdir(), key=lambda f: f.name == path.name)
        names = {f.name for f in written}
        for f in written:
            os.replace(f, parent / f.name)
        for suffix in stale:
            old = path.with_suffix(suffix)
            if old.name not in names and old.exists():
                old.unlink()
    finally:
        shutil.rmtree(tmpdir, ignore_errors=True)
        _IN_FLIGHT.discard(tmpdir)


class _Utf8Sink:
    """A text sink writing UTF-8 bytes to a binary file and counting them."""

    def __init__(self, raw):
        self.raw = raw
        self.nbytes = 0

    def write(self, text: str) -> int:
        data = text.encode("utf-8")
        self.raw.write(data)
        self.nbytes += len(data)
        return len(text)

    def write_bytes(self, data: bytes) -> int:
        """Write UTF-8 bytes as they are (the formatted rows: no decode and encode)."""
        self.raw.write(data)
        self.nbytes += len(data)
        return len(data)


@contextlib.contextmanager
def open_destination(dest: Source) -> Iterator[Any]:
    """A text stream to write a file's content to, replacing the file only when all went well.

    For a path: the text goes (UTF-8, Unix line ends) to a temporary file in the same
    folder (:func:`atomic_path`); after the ``with`` block it is flushed, synced to disk,
    its size checked against the bytes written, and renamed over `dest`. Any error (a full
    disk, an exception of the writer) leaves the previous `dest` untouched and no partial
    file. For a text file object: the object itself (the caller owns it).

    Raises
    ------
    CurveFormatError
        When the file cannot be written (naming it and the system's reason).
    """
    if not isinstance(dest, str | os.PathLike):
        if not hasattr(dest, "write"):
            raise CurveFormatError(
                f"dest must be a path or a text file object, got {type(dest).__name__}"
            )
        yield dest
        return
    name = os.fspath(dest)
    try:
        with atomic_path(dest) as tmp:
            with open(tmp, "wb") as raw:
                sink = _Utf8Sink(raw)
                yield sink
                raw.flush()
                os.fsync(raw.fileno())
            size = tmp.stat().st_size
            if size != sink.nbytes:
                raise CurveFormatError(
                    f"{name}: cannot write the file: {size} bytes on disk after writing "
                    f"{sink.nbytes}"
                )
    except OSError as exc:
        raise CurveFormatError(f"{name}: cannot write the file: {exc.strerror or exc}") from None


#: Rows formatted per chunk by :func:`format_rows` (bounded memory whatever the curve size).
CHUNK_ROWS = 16384


def write_rows(out: Any, points: np.ndarray, row: str) -> None:
    """Write the rows of `points` formatted by :func:`format_rows` to a text sink.

    The sinks of :func:`open_destination` take the formatted bytes as they are; any other
    text file object gets them as text.
    """
    raw = getattr(out, "write_bytes", None)
    for chunk in format_rows(points, row, as_bytes=raw is not None):
        (raw or out.write)(chunk)


def format_rows(
    points: np.ndarray, row: str, *, chunk: int | None = None, as_bytes: bool = False
) -> Iterator[Any]:
    """Format the rows of a float array chunk by chunk with a ``%``-template per row.

    ``row`` holds one ``%r`` per column (``"%r,%r;"``; a literal percent sign written as
    ``%%``). The text of each number is exactly :func:`repr` of the float, the shortest
    text that reads back to the same float, so the output round-trips bit-exactly and is
    what ``"%r" % value`` (and :func:`json.dumps`) writes. Each yielded string holds at most
    `chunk` rows (default :data:`CHUNK_ROWS`), so memory stays bounded for curves of any
    size; with `as_bytes` the chunks are UTF-8 bytes.

    The numbers are formatted by orjson's compiled shortest round-trip formatter (the same
    digits as ``repr``), about 25 ns per number where ``str.__mod__`` takes about 500 ns;
    orjson writes exponents of ``1e-5 .. 1e-9`` in another style (``1e-7``, ``0.00001``),
    so small blocks of rows that hold such a number are formatted by ``repr`` itself.
    Non-finite values raise
    :class:`~curvesmith.CurveError` (there is no text for them in these formats).

    Examples
    --------
    >>> "".join(format_rows(np.array([[0.1, 2.0], [1e-300, -0.0]]), "%r %r;"))
    '0.1 2.0;1e-300 -0.0;'
    >>> "".join(format_rows(np.array([[1e-7, 0.00001]]), "[%r, %r]"))
    '[1e-07, 1e-05]'
    """
    arr = np.asarray(points, dtype=np.float64)
    pieces = [""]
    for part in re.split(r"(%%|%r)", row):
        if part == "%r":
            pieces.append("")
        else:
            pieces[-1] += "%" if part == "%%" else part
    if arr.ndim != 2 or arr.shape[1] != len(pieces) - 1:
        raise CurveError(
            f"format_rows: row template {row!r} has {len(pieces) - 1} fields for an array "
            f"of shape {arr.shape}"
        )
    chunk = CHUNK_ROWS if chunk is None else int(chunk)
    head, inner, tail = pieces[0], pieces[1:-1], pieces[-1]
    if len(set(inner)) > 1:  # no writer needs it: the plain (slow) formatting
        for start in range(0, len(arr), chunk):
            block = arr[start : start + chunk]
            text = (row * len(block)) % tuple(block.ravel().tolist())
            yield text.encode() if as_bytes else text
        return
    sep = inner[0].encode() if inner else b","
    boundary = (tail + head).encode()
    joint = b"]" + sep + b"["

    head_b, tail_b = head.encode(), tail.encode()

    def fast(block: np.ndarray):
        body = orjson.dumps(block, option=orjson.OPT_SERIALIZE_NUMPY)[2:-2]  # a,b],[c,d
        if sep != b",":
            body = body.replace(b",", sep)  # a<sep>b]<sep>[c<sep>d: tokens hold no , [ ]
        if boundary != joint:
            body = body.replace(joint, boundary)
        return head_b + body + tail_b if as_bytes else head + body.decode() + tail

    for start in range(0, len(arr), chunk):
        block = np.ascontiguousarray(arr[start : start + chunk])
        if not np.isfinite(block).all():
            raise CurveError("format_rows: cannot write a non-finite coordinate (nan or inf)")
        mag = np.abs(block)
        odd = np.asarray(((mag >= _ORJSON_ODD[0]) & (mag < _ORJSON_ODD[1])).any(axis=1))
        if not odd.any():
            if len(block):
                yield fast(block)
            continue
        # rows with such numbers in sub-blocks: orjson where none is, repr where one is
        for s in range(0, len(block), _SUB_ROWS):
            sub = block[s : s + _SUB_ROWS]
            if odd[s : s + _SUB_ROWS].any():
                text = (row * len(sub)) % tuple(sub.ravel().tolist())
                yield text.encode() if as_bytes else text
            else:
                yield fast(sub)


# orjson writes the same digits as repr, but numbers of decimal exponent -5 .. -9 in another
# style (0.00001 and 1e-6 .. 1e-9 where repr writes 1e-05 .. 1e-09); rows holding a number
# of magnitude in this (slightly wider) range are formatted by repr, in sub-blocks of
# _SUB_ROWS rows (checked against repr on 6e5 random doubles of every exponent in
# tests/test_io_streaming.py)
_ORJSON_ODD = (9e-11, 1e-4)
_SUB_ROWS = 512


def _write_text(dest: Source, text: str) -> None:
    with open_destination(dest) as out:
        out.write(text)


def detect_format(path: str | os.PathLike | None, format: str | None = None) -> str:
    """Return the format name of a file, from `format` if given, else from the suffix.

    Parameters
    ----------
    path : str or path-like or None
        File name; only its suffix is used (``.csv``/``.txt`` -> ``"csv"``,
        ``.geojson``/``.json`` -> ``"geojson"``, ``.svg`` -> ``"svg"``,
        case-insensitive).
    format : str, optional
        Explicit format, one of :data:`FORMATS` (``"json"`` is accepted for
        ``"geojson"``); it wins over the suffix.

    Returns
    -------
    str
        One of :data:`FORMATS`.

    Raises
    ------
    CurveFormatError
        For an unknown format name or suffix; the message lists the supported ones.

    Examples
    --------
    >>> detect_format("lake.GeoJSON")
    'geojson'
    >>> detect_format("curve.dat")
    Traceback (most recent call last):
    ...
    curvesmith.errors.CurveFormatError: curve.dat: unknown file suffix '.dat'; supported suffixes are .csv, .txt (CSV), .geojson, .json (GeoJSON), .svg (SVG), or pass format= one of csv, geojson, svg
    """  # noqa: E501
    if format is not None:
        return _format_named(format).name
    names = ", ".join(REGISTRY)
    if path is None:
        raise CurveFormatError(
            f"cannot detect the format without a file name; pass format= one of {names}"
        )
    suffix = Path(path).suffix.lower()
    for fmt in REGISTRY.values():
        if suffix in fmt.suffixes:
            return fmt.name
    what = f"unknown file suffix {suffix!r}" if suffix else "no file suffix"
    raise CurveFormatError(
        f"{os.fspath(path)}: {what}; supported suffixes are {_suffix_text()}, "
        f"or pass format= one of {names}"
    )


def _format_for(obj, format: str | None) -> str:
    if format is not None:
        return detect_format(None, format)
    name = _name_of(obj)
    if name == _STREAM or (not isinstance(obj, str | os.PathLike) and name.startswith("<")):
        raise CurveFormatError(
            f"cannot detect the format of a stream; pass format= one of {', '.join(REGISTRY)}"
        )
    return detect_format(name)


def read_curves(
    source: Source, *, format: str | None = None, tolerance: float | None = None
) -> list[Curve]:
    """Read all curves of a CSV, GeoJSON or SVG file.

    Parameters
    ----------
    source : str or path-like or text file object
        The file. A file object must be opened in text mode (bytes are
        decoded as UTF-8).
    format : str, optional
        One of :data:`FORMATS`; default: from the file name's suffix (see
        :func:`detect_format`). Required for streams without a name.
    tolerance : float, optional
        SVG flattening tolerance in user units (see :func:`read_svg`); not used
        by the polyline formats CSV and GeoJSON.

    Returns
    -------
    list of Curve
        At least one curve, in file order.

    Raises
    ------
    CurveFormatError
        If the file is missing, empty or malformed; the message names the file.
    """
    fmt = REGISTRY[_format_for(source, format)]
    options = {"tolerance": tolerance} if "tolerance" in fmt.read_options else {}
    return fmt.read(source, **options)


def write_curves(
    curves: Iterable[Curve], dest: Source, *, format: str | None = None, **options: Any
) -> None:
    """Write curves to a CSV, GeoJSON or SVG file.

    Parameters
    ----------
    curves : iterable of Curve
        Curves to write (at least one).
    dest : str or path-like or text file object
        The file, overwritten if it exists.
    format : str, optional
        One of :data:`FORMATS`; default: from the file name's suffix.
    **options
        Passed to the format's writer (:func:`write_geojson` ``orient``,
        :func:`write_svg` ``stroke``, ``stroke_width``, ``fill``).

    Raises
    ------
    CurveFormatError
        If the curves cannot be written in this format (3D curves to SVG,
        inconsistent structure) or the file cannot be written.
    """
    REGISTRY[_format_for(dest, format)].write(curves, dest, **options)


def _check_curves(curves: Iterable[Curve]) -> list[Curve]:
    if isinstance(curves, Curve):
        curves = [curves]
    out = list(curves)
    for i, c in enumerate(out):
        if not isinstance(c, Curve):
            raise CurveError(f"curves must hold Curve objects, got {type(c).__name__} at index {i}")
    if not out:
        raise CurveFormatError("nothing to write: curves is empty")
    return out


def _json_default(value):
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, Mapping):
        return dict(value)
    if isinstance(value, tuple | set | frozenset):
        return list(value)
    raise TypeError(f"{type(value).__name__} is not JSON serializable")
