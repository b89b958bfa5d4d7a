"""numba kernels of the clearance screening and the shift bound (imported only when they run).

The conflict resolution asks, for a few thousand pairs of smoothed pieces, whether the
two polylines come within a small distance of each other. Nested contour lines, rivers
winding round each other and long coverage arcs have bounding boxes that contain most of
the other polyline, so comparing every segment of one with every segment of the other is
quadratic in the piece length (766 contour lines of Jacksboro's DEM, 2 passes: 23 s).
Here the segments of the second polyline are sorted once per pair along the axis in which
its bounding box is longer (x for a line running east-west, y for one running
north-south), and each segment of the first looks only at those whose range on that axis
can reach it (a binary search, widened by the longest segment's extent), so the cost is
about ``n log n`` plus the segment pairs that really are close along that axis.
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True, nogil=True)
def _seg_dist2(ax, ay, bx, by, px, py):
    """Squared distance from point p to segment a-b."""
    dx, dy = bx - ax, by - ay
    ll = dx * dx + dy * dy
    t = 0.0
    if ll > 0.0:
        t = ((px - ax) * dx + (py - ay) * dy) / ll
        t = min(1.0, max(0.0, t))
    ex, ey = ax + t * dx - px, ay + t * dy - py
    return ex * ex + ey * ey


@njit(cache=True, nogil=True)
def _segs_within(ax, ay, bx, by, cx, cy, dx, dy, d2):
    """Whether segments a-b and c-d cross or come within sqrt(d2) (floating point)."""
    o1 = (bx - ax) * (cy - ay) - (by - ay) * (cx - ax)
    o2 = (bx - ax) * (dy - ay) - (by - ay) * (dx - ax)
    o3 = (dx - cx) * (ay - cy) - (dy - cy) * (ax - cx)
    o4 = (dx - cx) * (by - cy) - (dy - cy) * (bx - cx)
    if o1 * o2 <= 0.0 and o3 * o4 <= 0.0:
        return True
    return (
        _seg_dist2(ax, ay, bx, by, cx, cy) < d2
        or _seg_dist2(ax, ay, bx, by, dx, dy) < d2
        or _seg_dist2(cx, cy, dx, dy, ax, ay) < d2
        or _seg_dist2(cx, cy, dx, dy, bx, by) < d2
    )


#: Segments per chunk of :func:`polylines_within`'s screening: a chunk whose box is
#: farther than the distance from the other polyline's box is skipped whole.
CHUNK = 16


@njit(cache=True, nogil=True)
def _candidates(X, i0, i1, cb, c0, bx0, bx1, by0, by1, r, out):
    """Segments ``t`` (``i0 <= t < i1 - 1``) whose box comes within `r` of the given box.

    ``cb[c0 + j]``: the box ``(x0, x1, y0, y1)`` of the polyline's chunk ``j`` (segments
    ``i0 + j * CHUNK`` onwards); the segments are listed in increasing order.
    """
    n = 0
    for j in range((i1 - 1 - i0 + CHUNK - 1) // CHUNK):
        b = c0 + j
        if cb[b, 0] > bx1 + r or cb[b, 1] < bx0 - r or cb[b, 2] > by1 + r or cb[b, 3] < by0 - r:
            continue
        t0 = i0 + j * CHUNK
        for t in range(t0, min(t0 + CHUNK, i1 - 1)):
            if (
                min(X[t, 0], X[t + 1, 0]) <= bx1 + r
                and max(X[t, 0], X[t + 1, 0]) >= bx0 - r
                and min(X[t, 1], X[t + 1, 1]) <= by1 + r
                and max(X[t, 1], X[t + 1, 1]) >= by0 - r
            ):
                out[n] = t
                n += 1
    return n


@njit(cache=True, nogil=True)
def _chunk_boxes(X, offsets, used):
    """Boxes of every used polyline and of its chunks: ``(boxes, chunk_boxes, first_chunk)``.

    A polyline that is not used gets no chunk (and an empty box).
    """
    npoly = offsets.shape[0] - 1
    first = np.zeros(npoly + 1, dtype=np.int64)
    for i in range(npoly):
        nseg = offsets[i + 1] - offsets[i] - 1
        first[i + 1] = first[i] + (((nseg + CHUNK - 1) // CHUNK) if used[i] and nseg > 0 else 0)
    boxes = np.empty((npoly, 4))
    cb = np.empty((first[npoly], 4))
    for i in range(npoly):
        x0, x1, y0, y1 = np.inf, -np.inf, np.inf, -np.inf
        if used[i]:
            i0, i1 = offsets[i], offsets[i + 1]
            if first[i + 1] == first[i]:  # a single vertex: no segment, no chunk
                x0, x1, y0, y1 = _box(X, i0, i1)
            for j in range(first[i + 1] - first[i]):  # the polyline's box: its chunks'
                t0 = i0 + j * CHUNK
                cx0, cx1, cy0, cy1 = _box(X, t0, min(t0 + CHUNK + 1, i1))
                cb[first[i] + j, 0], cb[first[i] + j, 1] = cx0, cx1
                cb[first[i] + j, 2], cb[first[i] + j, 3] = cy0, cy1
                x0, x1, y0, y1 = min(x0, cx0), max(x1, cx1), min(y0, cy0), max(y1, cy1)
        boxes[i, 0], boxes[i, 1], boxes[i, 2], boxes[i, 3] = x0, x1, y0, y1
    return boxes, cb, first


@njit(cache=True, nogil=True)
def polyline_boxes(X, offsets):
    """Per polyline ``X[offsets[p]:offsets[p + 1]]``: its box ``(x0, x1, y0, y1)``.

    An empty polyline gets the empty box ``(inf, -inf, inf, -inf)``, which meets nothing.
    """
    n = offsets.shape[0] - 1
    out = np.empty((n, 4))
    for p in range(n):
        out[p, 0], out[p, 1], out[p, 2], out[p, 3] = _box(X, offsets[p], offsets[p + 1])
    return out


@njit(cache=True, nogil=True)
def _box(X, i0, i1):
    x0, x1, y0, y1 = np.inf, -np.inf, np.inf, -np.inf
    for t in range(i0, i1):
        x0, x1 = min(x0, X[t, 0]), max(x1, X[t, 0])
        y0, y1 = min(y0, X[t, 1]), max(y1, X[t, 1])
    return x0, x1, y0, y1


@njit(cache=True, nogil=True)
def polylines_within(X, offsets, pa, pb, dist):
    """Per pair ``k``: whether polylines ``pa[k]`` and ``pb[k]`` come within ``dist[k]``.

    Polyline ``i`` is ``X[offsets[i]:offsets[i + 1]]``. A pair is close when some segment of
    one and some segment of the other cross or come within the distance (floating point:
    a screening test for the clearance margin, not a proof). Only the segments of each
    that lie within the distance of the other's bounding box take part; those of the
    second are sorted by x and searched, not scanned.
    """
    npairs = pa.shape[0]
    out = np.zeros(npairs, dtype=np.bool_)
    nmax = 1
    npoly = offsets.shape[0] - 1
    used = np.zeros(npoly, dtype=np.bool_)
    for k in range(npairs):
        used[pa[k]] = True
        used[pb[k]] = True
    for i in range(npoly):
        if used[i]:
            nmax = max(nmax, offsets[i + 1] - offsets[i])
    boxes, cb, first_chunk = _chunk_boxes(X, offsets, used)
    sa = np.empty(nmax, dtype=np.int64)
    sb = np.empty(nmax, dtype=np.int64)
    keys = np.empty(nmax, dtype=np.float64)
    for k in range(npairs):
        r = dist[k]
        d2 = r * r
        ia0, ia1 = offsets[pa[k]], offsets[pa[k] + 1]
        ib0, ib1 = offsets[pb[k]], offsets[pb[k] + 1]
        ax0, ax1, ay0, ay1 = boxes[pa[k], 0], boxes[pa[k], 1], boxes[pa[k], 2], boxes[pa[k], 3]
        bx0, bx1, by0, by1 = boxes[pb[k], 0], boxes[pb[k], 1], boxes[pb[k], 2], boxes[pb[k], 3]
        if ax0 > bx1 + r or bx0 > ax1 + r or ay0 > by1 + r or by0 > ay1 + r:
            continue  # the boxes are farther apart than r
        na = _candidates(X, ia0, ia1, cb, first_chunk[pa[k]], bx0, bx1, by0, by1, r, sa)
        nb = _candidates(X, ib0, ib1, cb, first_chunk[pb[k]], ax0, ax1, ay0, ay1, r, sb)
        if na == 0 or nb == 0:
            continue
        # sort b's candidates along its box's longer axis c (the other axis: e)
        c = 0 if bx1 - bx0 >= by1 - by0 else 1
        e = 1 - c
        wide = 0.0  # the largest extent of b's candidate segments along c
        for v in range(nb):
            q = sb[v]
            lo = min(X[q, c], X[q + 1, c])
            keys[v] = lo
            wide = max(wide, max(X[q, c], X[q + 1, c]) - lo)
        order = np.argsort(keys[:nb])
        xs = keys[:nb][order]
        found = False
        for u in range(na):
            t = sa[u]
            x0, x1 = min(X[t, c], X[t + 1, c]) - r, max(X[t, c], X[t + 1, c]) + r
            y0, y1 = min(X[t, e], X[t + 1, e]) - r, max(X[t, e], X[t + 1, e]) + r
            # b's segments with min <= x1 and max >= x0 along c, hence min >= x0 - wide
            first = np.searchsorted(xs, x0 - wide, side="left")
            last = np.searchsorted(xs, x1, side="right")
            for w in range(first, last):
                q = sb[order[w]]
                if (
                    max(X[q, c], X[q + 1, c]) < x0
                    or min(X[q, e], X[q + 1, e]) > y1
                    or max(X[q, e], X[q + 1, e]) < y0
                ):
                    continue
                if _segs_within(X[t, 0], X[t, 1], X[t + 1, 0], X[t + 1, 1],
                                X[q, 0], X[q, 1], X[q + 1, 0], X[q + 1, 1], d2):  # fmt: skip
                    found = True
                    break
            if found:
                break
        out[k] = found
    return out


@njit(cache=True, nogil=True)
def _segments(parts, f0, f1, sa, sb):
    """The segments of the polylines ``parts[f0:f1]`` as end indices into the coordinates.

    Polyline ``p`` is ``X[parts[p]:parts[p + 1]]``; a one-point polyline is one segment of
    length 0, an empty one has none. Returns their number (``sa[:n]``, ``sb[:n]``).
    """
    n = 0
    for p in range(f0, f1):
        i0, i1 = parts[p], parts[p + 1]
        if i1 - i0 == 1:
            sa[n], sb[n] = i0, i0
            n += 1
        for q in range(i0, i1 - 1):
            sa[n], sb[n] = q, q + 1
            n += 1
    return n


@njit(cache=True, nogil=True)
def _points_near(P, p0, p1, Q, q0, q1, sa, sb, ns, r, keys):
    """Whether every vertex ``P[p0:p1]`` lies within `r` of the segments ``sa[:ns]``, ``sb[:ns]``.

    The segments join vertices of ``Q`` (their ends, from :func:`_segments`), which all lie in
    ``Q[q0:q1]``. With no segment, only an empty ``P`` is within.
    """
    if ns == 0:
        return p1 <= p0
    qx0, qx1, qy0, qy1 = _box(Q, q0, q1)
    c = 0 if qx1 - qx0 >= qy1 - qy0 else 1  # sort along the box's longer axis
    e = 1 - c
    wide = 0.0
    for v in range(ns):
        lo = min(Q[sa[v], c], Q[sb[v], c])
        keys[v] = lo
        wide = max(wide, max(Q[sa[v], c], Q[sb[v], c]) - lo)
    order = np.argsort(keys[:ns])
    xs = keys[:ns][order]
    d2 = r * r
    last_hit = 0  # the segment that served the previous vertex: usually serves this one
    for i in range(p0, p1):
        px, py = P[i, c], P[i, e]
        a, b = sa[last_hit], sb[last_hit]
        if _seg_dist2(Q[a, 0], Q[a, 1], Q[b, 0], Q[b, 1], P[i, 0], P[i, 1]) <= d2:
            continue
        first = np.searchsorted(xs, px - r - wide, side="left")
        last = np.searchsorted(xs, px + r, side="right")
        hit = -1
        for w in range(first, last):
            v = order[w]
            a, b = sa[v], sb[v]
            if (
                max(Q[a, c], Q[b, c]) < px - r
                or min(Q[a, e], Q[b, e]) > py + r
                or max(Q[a, e], Q[b, e]) < py - r
            ):
                continue
            if _seg_dist2(Q[a, 0], Q[a, 1], Q[b, 0], Q[b, 1], P[i, 0], P[i, 1]) <= d2:
                hit = v
                break
        if hit < 0:
            return False
        last_hit = hit
    return True


@njit(cache=True, nogil=True)
def shifts_within(A, parta, feata, B, partb, featb, dist):
    """Per feature ``k``: whether the discrete Hausdorff distance of ``A_k``, ``B_k`` is <= dist[k].

    A feature is a set of polylines (the rings of a polygon, the lines of a multi-line): those
    of ``A_k`` are ``parta[feata[k]:feata[k + 1] + 1]`` as offsets into the coordinates ``A``
    (likewise ``B_k``). Every vertex of each must lie within ``dist[k]`` of a segment of the
    other (point-to-segment distance), the measure GEOS' ``hausdorff_distance`` takes,
    decided without computing it. A feature whose distance is not needed has ``dist[k]``
    NaN and is False.
    """
    n = feata.shape[0] - 1
    out = np.zeros(n, dtype=np.bool_)
    nmax = 1
    for k in range(n):
        na = parta[feata[k + 1]] - parta[feata[k]]
        nb = partb[featb[k + 1]] - partb[featb[k]]
        nmax = max(nmax, na, nb)
    keys = np.empty(nmax, dtype=np.float64)
    sa = np.empty(nmax, dtype=np.int64)
    sb = np.empty(nmax, dtype=np.int64)
    for k in range(n):
        r = dist[k]
        if not r >= 0.0:
            continue
        a0, a1 = parta[feata[k]], parta[feata[k + 1]]
        b0, b1 = partb[featb[k]], partb[featb[k + 1]]
        ns = _segments(partb, featb[k], featb[k + 1], sa, sb)
        if not _points_near(A, a0, a1, B, b0, b1, sa, sb, ns, r, keys):
            continue
        ns = _segments(parta, feata[k], feata[k + 1], sa, sb)
        out[k] = _points_near(B, b0, b1, A, a0, a1, sa, sb, ns, r, keys)
    return out
