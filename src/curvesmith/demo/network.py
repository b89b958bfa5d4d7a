"""Demo section "network": a road network and contour lines smoothed without new contacts."""

from __future__ import annotations

import time
from pathlib import Path
from typing import Any

import numpy as np

from .. import plot as _plot

TITLE = "Line networks and contours: junctions fixed, no new contacts (curvesmith.geo)"


def run(ctx) -> None:
    """Smooth the OSM road network of pyogrio's fixture and contours of the Jacksboro DEM."""
    from ..errors import require

    for module in ("shapely", "geopandas", "pyogrio", "pyproj"):
        require(module, "geo", "the network demo section")
    import matplotlib.pyplot as plt
    import pyogrio
    import shapely
    from matplotlib import cbook

    from .. import geo

    # ---- roads: the OSM extract pyogrio ships (Welwyn Garden City area), in metres
    pyogrio.set_gdal_config_options({"OSM_USE_CUSTOM_INDEXING": "NO"})
    osm = Path(pyogrio.__file__).parent / "tests" / "fixtures" / "sample.osm.pbf"
    roads = pyogrio.read_dataframe(osm, layer="lines").to_crs("EPSG:27700")
    before = roads.geometry.values
    t0 = time.perf_counter()
    net = geo.smooth_network(roads, iterations=3, full_output=True)
    t_net = time.perf_counter() - t0
    per_cca = geo.smooth(roads, iterations=3).geometry.values
    bounded = geo.smooth_network(roads, iterations=3, max_shift=1.0).geometry.values
    per_chaikin = geo.smooth(roads, method="chaikin", iterations=3).geometry.values
    after = net.geometry.geometry.values
    rows = [
        "| method | line pairs whose contact changed (new, lost or moved > 1 mm) |",
        "|---|---|",
        f"| cca network (smooth_network) | {geo.changed_contacts(before, after, tol=1e-3)} |",
        f"| cca line by line | {geo.changed_contacts(before, per_cca, tol=1e-3)} |",
        f"| Chaikin line by line | {geo.changed_contacts(before, per_chaikin, tol=1e-3)} |",
    ]
    ctx.number("network_roads", len(roads), "OSM ways in pyogrio's sample.osm.pbf")
    ctx.number("network_arcs", net.n_arcs, "arcs between fixed nodes")
    ctx.number("network_nodes", net.n_nodes, "nodes: ends, junctions, crossings")
    ctx.number("network_reductions", len(net.reductions), "arc pieces smoothed less")
    ctx.number(
        "network_max_open_area",
        net.max_open_area,
        "largest area between an input line and its output, / length²",
    )
    ctx.number("network_seconds", t_net, "smooth_network time, 3 iterations")
    ctx.number(
        "network_max_shift",
        float(shapely.hausdorff_distance(before, after).max()),
        "largest shift of a road (Hausdorff distance, m), 3 iterations",
    )
    ctx.number(
        "network_max_shift_bounded",
        float(shapely.hausdorff_distance(before, bounded).max()),
        "the same with max_shift=1 (--max-shift 1): each piece at the strongest level within it",
    )
    ctx.text(
        "The 36 OSM ways of pyogrio's test extract (roads, footpaths, cycleways; projected to "
        "the British National Grid) smoothed with 3 iterations. `smooth_network` nodes the "
        "network, keeps every end, junction and crossing where it is and smooths the pieces "
        "between them once, so roads still meet exactly where they met; smoothing line by "
        "line (what QGIS *Smooth* or PostGIS `ST_ChaikinSmoothing` do) moves junctions off "
        "the roads they end on.\n\n" + "\n".join(rows)
    )

    # zoom on the busiest junction
    topo_nodes = geo.network_topology(
        [shapely.get_coordinates(g) for g in before], np.zeros(len(before), dtype=bool)
    ).nodes
    pts = shapely.points(topo_nodes)
    deg = shapely.STRtree(before).query(shapely.buffer(pts, 1e-6), predicate="intersects")[0]
    cx, cy = topo_nodes[np.bincount(deg, minlength=len(pts)).argmax()]
    half = 60.0
    fig, axes = plt.subplots(1, 2, figsize=(14, 6.5))
    ax = axes[0]
    _plot.draw_geometries(ax, before, color="0.6", lw=2.5)
    _plot.draw_geometries(ax, after, color="tab:blue", lw=1.0)
    _plot.mark_points(ax, topo_nodes, marker=".", ms=4)
    _plot.window_box(ax, (cx - half, cy - half, cx + half, cy + half), lw=1.0)
    ax.set_title("OSM ways: input (grey), smooth_network (blue), fixed nodes (black)")
    ax.set_aspect("equal")
    ax.set_xlabel("x (m, EPSG:27700)")
    ax.set_ylabel("y (m)")
    ax = axes[1]
    for geoms, color, lw, label in [
        (before, "0.6", 3.0, "input"),
        (per_chaikin, "tab:orange", 1.0, "Chaikin line by line"),
        (per_cca, "tab:green", 1.0, "cca line by line"),
        (after, "tab:blue", 1.5, "cca network"),
        (bounded, "tab:purple", 1.0, "cca network, --max-shift 1 m"),
    ]:
        dash = "--" if geoms is bounded else "-"
        window = (cx - half, cy - half, cx + half, cy + half)
        _plot.draw_geometries(ax, geoms, window=window, ls=dash, color=color, lw=lw, label=label)
    _plot.mark_points(ax, topo_nodes, marker=".", ms=6)
    ax.set_title("Zoom (120 m) on the busiest junction")
    ax.legend(loc="lower left", fontsize=8)
    ctx.figure(
        fig,
        "network_roads",
        "OSM road network smoothed as a network (junctions fixed) against line-by-line smoothing",
    )

    # ---- contours over a hillshade of matplotlib's Jacksboro fault DEM
    d: Any = cbook.get_sample_data("jacksboro_fault_dem.npz")  # an NpzFile
    z = d["elevation"].astype(float)
    ny, nx = z.shape
    dx, dy = 74.5, 92.6  # 3 arc-seconds in metres at 36.6° N
    x, y = np.arange(nx) * dx, np.arange(ny)[::-1] * dy
    t0 = time.perf_counter()
    res = geo.contours(z, x=x, y=y, interval=50, iterations=2, full_output=True)
    t_con = time.perf_counter() - t0
    raw = geo.contours(z, x=x, y=y, interval=50, iterations=0)
    per_chaikin = geo.smooth(raw, method="chaikin", iterations=2)
    per_cca = geo.smooth(raw, iterations=2)
    ctx.number("contours_lines", len(res.geometry), "contour lines, 50 m interval")
    crossings = {
        name: geo.level_contacts(df.geometry.values, df["level"].to_numpy())
        for name, df in (
            ("network", res.geometry),
            ("cca_per_line", per_cca),
            ("chaikin_per_line", per_chaikin),
        )
    }
    for name, count in crossings.items():
        ctx.number(f"contours_level_contacts_{name}", count, "")
    ctx.number("contours_reductions", len(res.smoothing.reductions), "pieces smoothed less")
    ctx.number(
        "contours_max_area_change",
        res.smoothing.max_area_change,
        "closed lines, relative (round-off; largest on loops a few metres wide)",
    )
    ctx.number("contours_seconds", t_con, "contours + smooth_network, 2 iterations")
    ctx.text(
        "Contours every 50 m of matplotlib's Jacksboro fault DEM (344 x 403 cells of about "
        "90 m), smoothed as one network: pairs of lines of different levels that touch or "
        f"cross — network: {crossings['network']}, cca line by line: "
        f"{crossings['cca_per_line']}, Chaikin line by line: {crossings['chaikin_per_line']}. "
        "On this gentle DEM line-by-line smoothing happens to keep the levels apart too; on "
        "steep rough terrain it does not (below), while the network never lets two levels "
        "meet."
    )
    fig, axes = plt.subplots(1, 2, figsize=(14, 6.2))
    for ax, zoom in zip(axes, (None, 3000.0), strict=True):
        _plot.hillshade(z, x, y, vert_exag=2, ax=ax)
        if zoom is None:
            geoms = [(res.geometry, "tab:red", 0.6)]
        else:
            geoms = [(raw, "yellow", 1.5), (res.geometry, "tab:red", 1.0)]
        for df, color, lw in geoms:
            _plot.draw_geometries(ax, df, color=color, lw=lw)
        ax.set_aspect("equal")
        if zoom is not None:
            cx, cy = x[nx // 2], y[ny // 2]
            ax.set_xlim(cx - zoom, cx + zoom)
            ax.set_ylim(cy - zoom, cy + zoom)
            ax.set_title("Zoom (6 km): raw marching squares (yellow), smoothed (red)")
        else:
            ax.set_title("Jacksboro fault DEM: 50 m contours smoothed as one network")
        ax.set_xlabel("x (m)")
    ctx.figure(
        fig,
        "network_contours",
        "Smoothed 50 m contours over a hillshade of the Jacksboro DEM: no two levels touch",
    )
    steep(ctx)


def _crossings(df):
    """Points where lines of different levels touch or cross."""
    import shapely

    g, lv = df.geometry.values, df["level"].to_numpy()
    i, j = shapely.STRtree(g).query(g, predicate="intersects")
    keep = (i < j) & (lv[i] != lv[j])
    x = shapely.intersection(g[i[keep]], g[j[keep]])
    return shapely.get_coordinates(x)


def steep(ctx) -> None:
    """Steep rough synthetic terrain: per-line smoothing makes levels cross, the network not."""
    import matplotlib.pyplot as plt
    from scipy.ndimage import gaussian_filter

    from .. import geo

    rng = np.random.default_rng(1234)
    n = 28
    yy, xx = np.mgrid[0:n, 0:n] * 25.0
    rough = gaussian_filter(rng.normal(size=(n, n)), 1.0)
    z = 1.2 * xx + 400 * rough / rough.std()  # 120 % slope, 400 m rough relief, 25 m cells
    raw = geo.contours(z, x=xx[0], y=yy[:, 0], interval=20, iterations=0)
    net = geo.contours(z, x=xx[0], y=yy[:, 0], interval=20, iterations=2)
    runs = {
        "Chaikin line by line": geo.smooth(raw, method="chaikin", iterations=2),
        "cca line by line": geo.smooth(raw, iterations=2),
        "cca network (geo.contours)": net,
    }
    counts = {k: len(_crossings(v)) for k, v in runs.items()}
    for k, v in counts.items():
        key = k.split(" (")[0].replace(" ", "_").lower()
        ctx.number(f"steep_crossing_points_{key}", v, f"{k}: points where two levels meet")
    ctx.text(
        "Steep rough synthetic terrain (a 120 % slope with 400 m of rough relief on 25 m "
        f"cells, {len(raw)} contour lines every 20 m): points where lines of different levels "
        "touch or cross after 2 iterations — "
        + ", ".join(f"{k}: {v}" for k, v in counts.items())
        + "."
    )
    pts = _crossings(runs["cca line by line"])
    cx, cy = pts[len(pts) // 2] if len(pts) else (n * 12.5, n * 12.5)
    half = 12.0
    fig, axes = plt.subplots(1, 3, figsize=(15, 5.2))
    for ax, (name, df) in zip(axes, runs.items(), strict=True):
        window = (cx - half, cy - half, cx + half, cy + half)
        _plot.draw_geometries(ax, raw, window=window, color="0.75", lw=3.0)
        _plot.draw_geometries(ax, df, window=window, color="tab:blue", lw=1.2, marker=".", ms=2)
        p = _crossings(df)
        _plot.mark_points(ax, p, marker="x", color="r", ms=10, mew=2)
        ax.set_title(f"{name}\n{counts[name]} crossing points in all (24 m zoom)")
        ax.set_xlabel("x (m)")
    ctx.figure(
        fig,
        "network_steep",
        "Steep rough terrain, 20 m contours (grey: raw): line-by-line smoothing makes levels "
        "cross (red), the network does not",
    )
