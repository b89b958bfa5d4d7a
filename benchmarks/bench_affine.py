"""Benchmark of curvesmith.affine.approximate (Käferböck, section 4).

Times the approximation of the degree-8 Bézier test curve (``affine_bezier8.csv``,
the stand-in for Example 1 / Table 1) by affine arc length polylines with
``n + 1`` vertices from ``N`` samples, for ``n`` in {20, 60, 200} and ``N`` in
{200, 1000, 10000}, and reports how the time scales with ``N``.

Peer, in the same run: a least-squares quadratic B-spline with the same number of
control points (``scipy.interpolate.make_lsq_spline`` on the chord-length
parameter, uniform knots) — the usual way to get a quadratic spline with a given
number of control points from samples. Reported for both: time, the curvature
continuity defect ``max |kappa_left - kappa_right| / max |kappa|`` over the
interior knots (0 up to rounding for ours: section 2.5) and the maximum
distance from the spline to the exact curve (relative to the curve's bounding
box diagonal). Ours is not a best fit: the control points lie on the curve, so
the spline runs inside it at a distance of about ``kappa h^2 / 8``.

Run ``python benchmarks/bench_affine.py`` (``--quick`` for a short run).
"""

from __future__ import annotations

import argparse

import numpy as np
from scipy.interpolate import BSpline, make_lsq_spline
from scipy.spatial import cKDTree

from _timing import median_time
from curvesmith import affine
from curvesmith.data import load_points

CONTROL = load_points("affine_bezier8.csv")


def spline_curvature_jump(spline: BSpline, knots: np.ndarray, eps: float) -> float:
    d1, d2 = spline.derivative(1), spline.derivative(2)

    def kappa(t):
        a, b = d1(t), d2(t)
        return (a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]) / np.linalg.norm(a, axis=1) ** 3

    lo, hi = spline.t[spline.k], spline.t[-spline.k - 1]
    grid = np.linspace(lo, hi, 4000)
    scale = np.max(np.abs(kappa(grid)))
    return float(np.max(np.abs(kappa(knots - eps) - kappa(knots + eps))) / scale)


REFERENCE = affine.bezier_curve(CONTROL, np.linspace(0, 1, 400_001))
REFERENCE_TREE = cKDTree(REFERENCE)
DIAG = float(np.hypot(*np.ptp(REFERENCE, axis=0)))


def distance_to_curve(spline_pts: np.ndarray) -> float:
    """Max distance from the spline to the exact curve, relative to the bounding box diagonal."""
    d, _ = REFERENCE_TREE.query(spline_pts)
    return float(d.max() / DIAG)


def ours(samples, n):
    return affine.approximate(samples, vertices=n + 1)


def ours_metrics(res):
    s = affine.bspline(res.points)
    left, right = affine.joint_curvatures(res.points)
    _, k = affine.spline_curvature(res.points, per_segment=32)
    jump = float(np.max(np.abs(left - right)) / np.max(np.abs(k)))
    dense = s(np.linspace(s.t[2], s.t[-3] - 1e-12, 20000))
    return jump, distance_to_curve(dense)


def peer(samples, n):
    """Least-squares quadratic B-spline with n + 1 control points, uniform knots in chord length."""
    u = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(samples, axis=0), axis=1))])
    u /= u[-1]
    k = 2
    inner = np.linspace(0, 1, n + 1 - k + 1)[1:-1]
    t = np.r_[[0.0] * (k + 1), inner, [1.0] * (k + 1)]
    return make_lsq_spline(u, samples, t, k=k), inner


def peer_metrics(fit):
    spline, inner = fit
    jump = spline_curvature_jump(spline, inner, 1e-9)
    dense = spline(np.linspace(0, 1, 20000))
    return jump, distance_to_curve(dense)


def kappa_accuracy(res, count):
    t = res.t
    mid = (t[:-3] + t[1:-2] + t[2:-1] + t[3:]) / 4 / (count - 1)
    exact = affine.bezier_affine_curvature(CONTROL, mid)
    dev = np.abs(res.kappa_m - exact) / np.abs(exact)
    return float(dev.max()), float(dev.mean())


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer repeats")
    args = parser.parse_args()
    repeats = 3 if args.quick else 7
    rng = np.random.default_rng(1234)
    header = (
        f"{'n':>4} {'N':>6} {'ours ms':>9} {'peer ms':>9} {'ratio':>7} {'evals':>6} "
        f"{'ours G2 jump':>13} {'peer G2 jump':>13} {'ours dist':>10} {'peer dist':>10}"
    )
    print("affine.approximate vs least-squares quadratic B-spline (make_lsq_spline)")
    print(f"median of {repeats} runs; n + 1 vertices / control points, N samples")
    print(header)
    times = {}
    for n in (20, 60, 200):
        for count in (200, 1000, 10000):
            if count < 2 * (n + 1):
                print(f"{n:>4} {count:>6}   (skipped: approximate needs >= 2 samples per vertex)")
                continue
            # uniform parameter steps as in the paper's Example 1, plus a seeded jitter of
            # 1e-3 of a step (the method assumes near-uniform sampling, see end_gap)
            u = np.linspace(0, 1, count)
            u[1:-1] += rng.uniform(-1e-3, 1e-3, count - 2) / (count - 1)
            samples = affine.bezier_curve(CONTROL, u)
            t_ours, res = median_time(lambda s=samples, n=n: ours(s, n), repeats)
            t_peer, fit = median_time(lambda s=samples, n=n: peer(s, n), repeats)
            jo, do = ours_metrics(res)
            jp, dp = peer_metrics(fit)
            times[n, count] = t_ours
            print(
                f"{n:>4} {count:>6} {t_ours * 1e3:>9.2f} {t_peer * 1e3:>9.2f} "
                f"{t_ours / t_peer:>7.1f} {res.evaluations:>6} {jo:>13.2e} {jp:>13.2e} "
                f"{do:>10.2e} {dp:>10.2e}"
            )
    print()
    print("scaling of our time with N (time(N) / time(N / 10)):")
    for n in (20, 60, 200):
        if (n, 1000) in times and (n, 10000) in times:
            print(f"  n = {n:>3}: 1000 -> 10000 samples: x{times[n, 10000] / times[n, 1000]:.2f}")
    print()
    count = 1000
    samples = affine.bezier_curve(CONTROL, np.linspace(0, 1, count))
    t60, res = median_time(lambda: affine.approximate(samples, vertices=60), repeats)
    mx, mean = kappa_accuracy(res, count)
    print(
        f"target: 60 vertices from 1000 uniform samples: median {t60 * 1e3:.1f} ms "
        "(target < 50 ms); "
        f"kappa_m deviation max {mx * 100:.3f} % mean {mean * 100:.3f} % (Table 1: 0.9 %, 0.25 %)"
    )


if __name__ == "__main__":
    main()
