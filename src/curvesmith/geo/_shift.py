"""How far smoothing moved each feature: GEOS' discrete Hausdorff distance, decided fast.

``max_shift`` bounds, per feature, the discrete Hausdorff distance between input and
output (:func:`shapely.hausdorff_distance`: every vertex of each within the distance of
the other's linework). GEOS computes it by comparing every vertex with every segment,
quadratic in the feature's size: on Natural Earth's Russia (a 10,000-vertex outline and
its 40,000-vertex smoothing) one call took seconds, and ``smooth --max-shift`` asks it
once per strength tried. Here the question is only ever "within `d`?", answered by the
sorted-segment search of :func:`curvesmith.geo._clearance_kernel.shifts_within`
(``n log n``), and the one number that is needed, the power of 2 by which a feature's
shift exceeds the bound, by a doubling search over such questions.
"""

from __future__ import annotations

from typing import Any

import numpy as np

#: The largest power of 2 :func:`excess_powers` looks for (beyond: a feature's shift is
#: more than 2**1100 times the bound, a float ratio that cannot occur).
MAX_POWER = 1100


class Linework:
    """The linework of a geometry array: coordinates, polylines and features (2D).

    ``xy[parts[p]:parts[p + 1]]`` is polyline ``p`` (a ring with its closing vertex, a line,
    a point as a one-vertex polyline); feature ``k`` has the polylines
    ``feats[k]:feats[k + 1]``. A missing or empty geometry has none.
    """

    def __init__(self, geoms: Any) -> None:
        import shapely

        geoms = np.asarray(geoms, dtype=object)
        parts, feat = geoms, np.arange(len(geoms))
        while True:  # multi-parts and collections down to simple parts
            kind = shapely.get_type_id(parts)
            multi = kind >= 4
            if not multi.any():
                break
            sub, j = shapely.get_parts(parts[multi], return_index=True)
            parts = np.concatenate([parts[~multi], sub])
            feat = np.concatenate([feat[~multi], feat[multi][j]])
        poly = kind == 3
        rings, j = shapely.get_rings(parts[poly], return_index=True)
        keep = ~poly & (kind >= 0)  # points and lines; missing ones dropped
        lines = np.concatenate([parts[keep], rings])
        feat = np.concatenate([feat[keep], feat[poly][j]])
        order = np.argsort(feat, kind="stable")
        lines, feat = lines[order], feat[order]
        self.xy = np.ascontiguousarray(shapely.get_coordinates(lines), dtype=np.float64)
        self.parts = np.zeros(len(lines) + 1, dtype=np.int64)
        np.cumsum(shapely.get_num_coordinates(lines), out=self.parts[1:])
        self.feats = np.zeros(len(geoms) + 1, dtype=np.int64)
        np.cumsum(np.bincount(feat, minlength=len(geoms)), out=self.feats[1:])

    def __len__(self) -> int:
        return len(self.feats) - 1


def shifts_within(before: Linework, after: Linework, dist: Any) -> np.ndarray:
    """Per feature: whether ``hausdorff_distance(before_k, after_k) <= dist_k``.

    `dist` is one distance or one per feature; a NaN distance gives False.
    """
    from ._clearance_kernel import shifts_within as kernel

    if len(before) != len(after):
        raise ValueError("before and after must have the same features")
    dist = np.broadcast_to(np.asarray(dist, dtype=np.float64), (len(before),))
    return kernel(
        before.xy, before.parts, before.feats, after.xy, after.parts, after.feats,
        np.ascontiguousarray(dist),
    )  # fmt: skip


def excess_powers(before: Linework, after: Linework, dist: float) -> np.ndarray:
    """Per feature, the least ``m >= 0`` with ``hausdorff_distance <= dist * 2**m``.

    What ``ceil(log2(shift / dist))`` gives for a shift beyond `dist` (0 within it),
    found by doubling ``m`` and then bisecting, each step one :func:`shifts_within` over the
    features still open. `dist` must be positive.
    """
    n = len(before)
    lo = np.full(n, -1, dtype=np.int64)  # known: shift > dist * 2**lo (-1: nothing known)
    hi = np.full(n, -1, dtype=np.int64)  # known: shift <= dist * 2**hi (-1: not yet)
    m = np.zeros(n, dtype=np.int64)
    while True:  # doubling: m = 0, 1, 2, 4, 8, ...
        todo = np.flatnonzero(hi < 0)
        if not todo.size:
            break
        if m[todo[0]] > MAX_POWER:
            raise ValueError("a shift beyond every power of 2 of the bound")
        ok = _within_powers(before, after, dist, todo, m[todo])
        hi[todo[ok]] = m[todo[ok]]
        lo[todo[~ok]] = m[todo[~ok]]
        m[todo] = np.maximum(2 * m[todo], 1)
    while True:  # bisection: lo < answer <= hi
        todo = np.flatnonzero(hi - lo > 1)
        if not todo.size:
            return hi
        mid = (lo[todo] + hi[todo]) // 2
        ok = _within_powers(before, after, dist, todo, mid)
        hi[todo[ok]] = mid[ok]
        lo[todo[~ok]] = mid[~ok]


def _within_powers(before, after, dist, idx, powers) -> np.ndarray:
    d = np.full(len(before), np.nan)
    d[idx] = np.ldexp(dist, powers)
    return shifts_within(before, after, d)[idx]
