"""Restriction rules of CCA1: the local alpha decrease (Definition 2, Lemma 4, section 3.2).

:func:`restrict_passes` is the whole-array numpy form for any dimension (2D
signed cut areas, 3D vector cut areas); it is the reference the compiled 2D
kernel (:mod:`curvesmith.cca._kernel`) is tested against, and the restriction
of the N-d step (:mod:`curvesmith.cca._stepnd`). The rules themselves are
described in the notes of :mod:`curvesmith.cca`.
"""

from __future__ import annotations

import numpy as np

#: Factor applied to every computed decrease, so that the decreased edge clears its bound.
SHRINK = 1.0 - 8.0 * np.finfo(float).eps


def roll_m1(a: np.ndarray) -> np.ndarray:
    """a[i+1] (cyclic)."""
    out = np.empty_like(a)
    out[:-1] = a[1:]
    out[-1] = a[0]
    return out


def roll_p1(a: np.ndarray) -> np.ndarray:
    """a[i-1] (cyclic)."""
    out = np.empty_like(a)
    out[1:] = a[:-1]
    out[0] = a[-1]
    return out


def restrict(*args):
    # Nearly straight vertices (sin of the turning angle ~1e-309) give tan(beta) = inf;
    # the comparisons below then decide correctly (inf demands a decrease where there is
    # a cut area, inf * 0 = nan demands none), so overflow is expected, not an error.
    with np.errstate(over="ignore", invalid="ignore"):
        return restrict_passes(*args)


def restrict_passes(alpha, half_a2, cr, scross, dot, short, length, fixed, edge_on, c, C, limits):
    """Local alpha decrease for Definition 2 / Fig. 12 and the section 3.2 inflection rule.

    Per edge ``i`` (vertices ``i``, ``i + 1``): convex and end edges need
    ``w^2 >= c T |A|`` (``tan(gamma) >= c tan(beta)``), inflection edges
    ``|K_1 + K_2| <= 2 w^2 tan(C |tau_m| / 2)``. The first pass checks every
    edge, later passes only the edges next to vertices just decreased. Returns
    the decreased alphas, the number of vertices decreased, the number of
    edges violating at the end (pass limit reached, or decreases stopped by the
    ``min_factor`` floor), and the matching cut lengths ``a`` and cut areas
    ``K`` (so the caller need not recompute them). An edge is rechecked only
    when one of its vertices moved, so each edge's violation state is kept from
    its latest check: an edge stuck at the floor stays counted while decreases
    elsewhere go on.
    """
    max_passes, min_factor = limits
    n = alpha.shape[0]
    alpha = alpha.copy()
    alpha0 = alpha.copy()
    floor = min_factor * alpha0
    turning = ~fixed & (scross > 0)
    tanb = np.zeros(n)
    np.divide(1.0 + dot, scross, out=tanb, where=turning)  # tan(beta) = cot(|tau| / 2)
    endish_all = (fixed & roll_m1(turning)) | (roll_m1(fixed) & turning)  # end edges
    a = alpha * short
    kfac = alpha * alpha * half_a2
    K = [kfac * ck for ck in cr]
    edges = None  # None: all edges
    # violation state of every edge at its latest check: an edge is rechecked only when
    # one of its vertices moved, so this is the state at the end for every edge
    pending = np.zeros(n, dtype=bool)
    for npass in range(max_passes + 1):
        if edges is None:  # first pass: all edges, with shifts instead of gathers
            i = np.arange(n)
            j = roll_m1(i)
            K1 = K
            K2 = [roll_m1(k) for k in K]
            w = 0.5 * (length - a - roll_m1(a))
        else:
            i = edges
            j = i + 1
            j[j == n] = 0
            K1 = [k[i] for k in K]
            K2 = [k[j] for k in K]
            w = 0.5 * (length[i] - a[i] - a[j])
        if len(cr) == 1:
            k12 = K1[0] * K2[0]
            net = np.abs(K1[0] + K2[0])
        else:
            k12 = sum(p * q for p, q in zip(K1, K2, strict=True))
            net = np.sqrt(sum((p + q) ** 2 for p, q in zip(K1, K2, strict=True)))
        w2 = w * w
        if edges is None:
            T = np.maximum(tanb, roll_m1(tanb))
            endish = endish_all
            on = edge_on
        else:
            T = np.maximum(tanb[i], tanb[j])
            endish = endish_all[i]
            on = edge_on[i]
        need_c = (0.5 * c) * T * net  # c T |A|
        viol_c = (w2 < need_c * (1.0 - 1e-12)) & ((k12 > 0) | endish) & on
        ic = np.flatnonzero(viol_c)
        # inflection edges: epsilon = atan(|A| / w^2) <= C |tau_m| / 2
        ii = np.flatnonzero((k12 < 0) & on)
        if len(cr) == 1:
            m1 = np.abs(K1[0][ii])
            m2 = np.abs(K2[0][ii])
        else:
            m1 = np.sqrt(sum(k[ii] ** 2 for k in K1))
            m2 = np.sqrt(sum(k[ii] ** 2 for k in K2))
        minor2 = m2 <= m1
        mv = np.where(minor2, j[ii], i[ii])
        tau_m = np.arctan2(scross[mv], dot[mv])
        s2 = 2.0 * w2[ii] * np.tan(0.5 * C * tau_m)  # bound on |K_1 + K_2|
        bad = net[ii] > s2 * (1.0 + 1e-12)
        nbad = int(np.count_nonzero(bad))
        pending[i] = False
        pending[i[ic]] = True
        pending[i[ii[bad]]] = True
        if (ic.size == 0 and nbad == 0) or npass == max_passes:
            break
        f = np.sqrt(w2[ic] / need_c[ic]) * SHRINK
        verts = [i[ic], j[ic]]
        facs = [f, f]
        if nbad:
            ib, mi2 = ii[bad], minor2[bad]
            mag_d = np.where(mi2, m1[bad], m2[bad])
            mag_m = np.where(mi2, m2[bad], m1[bad])
            dotab = k12[ib]  # K_d . K_m
            sb = s2[bad]
            # largest t = f^2 with |t K_d + K_m| <= s2 (2D: t = (|K_m| + s2) / |K_d|)
            disc = dotab * dotab - mag_d * mag_d * (mag_m * mag_m - sb * sb)
            ok = disc >= 0
            t = (-dotab + np.sqrt(np.maximum(disc, 0.0))) / (mag_d * mag_d)
            f_dom = np.sqrt(np.clip(t, 0.0, 1.0)) * SHRINK
            dom = np.where(mi2, i[ib], j[ib])
            verts.append(dom[ok])
            facs.append(f_dom[ok])
            if not ok.all():
                # 3D only: the dominant cut alone cannot reach the bound; scale both
                fb = np.sqrt(sb[~ok] / net[ib[~ok]]) * SHRINK
                verts += [i[ib[~ok]], j[ib[~ok]]]
                facs += [fb, fb]
        v = np.concatenate(verts)
        fv = np.concatenate(facs)
        f_v = np.ones(n)
        np.minimum.at(f_v, v, fv)  # per vertex the smallest factor of its edges
        f_v[fixed] = 1.0
        v = np.flatnonzero(f_v < 1.0)
        new = np.maximum(alpha[v] * f_v[v], floor[v])
        moved = new < alpha[v]
        if not moved.all():
            v, new = v[moved], new[moved]
            if v.size == 0:  # every violation sits at the floor
                break
        alpha[v] = new
        a[v] = alpha[v] * short[v]
        kv = alpha[v] * alpha[v] * half_a2[v]
        for k, ck in zip(K, cr, strict=True):
            k[v] = kv * ck[v]
        touched = np.zeros(n, dtype=bool)
        touched[v] = True
        touched[v - 1] = True  # edge v - 1 ends at v (index -1 wraps to n - 1)
        edges = np.flatnonzero(touched)
    nred = int(np.count_nonzero(alpha < alpha0))
    return alpha, nred, int(np.count_nonzero(pending)), a, K
