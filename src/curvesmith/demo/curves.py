"""Demo section: compact G2 Bézier curves from a smoothed polygon, with curvature combs."""

from __future__ import annotations

import numpy as np

from .. import cca, curves, data, geometry, plot

TITLE = "Curves out: fewest G2 quadratic Béziers within a tolerance, area exact"


def run(ctx) -> None:
    """Smooth the bundled lake with cca, fit G2 quadratic Béziers, draw both combs."""
    lake = data.load_points("lake.csv")
    smooth = cca.smooth(lake, closed=True, iterations=4)
    diag = float(np.hypot(*np.ptp(smooth, axis=0)))
    tol = 2e-3 * diag
    fit = curves.fit(smooth, closed=True, tolerance=tol)
    fig = plot.comb_before_after(smooth, fit, closed=True, title="Curvature comb before and after")
    ctx.figure(
        fig,
        "curves_comb",
        f"cca-smoothed lake ({len(smooth)} vertices) and its {fit.count} G2 quadratic "
        "Béziers: the comb outline is continuous at every joint away from the inflections.",
    )
    ctx.number("vertices_smoothed", len(smooth), "vertices of the cca-smoothed polygon")
    ctx.number("segments", fit.count, "quadratic Bézier segments of the fit")
    ctx.number("tolerance", tol, "requested maximal deviation (0.2 % of the diagonal)")
    ctx.number("deviation", fit.deviation, "measured maximal deviation")
    ctx.number(
        "area_error",
        abs(fit.area / geometry.signed_area(lake) - 1),
        "relative area change against the input polygon",
    )
    ctx.number("g2_defect", fit.g2_defect, "max relative curvature jump at smooth joints")
    ctx.number(
        "inflection_jump", fit.inflection_jump, "max relative jump at inflection joints (sign flip)"
    )
    ctx.text(
        f"{len(smooth)} polygon vertices become {fit.count} quadratic Bézier segments "
        f"(a TrueType contour / SVG `Q` path) within {tol:.3g}; enclosed area kept to "
        f"{abs(fit.area / geometry.signed_area(lake) - 1):.1e}; max curvature jump at the "
        f"smooth joints {fit.g2_defect:.1e}."
    )
