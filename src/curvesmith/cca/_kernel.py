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
def _has_zero_edge(x, y, s, n, closed):
    last = n if closed else n - 1
    for i in range(last):
        j = s + i + 1 if i + 1 < n else s
        ex = x[j] - x[s + i]
        ey = y[j] - y[s + i]
        if math.sqrt(ex * ex + ey * ey) == 0.0:
            return True
    return False


@njit(cache=True, nogil=True)
def _dedupe(x, y, fixed, s, n, closed, cx, cy, cf):
    """Copy curve ``s .. s + n - 1`` into ``cx, cy, cf`` without duplicates; return the count.

    The rules of :func:`curvesmith.cca._input.dedupe`: trailing copies of the first
    vertex of a ring go first (their fixed flags move to vertex 0), then every vertex
    equal to its predecessor (its fixed flag moves to the kept copy).
    """
    k = n
    f0 = fixed[s]
    if closed and n > 1:
        while k > 1 and _zero_gap(x[s + k - 1] - x[s], y[s + k - 1] - y[s]):
            k -= 1
        for t in range(k, n):
            f0 = f0 or fixed[s + t]
    m = 0
    for t in range(k):
        f = f0 if t == 0 else fixed[s + t]
        if t > 0 and _zero_gap(x[s + t] - x[s + t - 1], y[s + t] - y[s + t - 1]):
            cf[m - 1] = cf[m - 1] or f
            continue
        cx[m] = x[s + t]
        cy[m] = y[s + t]
        cf[m] = f
        m += 1
    return m


@njit(cache=True, nogil=True)
def compact_ragged(x, y, fixed, offsets, closed):
    """Remove zero-length edges of every curve (as the step does before cutting)."""
    ncurves = offsets.shape[0] - 1
    nmax = 1
    for k in range(ncurves):
        nmax = max(nmax, offsets[k + 1] - offsets[k])
    cx, cy = np.empty(nmax), np.empty(nmax)
    cf = np.empty(nmax, dtype=np.bool_)
    ox, oy = np.empty(x.shape[0]), np.empty(x.shape[0])
    of = np.empty(x.shape[0], dtype=np.bool_)
    oo = np.empty(ncurves + 1, dtype=np.int64)
    oo[0] = 0
    pos = 0
    for k in range(ncurves):
        s, n = offsets[k], offsets[k + 1] - offsets[k]
        if n > 0 and _has_zero_edge(x, y, s, n, closed[k]):
            m = _dedupe(x, y, fixed, s, n, closed[k], cx, cy, cf)
            while m > 1 and _has_zero_edge(cx, cy, 0, m, closed[k]):
                m = _dedupe(cx.copy(), cy.copy(), cf.copy(), 0, m, closed[k], cx, cy, cf)
            for t in range(m):
                ox[pos + t], oy[pos + t], of[pos + t] = cx[t], cy[t], cf[t]
        else:
            m = n
            for t in range(n):
                ox[pos + t], oy[pos + t], of[pos + t] = x[s + t], y[s + t], fixed[s + t]
        pos += m
        oo[k + 1] = pos
    return ox[:pos].copy(), oy[:pos].copy(), of[:pos].copy(), oo


@njit(cache=True, nogil=True)
def angles_ragged(x, y, offsets, closed):
    """Interior angle ``atan2(|cross|, -dot)`` at every vertex (for a callable alpha)."""
    theta = np.zeros(x.shape[0])
    for k in range(offsets.shape[0] - 1):
        s, n = offsets[k], offsets[k + 1] - offsets[k]
        for i in range(n):
            h = s + (i - 1 if i > 0 else n - 1)
            j = s + (i + 1 if i + 1 < n else 0)
            upx, upy = _unit(x[s + i] - x[h], y[s + i] - y[h])
            ux, uy = _unit(x[j] - x[s + i], y[j] - y[s + i])
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
    x,
    y,
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
):
    """One CCA1 step on every curve of a ragged batch.

    Returns ``ox, oy, ofixed, ooffsets, nred, nfig, nunsat``: the new columns, the
    fixed mask of the output (each fixed vertex is emitted once, as itself), the
    offsets of the output curves and, per curve, the number of local alpha
    decreases, of Fig. 11 edges and of edges left violating a restriction.
    """
    ncurves = offsets.shape[0] - 1
    nmax = 1
    for k in range(ncurves):
        nmax = max(nmax, offsets[k + 1] - offsets[k])
    total = x.shape[0]
    ox = np.empty(4 * total)
    oy = np.empty(4 * total)
    of = np.zeros(4 * total, dtype=np.bool_)
    oo = np.empty(ncurves + 1, dtype=np.int64)
    nred = np.zeros(ncurves, dtype=np.int64)
    nfig = np.zeros(ncurves, dtype=np.int64)
    nunsat = np.zeros(ncurves, dtype=np.int64)
    # scratch, sized for the largest curve
    m1 = nmax + 1
    cx, cy = np.empty(m1), np.empty(m1)
    cf = np.empty(m1, dtype=np.bool_)
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
    pos = 0
    oo[0] = 0
    for k in range(ncurves):
        s, n = offsets[k], offsets[k + 1] - offsets[k]
        cl = closed[k]
        if n == 0:
            oo[k + 1] = pos
            continue
        # the curve in the scratch columns, zero-length edges removed
        if _has_zero_edge(x, y, s, n, cl):
            n = _dedupe(x, y, fixed, s, n, cl, cx, cy, cf)
            while n > 1 and _has_zero_edge(cx, cy, 0, n, cl):
                n = _dedupe(cx.copy(), cy.copy(), cf.copy(), 0, n, cl, cx, cy, cf)
        else:
            for t in range(n):
                cx[t], cy[t], cf[t] = x[s + t], y[s + t], fixed[s + t]
        for t in range(n):
            fx[t] = cf[t]
        if not cl:
            fx[0] = True
            fx[n - 1] = True
        # edges, unit vectors, turn at every vertex
        for i in range(n):
            j = i + 1 if i + 1 < n else 0
            ex = cx[j] - cx[i]
            ey = cy[j] - cy[i]
            le = math.sqrt(0.0 + ex * ex + ey * ey)
            length[i] = le
            inv = 1.0 / le if le > 0.0 else 0.0
            ux[i] = ex * inv
            uy[i] = ey * inv
        for i in range(n):
            h = i - 1 if i > 0 else n - 1
            cr[i] = ux[h] * uy[i] - uy[h] * ux[i]
            dot[i] = 0.0 + ux[h] * ux[i] + uy[h] * uy[i]
            scross[i] = abs(cr[i])
            short[i] = min(length[i], length[h])
            half[i] = 0.5 * short[i] * short[i]
            if fx[i]:
                alpha[i] = 0.0
            elif mode == MODE_REGULAR:
                alpha[i] = _profile(math.atan2(scross[i], -dot[i]), brk, coef)
            elif mode == MODE_CONSTANT:
                alpha[i] = const
            else:
                alpha[i] = alpha_in[s + i]
        if restrict:
            r = _restrict(
                n, cl, alpha, alpha0, half, cr, scross, dot, short, length, fx, c, C,
                max_passes, min_factor, a, K, tanb, fv, turning, endish, pending, check,
                cand, edges,
            )  # fmt: skip
            nred[k], nunsat[k] = r
        # cut lengths and cut areas of the final alphas
        for i in range(n):
            a[i] = alpha[i] * short[i]
            K[i] = alpha[i] * alpha[i] * half[i] * cr[i]
        # emit: vertex i -> [L_i, R_i] or [V_i]; edge i -> [G_i] or the Fig. 11 pair
        nf = 0
        for i in range(n):
            h = i - 1 if i > 0 else n - 1
            j = i + 1 if i + 1 < n else 0
            if fx[i] or a[i] == 0.0:
                ox[pos], oy[pos] = cx[i], cy[i]
                of[pos] = fx[i]
                pos += 1
            else:
                ox[pos] = cx[i] - a[i] * ux[h]
                oy[pos] = cy[i] - a[i] * uy[h]
                ox[pos + 1] = cx[i] + a[i] * ux[i]
                oy[pos + 1] = cy[i] + a[i] * uy[i]
                pos += 2
            if not cl and i == n - 1:
                continue  # no wrap edge on an open curve
            A = 0.5 * (K[i] + K[j])
            w = 0.5 * (length[i] - a[i] - a[j])
            winv = 1.0 / w if w > 0.0 else 0.0
            rx = cx[i] + a[i] * ux[i]
            ry = cy[i] + a[i] * uy[i]
            lx = cx[j] - a[j] * ux[i]
            ly = cy[j] - a[j] * uy[i]
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
                ox[pos] = mx + sv * uy[i]
                oy[pos] = my - sv * ux[i]
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
            ox[pos] = q1x + s1 * h1 * uy[i]
            oy[pos] = q1y - s1 * h1 * ux[i]
            ox[pos + 1] = q2x - s1 * h2 * uy[i]
            oy[pos + 1] = q2y + s1 * h2 * ux[i]
            pos += 2
        nfig[k] = nf
        oo[k + 1] = pos
    return ox[:pos].copy(), oy[:pos].copy(), of[:pos].copy(), oo, nred, nfig, nunsat


@njit(cache=True, nogil=True)
def _restrict(
    n, cl, alpha, alpha0, half, cr, scross, dot, short, length, fx, c, C, max_passes,
    min_factor, a, K, tanb, fv, turning, endish, pending, check, cand, edges,
):  # fmt: skip
    """Local alpha decrease of one curve; the rules and schedule of ``restrict_passes``.

    Returns ``(nred, nunsat)``; ``alpha`` is decreased in place.
    """
    for i in range(n):
        alpha0[i] = alpha[i]
        turning[i] = (not fx[i]) and scross[i] > 0.0
        tanb[i] = (1.0 + dot[i]) / scross[i] if turning[i] else 0.0
        a[i] = alpha[i] * short[i]
        K[i] = alpha[i] * alpha[i] * half[i] * cr[i]
        fv[i] = 1.0
        pending[i] = False
        check[i] = False
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
                tau_m = math.atan2(scross[mv], dot[mv])
                s2 = 2.0 * w2 * math.tan(0.5 * C * tau_m)
                if net > s2 * (1.0 + 1e-12):
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
        # apply the smallest factor of every vertex, from the state before the pass
        nmoved = 0
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
            check[v] = True
            check[v - 1 if v > 0 else n - 1] = True  # the edge ending at v
            nmoved += 1
        if nmoved == 0:
            break  # every violation sits at the floor
        ne = 0
        for i in range(nlast):
            if check[i]:
                edges[ne] = i
                ne += 1
                check[i] = False
        for i in range(nlast, n):
            check[i] = False
    nred = 0
    nunsat = 0
    for i in range(n):
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
    scratch = [np.empty(n + 1) for _ in range(5)]
    flags = [np.empty(n + 1, dtype=np.bool_) for _ in range(4)]
    ints = [np.empty(2 * n + 2, dtype=np.int64), np.empty(n + 1, dtype=np.int64)]
    nred, nunsat = _restrict(
        n, closed, alpha, scratch[0], half, cr, scross, dot, short, length,
        np.asarray(fixed, dtype=np.bool_), c, C, limits[0], limits[1], *scratch[1:],
        *flags, *ints,
    )  # fmt: skip
    return alpha, int(nred), int(nunsat)
