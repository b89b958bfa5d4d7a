"""numba kernels of :mod:`curvesmith._ragged` (imported only for large batches)."""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True, nogil=True)
def drop_closing(P, offsets, closed):
    """The batch without the repeated closing vertex of its closed curves, in one pass.

    A closed curve of at least 2 rows whose last row equals its first (``==`` on every
    column: NaN repeats nothing) loses the last row. Returns the kept rows, their
    offsets, the kept mask over the input rows and, per curve, whether it lost one.
    """
    m = offsets.shape[0] - 1
    d = P.shape[1]
    rep = np.zeros(m, dtype=np.bool_)
    n_drop = 0
    for k in range(m):
        s, e = offsets[k], offsets[k + 1]
        if closed[k] and e - s >= 2:
            same = True
            for c in range(d):
                if P[s, c] != P[e - 1, c]:
                    same = False
            rep[k] = same
            n_drop += same
    kept = np.ones(P.shape[0], dtype=np.bool_)
    out = np.empty((P.shape[0] - n_drop, d))
    new_off = np.empty(m + 1, dtype=np.int64)
    new_off[0] = 0
    pos = 0
    for k in range(m):
        s, e = offsets[k], offsets[k + 1]
        if rep[k]:
            e -= 1
            kept[e] = False
        for i in range(s, e):
            for c in range(d):
                out[pos, c] = P[i, c]
            pos += 1
        new_off[k + 1] = pos
    return out, new_off, kept, rep
