"""Benchmark of curvesmith.curves.fit against what a designer would use otherwise.

Outlines: smooth closed glyph contours of the fonts matplotlib ships (DejaVu
Sans and Serif ``o``, ``O``, ``0``: sampled exactly from their TrueType
quadratics) and SVG-like shapes (an ellipse, a bean with four inflections, a
cca-smoothed star with ten). For every outline and tolerance ``T`` (font units
for glyphs, 0.1 % of the diagonal for shapes):

* **ours**: ``curves.fit(points, closed=True, tolerance=T, area=exact)``;
* **lsq**: a plain least-squares fit with scipy, the periodic uniform quadratic
  B-spline on the chord-length parameter (``BSpline.design_matrix`` with wrapped
  columns, ``numpy.linalg.lstsq``), with the fewest control points whose
  deviation is within ``T`` (bisection on the count): C1, not G2;
* **cu2qu** (glyphs only): fontTools' ``curves_to_quadratic`` on the cubic
  elevation of the glyph's own contour at ``max_err = T`` — what a CFF-to-TrueType
  conversion does; it returns the designer's segments (here already quadratic).

Reported per outline: segments, G2 defect (max relative curvature jump at the
joints that are not inflections), relative area error, deviation and time, and
the ratios ours / peer. Seeded; the machine may be loaded (ratios are measured in
the same run).

Then the TrueType rounding of the glyph fits: plain rounding against
:func:`curvesmith.io.fonts.round_contour` (largest curvature jump and tangent
break as written, at 2048 and 16384 units per em, and the time of both).

Run ``python benchmarks/bench_curves.py`` (``--quick`` for fewer outlines).
"""

from __future__ import annotations

import argparse
import itertools
import os

import matplotlib
import numpy as np
from scipy.interpolate import BSpline

from _timing import median_time
from curvesmith import cca, curves
from curvesmith.io import fonts


def g2_defect(segments: np.ndarray) -> float:
    left, right = curves.joint_curvatures(segments, closed=True)
    same = np.sign(left) == np.sign(right)
    with np.errstate(divide="ignore", invalid="ignore"):
        jump = np.abs(left - right) / np.maximum(np.abs(left), np.abs(right))
    return float(np.nanmax(jump[same])) if same.any() else 0.0


def lsq_periodic(points: np.ndarray, count: int) -> np.ndarray:
    """Control polygon of the periodic uniform quadratic B-spline fitted by least squares."""
    ring = np.vstack([points, points[:1]])
    s = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(ring, axis=0).T))])
    u = s[:-1] / s[-1] * count  # parameter in [0, count)
    knots = np.arange(-2, count + 3, dtype=float)
    basis = BSpline.design_matrix(np.clip(u, 0, count - 1e-12), knots, 2).toarray()
    m = np.zeros((len(u), count))
    for j in range(basis.shape[1]):
        m[:, (j - 1) % count] += basis[:, j]  # wrap the basis functions
    ctrl, *_ = np.linalg.lstsq(m, points, rcond=None)
    # basis j has support [j - 2, j + 1): the segment on [i, i + 1) uses controls i-1, i, i+1
    return np.roll(ctrl, -1, axis=0)


def lsq_fit(points: np.ndarray, tol: float):
    """Fewest control points of the least-squares periodic spline within `tol`."""

    def dev(n):
        ctrl = lsq_periodic(points, n)
        seg = curves._uniform_segments(ctrl, True)
        return curves.bezier_deviation(seg, points, closed=True), seg

    lo, hi = 3, 8
    while dev(hi)[0] > tol:
        lo, hi = hi, 2 * hi
        if hi > 4000:
            break
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if dev(mid)[0] <= tol:
            hi = mid
        else:
            lo = mid
    return dev(hi)[1]


def cu2qu_fit(contour, tol: float) -> np.ndarray:
    from fontTools.cu2qu import curve_to_quadratic

    out = []
    for seg in contour.segments:
        q = np.asarray(seg, float)
        if len(q) == 2:
            out.append([q[0], 0.5 * (q[0] + q[1]), q[1]])
            continue
        if len(q) == 3:  # exact cubic elevation, as a CFF font would store it
            q = curves.elevate(q[None])[0]
        spline = curve_to_quadratic([tuple(p) for p in q], tol)
        pts = [np.asarray(p) for p in spline]
        offs = pts[1:-1]
        ons = [pts[0], *[0.5 * (a + b) for a, b in itertools.pairwise(offs)], pts[-1]]
        for k, c in enumerate(offs):
            out.append([ons[k], c, ons[k + 1]])
    return np.asarray(out)


def outlines(quick: bool):
    ttf = os.path.join(matplotlib.get_data_path(), "fonts", "ttf")
    names = ["DejaVuSans.ttf"] if quick else ["DejaVuSans.ttf", "DejaVuSerif.ttf"]
    for fname in names:
        font = fonts.open_font(os.path.join(ttf, fname))
        cmap = font.getBestCmap()
        for ch in "oO" if quick else "oO0":
            g = fonts.read_glyph(font, cmap[ord(ch)])
            for k, c in enumerate(g.contours):
                pts, corners = c.sample(1.0)
                if corners:
                    continue
                yield f"{fname[:-4]} {ch}[{k}]", pts, c.area(), 2.0, c
    u = np.linspace(0, 2 * np.pi, 2000, endpoint=False)
    ell = np.c_[300 * np.cos(u), 200 * np.sin(u)]
    yield "ellipse 300x200", ell, np.pi * 300 * 200, 0.001 * 721.0, None
    r = 1 + 0.35 * np.cos(2 * u)
    bean = 50 * np.c_[r * np.cos(u), 0.7 * r * np.sin(u)]
    yield "bean (4 inflections)", bean, None, 0.001 * 130, None
    if not quick:
        th = np.linspace(0, 2 * np.pi, 10, endpoint=False) + np.pi / 2
        rad = np.where(np.arange(10) % 2 == 0, 90.0, 40.0)
        star = cca.smooth(np.c_[rad * np.cos(th), rad * np.sin(th)], closed=True, iterations=5)
        yield "cca star (10 inflections)", star, None, 0.001 * 180, None


def area_of(points):
    x, y = points[:, 0], points[:, 1]
    return 0.5 * float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true")
    args = ap.parse_args()
    print("Machine shared with other jobs: times are noisy, ratios are from the same run.\n")
    head = (
        f"{'outline':<26} {'method':<6} {'segs':>5} {'G2 defect':>10} {'area err':>9} "
        f"{'dev/T':>6} {'time s':>8}"
    )
    print(head)
    ratios = []
    for label, pts, exact, tol, contour in outlines(args.quick):
        exact = area_of(pts) if exact is None else exact
        rows = {}
        t, fit = median_time(
            lambda pts=pts, tol=tol, exact=exact: curves.fit(
                pts, closed=True, tolerance=tol, area=exact
            ),
            1,
        )
        rows["ours"] = (fit.count, fit.g2_defect, abs(fit.area / exact - 1), fit.deviation / tol, t)
        t, seg = median_time(lambda pts=pts, tol=tol: lsq_fit(pts, tol), 1)
        rows["lsq"] = (
            len(seg),
            g2_defect(seg),
            abs(curves.bezier_area(seg) / exact - 1),
            curves.bezier_deviation(seg, pts, closed=True) / tol,
            t,
        )
        if contour is not None:
            t, seg = median_time(lambda c=contour, tol=tol: cu2qu_fit(c, tol), 1)
            rows["cu2qu"] = (
                len(seg),
                g2_defect(seg),
                abs(curves.bezier_area(seg) / exact - 1),
                curves.bezier_deviation(seg, pts, closed=True) / tol,
                t,
            )
        for m, (n, g2, ae, dv, t) in rows.items():
            print(f"{label:<26} {m:<6} {n:>5} {g2:>10.1e} {ae:>9.1e} {dv:>6.2f} {t:>8.3f}")
        for m in rows:
            if m != "ours":
                ratios.append(
                    (label, m, rows["ours"][0] / rows[m][0], rows["ours"][4] / rows[m][4])
                )
    print("\nratios ours / peer: segments, time")
    for label, m, rs, rt in ratios:
        print(f"  {label:<26} vs {m:<6} segments x{rs:.2f}  time x{rt:.1f}")
    rounding(args.quick)


def rounding(quick: bool) -> None:
    """TrueType rounding of the fits: plain rounding vs the search (round_contour).

    Per glyph contour and grid (output units per font unit: 1 keeps 2048 units per em,
    8 is 16384): the largest relative curvature jump at the fit's G2 joints and the
    largest tangent break at explicit smooth on-curve points, written; time of the
    search against plain rounding (the same steps: bound, measurements), same run.
    """
    from curvesmith import glyphs

    print("\nTrueType rounding (largest jump / kink in degrees; plain vs search)")
    print(
        f"{'outline':<26} {'grid':>4} {'jump plain':>10} {'search':>8} {'kink plain':>10} "
        f"{'search':>7} {'dev/T':>6} {'t search s':>10} {'x plain':>8}"
    )
    ttf = os.path.join(matplotlib.get_data_path(), "fonts", "ttf")
    cases = []
    for fname in ["DejaVuSans.ttf"] if quick else ["DejaVuSans.ttf", "DejaVuSerif.ttf"]:
        font = fonts.open_font(os.path.join(ttf, fname))
        for ch in "oS" if quick else "oSaR&":
            g = fonts.read_glyph(font, font.getBestCmap()[ord(ch)])
            for k, c in enumerate(g.contours):
                cases.append((f"{fname[:-4]} {ch}[{k}]", c))
    tol = 2.048
    for label, c in cases:
        pts, corners = c.sample(tol)
        fit = curves.fit(pts, closed=True, tolerance=tol, anchors=corners or None, area=c.area())
        for grid in (1.0, 8.0):
            res = {}
            for mode in ("plain", "search"):
                t, out = median_time(
                    lambda m=mode, g=grid, s=fit.segments, p=pts: glyphs._round(s, p, tol, g, m), 1
                )
                res[mode] = (t, *out)
            tp, _, jp, _, _, kp = res["plain"]
            ts, _, js, _, dev, ks = res["search"]
            print(
                f"{label:<26} {grid:>4g} {jp.max(initial=0):>10.2e} {js.max(initial=0):>8.2e} "
                f"{np.degrees(kp[0]):>10.3f} {np.degrees(ks[0]):>7.3f} {dev / tol:>6.2f} "
                f"{ts:>10.3f} {ts / tp:>8.1f}"
            )


if __name__ == "__main__":
    main()
