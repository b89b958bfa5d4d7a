"""Glyph outlines in and out of fonts with fontTools: TrueType, OpenType-CFF and UFO.

Reading gives every contour of a glyph as a chain of Bézier segments (lines,
quadratics with their implied on-curve points resolved, cubics), components
decomposed. Writing builds a TrueType font (``glyf``) from quadratic contours:
glyph order, names (``post`` format 2), character map, advance widths,
vertical metrics, names and the layout tables (``GSUB``, ``GPOS``, ``GDEF``,
``kern``) are copied from the source; hinting is dropped (no ``fpgm``,
``prep``, ``cvt``, no glyph instructions), and left side bearings follow the
new outlines. TrueType coordinates are integers: :func:`round_contour` chooses
each point among its 4 integer neighbours so that the curvature jumps (and the
tangent breaks at explicit on-curve points) stay least, within the tolerance;
that rounding is the only loss. A UFO keeps floats.

This is not a curve format of :mod:`curvesmith.io` (a font holds glyphs,
metrics and tables, not features of curves).
"""

from __future__ import annotations

import copy
import itertools
import math
import os
import struct
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import CurveError, CurveFormatError
from ..geometry import det2

__all__ = [
    "Contour",
    "GlyphOutline",
    "TrueTypeContour",
    "font_glyph_names",
    "joint_jumps",
    "joint_kinks",
    "open_font",
    "read_glyph",
    "resolve_glyphs",
    "round_contour",
    "truetype_contour",
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
        pts: list[np.ndarray] = []
        corners: list[int] = []
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
        p = np.array(pts, dtype=np.float64)
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
        # fontTools reads a table when it is first used: a truncated or damaged file
        # would fail in the middle of the work, so the tables are checked here
        size = path.stat().st_size
        for tag, entry in font.reader.tables.items():
            if entry.offset + entry.length > size:
                raise TTLibError(
                    f"the {tag.strip()!r} table runs past the end of the file "
                    f"({entry.offset + entry.length} > {size} bytes: truncated?)"
                )
        for tag in ("head", "maxp", "hhea", "hmtx", "cmap", "loca", "glyf", "CFF "):
            if tag in font:
                font[tag]
    except (TTLibError, OSError, AssertionError, struct.error, IndexError, ValueError) as exc:
        if isinstance(exc, FileNotFoundError):
            raise
        msg = f"{path}: not a TrueType/OpenType font, or a damaged one ({exc})"
        raise CurveFormatError(msg) from None
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
    from fontTools.ttLib import TTLibError

    if isinstance(font, _UFO):
        pen = RecordingPen()
        font.draw(name, pen)
        advance = font.advance(name)
        ops = _decompose_ufo(font, pen.value)
    else:
        gs = font.getGlyphSet()
        pen = DecomposingRecordingPen(gs)
        try:
            gs[name].draw(pen)
        except (TTLibError, struct.error, IndexError, ValueError, AssertionError) as exc:
            # fontTools unpacks a glyph's bytes when it is drawn: damaged data fails here
            raise CurveFormatError(
                f"glyph {name}: its outline data is damaged ({type(exc).__name__}: {exc})"
            ) from None
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


def write_truetype(source, glyphs: dict, path, *, keep=None, units_per_em=None) -> None:
    """Write a TrueType font: the source with some glyphs' contours replaced.

    Parameters
    ----------
    source : TTFont or UFO reader
        From :func:`open_font`; glyph order, cmap, metrics, names and layout tables
        are taken from it.
    glyphs : dict of str to list of (S, 3, 2) ndarray
        New quadratic contours (closed) per glyph name, in the output's units
        (rounded with ``round`` unless integral already, e.g. by :func:`round_contour`);
        other glyphs keep their outlines (cubic outlines converted with fontTools'
        cu2qu at 1/1000 em).
    path : str or os.PathLike
        Output ``.ttf``; written to a temporary file and renamed.
    keep : ignored
        Reserved.
    units_per_em : int, optional
        The output's ``unitsPerEm`` (16 .. 16384), default the source's. Everything
        but the new contours (the other glyphs, advance widths, vertical metrics,
        kerning and positioning) is scaled with ``fontTools.ttLib.scaleUpem``.

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
    out_upm = upm if units_per_em is None else int(units_per_em)
    if not 16 <= out_upm <= 16384:
        raise CurveError(f"units_per_em must be in 16 .. 16384, got {units_per_em}")
    later = {}  # the new glyphs of a scaled font: put in after the scaling
    fb = FontBuilder(upm, isTTF=True)
    fb.setupGlyphOrder(order)
    fb.setupCharacterMap(source.getBestCmap() or {})
    glyf = {}
    for name in order:
        pen = TTGlyphPen(None)
        if name in glyphs:
            for seg in glyphs[name]:
                _draw_quadratic_contour(pen, np.asarray(seg, float))
            if out_upm != upm:
                later[name] = _checked(pen.glyph(), name)
                pen = TTGlyphPen(None)
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
        glyf[name] = _checked(pen.glyph(), name)
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
                fb.font[tag] = source[tag] if out_upm == upm else copy.deepcopy(source[tag])
        fb.font["head"].macStyle = source["head"].macStyle
    if out_upm != upm:
        from fontTools.ttLib.scaleUpem import scale_upem

        scale_upem(fb.font, out_upm)
        glyf_table, hmtx = fb.font["glyf"], fb.font["hmtx"]
        for name, g in later.items():
            glyf_table[name] = g
            g.recalcBounds(glyf_table)
            hmtx[name] = (hmtx[name][0], int(g.xMin) if g.numberOfContours else 0)
        for name in order:
            _checked(glyf_table[name], name, glyf_table)
    out = Path(path)
    tmp = out.with_name(out.name + ".part")
    try:
        fb.save(os.fspath(tmp))
        os.replace(tmp, out)
    finally:
        if tmp.exists():
            tmp.unlink()


def _checked(g, name, glyf=None):
    """`g`, after checking that its coordinates fit TrueType's 16-bit range."""
    coords = g.getCoordinates(glyf)[0] if glyf is not None else getattr(g, "coordinates", None)
    if coords is not None and len(coords) and np.abs(np.asarray(coords)).max() > 32767:
        raise CurveError(f"glyph {name}: coordinates exceed TrueType's 16-bit range")
    return g


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

        class _Glyph:  # the attribute holder fontTools' UFO writer reads (glyphs and info)
            width: int
            unicodes: list[int]
            unitsPerEm: int
            familyName: str
            styleName: str
            ascender: int
            descender: int

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


# ------------------------------------------------------------------ TrueType points, rounded


@dataclass(frozen=True)
class TrueTypeContour:
    """A closed quadratic contour as TrueType points, and how its segments use them.

    Attributes
    ----------
    points : (P, 2) ndarray
        On- and off-curve points in drawing order (float, or integer after rounding).
    on : (P,) ndarray of bool
        On-curve flags; an on-curve point between two off-curve points that is
        their midpoint is left out (TrueType's implied point).
    control : (S,) ndarray of int
        Segment ``k``'s off-curve point (index into `points`); -1 for a straight segment
        (a line).
    end : (S,) ndarray of int
        Segment ``k``'s explicit end point; -1 when it is implied (the midpoint of
        ``control[k]`` and ``control[k + 1]``).
    smooth : (S,) ndarray of bool
        The joint at the end of segment ``k`` is G2 (relative curvature jump at most
        1e-6, one sign) in the exact (float) contour: a joint whose curvature jump the
        rounding must keep small.
    """

    points: np.ndarray
    on: np.ndarray
    control: np.ndarray
    end: np.ndarray
    smooth: np.ndarray

    def segments(self, points=None) -> np.ndarray:
        """The (S, 3, 2) quadratic segments of `points` (default: the contour's own)."""
        return _tt_segments(self, self.points if points is None else np.asarray(points))


def truetype_contour(seg) -> TrueTypeContour:
    """TrueType points of closed quadratic segments (implied on-curve points left out).

    A straight segment (control at the chord's midpoint) is a line; a joint that is
    the midpoint of the two controls around it, with neither segment straight, is
    implied.

    Parameters
    ----------
    seg : (S, 3, 2) array_like
        Closed: segment ``k`` ends where ``k + 1`` starts.

    Returns
    -------
    TrueTypeContour
    """
    seg = np.asarray(seg, dtype=float)
    n = len(seg)
    scale = max(1.0, float(np.max(np.abs(seg))))
    tol = 1e-9 * scale
    straight = np.max(np.abs(seg[:, 1] - 0.5 * (seg[:, 0] + seg[:, 2])), axis=1) <= tol
    nxt = np.roll(np.arange(n), -1)
    implied = (
        ~straight
        & ~straight[nxt]
        & (np.max(np.abs(seg[:, 2] - 0.5 * (seg[:, 1] + seg[nxt, 1])), axis=1) <= tol)
    )
    # the joint at the end of segment k: G1 and the curvature of one sign on both sides
    t_in, t_out = seg[:, 2] - seg[:, 1], seg[nxt, 1] - seg[nxt, 0]
    cross = t_in[:, 0] * t_out[:, 1] - t_in[:, 1] * t_out[:, 0]
    dot = np.sum(t_in * t_out, axis=1)
    norm = np.hypot(*t_in.T) * np.hypot(*t_out.T)
    g1 = (np.abs(cross) <= 1e-7 * norm) & (dot > 0)
    a_in = det2(seg[:, 1] - seg[:, 0], seg[:, 2] - seg[:, 1])
    a_out = a_in[nxt]
    smooth = g1 & ~straight & ~straight[nxt] & (np.sign(a_in) * np.sign(a_out) > 0)
    # and G2: the joints next to an inflection of the fit (where its cross area A changes
    # sign) are G1 with one sign but no G2 quadratic exists there; not a rounding matter
    smooth &= joint_jumps(seg, smooth) <= 1e-6
    pts: list = []
    on: list = []
    control = np.full(n, -1)
    end = np.full(n, -1)
    explicit = np.flatnonzero(~implied)
    if explicit.size == 0:  # every on-curve point implied
        control[:] = np.arange(n)
        return TrueTypeContour(seg[:, 1].copy(), np.zeros(n, bool), control, end, smooth)
    first = (int(explicit[0]) + 1) % n
    order = [(first + i) % n for i in range(n)]
    for k in order:
        if not straight[k]:
            control[k] = len(pts)
            pts.append(seg[k, 1])
            on.append(False)
        if not implied[k]:
            end[k] = len(pts)
            pts.append(seg[k, 2])
            on.append(True)
    return TrueTypeContour(np.array(pts), np.array(on), control, end, smooth)


def _tt_segments(tc: TrueTypeContour, p: np.ndarray) -> np.ndarray:
    n = len(tc.control)
    prev = np.roll(np.arange(n), 1)
    nxt = np.roll(np.arange(n), -1)
    c = np.where(tc.control[:, None] >= 0, p[np.maximum(tc.control, 0)], 0.0)
    e = np.where(
        tc.end[:, None] >= 0,
        p[np.maximum(tc.end, 0)],
        0.5 * (p[np.maximum(tc.control, 0)] + p[np.maximum(tc.control[nxt], 0)]),
    )
    s = e[prev]
    c = np.where(tc.control[:, None] >= 0, c, 0.5 * (s + e))
    return np.stack([s, c, e], axis=1)


def joint_jumps(seg, smooth) -> np.ndarray:
    """Relative curvature jump at the end of every segment of a closed quadratic contour.

    ``|k_left - k_right| / max(|k_left|, |k_right|)`` with ``k_left`` the curvature at
    the end of segment ``k`` and ``k_right`` at the start of ``k + 1``; 0 where both are
    0 (a joint of straight pieces) and where the joint is not `smooth` (a corner or
    an inflection of the exact contour: no G2 to keep there). At an implied point of
    a TrueType run ``k_left = A_k / |e_k|^3`` and ``k_right = A_(k+1) / |e_k|^3``
    (``e_k`` the edge of the off-curve polygon through the point, ``A`` the cross
    areas ``det(e_(k-1), e_k)`` at its ends), so the jump is
    ``|A_k - A_(k+1)| / max(|A_k|, |A_(k+1)|)``: zero exactly when the polygon is an
    affine arc length polyline.

    Parameters
    ----------
    seg : (..., S, 3, 2) array_like
    smooth : (S,) array_like of bool

    Returns
    -------
    (..., S) ndarray
    """
    q = np.asarray(seg, dtype=float)
    nq = np.roll(q, -1, axis=-3)
    u, w = q[..., 2, :] - q[..., 1, :], q[..., 1, :] - q[..., 0, :]
    lu = np.hypot(u[..., 0], u[..., 1])
    left = 0.5 * det2(w, u) / np.where(lu > 0, lu, 1.0) ** 3
    u2, w2 = nq[..., 1, :] - nq[..., 0, :], nq[..., 2, :] - nq[..., 1, :]
    lu2 = np.hypot(u2[..., 0], u2[..., 1])
    right = 0.5 * det2(u2, w2) / np.where(lu2 > 0, lu2, 1.0) ** 3
    big = np.maximum(np.abs(left), np.abs(right))
    jump = np.abs(left - right) / np.where(big > 0, big, 1.0)
    return np.where(np.asarray(smooth, bool) & (big > 0), jump, 0.0)


def joint_kinks(seg, smooth) -> np.ndarray:
    """Tangent break (radians) at the end of every segment; 0 where not `smooth`.

    Zero at implied points (the midpoint of two off-curve points is on their line);
    an explicit on-curve point between two off-curve points is a kink once
    rounding takes the three off their line.

    Parameters
    ----------
    seg : (..., S, 3, 2) array_like
    smooth : (S,) array_like of bool

    Returns
    -------
    (..., S) ndarray
    """
    q = np.asarray(seg, dtype=float)
    nq = np.roll(q, -1, axis=-3)
    t_in, t_out = q[..., 2, :] - q[..., 1, :], nq[..., 1, :] - nq[..., 0, :]
    ang = np.abs(np.arctan2(det2(t_in, t_out), np.sum(t_in * t_out, axis=-1)))
    return np.where(np.asarray(smooth, bool), ang, 0.0)


def _joint_defects(seg, smooth) -> np.ndarray:
    """What the rounding minimises per joint: the curvature jump or the kink, relative.

    A kink ``theta`` is the turning of the curve over ``theta / |k|`` of its length;
    against the shorter of the joint's two handles ``l`` it is the relative change of
    the mean curvature over ``l``: ``theta / (|k| l)``, the same scale as the jump.
    """
    q = np.asarray(seg, dtype=float)
    nq = np.roll(q, -1, axis=-3)
    jump = joint_jumps(q, smooth)
    kink = joint_kinks(q, smooth)
    h_in = np.hypot(*np.moveaxis(q[..., 2, :] - q[..., 1, :], -1, 0))
    h_out = np.hypot(*np.moveaxis(nq[..., 1, :] - nq[..., 0, :], -1, 0))
    w = q[..., 1, :] - q[..., 0, :]
    safe = np.where(h_in > 0, h_in, 1.0)
    area = 0.5 * np.abs(det2(w, q[..., 2, :] - q[..., 1, :]))
    k_left = np.where(h_in > 0, area / safe**3, 0.0)
    scale = k_left * np.minimum(h_in, h_out)
    ok = (kink > 0) & (scale > 0)
    rel = np.where(ok, kink / np.where(ok, scale, 1.0), np.where(kink > 0, 2.0 + kink, 0.0))
    return np.maximum(jump, rel)


_CAND = np.array([[0, 0], [1, 0], [0, 1], [1, 1]])  # floor + offsets: the 4 integer neighbours


def _terms(tc: TrueTypeContour):
    """Per segment and per smooth joint: the TrueType points it depends on."""
    n = len(tc.control)
    nxt = lambda k: (k + 1) % n  # noqa: E731
    prv = lambda k: (k - 1) % n  # noqa: E731

    def seg_points(k):
        out = set()
        e = prv(k)  # the start of segment k: the end of the previous one
        if tc.end[e] >= 0:
            out.add(int(tc.end[e]))
        else:
            out |= {int(tc.control[e]), int(tc.control[k])}
        if tc.control[k] >= 0:
            out.add(int(tc.control[k]))
        if tc.end[k] >= 0:
            out.add(int(tc.end[k]))
        else:
            out |= {int(tc.control[k]), int(tc.control[nxt(k)])}
        return out

    segs = [seg_points(k) for k in range(n)]
    joints = {k: segs[k] | segs[nxt(k)] for k in range(n) if tc.smooth[k]}
    return segs, joints


def _window(indices, count):
    """Smallest cyclic interval ``(start, length)`` of ``range(count)`` covering `indices`."""
    idx = sorted(indices)
    if len(idx) == 1:
        return idx[0], 1
    gaps = [(idx[(i + 1) % len(idx)] - idx[i]) % count for i in range(len(idx))]
    i = int(np.argmax(gaps))  # the largest gap is outside the window
    start = idx[(i + 1) % len(idx)]
    return start, count - gaps[i] + 1


def round_contour(tc: TrueTypeContour, *, bound=None, search: bool = True) -> np.ndarray:
    """Integer TrueType points with the least largest curvature defect at smooth joints.

    Every point is one of its 4 integer neighbours (floor or ceiling of each
    coordinate: it moves by less than 1 unit in x and y, so the outline by less
    than ``sqrt 2``). Each segment's shape depends on at most 3 consecutive
    points, each smooth joint's two curvatures (:func:`joint_jumps`) and tangents
    (:func:`joint_kinks`: an explicit on-curve point between two off-curve
    points, which plain rounding breaks by up to 2.6 degrees at 2048 units per
    em) on at most 5, so a dynamic programme along the contour that keeps the
    choices of the last 4 points as its state finds the rounding that minimises
    the largest relative defect (the jump, or the kink ``theta / (|k| l)`` against
    the shorter handle ``l``) exactly (a closed contour: the first 4 choices are
    fixed per run of the programme, all 256 run side by side); a second pass
    minimises the sum of squared defects among the roundings with that largest
    defect. Plain rounding is one of the candidates, so the largest defect is
    never worse (among the roundings within the bound); the curvature jump alone
    can be, where plain rounding broke a tangent instead (2 of DejaVu Serif's
    first 400 glyphs at 2048 units per em). The area is not a term: it moves by
    the rounding, up to 2e-3 of a glyph at 2048 units per em (DejaVu Sans' e and
    g; plain rounding about 3e-4), 3e-4 at 16384. Tried and dropped: moving single
    points back towards the exact area (every move of 1 unit changes the cross
    areas by about ``|e|``, so no move kept the largest defect), and a second pass
    minimising the segments' area changes (no better: the roundings with the
    least largest defect are few).

    Parameters
    ----------
    tc : TrueTypeContour
    bound : callable, optional
        ``bound(k, segment) -> (M,) float``: how far the (M, 3, 2) candidates of
        segment ``k`` are outside the tolerance (``<= 0``: within);
        a segment no candidate keeps within admits its candidates of least violation.
    search : bool, optional
        False: plain rounding (``round`` half away from zero, as fontTools' ``otRound``
        rounds half up).

    Returns
    -------
    (P, 2) ndarray of int
    """
    p = tc.points
    plain = np.floor(p + 0.5).astype(np.int64)
    if not search or len(p) == 0:
        return plain
    base = np.floor(p).astype(np.int64)
    cand = base[:, None, :] + _CAND[None]  # (P, 4, 2)
    count = len(p)
    segs, joints = _terms(tc)
    terms = []  # (points, kind, index)
    for k, pts in enumerate(segs):
        if bound is not None:
            terms.append((sorted(pts), "seg", k))
    for k, pts in joints.items():
        terms.append((sorted(pts), "joint", k))
    if count <= 6:
        return _round_brute(tc, cand, terms, bound)
    width = 5
    tables = []
    for pts, kind, k in terms:
        start, length = _window(pts, count)
        if length > width:  # pragma: no cover - segments use <= 3, joints <= 5 points
            raise CurveError(f"a term spans {length} TrueType points")
        window = [(start + i) % count for i in range(length)]
        combos = np.array(list(itertools.product(range(4), repeat=length)))  # (4^L, L)
        value = _term_values(tc, cand, window, combos, kind, k, bound)
        tables.append((start, length, value.reshape((4,) * length)))
    # the terms whose window ends at each unrolled position e = start + length - 1
    at: dict[int, list] = {}
    for start, length, value in tables:
        at.setdefault(start + length - 1, []).append((length, value))
    best_max = _dp(count, at, combine=np.maximum, trace=False)[0]
    limit = best_max * (1 + 1e-9) + 1e-15
    squared = {}
    for e, items in at.items():
        squared[e] = [
            (length, np.where(value <= limit, np.where(value >= 0, value, 0.0) ** 2, np.inf))
            for length, value in items
        ]
    _, choice = _dp(count, squared, combine=np.add)
    return cand[np.arange(count), choice]


def _term_values(tc, cand, window, combos, kind, k, bound):
    """Value of one term for every combination of its window's candidates."""
    pts = np.broadcast_to(tc.points, (len(combos), *tc.points.shape)).copy()
    for j, pi in enumerate(window):
        pts[:, pi] = cand[pi, combos[:, j]]
    n = len(tc.control)
    if kind == "joint":  # segments k and k + 1 only (closed pair: joint 0 is theirs)
        seg = _tt_segments_batch(tc, pts, [k, (k + 1) % n])
        return _joint_defects(seg, np.array([True, False]))[:, 0]
    over = np.asarray(bound(k, _tt_segments_batch(tc, pts, [k])[:, 0]), dtype=float)
    lim = max(0.0, float(over.min()) * (1 + 1e-9))  # nothing within: the least violation
    return np.where(over <= lim, -1.0, np.inf)


def _tt_segments_batch(tc, pts, ks=None):
    """(M, S, 3, 2) segments of (M, P, 2) candidate points (only segments `ks` if given)."""
    n = len(tc.control)
    ks = np.arange(n) if ks is None else np.asarray(ks)
    ctrl = np.maximum(tc.control, 0)

    def end(k):
        return np.where(
            (tc.end[k] >= 0)[None, :, None],
            pts[:, np.maximum(tc.end[k], 0)],
            0.5 * (pts[:, ctrl[k]] + pts[:, ctrl[(k + 1) % n]]),
        )

    e, s = end(ks), end((ks - 1) % n)
    c = np.where((tc.control[ks] >= 0)[None, :, None], pts[:, ctrl[ks]], 0.5 * (s + e))
    return np.stack([s, c, e], axis=2)


def _dp(count, at, combine, trace=True):
    """Cyclic dynamic programme over `count` points with 4 choices each.

    The state after position ``p`` is (the first 4 choices, the last 4 choices);
    positions ``count .. count + 3`` repeat the first 4 points with their choice
    forced. Terms (tables over 1-5 consecutive choices ending at a position) are
    combined with `combine` (max or sum); a term's value -1 means "no cost".
    """
    c4 = 4
    pre = np.array(list(itertools.product(range(c4), repeat=4)))  # (256, 4)
    neutral = -np.inf if combine is np.maximum else 0.0

    def cost_at(e, digits_shape):
        total = np.full((c4,) * 5, neutral)
        for length, value in at.get(e, []):
            v = np.where(value == -1.0, neutral, value) if combine is np.maximum else value
            v = v.reshape((1,) * (5 - length) + (c4,) * length)
            total = combine(total, v)
        return total

    # initial: the prefix's terms (ending at positions 0..3), on the prefix choices
    val = np.full(len(pre), neutral)
    for e in range(4):
        for length, value in at.get(e, []):
            v = value if combine is not np.maximum else np.where(value == -1.0, neutral, value)
            val = combine(val, v[tuple(pre[:, e - length + 1 + i] for i in range(length))])
    state = np.full((len(pre),) + (c4,) * 4, np.inf)
    state[(np.arange(len(pre)), *pre.T)] = val
    back = []
    for e in range(4, count + 4):
        cost = cost_at(e, None)  # axes: x_(e-4) .. x_e
        if e >= count:  # a repeated prefix point: its choice is forced
            forced = pre[:, e - count]
            keep = np.arange(c4)[None, :] == forced[:, None]  # (256, 4)
            keep = keep.reshape(len(pre), 1, 1, 1, 1, c4)
        else:
            keep = True
        total = np.where(keep, combine(state[..., None], cost[None]), np.inf)
        state = total.min(axis=1)
        if trace:
            back.append(np.argmin(total, axis=1).astype(np.int8))
    flat = int(np.argmin(state))
    best = float(state.flat[flat])
    if not trace:
        return best, None
    idx = np.unravel_index(flat, state.shape)
    pfx, last = idx[0], list(idx[1:])  # choices of positions count .. count + 3 (= prefix)
    choice = np.zeros(count + 4, dtype=int)
    choice[count : count + 4] = last
    window = list(last)
    for e in range(count + 3, 3, -1):
        a = int(back[e - 4][(pfx, *window)])
        choice[e - 4] = a
        window = [a, *window[:-1]]
    choice[:4] = pre[pfx]
    return best, choice[:count]


def _round_brute(tc, cand, terms, bound):
    count = len(tc.points)
    combos = np.array(list(itertools.product(range(4), repeat=count)))
    pts = cand[np.arange(count)[None, :], combos]  # (M, P, 2)
    seg = _tt_segments_batch(tc, pts.astype(float))
    worst = np.zeros(len(combos))
    if bound is not None:
        for k in range(len(tc.control)):
            over = np.asarray(bound(k, seg[:, k]), dtype=float)
            worst[over > max(0.0, float(over.min()) * (1 + 1e-9))] = np.inf
    jumps = _joint_defects(seg, tc.smooth)
    m = np.maximum(worst, jumps.max(axis=1))
    best = m.min()
    score = np.where(m <= best * (1 + 1e-9) + 1e-15, np.sum(jumps**2, axis=1), np.inf)
    return pts[int(np.argmin(score))]
