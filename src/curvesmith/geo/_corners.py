"""Sharp corners of GIS geometries: the vertices that ``keep_angle`` keeps in place.

Building footprints, field boundaries and parcels have corners that smoothing must not
round (QGIS's Smooth has MAX_ANGLE, GRASS v.generalize angle_thresh). A vertex whose
turning angle (the angle between the incoming and the outgoing edge, 0 on a straight
run, pi at a spike) is larger than the threshold is a corner; as a CCA anchor (paper,
section 5) it stays bit for bit, and every ring still keeps its area exactly.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from .._validate import as_float
from ..errors import CurveError, require

__all__ = ["corner_vertices", "with_corners"]


def _components(geoms: np.ndarray):
    """Linear components (rings, lines) of `geoms` in ``shapely.get_coordinates`` order."""
    shapely = require("shapely", "geo", "finding corners")
    present = np.array([g is not None for g in geoms], dtype=bool)
    parts = shapely.get_parts(geoms[present])
    # geometry collections hold multi-geometries too: flatten until only singles remain
    while True:
        kind = shapely.get_type_id(parts)
        nested = np.isin(kind, (4, 5, 6, 7))
        if not nested.any():
            break
        parts = shapely.get_parts(parts)
    kind = shapely.get_type_id(parts)
    poly = kind == 3
    rings, owner = shapely.get_rings(parts[poly], return_index=True)
    position = np.flatnonzero(poly)[owner] if len(rings) else np.zeros(0, dtype=np.intp)
    linear = np.flatnonzero(np.isin(kind, (1, 2)))  # LineString, LinearRing
    items = np.concatenate([parts[linear], rings])
    keys = np.concatenate([linear, position])
    order = np.argsort(keys, kind="stable")  # a polygon's rings stay in their order
    return items[order]


def corner_vertices(geometry: Any, angle: float) -> np.ndarray:
    """Vertices turning by more than `angle`, as a mask for the ``fixed=`` of geo's smoothers.

    Parameters
    ----------
    geometry : shapely geometries, GeoSeries or GeoDataFrame
        As :func:`curvesmith.geo.smooth` takes them.
    angle : float
        Threshold in radians, in ``[0, pi)``: a vertex whose turning angle (0 on a straight
        run, pi/2 at a square corner) exceeds it is a corner. The ends of open lines are
        fixed by the smoothers anyway and are not marked.

    Returns
    -------
    (N,) bool ndarray
        Over ``shapely.get_coordinates(geometry)`` (rings with their closing vertex, which
        is marked with the first).

    Examples
    --------
    >>> import shapely
    >>> square = shapely.Polygon([(0, 0), (4, 0), (4, 4), (2, 4.1), (0, 4)])
    >>> corner_vertices([square], math.radians(30)).tolist()
    [True, True, True, False, True, True]
    """
    from ._smooth import as_geometry_array

    shapely = require("shapely", "geo", "finding corners")
    angle = as_float(angle, name="keep_angle", low=0.0, low_open=False)
    if not angle < math.pi:
        raise CurveError(f"keep_angle must be in [0, pi) radians, got {angle}")
    geoms, _ = as_geometry_array(geometry)
    items = _components(np.asarray(geoms, dtype=object))
    if not len(items):
        return np.zeros(0, dtype=bool)
    xy, which = shapely.get_coordinates(items, return_index=True)
    counts = np.bincount(which, minlength=len(items))
    starts = np.concatenate([[0], np.cumsum(counts)])
    closed = shapely.is_closed(items) & (counts >= 4)
    # neighbours of every vertex: cyclic on closed components (skipping the closing
    # vertex), none at the ends of open ones
    idx = np.arange(len(xy))
    first, last = starts[which], starts[which + 1] - 1
    ring = closed[which]
    prev = np.where(idx == first, np.where(ring, last - 1, -1), idx - 1)
    nxt = np.where(idx == last, -1, idx + 1)
    nxt = np.where(ring & (idx == last - 1), first, nxt)
    inner = (prev >= 0) & (nxt >= 0) & ~(ring & (idx == last))
    a = xy[idx[inner]] - xy[prev[inner]]
    b = xy[nxt[inner]] - xy[idx[inner]]
    turn = np.abs(np.arctan2(a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0], np.sum(a * b, axis=1)))
    mask = np.zeros(len(xy), dtype=bool)
    mask[idx[inner]] = turn > angle
    mask[last[ring & (idx == last)]] = mask[first[ring & (idx == last)]]  # closing vertex
    return mask


def for_method(fixed: Any, method: str) -> Any:
    """`fixed`, or None when it keeps only the lon/lat domain's edges and `method` cannot.

    :func:`curvesmith.geo.domain_fixed` keeps vertices on ±180° / ±90° where CCA would push
    them off the map; Chaikin's points are averages of neighbouring vertices, inside the
    domain with them, so it needs no such anchors (and has none: ``curvesmith smooth
    --method chaikin`` on a lon/lat file failed with "fixed needs method='cca'").
    """
    from .. import methods

    if getattr(fixed, "domain_edges", False) and not methods.get(method).keeps_vertices:
        return None
    return fixed


def with_corners(geometry: Any, fixed: Any, keep_angle: float | None) -> Any:
    """`fixed` (mask, callable or None) plus the corners sharper than `keep_angle`."""
    if keep_angle is None:
        return fixed
    shapely = require("shapely", "geo", "finding corners")
    from ._smooth import as_geometry_array

    corners = corner_vertices(geometry, keep_angle)
    if fixed is None:
        return corners
    from ._smooth import FixedVertices

    # the existing checks of `fixed` (a mask over the coordinates or a callable on them)
    geoms, _ = as_geometry_array(geometry)
    geoms = np.asarray(geoms, dtype=object)
    present = ~shapely.is_missing(geoms)
    xy = shapely.get_coordinates(geoms[present])
    if callable(fixed):
        return corners | FixedVertices(fixed, geoms).mask(xy)
    FixedVertices(fixed, geoms)  # raises for a mask of the wrong shape or type
    return corners | np.asarray(fixed)
