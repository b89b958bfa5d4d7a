r"""Read and write curve files: CSV, GeoJSON and SVG.

Every reader returns a list of :class:`Curve` objects, every writer takes one.
A :class:`Curve` holds the vertices of one polyline or one polygon ring plus
where it came from (feature, part, ring, geometry kind, properties), so that
``read -> transform the points -> write`` gives back a file with the same
structure.

Conventions
-----------
Points and closedness
    ``Curve.points`` is a ``(N, 2)`` or ``(N, 3)`` float64 array. A closed
    curve (a ring) never repeats its first vertex at the end; writers add the
    repeated closing vertex back where the format requires it (CSV, GeoJSON).
    In a file, a curve is closed when the format says so: a ``closed`` column
    (CSV), a Polygon ring (GeoJSON), a ``Z`` command or a ``polygon``,
    ``rect``, ``circle`` or ``ellipse`` element (SVG). Where the format has no
    such flag (a CSV file without ``closed`` column, a GeoJSON LineString),
    a curve of at least 4 vertices whose last vertex repeats the first exactly
    is a closed ring, the usual file convention of GeoJSON/WKT rings; the
    repeat is dropped.
CSV
    A header row is required, with columns ``x``, ``y`` and optionally ``z``
    (case-insensitive, in any order). Several curves are told apart by an
    ``id`` column: rows are grouped by id in order of first appearance, and
    the id is kept as ``properties["id"]``. An optional ``closed`` column
    (``true/false``, ``1/0``, ``yes/no``) must be constant along a curve. Any
    other column that is constant along a curve becomes a property of that
    curve; a column that varies along a curve cannot follow the curve through
    smoothing and is dropped with a ``UserWarning`` that names it. Values are
    separated by commas, tabs or semicolons (taken from the header line) or,
    for a header without any of these, by whitespace; blank lines and lines
    starting with ``#`` are skipped. Property values are read as ``int`` or
    ``float`` when the text is their canonical spelling (so that writing them
    back gives the same text), otherwise as ``str``. The writer puts
    ``x,y[,z]`` first, then ``id`` (when there are several curves or a curve
    has an id), ``closed`` (when a curve is closed, or an open curve ends
    where it starts) and the properties; closed rings repeat their first
    point. Floats are written with ``repr``, the shortest text that reads back
    to the same float, so CSV round trips are bit-exact.
GeoJSON (RFC 7946)
    Read: a FeatureCollection, a Feature or a bare geometry; LineString,
    Polygon (exterior ring and holes), MultiLineString, MultiPolygon and
    GeometryCollections of these. ``Curve.feature`` is the index of the
    feature, ``part`` the index inside a Multi* geometry, ``ring`` 0 for an
    exterior ring or a line and k for the k-th hole, ``member`` the index in
    a GeometryCollection (None otherwise), ``kind`` the geometry type,
    ``properties`` the feature's properties and ``feature_id`` its ``id``.
    Points, MultiPoints, null geometries, empty geometries and nested
    GeometryCollections are refused with a :class:`CurveFormatError` naming
    the feature: they are not curves, and skipping them would silently lose
    data. ``bbox`` and foreign members are not kept; a ``crs`` member (old
    GeoJSON) is dropped with a ``UserWarning`` naming it. Coordinates with a
    third value keep it (``(N, 3)`` points).
    Write: always a FeatureCollection, one feature per distinct
    ``Curve.feature`` (in order of first appearance), its geometry rebuilt
    from ``kind``, ``member``, ``part`` and ``ring``. Rings are closed by
    repeating their first position. With ``orient=True`` (default) exterior
    rings are written counter-clockwise and holes clockwise, as RFC 7946
    section 3.1.6 asks (a reversed ring keeps its first vertex); orientation
    is judged on x and y. Floats are written with ``repr``: round trips are
    bit-exact.
SVG
    Read with `svgelements`: ``path`` (every command, absolute and relative,
    including elliptical arcs), ``polyline``, ``polygon``, ``line``, ``rect``
    (also with rounded corners), ``circle`` and ``ellipse``, also through
    ``use``; ``transform`` attributes are applied; ``display="none"``
    elements and the content of ``defs`` are not drawn and not read. Each
    subpath becomes one curve, closed when it ends with ``Z`` (closed
    subpaths that the fill rule leaves empty inside another one are read as
    holes, see :func:`read_svg`); a lone
    ``moveto`` draws nothing and is skipped, zero-length segments are dropped,
    and a closed subpath with only two distinct vertices (it encloses no
    area) is read as an open curve. Coordinates are the SVG user coordinates
    of the outermost ``svg`` element (its ``viewBox`` coordinates), with the
    y axis pointing down as in SVG: nothing is flipped, so a shape that looks
    counter-clockwise on screen has negative signed area here; flipping for
    display is the plotting code's job. Curved segments are flattened to
    polylines whose maximal distance from the exact curve (chord deviation)
    is at most ``tolerance`` user units; by default ``tolerance`` is
    ``1e-4`` times the diagonal of the drawing's bounding box (of the
    control points). The number of chords per segment follows the classical
    bound ``max |c(t) - chord| <= h**2 / 8 * max |c''|`` for a parameter step
    ``h`` (Wang's formula for Bézier curves; for an elliptic arc
    ``|c''| <= max(rx, ry)`` in the angle parameter), so segments with more
    curvature get more chords; under a transform the tolerance is divided by
    the transform's largest singular value before flattening. Lines and
    polyline vertices are kept exactly.
    Write: one ``<path>`` per feature (``M x,y L ... Z``, one subpath per
    curve, ``fill-rule="evenodd"`` so that holes render as holes), a
    ``viewBox`` fitted to the data with a 2 % margin, a stroke whose width is
    1/400 of the drawing size, and a fill for closed curves when ``fill`` is
    given. The curves' properties and structure (kind, member, part, ring,
    feature id) are stored in a ``data-curvesmith`` JSON attribute, and
    ``properties["id"]`` also as the element ``id``, so reading the file
    back restores them. SVG is planar: 3D curves raise
    :class:`CurveFormatError`.
Errors
    Every problem with a file raises :class:`~curvesmith.errors.CurveFormatError`
    (a :class:`~curvesmith.errors.CurveError`, hence a ``ValueError``) whose
    message starts with the file name (``<stream>`` for an unnamed stream)
    and says what is wrong: missing file, empty file, unknown suffix,
    malformed JSON or XML (with line and column), missing columns,
    non-numeric values (with the line number), curves with too few points,
    non-curve geometries, an SVG without drawable elements.

Examples
--------
>>> import io
>>> curves = read_csv(io.StringIO("x,y\n0,0\n1,0\n1,1\n0,0\n"))
>>> curves[0].closed, curves[0].points.shape
(True, (3, 2))
>>> buf = io.StringIO()
>>> write_geojson(curves, buf)
>>> read_geojson(io.StringIO(buf.getvalue()))[0].kind
'Polygon'
"""

from __future__ import annotations

import csv
import dataclasses
import io as _stdio
import itertools
import json
import math
import os
import re
import warnings
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, TextIO
from xml.sax.saxutils import escape, quoteattr

import numpy as np

from ._validate import as_float, as_points
from .errors import CurveError, CurveFormatError
from .geometry import _signed_area

__all__ = [
    "FORMATS",
    "KINDS",
    "Curve",
    "detect_format",
    "read_csv",
    "read_curves",
    "read_geojson",
    "read_svg",
    "write_csv",
    "write_curves",
    "write_geojson",
    "write_svg",
]

FORMATS = ("csv", "geojson", "svg")
"""Names of the supported formats, as accepted by ``format=``."""

KINDS = ("LineString", "Polygon", "MultiLineString", "MultiPolygon")
"""Geometry kinds a :class:`Curve` can come from (GeoJSON geometry type names)."""

_SUFFIXES = {".csv": "csv", ".txt": "csv", ".geojson": "geojson", ".json": "geojson", ".svg": "svg"}
_SUFFIX_TEXT = ".csv, .txt (CSV), .geojson, .json (GeoJSON), .svg (SVG)"
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
        if self.kind not in KINDS:
            raise CurveError(f"kind must be one of {', '.join(KINDS)}, got {self.kind!r}")
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

    def replace(self, points=None, *, closed: bool | None = None, **changes: Any) -> Curve:
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


def _write_text(dest: Source, text: str) -> None:
    if isinstance(dest, str | os.PathLike):
        path = Path(dest)
        try:
            path.write_text(text, encoding="utf-8", newline="\n")
        except FileNotFoundError:
            raise CurveFormatError(
                f"{os.fspath(dest)}: cannot write the file: the directory "
                f"{os.fspath(path.parent)!r} does not exist"
            ) from None
        except IsADirectoryError:
            raise CurveFormatError(f"{os.fspath(dest)}: is a directory, not a file") from None
        except OSError as exc:
            raise CurveFormatError(
                f"{os.fspath(dest)}: cannot write the file: {exc.strerror or exc}"
            ) from None
    elif hasattr(dest, "write"):
        dest.write(text)
    else:
        raise CurveFormatError(
            f"dest must be a path or a text file object, got {type(dest).__name__}"
        )


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
        fmt = str(format).lower()
        fmt = "geojson" if fmt == "json" else fmt
        if fmt not in FORMATS:
            raise CurveFormatError(f"format must be one of {', '.join(FORMATS)}, got {format!r}")
        return fmt
    if path is None:
        raise CurveFormatError(
            "cannot detect the format without a file name; "
            f"pass format= one of {', '.join(FORMATS)}"
        )
    suffix = Path(path).suffix.lower()
    if suffix not in _SUFFIXES:
        what = f"unknown file suffix {suffix!r}" if suffix else "no file suffix"
        raise CurveFormatError(
            f"{os.fspath(path)}: {what}; supported suffixes are {_SUFFIX_TEXT}, "
            f"or pass format= one of {', '.join(FORMATS)}"
        )
    return _SUFFIXES[suffix]


def _format_for(obj, format: str | None) -> str:
    if format is not None:
        return detect_format(None, format)
    name = _name_of(obj)
    if name == _STREAM or (not isinstance(obj, str | os.PathLike) and name.startswith("<")):
        raise CurveFormatError(
            f"cannot detect the format of a stream; pass format= one of {', '.join(FORMATS)}"
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
    fmt = _format_for(source, format)
    if fmt == "csv":
        return read_csv(source)
    if fmt == "geojson":
        return read_geojson(source)
    return read_svg(source, tolerance=tolerance)


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
    fmt = _format_for(dest, format)
    writer = {"csv": write_csv, "geojson": write_geojson, "svg": write_svg}[fmt]
    writer(curves, dest, **options)


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


# ----------------------------------------------------------------------------------------------
# CSV

_TRUE = frozenset({"true", "1", "yes", "t", "y"})
_FALSE = frozenset({"false", "0", "no", "f", "n"})
_RESERVED = ("x", "y", "z", "id", "closed")


def _scalar(text: str):
    """Read a property cell: int or float when `text` is their canonical spelling, else str."""
    try:
        value = int(text)
        if str(value) == text:
            return value
    except ValueError:
        pass
    try:
        value = float(text)
        if repr(value) == text:
            return value
    except ValueError:
        pass
    return text


def _cell(value) -> str:
    if value is None:
        return ""
    if isinstance(value, bool | np.bool_):
        return "true" if value else "false"
    if isinstance(value, int | np.integer):
        return str(int(value))
    if isinstance(value, float | np.floating):
        return repr(float(value))
    if isinstance(value, str):
        return value
    return json.dumps(value, default=str)


_SPACE = (" ", "\t", "\x0b", "\x0c", "\x1c", "\x1d", "\x1e", "\x1f")


def _split_lines(text: str, name: str) -> tuple[Sequence[int], list[str], list[list[str]]]:
    """Split CSV text into line numbers, header fields and data columns.

    Returns the line number of the header and of every data row (blank lines
    and lines starting with ``#`` are skipped), the stripped header fields and
    the stripped data fields as columns (one list per field position; rows
    with the wrong number of fields raise, naming the line).
    """
    lines = text.splitlines()
    while lines and not lines[-1].strip():
        lines.pop()
    fast = _split_simple(lines)
    if fast is not None:
        return fast
    numbered = [
        (n, line)
        for n, line in enumerate(lines, 1)
        if line.strip() and not line.lstrip().startswith("#")
    ]
    if not numbered:
        raise CurveFormatError(f"{name}: the file holds only comments and blank lines")
    header = numbered[0][1]
    delimiter = next((d for d in (",", "\t", ";") if d in header), None)
    numbers = [n for n, _ in numbered]
    if delimiter is None:
        rows = [line.split() for _, line in numbered]
    else:
        rows = list(csv.reader((line for _, line in numbered), delimiter=delimiter))
        rows = [[f.strip() for f in row] for row in rows]
    head = rows[0]
    for n, fields in zip(numbers[1:], rows[1:], strict=True):
        if len(fields) != len(head):
            raise CurveFormatError(
                f"{name}: line {n}: expected {len(head)} fields ({','.join(head)}), "
                f"got {len(fields)}"
            )
    columns = [list(col) for col in zip(*rows[1:], strict=True)] if len(rows) > 1 else []
    return numbers, head, columns


def _split_simple(lines: list[str]) -> tuple[range, list[str], list[list[str]]] | None:
    """Fast path of :func:`_split_lines` for plain files, None when it does not apply.

    Plain means: the first line is the header and holds a comma, tab or
    semicolon; no quotes, comments or blank lines; every row has as many
    fields as the header. Then splitting the joined rows once gives exactly
    the fields :mod:`csv` would give, and a million rows take a fraction of
    a second instead of seconds.
    """
    if len(lines) < 2 or not lines[0].strip() or lines[0].lstrip().startswith("#"):
        return None
    header = lines[0]
    delimiter = next((d for d in (",", "\t", ";") if d in header), None)
    if delimiter is None or '"' in header:
        return None
    data = lines[1:]
    body = delimiter.join(data)
    if '"' in body:
        return None
    if "#" in body and any(line.lstrip().startswith("#") for line in data):
        return None
    ncol = header.count(delimiter) + 1
    if set(map(str.count, data, itertools.repeat(delimiter))) != {ncol - 1}:
        return None  # blank lines or ragged rows: the general path reports them by line
    cells = body.split(delimiter)
    if not body.isascii() or any(c in body for c in _SPACE):
        cells = [c.strip() for c in cells]
    columns = [cells[k::ncol] for k in range(ncol)]
    head = [f.strip() for f in header.split(delimiter)]
    return range(1, len(lines) + 1), head, columns


def read_csv(source: Source) -> list[Curve]:
    r"""Read curves from a CSV file with a header ``x,y[,z]`` and optional ``id``, ``closed``.

    Parameters
    ----------
    source : str or path-like or text file object
        The file. See the module docstring for the conventions (header,
        ``id`` groups, ``closed`` column, properties, delimiters, comments).

    Returns
    -------
    list of Curve
        One curve per id (one in total without an ``id`` column), in order of
        first appearance; ``feature`` is that order, ``kind`` is
        ``"Polygon"`` for closed curves and ``"LineString"`` for open ones.

    Raises
    ------
    CurveFormatError
        If the header or a column is missing, a value is not a finite number
        (the message gives the line), a row has the wrong number of fields,
        ``closed`` is not a boolean or varies along a curve, or a curve has
        too few points.

    Examples
    --------
    >>> import io
    >>> text = "id,x,y\na,0,0\na,1,0\nb,5,5\nb,6,5\nb,6,6\n"
    >>> [(c.properties["id"], len(c.points), c.closed) for c in read_csv(io.StringIO(text))]
    [('a', 2, False), ('b', 3, False)]
    """
    text, name = _read_text(source)
    numbers, header, columns = _split_lines(text, name)
    lower = [h.lower() for h in header]
    for col in ("x", "y"):
        if col not in lower:
            if all(_is_number(h) for h in header):
                raise CurveFormatError(
                    f"{name}: line {numbers[0]}: missing header row; the first line must name "
                    f"the columns, e.g. x,y or x,y,z (got {','.join(header)!r})"
                )
            raise CurveFormatError(
                f"{name}: missing column {col!r}; the header has columns {header}, "
                "expected x,y[,z] (case-insensitive)"
            )
    dup = sorted({h for h in lower if lower.count(h) > 1})
    if dup:
        raise CurveFormatError(f"{name}: duplicate column names {dup} in the header")
    index = {h: i for i, h in enumerate(lower)}
    coord_cols = [c for c in ("x", "y", "z") if c in index]
    extra = [i for i, h in enumerate(lower) if h not in _RESERVED]
    if not columns or not columns[0]:
        raise CurveFormatError(f"{name}: no data rows after the header")
    nrows = len(columns[0])
    cols = [index[c] for c in coord_cols]
    try:
        # numpy parses decimal text exactly like float(): correctly rounded, bit-exact
        coords = np.stack([np.array(columns[i], dtype=np.float64) for i in cols], axis=1)
    except ValueError:
        coords = None
    if coords is None or not np.isfinite(coords).all():
        for r in range(nrows):
            for i in cols:
                cell = columns[i][r]
                try:
                    value = float(cell)
                except ValueError:
                    raise CurveFormatError(
                        f"{name}: line {numbers[r + 1]}: {header[i]} value {cell!r} is not a number"
                    ) from None
                if not math.isfinite(value):
                    raise CurveFormatError(
                        f"{name}: line {numbers[r + 1]}: {header[i]} value {cell!r} is not finite"
                    )
        coords = np.array([[float(columns[i][r]) for i in cols] for r in range(nrows)])
    groups: dict[str, Any] = {}
    if "id" in index:
        for r, ident in enumerate(columns[index["id"]]):
            groups.setdefault(ident, []).append(r)
        groups = {ident: np.array(rows_of) for ident, rows_of in groups.items()}
    else:
        groups[""] = np.arange(nrows)
    curves = []
    varying: dict[str, list[str]] = {}
    for feature, (ident, rows_of) in enumerate(groups.items()):
        label = f"curve {ident!r}" if "id" in index else "the curve"
        where = f"{label} (lines {numbers[rows_of[0] + 1]}-{numbers[rows_of[-1] + 1]})"
        pts = coords[rows_of]
        if "closed" in index:
            flags = set()
            column = columns[index["closed"]]
            for r in rows_of.tolist():
                cell = column[r].lower()
                if cell in _TRUE:
                    flags.add(True)
                elif cell in _FALSE:
                    flags.add(False)
                else:
                    raise CurveFormatError(
                        f"{name}: line {numbers[r + 1]}: closed value {column[r]!r} is not "
                        "true/false, 1/0 or yes/no"
                    )
            if len(flags) > 1:
                raise CurveFormatError(
                    f"{name}: {where}: the closed column must be constant along a curve, "
                    "got both true and false"
                )
            closed = flags.pop()
        else:
            closed = len(pts) >= 4 and bool(np.array_equal(pts[0], pts[-1]))
        props: dict[str, Any] = {}
        if "id" in index:
            props["id"] = _scalar(ident)
        for i in extra:
            column = columns[i]
            values = {column[r] for r in rows_of.tolist()}
            if len(values) > 1:
                varying.setdefault(header[i], []).append(label)
            else:
                value = values.pop()
                if value != "":
                    props[header[i]] = _scalar(value)
        try:
            curve = Curve(
                pts,
                closed=closed,
                properties=props,
                feature=feature,
                kind="Polygon" if closed else "LineString",
            )
        except CurveError as exc:
            raise CurveFormatError(f"{name}: {where}: {exc}") from None
        curves.append(curve)
    for col, labels in varying.items():
        warnings.warn(
            f"{name}: column {col!r} varies along {', '.join(labels)}; only columns that are "
            "constant along a curve are kept (as properties), so it was dropped",
            UserWarning,
            stacklevel=2,
        )
    return curves


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def _distinct_ids(ids: list) -> list[str]:
    """CSV id cells, one per curve and all distinct (the id column is what separates curves).

    A curve's cell is its id property; a curve without one gets its index. Curves that share a
    cell (the rings and parts of one GeoJSON feature with an ``id`` property, the subpaths of
    one SVG element, two ``<use>`` of one symbol) get ``#0``, ``#1``, ... appended in file
    order, skipping texts that are taken.
    """
    base = [str(i) if v is None else _cell(v) for i, v in enumerate(ids)]
    counts: dict[str, int] = {}
    for b in base:
        counts[b] = counts.get(b, 0) + 1
    taken = set(base)
    cells = []
    next_k: dict[str, int] = {}
    for b in base:
        if counts[b] == 1:
            cells.append(b)
            continue
        k = next_k.get(b, 0)
        while f"{b}#{k}" in taken:
            k += 1
        next_k[b] = k + 1
        taken.add(f"{b}#{k}")
        cells.append(f"{b}#{k}")
    return cells


def write_csv(curves: Iterable[Curve], dest: Source) -> None:
    """Write curves to a CSV file that :func:`read_csv` reads back bit-exactly.

    Parameters
    ----------
    curves : iterable of Curve
        2D curves or 3D curves (not both in one file).
    dest : str or path-like or text file object
        The file.

    Raises
    ------
    CurveFormatError
        If 2D and 3D curves are mixed, or a property name clashes with a
        column name (x, y, z, id, closed).

    Notes
    -----
    Columns: ``x,y[,z]``, then ``id`` when there is more than one curve or a
    curve has ``properties["id"]`` (the id property, or the curve's index for
    a curve without one; ids shared by several curves, such as the rings of
    one polygon or the subpaths of one SVG element, get ``#0``, ``#1``, ...
    appended, since the id column is what tells curves apart), ``closed``
    when a curve is closed or an open curve ends where it starts, then the
    other properties (union of their names, empty cells where a curve lacks
    one; booleans as ``true``/``false``, lists and mappings as JSON text,
    which reads back as text). Closed rings repeat their first point. Floats are written with
    ``repr``.

    Examples
    --------
    >>> import io
    >>> buf = io.StringIO()
    >>> write_csv([Curve([[0, 0], [1, 0], [0, 1]], closed=True)], buf)
    >>> print(buf.getvalue(), end="")
    x,y,closed
    0.0,0.0,true
    1.0,0.0,true
    0.0,1.0,true
    0.0,0.0,true
    """
    curves = _check_curves(curves)
    dims = sorted({c.dim for c in curves})
    if len(dims) > 1:
        raise CurveFormatError(
            "cannot write 2D and 3D curves to one CSV file (a column z would be empty for "
            "the 2D ones); write them to separate files"
        )
    ids = [c.properties.get("id") for c in curves]
    id_cells = None if len(curves) == 1 and ids[0] is None else _distinct_ids(ids)
    need_closed = any(c.closed or bool(np.array_equal(c.points[0], c.points[-1])) for c in curves)
    keys: list[str] = []
    for i, c in enumerate(curves):
        for key in c.properties:
            if key == "id":
                continue
            if str(key).lower() in _RESERVED:
                raise CurveFormatError(
                    f"property {key!r} of curve {i} clashes with the CSV column {key.lower()!r}; "
                    "rename it before writing CSV"
                )
            if key not in keys:
                keys.append(key)
    header = ["x", "y", "z"][: dims[0]]
    if id_cells is not None:
        header.append("id")
    if need_closed:
        header.append("closed")
    header.extend(str(k) for k in keys)
    buf = _stdio.StringIO()
    writer = csv.writer(buf, lineterminator="\n")
    writer.writerow(header)
    for i, c in enumerate(curves):
        tail = []
        if id_cells is not None:
            tail.append(id_cells[i])
        if need_closed:
            tail.append("true" if c.closed else "false")
        tail.extend(_cell(c.properties.get(k)) for k in keys)
        pts = c.points.tolist()
        if c.closed:
            pts.append(pts[0])
        # The coordinates (float reprs) never need quoting, so only the first row goes through
        # the csv writer; its quoted tail is reused verbatim by the other rows (same bytes,
        # several times faster on large curves).
        one = _stdio.StringIO()
        csv.writer(one, lineterminator="\n").writerow([*map(repr, pts[0]), *tail])
        first = one.getvalue()
        buf.write(first)
        suffix = first[len(",".join(map(repr, pts[0]))) :]
        cols = [list(map(repr, col)) for col in zip(*pts[1:], strict=True)]
        buf.write("".join([",".join(row) + suffix for row in zip(*cols, strict=True)]))
    _write_text(dest, buf.getvalue())


# ----------------------------------------------------------------------------------------------
# GeoJSON

_CURVE_TYPES = ("LineString", "Polygon", "MultiLineString", "MultiPolygon", "GeometryCollection")
_GEOMETRY_TYPES = (*_CURVE_TYPES, "Point", "MultiPoint")


def _describe(obj) -> str:
    if isinstance(obj, dict):
        if "type" in obj:
            return f"an object of type {obj['type']!r}"
        return f"an object with keys {sorted(obj)[:6]} and no 'type'"
    if isinstance(obj, list):
        return f"an array of {len(obj)} values"
    return f"a {type(obj).__name__} ({obj!r:.40})"


def _reject_constant(token: str):
    raise CurveFormatError(f"{token} is not valid JSON (numbers must be finite)")


class _GeoJSONReader:
    def __init__(self, name: str):
        self.name = name
        self.curves: list[Curve] = []

    def fail(self, where: str, message: str) -> CurveFormatError:
        return CurveFormatError(
            f"{self.name}: {where}: {message}" if where else f"{self.name}: {message}"
        )

    def top(self, obj) -> None:
        if not isinstance(obj, dict) or "type" not in obj:
            raise self.fail(
                "", f"expected a GeoJSON object with a 'type' member, found {_describe(obj)}"
            )
        kind = obj["type"]
        crs = obj.get("crs")
        props = crs.get("properties") if isinstance(crs, dict) else None
        label = props.get("name") if isinstance(props, dict) else None
        if crs is not None and not (isinstance(label, str) and label.endswith("CRS84")):
            warnings.warn(
                f"{self.name}: the 'crs' member ({label or crs!r}) is not kept; files written "
                "from these curves have none, and RFC 7946 readers will take the coordinates as "
                "WGS 84 longitude/latitude",
                UserWarning,
                stacklevel=4,
            )
        if kind == "FeatureCollection":
            features = obj.get("features")
            if not isinstance(features, list):
                raise self.fail(
                    "",
                    "the FeatureCollection's 'features' must be an array, "
                    f"found {_describe(features)}",
                )
            for i, feat in enumerate(features):
                self.feature(feat, i)
            if not features:
                raise self.fail("", "the FeatureCollection has no features, so no curves")
        elif kind == "Feature":
            self.feature(obj, 0)
        elif kind in _GEOMETRY_TYPES:
            self.geometry(obj, "geometry", 0, {}, None, None)
        else:
            raise self.fail(
                "",
                f"unknown GeoJSON type {kind!r}; expected FeatureCollection, Feature or one of "
                f"{', '.join(_GEOMETRY_TYPES)}",
            )

    def feature(self, feat, i: int) -> None:
        where = f"feature {i}"
        if not isinstance(feat, dict) or feat.get("type") != "Feature":
            raise self.fail(where, f"expected a Feature object, found {_describe(feat)}")
        props = feat.get("properties")
        if props is None:
            props = {}
        if not isinstance(props, dict):
            raise self.fail(
                where, f"properties must be an object or null, found {_describe(props)}"
            )
        geom = feat.get("geometry")
        if geom is None:
            raise self.fail(
                where,
                "the geometry is null; curvesmith reads only curves (LineString, Polygon, "
                "MultiLineString, MultiPolygon)",
            )
        fid = feat.get("id")
        if fid is not None and (isinstance(fid, bool) or not isinstance(fid, str | int | float)):
            raise self.fail(where, f"id must be a string or a number, found {_describe(fid)}")
        self.geometry(geom, where, i, props, fid, None)

    def positions(self, coords, where: str) -> np.ndarray:
        if not isinstance(coords, list) or not all(isinstance(p, list) for p in coords):
            raise self.fail(
                where, f"coordinates must be an array of positions, found {_describe(coords)}"
            )
        sizes = {len(p) for p in coords}
        if sizes - {2, 3}:
            raise self.fail(
                where,
                f"positions must have 2 or 3 numbers (x, y[, z]), found {sorted(sizes)}",
            )
        if len(sizes) > 1:
            raise self.fail(where, "positions mix 2 and 3 coordinates")
        if not all(
            isinstance(v, int | float) and not isinstance(v, bool) for p in coords for v in p
        ):
            raise self.fail(where, "coordinates must be numbers")
        return np.array(coords, dtype=np.float64).reshape(len(coords), -1)

    def add(self, where: str, pts: np.ndarray, closed: bool, **fields) -> None:
        try:
            self.curves.append(Curve(pts, closed=closed, **fields))
        except CurveError as exc:
            raise self.fail(where, str(exc)) from None

    def array(self, coords, where: str, what: str) -> list:
        if not isinstance(coords, list):
            raise self.fail(
                where, f"coordinates must be an array of {what}, found {_describe(coords)}"
            )
        if not coords:
            raise self.fail(where, f"the geometry is empty (no {what}), so it has no curves")
        return coords

    def geometry(self, geom, where, feature, props, fid, member) -> None:
        if not isinstance(geom, dict) or "type" not in geom:
            raise self.fail(where, f"expected a geometry object, found {_describe(geom)}")
        kind = geom["type"]
        common = {"properties": props, "feature": feature, "feature_id": fid, "member": member}
        coords = geom.get("coordinates")
        if kind in ("Point", "MultiPoint"):
            raise self.fail(
                where,
                f"a {kind} is not a curve; curvesmith reads LineString, Polygon, MultiLineString, "
                "MultiPolygon (and GeometryCollections of them)",
            )
        if kind == "GeometryCollection":
            if member is not None:
                raise self.fail(
                    where, "nested GeometryCollections are not supported (RFC 7946 3.1.8)"
                )
            members = self.array(geom.get("geometries"), where, "geometries")
            for j, g in enumerate(members):
                self.geometry(g, f"{where}, member {j}", feature, props, fid, j)
            return
        if kind == "LineString":
            pts = self.positions(self.array(coords, where, "positions"), where)
            closed = len(pts) >= 4 and bool(np.array_equal(pts[0], pts[-1]))
            self.add(where, pts, closed, kind=kind, **common)
        elif kind == "MultiLineString":
            for k, line in enumerate(self.array(coords, where, "lines")):
                w = f"{where} (MultiLineString part {k})"
                pts = self.positions(self.array(line, w, "positions"), w)
                closed = len(pts) >= 4 and bool(np.array_equal(pts[0], pts[-1]))
                self.add(w, pts, closed, kind=kind, part=k, **common)
        elif kind == "Polygon":
            self.polygon(self.array(coords, where, "rings"), where, kind, 0, common)
        elif kind == "MultiPolygon":
            for k, poly in enumerate(self.array(coords, where, "polygons")):
                w = f"{where} (MultiPolygon part {k})"
                self.polygon(self.array(poly, w, "rings"), w, kind, k, common)
        else:
            raise self.fail(
                where,
                f"unknown geometry type {kind!r}; expected one of {', '.join(_GEOMETRY_TYPES)}",
            )

    def polygon(self, rings, where, kind, part, common) -> None:
        for r, ring in enumerate(rings):
            w = f"{where} ring {r}" + (" (exterior)" if r == 0 else " (hole)")
            pts = self.positions(self.array(ring, w, "positions"), w)
            self.add(w, pts, True, kind=kind, part=part, ring=r, **common)


def read_geojson(source: Source) -> list[Curve]:
    """Read curves from a GeoJSON file (RFC 7946).

    Parameters
    ----------
    source : str or path-like or text file object
        A FeatureCollection, a Feature or a bare geometry.

    Returns
    -------
    list of Curve
        One curve per line and per ring, in file order, with ``feature``,
        ``part``, ``ring``, ``member``, ``kind``, ``properties`` and
        ``feature_id`` describing where it came from (see the module docstring).

    Raises
    ------
    CurveFormatError
        For malformed JSON (with line and column), a structure that is not
        GeoJSON (naming what was found), Point/MultiPoint, null or empty
        geometries, and curves with too few points.

    Examples
    --------
    >>> import io
    >>> text = '''{"type": "Polygon", "coordinates": [
    ...     [[0, 0], [4, 0], [4, 4], [0, 4], [0, 0]],
    ...     [[1, 1], [1, 2], [2, 2], [2, 1], [1, 1]]]}'''
    >>> [(c.ring, len(c.points), c.closed) for c in read_geojson(io.StringIO(text))]
    [(0, 4, True), (1, 4, True)]
    """
    text, name = _read_text(source)
    try:
        obj = json.loads(text, parse_constant=_reject_constant)
    except json.JSONDecodeError as exc:
        raise CurveFormatError(
            f"{name}: malformed JSON at line {exc.lineno}, column {exc.colno}: {exc.msg}"
        ) from None
    except CurveFormatError as exc:
        raise CurveFormatError(f"{name}: {exc}") from None
    reader = _GeoJSONReader(name)
    reader.top(obj)
    return reader.curves


def _area_sign(points: np.ndarray) -> int:
    """Sign of the signed area of a closed ring (x, y), exact also for extreme coordinates.

    The shoelace sum is evaluated in floating point after an exact power-of-two
    scaling (no overflow) with ``math.fsum``; when its magnitude is below the
    rounding error bound, the sign is recomputed exactly with fractions.
    """
    p = points[:, :2]
    top = float(np.abs(p).max())
    if top == 0.0:
        return 0
    q = np.ldexp(p, -math.frexp(top)[1])
    x, y = q[:, 0], q[:, 1]
    xn, yn = np.roll(x, -1), np.roll(y, -1)
    a, b = x * yn, xn * y
    total = math.fsum(a) - math.fsum(b)
    bound = 4.0 * np.finfo(np.float64).eps * float(np.sum(np.abs(a) + np.abs(b))) + len(p) * 1e-300
    if abs(total) > bound:
        return 1 if total > 0 else -1
    from fractions import Fraction

    xs = [Fraction(v) for v in p[:, 0].tolist()]
    ys = [Fraction(v) for v in p[:, 1].tolist()]
    exact = sum(xs[i - 1] * ys[i] - xs[i] * ys[i - 1] for i in range(len(xs)))
    return (exact > 0) - (exact < 0)


def _oriented_ring(points: np.ndarray, ccw: bool, orient: bool) -> list:
    pts = points
    if orient:
        sign = _area_sign(points)
        if (sign < 0 and ccw) or (sign > 0 and not ccw):
            pts = np.concatenate([points[:1], points[:0:-1]])
    out = pts.tolist()
    out.append(out[0])
    return out


def _line_coords(c: Curve) -> list:
    out = c.points.tolist()
    if c.closed:
        out.append(out[0])
    elif len(out) >= 4 and out[0] == out[-1]:
        # GeoJSON has no closedness flag for LineStrings: such a line reads back as a ring.
        warnings.warn(
            f"an open curve of feature {c.feature} ends where it starts; GeoJSON readers "
            "(curvesmith included) will read it back as a closed ring",
            UserWarning,
            stacklevel=4,
        )
    return out


def _polygon_coords(rings: list[Curve], where: str, orient: bool) -> list:
    rings = sorted(rings, key=lambda c: c.ring)
    if rings[0].ring != 0:
        raise CurveFormatError(f"{where}: the polygon has holes but no exterior ring (ring 0)")
    return [_oriented_ring(c.points, c.ring == 0, orient) for c in rings]


def _unique(curves: list[Curve], key, where: str) -> None:
    seen = set()
    for c in curves:
        k = key(c)
        if k in seen:
            raise CurveFormatError(
                f"{where}: two curves have the same (member, part, ring) {k}; give curves of "
                "different geometries distinct feature indices, e.g. curve.replace(feature=i)"
            )
        seen.add(k)


def _geometry(curves: list[Curve], where: str, orient: bool) -> dict:
    kinds = {c.kind for c in curves}
    if len(kinds) > 1:
        raise CurveFormatError(
            f"{where}: curves of one geometry have different kinds {sorted(kinds)}; set "
            "member= to make a GeometryCollection or give them distinct features"
        )
    kind = kinds.pop()
    if kind == "LineString":
        if len(curves) > 1:
            raise CurveFormatError(
                f"{where}: {len(curves)} curves of kind LineString in one geometry"
            )
        return {"type": kind, "coordinates": _line_coords(curves[0])}
    if kind == "MultiLineString":
        return {
            "type": kind,
            "coordinates": [_line_coords(c) for c in sorted(curves, key=lambda c: c.part)],
        }
    if kind == "Polygon":
        return {"type": kind, "coordinates": _polygon_coords(curves, where, orient)}
    parts: dict[int, list[Curve]] = {}
    for c in curves:
        parts.setdefault(c.part, []).append(c)
    return {
        "type": kind,
        "coordinates": [
            _polygon_coords(parts[k], f"{where} part {k}", orient) for k in sorted(parts)
        ],
    }


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


def _features(curves: list[Curve], orient: bool) -> list[dict]:
    groups: dict[int, list[Curve]] = {}
    for c in curves:
        groups.setdefault(c.feature, []).append(c)
    features = []
    for feature, group in groups.items():
        where = f"feature {feature}"
        first = group[0]
        for c in group[1:]:
            if c.properties != first.properties or c.feature_id != first.feature_id:
                raise CurveFormatError(
                    f"{where}: its curves have different properties or feature ids; give them "
                    "distinct feature indices to write them as separate features"
                )
        _unique(group, lambda c: (c.member, c.part, c.ring), where)
        members = {c.member for c in group}
        if None in members and len(members) > 1:
            raise CurveFormatError(
                f"{where}: some curves are members of a GeometryCollection and some are not"
            )
        if None in members:
            geometry = _geometry(group, where, orient)
        else:
            by_member: dict[int, list[Curve]] = {}
            for c in group:
                by_member.setdefault(c.member, []).append(c)
            geometry = {
                "type": "GeometryCollection",
                "geometries": [
                    _geometry(by_member[m], f"{where} member {m}", orient)
                    for m in sorted(by_member)
                ],
            }
        feat: dict[str, Any] = {"type": "Feature"}
        if first.feature_id is not None:
            feat["id"] = first.feature_id
        feat["properties"] = first.properties
        feat["geometry"] = geometry
        features.append(feat)
    return features


def write_geojson(curves: Iterable[Curve], dest: Source, *, orient: bool = True) -> None:
    """Write curves as a GeoJSON FeatureCollection (RFC 7946).

    Parameters
    ----------
    curves : iterable of Curve
        Curves; their ``feature``, ``member``, ``part``, ``ring`` and ``kind``
        say which geometry of which feature they belong to.
    dest : str or path-like or text file object
        The file.
    orient : bool, optional
        Write exterior rings counter-clockwise and holes clockwise (RFC 7946
        section 3.1.6), reversing rings as needed while keeping their first
        vertex. With False rings keep their vertex order.

    Raises
    ------
    CurveFormatError
        If curves of one feature disagree (properties, kinds, duplicate
        (member, part, ring), a polygon without exterior ring) or a property
        cannot be written as JSON (NaN, unknown objects).

    Examples
    --------
    >>> import io
    >>> cw = Curve([[0, 0], [0, 1], [1, 1], [1, 0]], closed=True, kind="Polygon")
    >>> buf = io.StringIO()
    >>> write_geojson([cw], buf)
    >>> json.loads(buf.getvalue())["features"][0]["geometry"]["coordinates"][0]
    [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0], [0.0, 0.0]]
    """
    curves = _check_curves(curves)
    features = _features(curves, bool(orient))
    try:
        body = ",\n".join(
            json.dumps(f, allow_nan=False, ensure_ascii=False, default=_json_default)
            for f in features
        )
    except (TypeError, ValueError) as exc:
        raise CurveFormatError(f"cannot write the properties as JSON: {exc}") from None
    _write_text(dest, '{"type": "FeatureCollection", "features": [\n' + body + "\n]}\n")


# ----------------------------------------------------------------------------------------------
# SVG

_META = "data-curvesmith"
_NUMBER = r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?"
_SEP = r"(?:\s*,\s*|\s+)"
_PAIR = rf"{_NUMBER}{_SEP}{_NUMBER}"
# Path data made only of moveto/lineto/closepath with separated coordinates (what write_svg
# writes): svgelements parses it completely, so the slow strict re-parse is not needed.
_POLYLINE_D = re.compile(
    rf"\s*[Mm]\s*{_PAIR}(?:{_SEP}{_PAIR})*(?:\s*(?:[MmLl]\s*{_PAIR}(?:{_SEP}{_PAIR})*|[Zz]))*\s*"
)
_MAX_CHORDS = 1_000_000
_DEFAULT_RELATIVE_TOLERANCE = 1e-4


def _bezier_points(ctrl: np.ndarray, n: int) -> np.ndarray:
    """Points at t = k/n, k = 1..n, of the Bézier curve with control points `ctrl`."""
    t = np.arange(1, n + 1, dtype=np.float64)[:, None] / n
    s = 1.0 - t
    if len(ctrl) == 3:
        pts = s * s * ctrl[0] + 2 * s * t * ctrl[1] + t * t * ctrl[2]
    else:
        pts = s**3 * ctrl[0] + 3 * s * s * t * ctrl[1] + 3 * s * t * t * ctrl[2] + t**3 * ctrl[3]
    pts[-1] = ctrl[-1]
    return pts


def _chords(second_derivative_bound: float, tol: float) -> int:
    """Number of equal parameter steps so that h**2/8 * max|c''| <= tol on [0, 1]."""
    n = max(1, math.ceil(math.sqrt(second_derivative_bound / (8.0 * tol))))
    if n > _MAX_CHORDS:
        raise CurveFormatError(
            f"tolerance {tol:g} is too small for this drawing: one segment would need {n} chords"
        )
    return n


def _xy(p) -> list[float]:
    return [float(p[0]), float(p[1])]


def _flatten(segments, tol: float) -> list[tuple[np.ndarray, bool]]:
    """Flatten svgelements path segments into (points, closed) subpaths."""
    import svgelements as se

    subpaths: list[tuple[list, bool]] = []
    current: list | None = None

    def finish(closed: bool) -> None:
        nonlocal current
        if current is not None:
            subpaths.append((current, closed))
        current = None

    for seg in segments:
        if isinstance(seg, se.Move):
            finish(False)
            current = [np.array([_xy(seg.end)])]
            continue
        if isinstance(seg, se.Close):
            finish(True)
            continue
        if current is None:
            current = [np.array([_xy(seg.start)])]
        if isinstance(seg, se.Line):
            current.append(np.array([_xy(seg.end)]))
        elif isinstance(seg, se.QuadraticBezier):
            ctrl = np.array([_xy(seg.start), _xy(seg.control), _xy(seg.end)])
            bound = 2.0 * float(np.hypot(*(ctrl[0] - 2 * ctrl[1] + ctrl[2])))
            current.append(_bezier_points(ctrl, _chords(bound, tol)))
        elif isinstance(seg, se.CubicBezier):
            ctrl = np.array([_xy(seg.start), _xy(seg.control1), _xy(seg.control2), _xy(seg.end)])
            d0 = np.hypot(*(ctrl[0] - 2 * ctrl[1] + ctrl[2]))
            d1 = np.hypot(*(ctrl[1] - 2 * ctrl[2] + ctrl[3]))
            current.append(_bezier_points(ctrl, _chords(6.0 * float(max(d0, d1)), tol)))
        elif isinstance(seg, se.Arc):
            if seg.start == seg.end and seg.sweep == 0:
                continue
            radius = max(abs(float(seg.rx)), abs(float(seg.ry)))
            n = _chords(float(seg.sweep) ** 2 * radius, tol)
            positions = np.arange(1, n + 1, dtype=np.float64) / n
            current.append(np.asarray(seg.npoint(positions), dtype=np.float64))
        else:  # pragma: no cover - svgelements has no other segment types
            raise CurveFormatError(f"unsupported SVG path segment {type(seg).__name__}")
    finish(False)
    return _clean_subpaths([(np.concatenate(chunks), closed) for chunks, closed in subpaths], tol)


def _clean_subpaths(subpaths, tol: float) -> list[tuple[np.ndarray, bool]]:
    """Drop repeated vertices, a closing vertex equal to the start and empty subpaths."""
    out = []
    for pts, closed in subpaths:
        keep = np.ones(len(pts), dtype=bool)
        keep[1:] = np.any(pts[1:] != pts[:-1], axis=1)
        pts = pts[keep]
        if closed and len(pts) > 1 and np.hypot(*(pts[-1] - pts[0])) <= 1e-9 * tol:
            pts = pts[:-1]
        if len(pts) < 2:
            continue
        if closed and len(pts) < 3:
            closed = False
        out.append((pts, closed))
    return out


_ABSOLUTE_POLYLINE_D = re.compile(
    rf"\s*M\s*{_PAIR}(?:{_SEP}{_PAIR})*(?:\s*(?:[ML]\s*{_PAIR}(?:{_SEP}{_PAIR})*|Z))*\s*"
)
_D_ATTRIBUTE = re.compile(r'(\sd\s*=\s*)"([^"]*)"')
_FAST_D_MIN = 2000


def _polyline_subpaths(d: str) -> list[tuple[np.ndarray, bool]] | None:
    """Subpaths of path data made of absolute M, L and Z only (what :func:`write_svg` writes).

    Parsed with one split instead of one svgelements object per segment (a 10^6-vertex path
    took minutes). None when the data need the general parser: relative commands, or a Z
    that is not the end of its subpath.
    """
    if not _ABSOLUTE_POLYLINE_D.fullmatch(d):
        return None
    out = []
    for chunk in d.split("M")[1:]:
        body = chunk.rstrip()
        closed = body.endswith("Z")
        if closed:
            body = body[:-1]
        if "Z" in body:
            return None  # segments after a closepath start at the subpath's first point
        values = np.array(body.replace("L", " ").replace(",", " ").split(), dtype=np.float64)
        out.append((values.reshape(-1, 2), closed))
    return out


def _stash_polylines(text: str) -> tuple[str, dict[str, list]]:
    """Replace long plain polyline path data by short placeholders before svgelements parses.

    Returns the new text and a map from placeholder to the parsed subpaths.
    """
    stash: dict[str, list] = {}

    def replace(match):
        d = match.group(2)
        if len(d) < _FAST_D_MIN:
            return match.group(0)
        subpaths = _polyline_subpaths(d)
        if subpaths is None:
            return match.group(0)
        key = f"M 0,0 L 0,{len(stash)}.5e-300"
        stash[key] = subpaths
        return f'{match.group(1)}"{key}"'

    if len(text) < _FAST_D_MIN:
        return text, stash
    return _D_ATTRIBUTE.sub(replace, text), stash


def _own_transform(element, viewport: str):
    """The element's transform without the root viewBox-to-viewport mapping."""
    import svgelements as se

    text = element.values.get("transform", "") or ""
    if viewport and viewport in text:
        text = text.replace(viewport, " ", 1)
        return se.Matrix(text)
    if viewport:
        return ~se.Matrix(viewport) * se.Matrix(text)
    return se.Matrix(text)


def _label(element, k: int) -> str:
    tag = element.values.get("tag", type(element).__name__.lower())
    ident = f' id="{element.id}"' if element.id else ""
    return f"<{tag}{ident}> (drawable element {k})"


def read_svg(source: Source, *, tolerance: float | None = None) -> list[Curve]:
    """Read the drawable shapes of an SVG file as polylines.

    Parameters
    ----------
    source : str or path-like or text file object
        The SVG document.
    tolerance : float, optional
        Maximal distance between a flattened curved segment and the exact
        curve, in user units of the outermost ``svg`` element; default
        ``1e-4`` times the diagonal of the bounding box of all control points.

    Returns
    -------
    list of Curve
        One curve per subpath, ``feature`` the index of the element (among
        those that gave curves), ``part`` the subpath index; ``kind`` is
        LineString/Polygon for single subpaths, MultiLineString/MultiPolygon
        when all subpaths of an element are open/closed, and mixed elements
        get one ``member`` per subpath. Closed subpaths inside another one
        that the fill leaves empty (any odd depth with
        ``fill-rule="evenodd"``; opposite winding with the default
        ``nonzero``) are holes: ``ring`` k >= 1 of the polygon (``part``) of
        their container, as in a GeoJSON Polygon. Files written by
        :func:`write_svg` restore the written structure and properties
        instead.

    Raises
    ------
    CurveFormatError
        For malformed XML (with line and column), a root that is not ``svg``,
        malformed path data, or a document without drawable elements.

    Examples
    --------
    >>> import io
    >>> svg = '''<svg xmlns="http://www.w3.org/2000/svg">
    ...   <path d="M 0 0 h 10 v 10 z"/><circle cx="0" cy="0" r="1"/></svg>'''
    >>> curves = read_svg(io.StringIO(svg), tolerance=1e-3)
    >>> [(c.kind, c.closed, len(c.points)) for c in curves]
    [('Polygon', True, 3), ('Polygon', True, 72)]
    """
    import xml.etree.ElementTree as ET

    import svgelements as se

    text, name = _read_text(source)
    if tolerance is not None:
        tolerance = as_float(tolerance, name="tolerance", low=0.0)
    text, stash = _stash_polylines(text)
    try:
        doc = se.SVG.parse(_stdio.StringIO(text), reify=False)
    except ET.ParseError as exc:
        line, col = exc.position
        raise CurveFormatError(
            f"{name}: malformed XML at line {line}, column {col + 1}: {str(exc).split(':')[0]}"
        ) from None
    if not isinstance(doc, se.SVG):
        raise CurveFormatError(f"{name}: the root element is not <svg>, so this is not an SVG file")
    viewport = doc.values.get("viewport_transform", "") or ""
    if not viewport:
        viewport = str(doc.viewbox_transform or "")
    items = []
    for element in doc.elements():
        if not isinstance(element, se.Shape):
            continue
        k = len(items)
        d = element.values.get("d") if isinstance(element, se.Path) else None
        if d in stash:
            matrix = _own_transform(element, viewport)
            linear = np.array([[matrix.a, matrix.c], [matrix.b, matrix.d]], dtype=np.float64)
            items.append((element, stash[d], matrix, linear))
            continue
        if d and not _POLYLINE_D.fullmatch(d):
            try:
                se.Path(d)  # strict: svgelements' document parser drops bad path data silently
            except ValueError:
                raise CurveFormatError(
                    f"{name}: {_label(element, k)}: malformed path data {d[:60]!r}"
                ) from None
        segments = list(se.Path(element).segments(transformed=False))
        matrix = _own_transform(element, viewport)
        linear = np.array([[matrix.a, matrix.c], [matrix.b, matrix.d]], dtype=np.float64)
        items.append((element, segments, matrix, linear))
    if tolerance is None:
        tolerance = _default_tolerance(items)
    curves: list[Curve] = []
    feature = 0
    for element, segments, matrix, linear in items:
        scale = float(np.linalg.norm(linear, 2))
        if not segments or scale == 0.0 or not math.isfinite(scale):
            continue
        if segments and isinstance(segments[0], tuple):  # parsed polyline data
            subpaths = _clean_subpaths(segments, tolerance / scale)
        else:
            subpaths = _flatten(segments, tolerance / scale)
        if not subpaths:
            continue
        if not (matrix.is_identity()):
            offset = np.array([matrix.e, matrix.f], dtype=np.float64)
            subpaths = [(pts @ linear.T + offset, closed) for pts, closed in subpaths]
        curves.extend(_svg_curves(element, subpaths, feature, name))
        feature += 1
    if not curves:
        raise CurveFormatError(f"{name}: contains no drawable path, polyline or polygon")
    return curves


def _default_tolerance(items) -> float:
    boxes = []
    for _, segments, matrix, linear in items:
        pts = []
        if segments and isinstance(segments[0], tuple):  # parsed polyline data
            segments, pts = (), np.concatenate([sub for sub, _ in segments])
        for seg in segments:
            for attr in ("start", "end", "control", "control1", "control2"):
                p = getattr(seg, attr, None)
                if p is not None:
                    pts.append(_xy(p))
            if hasattr(seg, "rx") and getattr(seg, "center", None) is not None:
                r = max(abs(float(seg.rx)), abs(float(seg.ry)))
                cx, cy = _xy(seg.center)
                pts += [[cx - r, cy - r], [cx + r, cy + r]]
        if len(pts):
            arr = np.asarray(pts) @ linear.T + [matrix.e, matrix.f]
            boxes.append(arr[np.all(np.isfinite(arr), axis=1)])
    if not boxes:
        return 1.0
    arr = np.concatenate(boxes)
    if len(arr) == 0:
        return 1.0
    with np.errstate(over="ignore"):
        diagonal = float(np.hypot(*(arr.max(axis=0) - arr.min(axis=0))))
    if not math.isfinite(diagonal):  # coordinates near the float range: the span overflows
        diagonal = float(np.finfo(np.float64).max)
    return _DEFAULT_RELATIVE_TOLERANCE * diagonal if diagonal > 0 else 1.0


def _svg_curves(element, subpaths, feature: int, name: str) -> list[Curve]:
    props: dict[str, Any] = {"id": element.id} if element.id else {}
    index = None
    fid = None
    meta = element.values.get(_META)
    if meta:
        try:
            meta = json.loads(meta)
            props = dict(meta["properties"])
            fid = meta.get("feature_id")
            index = [tuple(entry) for entry in meta["index"]]
        except (ValueError, KeyError, TypeError) as exc:
            raise CurveFormatError(
                f"{name}: element {element.id or feature}: malformed {_META} attribute: {exc}"
            ) from None
        if len(index) != len(subpaths) or any(
            kind not in KINDS or (kind in _POLYGON_KINDS and not closed)
            for (_, _, _, kind), (_, closed) in zip(index, subpaths, strict=True)
        ):
            index = None  # the path was edited: fall back to the plain SVG structure
    if index is None:
        n = len(subpaths)
        flags = {closed for _, closed in subpaths}
        if n == 1:
            kind = "Polygon" if subpaths[0][1] else "LineString"
            index = [(None, 0, 0, kind)]
        elif flags == {True}:
            index = _nested_rings(subpaths, element.values.get("fill-rule") == "evenodd")
        elif flags == {False}:
            index = [(None, k, 0, "MultiLineString") for k in range(n)]
        else:
            index = [
                (k, 0, 0, "Polygon" if c else "LineString") for k, (_, c) in enumerate(subpaths)
            ]
    out = []
    for (member, part, ring, kind), (pts, closed) in zip(index, subpaths, strict=True):
        try:
            out.append(
                Curve(
                    pts,
                    closed=closed,
                    properties=props,
                    feature=feature,
                    part=part,
                    ring=ring,
                    kind=kind,
                    member=member,
                    feature_id=fid,
                )
            )
        except CurveError as exc:
            raise CurveFormatError(f"{name}: element {feature}: {exc}") from None
    return out


def _inside(point: np.ndarray, ring: np.ndarray) -> bool:
    """Return whether `point` is inside the closed `ring` (even-odd ray casting)."""
    x, y = point
    xa, ya = ring[:, 0], ring[:, 1]
    xb, yb = np.roll(xa, -1), np.roll(ya, -1)
    crosses = (ya > y) != (yb > y)
    with np.errstate(divide="ignore", invalid="ignore"):
        xs = xa + (y - ya) * (xb - xa) / (yb - ya)
    return bool(np.count_nonzero(crosses & (x < xs)) % 2)


def _nested_rings(subpaths, evenodd: bool) -> list[tuple]:
    """(member, part, ring, kind) of closed subpaths: rings inside others become holes.

    A subpath inside another (its first vertex inside and its area smaller) is a hole of
    the smallest one containing it when the fill leaves it empty: always with
    ``fill-rule="evenodd"`` at odd depth, with the default ``nonzero`` rule when it winds the
    other way round than its container. Outer rings (and filled islands) become polygons;
    one polygon gives a Polygon, several a MultiPolygon. Subpaths that merely overlap stay
    separate polygons (the SVG fill of overlaps is not a simple feature anyway).
    """
    areas = [_signed_area(pts[:, :2]) for pts, _ in subpaths]
    n = len(subpaths)
    parent: list[int | None] = [None] * n
    for j, (pts, _) in enumerate(subpaths):
        best = None
        for i, (outer, _) in enumerate(subpaths):
            if i == j or abs(areas[i]) <= abs(areas[j]) or not _inside(pts[0], outer):
                continue
            if best is None or abs(areas[i]) < abs(areas[best]):
                best = i
        parent[j] = best
    hole = [False] * n
    owner: list[int] = list(range(n))
    for j in sorted(range(n), key=lambda k: -abs(areas[k])):  # containers first
        i = parent[j]
        if i is None:
            continue
        if evenodd:
            hole[j] = not hole[i]
        else:
            hole[j] = not hole[i] and (areas[i] > 0) != (areas[j] > 0)
        owner[j] = owner[i] if hole[j] else j
    exteriors = [k for k in range(n) if not hole[k]]
    if len(exteriors) == n:
        return [(None, k, 0, "MultiPolygon") for k in range(n)]
    kind = "Polygon" if len(exteriors) == 1 else "MultiPolygon"
    part_of = {k: p for p, k in enumerate(exteriors)}
    rings: dict[int, int] = {}
    index = []
    for k in range(n):
        if hole[k]:
            rings[owner[k]] = rings.get(owner[k], 0) + 1
            index.append((None, part_of[owner[k]], rings[owner[k]], kind))
        else:
            index.append((None, part_of[k], 0, kind))
    return index


def _num(v: float) -> str:
    return repr(float(v))


def write_svg(
    curves: Iterable[Curve],
    dest: Source,
    *,
    stroke: str = "black",
    stroke_width: float | None = None,
    fill: str | None = None,
) -> None:
    """Write 2D curves as an SVG drawing, one ``<path>`` per feature.

    Parameters
    ----------
    curves : iterable of Curve
        2D curves, in SVG user coordinates (y axis down, nothing is flipped).
    dest : str or path-like or text file object
        The file.
    stroke : str, optional
        Stroke colour (any SVG paint).
    stroke_width : float, optional
        Stroke width in user units; default 1/400 of the larger side of the
        data's bounding box.
    fill : str, optional
        Fill paint for features whose curves are all closed (``fill-rule``
        evenodd, so holes stay empty); default: no fill.

    Raises
    ------
    CurveFormatError
        If a curve is 3D.

    Examples
    --------
    >>> import io
    >>> buf = io.StringIO()
    >>> write_svg([Curve([[0, 0], [1, 0], [0, 1]], closed=True)], buf)
    >>> [c.points.tolist() for c in read_svg(io.StringIO(buf.getvalue()))]
    [[[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]]
    """
    curves = _check_curves(curves)
    for i, c in enumerate(curves):
        if c.dim != 2:
            raise CurveFormatError(
                f"SVG is planar: curve {i} has 3D points; drop or project the z coordinate first"
            )
    allpts = np.concatenate([c.points for c in curves])
    lo, hi = allpts.min(axis=0), allpts.max(axis=0)
    with np.errstate(over="ignore"):
        size = float(max(hi - lo))
    if not math.isfinite(size):
        raise CurveFormatError(
            f"the coordinates span more than the largest float (from {lo.min():.3g} to "
            f"{hi.max():.3g}): the extent overflows, so no SVG viewBox can hold them; scale "
            "them down"
        )
    if size == 0.0:
        size = max(1.0, float(np.abs(lo).max()))
    pad = 0.02 * size
    x0, y0 = lo - pad
    w, h = hi - lo + 2 * pad
    if stroke_width is None:
        stroke_width = size / 400.0
    stroke_width = as_float(stroke_width, name="stroke_width", low=0.0)
    pixels = 800.0 / max(w, h)
    lines = [
        '<?xml version="1.0" encoding="UTF-8"?>',
        "<!-- written by curvesmith: SVG user coordinates, y axis pointing down -->",
        f'<svg xmlns="http://www.w3.org/2000/svg" version="1.1" width="{w * pixels:.6g}" '
        f'height="{h * pixels:.6g}" viewBox="{_num(x0)} {_num(y0)} {_num(w)} {_num(h)}">',
        f'<g stroke={quoteattr(stroke)} stroke-width="{_num(stroke_width)}" '
        'stroke-linejoin="round" stroke-linecap="round" fill-rule="evenodd">',
    ]
    groups: dict[int, list[Curve]] = {}
    for c in curves:
        groups.setdefault(c.feature, []).append(c)
    for group in groups.values():
        first = group[0]
        d = []
        for c in group:
            pts = c.points.tolist()
            cmd = "M " + _num(pts[0][0]) + "," + _num(pts[0][1]) + " L"
            cmd += "".join(" " + _num(x) + "," + _num(y) for x, y in pts[1:])
            d.append(cmd + (" Z" if c.closed else ""))
        meta = {
            "properties": dict(first.properties),
            "feature_id": first.feature_id,
            "index": [[c.member, c.part, c.ring, c.kind] for c in group],
        }
        try:
            meta_text = json.dumps(meta, allow_nan=False, ensure_ascii=False, default=_json_default)
        except (TypeError, ValueError) as exc:
            raise CurveFormatError(f"cannot write the properties as JSON: {exc}") from None
        attrs = []
        ident = first.properties.get("id")
        if isinstance(ident, str | int) and not isinstance(ident, bool):
            attrs.append(f"id={quoteattr(str(ident))}")
        paint = fill if fill is not None and all(c.closed for c in group) else "none"
        attrs.append(f"fill={quoteattr(paint)}")
        attrs.append(f"{_META}={quoteattr(meta_text)}")
        attrs.append(f'd="{escape(" ".join(d))}"')
        lines.append("<path " + " ".join(attrs) + "/>")
    lines += ["</g>", "</svg>", ""]
    _write_text(dest, "\n".join(lines))
