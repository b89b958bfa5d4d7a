"""Core commands: ``measure``, ``smooth`` and ``demo``."""

from __future__ import annotations

import json
import math
import typing
import warnings
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
    output_option,
    parse_indices,
    read_curves,
    write_curves,
)

__all__ = ["demo_command", "measure_command", "smooth_command"]


@click.command("measure")
@click.argument("source", metavar="IN")
@FORMAT_OPTION
@click.option("--json", "as_json", is_flag=True, help="Print JSON (angles in radians).")
@click.option("--layer", default=None, help="GIS: the layer to measure (name or index).")
def measure_command(source: str, fmt: str | None, as_json: bool, layer: str | None) -> None:
    """Print length, signed area and turning angles of every curve in IN.

    Each row says where the curve comes from: its feature (with its id),
    the part of a MultiLineString/MultiPolygon, the hole number of a ring and
    the member of a GeometryCollection.

    Signed area is positive for counter-clockwise rings; for an open polyline
    it is the area between the polyline and its chord. Turning angles are
    signed (left turns positive); the table shows degrees, --json radians.
    GIS files (.gpkg, .shp, .fgb) are measured in their CRS's units.
    """
    from ._measure import measure_ragged
    from .geo import GEO_SUFFIXES

    check_input(source)
    gis = source != "-" and Path(source).suffix.lower() in GEO_SUFFIXES
    if layer is not None and not gis:
        raise click.UsageError("--layer is for GIS files (.gpkg, .shp, .fgb, ...)")
    if gis:
        from ..geo._io import curve_table, read_file
        from .geo import _echo_warnings, _layer

        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", UserWarning)
            df = read_file(source, layer=_layer(layer), columns=[])
        _echo_warnings(caught)  # one line each, like the errors
        table = curve_table(df, name=source)
        if len(table.closed) == 0:
            raise CurveError(f"{source} contains no lines or polygons")
        n_without = table.n_without
        ids: list = [None] * len(table.closed)
    else:
        curves = read_curves(source, fmt, keep_others=True)  # GeoJSON NULLs are data
        n_without = len(getattr(curves, "others", {}) or {})
        table = _curve_table(curves)
        ids = [_id_of(c) for c in curves]
    if n_without:
        click.echo(
            f"{n_without} feature(s) without a curve geometry (NULL, empty, Point, "
            "MultiPoint) not measured",
            err=True,
        )
    with np.errstate(over="ignore", invalid="ignore"):
        m = measure_ragged(table.coords, table.offsets, table.closed, table.dims)
    _refuse_overflow(m, source)
    angle = m.has_turning
    columns = {
        "index": range(len(ids)),
        "feature": table.feature.tolist(),
        "kind": table.kind.tolist(),
        "part": table.part.tolist(),
        "ring": table.ring.tolist(),
        "member": [None if j < 0 else j for j in table.member.tolist()],
        "id": ids,
        "points": m.points.tolist(),
        "closed": table.closed.tolist(),
        "dimension": table.dims.tolist(),
        "length": m.length.tolist(),
        "signed_area": _or_none(m.signed_area, m.has_area),
        "min_turning_angle": _or_none(m.min_turning_angle, angle),
        "max_turning_angle": _or_none(m.max_turning_angle, angle),
        "zero_length_edges": m.zero_length_edges.tolist(),
    }
    names = list(columns)
    if as_json:
        # one curve per line, each by json's C encoder (indent= takes the pure-Python one,
        # 25 s for 400,000 curves)
        rows = (
            json.dumps(dict(zip(names, values, strict=True)))
            for values in zip(*columns.values(), strict=True)
        )
        head = json.dumps(source)
        click.echo(f'{{"source": {head}, "curves": [\n' + ",\n".join(rows) + "\n]}")
        return

    def deg(v):
        return "-" if v is None else f"{math.degrees(v):.3f}"

    head = f"{'#':>4} {'points':>8} {'closed':>6} {'length':>16} {'signed area':>18} "
    head += f"{'min turn°':>10} {'max turn°':>10}  where"
    lines = [head]
    for i, feature, kind, part, ring, member, ident, points, closed, length, area, lo, hi in zip(
        columns["index"], columns["feature"], columns["kind"], columns["part"], columns["ring"],
        columns["member"], ids, columns["points"], columns["closed"], columns["length"],
        columns["signed_area"], columns["min_turning_angle"], columns["max_turning_angle"],
        strict=True,
    ):  # fmt: skip
        shown = "-" if area is None else f"{area:.10g}"
        lines.append(
            f"{i:>4} {points:>8} {('yes' if closed else 'no'):>6} {length:>16.10g} {shown:>18} "
            f"{deg(lo):>10} {deg(hi):>10}  {_where(feature, ident, kind, part, ring, member)}"
        )
    click.echo("\n".join(lines))


def _id_of(curve) -> str | int | float | None:
    """The id a row shows: the ``id`` property, else the GeoJSON Feature id."""
    ident = curve.properties.get("id", curve.feature_id)
    return ident if isinstance(ident, str | int | float) else None


def _curve_table(curves):
    """Curves read by :mod:`curvesmith.io` as the ragged table of :func:`geo._io.curve_table`."""
    from types import SimpleNamespace

    n = np.array([len(c.points) for c in curves], dtype=np.int64)
    coords = np.zeros((int(n.sum()), 3))
    at = 0
    for c, k in zip(curves, n.tolist(), strict=True):
        coords[at : at + k, : c.dim] = c.points
        at += k
    return SimpleNamespace(
        coords=coords,
        offsets=np.concatenate([[0], np.cumsum(n)]).astype(np.int64),
        closed=np.array([c.closed for c in curves], dtype=bool),
        dims=np.array([c.dim for c in curves], dtype=np.int64),
        feature=np.array([c.feature for c in curves], dtype=np.int64),
        part=np.array([c.part for c in curves], dtype=np.int64),
        ring=np.array([c.ring for c in curves], dtype=np.int64),
        member=np.array([-1 if c.member is None else c.member for c in curves], dtype=np.int64),
        kind=np.array([c.kind for c in curves], dtype=object),
    )


def _or_none(values: np.ndarray, present: np.ndarray) -> list:
    """`values` as floats, None where not `present`."""
    return [v if ok else None for v, ok in zip(values.tolist(), present.tolist(), strict=True)]


_MEASURED = ("length", "signed_area", "min_turning_angle", "max_turning_angle")


def _refuse_overflow(m, source: str) -> None:
    """The error for the first curve with a measure that overflowed (inf/nan)."""
    with np.errstate(invalid="ignore"):
        bad = np.column_stack([
            ~np.isfinite(m.length),
            m.has_area & ~np.isfinite(m.signed_area),
            m.has_turning & ~np.isfinite(m.min_turning_angle),
            m.has_turning & ~np.isfinite(m.max_turning_angle),
        ])  # fmt: skip
    if not bad.any():
        return
    i = int(np.flatnonzero(bad.any(axis=1))[0])
    names = [n for n, b in zip(_MEASURED, bad[i].tolist(), strict=True) if b]
    value = float(getattr(m, names[0])[i])
    raise CurveError(
        f"curve {i} of {source}: {', '.join(names)} overflow ({value}) in floating "
        "point: the coordinates are too large; scale them down"
    )


def _where(feature: int, ident, kind: str, part: int, ring: int, member: int | None) -> str:
    """Where a curve comes from: feature (and id), collection member, Multi* part, hole."""
    text = f"feature {feature}"
    if ident is not None:
        text += f" ({ident})"
    if member is not None:
        text += f" member {member}"
    if kind.startswith("Multi"):
        text += f" part {part}"
    if ring:
        text += f" hole {ring}"
    return text


@click.command("smooth")
@click.argument("source", metavar="IN")
@output_option("Output file, or -.", metavar="OUT")
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
    help="GIS: write features without geometry through (default: an error, a damaged "
    "file; GeoJSON's null geometries, which RFC 7946 allows, always pass).",
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
@click.option(
    "--tolerance",
    type=POSITIVE,
    default=None,
    help="--curves: max deviation of the Bezier paths from the smoothed curve (the smoothing's "
    "own change comes on top: --iterations 0 fits the input itself); default 1/1000 of the "
    "drawing's diagonal.",
)
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
    geojson_out = dest != "-" and Path(dest).suffix.lower() in (".geojson", ".json")
    if geojson_in and geojson_out and not gis_only and not (anchors or curve_kind):
        # XYZ GeoJSON too: smoothed in XY with Z interpolated, as GIS data are (the ring by
        # ring path smooths in 3D, and the same file gave other XY, 1.65 m off, and Z outside
        # the input's range, as .geojson than as .gpkg); methods geo has (cca, chaikin)
        gis_only = method in typing.get_args(methods.GisMethod) and _has_z(source)
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

    def fixed_of(c) -> list[int] | None:
        """The vertices of `c` that stay: --anchors, and the corners of --keep-angle."""
        fixed = anchor_idx
        if keep_angle is not None and len(c.points) >= 3:  # corners turning by more stay
            turn = np.abs(geometry.turning_angles(c.points, closed=c.closed))
            corners = np.flatnonzero(turn > math.radians(keep_angle))
            corners = corners if c.closed else corners + 1  # interior vertices of a line
            fixed = sorted(set(corners.tolist()) | set(anchor_idx or ()))
        return fixed or None

    def run(c):
        if not spec.keeps_vertices:
            return spec.smooth(c.points, closed=c.closed, iterations=iterations, **params)
        return spec.smooth(
            c.points, closed=c.closed, iterations=iterations, anchors=fixed_of(c), **params
        )

    curves = read_curves(source, fmt, keep_others=True)
    from ..io.geojson import GeoJSONCurves

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

        # the vertices that stayed are the ends of the fitted pieces (corners stay corners)
        kept = [fixed_of(c) if spec.keeps_vertices else None for c in curves]
        return write_fitted(
            curves, out, dest, fmt, kind=curve_kind, tolerance=tolerance, corners=kept,
            keep_angle=keep_angle,
        )  # fmt: skip
    if hasattr(curves, "with_curves"):  # GeoJSON's NULL/Point features and crs, SVG's document
        out = curves.with_curves(out)
    write_curves(out, dest, fmt)
    if isinstance(curves, GeoJSONCurves):  # what the GIS path says (after the run, so
        _warn_geographic(curves, source)  # that an error stays one line)
        smoothed = len({c.feature for c in curves})
        total = smoothed + len(curves.others)
        if iterations == 0 and not curve_kind:
            click.echo(f"{total} feature(s) not smoothed (--iterations 0)", err=True)
        else:
            click.echo(f"{smoothed} of {total} feature(s) smoothed", err=True)


def _warn_geographic(curves, source: str) -> None:
    """The GIS path's warning for GeoJSON in longitude/latitude (RFC 7946's default CRS).

    A file without a ``crs`` member is WGS 84 unless its coordinates cannot be degrees
    (a projected file written without its CRS: nothing is said of it); one with a ``crs``
    member is looked up with pyproj when it is installed.
    """
    from ..io.geojson import crs_label, is_crs84

    crs, label = curves.crs, crs_label(curves.crs)
    name = None
    if crs is None or is_crs84(crs):
        degrees = all(
            (np.abs(c.points[:, 0]) <= 180).all() and (np.abs(c.points[:, 1]) <= 90).all()
            for c in curves
        )
        name = "WGS 84" if degrees else None
    elif label is not None:
        try:
            from pyproj import CRS

            found = CRS.from_user_input(label)
        except Exception:  # pyproj missing, or a name it does not know: say nothing
            found = None
        name = found.name if found is not None and found.is_geographic else None
    if name is not None:
        from ..geo._io import geographic_message
        from .geo import _in_cli_words

        click.echo(f"Warning: {_in_cli_words(geographic_message(source, name))}", err=True)


# the options of `smooth` that belong to some methods only: (parameter, flag)
_METHOD_OPTIONS = (
    ("alpha", "--alpha"),
    ("anchors", "--anchors"),
    ("gamma", "--gamma"),
    ("degree", "--degree"),
    ("preserve_endpoints", "--preserve-endpoints/--free-endpoints"),
)


def _has_z(source: str) -> bool:
    """Whether a GeoJSON file has a position with a third (Z) coordinate."""
    try:
        with open(source, encoding="utf-8-sig") as fh:
            doc = json.load(fh)
    except (OSError, ValueError):
        return False  # the ring by ring path reads it again and says what is wrong

    def positions(node) -> bool:
        if isinstance(node, list) and node and not isinstance(node[0], list):
            return len(node) >= 3  # a position: x, y, z
        return isinstance(node, list) and any(positions(x) for x in node)

    def geometries(node):
        if not isinstance(node, dict):
            return
        if node.get("type") == "FeatureCollection":
            for f in node.get("features") or ():
                yield from geometries(f)
        elif node.get("type") == "Feature":
            yield from geometries(node.get("geometry"))
        elif node.get("type") == "GeometryCollection":
            for g in node.get("geometries") or ():
                yield from geometries(g)
        else:
            yield node

    return any(positions(g.get("coordinates")) for g in geometries(doc))


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
