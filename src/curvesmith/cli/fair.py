"""The ``fair`` command: replace each curve by its closest discrete elastica."""

from __future__ import annotations

import json

import click
import numpy as np

from ..errors import CurveError
from ._common import FORMAT_OPTION, read_curves, write_curves

__all__ = ["fair_command"]


def _prepare(curve, index: int) -> np.ndarray:
    if curve.closed:
        raise CurveError(
            f"curve {index} is closed; fair fits open curve segments (a discrete elastica "
            "segment of section 4 is open)"
        )
    if curve.points.shape[1] != 2:
        raise CurveError(
            f"curve {index} has {curve.points.shape[1]} coordinates; fair needs planar "
            "(x, y) curves (use `curvesmith keyline` for 3D scans)"
        )
    return curve.points


def _report_row(index: int, res, resampled: bool) -> dict:
    return {
        "index": index,
        "points": int(res.data.shape[0]),
        "resampled": resampled,
        "params": res.params._asdict(),
        "start": res.start._asdict(),
        "case": res.case,
        "rms": res.rms,
        "max_distance": res.max_distance,
        "iterations": res.iterations,
        "stages": res.stages,
        "success": res.success,
        "message": res.message,
    }


def _plot(path: str, fits: list[tuple[int, object]]) -> None:
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    from ..elastica import sample

    n = len(fits)
    cols = min(n, 3)
    rows = -(-n // cols)
    fig, axes = plt.subplots(rows, cols, figsize=(5.0 * cols, 4.2 * rows), squeeze=False)
    for ax, (index, res) in zip(axes.ravel(), fits, strict=False):
        guess = sample(res.start, res.data.shape[0])
        ax.plot(*res.data.T, "s", color="black", ms=3, mfc="none", label="input")
        ax.plot(*guess.T, "^", color="tab:green", ms=3, label="initial guess")
        ax.plot(*res.points.T, "o-", color="tab:red", ms=2.5, lw=0.8, label="discrete elastica")
        status = "" if res.success else " (failed)"
        ax.set_title(f"curve {index}: case ({res.case}), rms {res.rms:.3g}{status}")
        ax.set_xlabel("x")
        ax.set_ylabel("y")
        ax.set_aspect("equal", adjustable="datalim")
        ax.legend(fontsize="small")
    for ax in axes.ravel()[n:]:
        ax.set_visible(False)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


@click.command("fair")
@click.argument("source", metavar="IN")
@click.option("-o", "--output", "dest", required=True, help="Output file (- for stdout).")
@click.option("--report", "report", default=None, help="Write a JSON report of every fit.")
@click.option("--plot", "plot", default=None, help="Write a PNG: input, initial guess and fit.")
@click.option(
    "--resample/--no-resample",
    default=None,
    help="Resample to equal chords before fitting (default: only when spacing is uneven).",
)
@click.option(
    "--step",
    type=float,
    default=None,
    help="Chord length for resampling (implies --resample; default: mean edge length).",
)
@click.option(
    "--basin-factor",
    type=float,
    default=20.0,
    show_default=True,
    help="A fit fails if its rms exceeds this many times the data's local noise level; "
    "raise it for curves that are only roughly elasticae.",
)
@FORMAT_OPTION
def fair_command(
    source: str,
    dest: str,
    report: str | None,
    plot: str | None,
    resample: bool | None,
    step: float | None,
    basin_factor: float,
    fmt: str | None,
) -> None:
    """Replace every open curve of IN by its closest discrete elastica.

    Fits the integrable discrete elastica of Graiff Zurita, Kajiwara & Suzuki
    (section 4) to each curve, vertex by vertex, and writes the fitted
    vertices to OUT in the same format. Curves with grossly uneven spacing are
    first resampled to equal chords (or always with --resample, never with
    --no-resample). Exits with status 1 if any fit fails; the report and plot
    are still written.
    """
    from ..elastica import SPACING_TOL, fit, spacing_spread

    if step is not None and not (np.isfinite(step) and step > 0):
        raise click.BadParameter(f"must be > 0, got {step}", param_hint="--step")
    if not (np.isfinite(basin_factor) and basin_factor > 0):
        raise click.BadParameter(f"must be > 0, got {basin_factor}", param_hint="--basin-factor")
    if step is not None and resample is False:
        raise click.UsageError("--step needs resampling; drop --no-resample")
    curves = read_curves(source, fmt)
    out, rows, fits = [], [], []
    for index, curve in enumerate(curves):
        pts = _prepare(curve, index)
        do_resample = bool(resample) or step is not None
        if resample is None and step is None:
            do_resample = spacing_spread(pts) > SPACING_TOL
        option = (step if step is not None else True) if do_resample else False
        try:
            res = fit(pts, resample=option, basin_factor=basin_factor)
        except CurveError as exc:
            raise CurveError(f"curve {index}: {exc}") from None
        out.append(curve.replace(points=res.points))
        rows.append(_report_row(index, res, do_resample))
        fits.append((index, res))
    write_curves(out, dest, fmt)
    if report is not None:
        with open(report, "w", encoding="utf-8") as fh:
            json.dump({"source": source, "curves": rows}, fh, indent=2)
    if plot is not None:
        _plot(plot, fits)
    failed = [r for r in rows if not r["success"]]
    if failed:
        first = failed[0]
        raise CurveError(
            f"{len(failed)} of {len(rows)} fits failed; curve {first['index']}: {first['message']}"
        )
    if dest != "-":
        worst = max(r["rms"] for r in rows)
        click.echo(f"fitted {len(rows)} curve(s) to discrete elasticae; largest rms {worst:.6g}")
