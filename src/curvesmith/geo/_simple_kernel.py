"""numba kernel of :mod:`curvesmith.geo._simple` (imported only when it runs)."""

from __future__ import annotations

import numpy as np
from numba import njit

# Shewchuk's ccwerrboundA = (3 + 16 eps) eps, eps = 2**-53
_CCW_ERR = (3.0 + 16.0 * 2.0**-53) * 2.0**-53
# below this the products may have lost relative accuracy (subnormal range)
_TINY = 1e-280


@njit(cache=True, nogil=True)
def _orient(ax, ay, bx, by, cx, cy):
    """+1 / -1: c is certainly left / right of a -> b; 0: not certain (or NaN)."""
    detleft = (ax - cx) * (by - cy)
    detright = (ay - cy) * (bx - cx)
    det = detleft - detright
    size = abs(detleft) + abs(detright)
    if not size > _TINY:
        return 0
    err = _CCW_ERR * size
    if det > err:
        return 1
    if -det > err:
        return -1
    return 0


@njit(cache=True, nogil=True)
def _side(cx, cy, cid, oa, la, ea0, ea1, ob, lb, xlo, xhi, sign):
    """Signs of chain b's vertices in [xlo, xhi] against chain a: the common sign or 2.

    Chains are stored in increasing x: vertices ``oa .. oa + la`` (``la`` edges) of the
    scratch arrays ``cx, cy`` with their ring positions ``cid``. Returns the sign found
    (``sign`` on entry, 0 = none yet) or 2 when a vertex of b is on or across chain a,
    or its sign is not certain. ``ea0, ea1``: chain a's end vertices (ring positions),
    skipped (shared turning vertices of adjacent chains).
    """
    # first vertex of b at or after xlo (binary search)
    lo, hi = ob, ob + lb + 1
    while lo < hi:
        mid = (lo + hi) >> 1
        if cx[mid] < xlo:
            lo = mid + 1
        else:
            hi = mid
    i = oa  # segment of a: vertices i, i + 1
    last = oa + la - 1
    for t in range(lo, ob + lb + 1):
        x = cx[t]
        if x > xhi:
            break
        r = cid[t]
        if r == ea0 or r == ea1:  # noqa: SIM109 (plain compares in numba)
            continue
        while i < last and cx[i + 1] < x:
            i += 1
        o = _orient(cx[i], cy[i], cx[i + 1], cy[i + 1], x, cy[t])
        if o == 0:
            return 2
        if sign == 0:
            sign = o
        elif o != sign:
            return 2
    return sign


@njit(cache=True, nogil=True)
def _ring_simple(X, s, n, max_chains, starts, lens, ups, bb, co, cx, cy, cid):
    if n < 3:
        return False
    for i in range(n):
        if not (abs(X[s + i, 0]) < np.inf and abs(X[s + i, 1]) < np.inf):
            return False  # NaN or infinite: doubtful
    # direction of every edge; a vertical edge or a repeated vertex: doubtful
    e = X[s, 0] - X[s + n - 1, 0]
    if e > 0.0:
        d_prev = 1
    elif e < 0.0:
        d_prev = -1
    else:
        return False
    nch = 0
    for i in range(n):
        j = s + i + 1 if i + 1 < n else s
        e = X[j, 0] - X[s + i, 0]
        if e > 0.0:
            d = 1
        elif e < 0.0:
            d = -1
        else:
            return False
        if d != d_prev:  # vertex i turns in x: a chain starts here
            if nch == max_chains:
                return False
            starts[nch] = i
            ups[nch] = d > 0
            nch += 1
        d_prev = d
    if nch < 2:
        return False  # not possible for a closed ring of finite coordinates
    # every chain in increasing x into the scratch arrays, with its bounding box
    pos = 0
    for c in range(nch):
        nxt = starts[c + 1] if c + 1 < nch else starts[0] + n
        ln = nxt - starts[c]
        lens[c] = ln
        co[c] = pos
        y0, y1 = np.inf, -np.inf
        for t in range(ln + 1):
            u = starts[c] + (t if ups[c] else ln - t)
            if u >= n:
                u -= n
            cx[pos + t] = X[s + u, 0]
            cy[pos + t] = X[s + u, 1]
            cid[pos + t] = u
            y0 = min(y0, X[s + u, 1])
            y1 = max(y1, X[s + u, 1])
        bb[c, 0], bb[c, 1], bb[c, 2], bb[c, 3] = cx[pos], cx[pos + ln], y0, y1
        pos += ln + 1
    for a in range(nch):
        for b in range(a + 1, nch):
            xlo = max(bb[a, 0], bb[b, 0])
            xhi = min(bb[a, 1], bb[b, 1])
            if xlo > xhi or max(bb[a, 2], bb[b, 2]) > min(bb[a, 3], bb[b, 3]):
                continue  # boxes apart (touching boxes are compared)
            oa, la, ob, lb = co[a], lens[a], co[b], lens[b]
            sg = _side(cx, cy, cid, oa, la, cid[oa], cid[oa + la], ob, lb, xlo, xhi, 0)
            if sg == 2:
                return False
            # chain a's vertices against chain b give the sign of y_a - y_b: flip
            sg2 = _side(cx, cy, cid, ob, lb, cid[ob], cid[ob + lb], oa, la, xlo, xhi, -sg)
            if sg2 == 2:
                return False
            if sg == 0 and sg2 == 0 and xlo != xhi:
                return False  # nothing compared over an overlap of positive length
    return True


@njit(cache=True, nogil=True)
def rings_simple(X, offsets, closing, max_chains):
    m = offsets.shape[0] - 1
    out = np.zeros(m, dtype=np.bool_)
    nmax = 1
    for k in range(m):
        nmax = max(nmax, offsets[k + 1] - offsets[k])
    starts = np.empty(max_chains, dtype=np.int64)
    lens = np.empty(max_chains, dtype=np.int64)
    co = np.empty(max_chains, dtype=np.int64)
    ups = np.empty(max_chains, dtype=np.bool_)
    bb = np.empty((max_chains, 4))
    cx = np.empty(nmax + max_chains + 1)
    cy = np.empty(nmax + max_chains + 1)
    cid = np.empty(nmax + max_chains + 1, dtype=np.int64)
    for k in range(m):
        s = offsets[k]
        n = offsets[k + 1] - s
        if closing:
            if n < 1 or X[s, 0] != X[s + n - 1, 0] or X[s, 1] != X[s + n - 1, 1]:
                continue  # not closed: doubtful
            n -= 1
        out[k] = _ring_simple(X, s, n, max_chains, starts, lens, ups, bb, co, cx, cy, cid)
    return out
