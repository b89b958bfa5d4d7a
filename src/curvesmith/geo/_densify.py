"""Edges that stay straight where the data say they are: densification before projecting.

A layer in lon/lat means its edges straight in lon/lat: that is how every GIS draws them
and how GEOS measures them. Projected vertex by vertex into an equal-area projection, a
long edge becomes the straight chord between its ends' images, which is not the image of
the edge: the 49th parallel between Canada and the United States, one edge of 2,000 km,
is a chord up to kilometres from the parallel. Smoothed there and projected back, the
border bends by kilometres where the data drew it straight, whatever ``max_shift`` said.

:func:`densify_for` divides every edge until its image lies within a tolerance of the
straight chord between its pieces' images. The points are placed in the data's CRS, from
the edge's lesser end (lexicographically), so that an edge that two polygons of a coverage
share, each traversing it its own way, gets the very same points for both: the coverage
stays a coverage.
"""

from __future__ import annotations

from typing import Any

import numpy as np

__all__ = ["densify_for"]

#: Passes of division at most; the image's distance from the chord falls with the square
#: of the piece's length, so a second pass is rare and a third almost never needed.
MAX_PASSES = 4

#: Pieces one edge is divided into at most per pass.
MAX_PIECES = 4096


def densify_for(geoms: Any, transform: Any, tolerance: float) -> np.ndarray:
    """`geoms` with edges divided until each one's image under `transform` is straight.

    Parameters
    ----------
    geoms : array of shapely geometries
        Polygons, lines and their multi-part kinds are divided; other geometries, those
        with M values (shapely's ragged arrays would make M a Z), empty and missing
        entries are returned as they are.
    transform : callable
        ``transform(x, y) -> (x', y')`` on arrays, the projection (pyproj's
        ``Transformer.transform`` with ``always_xy=True``).
    tolerance : float
        The largest distance, in the projection's units, between the image of an edge's
        midpoint and the chord between the images of its ends.

    Returns
    -------
    numpy.ndarray of object
        The geometries, the same ones where nothing was divided. The Z of an inserted
        point is interpolated along its edge.
    """
    import shapely

    geoms = np.asarray(geoms, dtype=object)
    out = geoms.copy()
    types = shapely.get_type_id(geoms)
    T = shapely.GeometryType
    present = ~(shapely.is_missing(geoms) | shapely.is_empty(geoms))
    present[present] = ~shapely.has_m(geoms[present])
    for single, multi in ((T.POLYGON, T.MULTIPOLYGON), (T.LINESTRING, T.MULTILINESTRING)):
        sel = np.flatnonzero(present & np.isin(types, (single, multi)))
        if sel.size == 0:
            continue
        kind, xy, offsets = shapely.to_ragged_array(geoms[sel])
        new_xy, rows = _densify_rows(xy, np.asarray(offsets[0]), transform, tolerance)
        if new_xy is xy:
            continue
        g = shapely.from_ragged_array(kind, new_xy, (rows, *offsets[1:]))
        if kind == multi:  # the single-part ones were made multi by to_ragged_array
            one = types[sel] == single
            g[one] = shapely.get_geometry(g[one], 0)
        out[sel] = g
    return out


def _densify_rows(xy: np.ndarray, rows: np.ndarray, transform: Any, tolerance: float):
    """Divide the edges of ragged curves (`xy`, curve `rows` offsets); returns both anew."""
    n = len(xy)
    dirty = np.ones(n, dtype=bool)  # rows whose edge to the next row is to be looked at
    for _ in range(MAX_PASSES):
        last = np.zeros(n, dtype=bool)
        ends = rows[1:][rows[1:] > rows[:-1]]
        last[ends - 1] = True
        seg = np.flatnonzero(dirty & ~last)
        if seg.size == 0:
            break
        a, b = xy[seg], xy[seg + 1]
        swap = (a[:, 0] > b[:, 0]) | ((a[:, 0] == b[:, 0]) & (a[:, 1] > b[:, 1]))
        lo = np.where(swap[:, None], b, a)
        hi = np.where(swap[:, None], a, b)
        dev = _deviation(lo, hi, transform)
        need = dev > tolerance
        if not need.any():
            break
        seg, lo, hi, swap = seg[need], lo[need], hi[need], swap[need]
        pieces = np.minimum(np.ceil(np.sqrt(dev[need] / tolerance)), MAX_PIECES).astype(np.int64)
        pieces = np.maximum(pieces, 2)
        counts = np.ones(n, dtype=np.int64)
        counts[seg] = pieces
        start = np.zeros(n + 1, dtype=np.int64)
        np.cumsum(counts, out=start[1:])
        new = np.repeat(xy, counts, axis=0)
        # the inserted points: lo + (hi - lo) * j / k, j = 1 .. k - 1, in the edge's order
        owner = np.repeat(np.arange(seg.size), pieces - 1)
        first = np.repeat(np.cumsum(pieces - 1) - (pieces - 1), pieces - 1)
        rank = np.arange(owner.size) - first + 1  # 1 .. k - 1 within each edge
        k = pieces[owner]
        j = np.where(swap[owner], k - rank, rank)
        t = (j / k)[:, None]
        pts = lo[owner] + (hi[owner] - lo[owner]) * t
        at = start[seg][owner] + rank
        new[at] = pts
        dirty_new = np.zeros(start[-1], dtype=bool)
        dirty_new[start[seg]] = True
        dirty_new[at] = True
        xy, rows, dirty, n = new, start[rows], dirty_new, start[-1]
    return xy, rows


def _deviation(lo: np.ndarray, hi: np.ndarray, transform: Any) -> np.ndarray:
    """Distance of each edge's midpoint image from the chord of its ends' images."""
    mid = (lo[:, :2] + hi[:, :2]) * 0.5
    px, py = (np.asarray(v, dtype=float) for v in transform(lo[:, 0], lo[:, 1]))
    qx, qy = (np.asarray(v, dtype=float) for v in transform(hi[:, 0], hi[:, 1]))
    mx, my = (np.asarray(v, dtype=float) for v in transform(mid[:, 0], mid[:, 1]))
    dx, dy = qx - px, qy - py
    length = np.hypot(dx, dy)
    cross = np.abs(dx * (my - py) - dy * (mx - px))
    with np.errstate(invalid="ignore", divide="ignore"):
        dev = np.where(length > 0, cross / length, np.hypot(mx - px, my - py))
    return np.where(np.isfinite(dev), dev, 0.0)
