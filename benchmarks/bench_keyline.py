"""Benchmark of curvesmith.keyline (section 5 of Graiff Zurita, Kajiwara & Suzuki).

Part 1 -- equilateral resampling (Figs. 11-13) of dense noisy 3D keyline scans
projected on their plane, ``N`` scan points in {1e3, 1e4, 1e5}, step 1 mm
(about 270 output vertices). Compared, same data, same run:

* ``keyline.resample_equilateral``: the paper's rule, block bounding boxes
  searched from the right end, ``O(sqrt N)`` per output vertex;
* a brute-force numpy sweep of the same rule: every segment at every step,
  ``O(N)`` per output vertex (the plain vectorized implementation);
* the chord walker of ``curvesmith.elastica`` (first crossing ahead, a
  different rule on features smaller than r; a Python loop over segments).

Reported: median time, ratio to ours, and the largest distance between the
outputs (0 when the rules agree; the walker may differ on noisy scans).

Part 2 -- pipeline throughput: ``keyline.fit`` on M synthetic scans (two exact
elastica halves, tilted planes, noise 0.01 mm, ~2000 points each), scans per
second and the share of each stage (plane fit, resampling, inflection, fits).

Run ``python benchmarks/bench_keyline.py`` (``--quick`` for a short run).
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np

from _timing import median_time
from curvesmith import keyline
from curvesmith.geometry import resample_equilateral


def elastica_walker(p: np.ndarray, step: float) -> np.ndarray:
    """Peer: the plain first-hit walker (``rule="walk"``; one Python step per segment tried)."""
    return resample_equilateral(p, step, rule="walk")


def brute_force(p, r):
    """The paper's rule with a full O(N) numpy sweep over all segments at every step."""
    d = np.diff(p, axis=0)
    ll = np.einsum("ij,ij->i", d, d)
    keep = ll > 0
    a, d, ll = p[:-1][keep], d[keep], ll[keep]
    s0 = np.concatenate([[0.0], np.cumsum(np.sqrt(ll))])[:-1]
    out, c, tc = [p[0]], p[0], 0.0
    while True:
        w = a - c
        b = np.einsum("ij,ij->i", w, d)
        cq = np.einsum("ij,ij->i", w, w) - r * r
        disc = b * b - ll * cq
        ok = disc >= 0
        sq = np.sqrt(np.where(ok, disc, 0.0))
        u = np.concatenate([(-b - sq) / ll, (-b + sq) / ll])
        j = np.concatenate([np.arange(len(a))] * 2)
        v = np.concatenate([ok, ok]) & (u >= -1e-13) & (u <= 1 + 1e-13)
        u, j = np.clip(u[v], 0, 1), j[v]
        t = s0[j] + u * np.sqrt(ll[j])
        ahead = t > tc + 1e-12 * r
        if not ahead.any():
            return np.array(out)
        m = int(np.argmax(np.where(ahead, t, -np.inf)))
        tc, c = float(t[m]), a[j[m]] + u[m] * d[j[m]]
        out.append(c)


def scan2d(n_points, seed):
    ppe = max(1, round(n_points / 268))
    syn = keyline.synthetic_keyline(points_per_edge=ppe, noise=0.01, seed=seed)
    return np.ascontiguousarray(keyline.fit_plane(syn.points).points2d)


def part1(sizes, repeats):
    print("Part 1: equilateral resampling, step 1 mm, noisy scans (noise 0.01 mm)")
    header = (
        f"{'N':>8} {'method':<34} {'median [ms]':>12} {'ratio':>8} {'vertices':>9} {'max diff':>10}"
    )
    print(header)
    print("-" * len(header))
    for n in sizes:
        p = scan2d(n, seed=1234)
        t_ours, ours = median_time(lambda p=p: keyline.resample_equilateral(p, 1.0), repeats)
        rows = [("keyline.resample_equilateral", t_ours, ours)]
        t_bf, bf = median_time(lambda p=p: brute_force(p, 1.0), max(1, repeats // 2))
        rows.append(("brute-force numpy sweep (same rule)", t_bf, bf))
        t_w, w = median_time(lambda p=p: elastica_walker(p, 1.0), 1)
        rows.append(("elastica chord walker (first cut)", t_w, w))
        for name, t, out in rows:
            m = min(len(out), len(ours))
            diff = (
                float(np.abs(out[:m] - ours[:m]).max()) if len(out) == len(ours) else float("nan")
            )
            print(
                f"{len(p):>8} {name:<34} {1e3 * t:>12.2f} {t / t_ours:>8.1f} {len(out):>9} "
                f"{diff:>10.2e}"
            )


def part2(count, repeats):
    print()
    print(f"Part 2: keyline.fit throughput on {count} synthetic scans (noise 0.01 mm, step 1 mm)")
    rng = np.random.default_rng(1234)
    scans = []
    for _ in range(count):
        left = (rng.uniform(0.007, 0.009), None, rng.uniform(0.26, 0.34))
        right = (rng.uniform(0.014, 0.016), None, rng.uniform(0.36, 0.44))
        tilt = rng.uniform(-0.4, 0.4, size=3)
        syn = keyline.synthetic_keyline(
            left=left, right=right, tilt=tilt, noise=0.01, seed=int(rng.integers(1 << 31))
        )
        scans.append(syn.points)
    stage = {"plane fit": 0.0, "resampling": 0.0, "inflection": 0.0}
    for pts in scans:
        t0 = time.perf_counter()
        pf = keyline.fit_plane(pts)
        t1 = time.perf_counter()
        poly = keyline.resample_equilateral(pf.points2d, 1.0)
        t2 = time.perf_counter()
        keyline.estimate_inflection(keyline.principal_frame(poly).coords)
        t3 = time.perf_counter()
        stage["plane fit"] += t1 - t0
        stage["resampling"] += t2 - t1
        stage["inflection"] += t3 - t2
    totals, ok = [], 0
    for _ in range(repeats):
        t0 = time.perf_counter()
        results = [keyline.fit(pts, step=1.0) for pts in scans]
        totals.append(time.perf_counter() - t0)
        ok = sum(r.success for r in results)
    total = statistics.median(totals)
    stage["elastica fits (rest)"] = total - sum(stage.values())
    print(f"{'stage':<24} {'time [s]':>9} {'share':>7}")
    for name, t in stage.items():
        print(f"{name:<24} {t:>9.3f} {100 * t / total:>6.1f}%")
    print(
        f"total {total:.3f} s for {count} scans: {count / total:.2f} scans/s, "
        f"{1e3 * total / count:.0f} ms per scan; {ok}/{count} with both sides converged"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="short run")
    args = parser.parse_args()
    if args.quick:
        part1([1_000, 10_000], repeats=3)
        part2(4, repeats=1)
    else:
        part1([1_000, 10_000, 100_000], repeats=5)
        part2(20, repeats=1)


if __name__ == "__main__":
    main()
