"""Line networks and contours: smooth_network against per-line smoothing and shapely.simplify.

Peers, run in the same process: cca line by line (``geo.smooth``), Chaikin line by line
(PostGIS ``ST_ChaikinSmoothing`` / QGIS "Smooth"), and ``shapely.simplify`` (GEOS
Douglas-Peucker, what users reach for to "clean up" lines). For each: the pairs of lines
whose contact changed (new, lost, or moved), for contours the pairs of different levels
that touch or cross, the largest shift (Hausdorff distance), the largest area error and
the time; ``smooth_network`` also with ``max_shift`` set to the simplification tolerance.

Run: ``python benchmarks/bench_network.py [--quick]``.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np
import pyogrio
import shapely
from matplotlib import cbook
from scipy.ndimage import gaussian_filter

from curvesmith import geo


def max_area_error(before, after) -> float:
    """Largest area between an open line and its output / length²; relative for rings."""
    worst = 0.0
    for a, b in zip(before, after, strict=True):
        xa, xb = shapely.get_coordinates(a), shapely.get_coordinates(b)
        if a.is_closed:
            aa, ab = shapely.Polygon(xa).area, shapely.Polygon(xb).area
            worst = max(worst, abs(ab - aa) / aa if aa > 0 else 0.0)
        elif np.array_equal(xa[-1], xb[-1]):
            ring = np.vstack([xa, xb[::-1]])
            q = ring - ring[0]
            area = 0.5 * abs(np.dot(q[:-1, 0], q[1:, 1]) - np.dot(q[1:, 0], q[:-1, 1]))
            worst = max(worst, area / a.length**2)
        else:
            worst = float("nan")  # ends moved (Chaikin without preserved ends)
    return worst


def peers(df, iterations, tol):
    yield "cca network (smooth_network)", lambda: geo.smooth_network(df, iterations=iterations)
    yield (
        f"cca network, max_shift={tol:g}",
        lambda: geo.smooth_network(df, iterations=iterations, max_shift=tol),
    )
    yield "cca line by line", lambda: geo.smooth(df, iterations=iterations)
    yield "Chaikin line by line", lambda: geo.smooth(df, method="chaikin", iterations=iterations)
    yield (
        f"shapely.simplify({tol:g})",
        lambda: df.set_geometry(shapely.simplify(df.geometry.values, tol)),
    )


def run(name, df, iterations, tol, levels=None):
    before = df.geometry.values
    n_v = int(shapely.get_num_coordinates(before).sum())
    print(f"\n{name}: {len(df)} lines, {n_v} vertices, {iterations} iterations")
    head = f"{'method':<32} {'changed contacts':>16}"
    if levels is not None:
        head += f" {'level contacts':>15}"
    head += f" {'max shift':>10} {'max area error':>15} {'time (s)':>9} {'vs network':>10}"
    print(head)
    base = None
    for label, fn in peers(df, iterations, tol):
        t0 = time.perf_counter()
        out = fn()
        secs = time.perf_counter() - t0
        base = secs if base is None else base
        after = out.geometry.values
        row = f"{label:<32} {geo.changed_contacts(before, after):>16}"
        if levels is not None:
            row += f" {geo.level_contacts(after, levels):>15}"
        shift = float(shapely.hausdorff_distance(before, after).max())
        row += f" {shift:>10.3g} {max_area_error(before, after):>15.2e} {secs:>9.3f}"
        row += f" {secs / base:>9.2f}x"
        print(row)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true")
    args = ap.parse_args()
    pyogrio.set_gdal_config_options({"OSM_USE_CUSTOM_INDEXING": "NO"})
    osm = Path(pyogrio.__file__).parent / "tests" / "fixtures" / "sample.osm.pbf"
    roads = pyogrio.read_dataframe(osm, layer="lines").to_crs("EPSG:27700")
    run("OSM ways (pyogrio fixture, EPSG:27700)", roads, 3, 1.0)

    d = cbook.get_sample_data("jacksboro_fault_dem.npz")
    z = d["elevation"].astype(float)
    ny, nx = z.shape
    x, y = np.arange(nx) * 74.5, np.arange(ny)[::-1] * 92.6
    for interval in [100] if args.quick else [100, 20]:
        raw = geo.contours(z, x=x, y=y, interval=interval, iterations=0)
        run(f"Jacksboro DEM contours every {interval} m", raw, 2, 10.0, raw["level"].to_numpy())

    sizes = [28] if args.quick else [28, 56]
    for n in sizes:
        rng = np.random.default_rng(1234)
        yy, xx = np.mgrid[0:n, 0:n] * 25.0
        rough = gaussian_filter(rng.normal(size=(n, n)), 1.0)
        zz = 1.2 * xx + 400 * rough / rough.std()
        raw = geo.contours(zz, x=xx[0], y=yy[:, 0], interval=20, iterations=0)
        run(
            f"steep rough terrain {n}x{n}, contours every 20 m",
            raw,
            2,
            2.0,
            raw["level"].to_numpy(),
        )


if __name__ == "__main__":
    main()
