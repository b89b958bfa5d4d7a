"""``curvesmith contours`` and the ``--network`` path of ``curvesmith smooth``.

``contours_command`` draws smoothed contour lines or isobands of a grid
(:func:`curvesmith.geo.contours`); ``smooth_network_geofile`` is what
``curvesmith smooth IN -o OUT --network`` calls (:func:`curvesmith.geo.smooth_network`).
"""

from __future__ import annotations

import warnings
from pathlib import Path
from typing import Any

import click

from .. import methods
from ..errors import CurveError
from ..methods import GisMethod
from ._common import (
    ALPHA,
    COUNT,
    MAX_SHIFT_OPTION,
    MIN_SEGMENT_OPTION,
    POSITIVE,
    POSITIVE_INT,
    check_input,
    gis_method,
    output_option,
)

__all__ = ["contours_command", "smooth_network_geofile"]


def _check_output(path: str) -> None:
    """Fail before any work when the output format cannot be told from the suffix."""
    from .. import geo

    if Path(path).suffix.lower() not in geo.DRIVERS:
        raise CurveError(
            f"cannot tell the format of {path!r} from its suffix; use one of "
            f"{', '.join(sorted(geo.DRIVERS))}"
        )


def _write(df, path: str) -> None:
    """Write a GIS file atomically: a temporary file beside it, renamed once complete.

    A Shapefile is several files, and an existing GeoPackage may hold other layers to keep:
    those are written in place.
    """
    import os

    from .. import geo
    from ..io._core import in_flight

    target = Path(path)
    suffix = target.suffix.lower()
    if suffix == ".shp" or (suffix == ".gpkg" and target.exists()):
        geo.write_file(df, target)
        return
    tmp = target.with_name(f".{target.stem}.{os.getpid()}.tmp{target.suffix}")
    try:
        with in_flight(tmp):
            geo.write_file(df, tmp, layer=target.stem)  # the layer named as without the rename
            os.replace(tmp, target)
    finally:
        tmp.unlink(missing_ok=True)


def _alpha(text: Any) -> Any:
    if not isinstance(text, str) or text == "regular":
        return text
    try:
        return float(text)
    except ValueError:
        raise CurveError(f"--alpha must be 'regular' or a number, got {text!r}") from None


def smooth_network_geofile(
    in_path: str,
    out_path: str,
    *,
    method: str = "cca",
    iterations: int = 1,
    alpha: Any = "regular",
    layer: str | None = None,
    equal_area: bool = False,
    keep_angle: float | None = None,
    max_shift: float | None = None,
    min_segment: float | None = None,
):
    """Smooth the lines of a GIS file as one network; one-line summary on stderr.

    Parameters
    ----------
    in_path, out_path : str
        GeoPackage, Shapefile, FlatGeobuf or GeoJSON (formats by suffix).
    method : {"cca", "chaikin"}
        Smoothing method.
    iterations : int
        Smoothing passes per arc.
    alpha : "regular", float or str
        CCA cut parameter.
    layer : str, optional
        Input layer (digits select by index).
    equal_area : bool
        Smooth in an equal-area projection (for data in degrees).
    keep_angle : float, optional
        Corners turning by more than this (radians) stay fixed.
    max_shift, min_segment : float, optional
        Strength and vertex budget per arc, in the units of the CRS smoothed in (metres
        with `equal_area`), as in :func:`curvesmith.geo.smooth_network`.

    Returns
    -------
    curvesmith.geo.NetworkResult
    """
    from .. import geo

    gis = gis_method(method, what="networks")
    _check_output(out_path)
    from ..geo._io import InputWarning

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", InputWarning)
        df = geo.read_file(in_path, layer=int(layer) if layer and layer.isdigit() else layer)
    for w in caught:
        if issubclass(w.category, InputWarning):
            click.echo(f"Warning: {w.message}", err=True)
        else:
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
    crs = df.crs
    if equal_area and crs is None:
        raise CurveError(f"--equal-area needs a CRS, but {in_path!r} has none")
    from ..geo._io import is_equal_area_crs

    if equal_area and is_equal_area_crs(crs):
        equal_area = False  # already in an equal-area projection: smoothed in it
    if crs is not None and crs.is_geographic and not equal_area:
        from ..geo._io import geographic_message
        from .geo import _in_cli_words

        click.echo(f"Warning: {_in_cli_words(geographic_message(in_path, crs.name))}", err=True)
    from ..geo._io import (
        check_network_back,
        densify_tolerance,
        projected_budget,
        to_one_equal_area,
    )

    work, budget = df, max_shift
    if equal_area:  # max_shift in ground metres (geo._io.projected_budget)
        tolerance = densify_tolerance(max_shift)
        work = to_one_equal_area(df, mode="network", name=in_path, tolerance=tolerance)
        budget = projected_budget(work.geometry.values, max_shift, tolerance)
    res = geo.smooth_network(
        work,
        method=gis,
        iterations=iterations,
        alpha=_alpha(alpha),
        full_output=True,
        keep_angle=keep_angle,
        max_shift=budget,
        min_segment=min_segment,
    )
    out = res.geometry.to_crs(crs) if equal_area else res.geometry
    if equal_area:
        check_network_back(df.geometry, out.geometry, name=in_path)
    _write(out, out_path)
    counts = (res.n_lines, res.n_arcs, res.n_nodes, res.n_inserted)
    bounded = max_shift is not None or min_segment is not None
    parts = network_parts(counts, len(res.reductions), bounded)
    click.echo(f"{len(out)} features, " + "; ".join(parts), err=True)
    return res


def network_parts(counts: tuple[int, int, int, int], n_reductions: int, bounded: bool) -> list:
    """The summary of a network's smoothing (``smooth --network``, ``batch --network``).

    `counts`: ``(n_lines, n_arcs, n_nodes, n_inserted)`` of a NetworkResult; `bounded`:
    --max-shift or --min-segment was given.
    """
    lines, arcs, nodes, inserted = counts
    parts = [f"{lines} lines smoothed as one network ({arcs} arcs between {nodes} fixed nodes)"]
    if inserted:
        parts.append(f"{inserted} crossing/junction vertices inserted")
    if n_reductions:
        why = "to stay within the bounds or avoid" if bounded else "to avoid"
        why += " new contacts"
        parts.append(f"{n_reductions} piece(s) smoothed less {why}")
    return parts


def _levels(text: str | None) -> list[float] | None:
    if text is None:
        return None
    try:
        return [float(v) for v in text.split(",") if v.strip()]
    except ValueError:
        raise CurveError(f"--levels must be numbers separated by commas, got {text!r}") from None


@click.command("contours")
@click.argument("grid", metavar="GRID")
@output_option("Output GIS file.", metavar="OUT")
@click.option("--interval", type=POSITIVE, default=None, help="A level at every multiple of D.")
@click.option("--levels", default=None, help="Explicit levels, e.g. 100,250,500.")
@click.option("--bands", is_flag=True, help="Isobands (polygons between levels), not lines.")
@click.option("--iterations", type=COUNT, default=1, show_default=True, help="Smoothing passes.")
@click.option(
    "--method",
    type=click.Choice(list(methods.gis_names())),
    default="cca",
    show_default=True,
    help="cca keeps every area exactly; chaikin shrinks.",
)
@click.option(
    "--alpha",
    type=ALPHA,
    default="regular",
    show_default=True,
    help="cca: 'regular' (angle-dependent profile) or a number in (0, 1/3).",
)
@click.option(
    "--band", "raster_band", type=POSITIVE_INT, default=1, show_default=True, help="GeoTIFF band."
)
@click.option("--crs", default=None, help="CRS of the output when the grid has none.")
@MAX_SHIFT_OPTION
@MIN_SEGMENT_OPTION
def contours_command(
    grid: str,
    dest: str,
    interval: float | None,
    levels: str | None,
    bands: bool,
    iterations: int,
    method: GisMethod,
    alpha: str,
    raster_band: int,
    crs: str | None,
    max_shift: float | None,
    min_segment: float | None,
) -> None:
    """Smoothed contour lines (or isobands with --bands) of GRID, written to OUT.

    GRID is a GeoTIFF (extra "raster"), .npy, .npz or ESRI ASCII grid (.asc);
    OUT a GeoPackage, Shapefile, FlatGeobuf or GeoJSON file. The lines are
    smoothed together as one network, so lines of different levels never
    touch; each carries its `level`. Bands are smoothed as a coverage: each
    keeps its area, with no gaps or overlaps; they carry `lower` and `upper`.
    """
    from .. import geo

    if interval is not None and levels is not None:
        raise click.UsageError("give --interval or --levels, not both")
    _check_output(dest)
    check_input(grid)
    g = geo.read_grid(grid, band=raster_band)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", geo.GeographicCRSWarning)
        res = geo.contours(
            g,
            levels=_levels(levels),
            interval=interval,
            bands=bands,
            method=method,
            iterations=iterations,
            alpha=_alpha(alpha),
            crs=g.crs if g.crs is not None else crs,
            full_output=True,
            max_shift=max_shift,
            min_segment=min_segment,
        )
    with warnings.catch_warnings():
        if g.crs is None and crs is None:  # said in one line here, not as pyogrio's warning
            click.echo(
                f"Warning: {grid} has no CRS; the output has none either (give --crs)", err=True
            )
            warnings.filterwarnings("ignore", message="'crs' was not provided")
        _write(res.geometry, dest)
    what = "bands" if bands else "contour lines"
    red = len(res.smoothing.reductions)
    click.echo(
        f"{len(res.geometry)} {what} at {len(res.levels)} levels; "
        f"{red} piece(s) smoothed less to avoid contacts",
        err=True,
    )
