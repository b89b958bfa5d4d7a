"""GIS files in and out (GeoPackage, Shapefile, GeoJSON, FlatGeobuf) through pyogrio."""

from __future__ import annotations

import contextlib
import importlib.util
import itertools
import math
import os
import shutil
import warnings
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from .. import methods
from .._gc import paused_gc
from ..errors import CurveError, CurveFormatError, require
from ..io._core import atomic_path
from ..methods import GisMethod

__all__ = [
    "DRIVERS",
    "FileSmoothReport",
    "GeographicCRSWarning",
    "check_null_geometries",
    "domain_edge_mask",
    "equal_area_crs",
    "geometry_counts",
    "read_file",
    "smooth_file",
    "write_file",
]

#: File suffix -> OGR driver written by :func:`write_file`.
DRIVERS = {
    ".gpkg": "GPKG",
    ".shp": "ESRI Shapefile",
    ".geojson": "GeoJSON",
    ".json": "GeoJSON",
    ".fgb": "FlatGeobuf",
}


class GeographicCRSWarning(UserWarning):
    """Smoothing in longitude/latitude degrees: planar area is not ground area."""


class InputWarning(UserWarning):
    """What reading a GIS file chose or could not find.

    The first of several layers, a Shapefile's missing ``.dbf`` (no attributes) or
    ``.prj`` (no CRS).
    """


@dataclass(frozen=True)
class FileSmoothReport:
    """What :func:`smooth_file` did.

    Attributes
    ----------
    n_features : int
        Features read and written (always the same number, in the same order).
    crs : str or None
        CRS of the input (and output), as a string.
    geographic : bool
        Whether that CRS is geographic (degrees).
    equal_area : bool
        Whether smoothing ran in an equal-area projection (:func:`equal_area_crs`).
    coverage : bool
        Coverage mode (:func:`curvesmith.geo.smooth_coverage`) or feature by feature.
    n_reductions : int
        Pieces smoothed less to keep the output valid (see the ``reductions`` of the
        result types).
    invalid_edges : dict of int to float
        Coverage mode: features with invalid coverage edges (position -> length).
    max_area_change : float
        Largest relative change of a ring's / polygon's area in the smoothing CRS.
    coverage_valid : bool or None
        Coverage mode: :func:`shapely.coverage_is_valid` on the output.
    n_null : int
        Features without geometry (NULL), written through unchanged (only with
        ``allow_null=True``; otherwise they are an error).
    n_empty : int
        Features with an empty geometry, written through unchanged.
    n_points : int
        Features whose geometry is a Point or MultiPoint (nothing to smooth, as in a
        mixed GeoJSON layer), written through unchanged.
    not_equal_area : tuple of int
        With ``equal_area``: features smoothed in the data's own CRS instead, because the
        projection folded them (valid in degrees, self-intersecting projected) or they
        were not valid after projecting back.
    n_unchanged : int
        Feature by feature with ``max_shift`` / ``min_segment`` (not ``equal_area``):
        features that no strength tried kept within the bounds, written as they were.
    snap_area_change : float
        Coverage mode with ``snap``: the largest relative area change the snapping made
        before the smoothing (``max_area_change`` is measured after it); 0 without.
    """

    n_features: int
    crs: str | None
    geographic: bool
    equal_area: bool
    coverage: bool
    n_reductions: int
    invalid_edges: dict[int, float]
    max_area_change: float
    coverage_valid: bool | None
    n_null: int = 0
    n_empty: int = 0
    not_equal_area: tuple[int, ...] = ()
    n_points: int = 0
    n_unchanged: int = 0
    snap_area_change: float = 0.0


def _driver_for(path: Path) -> str:
    driver = DRIVERS.get(path.suffix.lower())
    if driver is None:
        raise CurveFormatError(
            f"cannot tell the format of {str(path)!r} from its suffix; use one of "
            f"{', '.join(sorted(DRIVERS))}"
        )
    return driver


def read_file(
    path: str | Path, *, layer: str | int | None = None, columns: Sequence[str] | None = None
):
    """Read a GeoPackage, Shapefile, GeoJSON or FlatGeobuf layer into a GeoDataFrame.

    Parameters
    ----------
    path : str or Path
        The file.
    layer : str or int, optional
        Layer name or index (GeoPackages may hold several); default the first.
    columns : list of str, optional
        Attribute columns to read (``[]``: geometries only); default all.

    Returns
    -------
    geopandas.GeoDataFrame
        The features in file order, with their attributes and CRS.

    Raises
    ------
    CurveFormatError
        Missing file, unreadable file, or unknown layer (the message lists the layers);
        a layer with M values without pyarrow (pyogrio's Arrow reader keeps M, its
        default reader drops it).
    """
    pyogrio = require("pyogrio", "geo", "reading GIS files")
    path = Path(path)
    if not path.exists():
        raise CurveFormatError(f"no such file: {str(path)!r}")
    if path.is_dir():
        raise CurveFormatError(f"{path}: is a directory, not a file")
    if path.suffix.lower() == ".shp":
        _check_shapefile(path)
    try:
        with warnings.catch_warnings():  # M layers are refused below, when read
            warnings.filterwarnings("ignore", message="Measured \\(M\\) geometry types")
            layers = pyogrio.list_layers(path)
    except Exception as exc:  # pyogrio raises its own DataSourceError subclasses
        raise CurveFormatError(f"cannot read {str(path)!r}: {exc}") from exc
    names = [str(x) for x in layers[:, 0]]
    if layer is not None:
        if isinstance(layer, int | np.integer):
            if not 0 <= int(layer) < len(names):
                raise CurveFormatError(
                    f"layer must be an index in [0, {len(names) - 1}] or one of {names}, "
                    f"got {layer!r}"
                )
        elif str(layer) not in names:
            raise CurveFormatError(f"layer {layer!r} not found in {str(path)!r}; layers: {names}")
    spatial = [str(n) for n, kind in layers[:, :2] if kind is not None]
    chosen = names[0] if layer is None else layer
    if isinstance(chosen, int | np.integer):
        chosen = names[int(chosen)]
    if str(chosen) not in spatial:
        if layer is None and spatial:
            chosen = spatial[0]  # the first layer is a plain table: take the first with shapes
        else:
            raise CurveFormatError(
                f"layer {str(chosen)!r} of {str(path)!r} is a table without geometries; "
                f"layers with geometries: {spatial}"
            )
    if layer is None and len(spatial) > 1:
        warnings.warn(
            f"{path.name} has {len(spatial)} layers with geometries ({', '.join(spatial)}): "
            f"reading the first, {str(chosen)!r}; choose one with layer= (--layer)",
            InputWarning,
            stacklevel=2,
        )
    if path.suffix.lower() == ".shp":
        for part, lost in ((".dbf", "the features have no attributes"), (".prj", "no CRS")):
            if not any(path.with_suffix(x).exists() for x in (part, part.upper())):
                warnings.warn(
                    f"{path.name} has no {part} beside it: {lost}", InputWarning, stacklevel=2
                )
    layer = chosen
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            with paused_gc():  # a layer's geometries made at once (see curvesmith._gc)
                # a DateTime field whose values have different UTC offsets keeps them (as
                # Python datetimes; pandas' datetime64 holds one zone per column): pyogrio's
                # default would convert them to UTC, and the file written would lose them
                df = pyogrio.read_dataframe(
                    path, layer=layer, columns=columns, mixed_offsets_as_utc=False
                )
    except Exception as exc:
        raise CurveFormatError(f"cannot read {str(path)!r}: {exc}") from exc
    measured = any("Measured (M)" in str(w.message) for w in caught)
    for w in caught:
        # numpy's "invalid value encountered in from_wkb" for a NaN coordinate says nothing
        # the checks of the geometries (which name the feature) do not say better
        noise = issubclass(w.category, RuntimeWarning) and "from_wkb" in str(w.message)
        if "Measured (M)" not in str(w.message) and not noise:
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
    if measured:  # pyogrio's default reader drops M; its Arrow reader keeps it
        df = _read_measured(path, layer, columns)
    else:
        _restore_field_types(df, pyogrio.read_info(path, layer=layer))
        _restore_wide_integers(df, path, layer)
    if path.suffix.lower() == ".gpkg":
        _keep_identity(df, path, layer)
    return df


def _keep_identity(df: Any, path: Path, layer: Any) -> None:
    """Note a GeoPackage layer's name in ``df.attrs`` (:data:`LAYER_NAME`) for :func:`write_file`.

    A GeoPackage written from the frame names its layer so (unless a layer is given), as
    ogr2ogr does; it was named after the output file. The feature ids go with the rows
    through :func:`feature_ids` instead: ``attrs`` survive sorting and filtering, which
    would pair the ids with other rows.
    """
    df.attrs[LAYER_NAME] = str(layer)


def feature_ids(path: str | Path, layer: Any) -> tuple[str, np.ndarray] | None:
    """A GeoPackage layer's feature ids, in the order :func:`read_file` reads the features.

    ``(fid column, (n,) int64)``, or None for other formats, or a layer without ids.
    GDAL gives every feature of a GeoPackage an id that joins, relations and QGIS
    selections refer to; written back without them, the features were numbered 1..n
    again (France went from fid 144 to 35 in QGIS's world map). The file commands pass
    them to the writer with the rows in the order read (``_write_file``'s ``fids``).
    """
    import pyogrio

    path = Path(path)
    if path.suffix.lower() != ".gpkg":
        return None
    try:
        with warnings.catch_warnings():  # (an M layer's warning: said when it was read)
            warnings.filterwarnings("ignore", message="Measured \\(M\\) geometry types")
            name = pyogrio.read_info(path, layer=layer).get("fid_column") or ""
            if not name:
                return None
            fids = pyogrio.read_dataframe(
                path, layer=layer, columns=[], read_geometry=False, fid_as_index=True
            ).index.to_numpy()
    except Exception:  # ids are a courtesy: the features themselves were read
        return None
    return str(name), np.asarray(fids, dtype=np.int64)


def _restore_wide_integers(df: Any, path: Path, layer: Any) -> None:
    """Read again, exactly, the 64-bit integer fields with NULLs that float64 rounded.

    pyogrio's default reader gives an Integer64 field with a NULL as float64, which holds
    integers up to 2**53 only: 9007199254740993 came back as 9007199254740992, and was
    written so (GDAL's ogr2ogr keeps it), and 2**63 - 1 failed the cast to Int64.
    :func:`_restore_field_types` leaves those with a value of 2**53 or more in magnitude as
    they are and names them (``attrs[_WIDE]``); they are read once more through the Arrow
    reader (int64 with nulls, the same features in the same order), without geometries.
    """
    import pandas as pd

    wide = [
        n
        for n in df.columns
        if n != df.geometry.name
        and str(df[n].dtype) in ("Int64", "float64")
        and n in df.attrs.get(_WIDE, ())
    ]
    df.attrs.pop(_WIDE, None)
    if not wide:
        return
    try:
        import pyarrow as pa
        import pyogrio
    except ImportError:  # without pyarrow (the 'geo' extra has it) the values stay rounded
        return
    try:
        _, table = pyogrio.read_arrow(path, layer=layer, columns=wide, read_geometry=False)
    except Exception as exc:
        raise CurveFormatError(f"cannot read {str(path)!r}: {exc}") from exc
    exact = {pa.int64(): pd.Int64Dtype()}.get
    for n in wide:
        col = table[n]
        if col.type == pa.int64() and len(col) == len(df):
            values = col.to_pandas(types_mapper=exact)
            values.index = df.index
            df[n] = values


#: Where the file keeps its field types (``df.attrs``): the Date fields, which pandas reads
#: as datetimes and :func:`write_file` writes back as dates.
DATE_FIELDS = "curvesmith_date_fields"
#: ... and the name of its geometry column (a GeoPackage's ``geom``, ``WKT``, ``shape``).
GEOMETRY_NAME = "curvesmith_geometry_name"
#: ... and a GeoPackage layer's name.
LAYER_NAME = "curvesmith_layer_name"
#: Integer64 fields that float64 rounded, read again by _restore_wide_integers (transient).
_WIDE = "curvesmith_wide_integers"


def _restore_field_types(df: Any, info: dict) -> None:
    """Give back the field types that pyogrio's default reader loses, in place.

    An Integer, Integer64, Int16 or Boolean field with a NULL reads as float64 (1.0,
    NaN): it becomes pandas' nullable Int32, Int64, Int16 or boolean, which the writer
    writes as the same field type. A Date field reads as datetime64: its name is kept in
    ``df.attrs[DATE_FIELDS]`` so that :func:`write_file` writes it as a Date again.
    """
    nullable = {"OFSTBoolean": "boolean", "OFSTInt16": "Int16"}
    dates: list[str] = []
    wide: list[str] = []
    fields = zip(info["fields"], info["ogr_types"], info["ogr_subtypes"], strict=True)
    for name, kind, sub in fields:
        if name not in df.columns:
            continue
        col = df[name]
        if kind in ("OFTInteger", "OFTInteger64") and col.dtype == np.float64:
            if kind == "OFTInteger64" and bool((col.abs() >= 2**53).any()):
                wide.append(str(name))  # float64 rounded it: read again exactly
                continue
            dtype = nullable.get(sub, "Int64" if kind == "OFTInteger64" else "Int32")
            df[name] = col.astype(dtype)
        elif kind == "OFTDate" and str(col.dtype).startswith("datetime64"):
            dates.append(str(name))
    if dates:
        df.attrs[DATE_FIELDS] = dates
    if wide:
        df.attrs[_WIDE] = wide  # (taken out again by _restore_wide_integers)
    if info.get("geometry_name"):  # a GeoPackage's geometry column: written with its name
        df.attrs[GEOMETRY_NAME] = str(info["geometry_name"])


def _with_dates(df: Any) -> tuple[Any, bool]:
    """`df` with its Date fields (see :func:`_restore_field_types`) as dates, for writing."""
    names = [n for n in df.attrs.get(DATE_FIELDS, ()) if n in df.columns]
    names = [n for n in names if str(df[n].dtype).startswith("datetime64")]
    if not names:
        return df, False
    import pandas as pd

    try:
        import pyarrow as pa
    except ImportError:  # without pyarrow the dates are written as date-times, as before
        return df, False
    # times of day or a time zone: no longer plain dates, written as date-times
    plain = [
        n
        for n in names
        if df[n].dt.tz is None and (df[n].dropna() == df[n].dropna().dt.normalize()).all()
    ]
    if not plain:
        return df, False
    out = df.copy()
    for n in plain:
        col = out[n]
        out[n] = pd.array(col.dt.date.where(col.notna(), None), dtype=pd.ArrowDtype(pa.date32()))
    return out, True


def _with_json(df: Any) -> Any:
    """`df` with nested values (dicts and lists) of its fields as JSON text, for writing.

    pyogrio reads a JSON field (a GeoJSON property holding an object or an array, GDAL's
    ``OFSTJSON``) as Python objects and writes them back with ``str()``: ``{'x': [1, 2]}``,
    which no program reads as JSON. As JSON text they stay JSON in every format (GDAL's
    GeoJSON writer turns such text back into the nested value).
    """
    import json

    import pandas as pd

    names = [
        n
        for n in df.columns
        if n != df.geometry.name
        and df[n].dtype == object
        and pd.api.types.infer_dtype(df[n], skipna=True) not in ("string", "empty", "bytes")
    ]
    nested = [n for n in names if df[n].map(lambda v: isinstance(v, dict | list)).any()]
    if not nested:
        return df
    out = df.copy()
    for n in nested:
        out[n] = out[n].map(
            lambda v: json.dumps(v, ensure_ascii=False) if isinstance(v, dict | list) else v
        )
    return out


def _read_measured(path: Path, layer: Any, columns: Any) -> Any:
    """Read a layer with M values through pyogrio's Arrow reader (which keeps M)."""
    import pyogrio

    try:
        import pyarrow  # noqa: F401
    except ImportError:
        raise CurveFormatError(
            f"{str(path)!r} has M (measure) values; reading them needs pyarrow (pip install "
            f"pyarrow, in the 'geo' extra); without it they would be lost"
        ) from None
    try:
        with warnings.catch_warnings():
            warnings.filterwarnings("ignore", message="Measured \\(M\\) geometry types")
            with paused_gc():
                return pyogrio.read_dataframe(
                    path, layer=layer, columns=columns, use_arrow=True, mixed_offsets_as_utc=False
                )
    except Exception as exc:
        raise CurveFormatError(f"cannot read {str(path)!r}: {exc}") from exc


def _check_shapefile(path: Path) -> None:
    """Refuse a truncated Shapefile: GDAL reads the missing records as NULL geometries.

    The 100-byte headers of ``.shp`` and ``.shx`` hold the file length (big-endian 16-bit
    words at offset 24, ESRI Shapefile Technical Description, 1998), the ``.dbf`` header
    the number and length of its records (dBASE III: little-endian at offsets 4, 8, 10); a
    file shorter than its header says was cut off (an interrupted copy or download, a full
    disk).
    """
    for part in (path, path.with_suffix(".shx")):
        if not part.exists():
            continue
        size = part.stat().st_size
        with open(part, "rb") as fh:
            header = fh.read(100)
        if len(header) < 100 or int.from_bytes(header[:4], "big") != 9994:
            raise CurveFormatError(
                f"cannot read {str(path)!r}: {part.name} is not a Shapefile part (damaged header)"
            )
        declared = 2 * int.from_bytes(header[24:28], "big")
        if size < declared:
            raise CurveFormatError(
                f"cannot read {str(path)!r}: {part.name} is truncated ({size} of the {declared} "
                f"bytes its header declares): the file is damaged; copy it again"
            )
    dbf = path.with_suffix(".dbf")
    if dbf.exists():
        with open(dbf, "rb") as fh:
            header = fh.read(12)
        if len(header) == 12:
            n = int.from_bytes(header[4:8], "little")
            declared = int.from_bytes(header[8:10], "little") + n * int.from_bytes(
                header[10:12], "little"
            )
            size = dbf.stat().st_size
            if size < declared:
                raise CurveFormatError(
                    f"cannot read {str(path)!r}: {dbf.name} is truncated ({size} of the "
                    f"{declared} bytes its header declares for {n} records): the file is "
                    f"damaged; copy it again"
                )


def geometry_counts(df: Any) -> tuple[int, int]:
    """Numbers of features without geometry (NULL) and with an empty geometry.

    Parameters
    ----------
    df : geopandas.GeoDataFrame or GeoSeries

    Returns
    -------
    n_null, n_empty : int
    """
    shapely = require("shapely", "geo", "counting geometries")
    geoms = np.asarray(getattr(df, "geometry", df).values, dtype=object)
    missing = shapely.is_missing(geoms)
    empty = shapely.is_empty(geoms) & ~missing
    return int(missing.sum()), int(empty.sum())


def check_null_geometries(df: Any, source: Any, *, allow_null: bool = False) -> tuple[int, int]:
    """Count NULL and empty geometries; refuse NULLs unless `allow_null` or GeoJSON.

    A damaged file (a truncated Shapefile, a GeoPackage with unreadable blobs) reads as NULL
    geometries without any error from GDAL, so NULLs are refused by default: the caller
    would otherwise report success for a file of which a part was lost. A GeoJSON file
    (``.geojson``/``.json``) is the exception: RFC 7946 allows ``"geometry": null``, and a
    truncated GeoJSON file does not parse at all, so its NULLs are data, as in
    :func:`curvesmith.io.read_geojson` (one policy for GeoJSON, whichever path reads it).
    Empty geometries are data (they pass through smoothing unchanged) and are only counted.

    Returns
    -------
    n_null, n_empty : int

    Raises
    ------
    CurveError
        If there are NULL geometries and `allow_null` is false.
    """
    n_null, n_empty = geometry_counts(df)
    geojson = Path(str(source)).suffix.lower() in (".geojson", ".json")
    if n_null and not allow_null and not geojson:
        geoms = np.asarray(df.geometry.values, dtype=object)
        first = int(np.flatnonzero([g is None for g in geoms])[0])
        raise CurveError(
            f"{str(source)!r}: {n_null} of {len(df)} features have no geometry (NULL; the "
            f"first is feature {first}): the file may be damaged (GDAL reads unreadable "
            f"records of a truncated file as NULL); pass allow_null=True (--allow-null) to "
            f"write them through unchanged"
        )
    return n_null, n_empty


def domain_edge_mask(df: Any, *, atol: float = 1e-9) -> list[np.ndarray]:
    """Which vertices lie on the edges of the longitude/latitude domain (±180°, ±90°).

    Smoothing such a vertex moves a country past the antimeridian or Antarctica past the
    pole; these are the vertices to keep fixed.

    Parameters
    ----------
    df : geopandas.GeoDataFrame or GeoSeries
        Data in a geographic CRS (x = longitude, y = latitude in degrees, the axis order
        pyogrio and geopandas use whatever the CRS's own axis order).
    atol : float, optional
        Tolerance in degrees: ``|lon| >= 180 - atol`` or ``|lat| >= 90 - atol`` is on an
        edge (Natural Earth has longitudes of 180.00000000000006).

    Returns
    -------
    list of (N_i,) bool ndarray
        One array per feature, aligned with ``shapely.get_coordinates(geometry)`` of that
        feature (rings in order, closing vertices included); empty for NULL or empty
        geometries.

    Raises
    ------
    CurveError
        If the data have no CRS or a projected one.

    Examples
    --------
    >>> import geopandas, shapely
    >>> df = geopandas.GeoDataFrame(geometry=[shapely.box(170, -90, 180, -80)], crs=4326)
    >>> shapely.get_coordinates(df.geometry[0]).tolist()[:3]
    [[180.0, -90.0], [180.0, -80.0], [170.0, -80.0]]
    >>> domain_edge_mask(df)[0].tolist()
    [True, True, False, True, True]
    """
    shapely = require("shapely", "geo", "finding vertices on the domain's edges")
    crs = getattr(df, "crs", None)
    if crs is None or not crs.is_geographic:
        what = "no CRS" if crs is None else f"a projected CRS ({crs.name})"
        raise CurveError(f"domain_edge_mask needs a geographic CRS, got {what}")
    atol = float(atol)
    if not (math.isfinite(atol) and 0.0 <= atol < 1.0):
        raise CurveError(f"atol must be a number of degrees in [0, 1), got {atol!r}")
    out = []
    for g in np.asarray(getattr(df, "geometry", df).values, dtype=object):
        if g is None:
            out.append(np.zeros(0, dtype=bool))
            continue
        xy = shapely.get_coordinates(g)
        out.append((np.abs(xy[:, 0]) >= 180.0 - atol) | (np.abs(xy[:, 1]) >= 90.0 - atol))
    return out


_DOMAIN_ATOL = 1e-7  # degrees (about 1 cm): round trips through an equal-area projection


def _on_domain_edge(lon: np.ndarray, lat: np.ndarray, atol: float) -> np.ndarray:
    return (np.abs(lon) >= 180.0 - atol) | (np.abs(lat) >= 90.0 - atol)


def domain_fixed(geo_crs: Any, work_crs: Any = None):
    """The ``fixed=`` callable that keeps vertices on the lon/lat domain's edges in place.

    Parameters
    ----------
    geo_crs : pyproj.CRS
        The data's geographic CRS (x = longitude, y = latitude in degrees).
    work_crs : pyproj.CRS, optional
        The CRS the smoothing runs in (an equal-area projection of the data); vertices are
        taken back to longitude/latitude to be judged. Default: the data's own CRS.

    Returns
    -------
    callable
        ``fixed(xy) -> (N,) bool`` for :func:`curvesmith.geo.smooth` and
        :func:`curvesmith.geo.smooth_coverage`: which rows lie on ±180° or ±90°
        (within 1e-9° in degrees, 1e-7° after a projection's round trip).

    Examples
    --------
    >>> import numpy as np
    >>> fixed = domain_fixed("EPSG:4326")
    >>> fixed(np.array([[180.0, 10.0], [179.0, -90.0], [0.0, 0.0]])).tolist()
    [True, True, False]
    """
    pyproj = require("pyproj", "geo", "keeping vertices on the antimeridian and the poles")
    geo_crs = pyproj.CRS.from_user_input(geo_crs)
    if work_crs is None or pyproj.CRS.from_user_input(work_crs) == geo_crs:

        def fixed(xy: np.ndarray) -> np.ndarray:
            return _on_domain_edge(xy[:, 0], xy[:, 1], 1e-9)

        fixed.domain_edges = True  # type: ignore[attr-defined]  # (geo._corners.for_method)
        return fixed
    to_geo = pyproj.Transformer.from_crs(work_crs, geo_crs, always_xy=True)

    def fixed_projected(xy: np.ndarray) -> np.ndarray:
        lon, lat = to_geo.transform(xy[:, 0], xy[:, 1])
        return _on_domain_edge(np.asarray(lon), np.asarray(lat), _DOMAIN_ATOL)

    fixed_projected.domain_edges = True  # type: ignore[attr-defined]
    return fixed_projected


def clamp_to_domain(geoms: Any, where: str, originals: Any = None) -> Any:
    """Snap coordinates that lie a rounding error beyond ±180° / ±90° onto the edge.

    Natural Earth stores longitudes of 180.00000000000006, and a projection's round trip
    adds 1e-12°; both are moved onto the edge (moving a vertex by under 1e-7°). A vertex
    farther outside means the smoothing left the map, which is an error, not a write.
    With `originals`, a smoothed vertex within 1e-7° of an input vertex on the domain's
    edge (fixed during smoothing, then moved by up to 1e-8° by an equal-area projection's
    round trip) gets that input vertex's coordinates back exactly.

    Parameters
    ----------
    geoms : GeoDataFrame, GeoSeries or array of geometries
        Smoothed geometries in a geographic CRS.
    where : str
        The file name, for the message.
    originals : GeoSeries or array of geometries, optional
        The geometries before smoothing.

    Returns
    -------
    The same kind of object, with every coordinate inside the domain.

    Raises
    ------
    CurveError
        If a vertex lies more than 1e-7° outside the domain, naming the feature.
    """
    shapely = require("shapely", "geo", "keeping coordinates inside the lon/lat domain")
    if hasattr(geoms, "geometry") and hasattr(geoms, "columns"):  # a GeoDataFrame
        frame = geoms.copy()
        orig = getattr(originals, "geometry", originals)
        frame.geometry = clamp_to_domain(geoms.geometry, where, orig)
        return frame
    values = np.asarray(getattr(geoms, "values", geoms), dtype=object)
    xy, index = shapely.get_coordinates(values, return_index=True)
    if not len(xy):
        return geoms
    over = np.maximum(np.abs(xy[:, 0]) - 180.0, np.abs(xy[:, 1]) - 90.0)
    if np.any(over > _DOMAIN_ATOL):
        k = int(np.argmax(over))
        raise CurveError(
            f"{where}: feature {int(index[k])}: smoothing moved a vertex to "
            f"({float(xy[k, 0])!r}, {float(xy[k, 1])!r}), outside the longitude/latitude domain"
        )
    snap = None
    if originals is not None:
        orig = shapely.get_coordinates(np.asarray(getattr(originals, "values", originals)))
        orig = orig[_on_domain_edge(orig[:, 0], orig[:, 1], 1e-9)]
        if len(orig):
            from scipy.spatial import cKDTree

            d, k = cKDTree(orig).query(xy, distance_upper_bound=_DOMAIN_ATOL)
            snap = (np.isfinite(d) & (d > 0), orig[np.minimum(k, len(orig) - 1)])
    if not np.any(over > 0) and (snap is None or not snap[0].any()):
        return geoms
    new = xy.copy()
    if snap is not None:
        new[snap[0]] = snap[1][snap[0]]
    new[:, 0] = np.clip(new[:, 0], -180.0, 180.0)
    new[:, 1] = np.clip(new[:, 1], -90.0, 90.0)
    clipped = _set_xy(np.array(values, dtype=object, copy=True), new, index)
    if hasattr(geoms, "values"):
        out = geoms.copy()
        out[:] = clipped
        return out
    return clipped


def _set_xy(values: np.ndarray, xy: np.ndarray, index: np.ndarray) -> np.ndarray:
    """``shapely.set_coordinates`` of new XY that keeps the Z of 3D features."""
    import shapely

    has_z = np.zeros(len(values), dtype=bool)
    present = ~shapely.is_missing(values)
    has_z[present] = shapely.has_z(values[present])
    if not has_z.any():
        return shapely.set_coordinates(values, xy)
    rows = has_z[index]
    z = shapely.get_coordinates(values[has_z], include_z=True)[:, 2]
    values[has_z] = shapely.set_coordinates(values[has_z], np.column_stack([xy[rows], z]))
    if (~has_z).any():
        values[~has_z] = shapely.set_coordinates(values[~has_z], xy[~rows])
    return values


def set_points_aside(df: Any, *, keep: bool = True) -> tuple[Any, np.ndarray, np.ndarray]:
    """`df` with its Point and MultiPoint features as NULLs, for smoothing (nothing to smooth).

    Returns ``(df, geometries, points)``: the input's geometries and the mask of points,
    for :func:`put_points_back`. With ``keep=False`` nothing is set aside (no points).
    """
    shapely = require("shapely", "geo", "smoothing a GIS file")
    kept = np.asarray(df.geometry.values, dtype=object)
    points = np.isin(shapely.get_type_id(kept), (0, 4)) & bool(keep)  # Point, MultiPoint
    if points.any():
        df = df.copy()
        df.geometry = np.where(points, np.array(None, dtype=object), kept)
    return df, kept, points


def put_points_back(out: Any, kept: np.ndarray, points: np.ndarray) -> Any:
    """`out` with the points that :func:`set_points_aside` set aside, unchanged."""
    if not points.any():
        return out
    out = out.copy()
    out.geometry = np.where(points, kept, np.asarray(out.geometry.values, dtype=object))
    return out


def input_layer_name(path: str | Path, layer: str | int | None) -> str | None:
    """The name of the input layer `layer` (a name, or an index into the file's layers).

    None when no layer was chosen. An index is resolved to the layer's name, so that
    ``--layer 0`` and ``--layer roads`` write the same output layer.
    """
    if layer is None:
        return None
    if not isinstance(layer, int | np.integer):
        return str(layer)
    pyogrio = require("pyogrio", "geo", "reading GIS files")
    names = [str(n) for n, _ in pyogrio.list_layers(path)]
    return names[int(layer)] if 0 <= int(layer) < len(names) else None


def geographic_message(name: str, crs_name: str) -> str:
    """The warning for data smoothed in longitude/latitude degrees (one text everywhere).

    The command line shows it in its own words (``cli.geo._in_cli_words``: the flag).
    """
    return (
        f"{name!r} is in a geographic CRS ({crs_name}): smoothing keeps planar areas in "
        f"degrees, not ground areas; smooth_file(..., equal_area=True) (--equal-area) smooths "
        f"in an equal-area projection"
    )


def check_layers_kept(path: str | Path, layer: str | None) -> None:
    """Refuse to replace an existing GeoPackage of several layers by a file of one.

    Written without a ``layer``, an existing file is replaced as a whole: a GeoPackage that
    holds other layers (a project's database: a copy of QGIS's ``world_map.gpkg``, say)
    would lose them without a word. With ``layer``, that layer alone is replaced and the
    others are kept. A file that GDAL cannot list is replaced as before.
    """
    path = Path(path)
    if layer is not None or _driver_for(path) != "GPKG" or not path.is_file():
        return
    pyogrio = require("pyogrio", "geo", "writing GIS files")
    try:
        names = [str(n) for n, _ in pyogrio.list_layers(path)]
    except Exception:  # not a GeoPackage GDAL can read: nothing in it to keep
        return
    if len(names) > 1:
        shown = ", ".join(names[:6]) + (", ..." if len(names) > 6 else "")
        raise CurveFormatError(
            f"{str(path)!r} holds {len(names)} layers ({shown}), which writing it would "
            f"delete: write to a new file or remove it first (one of its own layers smoothed in "
            f"place: --layer NAME)"
        )


def write_file(df: Any, path: str | Path, *, layer: str | None = None) -> None:
    """Write a GeoDataFrame; the format follows the suffix (see :data:`DRIVERS`).

    Features keep their order (FlatGeobuf is written without its spatial index, which
    would sort them). Shapefiles hold one geometry type per file: Polygons and MultiPolygons (or
    LineStrings and MultiLineStrings) are written as the Multi type; other mixes raise
    :class:`CurveFormatError`. An existing file is replaced as a whole; only an existing
    GeoPackage written with an explicit ``layer`` keeps its other layers (that layer is
    replaced, or added), and one of several layers written without is refused
    (:func:`check_layers_kept`). A GeoPackage layer read by :func:`read_file` is written
    under its name unless ``layer`` names another. The new file is written completely to a
    temporary file in the same folder and read back before it replaces anything: a failed
    write (a full disk) leaves the previous file untouched and no partial file. Shapefile
    and FlatGeobuf have no empty geometry: an empty one is written as NULL (no geometry).
    """
    _write_file(df, path, layer=layer)


def _write_file(
    df: Any,
    path: str | Path,
    *,
    layer: str | None = None,
    fids: tuple[str, np.ndarray] | None = None,
) -> None:
    """:func:`write_file`, and into a GeoPackage the feature ids `fids` of the rows, in order.

    `fids` (from :func:`feature_ids`, for the rows as read) are written as the layer's ids
    (GDAL's ``FID`` layer option), when they are as many as the rows.
    """
    pyogrio = require("pyogrio", "geo", "writing GIS files")
    shapely = require("shapely", "geo", "writing GIS files")
    path = Path(path)
    driver = _driver_for(path)
    check_layers_kept(path, layer)
    kwargs: dict[str, Any] = {}
    if driver == "ESRI Shapefile":
        geoms = np.asarray(df.geometry.values, dtype=object)
        names = sorted({g.geom_type for g in geoms if g is not None and not shapely.is_empty(g)})
        base = {n.replace("Multi", "").replace("LinearRing", "LineString") for n in names}
        if len(base) > 1:
            raise CurveFormatError(
                f"a Shapefile holds one geometry type, got {', '.join(names)}; write a "
                f"GeoPackage (.gpkg) or FlatGeobuf (.fgb) instead"
            )
        kwargs["promote_to_multi"] = True
    if driver == "FlatGeobuf":
        # the packed R-tree would reorder the features; the output keeps the input order
        kwargs["layer_options"] = {"SPATIAL_INDEX": "NO"}
    if driver == "GeoJSON":
        # GDAL writes 15 decimals by default (1/3 came back as 0.333333333333333, and a
        # smoothed polygon 3e-14 from touching itself came back invalid); 17 significant
        # figures read back bit for bit, as curvesmith.io's own GeoJSON writer does
        kwargs["layer_options"] = {"SIGNIFICANT_FIGURES": 17}
    geoms = np.asarray(df.geometry.values, dtype=object)
    present = ~shapely.is_missing(geoms)
    if present.any() and shapely.has_m(geoms[present]).any():
        if driver != "GPKG":  # pyogrio/GDAL write M through Arrow into GeoPackages only
            raise CurveFormatError(
                f"cannot write {str(path)!r}: the geometries have M (measure) values, which "
                f"pyogrio writes to a GeoPackage only; write .gpkg (or drop M first)"
            )
        try:
            import pyarrow  # noqa: F401
        except ImportError:
            raise CurveFormatError(
                f"cannot write {str(path)!r}: writing M (measure) values needs pyarrow "
                f"(pip install pyarrow, in the 'geo' extra)"
            ) from None
        kwargs["use_arrow"] = True
        # the layer declared with M (else GDAL warns that it sets the M hint itself)
        types = {g.geom_type for g in geoms[present]}
        base = {n.replace("Multi", "") for n in types}
        if len(base) == 1:  # one type, or a type and its Multi (written as the Multi)
            name = next(iter(types)) if len(types) == 1 else f"Multi{base.pop()}"
            if len(types) > 1:
                kwargs["promote_to_multi"] = True
            z = "3D " if shapely.has_z(geoms[present]).any() else ""
            kwargs["geometry_type"] = f"Measured {z}{name}"
    df = _with_json(df)
    df, dated = _with_dates(df)
    if dated:
        kwargs["use_arrow"] = True  # pyogrio writes a Date field from Arrow's date32 only
    # a GeoPackage read from a GeoPackage keeps its layer's name (unless one is given) and
    # its feature ids, as ogr2ogr does (_keep_identity)
    name_of_layer = layer
    fid_option: dict[str, str] = {}
    if driver == "GPKG":
        if layer is None and df.attrs.get(LAYER_NAME):
            name_of_layer = str(df.attrs[LAYER_NAME])
        if fids is not None and importlib.util.find_spec("pyarrow") is None:
            fids = None  # (without pyarrow, the 'geo' extra's, a layer of slices cannot)
        if fids is not None and len(fids[1]) == len(df) and fids[0] not in df.columns:
            df = df.assign(**{fids[0]: fids[1]})
            df = df[[fids[0], *[c for c in df.columns if c != fids[0]]]]
            fid_option = {"FID": fids[0]}
    n_null, n_empty = geometry_counts(df)
    if driver in _NO_EMPTY:
        n_null += n_empty  # written as NULL: that is what reading back must find
    # a large GeoPackage goes in slices (the first creates the layer, the others append),
    # with the layer's type fixed for the whole frame, so that the WKB of the whole layer
    # is never held at once; every other file is written in one call
    slices = _slices(geoms) if driver == "GPKG" and not kwargs else [slice(0, len(df))]
    if len(slices) > 1:
        kwargs["geometry_type"], kwargs["promote_to_multi"] = _layer_type(geoms)
    order: list[str] = []  # the layers of a GeoPackage that a named layer goes into
    with atomic_path(path, stale=_SHAPEFILE_PARTS if driver == "ESRI Shapefile" else ()) as tmp:
        if driver == "GPKG" and layer is not None and path.is_file():
            shutil.copy2(path, tmp)  # a named layer replaces that layer only: keep the others
        try:
            if driver == "GPKG" and layer is not None and tmp.is_file() and tmp.stat().st_size:
                order = _gpkg_order(tmp)  # (a damaged file: sqlite's error, as GDAL's below)
            # a GeoPackage keeps the geometry column's name it was read with (GDAL: "geom")
            name = df.attrs.get(GEOMETRY_NAME) if driver == "GPKG" else None
            with _fast_sqlite(pyogrio, driver == "GPKG"):
                for k, part in enumerate(slices):
                    piece = df if len(slices) == 1 else df.iloc[part]
                    options = dict(kwargs)
                    if k == 0:  # the layer's creation: its geometry column and fid names
                        created = {**fid_option, **({"GEOMETRY_NAME": name} if name else {})}
                        options["layer_options"] = {**options.get("layer_options", {}), **created}
                        if driver == "GPKG" and not tmp.is_file():
                            # a new file as GeoPackage 1.2, which every GDAL reads without a
                            # warning (GDAL 3.6, Debian's and QGIS 3.22-3.28's, warns about
                            # the 1.4 that newer GDALs write: 'may only be partially
                            # supported'); nothing curvesmith writes needs 1.3 or 1.4
                            given = options.get("dataset_options", {})
                            options["dataset_options"] = {"VERSION": GPKG_VERSION, **given}
                    elif fid_option:  # pyogrio appends the ids through Arrow only
                        options["use_arrow"] = True
                    pyogrio.write_dataframe(
                        piece, tmp, layer=name_of_layer, driver=driver, append=k > 0, **options
                    )
                    del piece
            if order:
                _restore_gpkg_order(tmp, order)
        except Exception as exc:
            raise CurveFormatError(f"cannot write {str(path)!r}: {exc}") from exc
        _verify_written(
            tmp, path, len(df), n_null, name_of_layer if driver == "GPKG" else None, slices
        )
        if driver == "GPKG":
            fsync_path(tmp)  # on disk before it replaces anything (SQLite did not sync it)


#: The GeoPackage version a new file is written as (GDAL's VERSION dataset option).
GPKG_VERSION = "1.2"


#: The GeoPackage tables that list its layers, in the order GDAL lists them (rowid order).
_GPKG_LISTS = ("gpkg_contents", "gpkg_geometry_columns", "gpkg_ogr_contents")


def _gpkg_order(path: Path) -> list[str]:
    """The table names of a GeoPackage's ``gpkg_contents``, in rowid order (GDAL's order)."""
    import sqlite3

    with contextlib.closing(sqlite3.connect(path)) as db:
        return [r[0] for r in db.execute("SELECT table_name FROM gpkg_contents ORDER BY rowid")]


def _restore_gpkg_order(path: Path, order: list[str]) -> None:
    """Put the layers of a GeoPackage back in `order` (new ones after them).

    GDAL replaces a layer by deleting it and creating it anew, which lists it last: the
    layer that ``--layer 1`` named would be another one on the next run. GDAL lists the
    layers in the rowid order of the tables in :data:`_GPKG_LISTS` (no other table refers
    to their rowids), so those are renumbered in the layers' old order.
    """
    import sqlite3

    rank = {name.lower(): k for k, name in enumerate(order)}
    with contextlib.closing(sqlite3.connect(path)) as db, db:
        for table in _GPKG_LISTS:
            if not db.execute(
                "SELECT 1 FROM sqlite_master WHERE type = 'table' AND name = ?", (table,)
            ).fetchone():
                continue
            rows = db.execute(f"SELECT rowid, table_name FROM {table} ORDER BY rowid").fetchall()
            ranked = sorted(rows, key=lambda r: (rank.get(r[1].lower(), len(rank)), r[0]))
            if ranked == rows:
                continue
            top = max(r[0] for r in rows) + 1  # out of the way first, then 1, 2, ...
            for k, (rowid, _) in enumerate(ranked):
                db.execute(f"UPDATE {table} SET rowid = ? WHERE rowid = ?", (top + k, rowid))
            for k in range(len(ranked)):
                db.execute(f"UPDATE {table} SET rowid = ? WHERE rowid = ?", (k + 1, top + k))


#: SQLite settings for writing a GeoPackage under its temporary name: no rollback
#: journal and no sync per transaction. A crash can spoil only that temporary file, which
#: never replaces anything; the finished file is read back and synced (:func:`fsync_path`)
#: before the rename. Measured on 1 M smoothed footprints (77 M vertices, 1.6 GB):
#: 28.8-30.4 s against 38.0-38.4 s with SQLite's defaults, interleaved.
GPKG_WRITE_OPTIONS = {"OGR_SQLITE_JOURNAL": "OFF", "OGR_SQLITE_SYNCHRONOUS": "OFF"}


@contextlib.contextmanager
def _fast_sqlite(pyogrio: Any, on: bool):
    """GDAL's config options of :data:`GPKG_WRITE_OPTIONS` while writing, then as before.

    An option the user has set (in the environment or through GDAL) is left as it is.
    """
    if not on:
        yield
        return
    mine = {
        k: v for k, v in GPKG_WRITE_OPTIONS.items() if pyogrio.get_gdal_config_option(k) is None
    }
    pyogrio.set_gdal_config_options(mine)
    try:
        yield
    finally:
        pyogrio.set_gdal_config_options(dict.fromkeys(mine))


def fsync_path(path: Path) -> None:
    """Flush the file's data to the disk (``os.fsync``)."""
    fd = os.open(path, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


#: A GeoPackage is written and read back in slices of about this many vertices (16 bytes
#: each in WKB), so that the WKB of a whole large layer is never held in memory at once.
WRITE_CHUNK_VERTICES = 1 << 22


def _slices(geoms: np.ndarray) -> list[slice]:
    """Consecutive slices of the features with about WRITE_CHUNK_VERTICES vertices each."""
    shapely = require("shapely", "geo", "writing GIS files")
    if len(geoms) == 0:
        return [slice(0, 0)]
    ends = np.cumsum(shapely.get_num_coordinates(geoms))
    cuts = np.searchsorted(
        ends, np.arange(WRITE_CHUNK_VERTICES, ends[-1], WRITE_CHUNK_VERTICES), "right"
    )
    bounds = np.unique(np.concatenate([[0], cuts, [len(geoms)]]))
    return [slice(int(a), int(b)) for a, b in itertools.pairwise(bounds)]


def _layer_type(geoms: np.ndarray) -> tuple[str, bool]:
    """The GeoPackage layer type and ``promote_to_multi`` that pyogrio infers for `geoms`.

    pyogrio's ``write_dataframe`` rules for a GeoPackage, for the whole column (a slice
    alone could give another type): one geometry type, or a type and its Multi (then
    promoted to the Multi), else ``"Unknown"``; with ``" Z"`` when some non-empty
    geometry has Z.
    """
    shapely = require("shapely", "geo", "writing GIS files")
    present = geoms[~shapely.is_missing(geoms)]
    kinds = sorted({_TYPE_NAMES[t] for t in shapely.get_type_id(present).tolist()}, key=len)
    promote = False
    if len(kinds) == 1:
        name = kinds[0]
    elif len(kinds) == 2 and kinds[1] == f"Multi{kinds[0]}":  # e.g. Polygon, MultiPolygon
        name, promote = kinds[1], True
    else:
        name = "Unknown"
    if name != "Unknown" and shapely.has_z(present[~shapely.is_empty(present)]).any():
        name += " Z"
    return name, promote


_TYPE_NAMES = {
    0: "Point",
    1: "LineString",
    2: "LinearRing",
    3: "Polygon",
    4: "MultiPoint",
    5: "MultiLineString",
    6: "MultiPolygon",
    7: "GeometryCollection",
}


#: Formats without an empty geometry: GDAL writes an empty one as NULL (no geometry).
_NO_EMPTY = ("ESRI Shapefile", "FlatGeobuf")

#: Sidecar files of a Shapefile that an older output may have and a new one not.
_SHAPEFILE_PARTS = (".shx", ".dbf", ".prj", ".cpg", ".qix", ".sbn", ".sbx")


def _verify_written(
    tmp: Path, path: Path, n_features: int, n_null: int, layer, slices: list[slice] | None = None
) -> None:
    """Read the written file back (geometries only) before it replaces anything.

    The geometries are read as GDAL gives them (WKB), without parsing them into shapely
    objects: the check counts features and NULL geometries (a damaged blob reads as NULL).

    ``slices``: a GeoPackage written in several slices is read back slice by slice (by
    FID range: the new layer numbers its features 1 .. n in order; skipping to a slice
    instead costs time growing with its position), and then past the last one (which
    must find nothing). Counts that do not match are checked once more by position
    before the file is refused, so an unexpected numbering cannot fail a good file.
    """
    import gc

    import pyogrio

    def count(parts: list[dict[str, Any]]) -> tuple[int, int]:
        got, got_null = 0, 0
        with warnings.catch_warnings():  # an M layer reads back without M here: counts only
            warnings.filterwarnings("ignore", message="Measured \\(M\\) geometry types")
            for part in parts:
                # the geometries as GDAL reads them (WKB, None for NULL), not parsed: a
                # damaged blob reads as NULL, which is what is counted
                _, _, wkb, _ = pyogrio.raw.read(tmp, layer=layer, columns=[], **part)
                got += len(wkb)
                got_null += int(np.count_nonzero(wkb == None))  # noqa: E711 (elementwise)
                del wkb
                # pyogrio's reader leaves the array in a reference cycle: free it now, so
                # that one slice at a time is in memory (1 M footprints: 0.2 GB, not 1.5)
                gc.collect(0)
        return got, got_null

    by_range: list[dict[str, Any]] = [{}]
    by_position: list[dict[str, Any]] = [{}]
    if slices is not None and len(slices) > 1:
        by_range = [{"where": f"FID > {p.start} AND FID <= {p.stop}"} for p in slices]
        by_range.append({"where": f"FID > {n_features}"})
        by_position = [{"skip_features": p.start, "max_features": p.stop - p.start} for p in slices]
        by_position.append({"skip_features": n_features, "max_features": 1})
    try:
        got, got_null = count(by_range)
        if (got, got_null) != (n_features, n_null) and by_range != by_position:
            got, got_null = count(by_position)
    except Exception as exc:
        raise CurveFormatError(
            f"cannot write {str(path)!r}: the written file cannot be read back ({exc}); "
            f"the disk may be full"
        ) from exc
    if got != n_features or got_null != n_null:
        raise CurveFormatError(
            f"cannot write {str(path)!r}: the written file reads back as {got} features "
            f"({got_null} without geometry) instead of {n_features} ({n_null}); the disk may "
            f"be full"
        )


def _lon_arc(lon: np.ndarray) -> tuple[float, float]:
    """Centre and half-width (degrees) of the shortest arc of the circle holding all `lon`.

    The complement of the largest gap between consecutive sorted longitudes (the gap
    across ±180° included): data that cross the antimeridian (the Aleutians, Fiji,
    Chukotka) get a centre near 180°, not the bounding box's near 0°.
    """
    x = np.sort(np.mod(np.asarray(lon, dtype=np.float64) + 180.0, 360.0) - 180.0)
    if len(x) == 0:
        return 0.0, 0.0
    gaps = np.diff(np.concatenate([x, x[:1] + 360.0]))
    k = int(np.argmax(gaps))
    start = x[(k + 1) % len(x)]
    width = 360.0 - float(gaps[k])
    centre = float(np.mod(start + width / 2.0 + 180.0, 360.0) - 180.0)
    return centre, width / 2.0


def _laea(lon: float, lat: float) -> str:
    return f"+proj=laea +lat_0={lat:.6f} +lon_0={lon:.6f} +datum=WGS84 +units=m +no_defs"


def _geographic_xy(df: Any) -> tuple[np.ndarray, np.ndarray]:
    """Longitude/latitude of every vertex and the feature index of each."""
    shapely = require("shapely", "geo", "equal-area smoothing")
    geo4326 = df.to_crs("EPSG:4326") if not df.crs.equals("EPSG:4326") else df
    xy, index = shapely.get_coordinates(geo4326.geometry.values, return_index=True)
    bad = ~np.isfinite(xy).all(axis=1)
    if bad.any():  # PROJ gives inf for points outside the CRS's domain
        k = int(np.flatnonzero(bad)[0])
        at = k - int(np.searchsorted(index, index[k]))  # the vertex's place in its feature
        src = shapely.get_coordinates(df.geometry.values[index[k]])[at]
        raise CurveError(
            f"--equal-area: feature {int(index[k])} cannot be placed on the globe: its vertex "
            f"({src[0]:.9g}, {src[1]:.9g}) lies outside the area of {df.crs.name} (longitude/"
            f"latitude {xy[k, 0]}, {xy[k, 1]}); fix its coordinates or its CRS, or smooth "
            "without --equal-area"
        )
    return xy, index


#: PROJ methods that keep ellipsoidal areas (the spherical forms, Mollweide among them,
#: keep the areas of a sphere only).
EQUAL_AREA_METHODS = (
    "Albers Equal Area",
    "Lambert Azimuthal Equal Area",
    "Lambert Cylindrical Equal Area",
    "Equal Earth",
    "Sinusoidal",
)


def is_equal_area_crs(crs: Any) -> bool:
    """Whether `crs` (pyproj) is a projection whose planar areas are ellipsoidal areas."""
    if crs is None or not crs.is_projected:
        return False
    op = crs.coordinate_operation
    return op is not None and op.method_name in EQUAL_AREA_METHODS


def equal_area_crs(df: Any) -> str:
    """A Lambert azimuthal equal-area projection centred on the data (PROJ string).

    Areas measured in it are ground areas on the WGS84 ellipsoid (to the datum shift),
    so smoothing there keeps true areas. The centre is the middle of the shortest
    longitude arc holding the data (antimeridian-aware: the US with the Aleutians is
    centred near -150°, not at the bounding box's 0.3°) and of the latitude range.
    One projection serves a region; for data spread over the globe, see
    :func:`equal_area_regions`.
    """
    require("pyproj", "geo", "equal-area smoothing")
    xy, _ = _geographic_xy(df)
    if len(xy) == 0:
        return _laea(0.0, 0.0)
    lon, _ = _lon_arc(xy[:, 0])
    lat = 0.5 * (float(xy[:, 1].min()) + float(xy[:, 1].max()))
    return _laea(lon, lat)


#: ``equal_area`` with ``max_shift``: an edge of the data, straight in its CRS as a GIS
#: draws it, is divided until its image in the projection is within ``max_shift`` over
#: this of straight (see :mod:`._densify`).
DENSIFY_FRACTION = 20.0

#: Metres in a degree, at most (of latitude, at the poles): a shift of d degrees is at most
#: d times this on the ground.
METRES_PER_DEGREE = 111_700.0

#: The sphere the scale of a Lambert azimuthal equal-area projection is reckoned on.
EARTH_RADIUS = 6_371_008.8


def densify_tolerance(max_shift: float | None) -> float | None:
    """How straight (metres) an edge's image must be: a twentieth of `max_shift`, or None.

    Without `max_shift` edges are not divided: CCA cuts a corner in proportion to the
    edges beside it, so dividing long edges finely would smooth coarse data far less.
    """
    return None if max_shift is None else max_shift / DENSIFY_FRACTION


def densified(geoms: Any, crs: Any, target: Any, tolerance: float | None) -> np.ndarray:
    """`geoms` (in `crs`) with their edges divided as :func:`._densify.densify_for` does.

    `tolerance` None: as they are.
    """
    if tolerance is None:
        return np.asarray(geoms, dtype=object)
    import pyproj

    from ._densify import densify_for

    transform = pyproj.Transformer.from_crs(crs, target, always_xy=True).transform
    return densify_for(np.asarray(geoms, dtype=object), transform, tolerance)


def projected_budget(projected: Any, max_shift: float | None, tolerance: float | None):
    """The `max_shift` to smooth with in a Lambert azimuthal projection, for ground metres.

    Its scale is at most ``1 / cos(c / 2)`` at angular distance c from the centre (a metre
    there is up to that much on the ground), and the edges of the data and of the output
    are straight in the data's CRS to within `tolerance` each: the budget is shrunk by both,
    so that no feature moves farther than `max_shift` on the ground.
    """
    if max_shift is None:
        return None
    import shapely

    xy = shapely.get_coordinates(np.asarray(projected, dtype=object))
    rho = float(np.hypot(xy[:, 0], xy[:, 1]).max()) if len(xy) else 0.0
    scale = math.sqrt(max(1.0 - (rho / (2 * EARTH_RADIUS)) ** 2, 0.0))  # cos(c / 2)
    return max(max_shift * scale - 2 * (tolerance or 0.0), 0.0)


def to_one_equal_area(df: Any, *, mode: str, name: str, tolerance: float | None = None) -> Any:
    """`df` in the one equal-area projection a coverage or a network is smoothed in, checked.

    Coverage and network modes cannot be cut into regions as feature-by-feature smoothing
    is (:func:`equal_area_regions`): shared borders and junctions tie the layer together, so
    it goes into one projection centred on the data (:func:`equal_area_crs`). Far from the
    centre that projection shears shapes and near the antipode it folds them (Natural Earth's
    countries: Fiji and Antarctica are not valid in it, four country outlines cross
    themselves); a layer that the projection breaks is refused here, naming the first
    feature it breaks, rather than smoothed into something invalid.

    Parameters
    ----------
    df : geopandas.GeoDataFrame
        The layer, in a CRS.
    mode : {"coverage", "network"}
        What the layer is smoothed as (polygons must stay valid, lines simple).
    name : str
        The input's name, for the message.

    Returns
    -------
    geopandas.GeoDataFrame
        `df` in the projection.
    """
    import shapely

    laea = equal_area_crs(df)
    # edges divided first, so that their images are the edges the data draw (see _densify)
    import geopandas

    straight = densified(df.geometry.values, df.crs, laea, tolerance)
    work = df.copy()
    work[df.geometry.name] = geopandas.GeoSeries(straight, index=df.index, crs=df.crs)
    work = work.to_crs(laea)
    before = np.asarray(df.geometry.values, dtype=object)
    after = np.asarray(work.geometry.values, dtype=object)
    present = ~(shapely.is_missing(before) | shapely.is_empty(before))
    test = shapely.is_valid if mode == "coverage" else shapely.is_simple
    broken = np.zeros(len(before), dtype=bool)
    broken[present] = test(before[present]) & ~test(after[present])
    if broken.any():
        k = int(np.flatnonzero(broken)[0])
        what = "not valid" if mode == "coverage" else "crossing itself"
        raise CurveError(
            f"{name}: --equal-area: feature {k} is {what} in the one equal-area projection "
            f"that {mode} mode smooths in ({int(broken.sum())} feature(s) in all): the layer "
            f"spans too much of the globe for one projection; reproject it to a projected CRS "
            f"that suits it, or smooth without --equal-area"
        )
    return work


def check_network_back(before: Any, after: Any, *, name: str) -> None:
    """Refuse a network whose smoothed lines meet differently back in the input's CRS.

    The network is smoothed without new contacts in its equal-area projection; projected
    back, lines that ran close far from the projection's centre can still touch or cross.
    """
    from ._network import changed_contacts

    changed = changed_contacts(
        np.asarray(getattr(before, "values", before), dtype=object),
        np.asarray(getattr(after, "values", after), dtype=object),
    )
    if changed:
        raise CurveError(
            f"{name}: --equal-area: {changed} pair(s) of lines meet differently after "
            f"projecting back from the one equal-area projection the network was smoothed in; "
            f"reproject the layer to a projected CRS that suits it, or smooth without "
            f"--equal-area"
        )


def equal_area_regions(df: Any, *, cell: float = 30.0) -> list[tuple[str, np.ndarray]]:
    """Split features into regions that one equal-area projection each serves well.

    CCA keeps the planar area in the projection exactly, but a smoothed edge is a straight
    line there, and far from the projection's centre straight lines are far from the
    ground's geodesics (and near the antipode shapes shear without bound): one projection
    for the world changed Vanuatu's ground area by -8 % and folded Sudan. Each feature's
    centre (antimeridian-aware, :func:`equal_area_crs`) falls in a `cell` x `cell` degree
    cell; the features of a cell share a projection centred on them, and a feature wider
    than a cell gets its own.

    Returns
    -------
    list of (crs, indices)
        PROJ strings of Lambert azimuthal equal-area projections and the positions of the
        features (NULL and empty geometries are in no region).
    """
    xy, index = _geographic_xy(df)
    order = np.argsort(index, kind="stable")
    xy, index = xy[order], index[order]
    starts = np.searchsorted(index, np.arange(len(df) + 1))
    info = {}
    for i in range(len(df)):
        pts = xy[starts[i] : starts[i + 1]]
        if len(pts):
            lon, half = _lon_arc(pts[:, 0])
            info[i] = (lon, half, float(pts[:, 1].min()), float(pts[:, 1].max()))
    cells: dict[tuple, list[int]] = {}
    for i, (lon, half, lat0, lat1) in info.items():
        if 2 * half > cell or lat1 - lat0 > cell:
            cells[("own", i)] = [i]
        else:
            key = (math.floor((lon + 180.0) / cell), math.floor((0.5 * (lat0 + lat1) + 90) / cell))
            cells.setdefault(key, []).append(i)
    regions = []
    for members in cells.values():
        lon_all = np.concatenate(
            [[info[i][0] - info[i][1], info[i][0] + info[i][1]] for i in members]
        )
        lon, _ = _lon_arc(lon_all)
        lat = 0.5 * (min(info[i][2] for i in members) + max(info[i][3] for i in members))
        regions.append((_laea(lon, lat), np.array(sorted(members), dtype=np.int64)))
    return regions


def _unwrap_ring(xy: np.ndarray) -> np.ndarray:
    """Longitudes of a ring made continuous (no 360° jumps), its mean kept in [-180, 180].

    Projecting back to degrees wraps a vertex smoothed past the antimeridian (180.01°) to
    -179.99°, which makes the ring run round the globe; unwrapped it stays at 180.01°,
    exactly as smoothing in degrees would leave it.
    """
    lon = np.unwrap(xy[:, 0], period=360.0)
    lon -= 360.0 * np.round(lon.mean() / 360.0)
    return np.column_stack([lon, xy[:, 1:]])


def _unwrap(geom):
    shapely = require("shapely", "geo", "equal-area smoothing")
    if geom is None or shapely.is_empty(geom):
        return geom
    kind = geom.geom_type
    if kind == "Polygon":
        rings = [geom.exterior, *geom.interiors]
        xy = [_unwrap_ring(shapely.get_coordinates(r, include_z=geom.has_z)) for r in rings]
        return shapely.Polygon(xy[0], xy[1:])
    if kind == "LineString":
        return shapely.LineString(_unwrap_ring(shapely.get_coordinates(geom, include_z=geom.has_z)))
    if kind in ("MultiPolygon", "MultiLineString", "GeometryCollection"):
        return type(geom)([_unwrap(g) for g in geom.geoms])
    return geom


def _split_antimeridian(geom):
    """Parts of a Multi* geometry split at ±180° into (west, east) groups, or None.

    Such a feature (Fiji, Russia's Chukotka) is valid in degrees, its halves 360° apart;
    in one projection around it the halves would touch along the antimeridian (invalid).
    """
    shapely = require("shapely", "geo", "equal-area smoothing")
    if geom is None or not geom.geom_type.startswith("Multi"):
        return None
    x0, _, x1, _ = shapely.bounds(geom)
    if x1 - x0 <= 180.0:
        return None
    sides = [bool(shapely.bounds(g)[0] + shapely.bounds(g)[2] > 0) for g in geom.geoms]
    if all(sides) or not any(sides):
        return None
    return sides


def _smooth_equal_area(
    df: Any, *, make_valid: bool, smoother: Any = None, errors: list | None = None, **options
):
    """Smooth region by region in equal-area projections; check validity back home.

    Each region of :func:`equal_area_regions` is projected, smoothed and projected back to
    the data's CRS (features split at the antimeridian are smoothed as their two halves,
    longitudes unwrapped on the way back). A feature that is not valid there is smoothed
    again alone in a projection centred on it; if that is still invalid the run stops
    with an error naming the feature, rather than writing it.

    `smoother` (used by :mod:`curvesmith.batch`) smooths the projected regions elsewhere:
    called with a list of ``(geometries, labels, extra_options)``, one per region (labels:
    the file's feature index of each geometry), it returns per region ``(smoothed,
    n_reductions, [(position, reason), ...])`` for the features it had to leave unchanged,
    which are appended to `errors` as ``(feature, reason)``.
    """
    import geopandas

    shapely = require("shapely", "geo", "equal-area smoothing")
    from ._smooth import check_layer_size, smooth

    crs = df.crs
    geographic = bool(crs.is_geographic)
    source = np.asarray(df.geometry.values, dtype=object)
    pieces: list[Any] = []  # (feature, side or None, geometry)
    owners: list[tuple[int, Any]] = []
    for i, g in enumerate(source):
        sides = _split_antimeridian(g) if geographic else None
        if sides is None:
            pieces.append(g)
            owners.append((i, None))
            continue
        for side in (False, True):
            parts = [p for p, s in zip(g.geoms, sides, strict=True) if s == side]
            pieces.append(type(g)(parts))
            owners.append((i, (side, sides)))
    work = geopandas.GeoDataFrame(geometry=pieces, crs=crs)
    done = np.array(pieces, dtype=object)
    # the regions are smoothed one by one, but their outputs are all held at the end
    bounded = options.get("max_shift") is not None or options.get("min_segment") is not None
    check_layer_size(done, options["method"], int(options["iterations"]), levels=bounded)
    n_red, change = 0, 0.0
    planar: set[int] = set()  # pieces smoothed in the data's own CRS instead

    def smooth_piece(geom_array, name_of, extra) -> np.ndarray:
        nonlocal n_red, change
        try:
            res = smooth(geom_array, make_valid=make_valid, full_output=True, **options | extra)
        except CurveError as exc:
            raise CurveError(f"{name_of()}: {exc}") from None
        n_red += len(res.reductions)
        change = max(change, float(res.max_area_change))
        return np.asarray(res.geometry, dtype=object)

    # the bounds are ground metres: in each projection, max_shift shrunk by its scale and by
    # how straight the edges are kept (projected_budget); in degrees, a degree's metres
    tolerance = densify_tolerance(options.get("max_shift"))
    jobs = []  # per region: the features it smooths there, projected, and its options
    for laea, idx in equal_area_regions(work):
        home = np.asarray(work.geometry.values[idx], dtype=object)
        # edges divided first, so that their images are the edges the data draw (_densify)
        straight = densified(home, crs, laea, tolerance)
        there = np.asarray(geopandas.GeoSeries(straight, crs=crs).to_crs(laea).values)
        # valid in degrees but folded by the projection (sparse vertices along a narrow
        # neck, Sudan): smoothed in the data's CRS, where it is valid
        folded = shapely.is_valid(home) & ~shapely.is_valid(there)
        planar.update(int(j) for j in idx[folded])
        if (~folded).any():
            extra = {"fixed": domain_fixed(crs, laea)} if geographic else {}
            if "max_shift" in options:
                budget = projected_budget(there[~folded], options["max_shift"], tolerance)
                extra["max_shift"] = budget
            jobs.append((idx[~folded], laea, there[~folded], extra))
    labels = [np.array([owners[j][0] for j in idx]) for idx, _, _, _ in jobs]
    results: list[Any]
    if smoother is None:
        results = [
            (
                smooth_piece(
                    g,
                    lambda lab=lab: f"in the equal-area projection, features {lab.tolist()}",
                    extra,
                ),
                0,  # smooth_piece counts the reductions itself
                [],
            )
            for (_, _, g, extra), lab in zip(jobs, labels, strict=True)
        ]
    else:
        results = smoother(
            [(g, lab, extra) for (_, _, g, extra), lab in zip(jobs, labels, strict=True)]
        )
    for (idx, laea, there, _), lab, (out, nr, errs) in zip(jobs, labels, results, strict=True):
        n_red += nr
        if errors is not None:
            errors.extend((int(lab[k]), reason) for k, reason in errs)
        back = geopandas.GeoSeries(out, crs=laea).to_crs(crs).values
        back = np.array([_unwrap(g) for g in back] if geographic else back, dtype=object)
        # a feature left as it was (its bounds allow no smoothing) comes back undivided
        same = shapely.equals_exact(np.asarray(out, dtype=object), there, 0.0)
        back[same] = np.asarray(pieces, dtype=object)[idx[same]]
        done[idx] = back
    present = ~(shapely.is_missing(done) | shapely.is_empty(done))
    planar.update(int(j) for j in np.flatnonzero(present & ~shapely.is_valid(done)))
    in_degrees = {"fixed": domain_fixed(crs)} if geographic else {}
    for key in ("max_shift", "min_segment"):
        if geographic and options.get(key) is not None:
            in_degrees[key] = options[key] / METRES_PER_DEGREE
    for j in sorted(planar):  # folded there, or invalid back home: smooth in the data's CRS
        done[j] = smooth_piece(
            np.array([pieces[j]], dtype=object), lambda j=j: f"feature {owners[j][0]}", in_degrees
        )[0]
    geoms = np.array(source, dtype=object, copy=True)
    halves: dict[int, dict[bool, Any]] = {}
    for j, (i, split) in enumerate(owners):
        if split is None:
            geoms[i] = done[j]
        else:
            halves.setdefault(i, {})[split[0]] = (done[j], split[1])
    for i, h in halves.items():
        sides = h[True][1]
        its = {side: iter(h[side][0].geoms) for side in (False, True)}
        geoms[i] = type(source[i])([next(its[s]) for s in sides])
    present = ~(shapely.is_missing(geoms) | shapely.is_empty(geoms))
    for bad in np.flatnonzero(present & ~shapely.is_valid(geoms)):
        raise CurveError(  # pragma: no cover - geo.smooth's output is valid in its CRS
            f"feature {bad} is not valid after smoothing ({shapely.is_valid_reason(geoms[bad])})"
        )
    out = df.copy()
    out[df.geometry.name] = geopandas.GeoSeries(geoms, index=df.index, crs=crs)
    return out, n_red, change, sorted({owners[j][0] for j in planar})


def smooth_file(
    in_path: str | Path,
    out_path: str | Path,
    *,
    method: GisMethod = "cca",
    iterations: int = 1,
    alpha: Any = "regular",
    coverage: bool = False,
    layer: str | int | None = None,
    out_layer: str | None = None,
    equal_area: bool = False,
    make_valid: bool = False,
    snap: float | None = None,
    allow_null: bool = False,
    keep_angle: float | None = None,
    max_shift: float | None = None,
    min_segment: float | None = None,
) -> FileSmoothReport:
    """Smooth every feature of a GIS file and write the result (same features, same order).

    Parameters
    ----------
    in_path, out_path : str or Path
        GeoPackage (.gpkg), Shapefile (.shp), GeoJSON (.geojson, .json) or FlatGeobuf
        (.fgb); the formats may differ.
    method, iterations, alpha, make_valid
        As in :func:`curvesmith.geo.smooth`.
    coverage : bool
        Treat the polygons as a coverage (:func:`curvesmith.geo.smooth_coverage`).
    layer : str or int, optional
        Input layer.
    out_layer : str, optional
        Output layer name (GeoPackage); default the input layer's name when `layer` is
        given (by name or by index: the same output), else GDAL's (the output's stem).
    equal_area : bool
        Smooth in an equal-area projection (:func:`equal_area_crs`) and transform back,
        so that ground areas, not areas in degrees, are the ones kept. Needs a CRS. Data
        already in an ellipsoidal equal-area projection (Albers, Lambert azimuthal or
        cylindrical equal-area, Equal Earth, sinusoidal: :func:`is_equal_area_crs`) are
        smoothed in it as they are.
    snap : float, optional
        Coverage mode: snapping distance for :func:`shapely.coverage_clean`.
    allow_null : bool, optional
        Write features without geometry (NULL) through unchanged. By default they are an
        error: a damaged file reads as NULL geometries without any error from GDAL.
    keep_angle : float, optional
        Keep sharp corners (radians), as in :func:`curvesmith.geo.smooth`.
    max_shift, min_segment : float, optional
        Strength and vertex budget in the smoothing CRS's units: feature by feature as in
        :func:`curvesmith.geo.smooth`, arc by arc in coverage mode
        (:func:`curvesmith.geo.smooth_coverage`).

    Returns
    -------
    FileSmoothReport

    Raises
    ------
    CurveError
        NULL geometries without `allow_null`, a damaged or unwritable file, ... (the
        output file is then left as it was).

    Warns
    -----
    GeographicCRSWarning
        When the data are in a geographic CRS and ``equal_area`` is off.
    """
    from .._validate import as_bool

    make_valid = as_bool(make_valid, name="make_valid")
    from ._coverage import smooth_coverage
    from ._smooth import smooth

    if out_layer is None:
        out_layer = input_layer_name(in_path, layer)
    check_layers_kept(out_path, out_layer)  # before the work, not after it
    df = read_file(in_path, layer=layer)
    ids = feature_ids(in_path, layer) if _driver_for(Path(out_path)) == "GPKG" else None
    n_null, n_empty = check_null_geometries(df, in_path, allow_null=allow_null)
    crs = df.crs
    geographic = bool(crs is not None and crs.is_geographic)
    if equal_area and crs is None:
        raise CurveError(f"equal_area needs a CRS, but {str(in_path)!r} has none")
    # data already in an equal-area projection are smoothed in it: projecting them to
    # another one and back bends their straight edges (US counties in EPSG:5070 Albers:
    # areas off by 1.8e-5 instead of 3e-15)
    in_equal_area = bool(equal_area) and is_equal_area_crs(crs)
    if in_equal_area:
        equal_area = False
    if geographic and not equal_area and iterations > 0:  # (a warning about smoothing)
        message = geographic_message(str(in_path), crs.name)
        warnings.warn(message, GeographicCRSWarning, stacklevel=2)
    df, kept, points = set_points_aside(df)
    planar: list[int] = []
    n_unchanged = 0
    snap_change = 0.0
    # lon/lat data: vertices on the antimeridian and the poles stay put (Fiji, Chukotka and
    # Antarctica keep meeting there) and the output stays inside the domain
    edges = {"fixed": domain_fixed(crs)} if geographic and not equal_area else {}
    if coverage:
        work, budget = df, max_shift
        if equal_area:  # max_shift in ground metres: see projected_budget
            tolerance = densify_tolerance(max_shift)
            work = to_one_equal_area(df, mode="coverage", name=str(in_path), tolerance=tolerance)
            budget = projected_budget(work.geometry.values, max_shift, tolerance)
        if geographic and equal_area:
            edges = {"fixed": domain_fixed(crs, work.crs)}
        res = smooth_coverage(
            work,
            method=method,
            iterations=iterations,
            alpha=alpha,
            snap=snap,
            make_valid=make_valid,
            full_output=True,
            keep_angle=keep_angle,
            max_shift=budget,
            min_segment=min_segment,
            **edges,
        )
        n_red, invalid, valid = len(res.reductions), res.invalid_edges, res.coverage_valid
        out, change = res.geometry, float(res.max_area_change)
        snap_change = float(res.snap_area_change)
        if equal_area:
            out = out.to_crs(crs)
    else:
        if snap is not None:
            raise CurveError("snap applies to coverage mode only (coverage=True)")
        options = {"method": method, "iterations": iterations, "alpha": alpha}
        for key, value in (
            ("keep_angle", keep_angle),
            ("max_shift", max_shift),
            ("min_segment", min_segment),
        ):
            if value is not None:
                options[key] = value
        if equal_area:
            out, n_red, change, planar = _smooth_equal_area(df, make_valid=make_valid, **options)
        else:
            res = smooth(df, make_valid=make_valid, full_output=True, **options, **edges)
            out, n_red, change = res.geometry, len(res.reductions), float(res.max_area_change)
            n_unchanged = res.n_unchanged
        invalid, valid = {}, None
    if geographic:
        out = out.copy()
        out.geometry = clamp_to_domain(out.geometry, str(in_path), df.geometry)
    out = put_points_back(out, kept, points)
    del df, kept  # the input's geometries are not needed while the output is written
    _write_file(out, out_path, layer=out_layer, fids=ids)
    return FileSmoothReport(
        n_features=len(out),
        crs=None if crs is None else crs.to_string(),
        geographic=geographic,
        equal_area=bool(equal_area) or in_equal_area,
        coverage=bool(coverage),
        n_reductions=n_red,
        invalid_edges=dict(invalid),
        max_area_change=change,
        coverage_valid=valid,
        n_null=n_null,
        n_empty=n_empty,
        not_equal_area=tuple(planar),
        n_points=int(points.sum()),
        n_unchanged=n_unchanged,
        snap_area_change=snap_change,
    )


@dataclass(frozen=True)
class ValidityReport:
    """What :func:`keep_polygons_valid` found and did.

    Attributes
    ----------
    n_polygons : int
        Polygons checked (one per (feature, member) of polygon rings, one per other
        closed curve).
    resmoothed : tuple of int
        Features whose polygon was invalid after ring-by-ring smoothing and was smoothed
        again by :func:`curvesmith.geo.smooth` (conflicting pieces smoothed less): valid now.
    invalid_input : tuple of (int, str)
        Features whose polygon was already invalid in the input (feature, shapely's reason):
        smoothed ring by ring, validity cannot be promised.
    still_invalid : tuple of (int, str)
        Features still invalid after all (a method that :func:`curvesmith.geo.smooth` does
        not have, fixed anchors, or 3D rings).
    """

    n_polygons: int
    resmoothed: tuple[int, ...]
    invalid_input: tuple[tuple[int, str], ...]
    still_invalid: tuple[tuple[int, str], ...]


def _polygon_groups(curves) -> list[list[int]]:
    """Curve indices of each polygon: by (feature, member), other closed curves alone."""
    groups: dict[tuple, list[int]] = {}
    for i, c in enumerate(curves):
        if c.kind in ("Polygon", "MultiPolygon"):
            groups.setdefault((c.feature, c.member), []).append(i)
        elif c.closed:
            groups[("ring", i)] = [i]
    return list(groups.values())


def _polygon_of(curves, idx: list[int]):
    import shapely

    parts: dict[int, dict[int, np.ndarray]] = {}
    for i in idx:
        c = curves[i]
        parts.setdefault(c.part, {})[c.ring] = c.points[:, :2]
    polys = []
    for part in sorted(parts):
        rings = parts[part]
        if 0 not in rings:
            return None
        holes = [rings[r] for r in sorted(rings) if r != 0]
        polys.append(shapely.Polygon(rings[0], holes))
    kind = curves[idx[0]].kind
    return shapely.MultiPolygon(polys) if kind == "MultiPolygon" else polys[0]


def _rings_of(geom) -> dict[tuple[int, int], np.ndarray]:
    import shapely

    polys = list(geom.geoms) if geom.geom_type == "MultiPolygon" else [geom]
    out = {}
    for p, poly in enumerate(polys):
        for r, ring in enumerate([poly.exterior, *poly.interiors]):
            out[(p, r)] = shapely.get_coordinates(ring)[:-1]
    return out


def invalid_polygons(curves) -> list[tuple[int, str]]:
    """The Polygon and MultiPolygon features of `curves` that are not valid: (feature, reason).

    What :func:`curvesmith.geo.smooth` refuses without ``make_valid``, for the curves of a
    GeoJSON file read ring by ring (closed curves of other kinds are not polygons).
    """
    shapely = require("shapely", "geo", "checking the validity of polygons")
    groups = [
        g
        for g in _polygon_groups(curves)
        if curves[g[0]].kind in ("Polygon", "MultiPolygon") and all(curves[i].dim == 2 for i in g)
    ]
    polys = [_polygon_of(curves, g) for g in groups]
    known = [k for k, p in enumerate(polys) if p is not None]
    valid = shapely.is_valid(np.array([polys[k] for k in known], dtype=object))
    return [
        (curves[groups[k][0]].feature, shapely.is_valid_reason(polys[k]))
        for k, ok in zip(known, valid, strict=True)
        if not ok
    ]


def keep_polygons_valid(
    before, after, *, method: str, iterations: int, alpha: Any = "regular", fixable: bool = True
):
    """Check the polygons of curves smoothed ring by ring; re-smooth the invalid ones.

    Ring-by-ring smoothing (the CSV, GeoJSON and SVG path of ``curvesmith smooth``) knows
    nothing of a polygon's other rings: a smoothed hole can cross its shell, two parts can
    overlap, a narrow ring can cross itself (8 of the 3,233 US counties as GeoJSON with one
    CCA iteration). Every polygon of `after` whose input in `before` was valid is checked
    with shapely; an invalid one is smoothed again from `before` with
    :func:`curvesmith.geo.smooth`, which smooths the conflicting pieces less and keeps the
    areas exactly.

    Parameters
    ----------
    before, after : list of Curve
        The curves before and after smoothing (same length, same structure).
    method, iterations, alpha
        The smoothing that made `after` (``method`` ``"cca"`` or ``"chaikin"`` can be redone
        by :func:`curvesmith.geo.smooth`).
    fixable : bool, optional
        False when `after` used options that :func:`curvesmith.geo.smooth` has not (fixed
        anchors): invalid polygons are then only reported.

    Returns
    -------
    curves : list of Curve
        `after`, with the re-smoothed polygons replaced.
    report : ValidityReport
    """
    shapely = require("shapely", "geo", "checking the validity of smoothed polygons")
    from ._smooth import smooth

    out = list(after)
    groups = [g for g in _polygon_groups(after) if all(after[i].dim == 2 for i in g)]
    polys_in = [_polygon_of(before, g) for g in groups]
    polys_out = [_polygon_of(after, g) for g in groups]
    known = [k for k, p in enumerate(polys_out) if p is not None and polys_in[k] is not None]
    valid_out = shapely.is_valid(np.array([polys_out[k] for k in known], dtype=object))
    resmoothed, invalid_input, still = [], [], []
    for k, ok in zip(known, valid_out, strict=True):
        if ok:
            continue
        idx = groups[k]
        feature = after[idx[0]].feature
        if not shapely.is_valid(polys_in[k]):
            invalid_input.append((feature, shapely.is_valid_reason(polys_in[k])))
            continue
        reason = shapely.is_valid_reason(polys_out[k])
        gis = methods.as_gis(method)
        if not fixable or gis is None:
            still.append((feature, reason))
            continue
        redo = smooth(polys_in[k], method=gis, iterations=iterations, alpha=alpha)
        rings = _rings_of(redo)
        if not shapely.is_valid(redo) or set(rings) != {
            (after[i].part, after[i].ring) for i in idx
        }:
            still.append((feature, reason))
            continue
        for i in idx:
            out[i] = after[i].replace(rings[(after[i].part, after[i].ring)])
        resmoothed.append(feature)
    report = ValidityReport(len(known), tuple(resmoothed), tuple(invalid_input), tuple(still))
    return out, report


@dataclass(frozen=True)
class CurveTable:
    """The lines and rings of a layer as one ragged batch (see :func:`curve_table`).

    Attributes
    ----------
    coords : (N, 3) float64 ndarray
        Vertices of all curves, in order; z = 0 for planar curves. A closed curve's
        repeated closing vertex is dropped (as :class:`curvesmith.io.Curve` drops it).
    offsets : (K + 1,) int64 ndarray
        Curve ``k`` is ``coords[offsets[k]:offsets[k + 1]]``.
    closed : (K,) bool ndarray
        Rings, and LineStrings of 4 or more vertices that end where they start.
    dims : (K,) int64 ndarray
        2, or 3 for curves with z.
    feature, part, ring : (K,) int64 ndarray
        The feature's position in the layer, the part of a Multi geometry, the ring of a
        polygon (0 the exterior, k the k-th hole).
    member : (K,) int64 ndarray
        The member of a GeometryCollection, -1 for none.
    kind : (K,) object ndarray
        The geometry type the curve belongs to (``"MultiPolygon"``, ...).
    n_features : int
        Features of the layer.
    n_without : int
        Features without curves (NULL, empty, Point, MultiPoint, ...).
    """

    coords: np.ndarray
    offsets: np.ndarray
    closed: np.ndarray
    dims: np.ndarray
    feature: np.ndarray
    part: np.ndarray
    ring: np.ndarray
    member: np.ndarray
    kind: np.ndarray
    n_features: int
    n_without: int


def _positions(groups: np.ndarray) -> np.ndarray:
    """Position of each element within its run of equal (sorted) group numbers."""
    if len(groups) == 0:
        return np.zeros(0, dtype=np.int64)
    return np.arange(len(groups), dtype=np.int64) - np.searchsorted(groups, groups, "left")


def curve_table(df: Any, *, name: str = "the layer") -> CurveTable:
    """The lines and rings of a GeoDataFrame (or geometry array) as a ragged batch.

    What ``curvesmith measure`` measures, in file order: per feature its lines (a
    MultiLineString's parts), or its polygons' rings, exterior first (a MultiPolygon's
    parts in order), or the same for each member of a GeometryCollection, as
    :mod:`curvesmith.io`'s GeoJSON model numbers them. NULL, empty and point geometries
    (and LinearRings, nested collections) give no curves; the empty parts of a Multi
    geometry give none either, but keep their number. Made by shapely's array functions,
    without a Python call per ring (a layer of 400,000 footprints in about a second).

    Raises
    ------
    CurveError
        A curve with a coordinate that is not finite (NaN or inf), naming its feature.
    """
    shapely = require("shapely", "geo", "reading GIS files")
    geoms = np.asarray(getattr(df, "geometry", df).values if hasattr(df, "geometry") else df,
                       dtype=object)  # fmt: skip
    T = shapely.GeometryType
    types = shapely.get_type_id(geoms)
    # the geometries that may hold curves: the features', and the members of collections
    top = np.flatnonzero(np.isin(types, (T.LINESTRING, T.POLYGON, T.MULTILINESTRING,
                                         T.MULTIPOLYGON)))  # fmt: skip
    gc = np.flatnonzero(types == T.GEOMETRYCOLLECTION)
    members, at = shapely.get_parts(geoms[gc], return_index=True)
    item_geom = np.concatenate([geoms[top], members])
    item_feature = np.concatenate([top, gc[at]]).astype(np.int64)
    item_member = np.concatenate([np.full(len(top), -1), _positions(at)]).astype(np.int64)
    item_type = shapely.get_type_id(item_geom)
    fill = ~shapely.is_empty(item_geom) & np.isin(
        item_type, (T.LINESTRING, T.POLYGON, T.MULTILINESTRING, T.MULTIPOLYGON)
    )  # a collection's nested collections, points and empties hold none
    order = np.flatnonzero(fill)
    order = order[np.lexsort((item_member[order], item_feature[order]))]
    item_geom, item_type = item_geom[order], item_type[order]
    item_feature, item_member = item_feature[order], item_member[order]
    item = np.arange(len(order), dtype=np.int64)

    # parts: a Polygon (LineString) is its own part 0; the parts of Multi geometries
    single = np.isin(item_type, (T.LINESTRING, T.POLYGON))
    multi = np.flatnonzero(~single)
    parts, of = shapely.get_parts(item_geom[multi], return_index=True)
    part_geom = np.concatenate([item_geom[single], parts])
    part_item = np.concatenate([item[single], multi[of]])
    part_no = np.concatenate([np.zeros(int(single.sum()), dtype=np.int64), _positions(of)])
    full = ~shapely.is_empty(part_geom)
    part_geom, part_item, part_no = part_geom[full], part_item[full], part_no[full]
    is_poly = np.isin(item_type[part_item], (T.POLYGON, T.MULTIPOLYGON))

    # curves: the lines, and the rings of the polygons (exterior first)
    rings, of = shapely.get_rings(part_geom[is_poly], return_index=True)
    line_idx = np.flatnonzero(~is_poly)
    poly_idx = np.flatnonzero(is_poly)
    curve_geom = np.concatenate([part_geom[line_idx], rings])
    curve_part = np.concatenate([line_idx, poly_idx[of]])  # into the parts
    curve_ring = np.concatenate([np.zeros(len(line_idx), dtype=np.int64), _positions(of)])
    full = ~shapely.is_empty(curve_geom)
    curve_geom, curve_part, curve_ring = curve_geom[full], curve_part[full], curve_ring[full]
    c_item = part_item[curve_part]
    sort = np.lexsort((curve_ring, part_no[curve_part], c_item))
    curve_geom, curve_part, curve_ring = curve_geom[sort], curve_part[sort], curve_ring[sort]
    c_item = c_item[sort]

    coords, idx = shapely.get_coordinates(curve_geom, include_z=True, return_index=True)
    k = len(curve_geom)
    n = np.bincount(idx, minlength=k).astype(np.int64)
    offsets = np.concatenate([[0], np.cumsum(n)]).astype(np.int64)
    dims = np.where(shapely.has_z(curve_geom), 3, 2).astype(np.int64)
    flat = dims[idx] == 2
    coords[flat, 2] = 0.0
    first, last = offsets[:-1], offsets[1:] - 1
    ends_equal = np.all(coords[first] == coords[last], axis=1) if k else np.zeros(0, bool)
    ring = ~np.isin(item_type[c_item], (T.LINESTRING, T.MULTILINESTRING))
    closed = ring | ((n >= 4) & ends_equal)
    bad = ~np.isfinite(coords).all(axis=1)
    if bad.any():
        row = int(np.flatnonzero(bad)[0])
        raise CurveError(
            f"{name}: feature {int(item_feature[c_item[idx[row]]])} has a coordinate that is "
            f"not finite: {coords[row, : dims[idx[row]]].tolist()}"
        )
    drop = closed & ends_equal  # the repeated closing vertex
    if drop.any():
        keep = np.ones(len(coords), dtype=bool)
        keep[last[drop]] = False
        coords = coords[keep]
        offsets = np.concatenate([[0], np.cumsum(n - drop)]).astype(np.int64)
    names = np.array([_TYPE_NAMES.get(int(t), "") for t in range(8)], dtype=object)
    feature = item_feature[c_item]
    return CurveTable(
        coords=np.ascontiguousarray(coords),
        offsets=offsets,
        closed=closed,
        dims=dims,
        feature=feature,
        part=part_no[curve_part],
        ring=curve_ring,
        member=item_member[c_item],
        kind=names[item_type[c_item]],
        n_features=len(geoms),
        n_without=len(geoms) - len(np.unique(feature)),
    )
