"""Benchmark of the global fit of ``curvesmith.elastica.fit`` on realistic section scans.

Curves from ``tests/elastica_curves.py`` (car-body-like C sections, 1.5 m in mm, spacing
0.001-11 mm, noise 0-0.3 mm, reversed, 5-point glitch). For each: the default fit
(``resample=True``), the exhaustive multi-start reference on the same resampled data
(``reference_fit``; ``--thorough`` for its full grid, else its 7-modulus grid), and the
paper's route (single start from the guess of section 4.3,
IPOPT with a quasi-Newton Hessian, ``continuation=False, method="ipopt"``) and the single
LM start. Prints time and rms of each and the ratio default / reference (target <= 1.15).
Then the speed at 800 and 7,600 points (a denser scan of the same curve). Run
``python benchmarks/bench_elastica_global.py`` (``--quick``: fewer curves, no reference).
"""

from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

from curvesmith.elastica import fit
from elastica_curves import SHAPES, reference_fit, scan

VARIANTS = [
    ("clean", {}),
    ("noise 0.05, reversed", {"noise": 0.05, "reverse": True}),
    ("noise 0.3, glitch", {"noise": 0.3, "glitch": True}),
]


def timed(fn):
    t0 = time.perf_counter()
    out = fn()
    return time.perf_counter() - t0, out


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--thorough", action="store_true", help="the full reference (hours)")
    args = ap.parse_args()
    shapes = SHAPES[:2] if args.quick else SHAPES
    print(
        "| curve | variant | N | default s | default rms | reference s | reference rms |"
        " ratio | single LM rms | IPOPT (paper) s | IPOPT rms |"
    )
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    worst = 0.0
    for shape in shapes:
        for name, kw in VARIANTS:
            pts = scan(shape, seed=1, **kw)
            t_def, res = timed(lambda pts=pts: fit(pts, resample=True))
            if args.quick:
                t_ref, ref_rms = float("nan"), float("nan")
            else:
                t_ref, (ref_rms, _) = timed(
                    lambda res=res: reference_fit(res.data, thorough=args.thorough)
                )
            single = fit(res.data, continuation=False)
            try:
                t_ip, ip = timed(lambda res=res: fit(res.data, continuation=False, method="ipopt"))
                ip_rms = ip.rms
            except Exception as exc:
                t_ip, ip_rms = float("nan"), float("nan")
                print(f"ipopt: {exc}")
            ratio = res.rms / ref_rms
            if np.isfinite(ratio):
                worst = max(worst, ratio)
            print(
                f"| {shape} | {name} | {res.data.shape[0]} | {t_def:.3f} | {res.rms:.4f} | "
                f"{t_ref:.1f} | {ref_rms:.4f} | {ratio:.3f} | {single.rms:.4f} | {t_ip:.2f} | "
                f"{ip_rms:.4f} |",
                flush=True,
            )
    print(f"\nworst default / reference rms ratio: {worst:.3f} (target <= 1.15)\n")
    print("| points | default fit s | rms | starts | total iterations |")
    print("|---|---|---|---|---|")
    for shape in ("clothoid", "elastica_error"):
        for n in (800, 7600):
            base = scan(shape, uneven=False, noise=0.005, seed=2)
            s = np.concatenate([[0], np.cumsum(np.hypot(*np.diff(base, axis=0).T))])
            pos = np.linspace(0, s[-1], n)
            pts = np.column_stack([np.interp(pos, s, base[:, 0]), np.interp(pos, s, base[:, 1])])
            times = []
            for _ in range(3):
                t, res = timed(lambda pts=pts: fit(pts))
                times.append(t)
            print(
                f"| {shape} {n} | {np.median(times):.3f} | {res.rms:.4f} | {res.starts} | "
                f"{res.total_iterations} |",
                flush=True,
            )


if __name__ == "__main__":
    main()
