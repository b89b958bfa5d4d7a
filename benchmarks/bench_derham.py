"""Benchmark: prescribed-length de Rham interpolation, default method vs the paper's methods.

For tolerances 1e-6, 1e-9 and 1e-12 it measures the number of length
evaluations and the median wall time of ``curvesmith.derham.interpolate`` with
``method="accelerated"`` (default, certified), ``"secant"`` (Merrien, Lemma 5)
and ``"regula_falsi"`` (Lemma 4), on the paper's triangle (section 5, lengths
3.2, 3.7, 4.0, 4.25) and on seeded random admissible data, and prints ratios
against the secant method. The paper's methods evaluate ``f^n`` at the level
of the section 4 rule ``(|AB| + |BC|) 0.25^n < eps / 2``; a case whose level
exceeds ``--max-paper-level`` (default 20: one evaluation at level 22 costs
about a second) is reported as n/a -- that is "the accuracy the secant method
can reach" here. A second table times the default method for gamma != 2, where
the certificate needs one evaluation at level 13..21.

Run: ``python benchmarks/bench_derham.py [--quick] [--deep]``.
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np

from curvesmith import derham

PAPER = ((-1.5, -1.0), (1.5, 2.0), (1.5, 0.0), (1.5, -1.0))
PAPER_LENGTHS = (3.2, 3.7, 4.0, 4.25)
TOLS = (1e-6, 1e-9, 1e-12)
METHODS = ("accelerated", "secant", "regula_falsi")


def random_cases(count: int, rng: np.random.Generator) -> list[tuple]:
    """Admissible data: a non-degenerate triangle ABC and a length inside (|AC|, |AB| + |BC|)."""
    cases = []
    while len(cases) < count:
        a, b, c = rng.uniform(-10, 10, (3, 2))
        ab, bc = b - a, c - b
        if abs(ab[0] * bc[1] - ab[1] * bc[0]) < 0.1 * np.linalg.norm(ab) * np.linalg.norm(bc):
            continue  # nearly straight corner: length interval too thin
        lo = np.linalg.norm(c - a)
        hi = np.linalg.norm(ab) + np.linalg.norm(bc)
        cases.append((a, ab, c, bc, float(lo + rng.uniform(0.05, 0.95) * (hi - lo))))
    return cases


def run_case(case, *, method: str, tol: float, gamma: float, repeats: int):
    a, ua, c, uc, target = case
    times = []
    res = None
    for _ in range(repeats):
        t0 = time.perf_counter()
        res = derham.interpolate(
            a, ua, c, uc, length=target, gamma=gamma, tol=tol, method=method, level=0
        )
        times.append(time.perf_counter() - t0)
    ok = res.success and abs(res.length - target) <= tol
    return res.evaluations, statistics.median(times), ok, res.certified, res.level


def paper_level(case, tol: float) -> int:
    a, ua, c, uc, _ = case
    return derham.paper_level(a, ua, c, uc, tol=tol)


def table(
    name: str, cases, *, gamma: float, max_paper_level: int, repeats: int, secant_level: int
) -> None:
    print(f"\n## {name}: {len(cases)} case(s), gamma = {gamma:g}, median over cases")
    head = f"{'tol':>7} {'method':>13} {'n':>5} {'evals':>6} {'ms':>9} {'certified':>10}"
    print(head + f" {'evals/secant':>13} {'time/secant':>12}")
    for tol in TOLS:
        rows = {}
        for method in METHODS:
            levels = [paper_level(cs, tol) for cs in cases]
            cap = secant_level if method == "secant" else max_paper_level
            if method != "accelerated" and max(levels) > cap:
                rows[method] = None
                continue
            out = [
                run_case(
                    cs,
                    method=method,
                    tol=tol,
                    gamma=gamma,
                    repeats=repeats if method == "accelerated" or tol > 1e-7 else 1,
                )
                for cs in cases
            ]
            rows[method] = (
                statistics.median(o[0] for o in out),
                1e3 * statistics.median(o[1] for o in out),
                sum(o[2] for o in out),
                sum(o[3] for o in out),
                statistics.median(o[4] for o in out),
            )
        sec = rows["secant"]
        for method in METHODS:
            r = rows[method]
            if r is None:
                rule = max(paper_level(cs, tol) for cs in cases)
                note = f"n/a: level > {secant_level if method == 'secant' else max_paper_level}"
                print(f"{tol:>7.0e} {method:>13} {rule:>5} {note:>28}")
                continue
            ratio_e = f"{r[0] / sec[0]:.2f}" if sec else "-"
            ratio_t = f"{r[1] / sec[1]:.3f}" if sec else "-"
            print(
                f"{tol:>7.0e} {method:>13} {r[4]:>5g} {r[0]:>6g} {r[1]:>9.3f} "
                f"{r[3]:>4d}/{len(cases):<5d} {ratio_e:>13} {ratio_t:>12}"
            )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer cases and repeats")
    parser.add_argument("--max-paper-level", type=int, default=20)
    parser.add_argument(
        "--deep",
        action="store_true",
        help="also run the secant method at level 22 (tol 1e-12) on the paper's triangle "
        "(about 9 s per case)",
    )
    args = parser.parse_args()
    rng = np.random.default_rng(1234)
    repeats = 3 if args.quick else 7
    paper_cases = [(*PAPER, length) for length in PAPER_LENGTHS]
    rand = random_cases(3 if args.quick else 12, rng)
    print("# derham.interpolate: length evaluations and wall time to reach tol")
    print("n = level of f^n (paper's methods) or of the certificate (accelerated; 0 = closed form)")
    table(
        "paper's triangle (section 5)",
        paper_cases,
        gamma=2.0,
        max_paper_level=args.max_paper_level,
        repeats=repeats,
        secant_level=22 if args.deep else args.max_paper_level,
    )
    table(
        "random admissible data (seed 1234)",
        rand,
        gamma=2.0,
        max_paper_level=args.max_paper_level,
        repeats=repeats,
        secant_level=args.max_paper_level,
    )
    print("\n## default method for gamma != 2 on the paper's triangle, length 3.7, tol 1e-12")
    print(f"{'gamma':>6} {'n':>4} {'evals':>6} {'ms':>9} {'certified':>10}")
    for gamma in (1.2, 5.0, 12.0) if args.quick else (1.2, 1.5, 3.0, 5.0, 12.0):
        ev, t, _, cert, n = run_case(
            (*PAPER, 3.7), method="accelerated", tol=1e-12, gamma=gamma, repeats=3
        )
        print(f"{gamma:>6g} {n:>4d} {ev:>6d} {1e3 * t:>9.2f} {cert!s:>10}")


if __name__ == "__main__":
    main()
