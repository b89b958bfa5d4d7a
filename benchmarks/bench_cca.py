"""Benchmark of curvesmith.cca.smooth against subdivision.chaikin on the same polygons.

Seeded random polygons of 1e2 .. 1e6 vertices (``--quick``: up to 1e5), 1 .. 5
iterations (capped so the output stays below ~30 M vertices). Three families:
``wavy`` (a smooth closed curve, few restriction decreases), ``jagged``
(radius noise, many inflections and local alpha decreases) and ``noisy``
(random angles and 5 % radius noise: uneven edges, like a digitised outline,
the slowest case). For each case the
median wall time over the repeats, output vertices per second for CCA (wall
time, and CPU time summed over its threads: the throughput of one core) and
Chaikin, the time ratio per output vertex (CCA / Chaikin) in wall time and in
CPU time (``process_time``, steadier on a shared machine), the number of local
alpha decreases, and the peak traced memory of one CCA run as a multiple of the
output array (tracemalloc; skipped above 3 M output vertices). Quantities not
measured print as ``-``. CCA runs its compiled kernel (numba; the first call of
the process, which loads or compiles it, is the warm-up and is printed); one
ring is one thread (``workers`` only splits batches of several curves);
Chaikin is one thread of numpy.

Run: ``python benchmarks/bench_cca.py [--quick] [--repeats R] [--workers W]``.
"""

from __future__ import annotations

import argparse
import functools
import statistics
import time
import tracemalloc

import numpy as np

from curvesmith import cca, subdivision

MAX_OUTPUT = 30_000_000


def polygon(kind: str, n: int, rng: np.random.Generator) -> np.ndarray:
    t = 2 * np.pi * np.arange(n) / n
    if kind == "wavy":
        r = 1 + 0.1 * np.sin(7 * t) + 0.05 * np.cos(3 * t)
    elif kind == "jagged":
        r = 1 + 0.3 * rng.uniform(size=n)
    else:
        t = np.sort(rng.uniform(0, 2 * np.pi, n))
        r = 1 + 0.05 * rng.normal(size=n)
    return np.column_stack([r * np.cos(t), r * np.sin(t)])


def timed(fn, repeats: int) -> tuple[float, float, np.ndarray]:
    """Median wall time (perf_counter) and median CPU time (process_time) over the repeats."""
    walls, cpus = [], []
    out = None
    for _ in range(repeats):
        c0, t0 = time.process_time(), time.perf_counter()
        out = fn()
        walls.append(time.perf_counter() - t0)
        cpus.append(time.process_time() - c0)
    return statistics.median(walls), statistics.median(cpus), out


def peak_ratio(fn, out_bytes: int) -> float:
    tracemalloc.start()
    fn()
    _, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    return peak / out_bytes


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="sizes up to 1e5, 2 repeats")
    ap.add_argument("--repeats", type=int, default=None, help="timing repeats (median)")
    ap.add_argument("--no-memory", action="store_true", help="skip the tracemalloc runs")
    ap.add_argument("--workers", type=int, default=None, help="cca threads (default: cca's)")
    args = ap.parse_args()
    sizes = [10**2, 10**3, 10**4, 10**5] + ([] if args.quick else [10**6])
    repeats = args.repeats or (2 if args.quick else 3)
    rng = np.random.default_rng(1234)
    t0 = time.perf_counter()
    cca.smooth(polygon("wavy", 100, rng), closed=True)  # warm-up: numba kernel, PCHIP
    print(f"first cca call (numba cache load or compile): {time.perf_counter() - t0:.2f} s")
    header = (
        f"{'shape':>6} {'N':>8} {'it':>2} {'out':>10} {'cca s':>8} {'cca Mv/s':>9} "
        f"{'cpu Mv/s':>9} {'chaikin Mv/s':>12} {'ratio':>6} {'cpu ratio':>9} {'reduced':>8} "
        f"{'peak/out':>8}"
    )
    print(header)
    print("-" * len(header))
    for kind in ("wavy", "jagged", "noisy"):
        for n in sizes:
            p = polygon(kind, n, rng)
            for it in range(1, 6):
                if n * 3**it > MAX_OUTPUT:
                    break
                run = functools.partial(
                    cca.smooth, p, closed=True, iterations=it, threads=args.workers
                )
                t_cca, c_cca, out = timed(run, repeats)
                t_ch, c_ch, ch = timed(
                    lambda p=p, it=it: subdivision.chaikin(p, closed=True, iterations=it), repeats
                )
                info = (
                    cca.smooth_with_info(p, closed=True, iterations=it, threads=args.workers)
                    if n <= 10**5
                    else None
                )
                v_cca = out.shape[0] / t_cca / 1e6
                v_cpu = out.shape[0] / max(c_cca, 1e-9) / 1e6
                v_ch = ch.shape[0] / t_ch / 1e6
                cpu_ratio = (c_cca / out.shape[0]) / max(c_ch / ch.shape[0], 1e-30)
                if args.no_memory or n * 3**it > 3_000_000:
                    mem = "-"
                else:
                    mem = f"{peak_ratio(run, out.nbytes):.2f}"
                red = "-" if info is None else str(info.reductions)
                print(
                    f"{kind:>6} {n:>8} {it:>2} {out.shape[0]:>10} {t_cca:>8.3f} {v_cca:>9.2f} "
                    f"{v_cpu:>9.2f} {v_ch:>12.2f} {v_ch / v_cca:>6.2f} {cpu_ratio:>9.2f} "
                    f"{red:>8} {mem:>8}"
                )


if __name__ == "__main__":
    main()
