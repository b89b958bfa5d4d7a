"""GIS files in and out (GeoPackage, Shapefile, GeoJSON, FlatGeobuf) through pyogrio."""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import CurveError, CurveFormatError, require

__all__ = [
    "DRIVERS",
    "FileSmoothReport",
    "GeographicCRSWarning",
    "equal_area_crs",
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


def _driver_for(path: Path) -> str:
    driver = DRIVERS.get(path.suffix.lower())
    if driver is None:
        raise CurveFormatError(
            f"cannot tell the format of {str(path)!r} from its suffix; use one of "
            f"{', '.join(sorted(DRIVERS))}"
        )
    return driver


def read_file(path: str | Path, *, layer: str | int | None = None):
    """Read a GeoPackage, Shapefile, GeoJSON or FlatGeobuf layer into a GeoDataFrame.

    Parameters
    ----------
    path : str or Path
        The file.
    layer : str or int, optional
        Layer name or index (GeoPackages may hold several); default the first.

    Returns
    -------
    geopandas.GeoDataFrame
        The features in file order, with their attributes and CRS.

    Raises
    ------
    CurveFormatError
        Missing file, unreadable file, or unknown layer (the message lists the layers).
    """
    pyogrio = require("pyogrio", "geo", "reading GIS files")
    path = Path(path)
    if not path.exists():
        raise CurveFormatError(f"no such file: {str(path)!r}")
    try:
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
    try:
        return pyogrio.read_dataframe(path, layer=layer)
    except Exception as exc:
        raise CurveFormatError(f"cannot read {str(path)!r}: {exc}") from exc


def write_file(df: Any, path: str | Path, *, layer: str | None = None) -> None:
    """Write a GeoDataFrame; the format follows the suffix (see :data:`DRIVERS`).

    Features keep their order (FlatGeobuf is written without its spatial index, which
    would sort them). Shapefiles hold one geometry type per file: Polygons and MultiPolygons (or
    LineStrings and MultiLineStrings) are written as the Multi type; other mixes raise
    :class:`CurveFormatError`. An existing file is replaced.
    """
    pyogrio = require("pyogrio", "geo", "writing GIS files")
    shapely = require("shapely", "geo", "writing GIS files")
    path = Path(path)
    driver = _driver_for(path)
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
    if path.exists() and driver != "GPKG":
        path.unlink()
    try:
        pyogrio.write_dataframe(df, path, layer=layer, driver=driver, **kwargs)
    except Exception as exc:
        raise CurveFormatError(f"cannot write {str(path)!r}: {exc}") from exc


def equal_area_crs(df: Any) -> str:
    """A Lambert azimuthal equal-area projection centred on the data (PROJ string).

    Areas measured in it are ground areas on the WGS84 ellipsoid (to the datum shift),
    so smoothing there keeps true areas.
    """
    require("pyproj", "geo", "equal-area smoothing")
    x0, y0, x1, y1 = df.to_crs("EPSG:4326").total_bounds
    lon, lat = (x0 + x1) / 2.0, (y0 + y1) / 2.0
    return f"+proj=laea +lat_0={lat:.6f} +lon_0={lon:.6f} +datum=WGS84 +units=m +no_defs"


def smooth_file(
    in_path: str | Path,
    out_path: str | Path,
    *,
    method: str = "cca",
    iterations: int = 1,
    alpha: Any = "regular",
    coverage: bool = False,
    layer: str | int | None = None,
    out_layer: str | None = None,
    equal_area: bool = False,
    make_valid: bool = False,
    snap: float | None = None,
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
        Output layer name (GeoPackage); default the input layer's name.
    equal_area : bool
        Smooth in an equal-area projection (:func:`equal_area_crs`) and transform back,
        so that ground areas, not areas in degrees, are the ones kept. Needs a CRS.
    snap : float, optional
        Coverage mode: snapping distance for :func:`shapely.coverage_clean`.

    Returns
    -------
    FileSmoothReport

    Warns
    -----
    GeographicCRSWarning
        When the data are in a geographic CRS and ``equal_area`` is off.
    """
    from ._coverage import smooth_coverage
    from ._smooth import smooth

    df = read_file(in_path, layer=layer)
    crs = df.crs
    geographic = bool(crs is not None and crs.is_geographic)
    if equal_area and crs is None:
        raise CurveError(f"equal_area needs a CRS, but {str(in_path)!r} has none")
    if geographic and not equal_area:
        warnings.warn(
            f"{str(in_path)!r} is in a geographic CRS ({crs.name}): smoothing keeps planar "
            f"areas in degrees, not ground areas; use equal_area=True (--equal-area) to "
            f"smooth in an equal-area projection",
            GeographicCRSWarning,
            stacklevel=2,
        )
    work = df
    if equal_area:
        work = df.to_crs(equal_area_crs(df))
    if coverage:
        res = smooth_coverage(
            work,
            method=method,
            iterations=iterations,
            alpha=alpha,
            snap=snap,
            make_valid=make_valid,
            full_output=True,
        )
        n_red, invalid, valid = len(res.reductions), res.invalid_edges, res.coverage_valid
    else:
        if snap is not None:
            raise CurveError("snap applies to coverage mode only (coverage=True)")
        res = smooth(
            work,
            method=method,
            iterations=iterations,
            alpha=alpha,
            make_valid=make_valid,
            full_output=True,
        )
        n_red, invalid, valid = len(res.reductions), {}, None
    out = res.geometry
    if equal_area:
        out = out.to_crs(crs)
    if out_layer is None and layer is not None and not isinstance(layer, int | np.integer):
        out_layer = str(layer)
    write_file(out, out_path, layer=out_layer)
    return FileSmoothReport(
        n_features=len(out),
        crs=None if crs is None else crs.to_string(),
        geographic=geographic,
        equal_area=bool(equal_area),
        coverage=bool(coverage),
        n_reductions=n_red,
        invalid_edges=dict(invalid),
        max_area_change=float(res.max_area_change),
        coverage_valid=valid,
    )
