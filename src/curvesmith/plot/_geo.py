"""Figures of GIS layers: geometries, before/after, area change, heights, terrain."""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike

from .._validate import as_choice
from ._core import _thin, new_axes

if TYPE_CHECKING:
    from matplotlib.axes import Axes


def _geometry_lines(geometry, most: int = 3000):
    import shapely

    values = getattr(geometry, "geometry", geometry)
    values = np.asarray(getattr(values, "values", values), dtype=object)
    values = values[[g is not None for g in values]]
    parts = shapely.get_parts(values)
    rings = shapely.get_rings(parts[shapely.get_type_id(parts) == shapely.GeometryType.POLYGON])
    lines = np.concatenate(
        [parts[shapely.get_type_id(parts) != shapely.GeometryType.POLYGON], rings]
    )
    lines = lines[~shapely.is_empty(lines)][:most]
    return [shapely.get_coordinates(g) for g in lines]


def _geometry_values(geometry: Any) -> np.ndarray:
    """The shapely geometries of a result, GeoDataFrame, GeoSeries, array, list or geometry."""
    values = geometry
    while (inner := getattr(values, "geometry", values)) is not values:  # result -> frame -> series
        values = inner
    import shapely

    values = getattr(values, "values", values)
    if values is None or isinstance(values, shapely.Geometry):
        values = [values]
    out = np.empty(len(values), dtype=object)
    out[:] = list(values)
    return out


def draw_geometries(
    ax: Axes,
    geometry: Any,
    *,
    window: Sequence[float] | None = None,
    label: str | None = None,
    **kw: Any,
) -> Axes:
    """Draw the boundaries of GIS geometries: polygon rings and lines, every part.

    Parameters
    ----------
    ax : matplotlib Axes
    geometry : shapely geometry, array or list of them, GeoSeries or GeoDataFrame
        Polygons (their exterior and interior rings are drawn), lines, Multi* and
        collections; None and empty geometries are skipped.
    window : (xmin, ymin, xmax, ymax), optional
        Draw only what lies inside (the lines are clipped, and the axes limited to it): a
        zoom on a layer of millions of vertices stays cheap.
    label : str, optional
        Legend label (given once for all the lines).
    **kw
        Line style passed to ``Axes.plot`` (``color``, ``lw``, ``ls``, ``marker``...).

    Returns
    -------
    matplotlib Axes

    Examples
    --------
    >>> import shapely
    >>> from curvesmith import plot
    >>> fig, (ax,) = plot.new_axes()
    >>> layer = [shapely.box(0, 0, 2, 1), shapely.LineString([(0, 2), (2, 2)])]
    >>> ax = plot.draw_geometries(ax, layer)
    >>> len(ax.lines)
    2
    """
    import shapely

    values = _geometry_values(geometry)
    values = values[[g is not None for g in values]]
    lines = shapely.boundary(values)
    mask = shapely.get_dimensions(values) == 1  # lines are their own drawing, not their ends
    lines[mask] = values[mask]
    if window is not None:
        x0, y0, x1, y1 = (float(v) for v in window)
        lines = shapely.intersection(lines, shapely.box(x0, y0, x1, y1))
        ax.set_xlim(x0, x1)
        ax.set_ylim(y0, y1)
    lines = lines[~shapely.is_empty(lines)]
    first = True
    for part in shapely.get_parts(shapely.get_parts(lines)):
        if shapely.get_type_id(part) == shapely.GeometryType.POINT:
            continue  # a clipped line touching the window in one point
        xy = _thin(shapely.get_coordinates(part))
        ax.plot(xy[:, 0], xy[:, 1], label=label if first else None, **kw)
        first = False
    ax.set_aspect("equal", adjustable="box")
    return ax


def layer_before_after(
    before: Any,
    after: Any,
    *,
    window: Sequence[float] | None = None,
    labels: Sequence[str] = ("input", "smoothed"),
    title: str | None = None,
    ax: Axes | None = None,
) -> Axes:
    """A GIS layer before (grey, wide) and after (blue) smoothing, whole or in a window.

    Parameters
    ----------
    before, after : geometries
        Anything :func:`draw_geometries` takes, e.g. the input GeoDataFrame and
        ``geo.smooth_coverage(...)``'s output.
    window : (xmin, ymin, xmax, ymax), optional
        A zoom (shared borders, junctions: where per-feature smoothing opens gaps).
    labels : (str, str)
        Legend labels.
    title : str, optional
    ax : matplotlib Axes, optional
        Target axes (a new figure otherwise).

    Returns
    -------
    matplotlib Axes

    Examples
    --------
    >>> import shapely
    >>> from curvesmith import geo, plot
    >>> grid = [shapely.box(i, j, i + 1, j + 1) for i in range(3) for j in range(2)]
    >>> ax = plot.layer_before_after(grid, geo.smooth_coverage(grid, iterations=2))
    >>> [t.get_text() for t in ax.get_legend().get_texts()]
    ['input', 'smoothed']
    """
    if ax is None:
        _, (ax,) = new_axes()
    zoom = window is not None
    draw_geometries(ax, before, window=window, label=labels[0], color="0.6", lw=2.5 if zoom else 1)
    draw_geometries(
        ax, after, window=window, label=labels[1], color="tab:blue", lw=1.2 if zoom else 0.6
    )
    if title:
        ax.set_title(title)
    ax.legend(loc="lower left", fontsize=8)
    return ax


def area_change(
    before: Any,
    after: Any,
    *,
    ax: Axes | None = None,
    title: str | None = None,
) -> Axes:
    """The distribution of the relative area change per polygon: the proof a GIS user asks for.

    A cumulative distribution of ``(A_after - A_before) / A_before`` in percent over the
    polygons of a layer, one line per result: CCA's is the vertical line at 0 (round-off),
    Chaikin's lies left of it (every polygon shrinks).

    Parameters
    ----------
    before : geometries
        The input polygons (what :func:`draw_geometries` takes).
    after : geometries, or dict of label to geometries
        One smoothed layer, or several to compare; feature by feature in the order of
        `before`.
    ax : matplotlib Axes, optional
    title : str, optional

    Returns
    -------
    matplotlib Axes

    Examples
    --------
    >>> import shapely
    >>> from curvesmith import geo, plot
    >>> grid = [shapely.box(i, 0, i + 1, 1) for i in range(4)]
    >>> runs = {"cca": geo.smooth(grid), "chaikin": geo.smooth(grid, method="chaikin")}
    >>> ax = plot.area_change(grid, runs)
    >>> [round(float(line.get_xdata().max()), 6) for line in ax.lines]
    [0.0, -12.5]
    """
    import shapely

    if ax is None:
        _, (ax,) = new_axes(width=7, height=4)
    a0 = shapely.area(_geometry_values(before))
    runs = after if isinstance(after, dict) else {"smoothed": after}
    for name, geoms in runs.items():
        a1 = shapely.area(_geometry_values(geoms))
        if a1.shape != a0.shape:
            from ..errors import CurveError

            raise CurveError(
                f"after[{name!r}] must have one geometry per input polygon ({a0.size}), "
                f"got {a1.size}"
            )
        ok = a0 > 0
        rel = np.sort((a1[ok] - a0[ok]) / a0[ok]) * 100.0
        ax.plot(rel, np.linspace(0, 1, rel.size), label=name)
    ax.set_xlabel("relative area change per polygon (%)")
    ax.set_ylabel("fraction of polygons")
    if title:
        ax.set_title(title)
    ax.legend()
    ax.grid(alpha=0.3)
    return ax


def _xyz_lines(geometry: Any, name: str) -> list[np.ndarray]:
    """The (N, 3) vertex arrays of lines with heights: an array, a list of them, or geometries."""
    from ..errors import CurveError

    if isinstance(geometry, np.ndarray) and geometry.dtype != object:
        arrays = [geometry]
    elif isinstance(geometry, (list, tuple)) and geometry and np.ndim(geometry[0]) == 2:
        arrays = [np.asarray(g, dtype=float) for g in geometry]
    else:
        import shapely

        parts = shapely.get_parts(_geometry_values(geometry))
        parts = parts[~shapely.is_empty(parts)]
        if not shapely.has_z(parts).all():
            raise CurveError(f"{name} must be lines with Z (heights), got 2D geometries")
        arrays = [shapely.get_coordinates(g, include_z=True) for g in parts]
    for k, a in enumerate(arrays):
        if a.ndim != 2 or a.shape[1] != 3:
            raise CurveError(f"{name}[{k}] must be (N, 3) x, y, z rows, got shape {a.shape}")
    return arrays


def z_profile(
    before: Any,
    after: Any,
    *,
    along: str = "x",
    labels: Sequence[str] = ("input", "smoothed"),
    ax: Axes | None = None,
    title: str | None = None,
) -> Axes:
    """Height profiles of lines with Z before and after smoothing.

    ``geo.smooth`` smooths XY like 2D data and interpolates Z along the input edge each new
    vertex comes from: the profile shows that the heights follow the input.

    Parameters
    ----------
    before, after : shapely geometries with Z, GeoSeries, or (N, 3) array_like
        The input lines and the smoothed ones (every part is drawn).
    along : {"x", "y", "arc"}, optional
        The horizontal axis: easting, northing, or each line's 2D arc length.
    labels : (str, str), optional
    ax : matplotlib Axes, optional
    title : str, optional

    Returns
    -------
    matplotlib Axes

    Examples
    --------
    >>> import numpy as np, shapely
    >>> from curvesmith import geo, plot
    >>> x = np.linspace(0, 1000, 30)
    >>> track = shapely.LineString(np.c_[x, 50 * np.sin(x / 90), 200 + x / 10])
    >>> ax = plot.z_profile(track, geo.smooth(track, iterations=2))
    >>> ax.get_ylabel(), ax.lines[1].get_label()
    ('height (Z)', 'smoothed')
    """
    along = as_choice(along, ("x", "y", "arc"), name="along")
    if ax is None:
        _, (ax,) = new_axes(width=8.0, height=3.6)
    styles: list[dict[str, Any]] = [
        {"marker": "o", "ls": "", "ms": 3, "color": "0.55"},
        {"lw": 1.2, "color": "tab:blue"},
    ]
    for k, (lines, style) in enumerate(
        zip((_xyz_lines(before, "before"), _xyz_lines(after, "after")), styles, strict=True)
    ):
        for i, a in enumerate(lines):
            if along == "arc":
                h = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(a[:, :2], axis=0).T))])
            else:
                h = a[:, 0 if along == "x" else 1]
            ax.plot(h, a[:, 2], label=labels[k] if i == 0 else None, **style)
    ax.set_xlabel({"x": "x (easting)", "y": "y (northing)", "arc": "arc length (2D)"}[along])
    ax.set_ylabel("height (Z)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    if title:
        ax.set_title(title)
    return ax


def hillshade(
    grid: Any,
    x: ArrayLike | None = None,
    y: ArrayLike | None = None,
    *,
    azimuth: float = 315.0,
    altitude: float = 45.0,
    vert_exag: float = 2.0,
    ax: Axes | None = None,
) -> Axes:
    """A grey hillshade of a terrain grid, north up, as the backdrop of contour lines.

    Parameters
    ----------
    grid : Grid or (ny, nx) array_like
        :func:`curvesmith.geo.read_grid`'s grid, or the heights (NaN: no data, drawn
        transparent).
    x, y : (nx,) and (ny,) array_like, optional
        Cell-centre coordinates (increasing or decreasing; regular), as for
        :func:`curvesmith.geo.contours`; taken from a Grid.
    azimuth, altitude : float, optional
        Direction of the light, degrees (matplotlib's ``LightSource``).
    vert_exag : float, optional
        Vertical exaggeration of the shading.
    ax : matplotlib Axes, optional

    Returns
    -------
    matplotlib Axes

    Examples
    --------
    >>> import numpy as np
    >>> from curvesmith import plot
    >>> yy, xx = np.mgrid[0:40, 0:50] * 30.0
    >>> ax = plot.hillshade(np.hypot(xx - 700, yy - 600), xx[0], yy[:, 0])
    >>> [float(v) for v in ax.images[0].get_extent()]
    [-15.0, 1485.0, -15.0, 1185.0]
    """
    from matplotlib.colors import LightSource

    from ..errors import CurveError

    if hasattr(grid, "z"):
        z, x, y = grid.z, grid.x if x is None else x, grid.y if y is None else y
    else:
        z = grid
    z = np.asarray(z, dtype=float)
    if z.ndim != 2 or min(z.shape) < 2:
        raise CurveError(f"grid must be a 2-D array of at least 2 x 2 heights, got shape {z.shape}")
    if x is None or y is None:
        raise CurveError("x and y (the cell-centre coordinates) are required with an array grid")
    xs, ys = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    if xs.shape != (z.shape[1],) or ys.shape != (z.shape[0],):
        raise CurveError(
            f"x and y must have {z.shape[1]} and {z.shape[0]} values for a grid of shape "
            f"{z.shape}, got {xs.shape} and {ys.shape}"
        )
    if xs[0] > xs[-1]:
        xs, z = xs[::-1], z[:, ::-1]
    if ys[0] < ys[-1]:  # row 0 to the north
        ys, z = ys[::-1], z[::-1]
    if not (np.all(np.diff(xs) > 0) and np.all(np.diff(ys) < 0)):
        raise CurveError("x and y must be strictly monotone (the cell centres of a regular grid)")
    dx, dy = float(np.mean(np.diff(xs))), float(np.mean(-np.diff(ys)))
    if ax is None:
        _, (ax,) = new_axes(width=7.0, height=6.0)
    light = LightSource(azdeg=azimuth, altdeg=altitude)
    shade = light.hillshade(np.ma.masked_invalid(z), vert_exag=vert_exag, dx=dx, dy=dy)
    extent = (xs[0] - dx / 2, xs[-1] + dx / 2, ys[-1] - dy / 2, ys[0] + dy / 2)
    ax.imshow(shade, cmap="gray", extent=extent, origin="upper")
    ax.set_aspect("equal")
    return ax
