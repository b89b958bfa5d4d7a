"""Shared test oracles: plain reference computations the tests compare curvesmith against.

Written from the definitions, independently of the library (no curvesmith import), and
slow where exactness needs it:

- :func:`exact_area`: the signed shoelace area of a ring, correctly rounded (Dekker's
  exact products summed by ``math.fsum``);
- :func:`exact_area_fraction`: the same in exact rational arithmetic, for differences of
  areas that must be exact (an input ring against its smoothed output);
- :func:`roundoff_bound`: what float coordinates can account for in such a difference;
- :func:`det`: the 2 x 2 determinant of row vectors.
"""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np


def _two_product(a, b):
    """Dekker's exact product: ``a*b == p + e`` exactly (no overflow at the scales used)."""
    p = a * b
    split = 134217729.0  # 2**27 + 1
    ca = split * a
    ah = ca - (ca - a)
    al = a - ah
    cb = split * b
    bh = cb - (cb - b)
    bl = b - bh
    e = ((ah * bh - p) + ah * bl + al * bh) + al * bl
    return p, e


def exact_area(points) -> float:
    """Signed shoelace area of a closed ring (no repeated last vertex), correctly rounded."""
    p = np.asarray(points, dtype=float)
    x, y = p[:, 0], p[:, 1]
    xn, yn = np.roll(x, -1), np.roll(y, -1)
    p1, e1 = _two_product(x, yn)
    p2, e2 = _two_product(xn, y)
    return 0.5 * math.fsum(np.concatenate([p1, e1, -p2, -e2]))


def exact_area_fraction(points) -> Fraction:
    """Signed shoelace area of a closed ring (no repeated last vertex), exactly."""
    pts = [(Fraction(float(a)), Fraction(float(b))) for a, b in np.asarray(points)[:, :2]]
    s = Fraction(0)
    for (x0, y0), (x1, y1) in zip(pts, pts[1:] + pts[:1], strict=True):
        s += x0 * y1 - x1 * y0
    return s / 2


def roundoff_bound(points, length: float) -> float:
    """Area error float coordinates can explain: 64 eps * coordinate magnitude * length."""
    return 64 * np.finfo(float).eps * float(np.abs(np.asarray(points)).max()) * length


def det(u, v):
    """``u[..., 0] v[..., 1] - u[..., 1] v[..., 0]``, the 2 x 2 determinant of rows u, v."""
    u, v = np.asarray(u, dtype=float), np.asarray(v, dtype=float)
    return u[..., 0] * v[..., 1] - u[..., 1] * v[..., 0]


def exact_area_sign(p) -> int:
    """Sign of the shoelace sum in exact rational arithmetic."""
    from fractions import Fraction

    xs = [Fraction(v) for v in np.asarray(p)[:, 0].tolist()]
    ys = [Fraction(v) for v in np.asarray(p)[:, 1].tolist()]
    total = sum(xs[i - 1] * ys[i] - xs[i] * ys[i - 1] for i in range(len(xs)))
    return (total > 0) - (total < 0)
