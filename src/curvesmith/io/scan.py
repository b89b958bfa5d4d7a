"""Scan tables: the point files of 3D scanners, read by ``curvesmith fair`` and ``keyline``.

A scan file holds one polyline as a plain table of numbers (``.xyz``, ``.txt``, ``.dat``:
``x y z`` or ``x y`` per line, whitespace or comma separated, ``#`` comments, an optional
header row without numbers) or a CSV file with a header (``x,y[,z]`` and an optional
``id`` column for several curves), GeoJSON or SVG through :func:`curvesmith.io.read_curves`.
Scan reading is a function rather than a registered format: ``.txt`` is registered to CSV
(with a header), and a scan table without a header is not CSV.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..errors import CurveError

__all__ = ["PLAIN_SUFFIXES", "read_scan"]

#: Suffixes read as plain whitespace- or comma-separated numbers with numpy.
PLAIN_SUFFIXES = (".xyz", ".txt", ".dat")


def read_scan(path: str | Path) -> list[tuple[str, np.ndarray]]:
    """Read the keylines of one scan file as ``(name, points)`` pairs.

    ``.xyz``, ``.txt`` and ``.dat`` files are plain tables of numbers (2 or 3
    columns, whitespace or comma separated, ``#`` comments, an optional first
    row without numbers such as ``x y z`` taken as a header), one keyline per
    file; other suffixes (CSV ``x,y,z`` with an optional ``id`` column for
    several keylines, GeoJSON, SVG) go through :func:`curvesmith.io.read_curves`.

    Parameters
    ----------
    path : str or Path
        The file.

    Returns
    -------
    list of (str, (N, d) ndarray)
        Name (the file stem, plus ``_<id>`` when the file holds several
        curves) and points of each keyline.

    Raises
    ------
    CurveError
        If the file cannot be read or parsed.
    """
    path = Path(path)
    if path.suffix.lower() in PLAIN_SUFFIXES:
        try:
            text = path.read_bytes().decode("utf-8-sig")
        except OSError as exc:
            raise CurveError(f"cannot read {path}: {exc.strerror or exc}") from None
        except UnicodeDecodeError as exc:
            raise CurveError(
                f"{path}: not a text table of numbers ({exc.reason} at byte {exc.start})"
            ) from None
        lines = [(n, ln.split("#", 1)[0].strip()) for n, ln in enumerate(text.splitlines(), 1)]
        numbered = [(n, r.replace(",", " ").split()) for n, r in lines if r]
        if numbered and not any(_is_float(v) for v in numbered[0][1]):
            numbered = numbered[1:]  # a header row such as "x y z" or "//X //Y //Z"
        if not numbered:
            raise CurveError(f"{path}: the file is empty (no rows of numbers)")
        width = len(numbered[0][1])
        for n, r in numbered:
            if len(r) not in (2, 3) or len(r) != width:
                raise CurveError(
                    f"{path}: line {n}: expected {width if width in (2, 3) else '2 or 3'} "
                    f"numbers (x y [z]) like every row, got {len(r)}"
                )
        rows = [r for _, r in numbered]
        try:
            pts = np.array([[float(v) for v in r] for r in rows], dtype=float)
        except ValueError:
            n, bad = next((n, v) for n, r in numbered for v in r if not _is_float(v))
            raise CurveError(f"{path}: line {n}: {bad!r} is not a number") from None
        return [(path.stem, pts)]
    from . import read_curves

    try:
        curves = read_curves(path)
    except OSError as exc:
        raise CurveError(f"cannot read {path}: {exc.strerror or exc}") from None
    if len(curves) == 1:
        return [(path.stem, np.asarray(curves[0].points, dtype=float))]
    out = []
    for i, c in enumerate(curves):
        tag = c.properties.get("id", i)
        out.append((f"{path.stem}_{tag}", np.asarray(c.points, dtype=float)))
    return out


def _is_float(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True
