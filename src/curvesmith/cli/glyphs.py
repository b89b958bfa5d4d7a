"""``curvesmith glyphs``: refit font glyphs as curvature continuous TrueType contours."""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path
from typing import Literal

import click

from ..errors import CurveError
from ._common import COUNT, POSITIVE

__all__ = ["glyphs_command"]


@click.command("glyphs")
@click.argument("font_path", metavar="FONT")
@click.option("-o", "--output", "dest", required=True, metavar="OUT", help="Output .ttf or .ufo.")
@click.option(
    "--glyphs", "spec", default=None, help="Characters or glyph names, e.g. a,g,S (default: all)."
)
@click.option("--iterations", type=COUNT, default=0, show_default=True, help="cca steps first.")
@click.option(
    "--tolerance",
    type=POSITIVE,
    default=None,
    help="Max deviation, font units (default 1/1000 em).",
)
@click.option(
    "--units-per-em",
    "upem",
    type=click.IntRange(16, 16384),
    default=None,
    help="TrueType output's unitsPerEm (default the source's; 16384 = 8x finer grid for 2048).",
)
@click.option(
    "--rounding",
    type=click.Choice(["search", "plain"]),
    default="search",
    show_default=True,
    help="Integer rounding: least curvature jump within the tolerance, or plain.",
)
@click.option("--json", "as_json", is_flag=True, help="Print the report as JSON.")
def glyphs_command(
    font_path: str,
    dest: str,
    spec: str | None,
    iterations: int,
    tolerance: float | None,
    upem: int | None,
    rounding: Literal["search", "plain"],
    as_json: bool,
) -> None:
    """Refit the glyphs of FONT (TrueType, OpenType-CFF or UFO); write a TrueType font or UFO.

    Every contour becomes the fewest quadratic Béziers of a curvature continuous
    (G2) quadratic B-spline within --tolerance of the outline (of its cca
    smoothing with --iterations), enclosed areas kept; corners and lines stay.
    Glyph names, order, advance widths, cmap, names and layout tables are kept;
    hinting is dropped. TrueType coordinates are integers, so a .ttf is G2 up to
    their rounding: each point is rounded to the one of its 4 integer neighbours
    that, over the contour, gives the least largest curvature jump within the
    tolerance ("G2 written": the largest relative jump at the smooth on-curve
    points as written; "plain": that of plain rounding; "kink deg": the largest
    tangent break at explicit smooth on-curve points). --units-per-em 16384
    makes the grid finer (every metric scaled). A .ufo keeps floats: exactly G2
    and every area exact; in a .ttf the areas change by the rounding ("area
    change" is that of the written contours).

    A glyph with no fit within the tolerance is written as it was and named on
    stderr, and the exit status is then 1 (the rest of the font is refitted).
    """
    from .. import glyphs
    from ..io.fonts import open_font

    if iterations < 0:
        raise CurveError(f"--iterations must be >= 0, got {iterations}")
    if not Path(font_path).exists():
        raise CurveError(f"{font_path}: no such file or directory")
    if Path(dest).suffix.lower() not in (".ttf", ".ufo"):
        raise CurveError(f"OUT must be a .ttf file or a .ufo directory, got {dest!r}")
    if Path(dest).suffix.lower() == ".ufo" and Path(dest).exists():
        raise CurveError(f"{dest} exists: remove it first (a UFO is a directory)")
    if Path(dest).suffix.lower() == ".ufo" and upem is not None:
        raise CurveError("--units-per-em applies to .ttf output (a .ufo keeps floats)")
    from ..io import check_destination

    check_destination(dest)  # before the work, in the words of the other commands
    if tolerance is None:
        font = open_font(font_path)
        upm = font.units_per_em if hasattr(font, "units_per_em") else font["head"].unitsPerEm
        tolerance = upm / 1000.0
    reports = glyphs.refit_font(
        font_path,
        dest,
        glyphs=spec,
        tolerance=tolerance,
        iterations=iterations,
        units_per_em=upem,
        rounding=rounding,
    )
    written = open_font(dest)
    rows = []
    for r in reports:
        row = r.row()
        if not r.refitted:
            row["g2_defect_written"] = None
        elif r.grid:  # TrueType: the jumps of the rounded contours, from the report
            row["g2_defect_written"] = r.g2_written
        else:  # UFO: the written floats
            row["g2_defect_written"] = glyphs.written_g2_defect(written, r.name)
        rows.append(row)
    kept = [r for r in reports if not r.refitted]
    if as_json:
        click.echo(json.dumps({"font": font_path, "output": dest, "glyphs": rows}, indent=2))
    else:
        _table(rows)
    if kept:
        shown = ", ".join(r.name for r in kept[:8]) + (", ..." if len(kept) > 8 else "")
        click.echo(
            f"Error: {len(kept)} of {len(reports)} glyph(s) have no G2 fit within the "
            f"tolerance {tolerance:g} and were written as they were ({shown}); the first: "
            f"{kept[0].message.removeprefix('kept as it was: ')}",
            err=True,
        )
        sys.exit(1)


def _table(rows) -> None:
    click.echo(
        f"{'glyph':<16} {'segments':>14} {'area change':>12} {'max dev':>9} "
        f"{'G2 fit':>9} {'G2 written':>10} {'plain':>9} {'kink deg':>8}"
    )
    for row in rows:
        if not row["refitted"]:
            click.echo(f"{row['glyph']:<16} {row['segments_before']:>6} (kept as it was)")
            continue
        # a .ttf: the change of the rounded contours as written (the fit's is ~1e-16)
        written = row.get("area_change_written")
        area = written if written is not None else row["area_change"]
        click.echo(
            f"{row['glyph']:<16} {row['segments_before']:>6} -> {row['segments_after']:<5} "
            f"{area:>12.2e} {row['max_deviation']:>9.3g} "
            f"{row['g2_defect']:>9.1e} {row['g2_defect_written']:>10.1e} "
            + (f"{p:>9.1e}" if (p := row["g2_plain_rounding"]) is not None else f"{'-':>9}")
            + (f" {math.degrees(k):>8.3f}" if (k := row["g1_written"]) is not None else "")
        )
