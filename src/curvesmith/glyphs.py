"""Refit font glyphs as curvature continuous TrueType contours (:func:`curvesmith.curves.fit`).

Every contour of a glyph is sampled exactly (lines, quadratics, cubics), its
corners found (tangent turning more than 5 degrees, and both ends of every
line), optionally smoothed with area-preserving cca (corners anchored), and
refitted by the fewest quadratic Bézier segments of a G2 quadratic B-spline
within a tolerance (font units). Lines stay lines; corners stay corners. The
result is written as a TrueType font by :func:`curvesmith.io.fonts.write_truetype`
(runs of segments whose joints are control midpoints become TrueType's implied
on-curve points).

TrueType coordinates are integers: the control points are rounded, so the
written contours are G2 up to that rounding; :class:`GlyphReport` gives the
curvature jumps measured on the written, rounded outline as well as on the
exact fit.

Examples
--------
>>> import os, matplotlib
>>> from curvesmith import glyphs
>>> from curvesmith.io import fonts
>>> path = os.path.join(matplotlib.get_data_path(), "fonts", "ttf", "DejaVuSans.ttf")
>>> font = fonts.open_font(path)
>>> rep = glyphs.refit_glyph(font, "o", tolerance=2.0)
>>> rep.contours, bool(rep.max_deviation <= 2.0), bool(rep.g2_defect < 1e-6)
(2, True, True)
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from . import curves
from .errors import CurveError

__all__ = ["GlyphReport", "refit_font", "refit_glyph"]


@dataclass(frozen=True)
class GlyphReport:
    """What :func:`refit_glyph` did to one glyph.

    Attributes
    ----------
    name : str
    contours : int
    segments_before, segments_after : int
        Bézier segments (lines included) of the source and of the fit.
    area_before, area_after : float
        Signed area of all contours (font units squared), exact, before rounding.
    max_deviation : float
        Largest distance of a fitted contour from the source outline (font units).
    g2_defect : float
        Largest relative curvature jump at smooth joints of the exact fit (0 for G2).
    segments : tuple of (S, 3, 2) ndarray
        The fitted quadratic contours (empty when the glyph was not refitted).
    message : str
    refitted : bool
        False when no G2 fit within the tolerance was found: :func:`refit_font` then
        writes the glyph as it was, and `message` says why.
    """

    name: str
    contours: int
    segments_before: int
    segments_after: int
    area_before: float
    area_after: float
    max_deviation: float
    g2_defect: float
    segments: tuple
    message: str
    refitted: bool = True

    @property
    def area_change(self) -> float:
        """Relative change of the glyph's area."""
        return (
            (self.area_after - self.area_before) / abs(self.area_before)
            if self.area_before
            else 0.0
        )

    def row(self) -> dict:
        """The report as a JSON-able dict."""
        return {
            "glyph": self.name,
            "contours": self.contours,
            "segments_before": self.segments_before,
            "segments_after": self.segments_after,
            "area_change": self.area_change,
            "max_deviation": self.max_deviation,
            "g2_defect": self.g2_defect if self.refitted else None,
            "refitted": self.refitted,
            "message": self.message,
        }


def refit_glyph(
    font, name: str, *, tolerance: float, iterations: int = 0, spacing: float | None = None
):
    """Refit the contours of one glyph.

    Parameters
    ----------
    font : from :func:`curvesmith.io.fonts.open_font`
    name : str
        Glyph name.
    tolerance : float
        Largest deviation from the source outline, font units, ``> 0``.
    iterations : int, optional
        cca smoothing steps on the sampled contour before fitting (corners anchored);
        0 refits the outline as it is.
    spacing : float, optional
        Sample spacing along the outline; default ``tolerance``, at most 1/200 em.

    Returns
    -------
    GlyphReport

    Raises
    ------
    CurveError
        If a contour cannot be fitted within the tolerance.
    """
    from . import cca
    from .io.fonts import read_glyph

    if not tolerance > 0:
        raise CurveError(f"tolerance must be > 0, got {tolerance}")
    outline = read_glyph(font, name)
    upm = font.units_per_em if hasattr(font, "units_per_em") else int(font["head"].unitsPerEm)
    step = spacing if spacing is not None else min(float(tolerance), upm / 200.0)
    fitted, before, after, devs, g2 = [], 0, 0, [], []
    area0 = area1 = 0.0
    for k, contour in enumerate(outline.contours):
        pts, corners = contour.sample(step)
        exact = contour.area()
        area0 += exact
        before += contour.count
        if len(pts) < 8:
            raise CurveError(f"glyph {name}, contour {k}: too small to refit ({len(pts)} points)")
        target = pts
        anchors = corners
        if iterations:
            target = cca.smooth(pts, closed=True, iterations=iterations, anchors=corners or None)
            anchors = [
                int(np.flatnonzero(np.all(target == pts[c], axis=1))[0])
                for c in corners
                if np.any(np.all(target == pts[c], axis=1))
            ]
        fit = curves.fit(
            target, closed=True, tolerance=tolerance, anchors=anchors or None, area=exact
        )
        if not fit.success:
            raise CurveError(f"glyph {name}, contour {k}: {fit.message}")
        # deviation from the source outline (the fit is within tolerance of the target)
        devs.append(curves.bezier_deviation(fit.segments, pts, closed=True))
        g2.append(fit.g2_defect)
        area1 += fit.area
        after += fit.count
        fitted.append(fit.segments)
    return GlyphReport(
        name=name,
        contours=len(outline.contours),
        segments_before=before,
        segments_after=after,
        area_before=area0,
        area_after=area1,
        max_deviation=max(devs, default=0.0),
        g2_defect=max(g2, default=0.0),
        segments=tuple(fitted),
        message=f"{name}: {before} -> {after} segments",
    )


def refit_font(
    source,
    dest,
    *,
    glyphs: str | None = None,
    tolerance: float = 1.0,
    iterations: int = 0,
    progress=None,
):
    """Refit glyphs of a font file and write a TrueType font.

    Parameters
    ----------
    source : str or os.PathLike
        TrueType / OpenType-CFF font or UFO directory.
    dest : str or os.PathLike
        Output ``.ttf`` (integer coordinates: G2 up to their rounding) or ``.ufo``
        (floats: exactly G2).
    glyphs : str, optional
        ``"a,g,S"``: characters or glyph names; all glyphs with contours when None.
    tolerance : float, optional
        Font units.
    iterations : int, optional
        cca steps before fitting.
    progress : callable, optional
        Called with each :class:`GlyphReport`.

    Returns
    -------
    list of GlyphReport
        One per glyph; a glyph that has no G2 fit within the tolerance (``refitted``
        false, the reason in ``message``) is written as it was, so one hard glyph does not
        cost the whole font.
    """
    from .io.fonts import open_font, resolve_glyphs, write_truetype

    font = open_font(source)
    names = resolve_glyphs(font, glyphs)
    reports, new = [], {}
    from .io.fonts import read_glyph

    for name in names:
        if glyphs is None and not read_glyph(font, name).contours:
            continue
        try:
            rep = refit_glyph(font, name, tolerance=tolerance, iterations=iterations)
        except CurveError as exc:
            outline = read_glyph(font, name)
            count = sum(c.count for c in outline.contours)
            area = sum(c.area() for c in outline.contours)
            rep = GlyphReport(
                name=name,
                contours=len(outline.contours),
                segments_before=count,
                segments_after=count,
                area_before=area,
                area_after=area,
                max_deviation=0.0,
                g2_defect=math.nan,
                segments=(),
                message=f"kept as it was: {exc}",
                refitted=False,
            )
        reports.append(rep)
        if rep.refitted:
            new[name] = list(rep.segments)
        if progress is not None:
            progress(rep)
    if str(dest).lower().rstrip("/").endswith(".ufo"):
        from .io.fonts import write_ufo

        write_ufo(font, new, dest)
    else:
        write_truetype(font, new, dest)
    return reports


def written_g2_defect(font, name: str) -> float:
    """Largest relative curvature jump at implied on-curve points of a written glyph."""
    from .io.fonts import read_glyph

    worst = 0.0
    for contour in read_glyph(font, name).contours:
        seg = np.array([s for s in contour.segments if len(s) == 3])
        if len(seg) < 2:
            continue
        left, right = curves.joint_curvatures(seg, closed=False)
        ends, starts = seg[:-1, 2], seg[1:, 0]
        # implied points only: joints that are control midpoints and where segments meet
        mid = 0.5 * (seg[:-1, 1] + seg[1:, 1])
        ok = np.all(np.abs(ends - starts) < 1e-9, axis=1) & np.all(
            np.abs(ends - mid) < 1e-6, axis=1
        )
        same = np.sign(left) == np.sign(right)
        ok &= same
        if ok.any():
            with np.errstate(divide="ignore", invalid="ignore"):
                j = np.abs(left - right) / np.maximum(np.abs(left), np.abs(right))
            worst = max(worst, float(np.nanmax(j[ok])))
    return worst if math.isfinite(worst) else math.inf
