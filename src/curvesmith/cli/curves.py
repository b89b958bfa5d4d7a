"""``smooth --curves``: write smoothed curves as G2 Bézier paths (:func:`curvesmith.curves.fit`)."""

from __future__ import annotations

import sys
import warnings
from pathlib import Path
from typing import Any

import click
import numpy as np

from ..errors import CurveError
from ..io import Curve
from ._common import _format_of, write_curves

__all__ = ["write_fitted"]


def _anchor_positions(original: np.ndarray, smooth: np.ndarray, anchors: list[int]) -> list[int]:
    """Indices in the smoothed curve of the input anchors (cca keeps them exactly)."""
    out = []
    for a in anchors:
        hit = np.flatnonzero(np.all(smooth == original[a % len(original)], axis=1))
        if hit.size:
            out.append(int(hit[0]))
    return out


#: A failed fit of a curve whose input turns by more than this at a vertex suggests
#: ``--keep-angle``: a G2 curve has no corners.
_CORNER_ADVICE = 45.0


def _corner_advice(curve: Curve, keep_angle: float | None) -> str:
    """Advice for a failed fit: the input's sharpest corner, and how to keep such."""
    from ..geometry import turning_angles

    if keep_angle is not None:
        return (
            f" (the corners turning by more than {keep_angle:g} degrees were kept: a smaller "
            "--keep-angle keeps more, more --iterations round the others further)"
        )
    if len(curve.points) < 3:
        return ""
    turn = np.degrees(np.abs(turning_angles(curve.points, closed=curve.closed)))
    if not float(turn.max()) > _CORNER_ADVICE:
        return ""
    k = int(np.argmax(turn))
    at = k if curve.closed else k + 1
    return (
        f" (its input turns by {turn[k]:.0f} degrees at vertex {at}, and a G2 curve has no "
        f"corners: keep corners with --keep-angle, e.g. --keep-angle {_CORNER_ADVICE:g})"
    )


def write_fitted(
    originals: list[Curve],
    smoothed: list[Curve],
    dest: str,
    fmt: str | None,
    *,
    kind: str,
    tolerance: float | None,
    corners: list[list[int] | None] | None = None,
    keep_angle: float | None = None,
) -> None:
    """Fit every smoothed curve and write the Bézier paths to `dest`.

    SVG gets one ``<path>`` of ``Q`` (quadratic) or ``C`` (cubic) segments per
    curve: an SVG input's document is written back as it was, each smoothed element a
    path with its own attributes (:func:`curvesmith.io.svg.write_bezier_document`);
    other inputs give a new drawing. CSV and GeoJSON get the Bézier control polygon of
    each path (on- and off-curve points in order, every ``degree``-th on the curve) with the
    properties ``degree``, ``segments``, ``deviation``, ``tolerance`` and
    ``g2_defect``. One report line per curve goes to standard error.

    Parameters
    ----------
    originals, smoothed : list of Curve
        The curves as read and after smoothing (same order).
    dest : str
        Output path or ``-``.
    fmt : str or None
        Output format (default: from the suffix of `dest`).
    kind : {"quadratic", "cubic"}
    tolerance : float or None
        Largest distance from the smoothed curve; default 1/1000 of the diagonal
        of the bounding box of all curves.
    corners : list of (list of int or None), optional
        Per curve, the input vertices that the smoothing kept in place (``--anchors``,
        and the corners of ``--keep-angle``): each is the end of a fitted piece, so that
        corners stay corners and straight sides straight.
    keep_angle : float or None
        The ``--keep-angle`` option (degrees), for the advice of a failed fit.
    """
    from .. import curves
    from ..io.svg import bezier_path_data, path_document

    degree = 2 if kind == "quadratic" else 3
    pts = [c.points for c in smoothed]
    if any(p.shape[1] != 2 for p in pts):
        raise CurveError("--curves needs planar (x, y) curves")
    lo = np.min([p.min(axis=0) for p in pts], axis=0)
    hi = np.max([p.max(axis=0) for p in pts], axis=0)
    if tolerance is None:
        tolerance = 1e-3 * float(np.hypot(*(hi - lo)))
    from ..io.svg import SVGCurves

    out_fmt = (
        "svg" if dest == "-" and fmt == "svg" else (fmt if dest == "-" else _format_of(dest, fmt))
    )
    # an SVG document written back: the shapes it keeps as they were are not fitted
    svg_doc = originals if isinstance(originals, SVGCurves) and out_fmt == "svg" else None
    if svg_doc is not None and svg_doc.document is None:
        svg_doc = None
    kept = svg_doc.kept() if svg_doc is not None else frozenset()
    fits: list[Any] = []
    said = []
    for i, (orig, c) in enumerate(zip(originals, smoothed, strict=True)):
        if c.feature in kept:  # written back as it was: nothing to fit, nothing to claim
            said.append(f"curve {i}: written back as it was (see the warning)")
            fits.append(None)
            continue
        idx = corners[i] if corners is not None else None
        where = _anchor_positions(orig.points, c.points, idx) if idx else None
        try:
            f = curves.fit(
                c.points, closed=c.closed, tolerance=tolerance, degree=degree, anchors=where
            )
        except CurveError as exc:
            raise CurveError(f"curve {i}: {exc}{_corner_advice(orig, keep_angle)}") from None
        if not f.success:
            raise CurveError(f"curve {i}: {f.message}{_corner_advice(orig, keep_angle)}")
        said.append(f"curve {i}: {f.message}")  # said once every curve is fitted: an
        fits.append(f)  # error stays the run's one line
    for line in said:
        click.echo(line, err=True)
    if out_fmt == "svg":
        from ..io.svg import SVGKeptWarning, write_bezier_document

        if svg_doc is not None:
            # an SVG document is written back as it was, each smoothed shape a path of
            # Béziers with its own attributes (ids, styles, transforms, text kept)
            target: Any = sys.stdout if dest == "-" else Path(dest)
            beziers = [None if f is None else (f.segments, f.closed) for f in fits]
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always", SVGKeptWarning)
                write_bezier_document(svg_doc.with_curves(smoothed), beziers, target)
            for w in caught:  # one line, as the other writers say it
                if issubclass(w.category, SVGKeptWarning):
                    click.echo(f"Warning: {dest}: {w.message}", err=True)
                else:
                    warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
            return
        doc = path_document(
            [bezier_path_data(f.segments, closed=f.closed) for f in fits], (tuple(lo), tuple(hi))
        )
        if dest == "-":
            click.echo(doc, nl=False)
        else:
            from ..io import open_destination

            with open_destination(Path(dest)) as fh:  # atomic: no partial file on failure
                fh.write(doc)
        return
    out = []
    for c, f in zip(smoothed, fits, strict=True):
        props = dict(c.properties)
        props.update(
            degree=degree,
            segments=f.count,
            deviation=f.deviation,
            tolerance=f.tolerance,
            g2_defect=f.g2_defect,
        )
        out.append(c.replace(points=f.bezier_polygon(), properties=props))
    write_curves(out, dest, fmt)
