"""Demo section: area-preserving CCA1 smoothing (Gordon 2010) against Chaikin."""

from __future__ import annotations

from typing import Any

import numpy as np

from .. import cca, data, geometry, plot, subdivision

TITLE = "Area-preserving smoothing: corner cutting and augmentation (CCA)"


def run(ctx) -> None:
    """Draw the alpha-profile (Fig. 14 left) and three CCA1 steps against Chaikin."""
    _profile_figure(ctx)
    _polygon_figure(ctx)
    _plot_figure(ctx)


def _profile_figure(ctx) -> None:
    fig, (ax,) = plot.new_axes(1, width=6.5, height=4.3)
    plot.alpha_profile(annotate=True, ax=ax)
    ax.set_xlim(-5, 185)
    ax.set_ylim(-0.01, 0.29)
    ax.set_title("CCA1 alpha-profile (Gordon 2010, Table 1 / Fig. 14 left)")
    ctx.figure(
        fig,
        "cca_profile",
        "The regular alpha-profile through the Table 1 values (eq. (5) for n = 4, 6, 12, "
        "the triangle root 0.24443, the limit (sqrt(3)-1)/4), monotone cubic interpolation.",
    )
    for n in (4, 6, 12):
        ctx.number(f"alpha_{n}gon", cca.regular_alpha(n), f"eq. (5) for the regular {n}-gon")
    ctx.number("alpha_triangle", cca.TRIANGLE_ALPHA, "triangle value (9-gon of aspect ratio 1)")
    ctx.number("alpha_limit", cca.LIMIT_ALPHA, "limit of eq. (5) at 180 degrees")


def _polygon_figure(ctx) -> None:
    poly = data.load_points("cca_fig14.csv")
    a0 = geometry.signed_area(poly)
    res = cca.smooth_with_info(poly, closed=True, iterations=3)
    ch = subdivision.chaikin(poly, closed=True, iterations=3)
    a_cca = geometry.signed_area(res.points)
    a_ch = geometry.signed_area(ch)
    fig, axes = plot.new_axes(2, width=5.8, height=5.6)
    plot.before_after(
        poly,
        [res.points, ch],
        closed=True,
        labels=["input", "CCA1 x3", "Chaikin x3"],
        title="Three iterations (cf. Fig. 14 right)",
        ax=axes[0],
    )
    variants: dict[str, tuple[dict[str, Any], dict[str, Any]]] = {
        "restrictions (default)": ({}, {"lw": 2.4}),
        "alpha floor min_factor=0.8": ({"min_factor": 0.8}, {"lw": 1.4, "ls": "--"}),
        "no restrictions": ({"restrict": False}, {"lw": 1.2, "ls": ":", "color": "k"}),
    }
    plot.draw_curve(
        axes[1],
        poly,
        closed=True,
        color="0.55",
        marker="o",
        markersize=3,
        lw=1.0,
        label=f"input: area {a0:.12g}",
    )
    for name, (kw, style) in variants.items():
        r = cca.smooth_with_info(poly, closed=True, iterations=3, **kw)
        plot.draw_curve(
            axes[1],
            r.points,
            closed=True,
            **style,
            label=f"{name}: area {geometry.signed_area(r.points):.12g}, {r.reductions} decreases",
        )
    axes[1].set_xlim(-0.3, 3.2)
    axes[1].set_ylim(-0.3, 3.6)
    axes[1].set_title("Zoom: Definition 2 restrictions vs. an alpha floor")
    axes[1].set_xlabel("x")
    axes[1].set_ylabel("y")
    axes[1].legend(loc="upper center", bbox_to_anchor=(0.5, -0.16), fontsize=8, frameon=False)
    ctx.figure(
        fig,
        "cca_polygon",
        "A non-convex 10-gon: CCA1 (regular profile) keeps the area, Chaikin shrinks it. "
        "Right: next to nearly straight vertices the strict Definition 2 restrictions keep "
        "corners almost uncut (Fig. 12); an alpha floor or no restriction smooths them.",
    )
    ctx.number("area_input", a0, "signed area of the input polygon")
    ctx.number("area_cca_x3", a_cca, "signed area after 3 CCA1 steps")
    ctx.number("area_chaikin_x3", a_ch, "signed area after 3 Chaikin steps")
    ctx.number("rel_area_change_cca_x3", a_cca / a0 - 1, "relative change, CCA1")
    ctx.number("rel_area_change_chaikin_x3", a_ch / a0 - 1, "relative change, Chaikin")
    ctx.number("cca_local_alpha_reductions_x3", res.reductions, "restriction decreases")
    ctx.text(
        f"CCA1 turns the {len(poly)}-gon into a {len(res.points)}-gon in three steps with "
        f"relative area change {a_cca / a0 - 1:.1e}; Chaikin loses "
        f"{100 * (1 - a_ch / a0):.1f} % of the area. {res.reductions} local alpha decreases "
        "kept the Definition 2 / section 3.2 restrictions."
    )


def _plot_figure(ctx) -> None:
    x = np.arange(0.0, 13.0)
    y = np.array([0.0, 0.5, 3.0, 2.0, 2.2, 5.0, 1.0, 1.2, 4.0, 3.5, 0.5, 0.8, 0.0])
    p = np.column_stack([x, y])
    anchors = [4, 8]
    sm = cca.smooth(p, closed=False, iterations=3, anchors=anchors)
    ch = subdivision.chaikin(p, closed=False, iterations=3, preserve_endpoints=True)

    def integral(q):
        return float(np.sum(0.5 * (q[1:, 1] + q[:-1, 1]) * np.diff(q[:, 0])))

    fig, (ax,) = plot.new_axes(1, width=8.0, height=4.2)
    plot.draw_curve(
        ax,
        p,
        closed=False,
        markers=True,
        color="0.55",
        lw=1.0,
        label=f"data: integral {integral(p):.12g}",
    )
    plot.draw_curve(
        ax,
        sm,
        closed=False,
        lw=1.6,
        label=f"CCA1 x3, anchors at x=4, 8: integral {integral(sm):.12g}",
    )
    plot.draw_curve(
        ax, ch, closed=False, lw=1.2, label=f"Chaikin x3 (ends kept): integral {integral(ch):.12g}"
    )
    plot.mark_points(ax, p[anchors], marker="s", ms=6, label="anchor points")
    ax.set_xlabel("x")
    ax.set_ylabel("y")
    ax.set_title("Smoothing a plot keeps its integral (anchored pieces independently)")
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.18), fontsize=8, frameon=False)
    ctx.figure(
        fig,
        "cca_plot",
        "An open polyline (a plot) with two anchors: CCA1 keeps the area under the plot.",
    )
    ctx.number("plot_integral_input", integral(p), "trapezoid integral of the data")
    ctx.number("plot_integral_cca_x3", integral(sm), "integral after 3 anchored CCA1 steps")
    ctx.number("plot_integral_chaikin_x3", integral(ch), "integral after 3 Chaikin steps")
