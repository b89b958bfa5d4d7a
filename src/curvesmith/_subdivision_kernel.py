"""numba kernel of the ragged de Rham / Chaikin step of :mod:`curvesmith.subdivision`.

Imported only for large batches. Every curve runs all its steps in scratch arrays (it
stays in the cache) and its last step writes straight into the output. The arithmetic
is the numpy step's operation by operation (``d = (b - a) * beta``, then ``a + d`` and
``b - d``; numba compiles without fused multiply-adds), so the rows are the same bits.
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True, nogil=True, inline="always")
def _step(src, n, closed, ends, beta, dst):
    """One de Rham step of ``src[:n]`` into ``dst``; returns the number of rows written."""
    d = src.shape[1]
    pos = 0
    if ends:
        for c in range(d):
            dst[0, c] = src[0, c]
        pos = 1
    n_edges = n if closed else n - 1
    for i in range(n_edges):
        j = i + 1 if i + 1 < n else 0
        for c in range(d):
            step = src[j, c] - src[i, c]
            step *= beta
            dst[pos, c] = src[i, c] + step
            dst[pos + 1, c] = src[j, c] - step
        pos += 2
    if ends:
        for c in range(d):
            dst[pos, c] = src[n - 1, c]
        pos += 1
    return pos


@njit(cache=True, nogil=True)
def de_rham_ragged(P, offsets, closed, beta, keep_ends, iterations, out_offsets, close_out):
    """``iterations`` steps of every curve; curve ``k`` goes to ``out_offsets[k]`` onwards.

    ``out_offsets`` (from the caller) hold each curve's final length, plus one row per
    closed curve with ``close_out`` (its first row repeated at its end).
    """
    m = offsets.shape[0] - 1
    d = P.shape[1]
    OUT = np.empty((out_offsets[m], d))
    big = 1
    for k in range(m):
        big = max(big, out_offsets[k + 1] - out_offsets[k])
    A = np.empty((big, d))
    B = np.empty((big, d))
    for k in range(m):
        s, e = offsets[k], offsets[k + 1]
        o = out_offsets[k]
        cl = closed[k]
        ends = keep_ends and not cl
        n = e - s
        src = P[s:e]
        for it in range(iterations):
            last = it == iterations - 1
            dst = OUT[o:] if last else (A if it % 2 == 0 else B)
            n = _step(src, n, cl, ends, beta, dst)
            src = dst
        if close_out and cl and n > 0:
            for c in range(d):
                OUT[o + n, c] = OUT[o, c]
    return OUT
