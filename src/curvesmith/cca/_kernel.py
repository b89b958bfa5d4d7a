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

The loops are written for the compiler's vectorizer: the coordinates of a unit are
two arrays (x and y), the arithmetic of every vertex and edge runs in loops without
branches (the interior angle, the profile's piece, ``min``/``max`` and the special
cases are selects), the first restriction pass marks the few edges that might break
a rule in such a loop before it checks them one by one, and the output rows are
computed in one before they are written in another. LLVM compiles such loops to
vector instructions for the machine's CPU (AVX-512: 8 vertices at a time, AVX2: 4;
the compiled step holds packed divisions and square roots); the branches of the
plain form, unpredictable on a rough curve, had kept it scalar at about twice the
time per vertex. Division by zero gives inf/NaN as in numpy (``error_model="numpy"``:
no check, no branch); every such value is selected away, as in the numpy form. A
helper inlined into its caller (``inline="always"``) takes the caller's error model,
not its own: every function that inlines one is compiled with ``error_model="numpy"``
too (a caller without it would raise ZeroDivisionError where the helper divides by 0).

The arithmetic is the N-d numpy step's (:func:`curvesmith.cca._stepnd.step`
with :func:`curvesmith.cca._restrict.restrict_passes`) operation by operation,
in the same order: numba compiles without ``fastmath`` (no reassociation, no
fused multiply-add), so the results agree with numpy to the last bit. The
profile's interior angle is :mod:`curvesmith.cca._angle`'s (fdlibm's ``atan``,
the same bits in both); the ``atan2``/``tan`` of the inflection bound and of
Fig. 11 are the C library's, which may differ from numpy's own in the last ulp
(the tests give the numpy reference the C library's there). The restriction
passes follow the same schedule: the first pass checks every edge (those its
vector loop clears have no violation: the tests it skips could not fail), later
passes only the edges next to the vertices just decreased, and all decreases of a
pass are computed from the state before it.

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


@njit(cache=True, nogil=True, inline="always", error_model="numpy")
def _nanmin(a, b):
    # np.minimum: NaN if either is NaN (selects, no branch)
    m = a if a <= b else b
    return math.nan if (a != a) | (b != b) else m


@njit(cache=True, nogil=True, inline="always", error_model="numpy")
def _nanmax(a, b):
    # np.maximum: NaN if either is NaN (selects, no branch)
    m = a if a >= b else b
    return math.nan if (a != a) | (b != b) else m


@njit(cache=True, nogil=True, inline="always", error_model="numpy")
def _profile(theta, brk, coef):
    # the pieces of the PCHIP profile: index = inner breakpoints below theta (they
    # increase: a sum of comparisons, no branch), then Horner
    idx = 0
    for b in range(1, brk.shape[0] - 1):
        idx += theta > brk[b]
    dt = theta - brk[idx]
    out = coef[0, idx]
    for k in range(1, 4):
        out = out * dt
        out = out + coef[k, idx]
    return out


_ATAN_INF = _A.ATAN_HI[3] + _A.ATAN_LO[3]


@njit(cache=True, nogil=True, inline="always", error_model="numpy")
def _interior(scross, dot):
    """:func:`curvesmith.cca._angle.interior_angle`, one value: the same operations.

    ``atan2(scross, -dot)`` as fdlibm's ``atan`` of ``t = scross / |dot|``, written
    without a branch: every range's reduction ``x = (na t + nb) / (dc + dd t)`` (``t``,
    ``(2t - 1) / (2 + t)``, ``(t - 1) / (t + 1)``, ``(t - 1.5) / (1 + 1.5 t)``, ``-1 / t``:
    the products by 1 and 0 and the sums with 0 are exact, so these are fdlibm's bits)
    and table angle ``hi + lo`` are selected, and so are the results of the special
    cases (``t`` below TINY or from HUGE on, ``dot`` 0 or positive). A loop of these
    compiles to vector instructions (8 angles at a time with AVX-512, 4 with AVX2; the
    branches of the plain form, unpredictable on a rough curve, kept it scalar at 3-4x
    the time).
    """
    t = scross / abs(dot)
    c0, c1, c2, c3 = t >= _A.B0, t >= _A.B1, t >= _A.B2, t >= _A.B3
    na = 2.0 if c0 else 1.0
    nb = -1.0 if c0 else 0.0
    dc = 2.0 if c0 else 1.0
    dd = 1.0 if c0 else 0.0
    hi = _A.ATAN_HI[0] if c0 else 0.0
    lo = _A.ATAN_LO[0] if c0 else 0.0
    na = 1.0 if c1 else na
    dc = 1.0 if c1 else dc
    hi = _A.ATAN_HI[1] if c1 else hi
    lo = _A.ATAN_LO[1] if c1 else lo
    nb = -1.5 if c2 else nb
    dd = 1.5 if c2 else dd
    hi = _A.ATAN_HI[2] if c2 else hi
    lo = _A.ATAN_LO[2] if c2 else lo
    na = 0.0 if c3 else na
    nb = -1.0 if c3 else nb
    dc = 0.0 if c3 else dc
    dd = 1.0 if c3 else dd
    hi = _A.ATAN_HI[3] if c3 else hi
    lo = _A.ATAN_LO[3] if c3 else lo
    x = (na * t + nb) / (dc + dd * t)
    z = x * x
    w = z * z
    s1 = z * (_AT0 + w * (_AT2 + w * (_AT4 + w * (_AT6 + w * (_AT8 + w * _AT10)))))
    s2 = w * (_AT1 + w * (_AT3 + w * (_AT5 + w * (_AT7 + w * _AT9))))
    xs = x * (s1 + s2)
    z = hi - ((xs - lo) - x) if c0 else x - xs
    z = t if t < _A.TINY else z
    z = _ATAN_INF if t >= _A.HUGE else z
    angle = _A.PI - (z - _A.PI_LO) if dot > 0.0 else z
    # dot = 0: pi / 2, or pi when scross is 0 as well (atan2(+0, -0)); NaN stays NaN
    square = _A.PI if scross == 0.0 else (_A.HALF_PI if scross > 0.0 else scross)
    return square if dot == 0.0 else angle


@njit(cache=True, nogil=True, error_model="numpy")
def interior_angle(scross, dot):
    """:func:`_interior` from Python (the tests compare it with the numpy form)."""
    return _interior(scross, dot)


@njit(cache=True, nogil=True, error_model="numpy")
def _zero_gap(dx, dy):
    return not (dx * dx > 0.0 or dy * dy > 0.0)


@njit(cache=True, nogil=True, error_model="numpy")
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


@njit(cache=True, nogil=True, error_model="numpy")
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


@njit(cache=True, nogil=True, error_model="numpy")
def _compact_curve(P, fixed, s, n, closed, Q, qf):
    """The curve without zero-length edges in ``Q, qf`` (repeated until none is left)."""
    m = _dedupe(P, fixed, s, n, closed, Q, qf)
    while m > 1 and _has_zero_edge(Q, 0, m, closed):
        m = _dedupe(Q.copy(), qf.copy(), 0, m, closed, Q, qf)
    return m


@njit(cache=True, nogil=True, error_model="numpy")
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


@njit(cache=True, nogil=True, error_model="numpy")
def any_zero_edge(P, offsets, closed, org):
    """Whether some curve has a zero-length edge, in the frame of its origin ``org[k]``."""
    for k in range(offsets.shape[0] - 1):
        s, n = offsets[k], offsets[k + 1] - offsets[k]
        if n > 0 and _has_zero_edge(P, s, n, closed[k], org[k, 0], org[k, 1]):
            return True
    return False


@njit(cache=True, nogil=True, error_model="numpy")
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


@njit(cache=True, nogil=True, error_model="numpy")
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


@njit(cache=True, nogil=True, error_model="numpy")
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


@njit(cache=True, nogil=True, inline="always", error_model="numpy")
def _edges_xy(X, Y, n, closed, length, ux, uy):
    """Edge lengths and unit vectors of ``X, Y`` ``[:n]`` (edge ``n - 1`` wraps).

    Returns whether an edge that exists (every edge of a ring, all but the wrap edge
    of an open curve) has length 0: the curve must be compacted first.
    """
    zero = False
    for i in range(n - 1):
        ex = X[i + 1] - X[i]
        ey = Y[i + 1] - Y[i]
        le = math.sqrt(0.0 + ex * ex + ey * ey)
        zero |= le == 0.0
        inv = 1.0 / le if le > 0.0 else 0.0
        length[i], ux[i], uy[i] = le, ex * inv, ey * inv
    ex = X[0] - X[n - 1]
    ey = Y[0] - Y[n - 1]
    le = math.sqrt(0.0 + ex * ex + ey * ey)
    zero |= (le == 0.0) & closed
    inv = 1.0 / le if le > 0.0 else 0.0
    length[n - 1], ux[n - 1], uy[n - 1] = le, ex * inv, ey * inv
    return zero


@njit(cache=True, nogil=True, inline="always", error_model="numpy")
def _turns(ux, uy, n, cr, dot, scross):
    """Cross and dot products of the unit edges before and after every vertex."""
    cr[0] = ux[n - 1] * uy[0] - uy[n - 1] * ux[0]
    dot[0] = 0.0 + ux[n - 1] * ux[0] + uy[n - 1] * uy[0]
    scross[0] = abs(cr[0])
    for i in range(1, n):
        cri = ux[i - 1] * uy[i] - uy[i - 1] * ux[i]
        cr[i] = cri
        dot[i] = 0.0 + ux[i - 1] * ux[i] + uy[i - 1] * uy[i]
        scross[i] = abs(cri)


@njit(cache=True, nogil=True, inline="always", error_model="numpy")
def _cuts(X, Y, a, K, length, ux, uy, i, h, j, balance_tol, ax, ay, add, cuts, fig):
    """Vertex ``i``'s cut points and its edge's apex into ``cuts[i]``; ``fig[i]``: Fig. 11.

    ``cuts[i]`` holds the rows the step emits for vertex ``i`` and its edge, in order:
    the cut point ``L_i`` on the edge before it (columns 0, 1), ``R_i`` on the edge
    after it (2, 3) and the augmenting apex of edge ``i`` (4, 5); ``h`` and ``j`` are
    the vertices before and after ``i``. With ``add`` the values are in the input's
    frame (the origin ``ax, ay`` added).
    """
    vx, vy = X[i], Y[i]
    ai, aj = a[i], a[j]
    rx = vx + ai * ux[i]  # R_i
    ry = vy + ai * uy[i]
    lix = vx - ai * ux[h]  # L_i
    liy = vy - ai * uy[h]
    A = 0.5 * (K[i] + K[j])
    w = 0.5 * (length[i] - ai - aj)
    winv = 1.0 / w if w > 0.0 else 0.0
    ljx = X[j] - aj * ux[i]  # L_j, the other end of the edge's middle piece
    ljy = Y[j] - aj * uy[i]
    mx = 0.5 * (rx + ljx)
    my = 0.5 * (ry + ljy)
    sv = A * winv
    px = mx + sv * uy[i]  # the apex
    py = my - sv * ux[i]
    k1, k2 = K[i], K[j]
    fig[i] = (k1 * k2 < 0.0) & (abs(k1 + k2) <= balance_tol * 0.5 * (abs(k1) + abs(k2))) & (w > 0.0)
    cuts[i, 0] = lix + ax if add else lix
    cuts[i, 1] = liy + ay if add else liy
    cuts[i, 2] = rx + ax if add else rx
    cuts[i, 3] = ry + ay if add else ry
    cuts[i, 4] = px + ax if add else px
    cuts[i, 5] = py + ay if add else py


@njit(cache=True, nogil=True, error_model="numpy")
def _put(OUT, of, pos, x, y, f, add, ox, oy):
    # one output row; with ``add`` in the frame of the input (the curve's origin added)
    if add:
        OUT[pos, 0] = x + ox
        OUT[pos, 1] = y + oy
    else:
        OUT[pos, 0] = x
        OUT[pos, 1] = y
    of[pos] = f


@njit(cache=True, nogil=True, error_model="numpy")
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
    X, Y = np.empty(m1), np.empty(m1)
    cuts = np.empty((m1, 6))  # per core vertex: its cut points L, R and its edge's apex
    fig = np.empty(m1, dtype=np.bool_)
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
        # gather the unit, in the curve's frame, coordinates in arrays of their own (so
        # that the loops below compile to vector instructions): at most two runs of
        # rows (a block of a ring may wrap around its end)
        ox, oy = org_in[k, 0], org_in[k, 1]
        t = 0
        while t < n:
            r = lo + t
            r = r + nc if r < 0 else (r - nc if r >= nc else r)
            run = min(n - t, nc - r)
            row = s0 + r
            for q in range(run):
                X[t + q] = P[row + q, 0] - ox
                Y[t + q] = P[row + q, 1] - oy
                fx[t + q] = fixed[row + q]
            if mode == MODE_GIVEN:
                for q in range(run):
                    ga[t + q] = alpha_in[row + q]
            t += run
        if _edges_xy(X, Y, n, cl, length, ux, uy):
            # an edge of length 0: the curve without them (a block gives up: compacting
            # would shift its core)
            if n != nc:
                return OUT, of, pos, span, nred, nfig, nunsat, ZERO_EDGE
            for t in range(n):
                G[t, 0], G[t, 1] = X[t], Y[t]
            n = _compact_curve(G, fx, 0, n, cl, Q, qf)
            chi = n
            for t in range(n):
                X[t], Y[t], fx[t] = Q[t, 0], Q[t, 1], qf[t]
            _edges_xy(X, Y, n, cl, length, ux, uy)
        if not cl:
            fx[0] = True
            fx[n - 1] = True
        # the turn at every vertex, from the edge before it; its interior angle into
        # alpha, then the profile
        _turns(ux, uy, n, cr, dot, scross)
        anyfix = False
        for i in range(n):
            anyfix |= fx[i]
        if mode == MODE_REGULAR:
            for i in range(n):
                alpha[i] = _interior(scross[i], dot[i])
            for i in range(n):
                alpha[i] = 0.0 if fx[i] else _profile(alpha[i], brk, coef)
        elif mode == MODE_CONSTANT:
            for i in range(n):
                alpha[i] = 0.0 if fx[i] else const
        else:
            for i in range(n):
                alpha[i] = 0.0 if fx[i] else ga[i]
        # cut length and signed cut area (kept current by the restriction passes)
        short[0] = min(length[0], length[n - 1])
        for i in range(1, n):
            short[i] = min(length[i], length[i - 1])
        for i in range(n):
            half[i] = 0.5 * short[i] * short[i]
            a[i] = alpha[i] * short[i]
            K[i] = alpha[i] * alpha[i] * half[i] * cr[i]
        if restrict:
            for i in range(n):
                alpha0[i] = alpha[i]
                tr = (not fx[i]) & (scross[i] > 0.0)
                turning[i] = tr
                tanb[i] = (1.0 + dot[i]) / scross[i] if tr else 0.0
                pending[i] = False
                endish[i] = False
                tq[i] = -1.0
            r = _restrict(
                n, cl, anyfix, alpha, alpha0, half, cr, scross, dot, short, length, fx, c, C,
                max_passes, min_factor, a, K, tanb, fv, turning, endish, pending, check,
                cand, edges, edges2, clo, chi, tq,
            )  # fmt: skip
            nred[u], nunsat[u] = r
        # the cut points and apexes of the core, all at once (vector instructions); then
        # emitted: vertex i -> [L_i, R_i] or [V_i]; edge i -> [apex_i] or the Fig. 11 pair
        ax, ay = org_out[k, 0], org_out[k, 1]
        mid_lo, mid_hi = max(clo, 1), min(chi, n - 1)
        bt = balance_tol
        if clo == 0:
            _cuts(X, Y, a, K, length, ux, uy, 0, n - 1, 1 % n, bt, ax, ay, add_out, cuts, fig)
        for i in range(mid_lo, mid_hi):
            _cuts(X, Y, a, K, length, ux, uy, i, i - 1, i + 1, bt, ax, ay, add_out, cuts, fig)
        if chi == n and n > 1:
            _cuts(X, Y, a, K, length, ux, uy, n - 1, n - 2, 0, bt, ax, ay, add_out, cuts, fig)
        nf = 0
        for i in range(clo, chi):
            kept = fx[i] or a[i] == 0.0
            if pos + (1 if kept else 2) > cap:
                return OUT, of, u, span, nred, nfig, nunsat, FULL
            if kept:
                _put(OUT, of, pos, X[i], Y[i], fx[i], add_out, ax, ay)
                pos += 1
            else:
                OUT[pos, 0], OUT[pos, 1], of[pos] = cuts[i, 0], cuts[i, 1], False
                OUT[pos + 1, 0], OUT[pos + 1, 1], of[pos + 1] = cuts[i, 2], cuts[i, 3], False
                pos += 2
            if not cl and i == n - 1:
                continue  # no wrap edge on an open curve
            if pos + (2 if fig[i] else 1) > cap:
                return OUT, of, u, span, nred, nfig, nunsat, FULL
            if not fig[i]:
                OUT[pos, 0], OUT[pos, 1], of[pos] = cuts[i, 4], cuts[i, 5], False
                pos += 1
                continue
            # Fig. 11: two congruent triangles on the halves, on opposite sides (a rare
            # edge: its middle piece is computed again here, not kept for every edge)
            nf += 1
            j = i + 1 if i + 1 < n else 0
            ai = a[i]
            A = 0.5 * (K[i] + K[j])
            w = 0.5 * (length[i] - ai - a[j])
            rx = X[i] + ai * ux[i]
            ry = Y[i] + ai * uy[i]
            lx = X[j] - a[j] * ux[i]
            ly = Y[j] - a[j] * uy[i]
            mx = 0.5 * (rx + lx)
            my = 0.5 * (ry + ly)
            k1 = K[i]
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


@njit(cache=True, nogil=True, inline="always", error_model="numpy")
def _edge_terms(i, j, K, length, a, tanb, half_c):
    """What both restriction rules read of edge ``i`` (to vertex ``j``).

    The signed cut areas ``K1, K2`` and their product, ``|K1 + K2|``, the squared half
    middle piece ``w^2`` and the corner rule's bound on it (one computation for the
    first pass's filter and the passes, so that both decide from the same bits).
    """
    K1, K2 = K[i], K[j]
    w = 0.5 * (length[i] - a[i] - a[j])
    net = abs(K1 + K2)
    return K1, K2, K1 * K2, net, w * w, half_c * _nanmax(tanb[i], tanb[j]) * net


@njit(cache=True, nogil=True, inline="always", error_model="numpy")
def _suspect(i, j, K, length, a, tanb, endish, scross, dot, half_c, C):
    """Whether edge ``i`` (to vertex ``j``) might break a rule: :func:`_restrict`'s first pass.

    The corner rule's test as the pass makes it; for the inflection rule, the test of
    the lower bound of ``tan`` with which the pass skips ``atan2`` and ``tan``.
    """
    K1, K2, k12, net, w2, need = _edge_terms(i, j, K, length, a, tanb, half_c)
    corner = (w2 < need * (1.0 - 1e-12)) & ((k12 > 0.0) | endish[i])
    minor2 = abs(K2) <= abs(K1)
    sm = scross[j] if minor2 else scross[i]
    dm = dot[j] if minor2 else dot[i]
    low = 0.5 * C * (sm / (dm + sm) if dm > 0.0 else 1.5707963267948966)
    cleared = net <= 2.0 * w2 * low * (1.0 - 1e-9)
    return corner | ((k12 < 0.0) & (not cleared))


# inlined by numba: a call passes its 25 arrays field by field, once per curve, which
# was about 7 % of a step on a batch of small polygons (one call per ~8 vertices)
@njit(cache=True, nogil=True, inline="always", error_model="numpy")
def _restrict(
    n, cl, anyfix, alpha, alpha0, half, cr, scross, dot, short, length, fx, c, C, max_passes,
    min_factor, a, K, tanb, fv, turning, endish, pending, check, cand, edges, edges2, lo, hi, tq,
):  # fmt: skip
    """Local alpha decrease of one curve; the rules and schedule of ``restrict_passes``.

    The counts cover vertices and edges ``lo .. hi - 1`` (the core of a block).

    On entry ``alpha0 = alpha``, ``a``, ``K``, ``turning`` and ``tanb`` hold the
    profile's values, ``fv`` is all 1 and ``check``, ``pending`` and ``endish`` all False
    (``fv`` and ``check`` are left so; ``pending`` ends as the last check of every edge
    left it), ``tq`` all -1.
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
    half_c = 0.5 * c
    # the first pass checks every edge: a loop of vector instructions marks those that
    # might break a rule (the corner rule's test itself; the inflection rule's with the
    # lower bound of tan below, which clears an edge whatever tq holds), and only they
    # go through the checks; no other edge has a violation (pending stays False). The
    # marks are held in check, all False again before the passes.
    for i in range(min(nlast, n - 1)):
        check[i] = _suspect(i, i + 1, K, length, a, tanb, endish, scross, dot, half_c, C)
    if nlast == n:
        check[n - 1] = _suspect(n - 1, 0, K, length, a, tanb, endish, scross, dot, half_c, C)
    ne = 0
    for i in range(nlast):
        edges[ne] = i
        ne += check[i]
        check[i] = False
    for npass in range(max_passes + 1):
        nc = 0  # candidate vertices with a factor < 1 this pass
        nviol = 0
        for t in range(ne):
            i = edges[t]
            j = i + 1 if i + 1 < n else 0
            K1, K2, k12, net, w2, need = _edge_terms(i, j, K, length, a, tanb, half_c)
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
        nred += alpha[i] < alpha0[i]
        nunsat += pending[i]
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


@njit(cache=True, nogil=True, error_model="numpy")
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


@njit(cache=True, nogil=True, error_model="numpy")
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


@njit(cache=True, nogil=True, error_model="numpy")
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


@njit(cache=True, nogil=True, error_model="numpy")
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


@njit(cache=True, nogil=True, error_model="numpy")
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


@njit(cache=True, nogil=True, error_model="numpy")
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


@njit(cache=True, nogil=True, error_model="numpy")
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


@njit(cache=True, nogil=True, error_model="numpy")
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
