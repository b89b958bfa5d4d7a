"""Benchmark of the global fit of ``curvesmith.elastica.fit`` on realistic section scans.

Curves from ``tests/elastica_curves.py`` (car-body-like C sections, 1.5 m in mm, spacing
0.001-11 mm, noise 0-0.3 mm, reversed, 5-point glitch). For each: the default fit
(``resample=True``), the exhaustive multi-start reference on the same resampled data
(``reference_fit``; ``--thorough`` for its full grid, else its 7-modulus grid), and the
paper's route (single start from the guess of section 4.3,
IPOPT with a quasi-Newton Hessian, ``continuation=False, method="ipopt"``) and the single
LM start. Prints time and rms of each and the ratio default / reference (target <= 1.15).
Then the speed at 800 and 7,600 points (equally spaced scans of three shapes, 0.005 mm noise,
and an uneven tilted 3D section scan in its PCA plane, spacing 0.01-17 mm, 0.1 mm noise),
wall and CPU time (``time.process_time``; the machine may be shared), against the same
search with seven-parameter solves throughout (``fit._VARPRO = False``, the search before
variable projection), run in the same process: the ratio is the speed-up. Run
``python benchmarks/bench_elastica_global.py`` (``--quick``: fewer curves, no reference;
``--speed``: the speed table only).
"""

from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import argparse
import importlib
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

from curvesmith import geometry
from curvesmith.elastica import fit
from elastica_curves import SHAPES, reference_fit, scan

fit_module = importlib.import_module("curvesmith.elastica.fit")

VARIANTS = [
    ("clean", {}),
    ("noise 0.05, reversed", {"noise": 0.05, "reverse": True}),
    ("noise 0.3, glitch", {"noise": 0.3, "glitch": True}),
]


def timed(fn):
    t0 = time.perf_counter()
    out = fn()
    return time.perf_counter() - t0, out


def timed_cpu(fn):
    t0, c0 = time.perf_counter(), time.process_time()
    out = fn()
    return time.perf_counter() - t0, time.process_time() - c0, out


def section_scan(n: int, seed: int = 7) -> np.ndarray:
    """A 1.5 m uneven 3D section (spacing ~0.01-17 mm, 0.1 mm noise) in its PCA plane.

    Tilted and reversed: the regression case of tests/test_elastica_realistic.py at `n` points.
    """
    rng = np.random.default_rng(seed)
    s = np.sort(rng.uniform(0, 1500, n))
    s[0], s[-1] = 0.0, 1500.0
    k = 1 / 900 + 1 / 2500 * np.sin(s / 700)
    th = np.concatenate([[0], np.cumsum(0.5 * (k[1:] + k[:-1]) * np.diff(s))])
    x = np.concatenate([[0], np.cumsum(np.cos(th[:-1]) * np.diff(s))])
    y = np.concatenate([[0], np.cumsum(np.sin(th[:-1]) * np.diff(s))])
    c, si = np.cos(0.4), np.sin(0.4)
    p = np.c_[x, y, np.zeros_like(x)] @ np.array([[1, 0, 0], [0, c, -si], [0, si, c]]).T
    p = (p + np.array([120.0, -40.0, 300.0]) + rng.normal(0, 0.1, (len(x), 3)))[::-1]
    centre, axes, _ = geometry.pca_frame(p)
    return (p - centre) @ axes[:2].T


def speed_table() -> None:
    print(
        "| curve | points | default wall s | default CPU s | rms | seven-parameter search CPU s |"
        " rms | speed-up (CPU) | starts | total iterations |"
    )
    print("|---|---|---|---|---|---|---|---|---|---|")
    cases = []
    for shape in ("clothoid", "bezier", "elastica_error"):
        base = scan(shape, uneven=False, noise=0.005, seed=2)
        s = np.concatenate([[0], np.cumsum(np.hypot(*np.diff(base, axis=0).T))])
        for n in (800, 7600):
            pos = np.linspace(0, s[-1], n)
            pts = np.column_stack([np.interp(pos, s, base[:, 0]), np.interp(pos, s, base[:, 1])])
            cases.append((shape, n, pts, False))
    for n in (800, 7600):
        cases.append(("section scan (uneven, resampled)", n, section_scan(n), True))
    for name, n, pts, resample in cases:
        rows = {}
        for varpro in (True, False):
            fit_module._VARPRO = varpro
            runs = [timed_cpu(lambda pts=pts, rs=resample: fit(pts, resample=rs)) for _ in range(3)]
            wall = float(np.median([r[0] for r in runs]))
            cpu = float(np.median([r[1] for r in runs]))
            rows[varpro] = (wall, cpu, runs[0][2])
        fit_module._VARPRO = True
        (w1, c1, r1), (_, c0, r0) = rows[True], rows[False]
        print(
            f"| {name} | {n} | {w1:.3f} | {c1:.3f} | {r1.rms:.4f} | {c0:.3f} | {r0.rms:.4f} | "
            f"{c0 / c1:.1f} | {r1.starts} | {r1.total_iterations} |",
            flush=True,
        )


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--thorough", action="store_true", help="the full reference (hours)")
    ap.add_argument("--speed", action="store_true", help="the speed table only")
    args = ap.parse_args()
    if args.speed:
        speed_table()
        return
    shapes = SHAPES[:2] if args.quick else SHAPES
    print(
        "| curve | variant | N | default s | default CPU s | default rms | reference s |"
        " reference rms | ratio | single LM rms | IPOPT (paper) s | IPOPT rms |"
    )
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    worst = 0.0
    for shape in shapes:
        for name, kw in VARIANTS:
            pts = scan(shape, seed=1, **kw)
            t_def, c_def, res = timed_cpu(lambda pts=pts: fit(pts, resample=True))
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
                f"| {shape} | {name} | {res.data.shape[0]} | {t_def:.3f} | {c_def:.3f} | "
                f"{res.rms:.4f} | "
                f"{t_ref:.1f} | {ref_rms:.4f} | {ratio:.3f} | {single.rms:.4f} | {t_ip:.2f} | "
                f"{ip_rms:.4f} |",
                flush=True,
            )
    print(f"\nworst default / reference rms ratio: {worst:.3f} (target <= 1.15)\n")
    speed_table()


if __name__ == "__main__":
    main()
