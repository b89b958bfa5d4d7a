"""Geometry helpers of the fit: end-to-end equal-chord resampling and point-to-polyline distances.

Neither is part of the paper's method; both serve the data preparation and the quality report
of :func:`curvesmith.elastica.fit`.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.spatial import cKDTree

__all__: list[str] = []


def drop_repeats(p: np.ndarray) -> np.ndarray:
    """Drop consecutive duplicate vertices (zero-length edges), keeping the first of each run."""
    if p.shape[0] < 2:
        return p
    keep = np.ones(p.shape[0], dtype=bool)
    keep[1:] = np.any(p[1:] != p[:-1], axis=1)
    return p[keep]


def chord_walk(p: np.ndarray, step: float) -> tuple[np.ndarray, float]:
    """Equal chords of length `step` along the polyline `p`, first hit ahead (a plain walk).

    Returns the vertices and the distance from the last one to the end of the polyline.
    The next vertex lies on the first segment that leaves the circle of radius `step` around
    the current vertex: a disc is convex, so a segment with both ends inside lies inside,
    and the first vertex outside the circle closes the segment that holds the crossing. The
    search scans the vertices ahead in vectorised windows. Same points as
    ``geometry.resample_equilateral(..., rule="walk")`` to rounding.
    """
    n = p.shape[0]
    out = [p[0]]
    cur = p[0]
    j = 1  # the next vertex of the polyline ahead of cur
    r2 = step * step
    window = 64
    while j < n:
        stop = min(n, j + window)
        d = p[j:stop] - cur
        far = np.flatnonzero(np.einsum("ij,ij->i", d, d) >= r2)
        if far.size == 0:
            if stop == n:
                break
            j = stop
            window = min(4096, 2 * window)
            continue
        window = max(64, window // 2)
        i = j + int(far[0])  # first vertex outside: the crossing is on segment (i-1, i)
        a = p[i - 1] if i - 1 >= j else cur
        e = p[i] - a
        f = a - cur
        aa = float(e @ e)
        bb = float(f @ e)
        cc = float(f @ f) - r2
        t = (-bb + math.sqrt(max(bb * bb - aa * cc, 0.0))) / aa
        cur = a + min(max(t, 0.0), 1.0) * e
        out.append(cur)
        j = i
    pts = np.array(out)
    return pts, float(np.linalg.norm(p[-1] - pts[-1]))


def walk_to_end(p: np.ndarray, step: float) -> np.ndarray:
    """Equal chords along `p` from its first vertex that end exactly on its last vertex.

    The chord is adjusted from `step` by a fixed-point iteration on the fractional number of
    chords ``f(r) = chords + rest / r`` until it is an integer ``n`` to ~1e-9 (``f`` is
    monotone and nearly proportional to ``1 / r``); the last vertex is then replaced by the
    end point, so the last chord differs from the others by ``|f - n| r``. Without this an
    equal-chord walk drops the last partial step: up to a whole chord of data unfitted.
    """
    total = float(np.sum(np.linalg.norm(np.diff(p, axis=0), axis=1)))
    pts, rest = chord_walk(p, step)
    target = max(4, round((pts.shape[0] - 1) + rest / step))
    r = step
    for _ in range(12):
        frac = (pts.shape[0] - 1) + rest / r
        if abs(frac - target) < 1e-9 * target:
            break
        r *= frac / target
        if not (0.0 < r <= total):
            break
        pts, rest = chord_walk(p, r)
    if rest > 0.5 * r:
        pts = np.vstack([pts, p[-1:]])
    else:
        pts = pts.copy()
        pts[-1] = p[-1]
    return pts


def point_polyline_distance(x: np.ndarray, poly: np.ndarray) -> np.ndarray:
    """Distance of every point of `x` (M, d) to the open polyline `poly` (K, d), exact.

    The nearest point of the polyline lies on a segment with an end within
    ``sqrt(d_v^2 + L^2/4)`` of the point (``d_v`` the distance to the nearest vertex, ``L``
    the longest segment): the segments next to the 8 nearest vertices are checked, and points
    whose 8th nearest vertex is not beyond that radius are checked against every segment.
    """
    x = np.asarray(x, dtype=float)
    poly = np.asarray(poly, dtype=float)
    if poly.shape[0] == 1:
        return np.linalg.norm(x - poly[0], axis=1)
    a = poly[:-1]
    e = poly[1:] - a
    ee = np.einsum("ij,ij->i", e, e)
    ee_safe = np.where(ee > 0, ee, 1.0)
    seg_max = float(np.sqrt(ee.max()))
    kq = min(8, poly.shape[0])
    tree = cKDTree(poly)
    dist_v, idx = tree.query(x, k=kq)
    if kq == 1:
        dist_v, idx = dist_v[:, None], idx[:, None]
    nseg = a.shape[0]
    segs = np.concatenate([np.clip(idx - 1, 0, nseg - 1), np.clip(idx, 0, nseg - 1)], axis=1)

    def seg_dist(pts, s):
        w = pts[:, None, :] - a[s]
        t = np.clip(np.einsum("mkd,mkd->mk", w, e[s]) / ee_safe[s], 0.0, 1.0)
        diff = w - t[..., None] * e[s]
        return np.sqrt(np.einsum("mkd,mkd->mk", diff, diff)).min(axis=1)

    out = seg_dist(x, segs)
    bound = np.sqrt(dist_v[:, 0] ** 2 + 0.25 * seg_max * seg_max)
    unsure = np.flatnonzero((dist_v[:, -1] < bound) & (kq < poly.shape[0]))
    allseg = np.arange(nseg)
    for start in range(0, unsure.size, 64):
        sel = unsure[start : start + 64]
        out[sel] = seg_dist(x[sel], np.broadcast_to(allseg, (sel.size, nseg)))
    return out
