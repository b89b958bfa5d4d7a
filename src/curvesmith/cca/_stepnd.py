"""The N-d CCA1 step in whole-array numpy: 3D polylines, and the reference of the 2D kernel.

One step on coordinate columns (``d`` arrays of length ``n``): corner cuts,
restrictions (:func:`~curvesmith.cca._restrict.restrict_passes`), augmenting
apexes, Fig. 11 edges in 2D, and the assembly of the output. In 2D it computes
the same values as the compiled kernel :mod:`curvesmith.cca._kernel` (the tests
compare both); non-planar 3D input (section 5) is smoothed here only.
"""

from __future__ import annotations

import numpy as np

from ._angle import interior_angle
from ._input import dedupe
from ._restrict import restrict as restrict_alphas
from ._restrict import roll_m1, roll_p1


def compact(cols, fixed, closed):
    """Remove zero-length edges (consecutive duplicates) from coordinate columns."""
    p = np.column_stack(cols)
    p, fixed = dedupe(p, fixed, closed)
    return [np.ascontiguousarray(p[:, k]) for k in range(p.shape[1])], fixed


def step(cols, fixed, closed, alpha_fn, restrict, c, C, tilt_n, balance_tol, limits):
    d = len(cols)
    e = [roll_m1(x) - x for x in cols]  # edge i: V_i -> V_{i+1} (wrap edge absent if open)
    length = np.sqrt(sum(ek * ek for ek in e))
    if np.any(length[: (None if closed else -1)] == 0):
        cols, fixed = compact(cols, fixed, closed)
        e = [roll_m1(x) - x for x in cols]
        length = np.sqrt(sum(ek * ek for ek in e))
    n = length.shape[0]
    edge_on = np.ones(n, dtype=bool)
    if not closed:
        edge_on[-1] = False
        fixed = fixed.copy()
        fixed[0] = fixed[-1] = True
    pos = length > 0
    inv = np.divide(1.0, length, out=np.zeros(n), where=pos)
    u = [ek * inv for ek in e]
    up = [roll_p1(uk) for uk in u]
    len_prev = roll_p1(length)

    # turn at every vertex: cross(u_{i-1}, u_i) (scalar in 2D, vector in 3D) and dot
    if d == 2:
        cr = [up[0] * u[1] - up[1] * u[0]]
        scross = np.abs(cr[0])
    else:
        cr = [
            up[1] * u[2] - up[2] * u[1],
            up[2] * u[0] - up[0] * u[2],
            up[0] * u[1] - up[1] * u[0],
        ]
        scross = np.sqrt(cr[0] ** 2 + cr[1] ** 2 + cr[2] ** 2)
    dot = sum(a * b for a, b in zip(up, u, strict=True))
    theta = interior_angle(scross, dot)  # in [0, pi], the kernel's bits
    free = ~fixed
    alpha = np.zeros(n)
    alpha[free] = alpha_fn(theta[free])
    short = np.minimum(length, len_prev)
    half_a2 = 0.5 * short * short  # K_i = alpha_i^2 * half_a2_i * cross_i

    nred = 0
    nunsat = 0
    if restrict:
        alpha, nred, nunsat, _, _ = restrict_alphas(
            alpha, half_a2, cr, scross, dot, short, length, fixed, edge_on, c, C, limits
        )

    a = alpha * short
    kfac = alpha * alpha * half_a2
    K = [kfac * ck for ck in cr]  # signed / vector cut areas
    K1 = K
    K2 = [roll_m1(k) for k in K]
    A = [0.5 * (k1 + k2) for k1, k2 in zip(K1, K2, strict=True)]  # augmentation per edge
    a_next = roll_m1(a)
    w = 0.5 * (length - a - a_next)
    wpos = w > 0
    winv = np.divide(1.0, w, out=np.zeros(n), where=wpos)

    # cut points
    Lp = [x - a * uk for x, uk in zip(cols, up, strict=True)]
    Rp = [x + a * uk for x, uk in zip(cols, u, strict=True)]
    Lnext = [roll_m1(lk) for lk in Lp]
    M = [0.5 * (r + ln) for r, ln in zip(Rp, Lnext, strict=True)]
    # apex offset = cross(u, A) / w
    if d == 2:
        s = A[0] * winv
        G = [M[0] + s * u[1], M[1] - s * u[0]]
    else:
        G = [
            M[0] + (u[1] * A[2] - u[2] * A[1]) * winv,
            M[1] + (u[2] * A[0] - u[0] * A[2]) * winv,
            M[2] + (u[0] * A[1] - u[1] * A[0]) * winv,
        ]

    # Fig. 11: balanced inflection edges (2D)
    fig = np.zeros(n, dtype=bool)
    if d == 2:
        k1, k2 = K1[0], K2[0]
        mag = np.abs(k1) + np.abs(k2)
        fig = edge_on & (k1 * k2 < 0) & (np.abs(k1 + k2) <= balance_tol * 0.5 * mag) & wpos
    nfig = int(np.count_nonzero(fig))
    if nfig:
        i = np.flatnonzero(fig)
        s1 = np.sign(K1[0][i])
        phi = np.full(i.size, tilt_n)
        if restrict:
            tau1 = np.arctan2(scross[i], dot[i])
            j = (i + 1) % n
            tau2 = np.arctan2(scross[j], dot[j])
            phi = np.minimum(phi, C * 0.5 * np.minimum(tau1, tau2))
        wi = w[i]
        hb = 0.5 * wi * np.tan(phi)
        carry = s1 * A[0][i] / wi
        h1, h2 = hb + carry, hb - carry
        ux, uy = u[0][i], u[1][i]
        Mx, My = M[0][i], M[1][i]
        Rx, Ry = Rp[0][i], Rp[1][i]
        Lx, Ly = Lnext[0][i], Lnext[1][i]
        q1x, q1y = 0.5 * (Rx + Mx), 0.5 * (Ry + My)
        q2x, q2y = 0.5 * (Mx + Lx), 0.5 * (My + Ly)
        # right normal (uy, -ux); first apex on side s1 (opposite the cut at V_i)
        apx = q1x + s1 * h1 * uy
        apy = q1y - s1 * h1 * ux
        bpx = q2x - s1 * h2 * uy
        bpy = q2y + s1 * h2 * ux

    # assemble: vertex i -> [L_i, R_i] (or [V_i] if fixed / uncut), edge i -> [G_i] or [A', B']
    single = fixed | (a == 0)
    cnt_v = np.where(single, 1, 2)
    cnt_e = edge_on.astype(np.intp) + fig
    cnt = cnt_v + cnt_e
    start = np.cumsum(cnt) - cnt
    total = int(start[-1] + cnt[-1]) if n else 0
    out = [np.empty(total) for _ in range(d)]
    two = ~single
    s_first = start
    s_second = start[two] + 1
    s_edge = (start + cnt_v)[edge_on]
    for k in range(d):
        first = np.where(single, cols[k], Lp[k])
        out[k][s_first] = first
        out[k][s_second] = Rp[k][two]
        out[k][s_edge] = G[k][edge_on]
    if nfig:
        se = start[i] + cnt_v[i]
        out[0][se] = apx
        out[1][se] = apy
        out[0][se + 1] = bpx
        out[1][se + 1] = bpy
    newfixed = np.zeros(total, dtype=bool)
    newfixed[start[fixed]] = True
    return out, newfixed, nred, nfig, nunsat
