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
        ax.plot(*res.data.T, "s", color="black", ms=3.5, mfc="none", label="input")
        ax.plot(*guess.T, "^", color="tab:green", ms=3.5, mfc="none", label="initial guess (4.3)")
        ax.plot(*res.points.T, "o", color="tab:red", ms=2.5, label="discrete elastica (fit)")
        ax.set_title(f"{label}\ncase ({res.case}), k = {res.params.k:.3f}, rms = {res.rms:.3g}")
        ax.set_xlabel("x")
        ax.set_ylabel("y")
        ax.set_aspect("equal", adjustable="datalim")
        ax.legend(fontsize="small", loc="best")
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
    p = res.params
    kappa = elastica.curvature(res.points)
    u = res.points[1:-1] @ np.array([np.sin(p.phi), -np.cos(p.phi)])
    kappa_data = elastica.curvature(res.data, rtol=1.0)
    fig, (ax,) = plot.new_axes(1, width=6.0, height=4.4)
    ax.plot(u, kappa_data, ".", color="0.6", label="data (noisy discrete curvature)")
    ax.plot(u, kappa, "o", color="tab:red", ms=3, label="fitted elastica")
    inv = elastica.invariants(p)
    line = np.linspace(u.min(), u.max(), 2)
    A = float(np.mean(kappa - inv.mu / inv.Lambda * u))
    ax.plot(line, inv.mu / inv.Lambda * line + A, "k--", lw=1, label="(mu / Lambda) u + A")
    ax.set_xlabel("u_n = <I, gamma_n>  (eq. 4.14)")
    ax.set_ylabel("discrete curvature kappa_n  (eq. 4.33)")
    ax.set_title("Prop. 4.1: kappa_n is affine in u_n on a discrete elastica")
    ax.legend(fontsize="small")
    ctx.figure(
        fig,
        "elastica_curvature_affine",
        "Discrete curvature against the projection u_n: on the fitted elastica the points lie "
        "on the line of Prop. 4.1; the noisy data scatter about it.",
    )
    ctx.number("elastica_alpha", inv.alpha, "alpha of eq. (3.9) for the fitted wave")
