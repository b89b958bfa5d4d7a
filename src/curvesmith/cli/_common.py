"""Shared helpers of the CLI commands: reading and writing curve files, ``-`` for stdio."""

from __future__ import annotations

import io as _stdio
import math
import sys
import warnings
from pathlib import Path

import click

from .. import methods
from ..errors import CurveError, CurveFormatError
from ..io import Curve, check_destination, detect_format, formats
from ..io import read_curves as _read_registry
from ..io import write_curves as _write
from ..io.svg import SVGKeptWarning

__all__ = [
    "ALPHA",
    "COUNT",
    "FORMAT_OPTION",
    "GAMMA",
    "KEEP_ANGLE_OPTION",
    "MAX_SHIFT_OPTION",
    "MIN_SEGMENT_OPTION",
    "POSITIVE",
    "POSITIVE_INT",
    "check_input",
    "check_output",
    "gis_method",
    "parse_floats",
    "parse_indices",
    "read_curves",
    "write_curves",
]


class OptionError(click.UsageError, CurveError):
    """Options that do not go together: exit status 2 on the command line, a CurveError in Python.

    The command line's functions (``smooth_geofile``, ...) are also called from Python
    (the QGIS plugin, scripts), where a CurveError is what callers catch.
    """


class _Number(click.FloatRange):
    """A finite float in a range (click's FloatRange lets ``nan`` and ``inf`` through)."""

    def convert(self, value, param, ctx):
        number = super().convert(value, param, ctx)
        if not math.isfinite(number):
            self.fail(f"{value!r} is not a finite number.", param, ctx)
        return number


class _Alpha(click.ParamType):
    """cca's cut parameter: ``regular`` (the angle-dependent profile) or a number in (0, 1/3)."""

    name = "regular|number"
    _range = _Number(min=0.0, max=1.0 / 3.0, min_open=True, max_open=True)

    def convert(self, value, param, ctx):
        if value == "regular":
            return value
        try:
            number = float(value)
        except (TypeError, ValueError):
            self.fail(f"{value!r} is neither 'regular' nor a number.", param, ctx)
        if not (0.0 < number < 1.0 / 3.0):
            self.fail(f"{value!r} is not in the open interval (0, 1/3).", param, ctx)
        return number


# Option value types of every command: a bad value is a usage error (click's one message,
# naming the option; exit status 2), found before any file is read.
#: iterations, passes: an integer >= 0
COUNT = click.IntRange(min=0)
#: sizes, caps: an integer >= 1
#: An output file (or - for stdout): an existing folder there is a usage error, exit 2
OUTPUT_FILE = click.Path(dir_okay=False, allow_dash=True)


def output_option(help: str, metavar: str | None = None):
    """The commands' ``-o/--output`` (``dest``): an :data:`OUTPUT_FILE`, required."""
    return click.option(
        "-o", "--output", "dest", required=True, type=OUTPUT_FILE, metavar=metavar, help=help
    )


POSITIVE_INT = click.IntRange(min=1)
#: tolerances, steps, intervals: a finite number > 0
POSITIVE = _Number(min=0.0, min_open=True)
#: distances that may be 0 (a snap distance): a finite number >= 0
NON_NEGATIVE = _Number(min=0.0)
#: de Rham's ratio 1:gamma:1: a finite number > 1
GAMMA = _Number(min=1.0, min_open=True)
#: cca's cut parameter
ALPHA = _Alpha()


KEEP_ANGLE_OPTION = click.option(
    "--keep-angle",
    type=_Number(min=0.0, max=180.0, max_open=True),
    default=None,
    metavar="DEG",
    help="cca: keep corners that turn by more than DEG degrees (footprints, parcels).",
)


MAX_SHIFT_OPTION = click.option(
    "--max-shift",
    type=POSITIVE,
    default=None,
    metavar="D",
    help="GIS: no feature moves farther than D map units (fewer or shallower passes).",
)

MIN_SEGMENT_OPTION = click.option(
    "--min-segment",
    type=POSITIVE,
    default=None,
    metavar="L",
    help="GIS: at most one vertex per L map units of boundary (fewer passes).",
)


FORMAT_OPTION = click.option(
    "--format",
    "fmt",
    type=click.Choice(list(formats())),
    default=None,
    help="Format of - (stdin/stdout), and of a file whose suffix names none (default: the suffix).",
)


def _read(source, format: str, keep_others: bool = False):
    """Read with the registry; with `keep_others`, GeoJSON keeps NULL/Point features aside."""
    if keep_others and format in ("geojson", "json"):
        from ..io.geojson import read_geojson

        return read_geojson(source, others="keep")  # what is not a curve: write_curves
    return _read_registry(source, format=format)


def check_input(source: str) -> None:
    """A directory given as an input file is that error, whatever its name.

    Without this, a folder without a suffix was "no file suffix" and one named like a GIS
    file got GDAL's "not recognized as being in a supported file format".
    """
    if source != "-" and Path(source).is_dir():
        raise CurveFormatError(f"{source}: is a directory, not a file")


def read_curves(source: str, fmt: str | None = None, *, keep_others: bool = False) -> list[Curve]:
    """Read curves from a path, or from standard input when `source` is ``-``.

    `keep_others`: GeoJSON features without a curve (NULL, Point) and the ``crs`` member are
    kept aside for the writer (commands that write the curves back, like ``smooth``).
    """
    check_input(source)
    if source == "-":
        if fmt is None:
            raise CurveError("--format is required when reading from standard input (-)")
        raw = getattr(sys.stdin, "buffer", None)
        # bytes, so that the reader reports a non-UTF-8 input instead of surrogate escapes
        data = raw.read() if raw is not None else sys.stdin.read()
        stream = _stdio.BytesIO(data) if isinstance(data, bytes) else _stdio.StringIO(data)
        stream.name = "<stdin>"
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", UserWarning)
            curves = _read(stream, format=fmt, keep_others=keep_others)
        for w in caught:
            click.echo(f"Warning: {w.message}", err=True)
    else:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", UserWarning)
            curves = _read(Path(source), format=_format_of(source, fmt), keep_others=keep_others)
        for w in caught:  # one line each, like the errors
            click.echo(f"Warning: {w.message}", err=True)
    if not curves:
        raise CurveError(f"{source} contains no curves")
    return curves


def _map_options(curves, fmt: str) -> dict:
    """GeoJSON (map data, y pointing north) to SVG: drawn upright (``flip_y``)."""
    return {"flip_y": True} if fmt == "svg" and hasattr(curves, "others") else {}


def _warn_lost_crs(curves, dest: str, fmt: str) -> None:
    crs = getattr(curves, "crs", None)
    if crs is None or fmt in ("geojson", "json"):
        return
    from ..io.geojson import crs_label, is_crs84

    if is_crs84(crs):
        return
    click.echo(
        f"Warning: {dest}: the 'crs' member ({crs_label(crs) or crs!r}) is not kept: a "
        f"{fmt.upper()} file has no place for it (write GeoJSON to keep it)",
        err=True,
    )


def _say_others(curves, fmt: str) -> None:
    """One line each on the GeoJSON input's features and members that are not curves."""
    others = getattr(curves, "others", {}) or {}  # a GeoJSONCurves read with others="keep"
    members = getattr(curves, "members", {}) or {}
    fate = (
        "passed through unchanged"
        if fmt in ("geojson", "json")
        else f"not written: {fmt.upper() or 'the output'} holds curves only (write GeoJSON)"
    )
    if others:
        click.echo(
            f"{len(others)} feature(s) without a curve geometry (NULL, empty, Point, "
            f"MultiPoint) {fate}",
            err=True,
        )
    if members:
        click.echo(
            f"{len(members)} Point/MultiPoint member(s) of GeometryCollections {fate}", err=True
        )


def write_curves(curves: list[Curve], dest: str, fmt: str | None = None) -> None:
    """Write curves to a path, or to standard output when `dest` is ``-``."""
    out_fmt = _format_of(dest, fmt) if dest != "-" else (fmt or "")
    _warn_lost_crs(curves, dest, out_fmt)
    _say_others(curves, out_fmt)
    if dest == "-":
        if fmt is None:
            raise CurveError("--format is required when writing to standard output (-)")
        buf = _stdio.StringIO()
        _write(curves, buf, format=fmt, **_map_options(curves, fmt))
        click.echo(buf.getvalue(), nl=False)
    else:
        try:
            fmt = _format_of(dest, fmt)
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always", SVGKeptWarning)
                _write(curves, Path(dest), format=fmt, **_map_options(curves, fmt))
            for w in caught:
                if issubclass(w.category, SVGKeptWarning):
                    click.echo(f"Warning: {dest}: {w.message}", err=True)
                else:
                    warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
        except CurveError as exc:
            text = str(exc)
            if not text.startswith(dest):  # the writers name the file only for OS errors
                text = f"{dest}: {text}"
            raise CurveFormatError(text) from None


def check_output(dest: str, fmt: str | None, *, gis_suffixes: tuple[str, ...] = ()) -> None:
    """Check OUT before any work: its folder exists and is writable, its format is known.

    A suffix in `gis_suffixes` (GeoPackage, Shapefile, FlatGeobuf for GIS inputs) is
    accepted as it is; any other path needs a suffix (or ``--format``) of the curve formats.
    """
    if dest == "-":
        if fmt is None:
            raise CurveError("--format is required when writing to standard output (-)")
        return
    check_destination(dest)
    if Path(dest).suffix.lower() not in gis_suffixes:
        _format_of(dest, fmt)


def _format_of(path: str, fmt: str | None) -> str:
    """The format of the named file `path`: its suffix's, else --format's.

    --format is the format of standard input and output (``-``): ``smooth - -o out.geojson
    --format csv`` reads CSV and writes GeoJSON, ``smooth in.csv -o - --format geojson``
    the same. A named file with a suffix of no known format takes --format too.
    """
    try:
        return detect_format(path)
    except CurveFormatError as exc:
        if fmt is not None:
            return fmt
        text = str(exc).replace("or pass format= one of", "or give --format with one of")
        raise CurveFormatError(text) from None


def parse_floats(text: str, *, name: str, count: int) -> tuple[float, ...]:
    """Parse ``"x,y"`` style option values into `count` finite floats.

    A bad value is a usage error (:class:`click.UsageError`, exit status 2) naming the
    option and the value.
    """
    parts = [p.strip() for p in text.split(",")]
    try:
        values = tuple(float(p) for p in parts)
    except ValueError:
        values = ()
    if len(values) != count or not all(math.isfinite(v) for v in values):
        raise click.UsageError(f"{name} must be {count} comma-separated numbers, got {text!r}")
    return values


def parse_indices(text: str, *, name: str) -> list[int]:
    """Parse ``"0,5,17"`` into a list of vertex indices (a usage error when it is not)."""
    try:
        return [int(p) for p in text.split(",") if p.strip()]
    except ValueError:
        raise click.UsageError(f"{name} must be comma-separated integers, got {text!r}") from None


def gis_method(method: str, *, what: str) -> methods.GisMethod:
    """`method` if it smooths GIS layers, else the usage error naming what it is not for.

    >>> gis_method("derham", what="GIS files")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    curvesmith.cli._common.OptionError: --method derham is not available for GIS files; use ...
    """
    gis = methods.as_gis(method)
    if gis is None:
        raise OptionError(
            f"--method {method} is not available for {what}; use {' or '.join(methods.gis_names())}"
        )
    return gis
