"""Benchmark of ``curvesmith.elastica.fit_segments`` (multi-segment fairing to a tolerance).

Curves (seeded; mm): exact discrete elasticae joined G1 (two and three pieces, 0.02 mm
noise, T = 0.09 mm: above the clean curve's own max deviation from the noisy points, which
is 0.082 mm at N = 1600 = 4.1 noise; a T below it makes every method chase the noise), an
Archimedean spiral (no elastica fits it), and a 1.5 m car-body-like section with
an S-bend and a tight bend, scanned at uneven 0.01-11 mm steps with 0.05 mm noise (from
``tests/test_elastica_segments.py``). Sizes: the G1 pieces and the spiral at N = 400, 800,
1600 points. For each: the number of segments, the max deviation (every input point to the
chained polyline), wall and CPU time (``time.process_time``; the machine may be shared).

Peer, in the same process: scipy's smoothing spline ``splprep`` (cubic, parametrised by
chord length) at the same tolerance: the largest smoothing factor ``s`` whose spline (sampled
at 20 points per knot span) keeps every input point within ``T``, found by bisection on
``log s`` (30 fits); printed: its knots (interior knots + 1 = polynomial pieces), its max
deviation, the time of that search and of one ``splprep`` call at the final ``s``. A spline
is C2 but not a discrete elastica; the comparison says what the fewest pieces and the time
cost against the obvious library way of meeting a tolerance.

Run ``python benchmarks/bench_elastica_segments.py`` (``--quick``: N = 800 only).
"""

from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import argparse
import math
import sys
import time
from pathlib import Path

import numpy as np
from scipy.interpolate import splev, splprep

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

from curvesmith.elastica import fit_segments
from curvesmith.elastica._geom import point_polyline_distance
from test_elastica_segments import g1_chain, section

TWO = [(2.0, 0.01, 0.3, 0.7, 400), (2.0, 0.006, -0.5, 2.5, 401)]
THREE = [(2.0, 0.012, 0.3, 0.7, 300), (2.0, 0.006, -0.5, 2.5, 251), (2.0, 0.01, 1.0, 0.5, 251)]


def scaled(pieces, n):
    """The same curve with about `n` vertices: h and z scaled by 800 / n."""
    f = 800.0 / n
    out = []
    for h, z, q, k, m in pieces:
        out.append((h * f, z * f, q, k, max(9, round((m - 1) / f) + 1)))
    return out


def curves(sizes):
    rng = np.random.default_rng(0)
    for n in sizes:
        for name, pieces in (("2 G1 pieces", TWO), ("3 G1 pieces", THREE)):
            clean, _ = g1_chain(scaled(pieces, n))
            noisy = clean + rng.normal(scale=0.02, size=clean.shape)
            yield name, noisy, 0.09, point_polyline_distance(noisy, clean).max()
        t = np.linspace(0.0, 4 * np.pi, n)
        r = 50 + 20 * t
        yield "spiral", np.column_stack([r * np.cos(t), r * np.sin(t)]), 0.1, math.nan
    pts, dense = section(seed=1)
    own = point_polyline_distance(pts, dense).max()
    yield "section 1.5 m, uneven", pts, 0.25, own
    yield "section, reversed", pts[::-1].copy(), 0.25, own


def spline_at_tolerance(pts, tol, tries=30):
    """Largest splprep smoothing factor meeting `tol`: (knots, max deviation, s)."""
    d = np.hypot(*np.diff(pts, axis=0).T)
    u = np.concatenate([[0.0], np.cumsum(d)])
    u /= u[-1]

    def run(s):
        tck, _ = splprep(pts.T, u=u, s=s, k=3)
        knots = np.unique(tck[0])
        fine = np.linspace(0, 1, 20 * len(knots) + len(pts))
        curve = np.column_stack(splev(fine, tck))
        if not np.all(np.isfinite(curve)):
            return tck, math.inf, len(knots) - 1
        return tck, float(point_polyline_distance(pts, curve).max()), len(knots) - 1

    # s is the sum of squared residuals: from (T/100)^2 to 10 T^2 per point
    lo, hi = math.log10(len(pts) * (tol / 100) ** 2), math.log10(len(pts) * tol * tol * 10)
    best = None
    for _ in range(tries):
        mid = 0.5 * (lo + hi)
        _tck, dev, pieces = run(10.0**mid)
        if dev <= tol:
            best = (pieces, dev, 10.0**mid)
            lo = mid
        else:
            hi = mid
    if best is None:
        _tck, dev, pieces = run(10.0**lo)
        best = (pieces, dev, 10.0**lo)
    return best


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true")
    args = ap.parse_args()
    sizes = (800,) if args.quick else (400, 800, 1600)
    print(
        "| curve | N | T | clean curve's max dev | segments | max dev | wall s | CPU s "
        "| splprep pieces | max dev | search s | one call s | time ratio (ours / search) |"
    )
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for name, pts, tol, own in curves(sizes):
        t0, c0 = time.perf_counter(), time.process_time()
        res = fit_segments(pts, tol)
        wall, cpu = time.perf_counter() - t0, time.process_time() - c0
        t0 = time.perf_counter()
        pieces, sdev, s = spline_at_tolerance(pts, tol)
        search = time.perf_counter() - t0
        d = np.hypot(*np.diff(pts, axis=0).T)
        u = np.concatenate([[0.0], np.cumsum(d)]) / d.sum()
        t0 = time.perf_counter()
        splprep(pts.T, u=u, s=s, k=3)
        one = time.perf_counter() - t0
        print(
            f"| {name} | {len(pts)} | {tol:g} | {own:.4f} | {len(res.segments)}"
            f"{'' if res.within_tolerance else ' (missed)'} | {res.max_deviation:.4f} | "
            f"{wall:.2f} | {cpu:.2f} | {pieces} | {sdev:.4f} | {search:.3f} | {one:.4f} | "
            f"{wall / search:.0f} |",
            flush=True,
        )
    print(f"\nload average {os.getloadavg()[0]:.1f} (2 cores shared)")


if __name__ == "__main__":
    main()
