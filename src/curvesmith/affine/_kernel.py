"""The construction of an affine arc length polyline (section 4), compiled with numba.

:func:`construct` is the scalar loop of
:func:`curvesmith.affine.approximation._construct` operation by operation: each new
vertex is the first intersection after ``x_{i-1}`` of the replacement curve ``f~``
with the line ``det(x_{i-1} - x_{i-2}, z - x_{i-1}) = A``, its arc found by a galloping
search started at the guess "same parameter step as the previous edge", then a
quadratic solved on that arc. The arithmetic is the same IEEE double operations in the
same order (numba compiles without ``fastmath``: no reassociation, no fused
multiply-add), so the vertices are the Python loop's to the bit; the tests compare
both on the paper's curves. The searches for ``t_1`` (section 4.3) evaluate the
construction thousands of times per curve, which in Python was most of the time of a
glyph refit.

Compilation happens on the first call (``cache=True``: later processes load the
machine code from numba's cache). The module is imported only when a construction
runs, so ``import curvesmith`` does not load numba.
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True, nogil=True)
def first_root(c0: float, c1: float, c2: float, lo: float, hi: float) -> tuple[bool, float]:
    """Smallest root of ``c0 + c1 u + c2 u^2`` in ``(lo, hi]`` (tolerance 1e-12), clipped.

    Returns ``(found, u)``.
    """
    tol = 1e-12
    r0 = r1 = 0.0
    count = 0
    if abs(c2) <= 1e-14 * (abs(c1) + abs(c0)):
        if c1 != 0.0:
            r0 = -c0 / c1
            count = 1
    else:
        disc = c1 * c1 - 4.0 * c2 * c0
        if disc < 0.0:
            return False, 0.0
        sq = np.sqrt(disc)
        qq = -0.5 * (c1 + (sq if c1 >= 0 else -sq))
        if qq != 0.0:
            r0, r1 = qq / c2, c0 / qq
            count = 2
        else:
            r0 = 0.0
            count = 1
    found = False
    best = 0.0
    for k in range(count):
        r = r0 if k == 0 else r1
        if lo - tol < r <= hi + tol and (not found or r < best):
            best = r
            found = True
    if not found:
        return False, 0.0
    return True, min(max(best, lo), hi)


@njit(cache=True, nogil=True)
def _crossed(j, n, closed, px, py, wx, wy, base, sgn) -> bool:
    k = j % n if closed else j
    return sgn * (wx * py[k] - wy * px[k] - base) >= 0.0


@njit(cache=True, nogil=True)
def _first_crossing(lo, hi, n, closed, px, py, wx, wy, base, sgn) -> int:
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if _crossed(mid, n, closed, px, py, wx, wy, base, sgn):
            hi = mid
        else:
            lo = mid
    return hi


@njit(cache=True, nogil=True)
def construct(
    px, py, ax, ay, ex, ey, closed, x0, y0, x1, y1, t0, t1, area, m, jlast, u_max, extrapolate
):
    """Vertices of the affine arc length polyline; see the module docstring.

    Returns ``(xs, ys, ts, count, done)``: the first `count` entries of the arrays are
    the vertices and their parameters, `done` the edges constructed.
    """
    n = len(ax)
    sgn = 1.0 if area > 0 else -1.0
    size = max(m + 1, 2)
    xs = np.empty(size)
    ys = np.empty(size)
    ts = np.empty(size)
    xs[0], ys[0], ts[0] = x0, y0, t0
    xs[1], ys[1], ts[1] = x1, y1, t1
    count = 2
    tprev = t1
    for _ in range(m - 1):
        wx, wy = xs[count - 1] - xs[count - 2], ys[count - 1] - ys[count - 2]
        base = wx * ys[count - 1] - wy * xs[count - 1] + area
        j0 = int(np.floor(tprev))
        jmax = j0 + n if closed else jlast + 1
        seg = -1
        extrap = False
        if not closed and j0 > jlast:
            seg, extrap = jlast, True
        else:
            start = j0
            jg = min(max(int(np.floor(2.0 * tprev - ts[count - 2])), j0 + 1), jmax)
            kg = jg % n if closed else jg
            if closed or jg < n:
                tx, ty = ax[kg], ay[kg]
            else:
                tx, ty = ax[n - 1] + 2.0 * ex[n - 1], ay[n - 1] + 2.0 * ey[n - 1]
            if sgn * (wx * ty - wy * tx) > 0.0:
                if sgn * (wx * py[kg] - wy * px[kg] - base) >= 0.0:
                    hi, off = jg, 1
                    while True:
                        lo = hi - off
                        if lo <= j0:
                            lo = j0
                            break
                        if not _crossed(lo, n, closed, px, py, wx, wy, base, sgn):
                            break
                        hi, off = lo, 2 * off
                    seg = _first_crossing(lo, hi, n, closed, px, py, wx, wy, base, sgn) - 1
                else:
                    start = jg
            if seg < 0:
                last_ok, off = start, 1
                while True:
                    jp = min(start + off, jmax)
                    kk = jp % n if closed else jp
                    if sgn * (wx * py[kk] - wy * px[kk] - base) >= 0.0:
                        seg = _first_crossing(last_ok, jp, n, closed, px, py, wx, wy, base, sgn) - 1
                        break
                    if closed or jp < n:
                        tx, ty = ax[kk], ay[kk]
                    else:
                        tx, ty = ax[n - 1] + 2.0 * ex[n - 1], ay[n - 1] + 2.0 * ey[n - 1]
                    if sgn * (wx * ty - wy * tx) <= 0.0:
                        for jj in range(last_ok, jp):
                            kj = jj % n if closed else jj
                            u_lo = tprev - jj if jj == j0 else 0.0
                            c0 = wx * py[kj] - wy * px[kj] - base
                            c1 = wx * ay[kj] - wy * ax[kj]
                            c2 = wx * ey[kj] - wy * ex[kj]
                            if first_root(c0, c1, c2, u_lo, 1.0)[0]:
                                seg = jj
                                break
                        break
                    last_ok = jp
                    if jp >= jmax:
                        if not closed:
                            seg, extrap = jlast, True
                        break
                    off *= 2
        if seg < 0:
            return xs, ys, ts, count, count - 1
        kj = seg % n if closed else seg
        u_lo = tprev - seg if seg == j0 or extrap else 0.0
        if u_lo < 0.0:
            u_lo = 0.0
        c0 = wx * py[kj] - wy * px[kj] - base
        c1 = wx * ay[kj] - wy * ax[kj]
        c2 = wx * ey[kj] - wy * ex[kj]
        if extrap and extrapolate:
            u_hi = max(u_max, u_lo + 2.0 * (ts[count - 1] - ts[count - 2]))
        else:
            u_hi = 1.0
        found, u = first_root(c0, c1, c2, u_lo, u_hi)
        if not found:
            return xs, ys, ts, count, count - 1
        xs[count] = px[kj] + u * (ax[kj] + u * ex[kj])
        ys[count] = py[kj] + u * (ay[kj] + u * ey[kj])
        tprev = seg + u
        ts[count] = tprev
        count += 1
    return xs, ys, ts, count, m
