"""numba kernels of the coverage topology (imported only when it runs).

:func:`curvesmith.geo._coverage.coverage_topology` needs, for a million vertices, which
vertices are the same point (exact coordinates), which ring edges are the same segment
(the same two points, in either direction) and which vertices are nodes. Sorting does
this (``np.lexsort`` of the points, ``np.unique`` of the segment keys) in O(n log n) with
several passes over the data; the hash tables here do it in two passes of O(n), giving
the same partition. Only the numbering differs: points and segments are numbered in the
order they first appear, not in sorted order, and nothing downstream depends on the
numbering (arcs are identified by their smallest segment number, the same for every
ring that runs along them, and numbered in the order of their first run).

A point's hash key is the bit pattern of its two coordinates; the caller maps -0.0 to
0.0 first, so that equal coordinates have equal bits (the coordinates of valid
geometries are finite).
"""

from __future__ import annotations

import numpy as np
from numba import njit

_EMPTY = -1


def _table_size(n):
    size = 16
    while size < 2 * n:
        size *= 2
    return size


@njit(cache=True, nogil=True)
def _mix(a, b, mask):
    # splitmix64's finaliser over the two words: every input bit reaches the low bits
    h = (a * np.uint64(0x9E3779B97F4A7C15)) ^ (b + np.uint64(0x632BE59BD9B4E019))
    h ^= h >> np.uint64(30)
    h *= np.uint64(0xBF58476D1CE4E5B9)
    h ^= h >> np.uint64(27)
    h *= np.uint64(0x94D049BB133111EB)
    h ^= h >> np.uint64(31)
    return np.int64(h & mask)


def point_ids(xy):
    """Per row of `xy` (``(n, 2)`` float64), the number of its point: ``(pid, n_points)``.

    Rows with bit-identical coordinates get the same number; numbers follow first
    appearance. The table and the output are allocated by numpy (huge pages: a
    coverage's million vertices fill tens of megabytes, which numba's malloc would
    touch page by page), as in :func:`segment_classes`.
    """
    n = xy.shape[0]
    if n >= 2**31:
        raise ValueError("point_ids: more than 2**31 - 1 rows")
    slot_row = np.full(_table_size(n), _EMPTY, dtype=np.int32)  # int32: fewer cache misses
    pid = np.empty(n, dtype=np.int64)
    return pid, _point_ids(np.ascontiguousarray(xy, dtype=np.float64), slot_row, pid)


@njit(cache=True, nogil=True)
def _point_ids(xy, slot_row, pid):
    n = xy.shape[0]
    bits = xy.view(np.uint64)
    size = slot_row.shape[0]
    mask = np.uint64(size - 1)
    n_points = 0
    for i in range(n):
        bx, by = bits[i, 0], bits[i, 1]
        h = _mix(bx, by, mask)
        while True:
            r = slot_row[h]
            if r == _EMPTY:  # a new point; the slot keeps its first row
                slot_row[h] = i
                pid[i] = n_points
                n_points += 1
                break
            if bits[r, 0] == bx and bits[r, 1] == by:
                pid[i] = pid[r]
                break
            h = (h + 1) & np.int64(size - 1)
    return n_points


def segment_classes(a, b, n_points):
    """Per segment ``a[i] -> b[i]`` (point numbers), the number of its unordered pair.

    Returns ``(cls, lo, hi)``: the class of every segment, and per class its two point
    numbers (``lo <= hi``). Classes follow first appearance. The pairs are bucketed by
    their lower point (a point has few segments, and consecutive segments of a ring
    have nearby point numbers, so the buckets are read close to where they were
    written), not hashed. The buckets and outputs are allocated by numpy (the US
    counties: 37-53 ms with numba's allocator, 14-36 ms so).
    """
    a = np.asarray(a, dtype=np.int64)
    b = np.asarray(b, dtype=np.int64)
    n = a.shape[0]
    start = np.zeros(n_points + 1, dtype=np.int64)
    bucket_hi, bucket_cls = np.empty(n, dtype=np.int64), np.empty(n, dtype=np.int64)
    cls = np.empty(n, dtype=np.int64)
    lo, hi = np.empty(n, dtype=np.int64), np.empty(n, dtype=np.int64)
    n_cls = _segment_classes(a, b, n_points, start, bucket_hi, bucket_cls, cls, lo, hi)
    return cls, lo[:n_cls].copy(), hi[:n_cls].copy()


@njit(cache=True, nogil=True)
def _segment_classes(a, b, n_points, start, bucket_hi, bucket_cls, cls, lo, hi):
    n = a.shape[0]
    for i in range(n):
        start[min(a[i], b[i]) + 1] += 1
    for p in range(n_points):
        start[p + 1] += start[p]
    fill = start[:-1].copy()
    n_cls = 0
    for i in range(n):
        p, q = a[i], b[i]
        if q < p:
            p, q = q, p
        c = _EMPTY
        for t in range(start[p], fill[p]):
            if bucket_hi[t] == q:
                c = bucket_cls[t]
                break
        if c == _EMPTY:
            c = n_cls
            n_cls += 1
            lo[c] = p
            hi[c] = q
            bucket_hi[fill[p]] = q
            bucket_cls[fill[p]] = c
            fill[p] += 1
        cls[i] = c
    return n_cls


@njit(cache=True, nogil=True)
def node_flags(pid, cls, prev, deg, count, gmin, gmax, frozen):
    """Per vertex: whether it is a node.

    A node is a point with other than two distinct incident segments (``deg``), or a
    vertex where the signature of the boundary changes between the segment before it
    (``cls[prev[i]]``) and the one after it (``cls[i]``): the number of rings along it,
    the polygons on either side (``gmin``, ``gmax``) or whether it is frozen.
    """
    n = pid.shape[0]
    node = np.empty(n, dtype=np.bool_)
    for i in range(n):
        c, d = cls[i], cls[prev[i]]
        node[i] = (
            deg[pid[i]] != 2
            or count[c] != count[d]
            or gmin[c] != gmin[d]
            or gmax[c] != gmax[d]
            or frozen[c] != frozen[d]
        )
    return node


@njit(cache=True, nogil=True)
def lexicographic_first(xy, starts, lens):
    """Per run of rows ``starts[r] .. starts[r] + lens[r] - 1``, its first smallest row.

    Smallest lexicographically (smallest x, then smallest y); the offset within the run.
    """
    out = np.zeros(starts.shape[0], dtype=np.int64)
    for r in range(starts.shape[0]):
        s = starts[r]
        best = 0
        for t in range(1, lens[r]):
            x, y = xy[s + t, 0], xy[s + t, 1]
            bx, by = xy[s + best, 0], xy[s + best, 1]
            if x < bx or (x == bx and y < by):
                best = t
        out[r] = best
    return out
