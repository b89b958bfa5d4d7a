"""``curvesmith affine``: control polygons of G2 uniform quadratic B-splines (Käferböck)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import click

from ..errors import CurveError
from ..io import open_destination
from ..io.svg import path_document, quadratic_path_data
from ._common import FORMAT_OPTION, output_option, read_curves, write_curves

__all__ = ["affine_command"]


def _with_results(pairs: list) -> list:
    """Attach the approximation results to the curves' properties.

    Properties belong to a feature, so a feature with several curves (holes, parts) gets
    each result as a list, one value per curve in file order; a single curve gets scalars.
    """
    by_feature: dict[int, list[dict]] = {}
    for curve, results in pairs:
        by_feature.setdefault(curve.feature, []).append(results)
    out = []
    for curve, _ in pairs:
        group = by_feature[curve.feature]
        props = dict(curve.properties)
        if len(group) == 1:
            props.update(group[0])
        else:
            props.update({key: [r[key] for r in group] for key in group[0]})
        out.append(curve.replace(properties=props))
    return out


@click.command("affine")
@click.argument("source", metavar="IN")
@output_option("Output file for the control polygons.")
@click.option(
    "--vertices",
    type=click.IntRange(min=4),
    required=True,
    help="Vertices of each control polygon (>= 4; about 1/20 of the samples is a good ratio).",
)
@click.option(
    "--spline-svg",
    type=click.Path(dir_okay=False),
    default=None,
    help="Also write the quadratic B-splines as an SVG of Q paths.",
)
@click.option(
    "--closed/--open",
    "closed",
    default=None,
    help="Treat the input curves as closed (convex) or open (default: as stored in IN).",
)
@click.option(
    "--match-end/--paper-end",
    default=True,
    show_default=True,
    help="Open curves: end the polygon at the curve's end (or keep the paper's A = (S/n)^3).",
)
@FORMAT_OPTION
def affine_command(
    source: str,
    dest: str,
    vertices: int,
    spline_svg: str | None,
    closed: bool | None,
    match_end: bool,
    fmt: str | None,
) -> None:
    """Approximate each curve of IN by an affine arc length polyline (Käferböck, section 4).

    The curves in IN are dense samples (font outlines, scanned profiles). Each
    becomes a control polygon with equal areas det(x_i - x_{i-1}, x_{i+1} - x_i)
    = A whose uniform quadratic B-spline is curvature continuous; its discrete
    affine curvatures are smoothed by optimising the second vertex. Curves with
    inflections are split into pieces; closed curves must be convex. The output
    properties record A, the smoothness objective and, for closed curves, the
    closing error (lists with one value per ring or part when a feature has
    several curves). Exit status 1 if a curve could not be approximated.
    """
    from .. import affine
    from ..io import check_destination

    if dest != "-":  # before the work (and a second output that cannot be written must
        check_destination(dest)  # not leave the first one written)
    if spline_svg is not None:
        check_destination(spline_svg)
    curves = read_curves(source, fmt, keep_others=True)  # GeoJSON's others: as in smooth
    out, paths, said = [], [], []
    lo = hi = None
    for i, curve in enumerate(curves):
        if curve.points.shape[1] != 2:
            raise CurveError(
                f"{source}: curve {i} must be planar (x, y), got {curve.points.shape[1]} columns"
            )
        is_closed = curve.closed if closed is None else closed
        try:
            res = affine.approximate(
                curve.points, vertices=vertices, closed=is_closed, match_end=match_end
            )
        except CurveError as exc:
            raise CurveError(f"{source}: curve {i}: {exc}") from None
        if not res.success:
            raise CurveError(f"{source}: curve {i}: {res.message}")
        results = {
            "affine_area": res.area,
            "affine_objective": res.objective,
            "affine_closing_error": res.closing_error,
            "affine_pieces": int(res.piece_areas.size),
        }
        changes: dict[str, Any] = {}
        if not is_closed and curve.kind in ("Polygon", "MultiPolygon"):
            # rings opened into lines: every ring of the feature becomes one line
            opened = sum(1 for c in curves if c.feature == curve.feature)
            part = sum(1 for c in curves[:i] if c.feature == curve.feature)
            kind = "MultiLineString" if opened > 1 else "LineString"
            changes.update(kind=kind, part=part if opened > 1 else 0, ring=0)
        out.append((curve.replace(res.points, closed=is_closed, **changes), results))
        paths.append(quadratic_path_data(res.points, closed=is_closed))
        pmin, pmax = res.points.min(axis=0), res.points.max(axis=0)
        lo = pmin if lo is None else lo.clip(max=pmin)
        hi = pmax if hi is None else hi.clip(min=pmax)
        said.append(f"curve {i}: {res.message}")
    for line in said:  # once every curve is done: an error stays the run's one line
        click.echo(line, err=True)
    written = _with_results(out)
    if hasattr(curves, "with_curves"):  # GeoJSON's features without a curve, and crs
        written = curves.with_curves(written)
    write_curves(written, dest, fmt)
    if spline_svg is not None:
        with open_destination(Path(spline_svg)) as fh:  # atomic: no partial file on failure
            fh.write(path_document(paths, (lo, hi)))
