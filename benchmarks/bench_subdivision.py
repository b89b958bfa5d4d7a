"""Subdivision throughput: output vertices per second for 1e3 .. 1e6 input vertices.

Runs curvesmith's Chaikin, de Rham (gamma = 5) and Lane–Riesenfeld (degree 3)
on seeded random closed polygons, one step each, and the plain vectorized numpy
Chaikin that a user would write (the peer) in the same run, printing medians
and the ratio to the peer. PostGIS ``ST_ChaikinSmoothing`` (C) runs at 22-57 M
output vertices/s on these machines (figure quoted in issue 2).

Usage: ``python benchmarks/bench_subdivision.py [--quick] [--repeat R]``
"""

from __future__ import annotations

import argparse

import numpy as np

from _timing import median_time
from curvesmith import subdivision


def plain_chaikin_closed(p: np.ndarray) -> np.ndarray:
    """The straightforward vectorized numpy Chaikin step (the peer)."""
    q = np.roll(p, -1, axis=0)
    out = np.empty((2 * len(p), p.shape[1]))
    out[0::2] = 0.75 * p + 0.25 * q
    out[1::2] = 0.25 * p + 0.75 * q
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="sizes up to 1e5 only")
    parser.add_argument("--repeat", type=int, default=15)
    args = parser.parse_args()
    sizes = [1_000, 10_000, 100_000] + ([] if args.quick else [1_000_000])
    rng = np.random.default_rng(1234)
    print(f"{'N':>9} {'method':<26} {'median ms':>10} {'M out-vert/s':>13} {'vs numpy peer':>14}")
    for n in sizes:
        t = np.sort(rng.uniform(0, 2 * np.pi, n))
        r = 1 + 0.1 * rng.standard_normal(n)
        p = np.c_[r * np.cos(t), r * np.sin(t)]
        cases = {
            "numpy peer (Chaikin)": lambda p=p: plain_chaikin_closed(p),
            "chaikin": lambda p=p: subdivision.chaikin(p, closed=True),
            "de_rham gamma=5": lambda p=p: subdivision.de_rham(p, gamma=5.0, closed=True),
            "lane_riesenfeld degree=3": lambda p=p: subdivision.lane_riesenfeld(
                p, degree=3, closed=True
            ),
        }
        peer = None
        for name, fn in cases.items():
            sec, _ = median_time(fn, args.repeat, warmup=True)
            peer = sec if peer is None else peer
            rate = 2 * n / sec / 1e6
            print(f"{n:>9} {name:<26} {sec * 1e3:>10.3f} {rate:>13.1f} {peer / sec:>13.2f}x")


if __name__ == "__main__":
    main()
