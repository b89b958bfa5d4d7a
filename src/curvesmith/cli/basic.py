"""Core commands: ``measure``, ``smooth`` and ``demo``."""

from __future__ import annotations

import json
import math
from pathlib import Path

import click
import numpy as np

from .. import geometry, methods
from ..errors import CurveError
from ._common import (
    ALPHA,
    COUNT,
    FORMAT_OPTION,
    GAMMA,
    KEEP_ANGLE_OPTION,
    MAX_SHIFT_OPTION,
    MIN_SEGMENT_OPTION,
    NON_NEGATIVE,
    POSITIVE,
    OptionError,
    check_input,
    check_output,
    parse_indices,
    read_curves,
    write_curves,
)

__all__ = ["demo_command", "measure_command", "smooth_command"]


def _measure(curve) -> dict:
    p = curve.points
    keep = np.ones(len(p), dtype=bool)
    keep[1:] = np.any(p[1:] != p[:-1], axis=1)
    q = p[keep]
    if curve.closed and len(q) > 1 and np.array_equal(q[0], q[-1]):
        q = q[:-1]
    ident = curve.properties.get("id", curve.feature_id)
    row = {
        "feature": curve.feature,
        "kind": curve.kind,
        "part": curve.part,
        "ring": curve.ring,
        "id": ident if isinstance(ident, str | int | float) else None,
        "points": len(p),
        "closed": bool(curve.closed),
        "dimension": int(p.shape[1]),
        "length": geometry.curve_length(p, closed=curve.closed) if len(p) >= 2 else 0.0,
        "signed_area": None,
        "min_turning_angle": None,
        "max_turning_angle": None,
        "zero_length_edges": int((~keep).sum()),
    }
    if p.shape[1] == 2 and len(q) >= 3:
        # For an open polyline this is the area between the polyline and its chord.
        row["signed_area"] = geometry.signed_area(q)
        t = geometry.turning_angles(q, closed=curve.closed)
        if t.size:
            row["min_turning_angle"] = float(t.min())
            row["max_turning_angle"] = float(t.max())
    return row


@click.command("measure")
@click.argument("source", metavar="IN")
@FORMAT_OPTION
@click.option("--json", "as_json", is_flag=True, help="Print JSON (angles in radians).")
def measure_command(source: str, fmt: str | None, as_json: bool) -> None:
    """Print length, signed area and turning angles of every curve in IN.

    Each row says where the curve comes from: its feature (with its id),
    the part of a MultiLineString/MultiPolygon and the hole number of a ring.

    Signed area is positive for counter-clockwise rings; for an open polyline
    it is the area between the polyline and its chord. Turning angles are
    signed (left turns positive); the table shows degrees, --json radians.
    GIS files (.gpkg, .shp, .fgb) are measured in their CRS's units.
    """
    from .geo import GEO_SUFFIXES

    check_input(source)
    if source != "-" and Path(source).suffix.lower() in GEO_SUFFIXES:
        from ..geo._io import curves_from_frame, read_file

        curves = curves_from_frame(read_file(source))
        if not curves:
            raise CurveError(f"{source} contains no lines or polygons")
    else:
        curves = read_curves(source, fmt, keep_others=True)  # GeoJSON NULLs are data
        others = getattr(curves, "others", {}) or {}
        if others:
            click.echo(
                f"{len(others)} feature(s) without a curve geometry (NULL, empty, Point, "
                "MultiPoint) not measured",
                err=True,
            )
    rows = []
    for i, c in enumerate(curves):
        with np.errstate(over="ignore", invalid="ignore"):
            row = _measure(c)
        bad = [k for k, v in row.items() if isinstance(v, float) and not math.isfinite(v)]
        if bad:
            raise CurveError(
                f"curve {i} of {source}: {', '.join(bad)} overflow ({row[bad[0]]}) in floating "
                "point: the coordinates are too large; scale them down"
            )
        rows.append(dict(index=i, **row))
    if as_json:
        click.echo(json.dumps({"source": source, "curves": rows}, indent=2))
        return

    def deg(v):
        return "-" if v is None else f"{math.degrees(v):.3f}"

    head = f"{'#':>4} {'points':>8} {'closed':>6} {'length':>16} {'signed area':>18} "
    head += f"{'min turn°':>10} {'max turn°':>10}  where"
    click.echo(head)
    for r in rows:
        area = "-" if r["signed_area"] is None else f"{r['signed_area']:.10g}"
        click.echo(
            f"{r['index']:>4} {r['points']:>8} {('yes' if r['closed'] else 'no'):>6} "
            f"{r['length']:>16.10g} {area:>18} {deg(r['min_turning_angle']):>10} "
            f"{deg(r['max_turning_angle']):>10}  {_where(r)}"
        )


def _where(row: dict) -> str:
    """Where a curve comes from: feature (and id), part of a Multi* geometry, hole."""
    text = f"feature {row['feature']}"
    if row["id"] is not None:
        text += f" ({row['id']})"
    if row["kind"].startswith("Multi"):
        text += f" part {row['part']}"
    if row["ring"]:
        text += f" hole {row['ring']}"
    return text


@click.command("smooth")
@click.argument("source", metavar="IN")
@click.option("-o", "--output", "dest", required=True, metavar="OUT", help="Output file, or -.")
@FORMAT_OPTION
@click.option(
    "--method",
    type=click.Choice(list(methods.METHODS)),
    default="cca",
    show_default=True,
    help="cca keeps every enclosed area exactly; the others are linear corner cutting "
    "(lane_riesenfeld: towards the B-spline of --degree).",
)
@click.option(
    "--iterations",
    type=COUNT,
    default=1,
    show_default=True,
    help="Refinement steps (each multiplies the vertices by up to 3 with cca, 2 with chaikin).",
)
@click.option(
    "--alpha",
    type=ALPHA,
    default="regular",
    show_default=True,
    help="cca: cut parameter, 'regular' (angle-dependent profile) or a number in (0, 1/3).",
)
@click.option("--anchors", default=None, help="cca: vertex indices that stay fixed, e.g. 0,12,40.")
@click.option(
    "--gamma", type=GAMMA, default=2.0, show_default=True, help="derham: ratio 1:gamma:1, > 1."
)
@click.option(
    "--degree",
    type=click.IntRange(min=1),
    default=3,
    show_default=True,
    help="lane_riesenfeld: B-spline degree (2 is chaikin).",
)
@click.option(
    "--preserve-endpoints/--free-endpoints",
    default=True,
    show_default=True,
    help="chaikin/derham/lane_riesenfeld: keep the end points of open polylines, beside "
    "the cut points (PostGIS keeps a line's ends in place of its outer cut points).",
)
@click.option(
    "--coverage",
    is_flag=True,
    help="GIS: polygons share borders; smooth each shared arc once (no gaps, areas exact).",
)
@click.option("--layer", default=None, help="GIS: input layer name or index.")
@click.option(
    "--equal-area", is_flag=True, help="GIS: smooth in an equal-area projection (data in degrees)."
)
@click.option("--make-valid", is_flag=True, help="GIS: repair invalid input polygons first.")
@click.option(
    "--snap",
    type=NON_NEGATIVE,
    default=None,
    help="GIS coverage: snap distance to clean it first.",
)
@click.option(
    "--allow-null",
    is_flag=True,
    help="GIS: write features without geometry through (default: an error, a damaged file).",
)
@click.option(
    "--network", is_flag=True, help="GIS lines: junctions fixed, shared pieces once, no contacts."
)
@click.option(
    "--curves",
    "curve_kind",
    type=click.Choice(["quadratic", "cubic"]),
    default=None,
    help="Write G2 Bezier paths (few segments within --tolerance) instead of polylines.",
)
@click.option("--tolerance", type=POSITIVE, default=None, help="--curves: max deviation.")
@KEEP_ANGLE_OPTION
@MAX_SHIFT_OPTION
@MIN_SEGMENT_OPTION
def smooth_command(
    source: str,
    dest: str,
    fmt: str | None,
    method: str,
    iterations: int,
    alpha: str | float,
    anchors: str | None,
    gamma: float,
    degree: int,
    preserve_endpoints: bool,
    coverage: bool,
    layer: str | None,
    equal_area: bool,
    make_valid: bool,
    snap: float | None,
    allow_null: bool,
    network: bool,
    curve_kind: str | None,
    tolerance: float | None,
    keep_angle: float | None,
    max_shift: float | None,
    min_segment: float | None,
) -> None:
    """Smooth every curve in IN and write the result to OUT.

    The default method, cca (Gordon's corner cutting and augmentation),
    preserves the signed area of every closed ring, and for open polylines the
    area between the polyline and its chord, exactly. Structure and properties
    of the input (features, holes, ids) are kept.

    GIS files (GeoPackage .gpkg, Shapefile .shp, FlatGeobuf .fgb, and GeoJSON
    with --coverage) go through curvesmith.geo (extra "geo"): attributes and
    CRS are kept, output stays valid, and --coverage keeps neighbouring
    polygons gap-free.
    """
    from .geo import check_geo_output, is_geofile, smooth_geofile

    check_input(source)
    spec = methods.get(method)
    _check_method_options(spec, keep_angle)
    budget = max_shift is not None or min_segment is not None
    if network:
        from .contours import smooth_network_geofile

        if anchors or coverage or make_valid or snap is not None or source == "-":
            raise OptionError("--network takes a GIS file and no --anchors/--coverage/--snap")
        smooth_network_geofile(
            source,
            dest,
            method=method,
            iterations=iterations,
            alpha=alpha,
            layer=layer,
            equal_area=equal_area,
            keep_angle=None if keep_angle is None else math.radians(keep_angle),
            max_shift=max_shift,
            min_segment=min_segment,
        )
        return
    geojson_in = Path(source).suffix.lower() in (".geojson", ".json")
    gis_out = dest != "-" and is_geofile(dest)
    # GeoJSON goes through curvesmith.geo for what only it does (GIS output, the map-unit
    # bounds, repair, NULLs, CRS work); otherwise ring by ring, every method, its own writer
    gis_only = budget or make_valid or allow_null or equal_area or layer is not None
    if source != "-" and (
        is_geofile(source, coverage=coverage) or (geojson_in and (gis_out or gis_only))
    ):
        if anchors or curve_kind:
            raise OptionError("--anchors and --curves are not available for GIS files")
        if snap is not None and not coverage:
            raise OptionError("--snap cleans a coverage: it needs --coverage")
        check_geo_output(dest, fmt)
        smooth_geofile(
            source,
            dest,
            method=method,
            iterations=iterations,
            alpha=alpha,
            coverage=coverage,
            layer=layer,
            equal_area=equal_area,
            make_valid=make_valid,
            snap=snap,
            allow_null=allow_null,
            keep_angle=keep_angle,
            max_shift=max_shift,
            min_segment=min_segment,
        )
        return
    flags = (coverage, layer is not None, equal_area, make_valid, snap is not None, allow_null)
    if any(flags) or budget:
        raise OptionError(
            "--coverage, --layer, --equal-area, --make-valid, --snap, --allow-null, "
            "--max-shift and --min-segment apply to GIS files (.gpkg, .shp, .fgb) and "
            "GeoJSON files, not to CSV, SVG or standard input"
        )
    if gis_out:
        raise CurveError(
            f"{dest}: GIS files (.gpkg, .shp, .fgb) are written from GIS or GeoJSON input; "
            f"{'standard input' if source == '-' else source} is not one: write .geojson, "
            ".csv or .svg"
        )
    check_output(dest, fmt)

    anchor_idx = parse_indices(anchors, name="--anchors") if anchors else None
    given = {"alpha": alpha, "gamma": gamma, "degree": degree}
    given["preserve_endpoints"] = preserve_endpoints
    params = {k: v for k, v in given.items() if k in spec.parameters}

    def run(c):
        if not spec.keeps_vertices:
            return spec.smooth(c.points, closed=c.closed, iterations=iterations, **params)
        fixed = anchor_idx
        if keep_angle is not None:  # corners turning by more than keep_angle stay
            turn = np.abs(geometry.turning_angles(c.points, closed=c.closed))
            corners = np.flatnonzero(turn > math.radians(keep_angle))
            corners = corners if c.closed else corners + 1  # interior vertices of a line
            fixed = sorted(set(corners.tolist()) | set(anchor_idx or ()))
        return spec.smooth(
            c.points, closed=c.closed, iterations=iterations, anchors=fixed or None, **params
        )

    curves = read_curves(source, fmt, keep_others=True)
    _refuse_invalid_polygons(curves, source)
    out = []
    for i, c in enumerate(curves):
        try:
            with np.errstate(over="ignore", invalid="ignore"):
                smooth = run(c)
            if not np.isfinite(smooth).all():
                raise CurveError(
                    "the smoothed coordinates overflow (inf/nan in floating point): the "
                    "coordinates are too large; scale them down"
                )
            out.append(c.replace(points=smooth))
        except CurveError as exc:
            raise CurveError(f"curve {i} of {source}: {exc}") from None
    out = _keep_valid(curves, out, method, iterations, alpha, fixable=not anchors)
    if curve_kind is not None:
        from .curves import write_fitted

        return write_fitted(
            curves, out, dest, fmt, kind=curve_kind, tolerance=tolerance, anchors=anchors
        )
    if hasattr(curves, "with_curves"):  # GeoJSON: NULL/Point features and crs go back too
        out = curves.with_curves(out)
    write_curves(out, dest, fmt)


# the options of `smooth` that belong to some methods only: (parameter, flag)
_METHOD_OPTIONS = (
    ("alpha", "--alpha"),
    ("anchors", "--anchors"),
    ("gamma", "--gamma"),
    ("degree", "--degree"),
    ("preserve_endpoints", "--preserve-endpoints/--free-endpoints"),
)


def _check_method_options(spec: methods.SmoothingMethod, keep_angle: float | None) -> None:
    """A usage error for an option given on the command line that `spec` does not take.

    An option given at its default value is no error (tools such as the QGIS plugin pass
    every option).
    """
    ctx = click.get_current_context()
    defaults = {p.name: p.default for p in ctx.command.params}
    for param, flag in _METHOD_OPTIONS:
        if param in spec.parameters or ctx.params.get(param) == defaults.get(param):
            continue
        if ctx.get_parameter_source(param) is click.core.ParameterSource.COMMANDLINE:
            takers = [m.name for m in methods.METHODS.values() if param in m.parameters]
            raise click.UsageError(
                f"{flag} applies to --method {' or '.join(takers)}, not {spec.name}"
            )
    if keep_angle is not None and not spec.keeps_vertices:
        able = " or ".join(m.name for m in methods.METHODS.values() if m.keeps_vertices)
        raise click.UsageError(f"--keep-angle needs --method {able}, got {spec.name}")


def _refuse_invalid_polygons(curves, source: str) -> None:
    """An error for GeoJSON polygons that are not valid, as the GIS path gives.

    Smoothed ring by ring they stay invalid (a bow-tie stays crossed), and the same file
    written to a GeoPackage is refused: the two outputs of one input must not differ.
    """
    from ..errors import MissingDependencyError
    from ..io.geojson import GeoJSONCurves

    if not isinstance(curves, GeoJSONCurves):  # CSV, SVG: closed curves, not polygons
        return

    try:
        from ..geo._io import invalid_polygons

        bad = invalid_polygons(curves)
    except (ImportError, MissingDependencyError):
        return  # _keep_valid says that validity was not checked
    if bad:
        f, why = bad[0]
        more = f" (and {len(bad) - 1} more)" if len(bad) > 1 else ""
        where = "standard input" if source == "-" else source
        raise CurveError(
            f"{where}: feature {f} is not a valid polygon ({why}){more}; repair it first or "
            "pass --make-valid to repair it with shapely.make_valid"
        )


def _features_text(items) -> str:
    shown = ", ".join(str(f) for f in items[:5])
    return shown + (f", ... ({len(items)} in all)" if len(items) > 5 else "")


def _keep_valid(before, after, method, iterations, alpha, *, fixable: bool):
    """Check the smoothed polygons with shapely; re-smooth invalid ones through curvesmith.geo."""
    if not any(c.closed for c in after):
        return after
    from ..errors import MissingDependencyError

    try:
        from ..geo._io import keep_polygons_valid

        after, report = keep_polygons_valid(
            before,
            after,
            method=method,
            iterations=iterations,
            alpha=alpha if "alpha" in methods.get(method).parameters else "regular",
            fixable=fixable,
        )
    except (ImportError, MissingDependencyError):
        click.echo(
            "Warning: the validity of the smoothed polygons was not checked (needs shapely: "
            "pip install 'curvesmith[geo]')",
            err=True,
        )
        return after
    if report.resmoothed:
        click.echo(
            f"{len(report.resmoothed)} of {report.n_polygons} polygon(s) smoothed less where "
            f"their rings would cross, to stay valid (feature "
            f"{_features_text(report.resmoothed)})",
            err=True,
        )
    if report.invalid_input:
        f, why = report.invalid_input[0]
        click.echo(
            f"Warning: {len(report.invalid_input)} polygon(s) were already invalid in the input "
            f"(feature {f}: {why}); smoothed ring by ring, they are not valid polygons",
            err=True,
        )
    if report.still_invalid:
        f, why = report.still_invalid[0]
        how = "with --anchors" if not fixable else f"with --method {method}"
        click.echo(
            f"Warning: {len(report.still_invalid)} polygon(s) are invalid after smoothing {how} "
            f"(feature {f}: {why}); --method cca or chaikin without --anchors keeps them valid",
            err=True,
        )
    return after


@click.command("demo")
@click.argument("outdir", type=click.Path(file_okay=False))
@click.option(
    "--section",
    "sections",
    multiple=True,
    help="Run only this section (repeatable). Default: all.",
)
def demo_command(outdir: str, sections: tuple[str, ...]) -> None:
    """Run every capability on bundled data; write PNG figures, summary.md and summary.json."""
    from ..demo import run_demo

    summary = run_demo(
        outdir,
        sections=list(sections) or None,
        progress=lambda msg: click.echo(f"demo {msg}", err=True),
    )
    n_fig = sum(len(s["figures"]) for s in summary["sections"])
    click.echo(f"wrote {n_fig} figures and summary.md / summary.json to {outdir}")
