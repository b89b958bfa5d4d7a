"""Writer throughput and memory: CSV, GeoJSON and SVG of smoothed 1e4 .. 1e6-vertex rings.

For each size, a seeded noisy ring of N vertices is smoothed by CCA (``--iterations``,
default 3: 27 N output vertices), then written by curvesmith's streaming writers; the peer,
in the same run, is the smoothing itself (the issue's target: writing within 3x of
smoothing's time) and, for CSV, the pre-streaming writer (all rows as Python strings, then
one ``write``). Peak memory of each writer (tracemalloc, which numpy reports its buffers
to) is printed as a multiple of the output array's size (target: under 3x).

Usage: ``python benchmarks/bench_io.py [--quick] [--iterations K] [--repeat R]`` (each
writer runs once timed and once under tracemalloc; --repeat is for the smoothing peer).
"""

from __future__ import annotations

import argparse
import tempfile
import time
import tracemalloc
from pathlib import Path

import numpy as np

from _timing import median_time
from curvesmith import cca
from curvesmith import io as cio


def ring(n: int, seed: int = 7) -> np.ndarray:
    rng = np.random.default_rng(seed)
    t = np.sort(rng.uniform(0, 2 * np.pi, n))
    r = 5e4 * (1 + 0.02 * rng.standard_normal(n))
    return np.c_[4.5e5 + r * np.cos(t), 5.2e6 + r * np.sin(t)]  # UTM-like metres


def old_csv(points: np.ndarray, path: Path) -> None:
    """The writer before streaming: every row a Python string, joined, written at once."""
    pts = points.tolist()
    pts.append(pts[0])
    cols = [list(map(repr, col)) for col in zip(*pts, strict=True)]
    text = "x,y,closed\n" + "".join([",".join(r) + ",true\n" for r in zip(*cols, strict=True)])
    path.write_text(text)


def traced(fn) -> tuple[float, float]:
    """Wall time and tracemalloc peak (bytes) of one call."""
    tracemalloc.start()
    t0 = time.perf_counter()
    try:
        fn()
        sec = time.perf_counter() - t0
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    return sec, peak


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="sizes up to 1e5 only")
    parser.add_argument("--iterations", type=int, default=3)
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    sizes = [10_000, 100_000] + ([] if args.quick else [1_000_000])
    print(f"{'N in':>9} {'N out':>10} {'step':<20} {'median s':>9} {'x smoothing':>12} "
          f"{'peak mem / output array':>24}")  # fmt: skip
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        for n in sizes:
            p = ring(n)
            sec_smooth, out = median_time(
                lambda p=p: cca.smooth(p, closed=True, iterations=args.iterations), args.repeat
            )
            curve = cio.Curve(out, closed=True, kind="Polygon")
            m = len(out)
            print(f"{n:>9} {m:>10} {'cca.smooth (peer)':<20} {sec_smooth:>9.3f} {1.0:>12.2f}")
            steps = {
                "old CSV writer": (old_csv, out, "old.csv"),
                "write CSV": (cio.write_curves, [curve], "o.csv"),
                "write GeoJSON": (cio.write_curves, [curve], "o.geojson"),
                "write SVG": (cio.write_curves, [curve], "o.svg"),
            }
            for name, (fn, data, file) in steps.items():
                if name.startswith("old") and n > 100_000:
                    continue  # minutes and gigabytes: the issue measured 110 s / 13.3 GB
                call = lambda fn=fn, data=data, file=file: fn(data, folder / file)  # noqa: E731
                sec, _ = median_time(call, 1)
                mem = traced(call)[1] / curve.points.nbytes  # tracemalloc slows it: separate run
                print(f"{n:>9} {m:>10} {name:<20} {sec:>9.3f} {sec / sec_smooth:>12.2f} "
                      f"{mem:>23.2f}x")  # fmt: skip
            back = cio.read_curves(folder / "o.csv")[0].points
            assert np.array_equal(back, curve.points), "CSV round trip is not bit-exact"


if __name__ == "__main__":
    main()
