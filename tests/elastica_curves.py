"""Realistic test curves for the elastica fit, and an exhaustive multi-start reference fit.

Shared by the tests (``tests/test_elastica_realistic.py``) and the benchmark
(``benchmarks/bench_elastica_global.py``, which puts this directory on ``sys.path``).

The curves imitate planar section scans of car bodies: C-shaped, about 1.5 m long with a
sagitta of 50-120 mm, in mm; samples at uneven arc-length steps (log-uniform between
0.001 and 11 mm), Gaussian noise up to 0.3 mm (a scanner's accuracy), optionally reversed
and with a 5-point glitch 1.5 mm off the curve. Shapes: a clothoid (Fresnel integrals,
curvature linear in arc length), a log-aesthetic curve (``rho^alpha`` linear in arc
length), a cubic Bezier curve, a cubic spline through five points, and an exact discrete
elastica with a smooth model error added.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.interpolate import CubicSpline
from scipy.special import fresnel

from curvesmith.elastica import sample

LENGTH = 1500.0  # mm

SHAPES = ("clothoid", "log_aesthetic", "bezier", "spline", "elastica_error")


def _arc_param(xy: np.ndarray) -> np.ndarray:
    return np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(xy, axis=0).T))])


def _dense(shape: str) -> np.ndarray:
    """A dense (20001-point) polyline of the shape, scaled to LENGTH along its arc."""
    t = np.linspace(0.0, 1.0, 20001)
    if shape == "clothoid":
        s = 0.35 + 1.1 * t
        S, C = fresnel(s)
        xy = np.column_stack([C, S])
    elif shape == "log_aesthetic":
        # rho(s)^alpha = c0 + c1 s with alpha = 2: radius grows like sqrt(s); theta = int 1/rho
        s = t
        rho = np.sqrt(0.25 + 2.0 * s)
        theta = np.concatenate([[0.0], np.cumsum(0.5 * (1 / rho[1:] + 1 / rho[:-1]) * np.diff(s))])
        e = np.column_stack([np.cos(theta), np.sin(theta)])
        xy = np.vstack([[0.0, 0.0], np.cumsum(0.5 * (e[1:] + e[:-1]) * np.diff(s)[:, None], 0)])
    elif shape == "bezier":
        c = np.array([[0.0, 0.0], [0.3, 0.16], [0.75, 0.14], [1.0, 0.02]])
        b = np.column_stack([(1 - t) ** 3, 3 * t * (1 - t) ** 2, 3 * t**2 * (1 - t), t**3])
        xy = b @ c
    elif shape == "spline":
        knots = np.array([[0.0, 0.0], [0.25, 0.07], [0.5, 0.095], [0.75, 0.08], [1.0, 0.0]])
        cs = CubicSpline(np.linspace(0, 1, 5), knots, bc_type="natural")
        xy = cs(t)
    elif shape == "elastica_error":
        xy = sample((0.0, 0.0, 1.0, 0.05, 0.0012, 0.25, 3.0), 1501)
        tt = np.linspace(0.0, 1.0, xy.shape[0])
        s_ = _arc_param(xy)
        e = np.diff(xy, axis=0)
        nrm = np.column_stack([-e[:, 1], e[:, 0]]) / np.hypot(*e.T)[:, None]
        nrm = np.vstack([nrm, nrm[-1:]])
        xy = xy + nrm * (0.4 * np.sin(3 * math.pi * tt))[:, None]  # 0.4 mm model error
        dense = np.linspace(0, s_[-1], 20001)
        xy = np.column_stack([np.interp(dense, s_, xy[:, 0]), np.interp(dense, s_, xy[:, 1])])
    else:
        raise ValueError(shape)
    s = _arc_param(xy)
    return xy * (LENGTH / s[-1])


def scan(
    shape: str,
    *,
    noise: float = 0.0,
    reverse: bool = False,
    glitch: bool = False,
    uneven: bool = True,
    seed: int = 0,
) -> np.ndarray:
    """A simulated section scan (M, 2) in mm of one of :data:`SHAPES`."""
    rng = np.random.default_rng(seed)
    dense = _dense(shape)
    s = _arc_param(dense)
    if uneven:
        steps = np.exp(rng.uniform(math.log(0.001), math.log(11.0), size=4000))
        pos = np.concatenate([[0.0], np.cumsum(steps)])
        pos = pos[pos < s[-1]]
        pos = np.append(pos, s[-1])
    else:
        pos = np.linspace(0.0, s[-1], 751)
    pts = np.column_stack([np.interp(pos, s, dense[:, 0]), np.interp(pos, s, dense[:, 1])])
    if noise > 0:
        pts = pts + rng.normal(scale=noise, size=pts.shape)
    if glitch:
        j = pts.shape[0] // 3
        e = pts[j + 5] - pts[j - 1]
        nrm = np.array([-e[1], e[0]]) / np.hypot(*e)
        pts[j : j + 5] += 1.5 * nrm
    return pts[::-1].copy() if reverse else pts


def reference_fit(data: np.ndarray, *, thorough: bool = True):
    """Exhaustive multi-start fit of equally spaced `data`: ``(rms, params)``.

    Starts: the guess variants and a grid of moduli (k from 0.1 to 100, z rescaled to keep
    ``k z``, both signs of z) on three subsampling levels; every start is solved, the 12
    best are refined on all points. Plain and slow, on purpose (minutes on 1000 points).
    ``thorough=False`` (the slow tests): one level, 7 moduli, the 4 best refined.
    """
    import importlib

    fm = importlib.import_module("curvesmith.elastica.fit")
    n = data.shape[0]
    results = []
    ms = {max(1, n // 30), max(1, n // 60), max(1, n // 120)} if thorough else {max(1, n // 60)}
    grid = (0.1, 0.3, 0.6, 0.9, 0.99, 1.01, 1.2, 2.0, 5.0, 20.0, 100.0)
    if not thorough:
        grid = (0.3, 0.9, 1.01, 1.2, 2.0, 5.0, 30.0)
    for m in sorted(ms):
        d = data[::m]
        starts = []
        for g in fm._starts(d):
            starts.append(g)
            for k in grid:
                for sign in (1.0, -1.0):
                    starts.append(g._replace(k=k, z=sign * g.z * g.k / k))
        for st in starts:
            params, *_ = fm._solve(d, st, {}, "lsq", 400, 1e-12)
            with np.errstate(all="ignore"):
                r = fm._rms(d, params)
            if math.isfinite(r):
                results.append((r, m, params))
    results.sort(key=lambda t: t[0])
    best = []
    for _r, m, params in results[: 12 if thorough else 4]:
        start = fm._scaled(params, m)
        p2, *_ = fm._solve(data, start, {}, "lsq", 20000 if thorough else 3000, 1e-12)
        with np.errstate(all="ignore"):
            r2 = fm._rms(data, p2)
        if math.isfinite(r2):
            best.append((r2, p2))
    for make in (fm._degenerate.line_fit, fm._degenerate.circle_fit):
        p = make(data)
        if p is not None:
            best.append((fm._rms(data, p), p))
    return min(best, key=lambda t: t[0])
