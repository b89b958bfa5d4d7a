"""Demo section: a glyph refitted as a curvature continuous TrueType contour, curvature combs."""

from __future__ import annotations

import os

import numpy as np

from .. import curves, glyphs, plot
from ..io import fonts

TITLE = "Curves out: fewest G2 quadratic Béziers within a tolerance, area exact"


def _quadratic(contour) -> np.ndarray:
    """A contour's segments as quadratics (lines with the midpoint as control point)."""
    out = []
    for s in contour.segments:
        q = np.asarray(s, float)
        out.append([q[0], 0.5 * (q[0] + q[1]), q[1]] if len(q) == 2 else q)
    return np.asarray(out)


def run(ctx) -> None:
    """Refit DejaVu Sans "S" (shipped with matplotlib) and draw both curvature combs."""
    import matplotlib

    path = os.path.join(matplotlib.get_data_path(), "fonts", "ttf", "DejaVuSans.ttf")
    font = fonts.open_font(path)
    name = font.getBestCmap()[ord("S")]
    tol = 2.0  # font units (1/1024 em)
    rep = glyphs.refit_glyph(font, name, tolerance=tol)
    before = _quadratic(fonts.read_glyph(font, name).contours[0])
    after = rep.segments[0]

    def jump(seg):
        left, right = curves.joint_curvatures(seg, closed=True)
        same = np.sign(left) == np.sign(right)
        j = np.abs(left - right) / np.maximum(np.abs(left), np.abs(right))
        return float(np.max(j[same & np.isfinite(j)]))

    fig, (a, b) = plot.new_axes(2, width=5.0, height=6.0)
    scale = 0.5 * 1000 / max(np.max(np.abs(curves.joint_curvatures(after, closed=True)[0])), 1e-12)
    plot.bezier_comb(
        before, closed=True, ax=a, scale=scale, color="tab:red",
        title=f"DejaVu Sans S: {len(before)} segments, curvature jumps {jump(before):.0%}",
    )  # fmt: skip
    plot.bezier_comb(
        after, closed=True, ax=b, scale=scale,
        title=f"refit: {len(after)} G2 quadratics, jumps {rep.g2_defect:.0e}",
    )  # fmt: skip
    fig.suptitle("Curvature combs at the same scale (joints: dots)")
    ctx.figure(
        fig,
        "curves_comb",
        f"DejaVu Sans 'S' as drawn ({len(before)} quadratic segments, G1: the comb steps at "
        f"the on-curve points) and refitted within {tol:g} font units by {len(after)} segments of "
        "a G2 quadratic B-spline (the comb is continuous except at the inflections).",
    )
    ctx.number("segments_before", len(before), "segments of the glyph's contour")
    ctx.number("segments_after", len(after), "G2 quadratic segments of the refit")
    ctx.number("tolerance", tol, "requested maximal deviation, font units")
    ctx.number("deviation", rep.max_deviation, "measured maximal deviation, font units")
    ctx.number("area_change", abs(rep.area_change), "relative change of the glyph's area")
    ctx.number("g2_before", jump(before), "max relative curvature jump at joints, as drawn")
    ctx.number("g2_after", rep.g2_defect, "max relative curvature jump at smooth joints, refit")
    ctx.text(
        f"The 'S' of DejaVu Sans has curvature jumps of up to {jump(before):.0%} at its "
        f"on-curve points; refitted within {tol:g} units it becomes {len(after)} quadratic "
        f"segments (a TrueType contour) with jumps below {max(rep.g2_defect, 1e-16):.0e} and "
        f"the same area to {abs(rep.area_change):.0e}."
    )
