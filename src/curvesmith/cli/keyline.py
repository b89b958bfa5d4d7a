"""``curvesmith keyline``: fit discrete elasticae to a folder of 3D keyline scans (section 5)."""

from __future__ import annotations

import csv
import json
import math
import sys
from pathlib import Path
from typing import Any

import click
import numpy as np

from ..errors import CurveError
from ..io.scan import PLAIN_SUFFIXES, read_scan
from ..keyline import TABLE_COLUMNS
from ._common import POSITIVE

__all__ = ["PLAIN_SUFFIXES", "SUMMARY_PARAMS", "TABLE_FIELDS", "keyline_command", "read_scan"]

#: Columns of ``keyline_table.csv`` (and keys of the rows in ``keyline_table.json``).
TABLE_FIELDS = (
    "file",
    "curve",
    *TABLE_COLUMNS,
    "step",
    "inflection_index",
    "plane_rms",
    "output",
    "transform",
    "error",
)

#: Parameters averaged in the ``summary`` of ``keyline_table.json`` (Table 1 of the paper).
SUMMARY_PARAMS = ("h", "phi", "phi_deg", "z", "q", "k")


def _rows_for(file: str, name: str, res, out_name: str) -> list[dict]:
    rows = []
    side_message = {side: fit.message for side, fit in res.sides}
    pinned = {side: rng[2] for (side, _), rng in zip(res.sides, res.piece_ranges, strict=True)}
    for row in res.table():
        full: dict[str, Any] = dict.fromkeys(TABLE_FIELDS, "")
        full.update(row)
        full.update(
            file=file,
            curve=name,
            step=res.step,
            inflection_index=pinned[row["side"]] if res.pieces else res.inflection.index,
            plane_rms=res.plane.rms_distance if res.plane is not None else 0.0,
            output=out_name,
            transform=Path(out_name).stem + "_transform.json",
            error="" if row["success"] else f"{row['side']} fit: {side_message[row['side']]}",
        )
        rows.append(full)
    return rows


def _error_row(file: str, name: str, message: str) -> dict:
    row: dict[str, Any] = dict.fromkeys(TABLE_FIELDS, "")
    row.update(file=file, curve=name, success=False, error=message)
    return row


def _write_fit(res, dest: Path) -> Path:
    """The resampled keyline and the fits in the scan's coordinates, and the transform (JSON)."""
    from ..io import Curve
    from ._common import write_curves

    curves = [Curve(res.to_input_frame(res.points), closed=False, properties={"id": "keyline"})]
    for side, fit in res.sides:
        curves.append(Curve(res.to_input_frame(fit.points), closed=False, properties={"id": side}))
    write_curves(curves, str(dest))
    transform = dest.with_name(dest.stem + "_transform.json")
    info = {
        "description": "x_scan = origin + x2d * axes[0] + y2d * axes[1] maps the 2D frame of "
        "the fitted parameters (keyline_table) to the scan's coordinates",
        **res.transform(),
        "resampling": res.resampling,
    }
    transform.write_text(json.dumps(info, indent=2), encoding="utf-8")
    return transform


#: Fits whose ``k`` and ``z`` are stand-ins (``curvesmith.elastica.FitResult.case``).
DEGENERATE = ("circle", "line")


def _summary(rows: list[dict]) -> dict:
    """Mean and standard deviation per side over the converged fits, like Table 1.

    A converged circle or straight line has no modulus of its own (``k`` is a stand-in:
    1e8 for infinity, or any value for a line), so it is counted under ``degenerate``
    and left out of the means, which it would swamp.
    """
    out = {}
    extra = sorted(
        {r["side"] for r in rows if str(r["side"]).startswith("middle")}, key=lambda s: int(s[6:])
    )
    for side in ("left", *extra, "right", "whole"):
        converged = [r for r in rows if r["side"] == side and r["success"] is True]
        if side == "whole" and not any(r["side"] == "whole" for r in rows):
            continue
        good = [r for r in converged if r["case"] not in DEGENERATE]
        entry: dict = {"count": len(good)}
        degenerate = {c: sum(r["case"] == c for r in converged) for c in DEGENERATE}
        if any(degenerate.values()):
            entry["degenerate"] = {c: n for c, n in degenerate.items() if n}
        if good:
            vals = np.array([[r[c] for c in SUMMARY_PARAMS] for r in good], dtype=float)
            entry["mean"] = dict(zip(SUMMARY_PARAMS, vals.mean(axis=0).tolist(), strict=True))
            entry["std"] = dict(zip(SUMMARY_PARAMS, vals.std(axis=0).tolist(), strict=True))
        out[side] = entry
    return out


def _json_value(v):
    if isinstance(v, float) and not math.isfinite(v):
        return None
    if isinstance(v, np.generic):
        return v.item()
    return v


@click.command("keyline")
@click.argument("inputs", metavar="IN...", nargs=-1, required=True, type=click.Path(dir_okay=False))
@click.option(
    "-o",
    "--output",
    "outdir",
    required=True,
    type=click.Path(file_okay=False),
    help="Output directory (created if needed).",
)
@click.option(
    "--step",
    type=POSITIVE,  # finite: --step nan is a usage error, as in fair
    default=None,
    help="Chord r of the equilateral resampling, in the scan's units "
    "(default: 1/200 of the keyline's extent).",
)
@click.option(
    "--normal",
    default="0,0,1",
    show_default=True,
    help="Viewing direction NX,NY,NZ: the side of the plane the 2D keyline is seen from.",
)
@click.option(
    "--max-iterations",
    "--max-iter",
    "max_iterations",
    type=click.IntRange(min=1),
    default=None,
    help="Function evaluations per elastica solve (default 5000).",
)
@click.pass_context
def keyline_command(ctx, inputs, outdir, step, normal, max_iterations) -> None:
    """Fit a discrete elastica to each side of the inflection of 3D keyline scans.

    Each IN is a scanned keyline: CSV with x,y,z columns (an id column for
    several keylines per file), or a plain .xyz/.txt/.dat table of numbers.
    The pipeline of section 5 of Graiff Zurita, Kajiwara & Suzuki runs on
    each: PCA plane fit, equilateral resampling with step R, principal-axes
    frame, RDP inflection estimate, and a discrete elastica fitted to each
    side with its start pinned at the inflection.

    A keyline without inflection (a C-shaped section) gets one elastica fitted
    to the whole keyline (side "whole"); one with several inflections is split
    at each and every piece gets its own elastica, pinned at an inflection
    (sides left, middle1, ..., right). Writes OUTDIR/<name>_fit.csv (the
    resampled keyline and the fitted elasticae in the scan's coordinates, ids
    keyline/left/right, keyline/whole or keyline/left/middle1/.../right),
    OUTDIR/<name>_fit_transform.json (the
    map from the 2D frame of the parameters to the scan) and the
    parameter table (h, phi, z, q, k per side, like Table 1) as
    OUTDIR/keyline_table.csv and .json (with the mean and standard deviation
    per side over the converged fits). A file that cannot be read or
    fitted is reported in the table and on stderr; the others are still
    processed, and the exit status is then 1.
    """
    from .. import keyline
    from ._common import parse_floats

    try:
        hint = parse_floats(normal, name="--normal", count=3)
        if not any(hint):
            raise CurveError(f"--normal must be a nonzero vector, got {normal!r}")
    except CurveError as exc:
        raise click.BadParameter(str(exc), param_hint="--normal") from None
    out = Path(outdir)
    out.mkdir(parents=True, exist_ok=True)
    rows: list[dict] = []
    failures: list[str] = []
    fitted = 0

    def fail(file: str, name: str, message: str) -> None:
        rows.append(_error_row(file, name, message))
        failures.append(message if file in message else f"{file}: {message}")

    with click.progressbar(inputs, label="Fitting keylines", file=sys.stderr) as bar:
        for item in bar:
            file = str(item)
            try:
                scans = read_scan(file)
            except CurveError as exc:
                fail(file, Path(file).stem, str(exc))
                continue
            for name, pts in scans:
                try:
                    options = {} if max_iterations is None else {"max_iterations": max_iterations}
                    res = keyline.fit(
                        pts,
                        step=step,
                        normal_hint=hint,
                        single_if_convex=True,
                        fit_options=options,
                    )
                    dest = out / f"{name}_fit.csv"
                    _write_fit(res, dest)
                except CurveError as exc:
                    fail(file, name, f"{file} ({name}): {exc}")
                    continue
                fitted += 1
                rows.extend(_rows_for(file, name, res, dest.name))
                if not res.success:
                    failures.append(f"{file} ({name}): fit did not converge: {res.message}")
    table_csv = out / "keyline_table.csv"
    with table_csv.open("w", newline="", encoding="utf-8") as fh:
        writer = csv.DictWriter(fh, fieldnames=TABLE_FIELDS, lineterminator="\n")
        writer.writeheader()
        writer.writerows(
            {k: (repr(v) if isinstance(v, float) else v) for k, v in r.items()} for r in rows
        )
    (out / "keyline_table.json").write_text(
        json.dumps(
            {
                "rows": [{k: _json_value(v) for k, v in r.items()} for r in rows],
                "summary": _summary(rows),
            },
            indent=2,
        ),
        encoding="utf-8",
    )
    click.echo(f"fitted {fitted} keyline(s) from {len(inputs)} file(s); table: {table_csv}")
    if failures:
        for f in failures:
            click.echo(f"Error: {f}", err=True)
        click.echo(f"Error: {len(failures)} keyline(s) failed; see {table_csv}", err=True)
        ctx.exit(1)
