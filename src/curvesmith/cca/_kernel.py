"""The 2D CCA1 step, compiled with numba, over a ragged batch of curves.

One call does one CCA1 step on every curve of a batch given as coordinate
columns ``x, y`` (all curves one after the other, each relative to its own
origin), ``offsets`` (curve ``k`` is ``offsets[k] .. offsets[k + 1] - 1``), a
per-vertex ``fixed`` mask and a per-curve ``closed`` flag. The work per curve
is a few loops over its vertices in scratch arrays sized for the largest curve,
so a curve of 5 vertices costs a few hundred nanoseconds, not the ~1 ms of
numpy's per-call overhead.

The arithmetic is the N-d numpy step's (:func:`curvesmith.cca._stepnd.step`
with :func:`curvesmith.cca._restrict.restrict_passes`) operation by operation,
in the same order: numba compiles without ``fastmath`` (no reassociation, no
fused multiply-add), so the results agree with numpy to the last bit, up to
``atan2``/``tan`` of the C library against numpy's own (a last-ulp difference
at most, which the tests bound). The restriction passes follow the same
schedule: the first pass checks every edge, later passes only the edges next
to the vertices just decreased, and all decreases of a pass are computed from
the state before it.

Compilation happens on the first call (``cache=True``: later processes load the
machine code from numba's cache, next to this file or, when that folder is not
writable, in the user's cache folder). The module is imported only when a 2D
step runs, so ``import curvesmith`` does not load numba.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ._restrict import SHRINK

#: Alpha modes of :func:`step_ragged`.
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
    # the pieces of the PCHIP profile: index = inner breakpoints below theta, then Horner
    idx = 0
    for b in range(1, brk.shape[0] - 1):
        if theta > brk[b]:
            idx += 1
    dt = theta - brk[idx]
    out = coef[0, idx]
    for k in range(1, 4):
        out = out * dt
        out = out + coef[k, idx]
    return out


@njit(cache=True, nogil=True)
def _zero_gap(dx, dy):
    return not (dx * dx > 0.0 or dy * dy > 0.0)


@njit(cache=True, nogil=True)
def _has_zero_edge(P, s, n, closed):
    last = n if closed else n - 1
    for i in range(last):
        j = s + i + 1 if i + 1 < n else s
        ex = P[j, 0] - P[s + i, 0]
        ey = P[j, 1] - P[s + i, 1]
        if math.sqrt(ex * ex + ey * ey) == 0.0:
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
def any_zero_edge(P, offsets, closed):
    """Whether some curve has a zero-length edge."""
    for k in range(offsets.shape[0] - 1):
        s, n = offsets[k], offsets[k + 1] - offsets[k]
        if n > 0 and _has_zero_edge(P, s, n, closed[k]):
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
            theta[s + i] = math.atan2(abs(cr), -dot)
    return theta


@njit(cache=True, nogil=True)
def _unit(ex, ey):
    length = math.sqrt(0.0 + ex * ex + ey * ey)
    inv = 1.0 / length if length > 0.0 else 0.0
    return ex * inv, ey * inv


@njit(cache=True, nogil=True)
def step_ragged(
    P,
    fixed,
    offsets,
    closed,
    mode,
    const,
    brk,
    coef,
    alpha_in,
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
    core,
):
    """One CCA1 step on every curve of a ragged batch of ``(N, 2)`` points.

    ``core`` ``(M, 2)``: per curve the vertices ``lo .. hi - 1`` whose output and counts
    are wanted (``0, n`` for a whole curve; a block of a long curve with halos, see
    :func:`curvesmith.cca._api._blocks`). ``span`` (returned) holds, per curve, the
    output rows of the core; a block that meets a zero-length edge gets ``-1, -1``.

    ``OUT, of``: the output buffers, ``(cap, 2)`` float64 and ``(cap,)`` bool, allocated
    by the caller (numpy's allocator asks for huge pages: first touching fresh 4 KiB
    pages costs more than the step's arithmetic). At most 4 rows per input vertex and 1
    per ring are needed; when ``cap`` is too small the step stops and returns ``m = -1``.
    ``close_out``: repeat
    the first output vertex of every closed curve at its end (shapely's ring layout).

    Returns ``OUT, ofixed, m, ooffsets, nred, nfig, nunsat``: the new points in
    ``OUT[:m]`` and the fixed mask of the output in ``ofixed[:m]`` (each fixed vertex
    is emitted once, as itself; the buffers hold up to 4 points per input vertex and
    are returned whole, so the caller takes views, not copies), the offsets of the
    output curves and, per curve, the number of local alpha
    decreases, of Fig. 11 edges and of edges left violating a restriction.
    """
    ncurves = offsets.shape[0] - 1
    nmax = 1
    for k in range(ncurves):
        nmax = max(nmax, offsets[k + 1] - offsets[k])
    cap = OUT.shape[0]
    oo = np.empty(ncurves + 1, dtype=np.int64)
    nred = np.zeros(ncurves, dtype=np.int64)
    nfig = np.zeros(ncurves, dtype=np.int64)
    nunsat = np.zeros(ncurves, dtype=np.int64)
    span = np.zeros((ncurves, 2), dtype=np.int64)
    # scratch, sized for the largest curve
    m1 = nmax + 1
    Q = np.empty((m1, 2))
    qf = np.empty(m1, dtype=np.bool_)
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
    oo[0] = 0
    for k in range(ncurves):
        s, n = offsets[k], offsets[k + 1] - offsets[k]
        cl = closed[k]
        if n == 0:
            oo[k + 1] = pos
            continue
        start = pos
        lo, hi = core[k, 0], core[k, 1]
        # the curve: rows b .. b + n - 1 of V (the input, or its copy without zero edges)
        if _has_zero_edge(P, s, n, cl):
            if lo != 0 or hi != n:  # a block: compacting would shift its core
                span[k, 0], span[k, 1] = -1, -1
                oo[k + 1] = pos
                continue
            n = _compact_curve(P, fixed, s, n, cl, Q, qf)
            hi = n
            V, b = Q, 0
            for t in range(n):
                fx[t] = qf[t]
        else:
            V, b = P, s
            for t in range(n):
                fx[t] = fixed[s + t]
        if not cl:
            fx[0] = True
            fx[n - 1] = True
        anyfix = False
        # edges and unit vectors; the turn at every vertex, from the edge before it
        ex = V[b, 0] - V[b + n - 1, 0]
        ey = V[b, 1] - V[b + n - 1, 1]
        le = math.sqrt(0.0 + ex * ex + ey * ey)
        inv = 1.0 / le if le > 0.0 else 0.0
        length[n - 1], ux[n - 1], uy[n - 1] = le, ex * inv, ey * inv
        for i in range(n):
            if i < n - 1:
                ex = V[b + i + 1, 0] - V[b + i, 0]
                ey = V[b + i + 1, 1] - V[b + i, 1]
                le = math.sqrt(0.0 + ex * ex + ey * ey)
                inv = 1.0 / le if le > 0.0 else 0.0
                length[i], ux[i], uy[i] = le, ex * inv, ey * inv
            h = i - 1 if i > 0 else n - 1
            cri = ux[h] * uy[i] - uy[h] * ux[i]
            doti = 0.0 + ux[h] * ux[i] + uy[h] * uy[i]
            cr[i] = cri
            dot[i] = doti
            scross[i] = abs(cri)
            sh = min(length[i], length[h])
            short[i] = sh
            half[i] = 0.5 * sh * sh
            if fx[i]:
                al = 0.0
                anyfix = True
            elif mode == MODE_REGULAR:
                al = _profile(math.atan2(abs(cri), -doti), brk, coef)
            elif mode == MODE_CONSTANT:
                al = const
            else:
                al = alpha_in[s + i]
            alpha[i] = al
            # cut length and signed cut area (kept current by the restriction passes)
            a[i] = al * sh
            K[i] = al * al * half[i] * cri
            if restrict:
                alpha0[i] = al
                turning[i] = (not fx[i]) and abs(cri) > 0.0
                tanb[i] = (1.0 + doti) / abs(cri) if turning[i] else 0.0
        if restrict:
            r = _restrict(
                n, cl, anyfix, alpha, alpha0, half, cr, scross, dot, short, length, fx, c, C,
                max_passes, min_factor, a, K, tanb, fv, turning, endish, pending, check,
                cand, edges, edges2, lo, hi, tq,
            )  # fmt: skip
            nred[k], nunsat[k] = r
        # emit: vertex i -> [L_i, R_i] or [V_i]; edge i -> [G_i] or the Fig. 11 pair
        nf = 0
        span[k, 1] = -2
        for i in range(n):
            if pos + 5 > cap:  # at most 4 points per vertex and a closing one
                return OUT, of, -1, oo, nred, nfig, nunsat, span  # the caller retries
            if i == lo:
                span[k, 0] = pos
            if i == hi:
                span[k, 1] = pos
            h = i - 1 if i > 0 else n - 1
            j = i + 1 if i + 1 < n else 0
            vx, vy = V[b + i, 0], V[b + i, 1]
            ai = a[i]
            rx = vx + ai * ux[i]
            ry = vy + ai * uy[i]
            if fx[i] or ai == 0.0:
                OUT[pos, 0], OUT[pos, 1] = vx, vy
                of[pos] = fx[i]
                pos += 1
            else:
                OUT[pos, 0] = vx - ai * ux[h]
                OUT[pos, 1] = vy - ai * uy[h]
                OUT[pos + 1, 0] = rx
                OUT[pos + 1, 1] = ry
                of[pos] = False
                of[pos + 1] = False
                pos += 2
            if not cl and i == n - 1:
                continue  # no wrap edge on an open curve
            A = 0.5 * (K[i] + K[j])
            w = 0.5 * (length[i] - ai - a[j])
            winv = 1.0 / w if w > 0.0 else 0.0
            lx = V[b + j, 0] - a[j] * ux[i]
            ly = V[b + j, 1] - a[j] * uy[i]
            mx = 0.5 * (rx + lx)
            my = 0.5 * (ry + ly)
            k1, k2 = K[i], K[j]
            fig = (
                k1 * k2 < 0.0
                and abs(k1 + k2) <= balance_tol * 0.5 * (abs(k1) + abs(k2))
                and w > 0.0
            )
            if not fig:
                sv = A * winv
                OUT[pos, 0] = mx + sv * uy[i]
                OUT[pos, 1] = my - sv * ux[i]
                of[pos] = False
                pos += 1
                continue
            # Fig. 11: two congruent triangles on the halves, on opposite sides
            if lo <= i < hi:
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
            OUT[pos, 0] = q1x + s1 * h1 * uy[i]
            OUT[pos, 1] = q1y - s1 * h1 * ux[i]
            OUT[pos + 1, 0] = q2x - s1 * h2 * uy[i]
            OUT[pos + 1, 1] = q2y + s1 * h2 * ux[i]
            of[pos] = False
            of[pos + 1] = False
            pos += 2
        nfig[k] = nf
        if span[k, 1] == -2:
            span[k, 1] = pos
        if close_out and cl:
            OUT[pos, 0], OUT[pos, 1] = OUT[start, 0], OUT[start, 1]
            of[pos] = False
            pos += 1
        oo[k + 1] = pos
    return OUT, of, pos, oo, nred, nfig, nunsat, span


@njit(cache=True, nogil=True)
def _restrict(
    n, cl, anyfix, alpha, alpha0, half, cr, scross, dot, short, length, fx, c, C, max_passes,
    min_factor, a, K, tanb, fv, turning, endish, pending, check, cand, edges, edges2, lo, hi, tq,
):  # fmt: skip
    """Local alpha decrease of one curve; the rules and schedule of ``restrict_passes``.

    The counts cover vertices and edges ``lo .. hi - 1`` (the core of a block).

    On entry ``alpha0 = alpha``, ``a``, ``K``, ``turning`` and ``tanb`` hold the
    profile's values, ``fv`` is all 1 and ``check`` all False (both are left so).
    ``alpha``, ``a`` and ``K`` are decreased in place. ``tq`` (scratch) keeps, per vertex,
    ``tan(C / 2 * tau)`` of its turn ``tau`` once computed (a vertex is the minor one
    of up to two edges, in several passes; the value does not change). Returns
    ``(nred, nunsat)``.
    """
    for i in range(n):
        pending[i] = False
        tq[i] = -1.0
        if anyfix:
            j = i + 1 if i + 1 < n else 0
            endish[i] = (fx[i] and turning[j]) or (fx[j] and turning[i])
        else:
            endish[i] = False
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
        *flags, *ints, 0, n, np.empty(n + 1),
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
def add_origins(P, offsets, origin):
    """``P += origin`` of every curve, in place."""
    for k in range(offsets.shape[0] - 1):
        ox, oy = origin[k, 0], origin[k, 1]
        for i in range(offsets[k], offsets[k + 1]):
            P[i, 0] += ox
            P[i, 1] += oy


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
