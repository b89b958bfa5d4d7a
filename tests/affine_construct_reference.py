"""The affine arc length construction as plain Python (the reference of the compiled one).

This is the loop that :func:`curvesmith.affine._kernel.construct` compiles, kept as it was
written before compilation, so that the tests can compare the two bit for bit.
"""

from __future__ import annotations

import math


def _first_crossing(lo: int, hi: int, crossed) -> int:
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if crossed(mid):
            hi = mid
        else:
            lo = mid
    return hi


def construct(
    cv,
    t0: float,
    t1: float,
    area: float,
    m: int,
    t_end: float,
    u_max: float = 4.0,
    extrapolate: bool = True,
):
    """Vertices x_0 .. x_m of the affine arc length polyline from x_0 = f~(t0), x_1 = f~(t1).

    Each new vertex is the first intersection after ``x_{i-1}`` of ``f~`` with the
    line ``det(x_{i-1} - x_{i-2}, z - x_{i-1}) = A``. The arc holding it is found by
    a galloping search over the samples, started at the guess "same parameter
    step as the previous edge" (``g(z) = det(w, z - x_{i-1})`` increases while the
    tangent has not turned past ``w``, which is checked at the guess and at every
    forward probe), then a quadratic equation is solved on that arc. The cost per vertex
    is logarithmic in the samples per edge, so a construction is O(n log(N/n)).
    For an open curve the last arc before ``t_end`` is extrapolated up to
    ``u_max`` or two previous edges (in parameter) beyond the last vertex.
    With ``extrapolate=False`` (pieces ending at an inflection) the last vertex must
    lie on the curve, ``t <= t_end``: the next piece starts at ``f~(t)`` on the next
    arc, which is another point than one on the extrapolated arc.
    Returns ``(xs, ys, ts, done)``, ``done`` = edges constructed.
    """
    px, py, ax, ay, ex, ey = cv.px, cv.py, cv.ax, cv.ay, cv.ex, cv.ey
    n = cv.n
    closed = cv.closed
    sgn = 1.0 if area > 0 else -1.0
    x0, y0 = cv.point(t0)
    x1, y1 = cv.point(t1)
    xs, ys, ts = [x0, x1], [y0, y1], [t0, t1]
    jlast = n - 1 if closed else min(n - 1, math.ceil(t_end) - 1)
    tprev = t1
    for _ in range(m - 1):
        wx, wy = xs[-1] - xs[-2], ys[-1] - ys[-2]
        base = wx * ys[-1] - wy * xs[-1] + area  # g(z) - A = wx*zy - wy*zx - base

        def crossed(j, wx=wx, wy=wy, base=base):  # g(x_j) - A has the sign of A
            k = j % n if closed else j
            return sgn * (wx * py[k] - wy * px[k] - base) >= 0.0

        j0 = math.floor(tprev)
        jmax = j0 + n if closed else jlast + 1
        seg = -1
        extrap = False
        if not closed and j0 > jlast:
            seg, extrap = jlast, True
        else:
            # start at the guess "same parameter step as the last edge"
            start = j0
            jg = min(max(math.floor(2.0 * tprev - ts[-2]), j0 + 1), jmax)
            kg = jg % n if closed else jg
            if closed or jg < n:
                tx, ty = ax[kg], ay[kg]
            else:
                tx, ty = ax[n - 1] + 2.0 * ex[n - 1], ay[n - 1] + 2.0 * ey[n - 1]
            if sgn * (wx * ty - wy * tx) > 0.0:  # g still increasing at the guess
                if sgn * (wx * py[kg] - wy * px[kg] - base) >= 0.0:
                    # crossing in (tprev, jg]: gallop backwards, then bisect
                    hi, off = jg, 1
                    while True:
                        lo = hi - off
                        if lo <= j0:
                            lo = j0
                            break
                        if not crossed(lo):
                            break
                        hi, off = lo, 2 * off
                    seg = _first_crossing(lo, hi, crossed) - 1
                else:
                    start = jg
            if seg < 0:
                last_ok, off = start, 1
                while True:
                    jp = min(start + off, jmax)
                    kk = jp % n if closed else jp
                    if sgn * (wx * py[kk] - wy * px[kk] - base) >= 0.0:
                        seg = _first_crossing(last_ok, jp, crossed) - 1
                        break
                    if closed or jp < n:
                        tx, ty = ax[kk], ay[kk]
                    else:
                        tx, ty = ax[n - 1] + 2.0 * ex[n - 1], ay[n - 1] + 2.0 * ey[n - 1]
                    if sgn * (wx * ty - wy * tx) <= 0.0:
                        # past the maximum of g: scan the last bracket arc by arc
                        for jj in range(last_ok, jp):
                            kj = jj % n if closed else jj
                            u_lo = tprev - jj if jj == j0 else 0.0
                            c0 = wx * py[kj] - wy * px[kj] - base
                            c1 = wx * ay[kj] - wy * ax[kj]
                            c2 = wx * ey[kj] - wy * ex[kj]
                            if _first_root(c0, c1, c2, u_lo, 1.0) is not None:
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
            return xs, ys, ts, len(xs) - 1
        kj = seg % n if closed else seg
        u_lo = tprev - seg if seg == j0 or extrap else 0.0
        if u_lo < 0.0:
            u_lo = 0.0
        c0 = wx * py[kj] - wy * px[kj] - base
        c1 = wx * ay[kj] - wy * ax[kj]
        c2 = wx * ey[kj] - wy * ex[kj]
        u_hi = max(u_max, u_lo + 2.0 * (ts[-1] - ts[-2])) if extrap and extrapolate else 1.0
        u = _first_root(c0, c1, c2, u_lo, u_hi)
        if u is None:
            return xs, ys, ts, len(xs) - 1
        xs.append(px[kj] + u * (ax[kj] + u * ex[kj]))
        ys.append(py[kj] + u * (ay[kj] + u * ey[kj]))
        tprev = seg + u
        ts.append(tprev)
    return xs, ys, ts, m


def _first_root(c0: float, c1: float, c2: float, lo: float, hi: float) -> float | None:
    """Smallest root of ``c0 + c1 u + c2 u^2`` in ``(lo, hi]`` (tolerance 1e-12), clipped to it."""
    tol = 1e-12
    if abs(c2) <= 1e-14 * (abs(c1) + abs(c0)):
        roots = [-c0 / c1] if c1 != 0.0 else []
    else:
        disc = c1 * c1 - 4.0 * c2 * c0
        if disc < 0.0:
            return None
        sq = math.sqrt(disc)
        qq = -0.5 * (c1 + (sq if c1 >= 0 else -sq))
        roots = [qq / c2, c0 / qq] if qq != 0.0 else [0.0]
    inside = [r for r in roots if lo - tol < r <= hi + tol]
    if not inside:
        return None
    return min(max(min(inside), lo), hi)
