"""Demo section: fairing by the integrable discrete elastica (like Fig. 5 of the paper)."""

from __future__ import annotations

import numpy as np

from .. import data, elastica, plot

TITLE = "Discrete elastica fairing: input, initial guess, fit"

_CASES = (
    ("elastica_wave.csv", "wave with inflections", False),
    ("elastica_loop.csv", "loops, no inflection", False),
    ("elastica_digitised.csv", "unevenly digitised (resampled)", True),
)


def run(ctx) -> None:
    """Fit the bundled noisy elasticae and draw input, initial guess and fit per curve."""
    fig, axes = plot.new_axes(len(_CASES), width=5.2, height=4.6)
    rows = []
    for ax, (name, label, resample) in zip(axes, _CASES, strict=True):
        pts = data.load_points(name)
        res = elastica.fit(pts, resample=resample)
        guess = elastica.sample(res.start, res.data.shape[0])
        plot.elastica_fit(
            res,
            markers=True,
            ax=ax,
            title=f"{label}\ncase ({res.case}), k = {res.params.k:.3f}, rms = {res.rms:.3g}",
        )
        ax.lines[1].set_label("initial guess (4.3)")
        ax.legend(fontsize="small", loc="best")
        ax.set_xlabel("x")
        ax.set_ylabel("y")
        key = name.removeprefix("elastica_").removesuffix(".csv")
        ctx.number(f"elastica_{key}_rms", res.rms, f"rms distance of the fit to {name}")
        ctx.number(f"elastica_{key}_k", res.params.k, f"fitted modulus k for {name}")
        ctx.number(f"elastica_{key}_success", res.success, f"fit of {name} converged")
        guess_rms = float(np.sqrt(np.mean(np.sum((guess - res.data) ** 2, axis=1))))
        rows.append(
            f"| `{name}` | {res.data.shape[0]} | {res.case} | "
            + " | ".join(f"{v:.4g}" for v in res.params[2:])
            + f" | {guess_rms:.3g} | {res.rms:.3g} | {res.iterations} |"
        )
    ctx.figure(
        fig,
        "elastica_fairing",
        "Fairing by the discrete elastica (cf. Fig. 5): black squares input, green triangles "
        "initial guess of section 4.3, red circles the fitted discrete elastica.",
    )
    ctx.text(
        "Fitted parameters (continued modulus k: k < 1 case (ii) with inflections, k > 1 "
        "case (i) with modulus 1/k), rms of the initial guess and of the fit:\n\n"
        "| data | N | case | h | phi | z | q | k | guess rms | fit rms | iterations |\n"
        "|---|---|---|---|---|---|---|---|---|---|---|\n" + "\n".join(rows)
    )

    # Curvature is affine in the projection u_n (Prop. 4.1) on the exact fitted curve.
    res = elastica.fit(data.load_points("elastica_wave.csv"))
    fig, (ax,) = plot.new_axes(1, width=6.0, height=4.4)
    plot.elastica_invariant(res, ax=ax)
    inv = elastica.invariants(res.params)
    ctx.figure(
        fig,
        "elastica_curvature_affine",
        "Discrete curvature against the projection u_n: on the fitted elastica the points lie "
        "on the line of Prop. 4.1; the noisy data scatter about it.",
    )
    ctx.number("elastica_alpha", inv.alpha, "alpha of eq. (3.9) for the fitted wave")
    _figure_4(ctx)
    _segments(ctx)


def _g1_pieces(pieces):
    """Exact discrete elasticae joined G1 (vertex tangent ``phi + 2 a`` of eq. 4.3 continued)."""
    import math

    from ..elastica.exact import _half_angles

    def a(s, k):
        S, C = _half_angles(np.array([s]), k)
        return math.atan2(S[0], C[0])

    out, joints, pos, theta = [], [], (0.0, 0.0), None
    for h, z, q, k, n in pieces:
        phi = 0.0 if theta is None else theta - 2 * a(q, k)
        pts = elastica.sample((*pos, h, phi, z, q, k), n)
        if out:
            joints.append(pts[0])
        out.append(pts if not out else pts[1:])
        pos, theta = tuple(pts[-1]), phi + 2 * a(z * (n - 1) + q, k)
    return np.vstack(out), np.array(joints)


def _segments(ctx) -> None:
    """Multi-segment fairing to a tolerance: three G1 pieces, 0.02 mm noise, T = 0.08 mm."""
    pieces = [(2.0, 0.012, 0.3, 0.7, 300), (2.0, 0.006, -0.5, 2.5, 251), (2.0, 0.01, 1.0, 0.5, 251)]
    clean, true_joints = _g1_pieces(pieces)
    pts = clean + np.random.default_rng(2).normal(scale=0.02, size=clean.shape)
    tol = 0.08
    res = elastica.fit_segments(pts, tol)
    fig, (ax0, ax1) = plot.new_axes(2, width=6.0, height=4.6)
    plot.elastica_segments(
        res,
        pts,
        reference_joints=true_joints,
        ax=ax0,
        title=f"{len(res.segments)} discrete elastica segments\nwithin T = {tol:g} mm",
    )
    ax0.lines[0].set_label("input (0.02 mm noise)")
    ax0.set_xlabel("x (mm)")
    ax0.set_ylabel("y (mm)")
    ax0.legend(fontsize="small")
    plot.segments_deviation(res, pts, ax=ax1)
    ax1.set_ylabel("deviation from the chain (mm)")
    found = np.array([res.points[j.vertex] for j in res.joints])
    ctx.figure(
        fig,
        "elastica_segments",
        "Multi-segment fairing to a tolerance (elastica.fit_segments, fair --tolerance T "
        "--max-segments M): three exact discrete elasticae joined G1 with 0.02 mm noise, "
        "faired to T = 0.08 mm by the fewest G1-joined elastica segments; right, the distance "
        "of every input point to the chain along the curve, joints dotted.",
    )
    ctx.number("elastica_segments_count", len(res.segments), "segments for T = 0.08 mm")
    ctx.number("elastica_segments_max_deviation", res.max_deviation, "max deviation (mm)")
    ctx.number(
        "elastica_segments_joint_error",
        float(np.hypot(*(found - true_joints).T).max()) if len(found) == len(true_joints) else -1,
        "largest distance of a fitted joint from the true one (mm; -1: other count)",
    )
    ctx.number(
        "elastica_segments_g1_defect", max(j.g1_defect for j in res.joints), "rad, by construction"
    )


def _figure_4(ctx) -> None:
    """Typical discrete elasticae as in Fig. 4: case (ii), case (i), the figure eight."""
    from scipy.optimize import brentq
    from scipy.special import ellipk

    per_period = 15

    def drift(k):
        z = 4 * ellipk(k * k) / per_period
        pts = elastica.sample((0.0, 0.0, 1.0, 0.0, z, 0.0, k), per_period + 1)
        return pts[-1, 0] - pts[0, 0]

    k8 = brentq(drift, 0.85, 0.999, xtol=1e-14)
    curves = [
        ("(ii) k = 0.8", (0.0, 0.0, 1.0, 0.0, 4 * ellipk(0.64) / 24, 0.0, 0.8), 73),
        # case (i) with modulus 0.909 is the continued modulus 1/0.909
        ("(i) k = 0.909", (0.0, 0.0, 1.0, 0.0, 0.12, 0.0, 1 / 0.909), 60),
        (
            f"(ii) figure eight, k = {k8:.4f}",
            (0.0, 0.0, 1.0, 0.0, 4 * ellipk(k8 * k8) / 15, 0.0, k8),
            16,
        ),
    ]
    fig, axes = plot.new_axes(3, width=4.6, height=4.2)
    for ax, (label, p, n) in zip(axes, curves, strict=True):
        pts = elastica.sample(p, n)
        plot.draw_curve(ax, pts, closed=False, markers=True, color="tab:blue", lw=1)
        ax.set_title(label)
        ax.set_xlabel("x")
        ax.set_ylabel("y")
        ax.set_aspect("equal", adjustable="datalim")
    ctx.figure(
        fig,
        "elastica_figure4",
        "Discrete elasticae as in Fig. 4: with inflections (k < 1), without (case (i)), and "
        "the closed figure eight, whose discrete modulus with 15 vertices per period is "
        f"{k8:.4f} (paper: 0.919...; the smooth figure eight has 0.9089).",
    )
    ctx.number("elastica_figure_eight_k", k8, "closing modulus, 15 vertices per period")
