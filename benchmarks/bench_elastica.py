"""Benchmark of curvesmith.elastica.fit: default backend vs IPOPT vs least_squares variants.

Same data, same run, for N in {100, 300, 1000}: a noisy discrete elastica (three periods,
case (ii)), each backend started from the same initial guess (section 4.3). Reports the
median wall time and the median CPU time (``time.process_time``, less sensitive to other
load on a shared machine) over repeats, the ratio of wall times to the default backend,
the iterations (Jacobian evaluations for the least-squares solvers, IPOPT iterations) and
the final rms. A last table fits long near-separatrix curves with many loops from
the own initial guess: single start vs the growing-prefix continuation of ``fit``.

Rows: the default ``fit`` (Levenberg-Marquardt, MINPACK ``leastsq``, with the bounded trf
fallback that does not run here); ``least_squares`` trf with the analytic Jacobian (the
previous default's solver, with today's model code, plus the initial guess); trf with a
2-point finite-difference Jacobian; IPOPT twice: as ``fit(method="ipopt")`` (variables
scaled by the Jacobian column norms, as least_squares does with x_scale="jac") and as set
up in the paper (raw parameters, L-BFGS Hessian), the peer. Run
``python benchmarks/bench_elastica.py`` (``--quick`` for a short run: fewer repeats,
unscaled IPOPT only at N = 100). OpenBLAS is pinned to one thread: the Jacobians have 7
columns, and on a shared machine a multi-threaded SVD of a 2000 x 7 matrix can stall for
~100 ms.
"""

from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")

import argparse
import time

import numpy as np
from scipy.optimize import least_squares
from scipy.special import ellipk

from curvesmith.elastica import fit, initial_guess, sample
from curvesmith.elastica.fit import _Problem


def make_data(n: int, rng) -> tuple[np.ndarray, np.ndarray]:
    k = 0.8
    z = 3 * 4 * ellipk(k * k) / (n - 1)  # three periods whatever N
    clean = sample((0.0, 0.0, 1.0, 0.3, z, 0.4, k), n)
    return clean, clean + rng.normal(scale=0.02, size=clean.shape)


def trf_least_squares(data: np.ndarray):
    """The previous default solver: least_squares trf, analytic Jacobian, bounds h, k > 0."""
    n = data.shape[0]
    start = np.array(initial_guess(data))
    prob = _Problem(data, start.copy(), np.ones(7, dtype=bool))
    lo = np.full(7, -np.inf)
    lo[2] = lo[6] = 1e-12
    res = least_squares(
        prob.residuals,
        start,
        jac=prob.jacobian,
        bounds=(lo, np.inf),
        method="trf",
        x_scale="jac",
        ftol=1e-12,
        xtol=1e-12,
        gtol=1e-12,
        max_nfev=400,
    )
    rms = float(np.sqrt(np.mean(np.sum((sample(res.x, n) - data) ** 2, axis=1))))
    return rms, res.status > 0, int(res.njev)


def fd_least_squares(data: np.ndarray):
    """Scipy least_squares with a 2-point finite-difference Jacobian, same start and bounds."""
    n = data.shape[0]
    start = np.array(initial_guess(data))
    lo = np.full(7, -np.inf)
    lo[2] = lo[6] = 1e-12

    def residuals(p):
        return (sample(p, n) - data).ravel()

    res = least_squares(
        residuals,
        start,
        jac="2-point",
        bounds=(lo, np.inf),
        method="trf",
        x_scale="jac",
        ftol=1e-14,
        xtol=1e-14,
        gtol=1e-14,
        max_nfev=4000,
    )
    rms = float(np.sqrt(np.mean(np.sum((sample(res.x, n) - data) ** 2, axis=1))))
    return rms, res.status > 0, int(res.njev)


def ipopt_unscaled(data: np.ndarray):
    """IPOPT as set up in the paper: objective (4.8), gradient (4.9), L-BFGS Hessian, raw params.

    tol 1e-6, looser than fit's 1e-8 (in IPOPT's favour: unscaled it stalls at 1e-8 until
    max_iterations).
    """
    import cyipopt

    n = data.shape[0]
    start = np.array(initial_guess(data))
    prob = _Problem(data, start.copy(), np.ones(7, dtype=bool))
    bounds = [(None, None)] * 7
    bounds[2] = bounds[6] = (1e-12, None)
    with np.errstate(over="ignore", invalid="ignore"):  # it diverges at N = 1000
        res = cyipopt.minimize_ipopt(
            prob.objective,
            start,
            jac=prob.gradient,
            bounds=bounds,
            options={
                "hessian_approximation": "limited-memory",
                "tol": 1e-6,
                "max_iter": 3000,  # IPOPT's own option name
                "print_level": 0,
                "sb": "yes",
            },
        )
    rms = float(np.sqrt(np.mean(np.sum((sample(res.x, n) - data) ** 2, axis=1))))
    return rms, bool(res.success), int(res.nit)


def timed(fn, repeats: int):
    """Median wall time and median CPU time (process_time) of ``fn()``, and its last result."""
    walls, cpus, out = [], [], None
    for _ in range(repeats):
        w, c = time.perf_counter(), time.process_time()
        out = fn()
        cpus.append(time.process_time() - c)
        walls.append(time.perf_counter() - w)
    return float(np.median(walls)), float(np.median(cpus)), out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="short run")
    args = parser.parse_args()
    rng = np.random.default_rng(1234)
    sizes = [100, 300, 1000]
    reps = 15 if args.quick else 51
    print("fit of a noisy discrete elastica (sigma = 0.02 h), median wall and CPU time")
    print(
        f"{'N':>5} {'backend':<30} {'time [ms]':>10} {'cpu [ms]':>9} {'x default':>10} "
        f"{'iters':>6} {'rms':>12} {'ok':>4}"
    )
    for n in sizes:
        _, data = make_data(n, rng)
        for _ in range(20):  # warm-up: caches, branch predictors, CPU clock
            fit(data)
        t_def, c_def, r = timed(lambda d=data: fit(d), reps)
        rows = [("default fit (LM, analytic jac)", t_def, c_def, r.iterations, r.rms, r.success)]
        t, c, (rms, ok, it) = timed(lambda d=data: trf_least_squares(d), max(3, reps // 3))
        rows.append(("least_squares trf (previous)", t, c, it, rms, ok))
        t, c, (rms, ok, it) = timed(lambda d=data: fd_least_squares(d), max(1, reps // 8))
        rows.append(("least_squares trf, 2-point FD", t, c, it, rms, ok))
        t, c, r = timed(lambda d=data: fit(d, method="ipopt"), 1 if n >= 1000 else 3)
        rows.append(("fit(method='ipopt'), scaled", t, c, r.iterations, r.rms, r.success))
        if not args.quick or n <= 100:
            t, c, (rms, ok, it) = timed(lambda d=data: ipopt_unscaled(d), 1 if args.quick else 3)
            rows.append(("IPOPT unscaled (paper)", t, c, it, rms, ok))
        for name, t, c, it, rms, ok in rows:
            print(
                f"{n:>5} {name:<30} {1e3 * t:>10.2f} {1e3 * c:>9.2f} {t / t_def:>10.1f} "
                f"{it:>6} {rms:>12.6g} {ok!s:>4}"
            )

    print()
    print("long curves with many loops near the separatrix, from the own initial guess")
    print(
        f"{'k':>9} {'N':>5} {'loops':>6} {'single ok':>10} {'single rms':>11} "
        f"{'cont. ok':>9} {'cont. rms':>10} {'stages':>7} {'time [ms]':>10}"
    )
    cases = [(0.9999, 0.1, 1000), (0.99999, 0.2, 600), (1.001, 0.1, 2000)]
    if args.quick:
        cases = cases[:2]
    for k, z, n in cases:
        clean = sample((0.0, 0.0, 0.1, 0.4, z, 0.3, k), n)
        data = clean + rng.normal(scale=0.002, size=clean.shape)
        single = fit(data, continuation=False)
        t, _, auto = timed(lambda d=data: fit(d), 1)
        period = 4 * ellipk(k * k) if k < 1 else 2 * ellipk(1 / (k * k)) / k
        loops = z * (n - 1) / period
        print(
            f"{k:>9} {n:>5} {loops:>6.1f} {single.success!s:>10} {single.rms:>11.3g} "
            f"{auto.success!s:>9} {auto.rms:>10.3g} {auto.stages:>7} {1e3 * t:>10.0f}"
        )


if __name__ == "__main__":
    main()
