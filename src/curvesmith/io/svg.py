"""SVG curves: paths (every command, arcs, transforms) and basic shapes in, ``<path>`` out.

See :mod:`curvesmith.io` for the format's conventions.
"""

from __future__ import annotations

import io as _stdio
import json
import math
import re
from collections.abc import Iterable
from typing import Any
from xml.sax.saxutils import quoteattr

import numpy as np

from .._validate import as_float
from ..errors import CurveError, CurveFormatError
from ..geometry import _signed_area
from ._core import (
    _POLYGON_KINDS,
    KINDS,
    Curve,
    Format,
    Source,
    _check_curves,
    _json_default,
    _read_text,
    format_rows,
    open_destination,
    register,
    write_rows,
)

__all__ = [
    "SVGCurves",
    "SVGKeptWarning",
    "bezier_path_data",
    "path_document",
    "quadratic_path_data",
    "read_bezier_paths",
    "read_quadratic_path",
    "read_svg",
    "write_bezier_document",
    "write_svg",
]

_META = "data-curvesmith"
# Each number text matches in exactly one way (``\d+\.?\d*`` could split "10" as "1" + "0",
# and a path that finally fails to match then backtracked through every split of every
# integer: 45 s for 8 segments, x9 per segment). With one way per number and separators that
# cannot swallow a digit, a failing match is linear in the length of the data.
_NUMBER = r"[+-]?(?:\d+(?:\.\d*)?|\.\d+)(?:[eE][+-]?\d+)?"
_SEP = r"(?:\s*,\s*|\s+)"
_PAIR = rf"{_NUMBER}{_SEP}{_NUMBER}"
# Path data made only of moveto/lineto/closepath with separated coordinates (what write_svg
# writes): svgelements parses it completely, so the slow strict re-parse is not needed.
_POLYLINE_D = re.compile(
    rf"\s*[Mm]\s*{_PAIR}(?:{_SEP}{_PAIR})*(?:\s*(?:[MmLl]\s*{_PAIR}(?:{_SEP}{_PAIR})*|[Zz]))*\s*"
)
_MAX_CHORDS = 1_000_000
_DEFAULT_RELATIVE_TOLERANCE = 1e-4


def _bezier_points(ctrl: np.ndarray, n: int) -> np.ndarray:
    """Points at t = k/n, k = 1..n, of the Bézier curve with control points `ctrl`."""
    t = np.arange(1, n + 1, dtype=np.float64)[:, None] / n
    s = 1.0 - t
    if len(ctrl) == 3:
        pts = s * s * ctrl[0] + 2 * s * t * ctrl[1] + t * t * ctrl[2]
    else:
        pts = s**3 * ctrl[0] + 3 * s * s * t * ctrl[1] + 3 * s * t * t * ctrl[2] + t**3 * ctrl[3]
    pts[-1] = ctrl[-1]
    return pts


def _chords(second_derivative_bound: float, tol: float) -> int:
    """Number of equal parameter steps so that h**2/8 * max|c''| <= tol on [0, 1]."""
    n = max(1, math.ceil(math.sqrt(second_derivative_bound / (8.0 * tol))))
    if n > _MAX_CHORDS:
        raise CurveFormatError(
            f"tolerance {tol:g} is too small for this drawing: one segment would need {n} chords"
        )
    return n


def _xy(p) -> list[float]:
    return [float(p[0]), float(p[1])]


def _flatten(segments, tol: float) -> list[tuple[np.ndarray, bool]]:
    """Flatten svgelements path segments into (points, closed) subpaths."""
    import svgelements as se

    subpaths: list[tuple[list, bool]] = []
    current: list | None = None

    def finish(closed: bool) -> None:
        nonlocal current
        if current is not None:
            subpaths.append((current, closed))
        current = None

    for seg in segments:
        if isinstance(seg, se.Move):
            finish(False)
            current = [np.array([_xy(seg.end)])]
            continue
        if isinstance(seg, se.Close):
            finish(True)
            continue
        if current is None:
            current = [np.array([_xy(seg.start)])]
        if isinstance(seg, se.Line):
            current.append(np.array([_xy(seg.end)]))
        elif isinstance(seg, se.QuadraticBezier):
            ctrl = np.array([_xy(seg.start), _xy(seg.control), _xy(seg.end)])
            bound = 2.0 * float(np.hypot(*(ctrl[0] - 2 * ctrl[1] + ctrl[2])))
            current.append(_bezier_points(ctrl, _chords(bound, tol)))
        elif isinstance(seg, se.CubicBezier):
            ctrl = np.array([_xy(seg.start), _xy(seg.control1), _xy(seg.control2), _xy(seg.end)])
            d0 = np.hypot(*(ctrl[0] - 2 * ctrl[1] + ctrl[2]))
            d1 = np.hypot(*(ctrl[1] - 2 * ctrl[2] + ctrl[3]))
            current.append(_bezier_points(ctrl, _chords(6.0 * float(max(d0, d1)), tol)))
        elif isinstance(seg, se.Arc):
            if seg.start == seg.end and seg.sweep == 0:
                continue
            radius = max(abs(float(seg.rx)), abs(float(seg.ry)))
            n = _chords(float(seg.sweep) ** 2 * radius, tol)
            positions = np.arange(1, n + 1, dtype=np.float64) / n
            current.append(np.asarray(seg.npoint(positions), dtype=np.float64))
        else:  # pragma: no cover - svgelements has no other segment types
            raise CurveFormatError(f"unsupported SVG path segment {type(seg).__name__}")
    finish(False)
    return _clean_subpaths([(np.concatenate(chunks), closed) for chunks, closed in subpaths], tol)


def _clean_subpaths(subpaths, tol: float) -> list[tuple[np.ndarray, bool]]:
    """Drop repeated vertices, a closing vertex equal to the start and empty subpaths."""
    out = []
    for pts, closed in subpaths:
        keep = np.ones(len(pts), dtype=bool)
        keep[1:] = np.any(pts[1:] != pts[:-1], axis=1)
        pts = pts[keep]
        if closed and len(pts) > 1 and np.hypot(*(pts[-1] - pts[0])) <= 1e-9 * tol:
            pts = pts[:-1]
        if len(pts) < 2:
            continue
        if closed and len(pts) < 3:
            closed = False
        out.append((pts, closed))
    return out


_ABSOLUTE_POLYLINE_D = re.compile(
    rf"\s*M\s*{_PAIR}(?:{_SEP}{_PAIR})*(?:\s*(?:[ML]\s*{_PAIR}(?:{_SEP}{_PAIR})*|Z))*\s*"
)
_D_ATTRIBUTE = re.compile(r'(\sd\s*=\s*)"([^"]*)"')
FAST_D_MIN = 2000


def _polyline_subpaths(d: str) -> list[tuple[np.ndarray, bool]] | None:
    """Subpaths of path data made of absolute M, L and Z only (what :func:`write_svg` writes).

    Parsed with one split instead of one svgelements object per segment (a 10^6-vertex path
    took minutes). None when the data need the general parser: relative commands, or a Z
    that is not the end of its subpath.
    """
    if not _ABSOLUTE_POLYLINE_D.fullmatch(d):
        return None
    out = []
    for chunk in d.split("M")[1:]:
        body = chunk.rstrip()
        closed = body.endswith("Z")
        if closed:
            body = body[:-1]
        if "Z" in body:
            return None  # segments after a closepath start at the subpath's first point
        values = np.array(body.replace("L", " ").replace(",", " ").split(), dtype=np.float64)
        out.append((values.reshape(-1, 2), closed))
    return out


def _stash_polylines(text: str) -> tuple[str, dict[str, list]]:
    """Replace long plain polyline path data by short placeholders before svgelements parses.

    Returns the new text and a map from placeholder to the parsed subpaths.
    """
    stash: dict[str, list] = {}

    def replace(match):
        d = match.group(2)
        if len(d) < FAST_D_MIN:
            return match.group(0)
        subpaths = _polyline_subpaths(d)
        if subpaths is None:
            return match.group(0)
        key = f"M 0,0 L 0,{len(stash)}.5e-300"
        stash[key] = subpaths
        return f'{match.group(1)}"{key}"'

    if len(text) < FAST_D_MIN:
        return text, stash
    return _D_ATTRIBUTE.sub(replace, text), stash


class SVGCurves(list):
    """The curves of an SVG document, its page and the document itself.

    A ``list`` of :class:`Curve` returned by :func:`read_svg`. :func:`write_svg` given one
    writes the source document back with each element that gave curves replaced by a
    ``<path>`` of its (smoothed) curves, in the element's own coordinates and with all its
    other attributes; everything else (text, images, ``defs``, clip paths, gradients,
    groups, metadata) is written as it was. ``page`` holds ``width``, ``height`` and
    ``viewBox`` of the root.
    """

    def __init__(self, curves=(), page=None, document=None):
        super().__init__(curves)
        self.page: dict[str, str] = dict(page or {})
        #: (root element with node marks, {feature: (node, 2x2 linear part, offset)}, nodes
        #: that cannot be rewritten: drawn more than once, or under a clipPath, mask ...)
        self.document = document

    def with_curves(self, curves) -> SVGCurves:
        """The same page and document with other curves (e.g. the smoothed ones)."""
        return SVGCurves(curves, self.page, self.document)

    def kept(self) -> frozenset[int]:
        """The features whose elements a rewrite writes back as they were.

        Shapes drawn more than once (through several ``<use>``) or not drawn on their own
        (under a ``clipPath``, ``mask``, ``marker`` or ``pattern``): :class:`SVGKeptWarning`.
        """
        if self.document is None:
            return frozenset()
        _, nodes, fixed = self.document
        return frozenset(f for f, (node, *_) in nodes.items() if node is None or node in fixed)


def _fixed_nodes(root, nodes: dict[int, tuple]) -> frozenset:
    """The shapes that a rewrite must leave as they are: drawn other than once, in place.

    A shape drawn more than once (through several ``<use>``) would need one path per
    drawing, and one under a ``clipPath``, ``mask``, ``marker`` or ``pattern`` is not a
    drawing of its own. A shape inside ``defs`` or a ``symbol`` that exactly one reference
    draws (the way Figma and Illustrator export: every path in ``defs``, drawn by one
    ``<use>``) is rewritten in its own coordinates, as any other: the feature's transform
    is the ``<use>``'s composed with the shape's. Any other reference to it or to a
    containing element (a second ``<use>``, a ``textPath``) keeps it, and so does a
    ``symbol`` with a ``viewBox``, whose mapping onto the ``<use>``'s width and height the
    reader (svgelements) does not apply.
    """
    from collections import Counter

    drawn = Counter(entry[0] for entry in nodes.values())
    fixed = {n for n, k in drawn.items() if n is None or k > 1}  # used more than once
    refs: dict[str, int] = {}
    for element in root.iter():
        href = element.get("href") or element.get("{http://www.w3.org/1999/xlink}href")
        if href and href.startswith("#"):
            refs[href[1:]] = refs.get(href[1:], 0) + 1
    parents = {child: parent for parent in root.iter() for child in parent}
    for element in root.iter():
        if _local(element.tag) not in _SHAPES:
            continue
        chain, hidden = [element], set()
        up = parents.get(element)
        while up is not None:
            chain.append(up)
            if _local(up.tag) in _NOT_DRAWN:
                # a symbol's viewBox maps it onto the <use>'s width and height, which the
                # reader does not apply: such a shape stays as it was
                viewbox = _local(up.tag) == "symbol" and up.get("viewBox") is not None
                hidden.add("scaled symbol" if viewbox else _local(up.tag))
            up = parents.get(up)
        if not hidden:
            continue
        node = element.get(_NODE)
        references = sum(refs.get(el.get("id"), 0) for el in chain if el.get("id"))
        if hidden - {"defs", "symbol"} or references != 1 or drawn[node] != 1:
            fixed.add(node)
    return frozenset(fixed)


class SVGKeptWarning(UserWarning):
    """Shapes of an SVG document written back as they were, not with their new curves."""


_SVG_NS = "http://www.w3.org/2000/svg"
_NODE = "data-curvesmith-node"
_SHAPES = frozenset({"path", "rect", "circle", "ellipse", "line", "polyline", "polygon"})
# shapes under these are drawn elsewhere (by reference) or not at all: never rewritten
_NOT_DRAWN = frozenset({"defs", "symbol", "clipPath", "mask", "marker", "pattern"})
_GEOMETRY = frozenset(
    {"d", "x", "y", "width", "height", "rx", "ry", "cx", "cy", "r", "points", "x1", "y1",
     "x2", "y2", "pathLength"}
)  # fmt: skip


def _local(tag) -> str:
    return tag.rsplit("}", 1)[-1] if isinstance(tag, str) else ""


def _marked_document(text: str, name: str):
    """The parsed document with every shape element marked by its node number.

    Returns the root and the marked text (what svgelements then parses), or
    ``(None, text)`` when ElementTree cannot serialise it back unchanged in meaning.
    """
    import xml.etree.ElementTree as ET

    try:
        for _, (prefix, uri) in ET.iterparse(_stdio.StringIO(text), events=("start-ns",)):
            if prefix and not prefix.startswith("ns"):
                ET.register_namespace(prefix, uri)
        ET.register_namespace("", _SVG_NS)
        root = ET.fromstring(text)
    except ET.ParseError:
        return None, text  # svgelements' parse reports it with line and column
    k = 0
    for element in root.iter():
        transform = element.get("transform")
        if transform is not None:
            _check_transform(transform, element, name)
        if _local(element.tag) in _SHAPES:
            element.set(_NODE, str(k))
            k += 1
    return root, ET.tostring(root, encoding="unicode")


#: How many numbers each transform function takes (SVG 1.1 and the CSS 2D functions that
#: svgelements reads).
_TRANSFORM_ARGS = {
    "matrix": (6,), "translate": (1, 2), "translatex": (1,), "translatey": (1,),
    "scale": (1, 2), "scalex": (1,), "scaley": (1,), "rotate": (1, 3), "skew": (1, 2),
    "skewx": (1,), "skewy": (1,),
}  # fmt: skip


_ANGLE_UNITS = ("deg", "rad", "grad", "turn")


def _check_transform(value: str, element, name: str) -> None:
    """Raise if a ``transform`` attribute is not a transform list.

    svgelements failed on some with an IndexError and silently ignored others.
    """
    import svgelements as se

    text = value.lower()
    ok = True
    end = 0
    for m in se.REGEX_TRANSFORM_TEMPLATE.finditer(text):
        if text[end : m.start()].strip(" \t\r\n,"):
            ok = False  # something between the functions that is not one
        end = m.end()
        args = m.group(2)
        params = se.REGEX_TRANSFORM_PARAMETER.findall(args)
        numbers = se.REGEX_FLOAT.findall(args)
        rest = se.REGEX_TRANSFORM_PARAMETER.sub("", args).strip(" \t\r\n,")
        fn = m.group(1)
        if rest or len(params) != len(numbers) or len(params) not in _TRANSFORM_ARGS[fn]:
            ok = False
        for i, (_, unit) in enumerate(params):
            angle = fn in ("rotate", "skew", "skewx", "skewy") and i == 0
            lengths = fn.startswith("translate") or (fn == "rotate" and i > 0)
            if unit not in ("",) + (_ANGLE_UNITS if angle else ("px",) if lengths else ()):
                ok = False  # lengths in mm, % ...: no page size to resolve them against
    if text[end:].strip(" \t\r\n,"):
        ok = False
    if not ok:
        tag = _local(element.tag)
        ident = f' id="{element.get("id")}"' if element.get("id") else ""
        raise CurveFormatError(
            f"{name}: <{tag}{ident}> has transform={value!r}, not an SVG transform list "
            "(matrix of 6 numbers, translate, scale, rotate of 1 or 3, skewX, skewY; lengths "
            "without units or in px)"
        )


def _page_of(text: str) -> dict[str, str]:
    """width, height and viewBox of the root element, as written."""
    import xml.etree.ElementTree as ET

    try:
        root = ET.fromstring(text)
    except ET.ParseError:
        return {}
    return {k: root.attrib[k] for k in ("width", "height", "viewBox") if root.attrib.get(k)}


def _own_transform(element, viewport: str):
    """The element's transform without the root viewBox-to-viewport mapping."""
    import svgelements as se

    text = element.values.get("transform", "") or ""
    if viewport and viewport in text:
        text = text.replace(viewport, " ", 1)
        return se.Matrix(text)
    if viewport:
        return ~se.Matrix(viewport) * se.Matrix(text)
    return se.Matrix(text)


def _label(element, k: int) -> str:
    tag = element.values.get("tag", type(element).__name__.lower())
    ident = f' id="{element.id}"' if element.id else ""
    return f"<{tag}{ident}> (drawable element {k})"


def read_svg(source: Source, *, tolerance: float | None = None) -> list[Curve]:
    """Read the drawable shapes of an SVG file as polylines.

    Parameters
    ----------
    source : str or path-like or text file object
        The SVG document.
    tolerance : float, optional
        Maximal distance between a flattened curved segment and the exact
        curve, in user units of the outermost ``svg`` element; default
        ``1e-4`` times the diagonal of the bounding box of all control points.

    Returns
    -------
    SVGCurves
        A list of curves with the document's page (``width``, ``height``,
        ``viewBox``, kept by :func:`write_svg`), and each curve's ``style``, the
        presentation attributes of its element. One curve per subpath,
        ``feature`` the index of the element (among those that gave curves),
        ``part`` the subpath index; ``kind`` is
        LineString/Polygon for single subpaths, MultiLineString/MultiPolygon
        when all subpaths of an element are open/closed, and mixed elements
        get one ``member`` per subpath. Closed subpaths inside another one
        that the fill leaves empty (any odd depth with
        ``fill-rule="evenodd"``; opposite winding with the default
        ``nonzero``) are holes: ``ring`` k >= 1 of the polygon (``part``) of
        their container, as in a GeoJSON Polygon. Files written by
        :func:`write_svg` restore the written structure and properties
        instead.

    Raises
    ------
    CurveFormatError
        For malformed XML (with line and column), a root that is not ``svg``,
        malformed path data, or a document without drawable elements.

    Examples
    --------
    >>> import io
    >>> svg = '''<svg xmlns="http://www.w3.org/2000/svg">
    ...   <path d="M 0 0 h 10 v 10 z"/><circle cx="0" cy="0" r="1"/></svg>'''
    >>> curves = read_svg(io.StringIO(svg), tolerance=1e-3)
    >>> [(c.kind, c.closed, len(c.points)) for c in curves]
    [('Polygon', True, 3), ('Polygon', True, 72)]
    """
    import xml.etree.ElementTree as ET

    import svgelements as se

    text, name = _read_text(source)
    if tolerance is not None:
        tolerance = as_float(tolerance, name="tolerance", low=0.0)
    root, text = _marked_document(text, name)
    text, stash = _stash_polylines(text)
    try:
        doc = se.SVG.parse(_stdio.StringIO(text), reify=False)
    except ET.ParseError as exc:
        line, col = exc.position
        raise CurveFormatError(
            f"{name}: malformed XML at line {line}, column {col + 1}: {str(exc).split(':')[0]}"
        ) from None
    if not isinstance(doc, se.SVG):
        raise CurveFormatError(f"{name}: the root element is not <svg>, so this is not an SVG file")
    viewport = doc.values.get("viewport_transform", "") or ""
    if not viewport:
        viewport = str(doc.viewbox_transform or "")
    items: list[Any] = []
    for element in doc.elements():
        if not isinstance(element, se.Shape):
            continue
        k = len(items)
        d = element.values.get("d") if isinstance(element, se.Path) else None
        if d in stash:
            matrix = _own_transform(element, viewport)
            linear = np.array([[matrix.a, matrix.c], [matrix.b, matrix.d]], dtype=np.float64)
            items.append((element, stash[d], matrix, linear))
            continue
        if d and not _POLYLINE_D.fullmatch(d):
            try:
                se.Path(d)  # strict: svgelements' document parser drops bad path data silently
            except ValueError:
                raise CurveFormatError(
                    f"{name}: {_label(element, k)}: malformed path data {d[:60]!r}"
                ) from None
        segments = list(se.Path(element).segments(transformed=False))
        matrix = _own_transform(element, viewport)
        linear = np.array([[matrix.a, matrix.c], [matrix.b, matrix.d]], dtype=np.float64)
        items.append((element, segments, matrix, linear))
    if tolerance is None:
        tolerance = _default_tolerance(items)
    curves: list[Curve] = []
    feature = 0
    nodes: dict[int, tuple] = {}
    for element, segments, matrix, linear in items:
        scale = float(np.linalg.norm(linear, 2))
        if not segments or scale == 0.0 or not math.isfinite(scale):
            continue
        if segments and isinstance(segments[0], tuple):  # parsed polyline data
            subpaths = _clean_subpaths(segments, tolerance / scale)
        else:
            subpaths = _flatten(segments, tolerance / scale)
        if not subpaths:
            continue
        if not (matrix.is_identity()):
            offset = np.array([matrix.e, matrix.f], dtype=np.float64)
            subpaths = [(pts @ linear.T + offset, closed) for pts, closed in subpaths]
        curves.extend(_svg_curves(element, subpaths, feature, name))
        offset = np.array([matrix.e, matrix.f], dtype=np.float64)
        if _flipped(element):  # the curves are y-up map coordinates: one more flip
            linear, offset = linear * [[1.0], [-1.0]], offset * [1.0, -1.0]
        nodes[feature] = (element.values.get(_NODE), linear, offset)
        feature += 1
    if not curves:
        raise CurveFormatError(f"{name}: contains no drawable path, polyline or polygon")
    page = _page_of(text) if "viewBox" in text else {}
    if not (page.get("viewBox") and len(page.get("viewBox", "").replace(",", " ").split()) == 4):
        page = {}  # without a viewBox the user coordinates are the page's: refit on writing
    document = None
    if root is not None:
        document = (root, nodes, _fixed_nodes(root, nodes))
    return SVGCurves(curves, page, document)


def _default_tolerance(items) -> float:
    boxes = []
    for _, segments, matrix, linear in items:
        pts: Any = []
        if segments and isinstance(segments[0], tuple):  # parsed polyline data
            parsed: list[tuple[np.ndarray, Any]] = list(segments)
            segments, pts = (), np.concatenate([piece for piece, _ in parsed])
        for seg in segments:
            for attr in ("start", "end", "control", "control1", "control2"):
                p = getattr(seg, attr, None)
                if p is not None:
                    pts.append(_xy(p))
            if hasattr(seg, "rx") and getattr(seg, "center", None) is not None:
                r = max(abs(float(seg.rx)), abs(float(seg.ry)))
                cx, cy = _xy(seg.center)
                pts += [[cx - r, cy - r], [cx + r, cy + r]]
        if len(pts):
            arr = np.asarray(pts) @ linear.T + [matrix.e, matrix.f]
            boxes.append(arr[np.all(np.isfinite(arr), axis=1)])
    if not boxes:
        return 1.0
    arr = np.concatenate(boxes)
    if len(arr) == 0:
        return 1.0
    with np.errstate(over="ignore"):
        diagonal = float(np.hypot(*(arr.max(axis=0) - arr.min(axis=0))))
    if not math.isfinite(diagonal):  # coordinates near the float range: the span overflows
        diagonal = float(np.finfo(np.float64).max)
    return _DEFAULT_RELATIVE_TOLERANCE * diagonal if diagonal > 0 else 1.0


#: Presentation attributes kept from the source elements and written back by write_svg.
STYLE_ATTRIBUTES = (
    "fill",
    "fill-opacity",
    "fill-rule",
    "stroke",
    "stroke-opacity",
    "stroke-width",
    "stroke-linejoin",
    "stroke-linecap",
    "stroke-dasharray",
    "opacity",
)


def _style_of(element) -> dict[str, str] | None:
    """The element's presentation attributes (CSS ``style`` resolved by svgelements)."""
    values = element.values
    style = {k: str(values[k]) for k in STYLE_ATTRIBUTES if values.get(k) not in (None, "")}
    return style or None


def _flipped(element) -> bool:
    """Whether write_svg(flip_y=True) wrote the element (its curves are read back y-up)."""
    try:
        return json.loads(element.values.get(_META) or "{}").get("flip_y") is True
    except (ValueError, AttributeError):
        return False


def _svg_curves(element, subpaths, feature: int, name: str) -> list[Curve]:
    props: dict[str, Any] = {"id": element.id} if element.id else {}
    index = None
    fid = None
    meta = element.values.get(_META)
    if meta:
        try:
            meta = json.loads(meta)
            props = dict(meta["properties"])
            fid = meta.get("feature_id")
            index = [tuple(entry) for entry in meta["index"]]
            if meta.get("flip_y") is True:  # written by write_svg(flip_y=True): y back up
                subpaths = [(pts * [1.0, -1.0], closed) for pts, closed in subpaths]
        except (ValueError, KeyError, TypeError) as exc:
            raise CurveFormatError(
                f"{name}: element {element.id or feature}: malformed {_META} attribute: {exc}"
            ) from None
        if len(index) != len(subpaths) or any(
            kind not in KINDS or (kind in _POLYGON_KINDS and not closed)
            for (_, _, _, kind), (_, closed) in zip(index, subpaths, strict=True)
        ):
            index = None  # the path was edited: fall back to the plain SVG structure
    if index is None:
        n = len(subpaths)
        flags = {closed for _, closed in subpaths}
        if n == 1:
            kind = "Polygon" if subpaths[0][1] else "LineString"
            index = [(None, 0, 0, kind)]
        elif flags == {True}:
            index = _nested_rings(subpaths, element.values.get("fill-rule") == "evenodd")
        elif flags == {False}:
            index = [(None, k, 0, "MultiLineString") for k in range(n)]
        else:
            index = [
                (k, 0, 0, "Polygon" if c else "LineString") for k, (_, c) in enumerate(subpaths)
            ]
    style = _style_of(element)
    out = []
    for (member, part, ring, kind), (pts, closed) in zip(index, subpaths, strict=True):
        try:
            out.append(
                Curve(
                    pts,
                    closed=closed,
                    properties=props,
                    feature=feature,
                    part=part,
                    ring=ring,
                    kind=kind,
                    member=member,
                    feature_id=fid,
                    style=style,
                )
            )
        except CurveError as exc:
            raise CurveFormatError(f"{name}: element {feature}: {exc}") from None
    return out


def _inside(point: np.ndarray, ring: np.ndarray) -> bool:
    """Return whether `point` is inside the closed `ring` (even-odd ray casting)."""
    x, y = point
    xa, ya = ring[:, 0], ring[:, 1]
    xb, yb = np.roll(xa, -1), np.roll(ya, -1)
    crosses = (ya > y) != (yb > y)
    with np.errstate(divide="ignore", invalid="ignore"):
        xs = xa + (y - ya) * (xb - xa) / (yb - ya)
    return bool(np.count_nonzero(crosses & (x < xs)) % 2)


def _nested_rings(subpaths, evenodd: bool) -> list[tuple]:
    """(member, part, ring, kind) of closed subpaths: rings inside others become holes.

    A subpath inside another (its first vertex inside and its area smaller) is a hole of
    the smallest one containing it when the fill leaves it empty: always with
    ``fill-rule="evenodd"`` at odd depth, with the default ``nonzero`` rule when it winds the
    other way round than its container. Outer rings (and filled islands) become polygons;
    one polygon gives a Polygon, several a MultiPolygon. Subpaths that merely overlap stay
    separate polygons (the SVG fill of overlaps is not a simple feature anyway).
    """
    areas = [_signed_area(pts[:, :2]) for pts, _ in subpaths]
    n = len(subpaths)
    parent: list[int | None] = [None] * n
    for j, (pts, _) in enumerate(subpaths):
        best = None
        for i, (outer, _) in enumerate(subpaths):
            if i == j or abs(areas[i]) <= abs(areas[j]) or not _inside(pts[0], outer):
                continue
            if best is None or abs(areas[i]) < abs(areas[best]):
                best = i
        parent[j] = best
    hole = [False] * n
    owner: list[int] = list(range(n))
    for j in sorted(range(n), key=lambda k: -abs(areas[k])):  # containers first
        up = parent[j]
        if up is None:
            continue
        if evenodd:
            hole[j] = not hole[up]
        else:
            hole[j] = not hole[up] and (areas[up] > 0) != (areas[j] > 0)
        owner[j] = owner[up] if hole[j] else j
    exteriors = [k for k in range(n) if not hole[k]]
    if len(exteriors) == n:
        return [(None, k, 0, "MultiPolygon") for k in range(n)]
    kind = "Polygon" if len(exteriors) == 1 else "MultiPolygon"
    part_of = {k: p for p, k in enumerate(exteriors)}
    rings: dict[int, int] = {}
    index = []
    for k in range(n):
        if hole[k]:
            rings[owner[k]] = rings.get(owner[k], 0) + 1
            index.append((None, part_of[owner[k]], rings[owner[k]], kind))
        else:
            index.append((None, part_of[k], 0, kind))
    return index


def _num(v: float) -> str:
    return repr(float(v))


def write_svg(
    curves: Iterable[Curve],
    dest: Source,
    *,
    stroke: str = "black",
    stroke_width: float | None = None,
    fill: str | None = None,
    flip_y: bool = False,
) -> None:
    """Write 2D curves as an SVG drawing, one ``<path>`` per feature.

    Parameters
    ----------
    curves : iterable of Curve
        2D curves, in SVG user coordinates (y axis down, nothing is flipped). An
        :class:`SVGCurves` (what :func:`read_svg` returns, or its ``with_curves``) is
        written as its source document, each element that gave curves replaced by a
        ``<path>`` of them and everything else as it was (see :class:`SVGCurves`;
        :class:`SVGKeptWarning` lists shapes drawn by reference, written unchanged),
        unless `flip_y`, `stroke`, `stroke_width` or `fill` ask for a new drawing.
    dest : str or path-like or text file object
        The file.
    stroke : str, optional
        Stroke colour (any SVG paint).
    stroke_width : float, optional
        Stroke width in user units; default 1/400 of the larger side of the
        data's bounding box.
    fill : str, optional
        Fill paint for features whose curves are all closed (``fill-rule``
        evenodd, so holes stay empty); default: the curve's own ``style`` fill (read
        from an SVG), else no fill. A curve's ``style`` (fill, stroke, opacity, ...)
        is written on its path and wins over `stroke`.
    flip_y : bool, optional
        Map data (y axis pointing up, north): draw them upright. The paths keep the
        curves' coordinates inside a ``<g transform="scale(1,-1)">`` and the viewBox is
        fitted to the flipped drawing, so :func:`read_svg` (which applies transforms)
        reads the same coordinates back, bit for bit.

    Raises
    ------
    CurveFormatError
        If a curve is 3D.

    Examples
    --------
    >>> import io
    >>> buf = io.StringIO()
    >>> write_svg([Curve([[0, 0], [1, 0], [0, 1]], closed=True)], buf)
    >>> [c.points.tolist() for c in read_svg(io.StringIO(buf.getvalue()))]
    [[[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]]
    """
    curves_in = curves
    curves = _check_curves(curves)
    for i, c in enumerate(curves):
        if c.dim != 2:
            raise CurveFormatError(
                f"SVG is planar: curve {i} has 3D points; drop or project the z coordinate first"
            )
    # the extent curve by curve: no copy of all the points
    lo = np.min([c.points.min(axis=0) for c in curves], axis=0)
    hi = np.max([c.points.max(axis=0) for c in curves], axis=0)
    with np.errstate(over="ignore"):
        size = float(max(hi - lo))
    if not math.isfinite(size):
        raise CurveFormatError(
            f"the coordinates span more than the largest float (from {lo.min():.3g} to "
            f"{hi.max():.3g}): the extent overflows, so no SVG viewBox can hold them; scale "
            "them down"
        )
    document = getattr(curves_in, "document", None)
    styled = stroke != "black" or stroke_width is not None or fill is not None
    if document is not None and not flip_y and not styled:
        _write_document(curves, document, dest)
        return
    if size == 0.0:
        size = max(1.0, float(np.abs(lo).max()))
    pad = 0.02 * size
    x0, y0 = lo - pad
    w, h = hi - lo + 2 * pad
    if flip_y:
        y0 = -hi[1] - pad  # the viewBox of the flipped drawing
    if stroke_width is None:
        stroke_width = size / 400.0
    stroke_width = as_float(stroke_width, name="stroke_width", low=0.0)
    pixels = 800.0 / max(w, h)
    size_attrs = f'width="{w * pixels:.6g}" height="{h * pixels:.6g}" '
    view = f"{_num(x0)} {_num(y0)} {_num(w)} {_num(h)}"
    page = getattr(curves_in, "page", None)
    if page and not flip_y:  # the source document's page: same size, same viewBox
        size_attrs = "".join(f"{k}={quoteattr(page[k])} " for k in ("width", "height") if k in page)
        view = page["viewBox"]
    lines = [
        '<?xml version="1.0" encoding="UTF-8"?>',
        "<!-- written by curvesmith: map coordinates (y up), drawn flipped by the group's "
        "transform -->"
        if flip_y
        else "<!-- written by curvesmith: SVG user coordinates, y axis pointing down -->",
        f'<svg xmlns="http://www.w3.org/2000/svg" version="1.1" {size_attrs}'
        f"viewBox={quoteattr(view)}>",
        f'<g stroke={quoteattr(stroke)} stroke-width="{_num(stroke_width)}" '
        'stroke-linejoin="round" stroke-linecap="round" fill-rule="evenodd"'
        + (' transform="scale(1,-1)">' if flip_y else ">"),
    ]
    groups: dict[int, list[Curve]] = {}
    for c in curves:
        groups.setdefault(c.feature, []).append(c)
    heads = []
    for group in groups.values():
        first = group[0]
        meta = {
            "properties": dict(first.properties),
            "feature_id": first.feature_id,
            "index": [[c.member, c.part, c.ring, c.kind] for c in group],
        }
        if flip_y:
            meta["flip_y"] = True  # read_svg undoes the drawing's flip: map coordinates back
        try:
            meta_text = json.dumps(meta, allow_nan=False, ensure_ascii=False, default=_json_default)
        except (TypeError, ValueError) as exc:
            raise CurveFormatError(f"cannot write the properties as JSON: {exc}") from None
        attrs = []
        ident = first.properties.get("id")
        if isinstance(ident, str | int) and not isinstance(ident, bool):
            attrs.append(f"id={quoteattr(str(ident))}")
        style = dict(first.style or {})
        paint = fill if fill is not None and all(c.closed for c in group) else "none"
        if fill is not None or "fill" not in style:
            style["fill"] = paint
        # the source's paint, opacity and stroke (they override the group's defaults)
        attrs.extend(f"{k}={quoteattr(v)}" for k, v in style.items() if k in STYLE_ATTRIBUTES)
        attrs.append(f"{_META}={quoteattr(meta_text)}")
        heads.append("<path " + " ".join(attrs) + ' d="')
    with open_destination(dest) as out:
        out.write("\n".join(lines) + "\n")
        for head, group in zip(heads, groups.values(), strict=True):
            out.write(head)
            for k, c in enumerate(group):
                # numbers need no XML escaping; rows streamed chunk by chunk
                x0, y0 = c.points[0].tolist()
                out.write(("" if k == 0 else " ") + f"M {x0!r},{y0!r} L")
                write_rows(out, c.points[1:], " %r,%r")
                if c.closed:
                    out.write(" Z")
            out.write('"/>\n')
        out.write("</g>\n</svg>\n")


FORMAT = register(Format("svg", "SVG", (".svg",), read_svg, write_svg))


# ----------------------------------------------------------------------------------------------
# quadratic B-spline paths (affine control polygons)


def write_bezier_document(curves: SVGCurves, beziers, dest: Source) -> None:
    """Write an SVG document with each element's curves as Bézier paths, in place.

    As :func:`write_svg` writes an :class:`SVGCurves` back (the document as it was, each
    element that gave curves replaced by a ``<path>`` with its other attributes, in the
    element's own coordinates), with the path data of curve ``i`` the quadratic (``Q``)
    or cubic (``C``) segments ``beziers[i]`` instead of a polyline. The element's
    transform is affine, so its inverse maps the control points exactly.

    Parameters
    ----------
    curves : SVGCurves
        The curves (what :func:`read_svg` returns, or its ``with_curves``).
    beziers : sequence of (segments, closed)
        Per curve, in order: ``(S, 3, 2)`` or ``(S, 4, 2)`` segments (as
        :attr:`curvesmith.curves.CurveFit.segments`) and whether the path closes.
    dest : str or path-like or text file object
        The file.
    """
    document = getattr(curves, "document", None)
    if document is None:
        raise CurveFormatError("write_bezier_document needs the curves of an SVG document")
    beziers = list(beziers)
    if len(beziers) != len(curves):
        raise CurveFormatError(f"beziers has {len(beziers)} entries for {len(curves)} curves")
    _write_document(_check_curves(curves), document, dest, beziers=beziers)


def _write_document(curves: list[Curve], document, dest: Source, *, beziers=None) -> None:
    """Write the source document with each element's curves in place (see SVGCurves).

    With `beziers` (one ``(segments, closed)`` per curve), the path data are Bézier
    segments (:func:`write_bezier_document`).
    """
    import copy
    import warnings
    import xml.etree.ElementTree as ET

    root, nodes, fixed = document
    root = copy.deepcopy(root)
    by_node = {el.get(_NODE): el for el in root.iter() if el.get(_NODE) is not None}
    groups: dict[int, list[tuple[int, Curve]]] = {}
    for i, c in enumerate(curves):
        groups.setdefault(c.feature, []).append((i, c))
    kept = []
    for feature, group in groups.items():
        node, linear, offset = nodes.get(feature, (None, None, None))
        element = by_node.get(node)
        if element is None or node in fixed:
            kept.append(feature)
            continue
        if np.array_equal(linear, np.eye(2)) and not offset.any():
            inverse = None
        else:
            inverse = np.linalg.inv(linear)
        data: list[str] = []
        for i, c in group:
            if beziers is not None:
                seg, closed = beziers[i]
                seg = np.asarray(seg, dtype=float)
                local = seg if inverse is None else (seg - offset) @ inverse.T
                if not np.isfinite(local).all():
                    raise CurveFormatError(
                        f"element {feature}: its transform cannot be inverted for the new curve"
                    )
                data.append((" " if data else "") + bezier_path_data(local, closed=closed))
                continue
            pts = c.points if inverse is None else (c.points - offset) @ inverse.T
            if not np.isfinite(pts).all():
                raise CurveFormatError(
                    f"element {feature}: its transform cannot be inverted for the new curve"
                )
            data.append(("M " if not data else " M ") + "".join(format_rows(pts[:1], "%r,%r")))
            if len(pts) > 1:
                data.append(" L")
                data.extend(format_rows(pts[1:], " %r,%r"))
            if c.closed:
                data.append(" Z")
        for key in [k for k in element.attrib if k in _GEOMETRY]:
            del element.attrib[key]
        element.tag = f"{{{_SVG_NS}}}path" if element.tag.startswith("{") else "path"
        # the resolved paint as presentation attributes: the same drawing (the properties
        # are inherited ones, so the value an element inherits is the value it gets; a CSS
        # style attribute wins over them). Opacity only where the element sets it: it is
        # not inherited, and a group's opacity on its children too would compound.
        own_css = {
            part.split(":", 1)[0].strip()
            for part in element.get("style", "").split(";")
            if ":" in part
        }
        for key, value in (group[0][1].style or {}).items():
            if key == "opacity" and key not in own_css:
                continue
            if key in STYLE_ATTRIBUTES and key not in element.attrib:
                element.set(key, value)
        element.set("d", "".join(data))
    for el in root.iter():
        el.attrib.pop(_NODE, None)
    if kept:
        warnings.warn(
            f"{len(kept)} SVG element(s) drawn more than once through <use>, referenced by "
            f"other elements, or inside a clipPath, mask, marker, pattern or scaled symbol, "
            f"written back as they were (element "
            f"{', '.join(map(str, kept[:5]))}{', ...' if len(kept) > 5 else ''})",
            SVGKeptWarning,
            stacklevel=3,
        )
    text = ET.tostring(root, encoding="unicode")
    with open_destination(dest) as out:
        out.write('<?xml version="1.0" encoding="UTF-8"?>\n')
        out.write(text)
        out.write("\n")


def _fmt(x: float) -> str:
    return f"{x:.17g}"


def quadratic_path_data(points, *, closed: bool = False) -> str:
    """The uniform quadratic B-spline of a control polygon as SVG path data of ``Q`` commands.

    Parameters
    ----------
    points : (N, 2) array_like
        Control polygon, ``N >= 3``.
    closed : bool, optional
        Closed control polygon; the path ends with ``Z``.

    Returns
    -------
    str
        ``"M x y Q cx cy x y Q ..."`` (17 significant digits, round-trips exactly).

    Examples
    --------
    >>> quadratic_path_data([[0, 0], [2, 0], [2, 2]])
    'M 1 0 Q 2 0 2 1'
    """
    from ..affine.spline import bezier_segments

    seg = bezier_segments(points, closed=closed)
    parts = [f"M {_fmt(seg[0, 0, 0])} {_fmt(seg[0, 0, 1])}"]
    parts += [
        f"Q {_fmt(c[0])} {_fmt(c[1])} {_fmt(e[0])} {_fmt(e[1])}"
        for c, e in zip(seg[:, 1], seg[:, 2], strict=True)
    ]
    if closed:
        parts.append("Z")
    return " ".join(parts)


def read_quadratic_path(source) -> tuple[np.ndarray, bool]:
    """Recover the control polygon from an SVG path of quadratic Bézier segments.

    Accepts path data (``"M ... Q ..."``), or an SVG document / file path whose
    first ``<path>`` is read with svgelements (its ``d`` data as written: the
    viewBox and transforms are not applied). The segments must join with
    ``C^1`` continuity as those of a uniform quadratic B-spline do; then the
    control polygon is the list of ``Q`` control points, extended by the
    reflected end points for an open path.

    Parameters
    ----------
    source : str or os.PathLike
        Path data, SVG text, or the path of an ``.svg`` file.

    Returns
    -------
    points : (N, 2) ndarray
        Control polygon.
    closed : bool
        Whether the path was closed (``Z``).

    Raises
    ------
    CurveFormatError
        If there is no path, a segment is not quadratic, or the segments are not
        joined like those of a uniform quadratic B-spline.

    Examples
    --------
    >>> pts, closed = read_quadratic_path("M 1 0 Q 2 0 2 1")
    >>> pts.tolist(), closed
    ([[0.0, 0.0], [2.0, 0.0], [2.0, 2.0]], False)
    """
    import svgelements

    text = str(source)
    if re.match(r"^\s*[Mm]", text):
        path = svgelements.Path(text)
    else:
        if "<svg" not in text:
            with open(text, encoding="utf-8") as fh:
                text = fh.read()
        doc = svgelements.SVG.parse(_stdio.StringIO(text), reify=False)
        paths = [e for e in doc.elements() if isinstance(e, svgelements.Path)]
        if not paths:
            raise CurveFormatError("SVG contains no <path> element")
        # the path data in user coordinates: viewBox and transforms are not applied
        path = svgelements.Path(paths[0].values["d"])
    quads = []
    closed = False
    for seg in path:
        if isinstance(seg, svgelements.Move):
            continue
        if isinstance(seg, svgelements.Close):
            closed = True
            continue
        if not isinstance(seg, svgelements.QuadraticBezier):
            raise CurveFormatError(
                f"path segment must be a quadratic Bezier (Q), got {type(seg).__name__}"
            )
        quads.append(
            [[seg.start.x, seg.start.y], [seg.control.x, seg.control.y], [seg.end.x, seg.end.y]]
        )
    if not quads:
        raise CurveFormatError("path has no quadratic Bezier segments")
    q = np.array(quads, dtype=float)
    ctrl = q[:, 1]
    scale = max(1.0, float(np.max(np.abs(q))))
    mids = 0.5 * (ctrl[:-1] + ctrl[1:])
    if closed:
        mids = np.concatenate([mids, [0.5 * (ctrl[-1] + ctrl[0])]])
        starts = np.roll(q[:, 0], -1, axis=0)
    else:
        starts = q[1:, 0]
    if np.max(np.abs(mids - starts), initial=0.0) > 1e-9 * scale:
        raise CurveFormatError(
            "segments do not join at the midpoints of their control points "
            "(not a uniform quadratic B-spline)"
        )
    if closed:
        return np.roll(ctrl, 1, axis=0), True
    first = 2.0 * q[0, 0] - ctrl[0]
    last = 2.0 * q[-1, 2] - ctrl[-1]
    return np.concatenate([[first], ctrl, [last]]), False


def path_document(paths: list[str], bounds) -> str:
    """An SVG document of unfilled paths (given as path data) in a viewBox around `bounds`.

    Parameters
    ----------
    paths : list of str
        Path data, one ``<path id="spline{i}">`` each.
    bounds : ((x0, y0), (x1, y1))
        Lower-left and upper-right corner of the drawing; the viewBox adds a 2 % margin.

    Returns
    -------
    str
        The document's text.

    Examples
    --------
    >>> path_document(["M 0 0 L 1 1"], ((0, 0), (1, 1))).splitlines()[2].split()[:3]
    ['<path', 'id="spline0"', 'd="M']
    """
    (x0, y0), (x1, y1) = bounds
    pad = 0.02 * max(x1 - x0, y1 - y0, 1e-12)
    view = f"{x0 - pad:.17g} {y0 - pad:.17g} {x1 - x0 + 2 * pad:.17g} {y1 - y0 + 2 * pad:.17g}"
    body = "\n".join(
        f'  <path id={quoteattr(f"spline{i}")} d={quoteattr(d)} fill="none" stroke="black" '
        'stroke-width="0.5" vector-effect="non-scaling-stroke"/>'
        for i, d in enumerate(paths)
    )
    return (
        '<?xml version="1.0" encoding="UTF-8"?>\n'
        f'<svg xmlns="http://www.w3.org/2000/svg" viewBox="{view}">\n{body}\n</svg>\n'
    )


def _point_xy(p) -> list[float]:
    return [float(p[0]), float(p[1])]


def bezier_path_data(segments, *, closed: bool = False) -> str:
    """SVG path data of a chain of quadratic (``Q``) or cubic (``C``) Bézier segments.

    Parameters
    ----------
    segments : (S, 3, 2) or (S, 4, 2) array_like
        Segment ``k`` starts where segment ``k - 1`` ends (as
        :attr:`curvesmith.curves.CurveFit.segments`).
    closed : bool, optional
        The path ends with ``Z`` (the last segment ends at the first point).

    Returns
    -------
    str
        17 significant digits: the control points read back exactly.

    Examples
    --------
    >>> bezier_path_data([[[0, 0], [1, 1], [2, 0]]])
    'M 0 0 Q 1 1 2 0'
    >>> bezier_path_data([[[0, 0], [1, 1], [2, 1], [3, 0]]], closed=True)
    'M 0 0 C 1 1 2 1 3 0 Z'
    """
    seg = np.asarray(segments, dtype=float)
    if seg.ndim != 3 or seg.shape[1] not in (3, 4) or seg.shape[2] != 2 or not len(seg):
        raise CurveFormatError(f"segments must have shape (S, 3, 2) or (S, 4, 2), got {seg.shape}")
    if not np.isfinite(seg).all():
        raise CurveFormatError("segments contain inf or nan")
    cmd = "Q" if seg.shape[1] == 3 else "C"
    parts = [f"M {_fmt(seg[0, 0, 0])} {_fmt(seg[0, 0, 1])}"]
    parts += [cmd + "".join(f" {_fmt(x)} {_fmt(y)}" for x, y in s[1:]) for s in seg]
    if closed:
        parts.append("Z")
    return " ".join(parts)


def read_bezier_paths(source) -> list[tuple[np.ndarray, bool]]:
    """Read the ``Q`` / ``C`` segments of every ``<path>`` of an SVG document.

    The inverse of :func:`bezier_path_data` in a :func:`path_document`: the path
    data as written, without viewBox or transforms; each subpath is one chain.

    Parameters
    ----------
    source : str or os.PathLike
        SVG text or the path of an ``.svg`` file.

    Returns
    -------
    list of (segments, closed)
        ``segments`` is ``(S, 3, 2)`` or ``(S, 4, 2)``.

    Raises
    ------
    CurveFormatError
        If a subpath mixes degrees or has another segment type.

    Examples
    --------
    >>> doc = path_document([bezier_path_data([[[0, 0], [1, 1], [2, 0]]])], ((0, 0), (2, 1)))
    >>> [(s.tolist(), c) for s, c in read_bezier_paths(doc)]
    [([[[0.0, 0.0], [1.0, 1.0], [2.0, 0.0]]], False)]
    """
    import svgelements

    text = str(source)
    if "<svg" not in text:
        with open(text, encoding="utf-8") as fh:
            text = fh.read()
    doc = svgelements.SVG.parse(_stdio.StringIO(text), reify=False)
    out: list[tuple[np.ndarray, bool]] = []
    for element in doc.elements():
        if not isinstance(element, svgelements.Path):
            continue
        chains: list[list] = []
        closes: list[bool] = []
        for seg in svgelements.Path(element.values["d"]):
            if isinstance(seg, svgelements.Move):
                chains.append([])
                closes.append(False)
                continue
            if not chains:
                chains.append([])
                closes.append(False)
            chain = chains[-1]
            if isinstance(seg, svgelements.Close):
                closes[-1] = True
            elif isinstance(seg, svgelements.QuadraticBezier):
                chain.append([_point_xy(seg.start), _point_xy(seg.control), _point_xy(seg.end)])
            elif isinstance(seg, svgelements.CubicBezier):
                chain.append(
                    [_point_xy(p) for p in (seg.start, seg.control1, seg.control2, seg.end)]
                )
            else:
                raise CurveFormatError(
                    f"path segment must be a Bezier (Q or C), got {type(seg).__name__}"
                )
        for chain, closed in zip(chains, closes, strict=True):
            if chain:
                if len({len(c) for c in chain}) != 1:
                    raise CurveFormatError("a subpath mixes quadratic and cubic segments")
                out.append((np.array(chain, dtype=float), closed))
    if not out:
        raise CurveFormatError("SVG contains no path of Bezier segments")
    return out
