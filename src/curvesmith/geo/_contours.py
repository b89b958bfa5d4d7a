"""Contour lines and isobands of a grid, smoothed so that no two levels ever touch.

The isolines come from contourpy (marching squares, the generator behind matplotlib's
``contour``); they are smoothed together as one line network
(:func:`curvesmith.geo.smooth_network`), so lines of different levels, which never meet in
the input, never meet after smoothing either, and every line keeps the area between itself
and its input (closed lines their enclosed area). Isobands are smoothed as a polygon coverage
(:func:`curvesmith.geo.smooth_coverage`): each band keeps its area and neighbouring bands
share their smoothed borders, without gaps or overlaps.

Grids are read from GeoTIFF (rasterio, extra ``raster``), ``.npy``, ``.npz`` and ESRI ASCII
grids (``.asc``) by :func:`read_grid`.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from .._rich import RichRepr
from ..errors import CurveError, CurveFormatError, require
from ..methods import GisMethod

__all__ = ["ContourResult", "Grid", "contours", "read_grid"]

#: Suffixes :func:`read_grid` understands.
GRID_SUFFIXES = (".tif", ".tiff", ".npy", ".npz", ".asc")


@dataclass(frozen=True)
class Grid:
    """A regular grid of values.

    Attributes
    ----------
    z : (ny, nx) ndarray
        Values, float64, NaN where there is no data.
    x : (nx,) ndarray
        Coordinates of the columns (cell centres), increasing or decreasing.
    y : (ny,) ndarray
        Coordinates of the rows.
    crs : str or None
        Coordinate reference system (WKT or authority string) when the file has one.
    """

    z: np.ndarray
    x: np.ndarray
    y: np.ndarray
    crs: str | None = None


@dataclass(frozen=True)
class ContourResult(RichRepr):
    """Result of :func:`contours` with ``full_output=True``.

    Attributes
    ----------
    geometry : geopandas.GeoDataFrame
        One LineString per contour line with its ``level`` (lines), or one (Multi)Polygon
        per band with its ``lower`` and ``upper`` level (bands).
    levels : (K,) ndarray
        The contour levels used.
    smoothing : NetworkResult or CoverageResult
        What the network / coverage smoothing reported (reductions, area checks).
    """

    geometry: Any
    levels: np.ndarray
    smoothing: Any


def _npz_grid(data) -> Grid:
    names = list(data.files)
    two_d = [k for k in names if np.ndim(data[k]) == 2]
    for key in ("z", "elevation", "topo", "data", "values"):
        if key in two_d:
            break
    else:
        if len(two_d) != 1:
            raise CurveFormatError(
                f"cannot tell which array of the .npz file is the grid; arrays {names}: name "
                f"it 'z' (with optional 1-D 'x' and 'y')"
            )
        key = two_d[0]
    z = np.asarray(data[key], dtype=float)
    ny, nx = z.shape
    x = y = None
    for kx, ky in (("x", "y"), ("lon", "lat"), ("longitude", "latitude")):
        if kx in names and ky in names and np.ndim(data[kx]) == 1 and np.ndim(data[ky]) == 1:
            x, y = np.asarray(data[kx], float), np.asarray(data[ky], float)
            break
    if x is None and all(k in names for k in ("xmin", "xmax", "ymin", "ymax")):
        # matplotlib's jacksboro_fault_dem.npz: row 0 at "ymin" (its northern edge)
        x = np.linspace(float(data["xmin"]), float(data["xmax"]), nx)
        y = np.linspace(float(data["ymin"]), float(data["ymax"]), ny)
    if x is None:
        x, y = np.arange(nx, dtype=float), np.arange(ny, dtype=float)
    assert y is not None  # set with x
    return Grid(z, x, y, None)


def _asc_grid(path: Path) -> Grid:
    header: dict[str, float] = {}
    with path.open("r", encoding="ascii", errors="replace") as fh:
        for _ in range(6):
            pos = fh.tell()
            line = fh.readline()
            parts = line.split()
            if len(parts) != 2 or parts[0][0].isdigit() or parts[0][0] in "-+.":
                fh.seek(pos)
                break
            try:
                header[parts[0].lower()] = float(parts[1])
            except ValueError:
                raise CurveFormatError(f"{str(path)!r}: bad header line {line.strip()!r}") from None
        try:
            values = np.loadtxt(fh, dtype=float, ndmin=2)
        except ValueError as exc:
            raise CurveFormatError(f"{str(path)!r}: bad grid values ({exc})") from None
    need = ("ncols", "nrows", "cellsize")
    missing = [k for k in need if k not in header]
    if missing or not ({"xllcorner", "xllcenter"} & header.keys()):
        raise CurveFormatError(
            f"{str(path)!r} is not an ESRI ASCII grid: header needs ncols, nrows, "
            f"xllcorner/xllcenter, yllcorner/yllcenter and cellsize, got {sorted(header)}"
        )
    nx, ny, cell = int(header["ncols"]), int(header["nrows"]), header["cellsize"]
    if values.shape != (ny, nx):
        raise CurveFormatError(
            f"{str(path)!r}: header says {ny} rows x {nx} columns, data has shape {values.shape}"
        )
    half = 0.5 * cell if "xllcorner" in header else 0.0
    x0 = header.get("xllcorner", header.get("xllcenter", 0.0)) + half
    y0 = header.get("yllcorner", header.get("yllcenter", 0.0)) + half
    x = x0 + cell * np.arange(nx)
    y = y0 + cell * np.arange(ny)[::-1]  # the first data row is the northern one
    if "nodata_value" in header:
        values = np.where(values == header["nodata_value"], np.nan, values)
    return Grid(values, x, y, None)


def _tif_grid(path: Path, band: int) -> Grid:
    rasterio = require("rasterio", "raster", "reading GeoTIFF grids")
    try:
        with rasterio.open(path) as src:
            if not 1 <= band <= src.count:
                raise CurveError(f"band must be in [1, {src.count}], got {band}")
            z = src.read(band, masked=True).astype(float).filled(np.nan)
            t = src.transform
            crs = None if src.crs is None else src.crs.to_string()
    except rasterio.errors.RasterioIOError as exc:
        raise CurveFormatError(f"cannot read {str(path)!r}: {exc}") from None
    if t.b != 0 or t.d != 0:
        raise CurveFormatError(f"{str(path)!r} has a rotated geotransform; warp it first")
    ny, nx = z.shape
    x = t.c + t.a * (np.arange(nx) + 0.5)
    y = t.f + t.e * (np.arange(ny) + 0.5)
    return Grid(z, x, y, crs)


def read_grid(path: str | Path, *, band: int = 1) -> Grid:
    """Read a grid: GeoTIFF (extra ``raster``), ``.npy``, ``.npz`` or ESRI ASCII ``.asc``.

    Parameters
    ----------
    path : str or Path
        The file. A ``.npy`` holds the 2-D array (coordinates: column and row numbers); a
        ``.npz`` a 2-D array named ``z`` (or ``elevation``/``topo``, or its only 2-D array)
        with optional 1-D ``x``/``y`` (or ``lon``/``lat``, or ``xmin``, ``xmax``, ``ymin``,
        ``ymax`` as in matplotlib's sample DEM); GeoTIFF and ASCII grids give cell centres
        from their georeferencing, no-data cells become NaN.
    band : int
        GeoTIFF band (1-based).

    Returns
    -------
    Grid
    """
    path = Path(path)
    if not path.exists():
        raise CurveFormatError(f"no such file: {str(path)!r}")
    suffix = path.suffix.lower()
    if suffix in (".tif", ".tiff"):
        return _tif_grid(path, int(band))
    if suffix == ".asc":
        return _asc_grid(path)
    if suffix in (".npy", ".npz"):
        try:
            data = np.load(path, allow_pickle=False)
        except (ValueError, OSError) as exc:
            raise CurveFormatError(f"cannot read {str(path)!r}: {exc}") from None
        if suffix == ".npz":
            return _npz_grid(data)
        z = np.asarray(data, dtype=float)
        if z.ndim != 2:
            raise CurveFormatError(f"{str(path)!r} holds an array of shape {z.shape}, not 2-D")
        return Grid(z, np.arange(z.shape[1], dtype=float), np.arange(z.shape[0], dtype=float))
    raise CurveFormatError(
        f"cannot tell the grid format of {str(path)!r}; use one of {', '.join(GRID_SUFFIXES)}"
    )


def _axis(v, n: int, name: str) -> np.ndarray:
    if v is None:
        return np.arange(n, dtype=float)
    a = np.asarray(v, dtype=float)
    if a.shape != (n,):
        raise CurveError(f"{name} must have shape ({n},) to match z, got {a.shape}")
    d = np.diff(a)
    if not np.isfinite(a).all() or not (np.all(d > 0) or np.all(d < 0)):
        raise CurveError(f"{name} must be finite and strictly monotonic")
    return a


def _frame(polys: np.ndarray, xs: np.ndarray, ys: np.ndarray, *, pad: float) -> np.ndarray:
    """Four trapezoids around the grid's rectangle, edge-matched with the bands along it.

    Added to the band coverage while it is smoothed, they make the rectangle's corners
    nodes of the coverage, so that the straight sides between nodes stay straight and the
    corners stay where they are; they are dropped afterwards.
    """
    shapely = require("shapely", "geo", "contours")
    x0, x1 = float(min(xs[0], xs[-1])), float(max(xs[0], xs[-1]))
    y0, y1 = float(min(ys[0], ys[-1])), float(max(ys[0], ys[-1]))
    c = np.unique(shapely.get_coordinates(polys), axis=0)
    tol = 1e-9 * pad  # contourpy's boundary points are on the sides up to round-off

    def side(axis: int, value: float, lo: float, hi: float) -> np.ndarray:
        # the bands' own vertices on this side, exactly as they are, sorted along it
        pts = c[np.abs(c[:, 1 - axis] - value) <= tol]
        corners = np.zeros((2, 2))
        corners[:, axis] = lo, hi
        corners[:, 1 - axis] = value
        for q in corners:
            if not len(pts) or np.abs(pts - q).max(axis=1).min() > tol:
                pts = np.vstack([pts, q])
        return pts[np.argsort(pts[:, axis], kind="stable")]

    bottom = side(0, y0, x0, x1)
    top = side(0, y1, x0, x1)[::-1]
    left = side(1, x0, y0, y1)[::-1]
    right = side(1, x1, y0, y1)
    # consecutive sides share their corner vertex exactly
    right[0], top[0], left[0] = bottom[-1], right[-1], top[-1]
    a, b = (x0 - pad, y0 - pad), (x1 + pad, y0 - pad)
    d, e = (x1 + pad, y1 + pad), (x0 - pad, y1 + pad)
    return np.array(
        [
            shapely.Polygon(np.vstack([bottom, [b, a]])),
            shapely.Polygon(np.vstack([right, [d, b]])),
            shapely.Polygon(np.vstack([top, [e, d]])),
            shapely.Polygon(np.vstack([left[:-1], bottom[:1], [a, e]])),
        ],
        dtype=object,
    )


def contour_levels(z: np.ndarray, *, levels: Any = None, interval: float | None = None):
    """The levels strictly between the grid's minimum and maximum.

    ``levels`` explicit, else multiples of ``interval``, else about ten "nice" levels
    (:class:`matplotlib.ticker.MaxNLocator`, as matplotlib's ``contour`` chooses them).
    """
    zmin, zmax = float(np.nanmin(z)), float(np.nanmax(z))
    if levels is not None and interval is not None:
        raise CurveError("give levels or interval, not both")
    if levels is not None:
        lv = np.unique(np.asarray(levels, dtype=float).ravel())
        if not np.isfinite(lv).all():
            raise CurveError(f"levels must be finite, got {levels!r}")
    elif interval is not None:
        step = float(interval)
        if not (np.isfinite(step) and step > 0):
            raise CurveError(f"interval must be > 0, got {interval!r}")
        k0, k1 = np.ceil(zmin / step), np.floor(zmax / step)
        if k1 - k0 > 10000:
            raise CurveError(
                f"interval {step} gives {int(k1 - k0) + 1} levels over [{zmin}, {zmax}]; "
                f"choose a larger one"
            )
        lv = np.arange(k0, k1 + 1) * step
    else:
        from matplotlib.ticker import MaxNLocator

        lv = np.asarray(MaxNLocator(10).tick_values(zmin, zmax), dtype=float)
    return lv[(lv > zmin) & (lv < zmax)]


def contours(
    z: Any,
    *,
    x: Any = None,
    y: Any = None,
    levels: Any = None,
    interval: float | None = None,
    bands: bool = False,
    method: GisMethod = "cca",
    iterations: int = 1,
    alpha: Any = "regular",
    crs: Any = None,
    full_output: bool = False,
    max_shift: float | None = None,
    min_segment: float | None = None,
) -> Any:
    """Contour lines (or isobands) of a grid, smoothed without any two levels touching.

    Parameters
    ----------
    z : (ny, nx) array_like or Grid
        Grid values (NaN: no data). A :class:`Grid` (from :func:`read_grid`) brings its
        coordinates and CRS.
    x : (nx,) array_like, optional
        Column coordinates (default 0, 1, ...).
    y : (ny,) array_like, optional
        Row coordinates (default 0, 1, ...).
    levels : sequence of float, optional
        Contour levels; only those strictly between the grid's minimum and maximum are
        used.
    interval : float, optional
        Levels at every multiple of ``interval`` instead. Default (neither): about ten
        "nice" levels, as matplotlib's ``contour`` picks them.
    bands : bool
        Return isobands (polygons between consecutive levels, the first from the minimum
        and the last up to the maximum), smoothed as a coverage, instead of lines.
    method : {"cca", "chaikin"}
        Smoothing method (``"cca"`` keeps the areas exactly).
    iterations : int
        Smoothing passes (0: the raw marching-squares output).
    alpha : "regular", float or callable
        CCA cut ratio.
    crs : optional
        CRS of the output (default: the grid's).
    full_output : bool
        Return a :class:`ContourResult` with the smoothing report.
    max_shift, min_segment : float, optional
        Strength and vertex budget in the grid's coordinate units, arc by arc (see
        :func:`curvesmith.geo.smooth_network`; for bands
        :func:`curvesmith.geo.smooth_coverage`): no line or band border moves farther than
        `max_shift`, and smoothing adds at most one vertex per `min_segment`.

    Returns
    -------
    geopandas.GeoDataFrame or ContourResult
        Lines: one LineString per contour line, column ``level``. Bands: one Polygon or
        MultiPolygon per band, columns ``lower`` and ``upper``.

    Notes
    -----
    Grid values exactly equal to a level are treated as lying a hair above it
    (``1e-9`` of the value range), as GDAL's contour generator does, so that contour lines
    never run through grid points and lines of one level never touch at a saddle; closed
    lines narrower than a thousandth of a cell (the trace of a lone grid point exactly on a
    level) are dropped. Band polygons are computed by contourpy with the shared borders
    rounded independently (they differ by round-off), so they are first snapped together by
    :func:`shapely.coverage_clean` with a distance of ``1e-6`` of a cell. While the bands are
    smoothed, four frame polygons around the grid's rectangle make its corners nodes of the
    coverage, so that the outline of the grid stays exactly where it is.

    Examples
    --------
    >>> import numpy as np
    >>> from curvesmith import geo
    >>> yy, xx = np.mgrid[-2:2:41j, -2:2:41j]
    >>> z = np.exp(-(xx**2) - yy**2)
    >>> res = geo.contours(z, x=xx[0], y=yy[:, 0], levels=[0.25, 0.5], full_output=True)
    >>> list(res.geometry["level"]), bool(res.geometry.is_ring.all())
    ([0.25, 0.5], True)
    >>> res.smoothing.max_area_change < 1e-12
    True
    """
    contourpy = require("contourpy", "geo", "contours")
    gpd = require("geopandas", "geo", "contours")
    shapely = require("shapely", "geo", "contours")
    from ._coverage import smooth_coverage
    from ._network import smooth_network
    from ._smooth import check_method

    iterations = check_method(method, iterations, alpha)
    if isinstance(z, Grid):
        grid = z
        x = grid.x if x is None else x
        y = grid.y if y is None else y
        crs = grid.crs if crs is None else crs
        z = grid.z
    zz = np.array(z, dtype=float)
    if zz.ndim != 2 or min(zz.shape) < 2:
        raise CurveError(f"z must be a 2-D grid with at least 2 x 2 values, got {zz.shape}")
    finite = np.isfinite(zz)
    if not finite.any():
        raise CurveError("z has no finite values")
    if np.isinf(zz).any():
        raise CurveError("z must not contain infinite values (use NaN for no data)")
    ny, nx = zz.shape
    xs, ys = _axis(x, nx, "x"), _axis(y, ny, "y")
    lv = contour_levels(zz, levels=levels, interval=interval)
    zmin, zmax = float(np.nanmin(zz)), float(np.nanmax(zz))
    delta = 1e-9 * max(zmax - zmin, abs(zmax), 1e-300)
    on = np.isin(zz, lv)
    zz[on] += delta
    zm = np.ma.masked_invalid(zz)
    gen = contourpy.contour_generator(
        xs, ys, zm, name="serial", line_type="Separate", fill_type="OuterOffset"
    )
    cell = float(min(np.abs(np.diff(xs)).min(), np.abs(np.diff(ys)).min()))
    if not bands:
        geoms, lvl = [], []
        for level in lv:
            for line in gen.lines(float(level)):
                if len(line) < 2 or not np.any(line[1:] != line[:-1]):
                    continue
                if np.array_equal(line[0], line[-1]) and np.ptp(line, axis=0).max() < 1e-3 * cell:
                    continue
                geoms.append(shapely.LineString(line))
                lvl.append(float(level))
        df = gpd.GeoDataFrame({"level": lvl}, geometry=geoms, crs=crs)
        res = smooth_network(
            df,
            method=method,
            iterations=iterations,
            alpha=alpha,
            full_output=True,
            max_shift=max_shift,
            min_segment=min_segment,
        )
    else:
        edges = np.concatenate([[zmin - delta], lv, [zmax]])
        polys, lower, upper = [], [], []
        for k in range(len(edges) - 1):
            pts, offs = gen.filled(float(edges[k]), float(edges[k + 1]))
            parts = []
            for p, o in zip(pts, offs, strict=True):
                rings = [p[o[i] : o[i + 1]] for i in range(len(o) - 1)]
                parts.append(shapely.Polygon(rings[0], rings[1:]))
            if not parts:
                continue
            polys.append(parts[0] if len(parts) == 1 else shapely.MultiPolygon(parts))
            lower.append(zmin if k == 0 else float(edges[k]))
            upper.append(float(edges[k + 1]))
        g = shapely.remove_repeated_points(
            shapely.coverage_clean(np.array(polys, dtype=object), snapping_distance=1e-6 * cell),
            0.0,
        )
        g = np.concatenate([g, _frame(g, xs, ys, pad=cell)])
        full = smooth_coverage(
            g,
            method=method,
            iterations=iterations,
            alpha=alpha,
            make_valid=True,
            full_output=True,
            max_shift=max_shift,
            min_segment=min_segment,
        )
        nb = len(polys)
        df = gpd.GeoDataFrame(
            {"lower": lower, "upper": upper}, geometry=full.geometry[:nb], crs=crs
        )
        res = dataclasses.replace(
            full,
            geometry=df,
            reductions=tuple(
                dataclasses.replace(r, polygons=tuple(p for p in r.polygons if p < nb))
                for r in full.reductions
            ),
            invalid_edges={k: v for k, v in full.invalid_edges.items() if k < nb},
        )
    if full_output:
        return ContourResult(res.geometry, lv, res)
    return res.geometry
