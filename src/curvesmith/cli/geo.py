"""GIS commands: ``curvesmith batch smooth`` and the GIS-file path of ``curvesmith smooth``.

``smooth_geofile`` is what ``curvesmith smooth`` calls when its input is a GeoPackage,
Shapefile or FlatGeobuf (or GeoJSON with ``--coverage``); ``batch_group`` is the
``curvesmith batch`` group with its ``smooth`` command (Dask).
"""

from __future__ import annotations

import math
import warnings
from pathlib import Path
from typing import Any

import click

from .. import methods
from ..errors import CurveError
from ._common import (
    ALPHA,
    COUNT,
    KEEP_ANGLE_OPTION,
    MAX_SHIFT_OPTION,
    MIN_SEGMENT_OPTION,
    NON_NEGATIVE,
    OptionError,
    check_input,
    gis_method,
    output_option,
)

__all__ = ["GEO_SUFFIXES", "batch_group", "check_geo_output", "is_geofile", "smooth_geofile"]

#: Suffixes always handled as GIS files (GeoJSON only with ``--coverage``: plain GeoJSON
#: curves go through the core reader).
GEO_SUFFIXES = (".gpkg", ".shp", ".fgb")


def is_geofile(path: str, *, coverage: bool = False) -> bool:
    """Whether ``curvesmith smooth`` should hand ``path`` to :func:`smooth_geofile`."""
    suffix = Path(path).suffix.lower()
    return suffix in GEO_SUFFIXES or (coverage and suffix in (".geojson", ".json"))


def check_geo_output(dest: str, fmt: str | None) -> None:
    """Check OUT of a GIS run before any work: known GIS suffix, existing writable folder.

    ``-`` (standard output) takes GeoJSON (``--format geojson``).
    """
    from ..geo import DRIVERS
    from ..io import check_destination

    if dest == "-":
        if fmt not in ("geojson", "json"):
            raise click.UsageError(
                "a GIS input goes to standard output (-o -) as GeoJSON: add --format geojson"
            )
        return
    check_destination(dest)
    if Path(dest).suffix.lower() not in DRIVERS:
        raise click.UsageError(
            f"{dest}: a GIS input is written as {', '.join(sorted(DRIVERS))}; got the suffix "
            f"{Path(dest).suffix or '(none)'!r}"
        )


def _alpha(alpha: Any) -> Any:
    if isinstance(alpha, str):
        if alpha == "regular":
            return alpha
        try:
            return float(alpha)
        except ValueError:
            raise CurveError(f"--alpha must be 'regular' or a number, got {alpha!r}") from None
    return alpha


def _echo_warnings(caught) -> None:
    for w in caught:
        click.echo(f"Warning: {_in_cli_words(str(w.message))}", err=True)


def _layer(layer: str | None) -> str | int | None:
    """A layer name, or its index when given as digits."""
    return int(layer) if isinstance(layer, str) and layer.isdigit() else layer


def _run_reporting_crs(fn, *args, **kwargs):
    """Call a file smoother and print its geographic-CRS warnings as one line each."""
    from .. import geo
    from ..geo._io import InputWarning

    kinds = (geo.GeographicCRSWarning, InputWarning)
    with warnings.catch_warnings(record=True) as caught:
        for kind in kinds:
            warnings.simplefilter("always", kind)
        try:
            report = fn(*args, **kwargs)
        except CurveError as exc:
            _echo_warnings(w for w in caught if issubclass(w.category, kinds))
            exc.args = (_in_cli_words(str(exc)), *exc.args[1:])
            raise
    _echo_warnings(w for w in caught if issubclass(w.category, kinds))
    return report


def _in_cli_words(message: str) -> str:
    """A library message in the command line's words: the file's feature, the flag."""
    import re

    message = re.sub(r"^(?:geometry|polygons)\[(\d+)\]", r"feature \1", message)
    for api, flag in (
        ("pass make_valid=True (--make-valid)", "pass --make-valid"),
        ("smooth_file(..., equal_area=True) (--equal-area)", "--equal-area"),
    ):
        message = message.replace(api, flag)
    return message


def smooth_geofile(
    in_path: str,
    out_path: str,
    *,
    method: str = "cca",
    iterations: int = 1,
    alpha: Any = "regular",
    coverage: bool = False,
    layer: str | None = None,
    equal_area: bool = False,
    make_valid: bool = False,
    snap: float | None = None,
    allow_null: bool = False,
    keep_angle: float | None = None,
    max_shift: float | None = None,
    min_segment: float | None = None,
):
    """Smooth a GIS file for ``curvesmith smooth`` and print a one-line summary on stderr.

    Parameters
    ----------
    in_path, out_path : str
        GeoPackage, Shapefile, GeoJSON or FlatGeobuf files (formats by suffix).
    method : {"cca", "chaikin"}
        Smoothing method.
    iterations : int
        Smoothing passes.
    alpha : "regular", float or str
        CCA cut parameter (a string number is converted).
    coverage : bool
        Treat the polygons as a coverage: shared borders smoothed once, no gaps.
    layer : str, optional
        Input layer (a string of digits selects by index).
    equal_area : bool
        Smooth in an equal-area projection (for data in degrees).
    make_valid : bool
        Repair invalid polygons instead of failing.
    snap : float, optional
        Coverage mode: snapping distance to clean an imperfect coverage first.
    allow_null : bool
        Write features without geometry through (default: an error, the file may be damaged).
    keep_angle : float, optional
        Keep corners turning by more than this many degrees.
    max_shift, min_segment : float, optional
        Strength and vertex budget per feature, in map units.

    Returns
    -------
    curvesmith.geo.FileSmoothReport
    """
    import tempfile

    from .. import geo
    from ..io._core import in_flight

    gis = gis_method(method, what="GIS files")
    with tempfile.TemporaryDirectory(prefix="curvesmith-") as tmp, in_flight(tmp):
        target = Path(tmp) / "stdout.geojson" if out_path == "-" else out_path
        report = _run_reporting_crs(
            geo.smooth_file,
            in_path,
            target,
            method=gis,
            iterations=iterations,
            alpha=_alpha(alpha),
            coverage=coverage,
            layer=_layer(layer),
            equal_area=equal_area,
            make_valid=make_valid,
            snap=snap,
            allow_null=allow_null,
            keep_angle=None if keep_angle is None else math.radians(keep_angle),
            max_shift=max_shift,
            min_segment=min_segment,
        )
        if out_path == "-":
            click.echo(Path(target).read_text(encoding="utf-8"), nl=False)
    _summary(report, iterations)
    return report


def _not_equal_area(features) -> str:
    shown = ", ".join(map(str, features[:5]))
    return (
        f"{len(features)} feature(s) smoothed in the file's CRS, not equal-area "
        f"(the projection would fold them: feature {shown})"
    )


def _snap_part(report) -> list[str]:
    """What ``--snap`` did to the areas, when it changed them (the smoothing keeps them)."""
    if not report.snap_area_change > 0.0:
        return []
    change = 100 * report.snap_area_change
    return [f"--snap changed feature areas by up to {change:.3g} % before smoothing"]


def _summary(report, iterations: int) -> None:
    through = report.n_null + report.n_empty + report.n_points + report.n_unchanged
    parts = [f"{report.n_features - through} of {report.n_features} feature(s) smoothed"]
    if iterations == 0:  # (a check of the input, or a copy through another format)
        parts = [f"{report.n_features} feature(s) written as they were (--iterations 0)"]
    if report.n_null or report.n_empty:
        parts.append(
            f"{report.n_null} without geometry (NULL) and {report.n_empty} empty, written "
            f"through unchanged"
        )
    if report.n_points:
        parts.append(f"{report.n_points} Point/MultiPoint feature(s) written through unchanged")
    if report.n_unchanged:
        parts.append(
            f"{report.n_unchanged} left as they were: no strength tried kept them within "
            "--max-shift / --min-segment"
        )
    if report.n_reductions:
        parts.append(f"{report.n_reductions} piece(s) smoothed less to stay valid")
    parts += _snap_part(report)
    if report.not_equal_area:
        parts.append(_not_equal_area(report.not_equal_area))
    if report.invalid_edges:
        parts.append(
            f"{len(report.invalid_edges)} feature(s) with invalid coverage edges left unchanged "
            f"there"
        )
    if report.coverage_valid is not None:
        if report.coverage_valid:
            parts.append("coverage valid")
        elif report.invalid_edges:
            parts.append("coverage NOT valid, as the input was not (clean it first: --snap)")
        else:
            parts.append("coverage NOT valid")
    click.echo("; ".join(parts), err=True)


@click.group("batch", context_settings={"help_option_names": ["-h", "--help"]})
def batch_group() -> None:
    """Process large GIS files on a Dask cluster (needs curvesmith[geo,dask])."""


@batch_group.command("smooth")
@click.argument("source", metavar="IN")
@output_option("Output GIS file.", metavar="OUT")
@click.option(
    "--method",
    type=click.Choice(list(methods.gis_names())),
    default="cca",
    show_default=True,
    help="cca keeps every ring's area exactly; chaikin shrinks.",
)
@click.option("--iterations", type=COUNT, default=1, show_default=True, help="Smoothing passes.")
@click.option(
    "--alpha",
    type=ALPHA,
    default="regular",
    show_default=True,
    help="cca: 'regular' (angle-dependent profile) or a number in (0, 1/3).",
)
@click.option("--coverage", is_flag=True, help="Shared borders smoothed once: no gaps/overlaps.")
@click.option(
    "--network",
    is_flag=True,
    help="Lines as one network: ends, junctions, crossings fixed; no new contacts.",
)
@click.option("--layer", default=None, help="Input layer name (or index).")
@click.option("--equal-area", is_flag=True, help="Smooth in an equal-area projection.")
@click.option("--make-valid", is_flag=True, help="Repair invalid polygons instead of failing them.")
@click.option(
    "--snap",
    type=NON_NEGATIVE,
    default=None,
    help="Coverage: snapping distance (CRS units).",
)
@click.option(
    "--workers",
    type=click.IntRange(min=1),
    default=None,
    help="Local worker processes [default: 2].",
)
@click.option("--scheduler", default=None, metavar="ADDRESS", help="Existing Dask scheduler.")
@click.option(
    "--partition-size",
    type=click.IntRange(min=1),
    default=None,
    help="Features per task [default: about 16 tasks of 1000-50000] (arcs per task with "
    "--coverage or --network [default: 1000]).",
)
@click.option(
    "--errors", "errors_path", default=None, help="Errors report [default: OUT.errors.json]."
)
@click.option("--progress/--no-progress", default=True, show_default=True, help="Progress bar.")
@click.option(
    "--allow-null",
    is_flag=True,
    help="Write features without geometry through unchanged (GeoJSON's always pass).",
)
@KEEP_ANGLE_OPTION
@MAX_SHIFT_OPTION
@MIN_SEGMENT_OPTION
def batch_smooth_command(
    source: str,
    dest: str,
    method: str,
    iterations: int,
    alpha: str,
    coverage: bool,
    network: bool,
    layer: str | None,
    equal_area: bool,
    make_valid: bool,
    snap: float | None,
    workers: int | None,
    scheduler: str | None,
    partition_size: int | None,
    errors_path: str | None,
    progress: bool,
    allow_null: bool,
    keep_angle: float | None,
    max_shift: float | None,
    min_segment: float | None,
) -> None:
    """Smooth every feature of IN on Dask and write OUT, in the same order.

    A feature that fails is written unchanged and listed with its reason in the
    errors report (JSON); the exit status is then 1. Features without geometry
    (NULL: the file may be damaged) are an error unless --allow-null (GeoJSON's
    null geometries, which RFC 7946 allows, pass).
    """
    from .. import batch

    if network:
        clash = [
            f
            for f, on in (
                ("--coverage", coverage),
                ("--snap", snap is not None),
                ("--make-valid", make_valid),
            )
            if on
        ]
        if clash:
            raise click.UsageError(f"--network cannot be combined with {clash[0]}")
    if snap is not None and not coverage:
        raise OptionError("--snap cleans a coverage: it needs --coverage")
    _check_batch_paths(source, dest)
    n_null, n_empty = _null_precheck(source, _layer(layer), allow_null)

    report = _run_reporting_crs(
        batch.smooth_file,
        source,
        dest,
        method=method,
        iterations=iterations,
        alpha=_alpha(alpha),
        layer=_layer(layer),
        coverage=coverage,
        network=network,
        equal_area=equal_area,
        make_valid=make_valid,
        snap=snap,
        partition_size=partition_size,
        workers=workers,
        scheduler=scheduler,
        progress=progress,
        errors_path=errors_path,
        keep_angle=None if keep_angle is None else math.radians(keep_angle),
        max_shift=max_shift,
        min_segment=min_segment,
    )
    if report.n_partitions:
        where = f"in {report.n_partitions} task(s)"
    elif coverage and (keep_angle is not None or max_shift is not None or min_segment is not None):
        # smooth_coverage tries these arc by arc at every strength: not cut into tasks
        where = "on the client (--coverage with --keep-angle, --max-shift or --min-segment)"
    elif coverage and report.geographic:
        where = "on the client (--coverage in longitude/latitude: ±180° and the poles kept)"
    else:
        where = "on the client"
    parts = [
        f"{report.n_features} features {where}, {report.seconds:.2f} s",
        f"{len(report.errors)} failed (written unchanged, see {report.errors_path})",
    ]
    if report.network is not None:  # as smooth --network says it
        from .contours import network_parts

        bounded = max_shift is not None or min_segment is not None
        parts += network_parts(report.network, report.n_reductions, bounded)
    if n_null or n_empty:
        parts.append(f"{n_null} without geometry (NULL) and {n_empty} empty")
    if report.n_reductions and report.network is None:
        parts.append(f"{report.n_reductions} piece(s) smoothed less to stay valid")
    if report.not_equal_area:
        parts.append(_not_equal_area(report.not_equal_area))
    parts += _snap_part(report)
    if report.coverage_valid is not None:  # as smooth says it
        parts.append("coverage valid" if report.coverage_valid else "coverage NOT valid")
    click.echo("; ".join(parts), err=True)
    if report.errors:
        first = report.errors[0]
        raise CurveError(
            f"{len(report.errors)} of {report.n_features} features of {source} failed and were "
            f"written unchanged (first: feature {first.index}: {first.reason})"
        )


def _check_batch_paths(source: str, dest: str) -> None:
    from ..geo import DRIVERS

    check_input(source)
    if Path(source).suffix.lower() not in DRIVERS:
        raise click.UsageError(
            f"{source}: batch smooth reads GIS files ({', '.join(sorted(DRIVERS))}); for CSV, "
            f"SVG or plain curves use curvesmith smooth"
        )
    if dest == "-":
        raise click.UsageError("batch smooth writes a GIS file, not standard output (-)")
    check_geo_output(dest, None)


def _null_precheck(source: str, layer, allow_null: bool) -> tuple[int, int]:
    """Refuse NULL geometries before the cluster starts (they are often a damaged file)."""
    from ..geo._io import InputWarning, check_null_geometries, read_file

    with warnings.catch_warnings():  # said once, by the smoothing's own reading
        warnings.simplefilter("ignore", InputWarning)
        geoms = read_file(source, layer=layer, columns=[])
    return check_null_geometries(geoms, source, allow_null=allow_null)
