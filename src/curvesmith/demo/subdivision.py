"""Demo section: linear corner cutting (Chaikin, de Rham, Lane–Riesenfeld) on bundled curves."""

from __future__ import annotations

import numpy as np
from matplotlib.transforms import offset_copy

from .. import data, geometry, plot, subdivision

TITLE = "Linear subdivision: Chaikin, de Rham and Lane–Riesenfeld"


def run(ctx) -> None:
    """Draw the subdivision figures and record areas and lengths."""
    lake = data.load_points("lake.csv")
    track = data.load_points("track.csv")
    a0 = geometry.signed_area(lake)

    fig, axes = plot.new_axes(2, width=6.0, height=5.5)
    results = {
        "Chaikin x4": subdivision.chaikin(lake, closed=True, iterations=4),
        "de Rham gamma=1.2 x4": subdivision.de_rham(lake, gamma=1.2, closed=True, iterations=4),
        "de Rham gamma=8 x4": subdivision.de_rham(lake, gamma=8.0, closed=True, iterations=4),
    }
    plot.before_after(
        lake,
        list(results.values()),
        closed=True,
        labels=["input", *results],
        title="Closed polygon: corner cutting shrinks the area",
        ax=axes[0],
    )
    curves = {
        "Chaikin, ends kept": subdivision.chaikin(
            track, closed=False, iterations=4, preserve_endpoints=True
        ),
        "Lane-Riesenfeld degree 3": subdivision.lane_riesenfeld(track, degree=3, iterations=4),
        "Lane-Riesenfeld degree 5": subdivision.lane_riesenfeld(track, degree=5, iterations=4),
    }
    plot.before_after(
        track,
        list(curves.values()),
        closed=False,
        labels=["input track", *curves],
        title="Open polyline (GPS-like track)",
        ax=axes[1],
    )
    # The track panel is short (equal aspect): anchor its legend a fixed distance below the
    # axes so that it clears the tick labels and the x label.
    axes[1].legend(
        loc="upper center",
        bbox_to_anchor=(0.5, 0.0),
        bbox_transform=offset_copy(axes[1].transAxes, fig=fig, y=-38, units="points"),
        fontsize=8,
        frameon=False,
    )
    ctx.figure(
        fig,
        "subdivision_overview",
        "Chaikin, de Rham and Lane-Riesenfeld on a lake outline and a track.",
    )

    # Area loss per iteration: linear schemes converge to a curve of smaller area.
    its = np.arange(0, 7)
    changes = {}
    for name, fn in {
        "Chaikin": lambda k: subdivision.chaikin(lake, closed=True, iterations=k),
        "de Rham gamma=1.2": lambda k: subdivision.de_rham(
            lake, gamma=1.2, closed=True, iterations=k
        ),
        "de Rham gamma=8": lambda k: subdivision.de_rham(
            lake, gamma=8.0, closed=True, iterations=k
        ),
        "Lane-Riesenfeld degree 3": lambda k: subdivision.lane_riesenfeld(
            lake, degree=3, closed=True, iterations=k
        ),
    }.items():
        rel = [geometry.signed_area(fn(int(k))) / a0 - 1 for k in its]
        changes[name] = 100 * np.asarray(rel)
        ctx.number(
            f"area_change_{name.replace(' ', '_')}_x6",
            float(rel[-1]),
            "relative area change after 6 steps",
        )
    fig, (ax,) = plot.new_axes(1, width=6.5, height=4.2)
    plot.convergence(
        changes,
        logy=False,
        baseline=0.0,
        xlabel="iterations",
        ylabel="area change (%)",
        title="Linear corner cutting loses area (cca keeps it exactly)",
        ax=ax,
    )
    ax.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.02, 1.0), borderaxespad=0.0)
    ctx.figure(
        fig,
        "subdivision_area_loss",
        "Relative area change of the lake polygon per refinement step.",
    )

    fig, axes = plot.new_axes(2, width=6.0, height=5.5)
    plot.curvature_comb(lake, closed=True, ax=axes[0], title="Input polygon: curvature comb")
    smooth = results["Chaikin x4"]
    plot.curvature_comb(smooth, closed=True, ax=axes[1], title="After Chaikin x4: curvature comb")
    ctx.figure(
        fig, "subdivision_combs", "Discrete (Menger) curvature combs before and after Chaikin."
    )

    ctx.number("lake_vertices", len(lake), "vertices of the bundled lake polygon")
    ctx.number("lake_area", a0, "signed area of the input (CCW positive)")
    ctx.number("lake_length", geometry.curve_length(lake, closed=True), "perimeter of the input")
    for name, p in results.items():
        ctx.number(f"area_{name.replace(' ', '_')}", geometry.signed_area(p), f"area after {name}")
    ctx.text(
        "Chaikin (de Rham with gamma = 2) and the other linear schemes converge to smooth "
        "curves but pull the polygon inwards: every step loses area. The `cca` section shows "
        "the area-exact alternative."
    )
