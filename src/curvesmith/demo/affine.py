"""Demo section: affine arc length polylines and G2 quadratic B-splines (Käferböck, Figs. 10-13)."""

from __future__ import annotations

import dataclasses
import time

import numpy as np

from .. import affine, data, plot

TITLE = "Affine arc length polylines: curvature continuous quadratic B-splines (Käferböck)"


def _mid_params(t: np.ndarray, samples: int) -> np.ndarray:
    return (t[:-3] + t[1:-2] + t[2:-1] + t[3:]) / 4 / (samples - 1)


def run(ctx) -> None:
    """Reproduce Figs. 10-13 on the bundled stand-in curves and record the accuracy numbers."""
    import matplotlib.pyplot as plt
    from scipy.interpolate import make_lsq_spline

    control = data.load_points("affine_bezier8.csv")
    samples = 1000
    curve = affine.bezier_curve(control, np.linspace(0, 1, samples))
    t0 = time.perf_counter()
    res = affine.approximate(curve, vertices=60)
    seconds = time.perf_counter() - t0
    exact = affine.bezier_affine_curvature(control, _mid_params(res.t, samples))
    dev = np.abs(res.kappa_m - exact) / np.abs(exact)

    # Fig. 10: curve, affine arc length polyline, its quadratic B-spline
    fig, axes = plt.subplots(1, 2, figsize=(12, 5.5))
    for ax, zoom in zip(axes, (None, (8.33, 4.02, 8.49, 4.26)), strict=True):
        plot.affine_approximation(res, curve, window=zoom, ax=ax)
        ax.lines[0].set_label("degree-8 Bézier curve")
        if zoom:
            ax.set_title("detail: vertices on the curve, the spline just inside")
        else:
            ax.set_title("60-vertex affine arc length polyline (Fig. 10)")
            ax.legend(loc="center", fontsize=8)
    ctx.figure(
        fig,
        "affine_fig10_bezier",
        "Degree-8 Bézier curve approximated by a 60-vertex affine arc length polyline "
        "(1000 samples); its uniform quadratic B-spline is curvature continuous.",
    )

    # Fig. 11: kappa^m against the exact affine curvature, optimal t1 and t1 + 0.2 %
    rc = affine.replacement_curve(curve)
    pts2, t2 = affine.construct(rc, t1=res.t1 * 1.002, area=res.area, vertices=60)
    k2 = affine.curvature(pts2, rtol=1e-8)
    km2 = k2 * abs(res.area) ** (-2.0 / 3.0)
    perturbed = dataclasses.replace(res, points=pts2, t=t2, curvature=k2, kappa_m=km2)
    fig, axes = plt.subplots(2, 1, figsize=(9, 7), sharex=True)
    for ax, r, title in (
        (axes[0], res, f"optimal t1 = {res.t1:.6f} (min sum (k_(i+1) - k_i)^2)"),
        (axes[1], perturbed, f"t1 increased by 0.2 % to {res.t1 * 1.002:.6f}"),
    ):
        plot.affine_curvature(
            r, lambda u: affine.bezier_affine_curvature(control, u), samples=samples, ax=ax
        )
        ax.set_title(title)
        ax.set_xlabel("")
    axes[1].set_xlabel("Bézier parameter u at (t_(i-1) + t_i + t_(i+1) + t_(i+2)) / 4")
    ctx.figure(
        fig,
        "affine_fig11_curvature",
        "Discrete affine curvatures of the middle osculating conics against the exact affine "
        "curvature (Fig. 11): smooth at the optimal t1, oscillating after +0.2 %.",
    )

    # Table 1: deviation against the number of samples
    table = []
    for count in (200, 400, 600, 800, 1000):
        p = affine.bezier_curve(control, np.linspace(0, 1, count))
        r = affine.approximate(p, vertices=60)
        d = np.abs(r.kappa_m - affine.bezier_affine_curvature(control, _mid_params(r.t, count)))
        d /= np.abs(affine.bezier_affine_curvature(control, _mid_params(r.t, count)))
        table.append((count, float(d.max()), float(d.mean())))
    ctx.text(
        "Table 1 (60 vertices, stand-in degree-8 Bézier curve; the paper's control points are not "
        "published): relative deviation of kappa^m from the exact affine curvature.\n\n"
        "| samples | max (ours) | mean (ours) | max (paper) | mean (paper) |\n"
        "|---|---|---|---|---|\n"
        + "\n".join(
            f"| {c} | {m * 100:.3f} % | {a * 100:.3f} % | {pm} | {pa} |"
            for (c, m, a), pm, pa in zip(
                table,
                ("90 %", "14 %", "2.9 %", "1.3 %", "0.9 %"),
                ("19 %", "2.4 %", "0.7 %", "0.37 %", "0.25 %"),
                strict=True,
            )
        )
    )

    # Figs. 12/13: a curve with an inflection, two concatenated affine arc length polylines
    scurve_ctrl = data.load_points("affine_scurve6.csv")
    scurve = affine.bezier_curve(scurve_ctrl, np.linspace(0, 1, samples))
    rs = affine.approximate(scurve, vertices=50)
    fig, axes = plt.subplots(1, 2, figsize=(13, 4.8))
    ax = plot.affine_approximation(
        rs, scurve, ax=axes[0], title="Curve with an inflection, 50 vertices (Fig. 12)"
    )
    ax.lines[0].set_label("S-shaped Bézier curve")
    ax.lines[1].set_label("two affine arc length pieces")
    ax.legend(fontsize=8, loc="lower left")
    ax = plot.affine_curvature(
        rs,
        lambda u: affine.bezier_affine_curvature(scurve_ctrl, np.clip(u, 1e-3, 1 - 1e-3)),
        samples=samples,
        ax=axes[1],
    )
    ax.set_ylim(-1.5, 1.5)
    ax.set_xlabel("Bézier parameter u")
    ax.set_title("Affine curvature; values across the join omitted (Fig. 13)")
    ax.legend(fontsize=8)
    ctx.figure(
        fig,
        "affine_fig12_inflection",
        "A curve with an inflection approximated by two affine arc length polylines sharing a "
        "vertex near the inflection, and their discrete affine curvatures.",
    )

    # G2 check: Euclidean curvature of our spline vs a least-squares quadratic B-spline
    u = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(curve, axis=0), axis=1))])
    u /= u[-1]
    inner = np.linspace(0, 1, 59)[1:-1]
    lsq = make_lsq_spline(u, curve, np.r_[[0.0] * 3, inner, [1.0] * 3], k=2)
    fig, ax = plt.subplots(figsize=(9, 4))
    plot.spline_curvature(
        {
            "least-squares quadratic B-spline (C1 only)": lsq,
            "B-spline of the affine arc length polyline (G2)": res.points,
        },
        ax=ax,
    )
    ax.set_title("Curvature along the two quadratic splines with 60 control points")
    ctx.figure(
        fig,
        "affine_g2_curvature",
        "Euclidean curvature of the B-spline of the affine arc length polyline is continuous; "
        "a least-squares quadratic B-spline of the same size jumps at every knot.",
    )

    # closed convex curve (a font-outline-like 'O'): closes up with the same A across the seam
    th = np.linspace(0, 2 * np.pi, 1200, endpoint=False)
    ring = np.c_[2 * np.cos(th) + 0.15 * np.cos(2 * th), np.sin(th) + 0.1 * np.sin(2 * th)]
    rcl = affine.approximate(ring, vertices=30, closed=True)
    a_cl, _ = affine.coordinates(rcl.points, closed=True)

    left, right = affine.joint_curvatures(res.points)
    ctx.number("bezier_t1", res.t1, "optimised parameter of x_1 on the replacement curve (samples)")
    ctx.number("bezier_area", res.area, "the constant A of the 60-vertex polyline")
    ctx.number("bezier_objective", res.objective, "sum (k_(i+1) - k_i)^2 at the optimum")
    ctx.number(
        "bezier_objective_t1_plus_0.2pct",
        float(np.sum(np.diff(k2) ** 2)),
        "the same after t1 * 1.002",
    )
    ctx.number(
        "bezier_kappa_dev_max",
        float(dev.max()),
        "max relative deviation of kappa^m (Table 1: 0.009)",
    )
    ctx.number(
        "bezier_kappa_dev_mean", float(dev.mean()), "mean relative deviation (Table 1: 0.0025)"
    )
    ctx.number("bezier_seconds", seconds, "time of approximate(1000 samples, 60 vertices)")
    ctx.number(
        "bezier_g2_jump",
        float(np.max(np.abs(left - right) / np.abs(right))),
        "max relative curvature jump at the spline joints",
    )
    ctx.number("scurve_pieces", int(rs.piece_areas.size), "affine arc length pieces of the S-curve")
    ctx.number(
        "closed_closing_error",
        rcl.closing_error,
        "closed 30-gon: max(|x_n - x_0|, |x_(n+1) - x_1|)",
    )
    ctx.number(
        "closed_area_spread",
        float(np.ptp(a_cl) / abs(rcl.area)),
        "closed 30-gon: relative spread of A_i including the seam",
    )
