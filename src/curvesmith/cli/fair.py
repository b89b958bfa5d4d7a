"""The ``fair`` command: replace each curve by its closest discrete elastica."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import click
import numpy as np

from ..errors import CurveError
from ._common import (
    FORMAT_OPTION,
    POSITIVE,
    check_input,
    check_output,
    output_option,
    read_curves,
    write_curves,
)

__all__ = ["fair_command"]

#: A 3D curve whose rms distance from its PCA plane exceeds this fraction of its extent
#: gets a warning: it is fitted in that plane all the same.
PLANAR_TOL = 1e-3


def _read(source: str, fmt: str | None):
    """Curves of IN: scan tables (.xyz/.txt/.dat) through ``io.scan``, other files as usual."""
    from ..io import Curve
    from ..io.scan import PLAIN_SUFFIXES, read_scan

    check_input(source)
    if source != "-" and fmt is None and Path(source).suffix.lower() in PLAIN_SUFFIXES:
        return [
            Curve(pts, closed=False, properties={"id": name} if i else {})
            for i, (name, pts) in enumerate(read_scan(source))
        ]
    # GeoJSON's features without a curve (null, Point) pass through, as in smooth
    return read_curves(source, fmt, keep_others=True)


def _plane_2d(points: np.ndarray, index: int):
    """The PCA plane of a 3D curve: ``(2D coordinates, plane dict, warning or None)``."""
    from ..geometry import pca_frame

    centroid, axes, _ = pca_frame(points)
    coords = (points - centroid) @ axes.T
    rms = float(np.sqrt(np.mean(coords[:, 2] ** 2)))
    extent = float(np.ptp(coords[:, :2], axis=0).max())
    plane = {
        "origin": centroid.tolist(),
        "normal": axes[2].tolist(),
        "axes": [axes[0].tolist(), axes[1].tolist()],
        "rms": rms,
        "max_distance": float(np.abs(coords[:, 2]).max()),
    }
    warning = None
    if rms > PLANAR_TOL * extent:
        warning = (
            f"curve {index} is not planar: rms distance {rms:.3g} from its best plane "
            f"({rms / extent:.2g} of its extent); fitted in that plane"
        )
    return np.ascontiguousarray(coords[:, :2]), (centroid, axes), plane, warning


def _in_space(row: dict, points: np.ndarray, written: np.ndarray) -> None:
    """A 3D curve's row: the distances of its input `points` from the `written` (3D) fit.

    Beside the in-plane deviations (``*_in_space``; every input point, repeated ones
    too). The tolerance is judged in the plane (the section is faired there; what lies
    off the plane is the scan's, reported in ``plane``); ``within_tolerance_in_space``
    tells whether the points are within it in space too.
    """
    from ..elastica._geom import point_polyline_distance

    dev = point_polyline_distance(np.asarray(points, dtype=float), written)
    row["max_deviation_in_space"] = float(dev.max()) if dev.size else 0.0
    row["rms_deviation_in_space"] = float(np.sqrt(np.mean(dev**2))) if dev.size else 0.0
    if row["tolerance"] is not None:
        row["within_tolerance_in_space"] = bool(row["max_deviation_in_space"] <= row["tolerance"])


def _report_row(index: int, res, resampled: bool, plane) -> dict:
    row = {
        "index": index,
        "points": int(res.data.shape[0]),
        "input_points": int(res.deviation.shape[0]),
        "resampled": resampled,
        "params": res.params._asdict(),
        "start": res.start._asdict(),
        "case": res.case,
        "rms": res.rms,
        "max_deviation": res.max_deviation,
        "rms_deviation": res.rms_deviation,
        "max_distance": res.max_distance,
        "noise": None if math.isnan(res.noise) else res.noise,  # too few points: JSON null
        "tolerance": res.tolerance,
        "within_tolerance": res.within_tolerance,
        "iterations": res.iterations,
        "total_iterations": res.total_iterations,
        "starts": res.starts,
        "stages": res.stages,
        "success": res.success,
        "message": res.message,
    }
    if plane is not None:
        row["plane"] = plane
    return row


def _segments_row(index: int, res, resampled: bool, plane) -> dict:
    """The report row of a multi-segment fair (``--max-segments``): one entry per segment."""
    row = {
        "index": index,
        "points": int(res.data.shape[0]),
        "input_points": int(res.deviation.shape[0]),
        "resampled": resampled,
        "case": "segments",
        "rms": res.rms,
        "max_deviation": res.max_deviation,
        "rms_deviation": res.rms_deviation,
        "tolerance": res.tolerance,
        "within_tolerance": res.within_tolerance,
        "success": res.success,
        "message": res.message,
        "solves": res.solves,
        "single_fit": {
            "case": res.single.case,
            "rms": res.single.rms,
            "max_deviation": res.single.max_deviation,
            "message": res.single.message,
        },
        "segments": [
            {
                "params": s.params._asdict(),
                "first": s.first,
                "last": s.last,
                "rms": s.rms,
                "max_deviation": s.max_deviation,
            }
            for s in res.segments
        ],
        "joints": [
            {
                "after_segment": j.index,
                "vertex": j.vertex,
                "g1_defect": j.g1_defect,
                "turning": j.turning,
                "curvature_before": j.curvature_before,
                "curvature_after": j.curvature_after,
                "curvature_jump": j.curvature_jump,
            }
            for j in res.joints
        ],
    }
    if plane is not None:
        row["plane"] = plane
    return row


def _plot(path: str, fits: list[tuple[int, Any, np.ndarray]]) -> None:
    """``--plot``: :func:`curvesmith.plot.fit_figure`, one row per curve."""
    from ..plot import fit_figure

    fig = fit_figure(
        [(res, raw) for _, res, raw in fits], labels=[f"curve {i}" for i, _, _ in fits]
    )
    fig.savefig(path, dpi=110)


@click.command("fair")
@click.argument("source", metavar="IN")
@output_option("Output file (- for stdout); .dxf writes 3D polylines for CAD.")
@click.option("--report", "report", default=None, help="Write a JSON report of every fit.")
@click.option(
    "--plot",
    "plot",
    default=None,
    help="Write a PNG: input and fit, deviation and curvature along each curve.",
)
@click.option(
    "--resample/--no-resample",
    default=None,
    help="Resample to equal chords before fitting (default: when the vertices drift from "
    "equal chords by more than the data's noise explains).",
)
@click.option(
    "--step",
    type=POSITIVE,
    default=None,
    help="Chord length for resampling (implies --resample; default: the mean edge length "
    "or 20 noise levels, adjusted to end on the last point).",
)
@click.option(
    "--tolerance",
    type=POSITIVE,
    default=None,
    help="Largest allowed distance of an input point from the fitted curve (for a 3D curve "
    "in its plane: the distances from the plane are reported and warned about); exit 1 if a "
    "fit misses it.",
)
@click.option(
    "--max-segments",
    "max_segments",
    type=click.IntRange(min=1),
    default=None,
    help="With --tolerance: fair by the fewest discrete elastica segments (at most this many), "
    "joined G1, within the tolerance; exit 1 if it takes more.",
)
@click.option(
    "--max-iterations",
    "--max-iter",
    "max_iterations",
    type=click.IntRange(min=1),
    default=None,
    help="Function evaluations per solve (default 5000).",
)
@FORMAT_OPTION
def fair_command(
    source: str,
    dest: str,
    report: str | None,
    plot: str | None,
    resample: bool | None,
    step: float | None,
    tolerance: float | None,
    max_segments: int | None,
    max_iterations: int | None,
    fmt: str | None,
) -> None:
    """Replace every open curve of IN by its closest discrete elastica.

    Fits the integrable discrete elastica of Graiff Zurita, Kajiwara & Suzuki
    (section 4) to each curve, vertex by vertex, with a global multi-start
    search, and writes the fitted vertices to OUT in the same format. IN may be
    a 2D or 3D curve file or a scan table (.xyz/.txt/.dat, x y z per line); a
    3D curve is fitted in its least-squares (PCA) plane and written back in the
    input's coordinates (the report gives the plane). Curves whose vertices
    drift from equal chords by more than their noise explains are first
    resampled to equal chords (or always with --resample, never with
    --no-resample): the fit pairs data and model vertices by index. Exits with
    status 1, writing no OUT, if a fit does not converge or misses --tolerance;
    the report and plot are still written.

    With --tolerance T --max-segments M, each curve is faired by the fewest
    discrete elastica segments (at most M) whose union is within T of every input
    point, consecutive segments sharing the joint vertex and its tangent (G1); the
    report lists the segments and the G1 defect and curvature jump at each joint.
    """
    from ..elastica import fit, fit_segments, needs_resampling
    from ..io import check_destination

    if step is not None and resample is False:
        raise click.UsageError("--step needs resampling; drop --no-resample")
    if max_segments is not None and tolerance is None:
        raise click.UsageError("--max-segments needs --tolerance (the deviation to meet)")
    # every destination checked before the fitting: no output is written and then
    # followed by an error about the report or the plot
    if fmt is None and dest.lower().endswith(".dxf"):
        check_destination(dest)
    else:
        check_output(dest, fmt)
    for extra in (report, plot):
        if extra is not None:
            check_destination(extra)
    curves = _read(source, fmt)
    out: list = []
    rows: list[dict[str, Any]] = []
    fits: list[tuple[int, Any, np.ndarray]] = []
    for index, curve in enumerate(curves):
        start = np.asarray(curve.points[:1], dtype=float)
        if len(curve.points) > 1 and np.all(np.asarray(curve.points) == start):
            # the reader calls a curve that ends where it starts closed: say what is wrong
            raise CurveError(
                f"curve {index}: points must not all coincide, got every point at "
                f"{start[0].tolist()}"
            )
        if curve.closed:
            raise CurveError(
                f"curve {index} is closed; fair fits open curves (a discrete elastica of "
                "section 4 is an open segment); open the ring at a vertex to fit it"
            )
        pts = np.asarray(curve.points, dtype=float)
        frame = plane = None
        try:
            if pts.shape[1] == 3:
                pts, frame, plane, warning = _plane_2d(pts, index)
                if warning:
                    click.echo(f"Warning: {warning}", err=True)
            do_resample = bool(resample) or step is not None
            if resample is None and step is None:  # vertices off equal chords (or repeated)
                do_resample = needs_resampling(pts)
            option = (step if step is not None else True) if do_resample else False
            res: Any  # a SegmentFit or a FitResult
            if max_segments is not None:
                assert tolerance is not None  # --max-segments needs --tolerance (usage error)
                res = fit_segments(
                    pts,
                    tolerance,
                    max_segments=max_segments,
                    resample=option,
                    max_iterations=max_iterations,
                )
            else:
                res = fit(pts, resample=option, tolerance=tolerance, max_iterations=max_iterations)
        except CurveError as exc:
            raise CurveError(f"curve {index}: {exc}") from None
        faired = res.points
        if frame is not None:
            centroid, axes = frame
            faired = centroid + faired @ axes[:2]
        out.append(curve.replace(points=faired))
        if max_segments is not None:
            row = _segments_row(index, res, do_resample, plane)
        else:
            row = _report_row(index, res, do_resample, plane)
        if frame is not None:
            _in_space(row, curve.points, faired)
        rows.append(row)
        fits.append((index, res, pts))
    failed = [r for r in rows if not r["success"]]
    missed = [r for r in rows if r["within_tolerance"] is False]
    for r in rows:
        if r["within_tolerance"] and r.get("within_tolerance_in_space") is False:
            click.echo(
                f"Warning: curve {r['index']} is within the tolerance {tolerance:g} in its best "
                f"plane ({r['max_deviation']:.6g}), but its points lie up to "
                f"{r['plane']['max_distance']:.6g} from that plane: "
                f"{r['max_deviation_in_space']:.6g} from the fit in space",
                err=True,
            )
    if not failed and not missed:
        if fmt is None and dest.lower().endswith(".dxf"):
            from ..io.dxf import write_dxf

            write_dxf(out, dest)  # 3D polylines for CAD (DXF is written, not read)
        else:
            if hasattr(curves, "with_curves"):  # GeoJSON's other features and crs go back too
                out = curves.with_curves(out)
            write_curves(out, dest, fmt)
    if report is not None:
        with open(report, "w", encoding="utf-8") as fh:
            json.dump({"source": source, "curves": rows}, fh, indent=2)
    if plot is not None:
        _plot(plot, fits)
    if failed:
        first = failed[0]
        raise CurveError(
            f"{len(failed)} of {len(rows)} fits failed (no output written); "
            f"curve {first['index']}: {first['message']}"
        )
    if missed and max_segments is not None:
        first = missed[0]
        raise CurveError(
            f"{len(missed)} of {len(rows)} curves need more than {max_segments} segment"
            f"{'s' if max_segments > 1 else ''} "
            f"(no output written); curve {first['index']}: {first['message']}"
        )
    if missed:
        first = missed[0]
        raise CurveError(
            f"{len(missed)} of {len(rows)} fits miss the tolerance {tolerance:g} (no output "
            f"written); curve {first['index']}: max deviation {first['max_deviation']:.6g}"
        )
    if dest != "-" and max_segments is not None:
        worst = max(rows, key=lambda r: r["max_deviation"])
        click.echo(
            f"faired {len(rows)} curve(s) by {sum(len(r['segments']) for r in rows)} discrete "
            f"elastica segment(s) joined G1; largest max deviation {worst['max_deviation']:.6g} "
            f"(tolerance {tolerance:g})"
        )
    elif dest != "-":
        worst = max(rows, key=lambda r: r["max_deviation"])
        click.echo(
            f"fitted {len(rows)} curve(s) to discrete elasticae; largest max deviation "
            f"{worst['max_deviation']:.6g} (curve {worst['index']}: {worst['message']})"
        )
