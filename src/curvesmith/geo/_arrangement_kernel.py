"""numba kernel of the segment arrangement (imported only when it runs).

Given many polylines, find the pairs of segments that meet anywhere other than at a
vertex both are allowed to share: the end vertices of two different open polylines (a
node of a coverage, the shared end of two pieces of an arc), the common vertex of two
consecutive segments of one polyline, and the closing vertex of a closed one. The
segments are boxed in chunks of consecutive ones, the chunks go into a uniform grid,
and of every pair of chunks whose boxes meet the segments that reach the other box are
compared (:func:`segment_meetings`).

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


#: Consecutive segments of a polyline are boxed together in chunks of this many.
CHUNK = 16


@njit(cache=True, nogil=True)
def _grow(rec):
    bigger = np.empty((2 * rec.shape[0], 3), dtype=np.int64)
    bigger[: rec.shape[0]] = rec
    return bigger


@njit(cache=True, nogil=True)
def _seg_box_meets(X, t, x0, x1, y0, y1):
    return (
        min(X[t, 0], X[t + 1, 0]) <= x1
        and max(X[t, 0], X[t + 1, 0]) >= x0
        and min(X[t, 1], X[t + 1, 1]) <= y1
        and max(X[t, 1], X[t + 1, 1]) >= y0
    )


@njit(cache=True, nogil=True)
def _compare(X, offsets, loop, p, ta, q, tb):
    """The verdict on segments ``ta`` (of polyline p) and ``tb`` (of q).

    -1: nothing to record (boxes apart, disjoint, or an allowed contact within one
    polyline).
    """
    if not _seg_box_meets(
        X, tb, min(X[ta, 0], X[ta + 1, 0]), max(X[ta, 0], X[ta + 1, 0]),
        min(X[ta, 1], X[ta + 1, 1]), max(X[ta, 1], X[ta + 1, 1]),
    ):  # fmt: skip
        return -1
    if ta > tb:
        ta, tb = tb, ta
        p, q = q, p
    ok = _allowed(X, offsets, p, ta, q, tb, loop)
    v = classify(X[ta, 0], X[ta, 1], X[ta + 1, 0], X[ta + 1, 1],
                 X[tb, 0], X[tb, 1], X[tb + 1, 0], X[tb + 1, 1], ok)  # fmt: skip
    if v == DISJOINT or (v == TOUCH and p == q):
        return -1
    return v


@njit(cache=True, nogil=True)
def _monotone(X, t0, t1):
    """How segments ``t0 .. t1 - 1`` are strictly monotone: ``(in_x, in_y)``.

    Each is 1 (increasing), -1 (decreasing) or 0 (neither).
    Monotone segments meet only where consecutive ones share their vertex: the x (or y)
    ranges of non-consecutive segments are disjoint, and no segment turns back along the
    previous one or has length zero; two runs of consecutive segments that are monotone
    the same way in x (or y) form one monotone run. Exact: signs of differences of
    coordinates. A chunk of a smoothed curve turns by less than a right angle, so it is
    monotone in x or in y.
    """
    sx = 1 if X[t0 + 1, 0] > X[t0, 0] else -1
    sy = 1 if X[t0 + 1, 1] > X[t0, 1] else -1
    for t in range(t0, t1):
        dx = X[t + 1, 0] - X[t, 0]
        dy = X[t + 1, 1] - X[t, 1]
        if sx != 0 and not ((dx > 0.0) if sx > 0 else (dx < 0.0)):
            sx = 0
        if sy != 0 and not ((dy > 0.0) if sy > 0 else (dy < 0.0)):
            sy = 0
        if sx == 0 and sy == 0:
            break
    return sx, sy


@njit(cache=True, nogil=True)
def _within_chunks(X, offsets, loop, group, c0, c1, cp, mono, rec, nrec):
    """The meetings of segment pairs within one chunk, appended to ``rec[:nrec]``.

    ``mono``: per chunk, :func:`_monotone` (a monotone chunk has none).
    """
    buf = np.empty((CHUNK * CHUNK, 2), dtype=np.int64)
    for c in range(c0.shape[0]):
        p = cp[c]
        if group[p] < 0 or mono[c, 0] != 0 or mono[c, 1] != 0:
            continue
        nb = 0  # consecutive segments: they overlap only along one ray
        for ta in range(c0[c], c1[c] - 1):
            tb = ta + 1
            v = _same_ray(X[tb, 0], X[tb, 1], X[ta, 0], X[ta, 1], X[tb + 1, 0], X[tb + 1, 1])
            zero = (X[ta, 0] == X[tb, 0] and X[ta, 1] == X[tb, 1]) or (
                X[tb, 0] == X[tb + 1, 0] and X[tb, 1] == X[tb + 1, 1]
            )
            if v != 0 or zero:
                buf[nb, 0] = ta
                buf[nb, 1] = MEET if (v == 1 and not zero) else DOUBT
                nb += 1
        for u in range(nb):
            if nrec == rec.shape[0]:
                rec = _grow(rec)
            rec[nrec, 0], rec[nrec, 1], rec[nrec, 2] = buf[u, 0], buf[u, 0] + 1, buf[u, 1]
            nrec += 1
        nb = 0  # non-consecutive pairs with meeting boxes, compared after the scan
        for ta in range(c0[c], c1[c] - 2):
            x0, x1 = min(X[ta, 0], X[ta + 1, 0]), max(X[ta, 0], X[ta + 1, 0])
            y0, y1 = min(X[ta, 1], X[ta + 1, 1]), max(X[ta, 1], X[ta + 1, 1])
            for tb in range(ta + 2, c1[c]):
                if _seg_box_meets(X, tb, x0, x1, y0, y1):
                    buf[nb, 0], buf[nb, 1] = ta, tb
                    nb += 1
        for u in range(nb):
            ta, tb = buf[u, 0], buf[u, 1]
            v = _compare(X, offsets, loop, p, ta, p, tb)
            if v >= 0:
                if nrec == rec.shape[0]:
                    rec = _grow(rec)
                rec[nrec, 0], rec[nrec, 1], rec[nrec, 2] = ta, tb, v
                nrec += 1
    return rec, nrec


@njit(cache=True, nogil=True)
def segment_meetings(X, offsets, loop, group, need, self_pairs):
    """Segment pairs of the polylines that meet (MEET, DOUBT or TOUCH).

    Polyline ``p`` is ``X[offsets[p]:offsets[p + 1]]`` (a closed one repeats its first
    vertex at the end). Pairs of two polylines are compared when both have the same
    ``group`` (>= 0) and ``need`` is set for at least one of them; with `self_pairs` the
    segments of one polyline are compared too. ``loop[p]``: a closed loop without a node,
    whose vertices no other polyline may share.

    Consecutive segments are boxed in chunks of `CHUNK`; the chunks go into a uniform grid
    (every cell their box covers, each cell's list in increasing ``x0``), the chunk pairs
    of a cell are swept in x and compared in the one cell that holds the lower-left corner
    of the overlap of their boxes, and of a chunk pair only the segments that reach the
    other chunk's box are compared.

    Returns ``(ok, seg_a, seg_b, verdict)``: ``ok`` is False when a coordinate is not
    finite or too large for the filter (nothing was compared); segments are numbered by
    their first vertex's row in `X` (``seg_a < seg_b``). The allowed contacts of a
    polyline with itself (TOUCH) are not returned.
    """
    npoly = offsets.shape[0] - 1
    nch = 0
    for p in range(npoly):
        nseg = offsets[p + 1] - offsets[p] - 1
        if nseg > 0:
            nch += (nseg + CHUNK - 1) // CHUNK
    rec = np.empty((1024, 3), dtype=np.int64)
    if nch == 0:
        return True, rec[:0, 0].copy(), rec[:0, 1].copy(), rec[:0, 2].astype(np.int8)
    c0 = np.empty(nch, dtype=np.int64)  # first segment (row) of the chunk
    c1 = np.empty(nch, dtype=np.int64)  # one past its last segment
    cp = np.empty(nch, dtype=np.int64)  # its polyline
    bx0 = np.empty(nch)
    bx1 = np.empty(nch)
    by0 = np.empty(nch)
    by1 = np.empty(nch)
    k = 0
    gx0, gx1, gy0, gy1 = np.inf, -np.inf, np.inf, -np.inf
    ext = 0.0
    for p in range(npoly):
        for t0 in range(offsets[p], offsets[p + 1] - 1, CHUNK):
            t1 = min(t0 + CHUNK, offsets[p + 1] - 1)
            x0, x1, y0, y1 = np.inf, -np.inf, np.inf, -np.inf
            for t in range(t0, t1 + 1):
                xt, yt = X[t, 0], X[t, 1]
                if not (abs(xt) < _BIG and abs(yt) < _BIG):
                    return False, rec[:0, 0].copy(), rec[:0, 1].copy(), rec[:0, 2].astype(np.int8)
                x0, x1 = min(x0, xt), max(x1, xt)
                y0, y1 = min(y0, yt), max(y1, yt)
            c0[k], c1[k], cp[k] = t0, t1, p
            bx0[k], bx1[k], by0[k], by1[k] = x0, x1, y0, y1
            gx0, gx1 = min(gx0, x0), max(gx1, x1)
            gy0, gy1 = min(gy0, y0), max(gy1, y1)
            ext += max(x1 - x0, y1 - y0)
            k += 1
    # cell size: twice the mean chunk extent, and at most ~4 cells per chunk
    w, hgt = gx1 - gx0, gy1 - gy0
    h = max(2.0 * ext / nch, np.sqrt(w * hgt / (4.0 * nch)), 1e-300)
    nx = min(int(w / h) + 1, 1 << 15)
    ny = min(int(hgt / h) + 1, 1 << 15)
    hx = max(w / nx, 1e-300) * (1.0 + 1e-12)
    hy = max(hgt / ny, 1e-300) * (1.0 + 1e-12)
    cnt = np.zeros(nx * ny + 1, dtype=np.int64)
    for c in range(nch):
        i0 = min(int((bx0[c] - gx0) / hx), nx - 1)
        i1 = min(int((bx1[c] - gx0) / hx), nx - 1)
        j0 = min(int((by0[c] - gy0) / hy), ny - 1)
        j1 = min(int((by1[c] - gy0) / hy), ny - 1)
        for j in range(j0, j1 + 1):
            for i in range(i0, i1 + 1):
                cnt[j * nx + i + 1] += 1
    for c in range(nx * ny):
        cnt[c + 1] += cnt[c]
    ent = np.empty(cnt[nx * ny], dtype=np.int64)
    fill = cnt[:-1].copy()
    for c in range(nch):
        i0 = min(int((bx0[c] - gx0) / hx), nx - 1)
        i1 = min(int((bx1[c] - gx0) / hx), nx - 1)
        j0 = min(int((by0[c] - gy0) / hy), ny - 1)
        j1 = min(int((by1[c] - gy0) / hy), ny - 1)
        for j in range(j0, j1 + 1):
            for i in range(i0, i1 + 1):
                cell = j * nx + i
                ent[fill[cell]] = c
                fill[cell] += 1
    # every cell's list in increasing x0, ties in chunk order (the order a stable sort of
    # all chunks gave, at half its cost: a cell holds a few chunks, filled in chunk order)
    for cell in range(nx * ny):
        lo, hi = cnt[cell], cnt[cell + 1]
        if hi - lo > 32:  # a crowded cell (chunks of very uneven size): a stable sort
            part = ent[lo:hi].copy()
            ent[lo:hi] = part[np.argsort(bx0[part], kind="mergesort")]
            continue
        for m in range(lo + 1, hi):
            c = ent[m]
            x = bx0[c]
            n = m - 1
            while n >= lo and bx0[ent[n]] > x:
                ent[n + 1] = ent[n]
                n -= 1
            ent[n + 1] = c
    nrec = 0
    buf_a = np.empty(CHUNK, dtype=np.int64)
    buf_b = np.empty(CHUNK, dtype=np.int64)
    mono = np.zeros((nch if self_pairs else 0, 2), dtype=np.int64)
    if self_pairs:  # the segment pairs within one chunk
        for c in range(nch):
            mono[c, 0], mono[c, 1] = _monotone(X, c0[c], c1[c])
        rec, nrec = _within_chunks(X, offsets, loop, group, c0, c1, cp, mono, rec, nrec)
    for cell in range(nx * ny):
        e0, e1 = cnt[cell], cnt[cell + 1]
        ci, cj = cell % nx, cell // nx
        for m in range(e0, e1):
            a = ent[m]
            p = cp[a]
            gp = group[p]
            if gp < 0:
                continue
            for n in range(m + 1, e1):
                b = ent[n]
                if bx0[b] > bx1[a]:
                    break
                if by0[b] > by1[a] or by1[b] < by0[a]:
                    continue
                q = cp[b]
                if p == q:
                    if not self_pairs:
                        continue
                    # consecutive chunks monotone the same way: one monotone run
                    same_way = (mono[a, 0] != 0 and mono[a, 0] == mono[b, 0]) or (
                        mono[a, 1] != 0 and mono[a, 1] == mono[b, 1]
                    )
                    if same_way and (c1[a] == c0[b] or c1[b] == c0[a]):
                        continue
                elif group[q] != gp or not (need[p] or need[q]):
                    continue
                # compare the pair only in the cell of the lower-left corner of the overlap
                lx = max(bx0[a], bx0[b])
                ly = max(by0[a], by0[b])
                if min(int((lx - gx0) / hx), nx - 1) != ci:
                    continue
                if min(int((ly - gy0) / hy), ny - 1) != cj:
                    continue
                na = 0
                for t in range(c0[a], c1[a]):
                    if _seg_box_meets(X, t, bx0[b], bx1[b], by0[b], by1[b]):
                        buf_a[na] = t
                        na += 1
                nb = 0
                for t in range(c0[b], c1[b]):
                    if _seg_box_meets(X, t, bx0[a], bx1[a], by0[a], by1[a]):
                        buf_b[nb] = t
                        nb += 1
                for u in range(na):
                    for w_ in range(nb):
                        ta, tb = buf_a[u], buf_b[w_]
                        v = _compare(X, offsets, loop, p, ta, q, tb)
                        if v >= 0:
                            if nrec == rec.shape[0]:
                                rec = _grow(rec)
                            rec[nrec, 0], rec[nrec, 1] = min(ta, tb), max(ta, tb)
                            rec[nrec, 2] = v
                            nrec += 1
    return True, rec[:nrec, 0].copy(), rec[:nrec, 1].copy(), rec[:nrec, 2].astype(np.int8)


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


def gather_rings(A, a_off, loops, use_arc, use_fwd, ring_off_uses, closed_loops=False):
    """Closed rings from the arcs ``A[a_off[k]:a_off[k + 1]]``: ``(coordinates, offsets)``.

    Ring ``r`` is its uses ``ring_off_uses[r] .. ring_off_uses[r + 1] - 1`` in order: arc
    ``use_arc[u]``, reversed unless ``use_fwd[u]``, without its last vertex unless it is
    a loop; then its first vertex again. With `closed_loops` the loops in `A` repeat their
    first vertex at the end (the layout of the arrangement's polylines); it is skipped.

    The output is allocated by numpy, which asks for huge pages for large arrays: a
    coverage's rings are millions of vertices, and numba's allocator (malloc) touches
    them page by page (the US counties' 9.2 M ring vertices: 0.11-0.13 s against
    0.03 s on the 2-core machine).
    """
    offs = _ring_offsets(a_off, loops, use_arc, ring_off_uses, closed_loops)
    out = np.empty((offs[-1], 2))
    _fill_rings(A, a_off, loops, use_arc, use_fwd, ring_off_uses, closed_loops, offs, out)
    return out, offs


@njit(cache=True, nogil=True)
def _ring_offsets(a_off, loops, use_arc, ring_off_uses, closed_loops):
    n_rings = ring_off_uses.shape[0] - 1
    offs = np.zeros(n_rings + 1, dtype=np.int64)
    for r in range(n_rings):
        n = 1
        for u in range(ring_off_uses[r], ring_off_uses[r + 1]):
            k = use_arc[u]
            n += a_off[k + 1] - a_off[k] - 1
            if loops[k] and not closed_loops:
                n += 1
        offs[r + 1] = offs[r] + n
    return offs


@njit(cache=True, nogil=True)
def _fill_rings(A, a_off, loops, use_arc, use_fwd, ring_off_uses, closed_loops, offs, out):
    n_rings = ring_off_uses.shape[0] - 1
    for r in range(n_rings):
        w = offs[r]
        for u in range(ring_off_uses[r], ring_off_uses[r + 1]):
            k = use_arc[u]
            s, e = a_off[k], a_off[k + 1]
            if loops[k] and closed_loops:
                e -= 1
            m = e - s - (0 if loops[k] else 1)
            if use_fwd[u]:
                for t in range(m):
                    out[w + t, 0] = A[s + t, 0]
                    out[w + t, 1] = A[s + t, 1]
            else:
                for t in range(m):
                    out[w + t, 0] = A[e - 1 - t, 0]
                    out[w + t, 1] = A[e - 1 - t, 1]
            w += m
        out[w, 0] = out[offs[r], 0]
        out[w, 1] = out[offs[r], 1]
