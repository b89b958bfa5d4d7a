"""numba kernel of :mod:`curvesmith.geo._simple` (imported only when it runs)."""

from __future__ import annotations

import numpy as np
from numba import njit

# Shewchuk's ccwerrboundA = (3 + 16 eps) eps, eps = 2**-53
_CCW_ERR = (3.0 + 16.0 * 2.0**-53) * 2.0**-53
# below this the products may have lost relative accuracy (subnormal range)
_TINY = 1e-280
# coordinates at least this large are doubtful: the products of their differences could
# overflow (the exact comparisons of the y shortcut would not see it)
_BIG = 2.0**500


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
def _pair(cx, cy, cid, oa, la, ob, lb, xlo, xhi):
    """Sign of ``y_b - y_a`` over ``[xlo, xhi]``, the x-overlap of chains a and b.

    Chains are stored in increasing x: vertices ``oa .. oa + la`` (``la`` edges) of the
    scratch arrays ``cx, cy`` with their ring positions ``cid``. The vertices of both
    chains inside the overlap are visited in x order (ties: a first), each against the
    other chain's edge over its x; a vertex that is an end of the other chain (a shared
    turning vertex) is skipped. Returns +1 / -1 (one strict sign), 0 (no vertex
    compared) or 2 (a vertex on or across the other chain, or a sign not certain).
    A vertex above or below both ends of the edge has that sign exactly, with no
    arithmetic; the others take the filtered orientation determinant.
    """
    pa = oa  # next vertex of a (and b) to visit; qa, qb: the last ones in the overlap
    while cx[pa] < xlo:
        pa += 1
    pb = ob
    while cx[pb] < xlo:
        pb += 1
    qa = oa + la
    while cx[qa] > xhi:
        qa -= 1
    qb = ob + lb
    while cx[qb] > xhi:
        qb -= 1
    ea0, ea1, eb0, eb1 = cid[oa], cid[oa + la], cid[ob], cid[ob + lb]
    pos = False
    neg = False
    while pa <= qa or pb <= qb:
        if pa <= qa and (pb > qb or cx[pa] <= cx[pb]):
            t = pa
            pa += 1
            r = cid[t]
            if r == eb0 or r == eb1:  # noqa: SIM109
                continue
            j = min(max(pb - 1, ob), ob + lb - 1)
            flip = True
        else:
            t = pb
            pb += 1
            r = cid[t]
            if r == ea0 or r == ea1:  # noqa: SIM109
                continue
            j = min(max(pa - 1, oa), oa + la - 1)
            flip = False
        y = cy[t]
        y0, y1 = cy[j], cy[j + 1]
        if y > y0 and y > y1:
            o = 1
        elif y < y0 and y < y1:
            o = -1
        else:
            o = _orient(cx[j], y0, cx[j + 1], y1, cx[t], y)
            if o == 0:
                return 2
        if flip:
            o = -o
        if o > 0:
            pos = True
        else:
            neg = True
    if pos and neg:
        return 2
    return 1 if pos else (-1 if neg else 0)


@njit(cache=True, nogil=True)
def _star_around(X, s, n, cx, cy):
    """True when every edge ``p -> q`` turns one strict way about ``c``, passing +x once.

    See :func:`_star_simple`.
    """
    px, py = X[s + n - 1, 0] - cx, X[s + n - 1, 1] - cy
    hp = py > 0.0 or (py == 0.0 and px > 0.0)
    sg = 0
    wraps = 0
    for i in range(n):
        qx, qy = X[s + i, 0] - cx, X[s + i, 1] - cy
        left = px * qy
        right = py * qx
        det = left - right
        size = abs(left) + abs(right)
        if not size > _TINY:
            return False
        err = _CCW_ERR * size
        if det > err:
            o = 1
        elif -det > err:
            o = -1
        else:
            return False
        if o != sg:
            if sg != 0:
                return False
            sg = o
        hq = qy > 0.0 or (qy == 0.0 and qx > 0.0)
        if hq and not hp:
            wraps += 1
        px, py, hp = qx, qy, hq
    return wraps == 1


@njit(cache=True, nogil=True)
def _star_simple(X, s, n):
    """``(1, cx, cy)``: the ring is proven star-shaped about ``c``, its centroid or mean.

    ``c`` is the area centroid or else the vertex mean. ``(0, nan, nan)``: not proven;
    ``(-1, nan, nan)``: a coordinate is NaN, infinite or at least ``_BIG`` (doubtful
    for every proof here).

    About a centre c, every edge ``p -> q`` must have ``orient(p, q, c)`` of one strict
    sign (the filtered determinant of :func:`_orient`, from the same rounded differences
    ``p - c``) and the direction from c must pass the +x ray exactly once
    (:func:`_star_around`, exact for any c on its own: a product that overflows makes
    the filter's bound infinite or NaN, and no comparison with it accepts). The direction
    then turns monotonically, by less than pi per edge, through one revolution: it is
    one-to-one on the ring, so no two points of the ring coincide and the ring is simple.
    The ray is counted with comparisons only: ``p - c`` lies in the half-plane
    ``[0, pi)`` when ``dy > 0`` or ``dy == 0 < dx`` (a rounded difference has the exact
    sign), and as every step is less than pi, the direction passes the ray once per
    move from ``[pi, 2 pi)`` into ``[0, pi)``. The centre can be any point: it is only
    a candidate, never trusted (the centroid, computed in the first vertex's frame, may
    overflow for coordinates beyond ~1e100; the vertex mean cannot).
    """
    ox, oy = X[s, 0], X[s, 1]
    acc = 0.0
    sx = 0.0
    sy = 0.0
    mx = 0.0
    my = 0.0
    px, py = X[s + n - 1, 0] - ox, X[s + n - 1, 1] - oy
    for i in range(n):
        xi, yi = X[s + i, 0], X[s + i, 1]
        if not (abs(xi) < _BIG and abs(yi) < _BIG):
            return -1, np.nan, np.nan  # NaN, infinite or near overflow: doubtful
        qx, qy = xi - ox, yi - oy
        cr = px * qy - qx * py
        acc += cr
        sx += (px + qx) * cr
        sy += (py + qy) * cr
        mx += qx
        my += qy
        px, py = qx, qy
    if abs(acc) > _TINY:
        cx = ox + sx / (3.0 * acc)
        cy = oy + sy / (3.0 * acc)
        if abs(cx) < _BIG and abs(cy) < _BIG and _star_around(X, s, n, cx, cy):
            return 1, cx, cy
    cx = ox + mx / n
    cy = oy + my / n
    if _star_around(X, s, n, cx, cy):
        return 1, cx, cy
    return 0, np.nan, np.nan


@njit(cache=True, nogil=True)
def _chains_simple(X, s, n, max_chains, starts, lens, ups, bb, co, cx, cy, cid):
    """The x-monotone chain proof of a ring of finite coordinates below ``_BIG``."""
    e = X[s, 0] - X[s + n - 1, 0]
    if e > 0.0:
        d_prev = 1
    elif e < 0.0:
        d_prev = -1
    else:
        return False
    nch = 0
    for i in range(n):
        xi = X[s + i, 0]
        j = s + i + 1 if i + 1 < n else s
        e = X[j, 0] - xi
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
        st = starts[c]
        nxt = starts[c + 1] if c + 1 < nch else starts[0] + n
        ln = nxt - st
        lens[c] = ln
        co[c] = pos
        y0, y1 = np.inf, -np.inf
        up = ups[c]
        for t in range(ln + 1):
            u = st + t if up else nxt - t  # chains are stored in increasing x
            if u >= n:
                u -= n
            yv = X[s + u, 1]
            cx[pos + t] = X[s + u, 0]
            cy[pos + t] = yv
            cid[pos + t] = u
            y0 = min(y0, yv)
            y1 = max(y1, yv)
        bb[c, 0], bb[c, 1], bb[c, 2], bb[c, 3] = cx[pos], cx[pos + ln], y0, y1
        pos += ln + 1
    for a in range(nch):
        for b in range(a + 1, nch):
            xlo = max(bb[a, 0], bb[b, 0])
            xhi = min(bb[a, 1], bb[b, 1])
            if xlo > xhi or max(bb[a, 2], bb[b, 2]) > min(bb[a, 3], bb[b, 3]):
                continue  # boxes apart (touching boxes are compared)
            sg = _pair(cx, cy, cid, co[a], lens[a], co[b], lens[b], xlo, xhi)
            if sg == 2:
                return False
            if sg == 0 and xlo != xhi:
                return False  # nothing compared over an overlap of positive length
    return True


@njit(cache=True, nogil=True)
def rings_simple(X, offsets, closing, max_chains, centres):
    """Per ring: proven simple.

    ``centres`` ``(M, 2)``: a centre to try the star proof about first (NaN: none);
    overwritten with the centre that proved the ring by the star proof, or NaN.
    """
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
        if n < 3:
            continue
        # the star proof first (one or two passes); the chains (scratch arrays) only when
        # it cannot decide -- called here, not inside one ring function: numba compiles the
        # star path much tighter so
        hx, hy = centres[k, 0], centres[k, 1]
        if hx == hx and hy == hy and _star_around(X, s, n, hx, hy):
            out[k] = True  # star-shaped about the given centre: one pass
            continue
        star, zx, zy = _star_simple(X, s, n)
        centres[k, 0], centres[k, 1] = zx, zy
        if star == 1:
            out[k] = True
        elif star == 0:
            out[k] = _chains_simple(X, s, n, max_chains, starts, lens, ups, bb, co, cx, cy, cid)
    return out


@njit(cache=True, nogil=True)
def rings_star(X, offsets, closing):
    """Per ring: the star-shaped proof alone (:func:`_star_simple`), for the tests."""
    m = offsets.shape[0] - 1
    out = np.zeros(m, dtype=np.bool_)
    for k in range(m):
        s = offsets[k]
        n = offsets[k + 1] - s
        if closing:
            if n < 1 or X[s, 0] != X[s + n - 1, 0] or X[s, 1] != X[s + n - 1, 1]:
                continue
            n -= 1
        if n < 3:
            continue
        out[k] = _star_simple(X, s, n)[0] == 1
    return out


@njit(cache=True, nogil=True)
def _inside(X, s, e, bb, px, py):
    """Whether ``(px, py)`` is inside the closed ring ``X[s:e]`` (box ``bb``): 1, 0, or -1.

    -1: a sign is not certain (the point is on the ring, or too close to tell). The
    crossing rule is half-open in y (exact comparisons); which side of an edge the point
    lies on is the filtered orientation determinant.
    """
    if px < bb[0] or px > bb[1] or py < bb[2] or py > bb[3]:
        return 0
    inside = False
    for i in range(s, e - 1):
        ay, by = X[i, 1], X[i + 1, 1]
        if (ay > py) != (by > py):
            o = _orient(X[i, 0], ay, X[i + 1, 0], by, px, py)
            if o == 0:
                return -1
            if (o > 0) == (by > ay):  # the edge crosses the ray to the right of the point
                inside = not inside
    return 1 if inside else 0


@njit(cache=True, nogil=True)
def nesting_proven(X, ring_lo, ring_hi, part_off, feat_off, budget):
    """Per (Multi)Polygon of pairwise disjoint simple rings: whether they nest validly.

    Ring ``r`` is rows ``ring_lo[r] .. ring_hi[r] - 1`` of ``X``, closed (shapely's
    layout); part ``p`` has rings ``part_off[p] .. part_off[p + 1] - 1``, its shell
    first; feature ``f`` has parts ``feat_off[f] .. feat_off[f + 1] - 1``. With
    disjoint simple rings, a hole is inside its shell and in no other hole of its part,
    and a part's shell is inside no other part's region (its shell without its holes),
    as the first vertex of each ring tells. False: a rule fails, a sign is not certain,
    or the feature's rings times its rows exceed `budget` (the test's worst-case cost).
    """
    nr = ring_lo.shape[0]
    bb = np.empty((nr, 4))
    for r in range(nr):
        x0, x1, y0, y1 = np.inf, -np.inf, np.inf, -np.inf
        for i in range(ring_lo[r], ring_hi[r]):
            x0, x1 = min(x0, X[i, 0]), max(x1, X[i, 0])
            y0, y1 = min(y0, X[i, 1]), max(y1, X[i, 1])
        bb[r, 0], bb[r, 1], bb[r, 2], bb[r, 3] = x0, x1, y0, y1
    nf = feat_off.shape[0] - 1
    out = np.zeros(nf, dtype=np.bool_)
    for f in range(nf):
        r0, r1 = part_off[feat_off[f]], part_off[feat_off[f + 1]]
        rows = 0
        for r in range(r0, r1):
            rows += ring_hi[r] - ring_lo[r]
        if (r1 - r0) * rows > budget:
            continue
        ok = r1 > r0  # a feature without rings (or a part, a ring without any): not proven
        for p in range(feat_off[f], feat_off[f + 1]):
            if part_off[p + 1] == part_off[p]:
                ok = False
        for r in range(r0, r1):
            if ring_hi[r] <= ring_lo[r]:
                ok = False
        for p in range(feat_off[f], feat_off[f + 1] if ok else feat_off[f]):
            shell = part_off[p]
            for a in range(shell + 1, part_off[p + 1]):  # the holes of part p
                px, py = X[ring_lo[a], 0], X[ring_lo[a], 1]
                if _inside(X, ring_lo[shell], ring_hi[shell], bb[shell], px, py) != 1:
                    ok = False
                    break
                for b in range(shell + 1, part_off[p + 1]):
                    if b != a and _inside(X, ring_lo[b], ring_hi[b], bb[b], px, py) != 0:
                        ok = False
                        break
                if not ok:
                    break
            if not ok:
                break
            px, py = X[ring_lo[shell], 0], X[ring_lo[shell], 1]
            for q in range(feat_off[f], feat_off[f + 1]):  # the other parts' regions
                if q == p:
                    continue
                sq = part_off[q]
                c = _inside(X, ring_lo[sq], ring_hi[sq], bb[sq], px, py)
                if c == 1:  # inside q's shell: fine only inside one of q's holes
                    c = 0
                    for h in range(sq + 1, part_off[q + 1]):
                        c = _inside(X, ring_lo[h], ring_hi[h], bb[h], px, py)
                        if c != 0:
                            break
                    if c != 1:
                        ok = False
                elif c != 0:
                    ok = False
                if not ok:
                    break
            if not ok:
                break
        out[f] = ok
    return out
