"""Glyph outlines in and out of fonts with fontTools: TrueType, OpenType-CFF and UFO.

Reading gives every contour of a glyph as a chain of Bézier segments (lines,
quadratics with their implied on-curve points resolved, cubics), components
decomposed. Writing builds a TrueType font (``glyf``) from quadratic contours:
glyph order, names (``post`` format 2), character map, advance widths,
vertical metrics, names and the layout tables (``GSUB``, ``GPOS``, ``GDEF``,
``kern``) are copied from the source; hinting is dropped (no ``fpgm``,
``prep``, ``cvt``, no glyph instructions), and left side bearings follow the
new outlines. TrueType coordinates are integers: control points are rounded
(``round``), which is the only loss.

This is not a curve format of :mod:`curvesmith.io` (a font holds glyphs,
metrics and tables, not features of curves).
"""

from __future__ import annotations

import copy
import math
import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import CurveError, CurveFormatError

__all__ = [
    "Contour",
    "GlyphOutline",
    "font_glyph_names",
    "open_font",
    "read_glyph",
    "resolve_glyphs",
    "write_truetype",
]


@dataclass(frozen=True)
class Contour:
    """One closed contour: Bézier segments in drawing order.

    Attributes
    ----------
    segments : tuple of (k + 1, 2) ndarray
        Segment ``i`` has degree ``k`` (1 line, 2 quadratic, 3 cubic) and starts where
        segment ``i - 1`` ends; the last ends at the first point.
    """

    segments: tuple

    @property
    def count(self) -> int:
        """Number of segments."""
        return len(self.segments)

    def sample(self, spacing: float, corner_angle: float = math.radians(5.0)):
        """Dense points along the contour and the indices of its corners.

        Parameters
        ----------
        spacing : float
            Largest distance between consecutive points (font units).
        corner_angle : float, optional
            A joint whose tangent turns by more than this (radians) is a corner.
            Both ends of every line segment are corners too (a straight piece
            has no affine arc length and stays a line).

        Returns
        -------
        points : (N, 2) ndarray
            Closed polyline (first point not repeated), consecutive points distinct.
        corners : list of int
            Indices into `points`.
        """
        pts, corners = [], []
        n = len(self.segments)
        for i, seg in enumerate(self.segments):
            prev = self.segments[i - 1]
            t_in = _end_tangent(prev)
            t_out = _start_tangent(seg)
            turn = _angle(t_in, t_out)
            if len(seg) == 2 or len(prev) == 2 or turn > corner_angle:
                corners.append(len(pts))
            length = float(np.sum(np.hypot(*np.diff(seg, axis=0).T)))
            k = max(4 if len(seg) > 2 else 1, math.ceil(length / spacing))
            t = np.arange(k) / k
            pts.extend(_bezier(seg, t))
        p = np.asarray(pts, dtype=float)
        keep = np.ones(len(p), dtype=bool)
        keep[1:] = np.any(np.abs(np.diff(p, axis=0)) > 0, axis=1)
        if len(p) > 1 and np.array_equal(p[0], p[-1]):
            keep[-1] = False
        index = np.cumsum(keep) - 1
        corners = sorted({int(index[c]) for c in corners})
        del n
        return p[keep], corners

    def area(self) -> float:
        """Signed area enclosed (exact; positive counter-clockwise in y-up font units)."""
        total = 0.0
        for seg in self.segments:
            q = np.asarray(seg, dtype=float)
            d = len(q) - 1
            # 1/2 int det(B, B') dt, exact for degree <= 3 by Gauss-Legendre with 3 nodes
            x, w = np.polynomial.legendre.leggauss(3)
            t = 0.5 * (x + 1)
            b = _bezier(q, t)
            db = d * _bezier(np.diff(q, axis=0), t) if d > 1 else np.repeat(q[1:] - q[:1], 3, 0)
            total += 0.25 * float(np.sum(w * (b[:, 0] * db[:, 1] - b[:, 1] * db[:, 0])))
        return total


@dataclass(frozen=True)
class GlyphOutline:
    """A glyph's contours (components decomposed) and its advance width."""

    name: str
    advance: int
    contours: tuple


def _bezier(q, t) -> np.ndarray:
    q = np.asarray(q, dtype=float)
    d = len(q) - 1
    t = np.asarray(t, dtype=float)[:, None]
    return sum(math.comb(d, i) * t**i * (1 - t) ** (d - i) * q[i] for i in range(d + 1))


def _start_tangent(seg) -> np.ndarray:
    q = np.asarray(seg, dtype=float)
    for j in range(1, len(q)):
        if np.any(q[j] != q[0]):
            return q[j] - q[0]
    return np.zeros(2)


def _end_tangent(seg) -> np.ndarray:
    q = np.asarray(seg, dtype=float)[::-1]
    return -_start_tangent(q)


def _angle(u, v) -> float:
    nu, nv = math.hypot(*u), math.hypot(*v)
    if nu == 0 or nv == 0:
        return math.pi
    c = max(-1.0, min(1.0, float(np.dot(u, v)) / (nu * nv)))
    return math.acos(c)


def open_font(path):
    """Open a TrueType / OpenType-CFF font file or a UFO directory.

    Parameters
    ----------
    path : str or os.PathLike

    Returns
    -------
    fontTools.ttLib.TTFont or _UFO
        The font; for a UFO a small reader with the same ``getGlyphOrder`` /
        ``getGlyphSet`` / ``getBestCmap`` interface.

    Raises
    ------
    CurveFormatError
        If the file is not a font fontTools can read.
    """
    path = Path(path)
    if path.is_dir():
        return _UFO(path)
    from fontTools.ttLib import TTFont, TTLibError

    try:
        font = TTFont(os.fspath(path), lazy=False)
    except (TTLibError, OSError, AssertionError) as exc:
        if isinstance(exc, FileNotFoundError):
            raise
        raise CurveFormatError(f"{path}: not a TrueType/OpenType font ({exc})") from None
    if "glyf" not in font and "CFF " not in font:
        raise CurveFormatError(f"{path}: the font has no glyf or CFF outlines")
    return font


class _UFO:
    """Minimal UFO source reader (fontTools.ufoLib): glyph order, cmap, glyph set."""

    def __init__(self, path: Path):
        from fontTools.ufoLib import UFOLibError, UFOReader

        try:
            self.reader = UFOReader(os.fspath(path), validate=False)
            self.glyphset = self.reader.getGlyphSet()
        except (UFOLibError, OSError) as exc:
            raise CurveFormatError(f"{path}: not a UFO font source ({exc})") from None
        order = self.reader.readLib().get("public.glyphOrder")
        names = list(self.glyphset.keys())
        self.order = [n for n in order if n in self.glyphset] if order else sorted(names)
        self.order += [n for n in names if n not in set(self.order)]
        self.info = type("Info", (), {})()
        self.reader.readInfo(self.info)

    def getGlyphOrder(self):
        return list(self.order)

    def getBestCmap(self):
        cmap = {}
        for name in self.order:
            g = self._glyph(name)
            for u in getattr(g, "unicodes", []) or []:
                cmap.setdefault(u, name)
        return cmap

    def _glyph(self, name):
        class G:
            pass

        g = G()
        self.glyphset.readGlyph(name, g)
        return g

    def advance(self, name) -> int:
        return round(getattr(self._glyph(name), "width", 0) or 0)

    def draw(self, name, pen):
        from fontTools.pens.pointPen import PointToSegmentPen

        class G:
            pass

        g = G()
        self.glyphset.readGlyph(name, g, PointToSegmentPen(pen))

    @property
    def units_per_em(self) -> int:
        return int(getattr(self.info, "unitsPerEm", 1000) or 1000)


def font_glyph_names(font) -> list[str]:
    """Glyph names in glyph order."""
    return list(font.getGlyphOrder())


def resolve_glyphs(font, spec: str | None) -> list[str]:
    """Glyph names for ``"a,g,S"`` (characters or glyph names); all glyphs for None.

    Raises
    ------
    CurveError
        Naming the first entry that is neither a glyph name nor a mapped character.
    """
    names = font_glyph_names(font)
    if spec is None:
        return names
    have = set(names)
    cmap = font.getBestCmap() or {}
    out = []
    for item in (s.strip() for s in spec.split(",")):
        if not item:
            continue
        if item in have:
            out.append(item)
        elif len(item) == 1 and ord(item) in cmap:
            out.append(cmap[ord(item)])
        else:
            raise CurveError(
                f"--glyphs: {item!r} is neither a glyph name nor a character of the font"
            )
    return list(dict.fromkeys(out))


def read_glyph(font, name: str) -> GlyphOutline:
    """The contours of a glyph as Bézier segments (components decomposed).

    Parameters
    ----------
    font : TTFont or UFO reader from :func:`open_font`
    name : str

    Returns
    -------
    GlyphOutline
    """
    from fontTools.pens.basePen import decomposeQuadraticSegment, decomposeSuperBezierSegment
    from fontTools.pens.recordingPen import DecomposingRecordingPen, RecordingPen

    if isinstance(font, _UFO):
        pen = RecordingPen()
        font.draw(name, pen)
        advance = font.advance(name)
        ops = _decompose_ufo(font, pen.value)
    else:
        gs = font.getGlyphSet()
        pen = DecomposingRecordingPen(gs)
        gs[name].draw(pen)
        advance = int(font["hmtx"][name][0])
        ops = pen.value
    contours = []
    cur = None
    segs: list = []
    for op, args in ops:
        if op == "moveTo":
            cur = np.asarray(args[0], float)
            start = cur
            segs = []
        elif op == "lineTo":
            p = np.asarray(args[0], float)
            segs.append(np.array([cur, p]))
            cur = p
        elif op == "qCurveTo":
            pts = list(args)
            if pts[-1] is None:  # a contour of off-curve points only
                pts = pts[:-1]
                mid = 0.5 * (np.asarray(pts[-1], float) + np.asarray(pts[0], float))
                cur = start = mid
                pts = [*pts, tuple(mid)]
            for c, e in decomposeQuadraticSegment(pts):
                segs.append(np.array([cur, c, e], float))
                cur = np.asarray(e, float)
        elif op == "curveTo":
            for c1, c2, e in decomposeSuperBezierSegment(list(args)):
                segs.append(np.array([cur, c1, c2, e], float))
                cur = np.asarray(e, float)
        elif op in ("closePath", "endPath"):
            if segs and np.any(cur != start):
                segs.append(np.array([cur, start]))
            segs = [s for s in segs if np.any(s != s[0])]  # zero-length segments
            if segs:
                contours.append(Contour(tuple(segs)))
            segs = []
        elif op == "addComponent":  # pragma: no cover - decomposed above
            raise CurveError(f"glyph {name}: unexpected component")
    return GlyphOutline(name=name, advance=advance, contours=tuple(contours))


def _decompose_ufo(font: _UFO, ops):
    """Replace UFO components by the transformed outlines of their base glyphs."""
    from fontTools.pens.recordingPen import RecordingPen
    from fontTools.pens.transformPen import TransformPen

    out = []
    for op, args in ops:
        if op != "addComponent":
            out.append((op, args))
            continue
        base, transform = args
        rec = RecordingPen()
        tp = TransformPen(rec, transform)
        inner = RecordingPen()
        font.draw(base, inner)
        RecordingPen.replay(type("R", (), {"value": _decompose_ufo(font, inner.value)})(), tp)
        out.extend(rec.value)
    return out


def write_truetype(source, glyphs: dict, path, *, keep=None) -> None:
    """Write a TrueType font: the source with some glyphs' contours replaced.

    Parameters
    ----------
    source : TTFont or UFO reader
        From :func:`open_font`; glyph order, cmap, metrics, names and layout tables
        are taken from it.
    glyphs : dict of str to list of (S, 3, 2) ndarray
        New quadratic contours (closed) per glyph name; other glyphs keep their
        outlines (cubic outlines converted with fontTools' cu2qu at 1/1000 em).
    path : str or os.PathLike
        Output ``.ttf``; written to a temporary file and renamed.
    keep : ignored
        Reserved.

    Raises
    ------
    CurveError
        If a coordinate does not fit TrueType's 16-bit range.
    """
    from fontTools.fontBuilder import FontBuilder
    from fontTools.pens.cu2quPen import Cu2QuPen
    from fontTools.pens.recordingPen import DecomposingRecordingPen
    from fontTools.pens.ttGlyphPen import TTGlyphPen
    from fontTools.ttLib.tables import ttProgram

    order = font_glyph_names(source)
    is_ufo = isinstance(source, _UFO)
    upm = source.units_per_em if is_ufo else int(source["head"].unitsPerEm)
    fb = FontBuilder(upm, isTTF=True)
    fb.setupGlyphOrder(order)
    fb.setupCharacterMap(source.getBestCmap() or {})
    glyf = {}
    for name in order:
        pen = TTGlyphPen(None)
        if name in glyphs:
            for seg in glyphs[name]:
                _draw_quadratic_contour(pen, np.asarray(seg, float))
        elif not is_ufo and "glyf" in source:
            # an unchanged TrueType glyph (simple or composite) without its instructions
            g = copy.deepcopy(source["glyf"][name])
            if hasattr(g, "program"):
                g.program = ttProgram.Program()
                g.program.fromBytecode(b"")
            glyf[name] = g
            continue
        else:
            cu = Cu2QuPen(pen, max_err=upm / 1000.0, reverse_direction=False)
            if is_ufo:
                rec = DecomposingRecordingPen({})
                source.draw(name, rec)
                for op, args in _decompose_ufo(source, rec.value):
                    getattr(cu, op)(*args)
            else:
                gs = source.getGlyphSet()
                rec = DecomposingRecordingPen(gs)
                gs[name].draw(rec)
                rec.replay(cu)
        g = pen.glyph()
        coords = getattr(g, "coordinates", None)
        if coords is not None and len(coords):
            arr = np.asarray(coords)
            if np.abs(arr).max() > 32767:
                raise CurveError(f"glyph {name}: coordinates exceed TrueType's 16-bit range")
        glyf[name] = g
    fb.setupGlyf(glyf)
    metrics = {}
    for name in order:
        adv = source.advance(name) if is_ufo else int(source["hmtx"][name][0])
        g = fb.font["glyf"][name]
        metrics[name] = (adv, int(getattr(g, "xMin", 0)) if g.numberOfContours else 0)
    fb.setupHorizontalMetrics(metrics)
    if is_ufo:
        info = source.info
        asc = int(getattr(info, "ascender", 0.8 * upm) or 0.8 * upm)
        desc = int(getattr(info, "descender", -0.2 * upm) or -0.2 * upm)
        fb.setupHorizontalHeader(ascent=asc, descent=desc)
        fb.setupNameTable(
            {
                "familyName": getattr(info, "familyName", None) or "curvesmith",
                "styleName": getattr(info, "styleName", None) or "Regular",
            }
        )
        fb.setupOS2(sTypoAscender=asc, sTypoDescender=desc, usWinAscent=asc, usWinDescent=-desc)
        fb.setupPost(keepGlyphNames=True)
    else:
        hhea = source["hhea"]
        fb.setupHorizontalHeader(ascent=hhea.ascent, descent=hhea.descent, lineGap=hhea.lineGap)
        fb.font["name"] = source["name"]
        os2 = source["OS/2"]
        fb.setupOS2()
        for attr in (
            "sTypoAscender",
            "sTypoDescender",
            "sTypoLineGap",
            "usWinAscent",
            "usWinDescent",
            "usWeightClass",
            "usWidthClass",
            "fsType",
            "fsSelection",
            "sxHeight",
            "sCapHeight",
            "panose",
            "achVendID",
        ):
            if hasattr(os2, attr):
                setattr(fb.font["OS/2"], attr, getattr(os2, attr))
        post = source["post"]
        fb.setupPost(
            keepGlyphNames=True,
            italicAngle=post.italicAngle,
            underlinePosition=post.underlinePosition,
            underlineThickness=post.underlineThickness,
            isFixedPitch=post.isFixedPitch,
        )
        for tag in ("GDEF", "GSUB", "GPOS", "kern"):
            if tag in source:
                fb.font[tag] = source[tag]
        fb.font["head"].macStyle = source["head"].macStyle
    out = Path(path)
    tmp = out.with_name(out.name + ".part")
    try:
        fb.save(os.fspath(tmp))
        os.replace(tmp, out)
    finally:
        if tmp.exists():
            tmp.unlink()


def _pt(p) -> tuple[float, float]:
    return (float(p[0]), float(p[1]))


def _draw_quadratic_contour(pen, seg: np.ndarray) -> None:
    """Draw closed quadratic segments; joints at control midpoints become implied points.

    A straight segment (control at the chord's midpoint) is a line. A run of
    segments whose joints are the midpoints of neighbouring controls is one
    ``qCurveTo`` with only off-curve points (TrueType's implied on-curve points).
    """
    n = len(seg)
    scale = max(1.0, float(np.max(np.abs(seg))))
    tol = 1e-9 * scale

    def straight(s):
        return np.max(np.abs(s[1] - 0.5 * (s[0] + s[2]))) <= tol

    def implied(k):  # joint at the end of segment k
        a, b = seg[k], seg[(k + 1) % n]
        if straight(a) or straight(b):
            return False
        return np.max(np.abs(a[2] - 0.5 * (a[1] + b[1]))) <= tol

    explicit = [k for k in range(n) if not implied(k)]
    if not explicit:  # every on-curve point implied: an all-off-curve contour
        pen.qCurveTo(*[_pt(s[1]) for s in seg], None)
        pen.closePath()
        return
    first = (explicit[0] + 1) % n  # start at an explicit on-curve point
    pen.moveTo(_pt(seg[first][0]))
    run: list = []
    for i in range(n):
        k = (first + i) % n
        s = seg[k]
        if straight(s):
            pen.lineTo(_pt(s[2]))
            continue
        run.append(_pt(s[1]))
        if not implied(k):
            pen.qCurveTo(*run, _pt(s[2]))
            run = []
    pen.closePath()


def write_ufo(source, glyphs: dict, path) -> None:
    """Write a UFO 3 source: the source's glyphs with some contours replaced, floats kept.

    UFO coordinates are not rounded, so the refitted contours stay exactly G2 at
    their implied on-curve points (TrueType output rounds them to integers).
    Glyph order, names, advance widths, unicodes, units per em, family / style
    names and vertical metrics are kept; components are decomposed; no hinting.

    Parameters
    ----------
    source : TTFont or UFO reader
        From :func:`open_font`.
    glyphs : dict of str to list of (S, 3, 2) ndarray
        New quadratic contours (closed) per glyph name.
    path : str or os.PathLike
        Output ``.ufo`` directory; must not exist (written to a temporary
        directory and renamed).
    """
    import shutil

    from fontTools.pens.pointPen import SegmentToPointPen
    from fontTools.pens.recordingPen import DecomposingRecordingPen
    from fontTools.ufoLib import UFOWriter

    out = Path(path)
    if out.exists():
        raise CurveError(f"{out} exists: a UFO is a directory, remove it first")
    tmp = out.with_name(out.name + ".part")
    if tmp.exists():
        shutil.rmtree(tmp)
    is_ufo = isinstance(source, _UFO)
    order = font_glyph_names(source)
    unicodes: dict[str, list[int]] = {}
    for u, n in sorted((source.getBestCmap() or {}).items()):
        unicodes.setdefault(n, []).append(u)
    try:
        writer = UFOWriter(os.fspath(tmp))
        gset = writer.getGlyphSet()

        class _Glyph:
            pass

        for name in order:
            g = _Glyph()
            g.width = source.advance(name) if is_ufo else int(source["hmtx"][name][0])
            g.unicodes = unicodes.get(name, [])

            def draw(point_pen, name=name):
                pen = SegmentToPointPen(point_pen)
                if name in glyphs:
                    for seg in glyphs[name]:
                        _draw_quadratic_contour(pen, np.asarray(seg, float))
                    return
                if is_ufo:
                    rec = DecomposingRecordingPen({})
                    source.draw(name, rec)
                    ops = _decompose_ufo(source, rec.value)
                else:
                    gs = source.getGlyphSet()
                    rec = DecomposingRecordingPen(gs)
                    gs[name].draw(rec)
                    ops = rec.value
                for op, args in ops:
                    getattr(pen, op)(*args)

            gset.writeGlyph(name, g, draw)
        gset.writeContents()
        writer.writeLayerContents()
        info = _Glyph()
        if is_ufo:
            for attr in ("unitsPerEm", "familyName", "styleName", "ascender", "descender"):
                if getattr(source.info, attr, None) is not None:
                    setattr(info, attr, getattr(source.info, attr))
        else:
            names = source["name"]
            info.unitsPerEm = int(source["head"].unitsPerEm)
            info.familyName = names.getDebugName(1) or "curvesmith"
            info.styleName = names.getDebugName(2) or "Regular"
            info.ascender = int(source["hhea"].ascent)
            info.descender = int(source["hhea"].descent)
        writer.writeInfo(info)
        writer.writeLib({"public.glyphOrder": order})
        os.replace(tmp, out)
    finally:
        if tmp.exists():
            shutil.rmtree(tmp)


__all__ += ["write_ufo"]
