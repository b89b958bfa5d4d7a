"""numba kernel of the segment arrangement (imported only when it runs).

Given many polylines, find the pairs of segments that meet anywhere other than at a
vertex both are allowed to share: the end vertices of two different open polylines (a
node of a coverage, the shared end of two pieces of an arc), the common vertex of two
consecutive segments of one polyline, and the closing vertex of a closed one. The
segments go into a uniform grid (every cell its box covers, filled in increasing
``x0`` so that each cell's list is sorted); the pairs of a cell are swept in ``x`` and
each pair is compared in the one cell that holds the lower-left corner of the
intersection of the two boxes, so it is compared once.

Every decision is exact or "doubtful": the orientation signs come from Shewchuk's
filtered determinant (:func:`curvesmith.geo._simple_kernel._orient`, a sign it cannot
certify is 0) and the other tests are exact comparisons of coordinates. A segment pair
that the filter cannot decide is returned as doubtful; the caller decides those with
exact rational arithmetic (:func:`curvesmith.geo._arrangement.classify_exact`).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from ._simple_kernel import _BIG, _orient

#: Segment-pair verdicts.
DISJOINT, MEET, DOUBT, TOUCH = 0, 1, 2, 3


@njit(cache=True, nogil=True)
def _same_ray(px, py, qx, qy, rx, ry):
    """1: q and r lie on one ray from p (collinear overlap), 0: not, 2: doubtful."""
    sx = (qx > px) - (qx < px)
    tx = (rx > px) - (rx < px)
    sy = (qy > py) - (qy < py)
    ty = (ry > py) - (ry < py)
    if sx != tx or sy != ty:
        return 0
    o = _orient(px, py, qx, qy, rx, ry)
    if o != 0:
        return 0
    return 2


@njit(cache=True, nogil=True)
def classify(ax, ay, bx, by, cx, cy, dx, dy, ok):
    """How segments a-b and c-d meet: DISJOINT, MEET (somewhere not allowed), DOUBT, TOUCH.

    `ok` has bit 0 set when a = c may be shared, bit 1 for a = d, bit 2 for b = c, bit 3
    for b = d. TOUCH: the segments meet only in one vertex they share and may share.
    The caller has checked that the closed boxes of the segments overlap.
    """
    if (ax == bx and ay == by) or (cx == dx and cy == dy):
        return DOUBT  # a zero-length segment: left to the exact test
    ac = ax == cx and ay == cy
    ad = ax == dx and ay == dy
    bc = bx == cx and by == cy
    bd = bx == dx and by == dy
    if (ac and bd) or (ad and bc):
        return MEET  # the same segment twice
    if ac or ad or bc or bd:
        if ac:
            r, bit = _same_ray(ax, ay, bx, by, dx, dy), 1
        elif ad:
            r, bit = _same_ray(ax, ay, bx, by, cx, cy), 2
        elif bc:
            r, bit = _same_ray(bx, by, ax, ay, dx, dy), 4
        else:
            r, bit = _same_ray(bx, by, ax, ay, cx, cy), 8
        if r == 2:
            return DOUBT
        if r == 1:
            return MEET
        return TOUCH if ok & bit else MEET
    o1 = _orient(ax, ay, bx, by, cx, cy)
    o2 = _orient(ax, ay, bx, by, dx, dy)
    if o1 != 0 and o1 == o2:
        return DISJOINT
    o3 = _orient(cx, cy, dx, dy, ax, ay)
    o4 = _orient(cx, cy, dx, dy, bx, by)
    if o3 != 0 and o3 == o4:
        return DISJOINT
    if o1 != 0 and o2 != 0 and o3 != 0 and o4 != 0:
        return MEET  # a proper crossing
    return DOUBT


@njit(cache=True, nogil=True)
def _at_end(X, s0, s1, t):
    """Whether vertex t has the coordinates of an end vertex of polyline ``X[s0:s1]``."""
    return (X[t, 0] == X[s0, 0] and X[t, 1] == X[s0, 1]) or (
        X[t, 0] == X[s1 - 1, 0] and X[t, 1] == X[s1 - 1, 1]
    )


@njit(cache=True, nogil=True)
def _allowed(X, offsets, p, i, q, j, loop):
    """The `ok` bits of :func:`classify` for segments ``i < j`` (rows of `X`).

    Segment ``i`` belongs to polyline ``p``, segment ``j`` to polyline ``q``.

    Within one polyline: the common vertex of consecutive segments, and the closing vertex
    of a closed one. Between two: a vertex at the coordinates of an end of both (GEOS'
    boundary of a LineString, also where the line passes there again), none for a loop.
    """
    s0, s1 = offsets[p], offsets[p + 1]
    ok = 0
    if p == q:
        if j == i + 1:
            ok |= 4  # b = c: the common vertex of consecutive segments
        closed = X[s0, 0] == X[s1 - 1, 0] and X[s0, 1] == X[s1 - 1, 1]
        if closed and i == s0 and j == s1 - 2:
            ok |= 2  # a = d: the closing vertex
        return ok
    if loop[p] or loop[q]:
        return 0
    r0, r1 = offsets[q], offsets[q + 1]
    ae = _at_end(X, s0, s1, i) and _at_end(X, r0, r1, i)
    be = _at_end(X, s0, s1, i + 1) and _at_end(X, r0, r1, i + 1)
    ce = _at_end(X, r0, r1, j) and _at_end(X, s0, s1, j)
    de = _at_end(X, r0, r1, j + 1) and _at_end(X, s0, s1, j + 1)
    if ae and ce:
        ok |= 1
    if ae and de:
        ok |= 2
    if be and ce:
        ok |= 4
    if be and de:
        ok |= 8
    return ok


@njit(cache=True, nogil=True)
def segment_meetings(X, offsets, loop, group, need, self_pairs):
    """Segment pairs of the polylines that meet (MEET, DOUBT or TOUCH).

    Polyline ``p`` is ``X[offsets[p]:offsets[p + 1]]`` (a closed one repeats its first
    vertex at the end). Pairs of two polylines are compared when both have the same
    ``group`` (>= 0) and ``need`` is set for at least one of them; with `self_pairs` the
    segments of one polyline are compared too. ``loop[p]``: a closed loop without a node,
    whose vertices no other polyline may share.

    Returns ``(ok, seg_a, seg_b, verdict)``: ``ok`` is False when a coordinate is not
    finite or too large for the filter (nothing was compared); segments are numbered by
    their first vertex's row in `X` (``seg_a < seg_b``). The allowed contacts of a
    polyline with itself (TOUCH) are not returned.
    """
    npoly = offsets.shape[0] - 1
    nseg = 0
    for p in range(npoly):
        nseg += max(offsets[p + 1] - offsets[p] - 1, 0)
    seg = np.empty(nseg, dtype=np.int64)
    own = np.empty(nseg, dtype=np.int64)
    k = 0
    for p in range(npoly):
        for t in range(offsets[p], offsets[p + 1] - 1):
            seg[k] = t
            own[k] = p
            k += 1
    empty = np.empty(0, dtype=np.int64)
    if nseg == 0:
        return True, empty, empty.copy(), np.empty(0, dtype=np.int8)
    bx0 = np.empty(nseg)
    bx1 = np.empty(nseg)
    by0 = np.empty(nseg)
    by1 = np.empty(nseg)
    gx0, gx1, gy0, gy1 = np.inf, -np.inf, np.inf, -np.inf
    ext = 0.0
    for s in range(nseg):
        t = seg[s]
        xa, ya, xb, yb = X[t, 0], X[t, 1], X[t + 1, 0], X[t + 1, 1]
        if not (abs(xa) < _BIG and abs(ya) < _BIG and abs(xb) < _BIG and abs(yb) < _BIG):
            return False, empty, empty.copy(), np.empty(0, dtype=np.int8)
        bx0[s], bx1[s] = min(xa, xb), max(xa, xb)
        by0[s], by1[s] = min(ya, yb), max(ya, yb)
        gx0, gx1 = min(gx0, bx0[s]), max(gx1, bx1[s])
        gy0, gy1 = min(gy0, by0[s]), max(gy1, by1[s])
        ext += max(bx1[s] - bx0[s], by1[s] - by0[s])
    # cell size: twice the mean segment extent, and at most ~2 cells per segment
    w, hgt = gx1 - gx0, gy1 - gy0
    h = max(2.0 * ext / nseg, np.sqrt(w * hgt / (2.0 * nseg)), 1e-300)
    nx = min(int(w / h) + 1, 1 << 15)
    ny = min(int(hgt / h) + 1, 1 << 15)
    hx = max(w / nx, 1e-300) * (1.0 + 1e-12)
    hy = max(hgt / ny, 1e-300) * (1.0 + 1e-12)
    cnt = np.zeros(nx * ny + 1, dtype=np.int64)
    for s in range(nseg):
        i0 = min(int((bx0[s] - gx0) / hx), nx - 1)
        i1 = min(int((bx1[s] - gx0) / hx), nx - 1)
        j0 = min(int((by0[s] - gy0) / hy), ny - 1)
        j1 = min(int((by1[s] - gy0) / hy), ny - 1)
        for j in range(j0, j1 + 1):
            for i in range(i0, i1 + 1):
                cnt[j * nx + i + 1] += 1
    for c in range(nx * ny):
        cnt[c + 1] += cnt[c]
    ent = np.empty(cnt[nx * ny], dtype=np.int64)
    fill = cnt[:-1].copy()
    for s in np.argsort(bx0, kind="mergesort"):
        i0 = min(int((bx0[s] - gx0) / hx), nx - 1)
        i1 = min(int((bx1[s] - gx0) / hx), nx - 1)
        j0 = min(int((by0[s] - gy0) / hy), ny - 1)
        j1 = min(int((by1[s] - gy0) / hy), ny - 1)
        for j in range(j0, j1 + 1):
            for i in range(i0, i1 + 1):
                c = j * nx + i
                ent[fill[c]] = s
                fill[c] += 1
    cap = 1024
    ra = np.empty(cap, dtype=np.int64)
    rb = np.empty(cap, dtype=np.int64)
    rv = np.empty(cap, dtype=np.int8)
    nrec = 0
    for c in range(nx * ny):
        e0, e1 = cnt[c], cnt[c + 1]
        ci, cj = c % nx, c // nx
        for m in range(e0, e1):
            s = ent[m]
            p = own[s]
            gp = group[p]
            if gp < 0:
                continue
            for n in range(m + 1, e1):
                u = ent[n]
                if bx0[u] > bx1[s]:
                    break
                if by0[u] > by1[s] or by1[u] < by0[s]:
                    continue
                q = own[u]
                if p == q:
                    if not self_pairs:
                        continue
                elif group[q] != gp or not (need[p] or need[q]):
                    continue
                # compare the pair only in the cell of the lower-left corner of the overlap
                lx = max(bx0[s], bx0[u])
                ly = max(by0[s], by0[u])
                if min(int((lx - gx0) / hx), nx - 1) != ci:
                    continue
                if min(int((ly - gy0) / hy), ny - 1) != cj:
                    continue
                ta, tb = seg[s], seg[u]
                pa, pb = p, q
                if ta > tb:
                    ta, tb = tb, ta
                    pa, pb = q, p
                ok = _allowed(X, offsets, pa, ta, pb, tb, loop)
                v = classify(X[ta, 0], X[ta, 1], X[ta + 1, 0], X[ta + 1, 1],
                             X[tb, 0], X[tb, 1], X[tb + 1, 0], X[tb + 1, 1], ok)  # fmt: skip
                if v == DISJOINT or (v == TOUCH and pa == pb):
                    continue
                if nrec == cap:
                    cap *= 2
                    ra2 = np.empty(cap, dtype=np.int64)
                    rb2 = np.empty(cap, dtype=np.int64)
                    rv2 = np.empty(cap, dtype=np.int8)
                    ra2[:nrec] = ra[:nrec]
                    rb2[:nrec] = rb[:nrec]
                    rv2[:nrec] = rv[:nrec]
                    ra, rb, rv = ra2, rb2, rv2
                ra[nrec] = ta
                rb[nrec] = tb
                rv[nrec] = v
                nrec += 1
    return True, ra[:nrec].copy(), rb[:nrec].copy(), rv[:nrec].copy()


@njit(cache=True, nogil=True)
def ring_orientation(X, offsets):
    """Per closed ring ``X[offsets[r]:offsets[r + 1]]``: +1 counterclockwise, -1 clockwise.

    0: doubtful. The sign of the turn at the lexicographically smallest vertex, which is
    the ring's orientation when the ring is simple.
    """
    m = offsets.shape[0] - 1
    out = np.zeros(m, dtype=np.int8)
    for r in range(m):
        s, e = offsets[r], offsets[r + 1] - 1  # e: the repeated closing vertex
        n = e - s
        if n < 3:
            continue
        k = s
        for t in range(s + 1, e):
            if X[t, 0] < X[k, 0] or (X[t, 0] == X[k, 0] and X[t, 1] < X[k, 1]):
                k = t
        p = k - 1 if k > s else e - 1
        q = k + 1
        out[r] = _orient(X[p, 0], X[p, 1], X[k, 0], X[k, 1], X[q, 0], X[q, 1])
    return out


# ----------------------------------------------------------------- exact fallback (Python)


def _sign(v) -> int:
    return (v > 0) - (v < 0)


def orient_exact(a, b, c) -> int:
    """Exact sign of the orientation of c against a -> b (+1: left), in rationals."""
    from fractions import Fraction as F

    ax, ay, bx, by, cx, cy = (F(float(v)) for v in (*a, *b, *c))
    return _sign((ax - cx) * (by - cy) - (ay - cy) * (bx - cx))


def classify_exact(a, b, c, d, ok: int) -> int:
    """:func:`classify` in exact rational arithmetic (never DOUBT): the reference."""
    from fractions import Fraction as F

    A, B, C, D = (tuple(F(float(v)) for v in p) for p in (a, b, c, d))

    def on_segment(p, s, t):
        if s == t:
            return p == s
        return (
            orient_exact(s, t, p) == 0
            and min(s[0], t[0]) <= p[0] <= max(s[0], t[0])
            and min(s[1], t[1]) <= p[1] <= max(s[1], t[1])
        )

    point = None
    if A == B or C == D:
        if A == B and on_segment(A, C, D):
            point = A
        elif C == D and on_segment(C, A, B):
            point = C
        else:
            return DISJOINT
    else:
        o1, o2 = orient_exact(A, B, C), orient_exact(A, B, D)
        o3, o4 = orient_exact(C, D, A), orient_exact(C, D, B)
        if o1 == 0 and o2 == 0:  # collinear: overlap of the projections
            ax = 0 if A[0] != B[0] else 1
            lo = max(min(A[ax], B[ax]), min(C[ax], D[ax]))
            hi = min(max(A[ax], B[ax]), max(C[ax], D[ax]))
            if lo > hi:
                return DISJOINT
            if lo < hi:
                return MEET
            point = next(p for p in (A, B) if p[ax] == lo)
        else:
            if o1 * o2 > 0 or o3 * o4 > 0:
                return DISJOINT
            ux, uy = B[0] - A[0], B[1] - A[1]
            vx, vy = D[0] - C[0], D[1] - C[1]
            den = ux * vy - uy * vx
            t = ((C[0] - A[0]) * vy - (C[1] - A[1]) * vx) / den
            point = (A[0] + t * ux, A[1] + t * uy)
    for bit, (p, q) in ((1, (A, C)), (2, (A, D)), (4, (B, C)), (8, (B, D))):
        if ok & bit and p == point and q == point:
            return TOUCH
    return MEET


#: More doubtful segment pairs than this are not decided in rationals (the caller
#: falls back to GEOS).
MAX_DOUBTFUL = 20_000


def meetings(X, offsets, loop, group, need, *, self_pairs: bool):
    """Segment pairs that meet, decided exactly: ``(seg_a, seg_b, verdict)`` or None.

    :func:`segment_meetings` with its doubtful pairs decided by :func:`classify_exact`;
    verdicts are MEET or TOUCH. None when the filter could not run (coordinates not
    finite or beyond ``2**500``) or left more than `MAX_DOUBTFUL` pairs undecided.
    """
    X = np.ascontiguousarray(X, dtype=np.float64)
    offsets = np.asarray(offsets, dtype=np.int64)
    ok, sa, sb, v = segment_meetings(
        X,
        offsets,
        np.asarray(loop, dtype=np.bool_),
        np.asarray(group, dtype=np.int64),
        np.asarray(need, dtype=np.bool_),
        bool(self_pairs),
    )
    if not ok:
        return None
    doubt = np.flatnonzero(v == DOUBT)
    if doubt.size > MAX_DOUBTFUL:
        return None
    if doubt.size:
        owner = np.searchsorted(offsets, np.concatenate([sa[doubt], sb[doubt]]), "right") - 1
        pa, pb = owner[: doubt.size], owner[doubt.size :]
        lp = np.asarray(loop, dtype=np.bool_)
        for k, i, j, p, q in zip(doubt, sa[doubt], sb[doubt], pa, pb, strict=True):
            bits = int(_allowed(X, offsets, int(p), int(i), int(q), int(j), lp))
            v[k] = classify_exact(X[i], X[i + 1], X[j], X[j + 1], bits)
        keep = v != DISJOINT
        sa, sb, v = sa[keep], sb[keep], v[keep]
    return sa, sb, v
