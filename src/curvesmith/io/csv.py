"""CSV curves: an ``x,y[,z]`` header, an ``id`` column for several curves, a ``closed`` column.

See :mod:`curvesmith.io` for the format's conventions.
"""

from __future__ import annotations

import csv
import io as _stdio
import itertools
import json
import math
import warnings
from collections.abc import Iterable, Sequence
from typing import Any

import numpy as np

from ..errors import CurveError, CurveFormatError
from ._core import (
    Curve,
    Format,
    Source,
    _check_curves,
    _read_text,
    open_destination,
    register,
    write_rows,
)

__all__ = ["read_csv", "write_csv"]

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
        number = float(text)
        if repr(number) == text:
            return number
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
    with open_destination(dest) as out:
        head = _stdio.StringIO()
        csv.writer(head, lineterminator="\n").writerow(header)
        out.write(head.getvalue())
        for i, c in enumerate(curves):
            tail = []
            if id_cells is not None:
                tail.append(id_cells[i])
            if need_closed:
                tail.append("true" if c.closed else "false")
            tail.extend(_cell(c.properties.get(k)) for k in keys)
            pts = c.points
            # The coordinates (float reprs) never need quoting, so only the first row goes
            # through the csv writer; its quoted tail is reused verbatim by every row, and the
            # rows are formatted chunk by chunk (bounded memory, no Python call per number).
            first_xy = [float(v) for v in pts[0]]
            one = _stdio.StringIO()
            csv.writer(one, lineterminator="\n").writerow([*map(repr, first_xy), *tail])
            first = one.getvalue()
            suffix = first[len(",".join(map(repr, first_xy))) :]
            row = ",".join(["%r"] * c.dim) + suffix.replace("%", "%%")
            write_rows(out, pts, row)
            if c.closed:
                out.write(first)


FORMAT = register(Format("csv", "CSV", (".csv", ".txt"), read_csv, write_csv))
