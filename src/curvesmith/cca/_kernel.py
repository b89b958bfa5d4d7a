"""The 2D CCA1 step, compiled with numba, over a ragged batch of curves.

One call (:func:`step_units`) does one CCA1 step on every unit of a batch: the
points ``P`` of all curves one after the other, a per-vertex ``fixed`` mask, and a
table of units, each a whole curve or a block (with halos) of a long one. Each
unit is gathered into scratch arrays sized for the largest unit, in the frame of
its curve's first vertex (the origin is subtracted as the unit is read and, on the
last step, added back as the output is written: the same bits as two separate
passes, without them). The work per unit is a few loops over its vertices, so a
curve of 5 vertices costs a few hundred nanoseconds, not the ~1 ms of numpy's
per-call overhead, and a block of a long curve stays in the cache.

The arithmetic is the N-d numpy step's (:func:`curvesmith.cca._stepnd.step`
with :func:`curvesmith.cca._restrict.restrict_passes`) operation by operation,
in the same order: numba compiles without ``fastmath`` (no reassociation, no
fused multiply-add), so the results agree with numpy to the last bit. The
profile's interior angle is :mod:`curvesmith.cca._angle`'s (fdlibm's ``atan``,
the same bits in both); the ``atan2``/``tan`` of the inflection bound and of
Fig. 11 are the C library's, which may differ from numpy's own in the last ulp
(the tests give the numpy reference the C library's there). The restriction
passes follow the same schedule: the first pass checks every edge, later passes
only the edges next to the vertices just decreased, and all decreases of a pass
are computed from the state before it.

Compilation happens on the first call (``cache=True``: later processes load the
machine code from numba's cache, next to this file or, when that folder is not
writable, in the user's cache folder). The module is imported only when a 2D
step runs, so ``import curvesmith`` does not load numba.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from . import _angle as _A
from ._restrict import SHRINK

_AT0, _AT1, _AT2, _AT3, _AT4, _AT5, _AT6, _AT7, _AT8, _AT9, _AT10 = _A.AT

#: Alpha modes of :func:`step_units`.
MODE_REGULAR, MODE_CONSTANT, MODE_GIVEN = 0, 1, 2


@njit(cache=True, nogil=True)
def _nanmin(a, b):
    # np.minimum: NaN if either is NaN
    if a != a or b != b:
        return math.nan
    return a if a <= b else b


@njit(cache=True, nogil=True)
def _nanmax(a, b):
    # np.maximum: NaN if either is NaN
    if a != a or b != b:
        return math.nan
    return a if a >= b else b


@njit(cache=True, nogil=True)
def _profile(theta, brk, coef):
    # the pieces of the PCHIP profile: index = inner breakpoints below theta, then Horner;
    # the breakpoints increase, so an angle above the last inner one (almost every angle
    # of a smoothed curve) is above them all
    last = brk.shape[0] - 2
    if theta > brk[last]:
        idx = last
    else:
        idx = 0
        for b in range(1, last):
            if theta > brk[b]:
                idx += 1
    dt = theta - brk[idx]
    out = coef[0, idx]
    for k in range(1, 4):
        out = out * dt
        out = out + coef[k, idx]
    return out


@njit(cache=True, nogil=True, inline="always")
def _atan_nonneg(t):
    # :func:`curvesmith.cca._angle.atan_nonneg`, one value: the same operations
    if t >= _A.HUGE:
        return _A.ATAN_HI[3] + _A.ATAN_LO[3]
    if t < _A.TINY:
        return t
    if t < _A.B0:
        x = t
    elif t < _A.B1:
        x = (2.0 * t - 1.0) / (2.0 + t)
    elif t < _A.B2:
        x = (t - 1.0) / (t + 1.0)
    elif t < _A.B3:
        x = (t - 1.5) / (1.0 + 1.5 * t)
    else:
        x = -1.0 / t
    z = x * x
    w = z * z
    s1 = z * (_AT0 + w * (_AT2 + w * (_AT4 + w * (_AT6 + w * (_AT8 + w * _AT10)))))
    s2 = w * (_AT1 + w * (_AT3 + w * (_AT5 + w * (_AT7 + w * _AT9))))
    if t < _A.B0:
        return x - x * (s1 + s2)
    if t < _A.B1:
        hi, lo = _A.ATAN_HI[0], _A.ATAN_LO[0]
    elif t < _A.B2:
        hi, lo = _A.ATAN_HI[1], _A.ATAN_LO[1]
    elif t < _A.B3:
        hi, lo = _A.ATAN_HI[2], _A.ATAN_LO[2]
    else:
        hi, lo = _A.ATAN_HI[3], _A.ATAN_LO[3]
    return hi - ((x * (s1 + s2) - lo) - x)


@njit(cache=True, nogil=True, inline="always")
def _interior(scross, dot):
    # :func:`curvesmith.cca._angle.interior_angle`, one value: atan2(scross, -dot)
    if dot < 0.0:
        return _atan_nonneg(scross / -dot)
    if dot > 0.0:
        return _A.PI - (_atan_nonneg(scross / dot) - _A.PI_LO)
    if dot == 0.0:
        if scross == 0.0:
            return _A.PI
        return _A.HALF_PI if scross > 0.0 else scross  # NaN stays NaN
    return _atan_nonneg(scross / abs(dot))  # NaN


@njit(cache=True, nogil=True)
def interior_angle(scross, dot):
    """:func:`_interior` from Python (the tests compare it with the numpy form)."""
    return _interior(scross, dot)


@njit(cache=True, nogil=True)
def _zero_gap(dx, dy):
    return not (dx * dx > 0.0 or dy * dy > 0.0)


@njit(cache=True, nogil=True)
def _has_zero_edge(P, s, n, closed, ox=0.0, oy=0.0):
    # an edge of length 0 (sqrt(x) == 0 exactly when x == 0), in the frame of origin (ox, oy)
    last = n if closed else n - 1
    for i in range(last):
        j = s + i + 1 if i + 1 < n else s
        ex = (P[j, 0] - ox) - (P[s + i, 0] - ox)
        ey = (P[j, 1] - oy) - (P[s + i, 1] - oy)
        if ex * ex + ey * ey == 0.0:
            return True
    return False


@njit(cache=True, nogil=True)
def _dedupe(P, fixed, s, n, closed, Q, qf):
    """Copy curve ``s .. s + n - 1`` of ``P`` into ``Q, qf`` without duplicates; return the count.

    The rules of :func:`curvesmith.cca._input.dedupe`: trailing copies of the first
    vertex of a ring go first (their fixed flags move to vertex 0), then every vertex
    equal to its predecessor (its fixed flag moves to the kept copy).
    """
    k = n
    f0 = fixed[s]
    if closed and n > 1:
        while k > 1 and _zero_gap(P[s + k - 1, 0] - P[s, 0], P[s + k - 1, 1] - P[s, 1]):
            k -= 1
        for t in range(k, n):
            f0 = f0 or fixed[s + t]
    m = 0
    for t in range(k):
        f = f0 if t == 0 else fixed[s + t]
        if t > 0 and _zero_gap(P[s + t, 0] - P[s + t - 1, 0], P[s + t, 1] - P[s + t - 1, 1]):
            qf[m - 1] = qf[m - 1] or f
            continue
        Q[m, 0] = P[s + t, 0]
        Q[m, 1] = P[s + t, 1]
        qf[m] = f
        m += 1
    return m


@njit(cache=True, nogil=True)
def _compact_curve(P, fixed, s, n, closed, Q, qf):
    """The curve without zero-length edges in ``Q, qf`` (repeated until none is left)."""
    m = _dedupe(P, fixed, s, n, closed, Q, qf)
    while m > 1 and _has_zero_edge(Q, 0, m, closed):
        m = _dedupe(Q.copy(), qf.copy(), 0, m, closed, Q, qf)
    return m


@njit(cache=True, nogil=True)
def compact_ragged(P, fixed, offsets, closed):
    """Remove zero-length edges of every curve (as the step does before cutting)."""
    ncurves = offsets.shape[0] - 1
    nmax = 1
    for k in range(ncurves):
        nmax = max(nmax, offsets[k + 1] - offsets[k])
    Q = np.empty((nmax, 2))
    qf = np.empty(nmax, dtype=np.bool_)
    OUT = np.empty((P.shape[0], 2))
    of = np.empty(P.shape[0], dtype=np.bool_)
    oo = np.empty(ncurves + 1, dtype=np.int64)
    oo[0] = 0
    pos = 0
    for k in range(ncurves):
        s, n = offsets[k], offsets[k + 1] - offsets[k]
        if n > 0 and _has_zero_edge(P, s, n, closed[k]):
            m = _compact_curve(P, fixed, s, n, closed[k], Q, qf)
            for t in range(m):
                OUT[pos + t, 0], OUT[pos + t, 1], of[pos + t] = Q[t, 0], Q[t, 1], qf[t]
        else:
            m = n
            for t in range(n):
                OUT[pos + t, 0], OUT[pos + t, 1] = P[s + t, 0], P[s + t, 1]
                of[pos + t] = fixed[s + t]
        pos += m
        oo[k + 1] = pos
    return OUT[:pos].copy(), of[:pos].copy(), oo


@njit(cache=True, nogil=True)
def any_zero_edge(P, offsets, closed, org):
    """Whether some curve has a zero-length edge, in the frame of its origin ``org[k]``."""
    for k in range(offsets.shape[0] - 1):
        s, n = offsets[k], offsets[k + 1] - offsets[k]
        if n > 0 and _has_zero_edge(P, s, n, closed[k], org[k, 0], org[k, 1]):
            return True
    return False


@njit(cache=True, nogil=True)
def angles_ragged(P, offsets, closed):
    """Interior angle ``atan2(|cross|, -dot)`` at every vertex (for a callable alpha)."""
    theta = np.zeros(P.shape[0])
    for k in range(offsets.shape[0] - 1):
        s, n = offsets[k], offsets[k + 1] - offsets[k]
        for i in range(n):
            h = s + (i - 1 if i > 0 else n - 1)
            j = s + (i + 1 if i + 1 < n else 0)
            upx, upy = _unit(P[s + i, 0] - P[h, 0], P[s + i, 1] - P[h, 1])
            ux, uy = _unit(P[j, 0] - P[s + i, 0], P[j, 1] - P[s + i, 1])
            cr = upx * uy - upy * ux
            dot = 0.0 + upx * ux + upy * uy
            theta[s + i] = _interior(abs(cr), dot)
    return theta


@njit(cache=True, nogil=True)
def _unit(ex, ey):
    length = math.sqrt(0.0 + ex * ex + ey * ey)
    inv = 1.0 / length if length > 0.0 else 0.0
    return ex * inv, ey * inv


#: Flags of a unit (column 7 of the unit table of :func:`step_units`): the unit is
#: smoothed as a closed curve; it is the first / last unit of its curve; its curve is a ring.
U_CLOSED, U_FIRST, U_LAST, U_RING = 1, 2, 4, 8
#: Statuses of :func:`step_units`: done; the output buffer is too small; a block met a
#: zero-length edge (its own wrap edge: the ring passes twice through one point).
DONE, FULL, ZERO_EDGE = 0, -1, -2


@njit(cache=True, nogil=True)
def curve_units(offsets, closed):
    """The unit table of :func:`step_units` whose units are the curves themselves."""
    m = offsets.shape[0] - 1
    table = np.empty((m, 8), dtype=np.int64)
    for k in range(m):
        n = offsets[k + 1] - offsets[k]
        ring = U_CLOSED | U_RING if closed[k] else 0
        table[k, 0], table[k, 1], table[k, 2], table[k, 3] = k, offsets[k], n, 0
        table[k, 4], table[k, 5], table[k, 6], table[k, 7] = n, 0, n, ring | U_FIRST | U_LAST
    return table


@njit(cache=True, nogil=True)
def _edges(V, n, closed, length, ux, uy):
    """Edge lengths and unit vectors of ``V[:n]`` (edge ``n - 1`` wraps); False at a zero edge.

    A zero-length edge that exists (every edge of a ring, all but the wrap edge of an
    open curve) stops the loop: the curve must be compacted first.
    """
    for i in range(n):
        j = i + 1 if i + 1 < n else 0
        ex = V[j, 0] - V[i, 0]
        ey = V[j, 1] - V[i, 1]
        le = math.sqrt(0.0 + ex * ex + ey * ey)
        if le == 0.0 and (closed or i < n - 1):
            return False
        inv = 1.0 / le if le > 0.0 else 0.0
        length[i], ux[i], uy[i] = le, ex * inv, ey * inv
    return True


@njit(cache=True, nogil=True)
def _put(OUT, of, pos, x, y, f, add, ox, oy):
    # one output row; with ``add`` in the frame of the input (the curve's origin added)
    if add:
        OUT[pos, 0] = x + ox
        OUT[pos, 1] = y + oy
    else:
        OUT[pos, 0] = x
        OUT[pos, 1] = y
    of[pos] = f


@njit(cache=True, nogil=True)
def step_units(
    P,
    fixed,
    alpha_in,
    org_in,
    org_out,
    units,
    mode,
    const,
    brk,
    coef,
    restrict,
    c,
    C,
    tilt_n,
    balance_tol,
    max_passes,
    min_factor,
    OUT,
    of,
    close_out,
    add_out,
):
    """One CCA1 step on every unit of a ragged batch of ``(N, 2)`` points.

    A unit is a whole curve or a block of a long one (see
    :func:`curvesmith.cca._api._blocks`). ``units`` ``(U, 8)`` int64, per unit: its curve
    ``k``, the curve's first row ``s0`` and length ``n``, the unit's first vertex ``lo``
    relative to ``s0`` (negative, or running past ``n``, wraps around a ring) and its
    length ``L``, its core ``clo .. chi - 1`` (the vertices whose output and counts are
    wanted: ``0, L`` for a whole curve), and :data:`U_CLOSED` | ... flags. The units of a
    curve come one after the other.

    Each unit is gathered into scratch arrays sized for the largest unit (so a block
    stays in the cache), minus ``org_in[k]`` (zeros: unchanged; subtracting ``+0.0``
    is exact). Only the core is emitted, into ``OUT, of`` (``(cap, 2)`` float64 and
    ``(cap,)`` bool, allocated by the caller: numpy's allocator asks for huge pages),
    plus ``org_out[k]`` when ``add_out``. With ``close_out`` the first output vertex of
    every ring is repeated after its last unit (shapely's ring layout); when the ring's
    first unit is not in this call, that row is left for the caller to fill.

    Returns ``OUT, ofixed, m, span, nred, nfig, nunsat, status``: the new points in
    ``OUT[:m]`` and their fixed mask (each fixed vertex is emitted once, as itself),
    per unit the output rows ``span[u, 0] .. span[u, 1] - 1`` (with the closing
    vertex) and the number of local alpha decreases, of Fig. 11 edges and of edges
    left violating a restriction, all over its core; ``status`` :data:`DONE`,
    :data:`FULL` or :data:`ZERO_EDGE`. With :data:`FULL` the buffer ran out (the
    capacity is checked row by row, so a buffer of exactly the rows needed is
    enough; at most 4 rows per input vertex and 1 per ring are): ``m`` is then the
    number of units done, whose rows and counts are valid; the caller runs the
    others into a larger buffer.
    """
    nu = units.shape[0]
    lmax = 1
    for u in range(nu):
        lmax = max(lmax, units[u, 4])
    cap = OUT.shape[0]
    nred = np.zeros(nu, dtype=np.int64)
    nfig = np.zeros(nu, dtype=np.int64)
    nunsat = np.zeros(nu, dtype=np.int64)
    span = np.zeros((nu, 2), dtype=np.int64)
    # scratch, sized for the largest unit
    m1 = lmax + 1
    G, Q = np.empty((m1, 2)), np.empty((m1, 2))
    qf, ga = np.empty(m1, dtype=np.bool_), np.empty(m1)
    length, ux, uy = np.empty(m1), np.empty(m1), np.empty(m1)
    cr, dot, scross = np.empty(m1), np.empty(m1), np.empty(m1)
    alpha, alpha0, short, half = np.empty(m1), np.empty(m1), np.empty(m1), np.empty(m1)
    a, K, tanb, fv = np.empty(m1), np.empty(m1), np.empty(m1), np.empty(m1)
    turning = np.empty(m1, dtype=np.bool_)
    endish = np.empty(m1, dtype=np.bool_)
    pending = np.empty(m1, dtype=np.bool_)
    check = np.empty(m1, dtype=np.bool_)
    fx = np.empty(m1, dtype=np.bool_)
    cand = np.empty(2 * m1, dtype=np.int64)
    edges = np.empty(m1, dtype=np.int64)
    edges2 = np.empty(m1, dtype=np.int64)
    tq = np.empty(m1)
    fv[:] = 1.0
    check[:] = False
    pos = 0
    cstart = -1  # output row of the first vertex of the current curve (-1: not in this call)
    for u in range(nu):
        k, s0, nc, lo, n = units[u, 0], units[u, 1], units[u, 2], units[u, 3], units[u, 4]
        clo, chi, flags = units[u, 5], units[u, 6], units[u, 7]
        cl = (flags & U_CLOSED) != 0
        if flags & U_FIRST:
            cstart = pos
        span[u, 0] = pos
        if n == 0:
            span[u, 1] = pos
            continue
        # gather the unit, in the curve's frame, and its edges (edge t - 1 once vertex t
        # is in; the wrap edge n - 1 last); stop computing edges at a zero-length one
        ox, oy = org_in[k, 0], org_in[k, 1]
        ok = True
        for t in range(n):
            r = lo + t
            if r < 0:
                r += nc
            elif r >= nc:
                r -= nc
            row = s0 + r
            gx = P[row, 0] - ox
            gy = P[row, 1] - oy
            G[t, 0] = gx
            G[t, 1] = gy
            fx[t] = fixed[row]
            if mode == MODE_GIVEN:
                ga[t] = alpha_in[row]
            if t > 0 and ok:
                ex = gx - G[t - 1, 0]
                ey = gy - G[t - 1, 1]
                le = math.sqrt(0.0 + ex * ex + ey * ey)
                if le == 0.0:
                    ok = False
                inv = 1.0 / le if le > 0.0 else 0.0
                length[t - 1], ux[t - 1], uy[t - 1] = le, ex * inv, ey * inv
        if ok:
            ex = G[0, 0] - G[n - 1, 0]
            ey = G[0, 1] - G[n - 1, 1]
            le = math.sqrt(0.0 + ex * ex + ey * ey)
            if le == 0.0 and cl:
                ok = False
            inv = 1.0 / le if le > 0.0 else 0.0
            length[n - 1], ux[n - 1], uy[n - 1] = le, ex * inv, ey * inv
        V = G
        if not ok:
            if n != nc:  # a block: compacting would shift its core
                return OUT, of, pos, span, nred, nfig, nunsat, ZERO_EDGE
            n = _compact_curve(G, fx, 0, n, cl, Q, qf)
            chi = n
            V = Q
            for t in range(n):
                fx[t] = qf[t]
            _edges(Q, n, cl, length, ux, uy)
        if not cl:
            fx[0] = True
            fx[n - 1] = True
        anyfix = False
        # the turn at every vertex, from the edge before it (the interior angle into
        # alpha, a loop of its own: its long chain of operations overlaps across vertices)
        regular = mode == MODE_REGULAR
        for i in range(n):
            h = i - 1 if i > 0 else n - 1
            cri = ux[h] * uy[i] - uy[h] * ux[i]
            doti = 0.0 + ux[h] * ux[i] + uy[h] * uy[i]
            cr[i] = cri
            dot[i] = doti
            scross[i] = abs(cri)
            if regular:
                alpha[i] = _interior(abs(cri), doti)
        # the profile's last piece (150-180 degrees: almost every angle of a smoothed
        # curve) with its coefficients held in registers; _profile's Horner steps
        blast = brk[brk.shape[0] - 2]
        lc0, lc1, lc2, lc3 = coef[0, -1], coef[1, -1], coef[2, -1], coef[3, -1]
        for i in range(n):
            h = i - 1 if i > 0 else n - 1
            cri = cr[i]
            sh = min(length[i], length[h])
            short[i] = sh
            half[i] = 0.5 * sh * sh
            if fx[i]:
                al = 0.0
                anyfix = True
            elif regular:
                th = alpha[i]
                if th > blast:
                    dt = th - blast
                    al = ((lc0 * dt + lc1) * dt + lc2) * dt + lc3
                else:
                    al = _profile(th, brk, coef)
            elif mode == MODE_CONSTANT:
                al = const
            else:
                al = ga[i]
            alpha[i] = al
            # cut length and signed cut area (kept current by the restriction passes)
            a[i] = al * sh
            K[i] = al * al * half[i] * cri
            if restrict:
                doti = dot[i]
                alpha0[i] = al
                turning[i] = (not fx[i]) and abs(cri) > 0.0
                tanb[i] = (1.0 + doti) / abs(cri) if turning[i] else 0.0
                pending[i] = False
                endish[i] = False
                tq[i] = -1.0
        if restrict:
            r = _restrict(
                n, cl, anyfix, alpha, alpha0, half, cr, scross, dot, short, length, fx, c, C,
                max_passes, min_factor, a, K, tanb, fv, turning, endish, pending, check,
                cand, edges, edges2, clo, chi, tq,
            )  # fmt: skip
            nred[u], nunsat[u] = r
        # emit the core: vertex i -> [L_i, R_i] or [V_i]; edge i -> [G_i] or the Fig. 11 pair
        ax, ay = org_out[k, 0], org_out[k, 1]
        nf = 0
        for i in range(clo, chi):
            h = i - 1 if i > 0 else n - 1
            j = i + 1 if i + 1 < n else 0
            vx, vy = V[i, 0], V[i, 1]
            ai = a[i]
            rx = vx + ai * ux[i]
            ry = vy + ai * uy[i]
            kept = fx[i] or ai == 0.0
            if pos + (1 if kept else 2) > cap:
                return OUT, of, u, span, nred, nfig, nunsat, FULL
            if kept:
                _put(OUT, of, pos, vx, vy, fx[i], add_out, ax, ay)
                pos += 1
            else:
                _put(OUT, of, pos, vx - ai * ux[h], vy - ai * uy[h], False, add_out, ax, ay)
                _put(OUT, of, pos + 1, rx, ry, False, add_out, ax, ay)
                pos += 2
            if not cl and i == n - 1:
                continue  # no wrap edge on an open curve
            A = 0.5 * (K[i] + K[j])
            w = 0.5 * (length[i] - ai - a[j])
            winv = 1.0 / w if w > 0.0 else 0.0
            lx = V[j, 0] - a[j] * ux[i]
            ly = V[j, 1] - a[j] * uy[i]
            mx = 0.5 * (rx + lx)
            my = 0.5 * (ry + ly)
            k1, k2 = K[i], K[j]
            fig = (
                k1 * k2 < 0.0
                and abs(k1 + k2) <= balance_tol * 0.5 * (abs(k1) + abs(k2))
                and w > 0.0
            )
            if pos + (2 if fig else 1) > cap:
                return OUT, of, u, span, nred, nfig, nunsat, FULL
            if not fig:
                sv = A * winv
                _put(OUT, of, pos, mx + sv * uy[i], my - sv * ux[i], False, add_out, ax, ay)
                pos += 1
                continue
            # Fig. 11: two congruent triangles on the halves, on opposite sides
            nf += 1
            s1 = 1.0 if k1 > 0.0 else (-1.0 if k1 < 0.0 else 0.0)
            phi = tilt_n
            if restrict:
                tau1 = math.atan2(scross[i], dot[i])
                tau2 = math.atan2(scross[j], dot[j])
                phi = _nanmin(phi, C * 0.5 * _nanmin(tau1, tau2))
            hb = 0.5 * w * math.tan(phi)
            carry = s1 * A / w
            h1, h2 = hb + carry, hb - carry
            q1x, q1y = 0.5 * (rx + mx), 0.5 * (ry + my)
            q2x, q2y = 0.5 * (mx + lx), 0.5 * (my + ly)
            _put(OUT, of, pos, q1x + s1 * h1 * uy[i], q1y - s1 * h1 * ux[i], False, add_out, ax, ay)
            _put(
                OUT, of, pos + 1, q2x - s1 * h2 * uy[i], q2y + s1 * h2 * ux[i], False, add_out,
                ax, ay,
            )  # fmt: skip
            pos += 2
        nfig[u] = nf
        if close_out and (flags & U_LAST) and (flags & U_RING):
            if pos + 1 > cap:
                return OUT, of, u, span, nred, nfig, nunsat, FULL
            if cstart >= 0:  # else the ring's first unit is in another call: row left empty
                OUT[pos, 0], OUT[pos, 1] = OUT[cstart, 0], OUT[cstart, 1]
            of[pos] = False
            pos += 1
        span[u, 1] = pos
    return OUT, of, pos, span, nred, nfig, nunsat, DONE


# inlined by numba: a call passes its 25 arrays field by field, once per curve, which
# was about 7 % of a step on a batch of small polygons (one call per ~8 vertices)
@njit(cache=True, nogil=True, inline="always")
def _restrict(
    n, cl, anyfix, alpha, alpha0, half, cr, scross, dot, short, length, fx, c, C, max_passes,
    min_factor, a, K, tanb, fv, turning, endish, pending, check, cand, edges, edges2, lo, hi, tq,
):  # fmt: skip
    """Local alpha decrease of one curve; the rules and schedule of ``restrict_passes``.

    The counts cover vertices and edges ``lo .. hi - 1`` (the core of a block).

    On entry ``alpha0 = alpha``, ``a``, ``K``, ``turning`` and ``tanb`` hold the
    profile's values, ``fv`` is all 1 and ``check``, ``pending`` and ``endish`` all False
    (the first two are left so), ``tq`` all -1.
    ``alpha``, ``a`` and ``K`` are decreased in place. ``tq`` (scratch) keeps, per vertex,
    ``tan(C / 2 * tau)`` of its turn ``tau`` once computed (a vertex is the minor one
    of up to two edges, in several passes; the value does not change). Returns
    ``(nred, nunsat)``.
    """
    if anyfix:
        for i in range(n):
            j = i + 1 if i + 1 < n else 0
            endish[i] = (fx[i] and turning[j]) or (fx[j] and turning[i])
    nlast = n if cl else n - 1  # edges that exist
    ne = nlast
    for i in range(ne):
        edges[i] = i
    half_c = 0.5 * c
    for npass in range(max_passes + 1):
        nc = 0  # candidate vertices with a factor < 1 this pass
        nviol = 0
        for t in range(ne):
            i = edges[t]
            j = i + 1 if i + 1 < n else 0
            K1, K2 = K[i], K[j]
            w = 0.5 * (length[i] - a[i] - a[j])
            k12 = K1 * K2
            net = abs(K1 + K2)
            w2 = w * w
            need = half_c * _nanmax(tanb[i], tanb[j]) * net
            pending[i] = False
            if w2 < need * (1.0 - 1e-12) and (k12 > 0.0 or endish[i]):
                pending[i] = True
                nviol += 1
                f = math.sqrt(w2 / need) * SHRINK
                fv[i] = _nanmin(fv[i], f)
                fv[j] = _nanmin(fv[j], f)
                cand[nc], cand[nc + 1] = i, j
                nc += 2
            if k12 < 0.0:
                m1, m2 = abs(K1), abs(K2)
                minor2 = m2 <= m1
                mv = j if minor2 else i
                th = tq[mv]
                if th < 0.0:
                    # a lower bound of th first (tan(phi) >= phi; atan(t) >= t / (1 + t)
                    # for t = |cr| / dot >= 0; the angle is >= pi / 2 when dot <= 0): an
                    # edge well inside it cannot violate the rule, and needs no atan2, tan
                    sm, dm = scross[mv], dot[mv]
                    low = 0.5 * C * (sm / (dm + sm) if dm > 0.0 else 1.5707963267948966)
                    if not net <= 2.0 * w2 * low * (1.0 - 1e-9):
                        th = math.tan(0.5 * C * math.atan2(sm, dm))
                        tq[mv] = th
                s2 = 2.0 * w2 * th
                if th >= 0.0 and net > s2 * (1.0 + 1e-12):
                    pending[i] = True
                    nviol += 1
                    mag_d = m1 if minor2 else m2
                    mag_m = m2 if minor2 else m1
                    dotab = k12
                    disc = dotab * dotab - mag_d * mag_d * (mag_m * mag_m - s2 * s2)
                    if disc >= 0.0:
                        t_ = (-dotab + math.sqrt(max(disc, 0.0))) / (mag_d * mag_d)
                        f = math.sqrt(_nanmin(_nanmax(t_, 0.0), 1.0)) * SHRINK
                        dom = i if minor2 else j
                        fv[dom] = _nanmin(fv[dom], f)
                        cand[nc] = dom
                        nc += 1
                    else:
                        f = math.sqrt(s2 / net) * SHRINK
                        fv[i] = _nanmin(fv[i], f)
                        fv[j] = _nanmin(fv[j], f)
                        cand[nc], cand[nc + 1] = i, j
                        nc += 2
        if nviol == 0 or npass == max_passes:
            for t in range(nc):
                fv[cand[t]] = 1.0
            break
        # apply the smallest factor of every vertex, from the state before the pass; the
        # next pass checks the edges next to the vertices that moved (the order of the
        # edges does not matter: every edge's decision reads the state before the pass)
        ne2 = 0
        for t in range(nc):
            v = cand[t]
            f = fv[v]
            if f == 1.0:
                continue  # done already (a vertex may be listed twice)
            fv[v] = 1.0
            if not f < 1.0 or fx[v]:
                continue
            new = _nanmax(alpha[v] * f, min_factor * alpha0[v])
            if not new < alpha[v]:
                continue
            alpha[v] = new
            a[v] = new * short[v]
            K[v] = alpha[v] * alpha[v] * half[v] * cr[v]
            e = v - 1 if v > 0 else n - 1  # the edge ending at v
            if v < nlast and not check[v]:
                check[v] = True
                edges2[ne2] = v
                ne2 += 1
            if e < nlast and not check[e]:
                check[e] = True
                edges2[ne2] = e
                ne2 += 1
        if ne2 == 0:
            break  # every violation sits at the floor
        for t in range(ne2):
            check[edges2[t]] = False
        edges, edges2 = edges2, edges
        ne = ne2
    nred = 0
    nunsat = 0
    for i in range(lo, hi):
        if alpha[i] < alpha0[i]:
            nred += 1
        if pending[i]:
            nunsat += 1
    return nred, nunsat


def restrict_curve(alpha, half, cr, scross, dot, short, length, fixed, closed, c, C, limits):
    """The kernel's restriction of one curve, from Python (the tests compare it with numpy).

    Returns the decreased alphas, the number of decreases and of unsatisfied edges.
    """
    n = alpha.shape[0]
    alpha = np.array(alpha, dtype=float)
    fixed = np.asarray(fixed, dtype=np.bool_)
    turning = ~fixed & (scross > 0)
    tanb = np.zeros(n + 1)
    np.divide(1.0 + dot, scross, out=tanb[:n], where=turning)
    a = np.append(alpha * short, 0.0)
    K = np.append(alpha * alpha * half * cr, 0.0)
    fv = np.ones(n + 1)
    flags = [np.zeros(n + 1, dtype=np.bool_) for _ in range(3)]
    ints = [np.empty(2 * n + 2, dtype=np.int64), np.empty(n + 1), np.empty(n + 1)]
    ints[1:] = [np.empty(n + 1, dtype=np.int64), np.empty(n + 1, dtype=np.int64)]
    nred, nunsat = _restrict(
        n, closed, bool(fixed.any()), alpha, alpha.copy(), half, cr, scross, dot, short,
        length, fixed, c, C, limits[0], limits[1], a, K, tanb, fv, np.append(turning, False),
        *flags, *ints, 0, n, np.full(n + 1, -1.0),
    )  # fmt: skip
    return alpha, int(nred), int(nunsat)


@njit(cache=True, nogil=True)
def move_rows(src, src_f, dst, dst_f, span, dest):
    """Rows ``span[u, 0] .. span[u, 1] - 1`` of ``src, src_f`` to ``dest[u] ..`` of ``dst, dst_f``.

    ``dst`` may be ``src`` when every ``dest[u] <= span[u, 0]`` (rows move forward).
    """
    for u in range(span.shape[0]):
        d = dest[u]
        for i in range(span[u, 0], span[u, 1]):
            dst[d, 0] = src[i, 0]
            dst[d, 1] = src[i, 1]
            dst_f[d] = src_f[i]
            d += 1


@njit(cache=True, nogil=True)
def move_rows_back(buf, buf_f, span, dest):
    """:func:`move_rows` within one buffer, to later rows (every ``dest[u] >= span[u, 0]``).

    The last row goes first, so that no row is overwritten before it moved.
    """
    for u in range(span.shape[0] - 1, -1, -1):
        d = dest[u] + span[u, 1] - span[u, 0]
        for i in range(span[u, 1] - 1, span[u, 0] - 1, -1):
            d -= 1
            buf[d, 0] = buf[i, 0]
            buf[d, 1] = buf[i, 1]
            buf_f[d] = buf_f[i]


@njit(cache=True, nogil=True)
def close_ragged(P, offsets, closed, OUT, out_offsets):
    """Copy curves ``P`` into ``OUT``, each closed one with its first row repeated after it.

    ``out_offsets`` (from the caller: the offsets plus one row per closed non-empty
    curve) give where each curve goes. One pass over the rows, without the index
    arrays numpy's scatter needs (100 ms for 5 million rows against 10-15 ms here).
    """
    for k in range(offsets.shape[0] - 1):
        s, e, d = offsets[k], offsets[k + 1], out_offsets[k]
        for i in range(s, e):
            for c in range(P.shape[1]):
                OUT[d, c] = P[i, c]
            d += 1
        if closed[k] and e > s:
            for c in range(P.shape[1]):
                OUT[d, c] = P[s, c]


@njit(cache=True, nogil=True)
def to_local(P, offsets, Q):
    """Every curve relative to its first vertex: ``Q = P - origin``; returns the origins."""
    m = offsets.shape[0] - 1
    origin = np.zeros((m, 2))
    for k in range(m):
        s, e = offsets[k], offsets[k + 1]
        if e > s:
            ox, oy = P[s, 0], P[s, 1]
            origin[k, 0], origin[k, 1] = ox, oy
            for i in range(s, e):
                Q[i, 0] = P[i, 0] - ox
                Q[i, 1] = P[i, 1] - oy
    return origin


@njit(cache=True, nogil=True)
def abs_max_per_curve(P, offsets):
    """Largest ``|coordinate|`` of every curve (0 for an empty curve)."""
    m = offsets.shape[0] - 1
    top = np.zeros(m)
    for k in range(m):
        t = 0.0
        for i in range(offsets[k], offsets[k + 1]):
            t = max(t, abs(P[i, 0]), abs(P[i, 1]))
        top[k] = t
    return top


@njit(cache=True, nogil=True)
def scan_curves(P, offsets, closed):
    """:func:`abs_max_per_curve` and :func:`any_zero_edge` (origin 0) in one pass over ``P``.

    The input checks of a call read the points once instead of twice (each pass over a
    long curve costs about as much as a tenth of a CCA1 step on it).
    """
    m = offsets.shape[0] - 1
    top = np.zeros(m)
    zero = False
    for k in range(m):
        s, e = offsets[k], offsets[k + 1]
        t = 0.0
        if e > s:
            px, py = P[s, 0], P[s, 1]
            t = max(t, abs(px), abs(py))
            for i in range(s + 1, e):
                x, y = P[i, 0], P[i, 1]
                t = max(t, abs(x), abs(y))
                ex, ey = x - px, y - py
                if ex * ex + ey * ey == 0.0:
                    zero = True
                px, py = x, y
            if closed[k] and not zero:
                ex, ey = P[s, 0] - px, P[s, 1] - py
                zero = ex * ex + ey * ey == 0.0
        top[k] = t
    return top, zero


@njit(cache=True, nogil=True)
def ring_areas(P, offsets):
    """Signed area of every ring (closing vertex repeated or not), in its first vertex's frame.

    The trapezoid form of :func:`curvesmith.geometry.signed_area`, without temporaries.
    """
    m = offsets.shape[0] - 1
    out = np.zeros(m)
    for k in range(m):
        s, e = offsets[k], offsets[k + 1]
        if e - s < 2:
            continue
        ox, oy = P[s, 0], P[s, 1]
        acc = 0.0
        for i in range(s, e):
            j = i + 1 if i + 1 < e else s
            xi, yi = P[i, 0] - ox, P[i, 1] - oy
            xj, yj = P[j, 0] - ox, P[j, 1] - oy
            acc += (xi - xj) * (yi + yj)
        out[k] = 0.5 * acc
    return out


@njit(cache=True, nogil=True)
def refusal_candidates(P, offsets, closed):
    """Per curve: whether CCA might refuse it (the scan of ``geo``'s ``_cca_refused``).

    A curve is a candidate when it is short (fewer than 4 rows for a ring given with its
    closing vertex, 2 for a line), when two consecutive rows are equal or so close that
    both squared components underflow, or when a ring's last row is that close to its
    first without being equal. One pass over ``P``, no temporaries.
    """
    m = offsets.shape[0] - 1
    cand = np.zeros(m, dtype=np.bool_)
    for k in range(m):
        s, e = offsets[k], offsets[k + 1]
        n = e - s
        if n < (4 if closed[k] else 2):
            cand[k] = True
            continue
        for i in range(s + 1, e):
            if _zero_gap(P[i, 0] - P[i - 1, 0], P[i, 1] - P[i - 1, 1]):
                cand[k] = True
                break
        if not cand[k] and closed[k]:
            dx, dy = P[e - 1, 0] - P[s, 0], P[e - 1, 1] - P[s, 1]
            if _zero_gap(dx, dy) and (dx != 0.0 or dy != 0.0):
                cand[k] = True
    return cand
