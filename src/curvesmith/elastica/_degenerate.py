"""Degenerate discrete elasticae: the straight line and the circle, fitted in closed form.

Both are limits of the family of eq. (4.3) that a least-squares solver started from the
guess of section 4.3 cannot reach (the guess needs varying curvature, eq. (4.34) has
``mu = 0`` on a circle), so :func:`curvesmith.elastica.fit` adds them as candidates:

* **Line**: ``z = 0`` makes the half angle ``a_n = a(q)`` constant, so with ``q = 0`` every
  tangent is ``exp(i phi)`` and ``gamma_n = gamma_0 + n h exp(i phi)``: exactly a discrete
  elastica (any ``k``; we report ``k = 0.5``). The best one is the complex linear
  regression of the data on ``n``.
* **Circle**: as ``k -> infinity`` (case (i), modulus ``1/k -> 0``), ``sn(k s; 1/k) ->
  sin(k s)``, so ``a(s) = k s`` and the tangent turns by ``2 k z`` per vertex: a regular
  polygon. We fit the polygon ``c + R exp(i (t0 + n d))`` (centre, radius, phase, step) by
  Levenberg-Marquardt from an algebraic circle fit, and map it to ``k = CIRCLE_K``,
  ``z = d / (2k)``, ``q = 0``, ``phi = angle(T_0) - d / 2``. At ``k = 1e8`` the sampled
  vertices differ from the regular polygon by ``~ n d / k^2``, below rounding.
"""

from __future__ import annotations

import math

import numpy as np

from .exact import ElasticaParams

__all__: list[str] = []

#: The modulus that stands for ``k = infinity`` (the circle).
CIRCLE_K = 1e8
#: The modulus reported for a straight line (any value draws the same line when z = 0).
LINE_K = 0.5


def line_fit(data: np.ndarray) -> ElasticaParams:
    """Best ``gamma_n = gamma_0 + n w`` (complex ``w = h e^{i phi}``) by linear least squares."""
    n = data.shape[0]
    t = np.arange(n, dtype=float)
    zc = data[:, 0] + 1j * data[:, 1]
    tm = t.mean()
    w = complex(((t - tm) @ (zc - zc.mean())) / ((t - tm) @ (t - tm)))
    g0 = zc.mean() - w * tm
    return ElasticaParams(
        float(g0.real), float(g0.imag), abs(w), math.atan2(w.imag, w.real), 0.0, 0.0, LINE_K
    )


def circle_fit(data: np.ndarray) -> ElasticaParams | None:
    """Best regular polygon through the data in the vertex pairing, or None if no circle fits."""
    from scipy.optimize import leastsq

    x, y = data[:, 0], data[:, 1]
    centre = data.mean(axis=0)
    u, v = x - centre[0], y - centre[1]
    # Kasa: u^2 + v^2 = 2 a u + 2 b v + c, linear in (a, b, c)
    design = np.column_stack((2 * u, 2 * v, np.ones_like(u)))
    sol, *_ = np.linalg.lstsq(design, u * u + v * v, rcond=None)
    a, b, c = sol
    r2 = c + a * a + b * b
    if not (np.isfinite(r2) and r2 > 0):
        return None
    cx, cy = centre[0] + a, centre[1] + b
    ang = np.unwrap(np.arctan2(y - cy, x - cx))
    n = data.shape[0]
    t = np.arange(n, dtype=float)
    d0, t0 = np.polyfit(t, ang, 1)
    x0 = np.array([cx, cy, math.sqrt(r2), t0, d0])

    def resid(p):
        phase = p[3] + p[4] * t
        return np.concatenate([p[0] + p[2] * np.cos(phase) - x, p[1] + p[2] * np.sin(phase) - y])

    with np.errstate(all="ignore"):
        sol, _, _, _, ier = leastsq(resid, x0, full_output=True, xtol=1e-14, ftol=1e-14)
    if ier not in (1, 2, 3, 4) or not np.all(np.isfinite(sol)):
        return None
    cx, cy, rad, t0, d = (float(v) for v in sol)
    if rad <= 0 or d == 0.0 or abs(d) >= math.pi:
        return None
    g0 = np.array([cx + rad * math.cos(t0), cy + rad * math.sin(t0)])
    g1 = np.array([cx + rad * math.cos(t0 + d), cy + rad * math.sin(t0 + d)])
    edge = g1 - g0
    h = float(np.hypot(*edge))
    phi = math.atan2(edge[1], edge[0]) - d / 2.0
    return ElasticaParams(float(g0[0]), float(g0[1]), h, phi, d / (2.0 * CIRCLE_K), 0.0, CIRCLE_K)


def degenerate_case(p: ElasticaParams) -> str | None:
    """``"line"`` or ``"circle"`` for the degenerate parameters above, else None."""
    if p.z == 0.0:
        return "line"
    if p.k >= CIRCLE_K:
        return "circle"
    return None
