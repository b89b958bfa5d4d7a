"""Compiled kernel of :mod:`curvesmith.geo._zm`: values along the input curve, ragged.

Imported only when a geometry has Z or M, so ``import curvesmith.geo`` does not load
numba. See :mod:`curvesmith.geo._zm` for what is computed and why.
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True, nogil=True)
def _less(ax, ay, bx, by):
    return ax < bx or (ax == bx and ay < by)


@njit(cache=True, nogil=True)
def _foot(qx, qy, ax, ay, bx, by, lo, hi):
    """Parameter of the nearest point of segment ab to q, within [lo, hi]; squared dist."""
    dx = bx - ax
    dy = by - ay
    den = dx * dx + dy * dy
    t = 0.0
    if den > 0.0:
        t = ((qx - ax) * dx + (qy - ay) * dy) / den
    if t < lo:
        t = lo
    if t > hi:
        t = hi
    ex = ax + t * dx - qx
    ey = ay + t * dy - qy
    return t, ex * ex + ey * ey


@njit(cache=True, nogil=True)
def _lerp(v, a, b, t, out, j):
    """``v_a + t (v_b - v_a)``, exact at both ends and for equal values.

    A flat polygon stays at its height bit for bit; the result is clamped into
    ``[v_a, v_b]`` against rounding.
    """
    for d in range(v.shape[1]):
        va = v[a, d]
        vb = v[b, d]
        if t == 0.0 or va == vb:
            r = va
        elif t == 1.0:
            r = vb
        else:
            r = va + t * (vb - va)
            lo = min(va, vb)
            hi = max(va, vb)
            r = lo if r < lo else (hi if r > hi else r)
        out[j, d] = r


@njit(cache=True, nogil=True)
def _walk(P, PV, Q, QV, window, cyclic, e0, t0):
    """Project Q[1:-1] (open) or Q[1:] (cyclic from edge e0 at t0) forward along P."""
    n = P.shape[0]
    n_edges = n - 1 if not cyclic else n
    last = n_edges - 1 if not cyclic else e0 + n_edges  # last unwrapped edge
    ce = e0
    ct = t0
    stop = Q.shape[0] - 1 if not cyclic else Q.shape[0]
    for j in range(1, stop):
        best_d = np.inf
        best_e = ce
        best_t = ct
        top = min(ce + window, last)
        for u in range(ce, top + 1):
            e = u % n
            f = (e + 1) % n
            lo = ct if u == ce else 0.0
            hi = t0 if (cyclic and u == last) else 1.0
            if lo > hi:
                continue
            t, d = _foot(Q[j, 0], Q[j, 1], P[e, 0], P[e, 1], P[f, 0], P[f, 1], lo, hi)
            if d < best_d:
                best_d = d
                best_e = u
                best_t = t
        ce = best_e
        ct = best_t
        _lerp(PV, ce % n, (ce + 1) % n, ct, QV, j)


@njit(cache=True, nogil=True)
def _piece(P, PV, Q, QV, window):
    """An open piece between two kept vertices, in its canonical direction."""
    L = P.shape[0] - 1
    M = Q.shape[0] - 1
    rev = _less(P[L, 0], P[L, 1], P[0, 0], P[0, 1])
    if P[L, 0] == P[0, 0] and P[L, 1] == P[0, 1] and L >= 2:
        rev = _less(P[L - 1, 0], P[L - 1, 1], P[1, 0], P[1, 1])
    if rev:
        P = P[::-1].copy()
        PV = PV[::-1].copy()
        Q = Q[::-1].copy()
    R = np.empty_like(QV)
    for d in range(PV.shape[1]):
        R[0, d] = PV[0, d]
        R[M, d] = PV[L, d]
    _walk(P, PV, Q, R, window, False, 0, 0.0)
    for j in range(M + 1):
        jj = M - j if rev else j
        for d in range(PV.shape[1]):
            QV[jj, d] = R[j, d]


@njit(cache=True, nogil=True)
def _area(P):
    s = 0.0
    n = P.shape[0]
    for i in range(n):
        k = (i + 1) % n
        s += (P[i, 0] - P[k, 0]) * (P[i, 1] + P[k, 1])
    return s


@njit(cache=True, nogil=True)
def _canonical(P):
    """Rotation start (lexicographic minimum) and orientation (CCW) of a ring."""
    r = 0
    for i in range(1, P.shape[0]):
        if _less(P[i, 0], P[i, 1], P[r, 0], P[r, 1]):
            r = i
    return r, _area(P) < 0.0


@njit(cache=True, nogil=True)
def _reorder(n, r, rev):
    idx = np.empty(n, dtype=np.int64)
    for i in range(n):
        idx[i] = (r - i) % n if rev else (r + i) % n
    return idx


@njit(cache=True, nogil=True)
def _loop(P, PV, Q, QV, window):
    """A ring with no kept vertex: canonical start and orientation, then once around."""
    rs, revs = _canonical(P)
    si = _reorder(P.shape[0], rs, revs)
    rq, revq = _canonical(Q)
    qi = _reorder(Q.shape[0], rq, revq)
    P2 = P[si].copy()
    PV2 = PV[si].copy()
    Q2 = Q[qi].copy()
    R = np.empty((Q2.shape[0], PV.shape[1]))
    n = P2.shape[0]
    best_d = np.inf
    e0 = 0
    t0 = 0.0
    for e in range(n):
        f = (e + 1) % n
        t, d = _foot(Q2[0, 0], Q2[0, 1], P2[e, 0], P2[e, 1], P2[f, 0], P2[f, 1], 0.0, 1.0)
        if d < best_d:
            best_d = d
            e0 = e
            t0 = t
    _lerp(PV2, e0, (e0 + 1) % n, t0, R, 0)
    _walk(P2, PV2, Q2, R, window, True, e0, t0)
    for j in range(Q2.shape[0]):
        for d in range(PV.shape[1]):
            QV[qi[j], d] = R[j, d]


@njit(cache=True, nogil=True)
def _match(r, lo, hi, order, s0, n, after, limit, cyclic, base):
    """Smallest candidate input index (unwrapped from `base`) in (after, limit); -1: none."""
    best = -1
    for c in range(lo[r], hi[r]):
        i = order[c] - s0
        if cyclic and i < base:
            i += n
        if i > after and i < limit and (best < 0 or i < best):
            best = i
    return best


@njit(cache=True, nogil=True)
def interpolate(sxy, sv, soff, pair, closed, oxy, ooff, lo, hi, order, window, vals):
    """Fill ``vals`` (one row per output vertex) for every output curve.

    ``pair[c]``: input curve of output curve ``c`` (-1: none); ``closed[c]``: a ring
    (no closing vertex in the arrays). ``order[lo[r]:hi[r]]``: the input rows whose XY
    equal output row ``r`` (same pair), ascending.
    """
    for c in range(ooff.shape[0] - 1):
        p = pair[c]
        if p < 0:
            continue
        o0 = ooff[c]
        m = ooff[c + 1] - o0
        s0 = soff[p]
        n = soff[p + 1] - s0
        if m == 0 or n == 0:
            continue
        P = sxy[s0 : s0 + n]
        PV = sv[s0 : s0 + n]
        if n == 1:
            for j in range(m):
                for d in range(sv.shape[1]):
                    vals[o0 + j, d] = PV[0, d]
            continue
        cyc = closed[c]
        # kept vertices: (output index, unwrapped input index), in order
        ka = np.empty(m + 1, dtype=np.int64)
        ki = np.empty(m + 1, dtype=np.int64)
        k = 0
        if cyc:
            j0 = -1
            i0 = -1
            for j in range(m):
                i = _match(o0 + j, lo, hi, order, s0, n, -1, n, False, 0)
                if i >= 0:
                    j0 = j
                    i0 = i
                    break
            if j0 < 0:
                Q = oxy[o0 : o0 + m]
                QV = np.empty((m, sv.shape[1]))
                _loop(P, PV, Q, QV, window)
                vals[o0 : o0 + m] = QV
                continue
            ka[0] = j0
            ki[0] = i0
            k = 1
            for jj in range(j0 + 1, j0 + m):
                i = _match(o0 + jj % m, lo, hi, order, s0, n, ki[k - 1], i0 + n, True, i0)
                if i >= 0:
                    ka[k] = jj
                    ki[k] = i
                    k += 1
            ka[k] = j0 + m
            ki[k] = i0 + n
            k += 1
        else:
            ka[0] = 0
            ki[0] = 0
            k = 1
            for j in range(1, m - 1):
                i = _match(o0 + j, lo, hi, order, s0, n, ki[k - 1], n - 1, False, 0)
                if i >= 0:
                    ka[k] = j
                    ki[k] = i
                    k += 1
            ka[k] = m - 1
            ki[k] = n - 1
            k += 1
        for a in range(k):
            for d in range(sv.shape[1]):
                vals[o0 + ka[a] % m, d] = PV[ki[a] % n, d]
        for a in range(k - 1):
            ja, jb = ka[a], ka[a + 1]
            if jb - ja < 2:
                continue
            ia, ib = ki[a], ki[a + 1]
            L = ib - ia
            Pp = np.empty((L + 1, 2))
            PVp = np.empty((L + 1, sv.shape[1]))
            for i in range(L + 1):
                Pp[i] = P[(ia + i) % n]
                PVp[i] = PV[(ia + i) % n]
            Qp = np.empty((jb - ja + 1, 2))
            for j in range(jb - ja + 1):
                Qp[j] = oxy[o0 + (ja + j) % m]
            QVp = np.empty((jb - ja + 1, sv.shape[1]))
            if L == 0:  # both ends on one input vertex: constant
                for j in range(jb - ja + 1):
                    QVp[j] = PVp[0]
            else:
                _piece(Pp, PVp, Qp, QVp, window)
            for j in range(1, jb - ja):
                for d in range(sv.shape[1]):
                    vals[o0 + (ja + j) % m, d] = QVp[j, d]
