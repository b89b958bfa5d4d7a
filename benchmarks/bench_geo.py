"""Benchmark of curvesmith.geo and curvesmith.batch.

1. Batch throughput: polygons per second for 1e3..1e5 seeded random polygons, smoothed in
   one process (``geo.smooth``) and on a local Dask cluster of 1 and 2 worker processes
   (``batch.smooth_partitioned``); the ratio 2 workers / 1 worker is the speedup.
2. Coverage: the US county coverage bundled in ``plotly-geo`` (3233 polygons, 1.04 M
   vertices; ``--quick``: Nebraska and Kansas) smoothed as a coverage with cca (one
   process, and 2 Dask workers in parallel over arcs), against our Chaikin (coverage mode
   and per county) and Smoothify (pip; per county, area restored by buffering) in the same
   run: time, max relative area change per polygon, gap and overlap area.

Run ``python benchmarks/bench_geo.py [--quick]``.
"""

from __future__ import annotations

import argparse
import statistics
import time
import warnings

import numpy as np
import shapely

from curvesmith import batch, geo

_LAST_CPU = [0.0]


def median_time(fn, repeats: int) -> tuple[float, object]:
    """Median wall time of ``repeats`` runs.

    The median CPU time of this process is kept in ``_LAST_CPU[0]`` (the machine may be
    shared: CPU time shows the cost without the waiting).
    """
    times, cpu, out = [], [], None
    for _ in range(repeats):
        t0, c0 = time.perf_counter(), time.process_time()
        out = fn()
        times.append(time.perf_counter() - t0)
        cpu.append(time.process_time() - c0)
    _LAST_CPU[0] = statistics.median(cpu)
    return statistics.median(times), out


def random_polygons(n: int, rng: np.random.Generator) -> np.ndarray:
    """N star-shaped polygons with 16..47 vertices on a grid (no two interact)."""
    k = rng.integers(16, 48, size=n)
    idx = np.repeat(np.arange(n), k)
    start = np.repeat(np.cumsum(k) - k, k)
    j = np.arange(k.sum()) - start
    t = 2 * np.pi * j / np.repeat(k, k) + rng.uniform(0, 0.05, size=k.sum())
    r = rng.uniform(0.5, 1.0, size=k.sum())
    side = int(np.ceil(np.sqrt(n)))
    cx = 3.0 * (np.arange(n) % side)
    cy = 3.0 * (np.arange(n) // side)
    xy = np.column_stack([cx[idx] + r * np.cos(t), cy[idx] + r * np.sin(t)])
    rings = shapely.linearrings(xy, indices=idx)
    polys = shapely.polygons(rings)
    return shapely.make_valid(polys, method="structure", keep_collapsed=False)


def gaps_overlaps(after: np.ndarray) -> tuple[float, float]:
    """Gap area (holes inside the union) and overlap area (pairwise intersections).

    Invalid outputs (a peer may produce some) are repaired for the measurement only.
    """
    after = shapely.make_valid(after)
    union = shapely.union_all(after)
    holes = [shapely.Polygon(r) for p in shapely.get_parts(union) for r in p.interiors]
    gap = float(shapely.area(np.array(holes, dtype=object)).sum()) if holes else 0.0
    a, b = shapely.STRtree(after).query(after, predicate="intersects")
    keep = a < b
    inter = shapely.area(shapely.intersection(after[a[keep]], after[b[keep]]))
    return gap, float(inter.sum())


def bench_batch(sizes: list[int], repeats: int) -> None:
    import distributed

    rng = np.random.default_rng(1234)
    print("\n== batch throughput: geo.smooth (cca, 1 iteration) on random polygons ==")
    print(
        f"{'polygons':>9} {'vertices':>10} {'1 proc /s':>11} {'dask 1w /s':>11} "
        f"{'dask 2w /s':>11} {'2w / 1w':>8} {'2w / proc':>9} {'2w cores used':>13}"
    )
    clusters = {}
    try:
        for w in (1, 2):
            clusters[w] = distributed.LocalCluster(
                n_workers=w,
                threads_per_worker=1,
                processes=True,
                dashboard_address=":0",
                silence_logs=40,
            )
        clients = {w: distributed.Client(c) for w, c in clusters.items()}
        for n in sizes:
            polys = random_polygons(n, rng)
            nv = int(shapely.get_num_coordinates(polys).sum())
            rep = repeats if n <= 10_000 else 1
            t1, _ = median_time(lambda p=polys: geo.smooth(p), rep)
            psize = max(100, n // 16)
            td, used = {}, {}
            for w, client in clients.items():
                client.run(lambda: None)  # workers up
                cpu0 = client.run(time.process_time)
                w0 = time.perf_counter()
                td[w], _ = median_time(
                    lambda p=polys, c=client, k=psize: batch.smooth_partitioned(
                        p, client=c, partition_size=k
                    ),
                    rep,
                )
                wall = time.perf_counter() - w0
                cpu1 = client.run(time.process_time)
                # worker CPU seconds per wall second: 2.0 = both workers had a core each
                used[w] = sum(cpu1[k] - cpu0[k] for k in cpu1) / wall
            print(
                f"{n:>9} {nv:>10} {n / t1:>11.0f} {n / td[1]:>11.0f} {n / td[2]:>11.0f} "
                f"{td[1] / td[2]:>8.2f} {t1 / td[2]:>9.2f} {used[2]:>13.2f}"
            )
        for c in clients.values():
            c.close()
    finally:
        for c in clusters.values():
            c.close()


def bench_coverage(quick: bool) -> None:
    import distributed

    states = ("31", "20") if quick else None
    df = geo.us_counties(states=states).to_crs("EPSG:5070")
    g = df.geometry.values
    a0 = shapely.area(g)
    nv = int(shapely.get_num_coordinates(g).sum())
    print(f"\n== coverage: {len(df)} US counties, {nv} vertices (plotly-geo, EPSG:5070) ==")
    rows = []

    def record(name, secs, out, cpu=None):
        cpu = _LAST_CPU[0] if cpu is None else cpu
        out = np.asarray(out, dtype=object)
        rel = float(np.max(np.abs(shapely.area(out) - a0) / a0))
        n_invalid = int((~shapely.is_valid(out)).sum())
        gap, overlap = gaps_overlaps(out)
        rows.append((name, secs, cpu, rel, gap / 1e6, overlap / 1e6, n_invalid))

    geo.smooth_coverage(g[:3])  # warm-up: imports, alpha profile
    t, res = median_time(lambda: geo.smooth_coverage(g, validate=False, full_output=True), 1)
    record("cca coverage, 1 process", t, res.geometry)
    tv, valid = median_time(lambda: shapely.coverage_is_valid(res.geometry), 1)
    print(
        f"cca coverage: {res.n_arcs} arcs, {res.n_nodes} nodes, {len(res.reductions)} "
        f"reduced pieces; coverage_is_valid(result) = {valid} ({tv:.2f} s wall, "
        f"{_LAST_CPU[0]:.2f} s cpu to check)"
    )
    with (
        distributed.LocalCluster(
            n_workers=2,
            threads_per_worker=1,
            processes=True,
            dashboard_address=":0",
            silence_logs=40,
        ) as cluster,
        distributed.Client(cluster) as client,
    ):
        client.run(lambda: None)
        t2, out2 = median_time(
            lambda: batch._coverage_on_dask(
                df,
                method="cca",
                iterations=1,
                alpha="regular",
                make_valid=False,
                snap=None,
                chunk=max(200, len(df) * 4 // 8),
                workers=None,
                scheduler=None,
                client=client,
                progress=False,
            ),
            1,
        )
    record("cca coverage, 2 Dask workers (+validate)", t2, out2[0].geometry.values, float("nan"))
    t, out = median_time(lambda: geo.smooth_coverage(g, method="chaikin", validate=False), 1)
    record("Chaikin coverage, 1 process", t, out)
    t, out = median_time(lambda: geo.smooth(g), 1)
    record("cca per polygon, 1 process", t, out)
    t, out = median_time(lambda: geo.smooth(g, method="chaikin"), 1)
    record("Chaikin per polygon, 1 process", t, out)
    try:
        import smoothify

        seg = float(
            np.median(np.linalg.norm(np.diff(shapely.get_coordinates(g[:200]), axis=0), axis=1))
        )
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            t, out = median_time(
                lambda: smoothify.smoothify(
                    df,
                    segment_length=seg,
                    num_cores=1,
                    smooth_iterations=1,
                    merge_collection=False,
                    merge_multipolygons=False,
                    merge_holes=False,
                ),
                1,
            )
        record("Smoothify per polygon (1 core, buffer area fix)", t, out.geometry.values)
    except ImportError:
        print("Smoothify not installed: pip install smoothify")
    base = rows[0][1]
    print(
        f"{'method':<48} {'wall s':>7} {'cpu s':>6} {'x cca':>6} {'max |dA|/A':>11} "
        f"{'gaps km2':>9} {'overl. km2':>10} {'invalid':>7}"
    )
    for name, secs, cpu, rel, gap, ov, bad in rows:
        print(
            f"{name:<48} {secs:>7.2f} {cpu:>6.2f} {secs / base:>6.2f} {rel:>11.2e} "
            f"{gap:>9.3f} {ov:>10.3f} {bad:>7}"
        )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="small sizes, state subset")
    args = ap.parse_args()
    sizes = [1_000, 10_000] if args.quick else [1_000, 10_000, 100_000]
    bench_batch(sizes, repeats=1 if args.quick else 3)
    bench_coverage(args.quick)


if __name__ == "__main__":
    main()
