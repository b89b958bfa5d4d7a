"""GeoJSON (RFC 7946) curves: LineString, Polygon, Multi* and GeometryCollections of them.

See :mod:`curvesmith.io` for the format's conventions.
"""

from __future__ import annotations

import json
import re
import uuid
import warnings
from collections.abc import Iterable
from typing import Any, Literal

import numpy as np

from .._validate import as_choice
from ..errors import CurveError, CurveFormatError
from ..geometry import _orientation  # the exact sign of the shoelace sum
from ._core import (
    Curve,
    Format,
    Source,
    _check_curves,
    _json_default,
    _read_text,
    open_destination,
    register,
    write_rows,
)

__all__ = ["GeoJSONCurves", "read_geojson", "write_geojson"]

_CURVE_TYPES = ("LineString", "Polygon", "MultiLineString", "MultiPolygon", "GeometryCollection")
_GEOMETRY_TYPES = (*_CURVE_TYPES, "Point", "MultiPoint")


def _describe(obj) -> str:
    if isinstance(obj, dict):
        if "type" in obj:
            return f"an object of type {obj['type']!r}"
        return f"an object with keys {sorted(obj)[:6]} and no 'type'"
    if isinstance(obj, list):
        return f"an array of {len(obj)} values"
    return f"a {type(obj).__name__} ({obj!r:.40})"


def _reject_constant(token: str):
    raise CurveFormatError(f"{token} is not valid JSON (numbers must be finite)")


def crs_label(crs: Any) -> str | None:
    """The name in a (2008 GeoJSON) ``crs`` member, or None.

    The member is ``{"type": "name", "properties": {"name": ...}}``.
    """
    props = crs.get("properties") if isinstance(crs, dict) else None
    label = props.get("name") if isinstance(props, dict) else None
    return label if isinstance(label, str) else None


def is_crs84(crs: Any) -> bool:
    """Whether a ``crs`` member names OGC's CRS84: RFC 7946's longitude/latitude."""
    label = crs_label(crs)
    return label is not None and label.endswith("CRS84")


class GeoJSONCurves(list):
    """The curves of a GeoJSON file read with ``others="keep"``, and what is not a curve.

    A ``list`` of :class:`Curve`; :func:`write_geojson` writes `others` back at their
    positions and `crs` as the collection's ``crs`` member, so that smoothing a layer with
    Points or NULL geometries (RFC 7946 allows ``"geometry": null``) loses nothing.

    Attributes
    ----------
    others : dict of int to dict
        Features without a curve geometry (NULL, Point, MultiPoint, a GeometryCollection
        of points only), by feature index, as read.
    members : dict of (int, int) to dict
        Point and MultiPoint members of GeometryCollections that also hold curves, by
        (feature index, member index), as read: written back at their places.
    crs : dict or None
        The (pre-RFC 7946) ``crs`` member of the file.
    """

    def __init__(self, curves=(), others=None, crs=None, members=None):
        super().__init__(curves)
        self.others: dict[int, dict] = dict(others or {})
        self.members: dict[tuple[int, int], dict] = dict(members or {})
        self.crs = crs

    def with_curves(self, curves) -> GeoJSONCurves:
        """The same others, members and crs with other curves (e.g. the smoothed ones)."""
        return GeoJSONCurves(curves, self.others, self.crs, self.members)


class _GeoJSONReader:
    def __init__(self, name: str, keep: bool = False):
        self.name = name
        self.keep = keep
        self.others: dict[int, dict] = {}
        self.members: dict[tuple[int, int], dict] = {}
        self.crs = None
        self.curves: list[Curve] = []

    def fail(self, where: str, message: str) -> CurveFormatError:
        return CurveFormatError(
            f"{self.name}: {where}: {message}" if where else f"{self.name}: {message}"
        )

    def top(self, obj) -> None:
        if not isinstance(obj, dict) or "type" not in obj:
            raise self.fail(
                "", f"expected a GeoJSON object with a 'type' member, found {_describe(obj)}"
            )
        kind = obj["type"]
        crs = obj.get("crs")
        self.crs = crs
        if crs is not None and not self.keep and not is_crs84(crs):
            warnings.warn(
                f"{self.name}: the 'crs' member ({crs_label(crs) or crs!r}) is not kept; files "
                "written from these curves have none, and RFC 7946 readers will take the "
                "coordinates as WGS 84 longitude/latitude",
                UserWarning,
                stacklevel=4,
            )
        if kind == "FeatureCollection":
            features = obj.get("features")
            if not isinstance(features, list):
                raise self.fail(
                    "",
                    "the FeatureCollection's 'features' must be an array, "
                    f"found {_describe(features)}",
                )
            for i, feat in enumerate(features):
                self.feature(feat, i)
            if not features:
                raise self.fail("", "the FeatureCollection has no features, so no curves")
        elif kind == "Feature":
            self.feature(obj, 0)
        elif kind in _GEOMETRY_TYPES:
            self.geometry(obj, "geometry", 0, {}, None, None)
        else:
            raise self.fail(
                "",
                f"unknown GeoJSON type {kind!r}; expected FeatureCollection, Feature or one of "
                f"{', '.join(_GEOMETRY_TYPES)}",
            )

    def feature(self, feat, i: int) -> None:
        where = f"feature {i}"
        if not isinstance(feat, dict) or feat.get("type") != "Feature":
            raise self.fail(where, f"expected a Feature object, found {_describe(feat)}")
        props = feat.get("properties")
        if props is None:
            props = {}
        if not isinstance(props, dict):
            raise self.fail(
                where, f"properties must be an object or null, found {_describe(props)}"
            )
        geom = feat.get("geometry")
        kind = geom.get("type") if isinstance(geom, dict) else None
        if self.keep and (
            geom is None or kind in ("Point", "MultiPoint") or _points_only(geom) or _empty(geom)
        ):
            self.others[i] = feat
            return
        if geom is None:
            raise self.fail(
                where,
                "the geometry is null; curvesmith reads only curves (LineString, Polygon, "
                "MultiLineString, MultiPolygon)",
            )
        fid = feat.get("id")
        if fid is not None and (isinstance(fid, bool) or not isinstance(fid, str | int | float)):
            raise self.fail(where, f"id must be a string or a number, found {_describe(fid)}")
        self.geometry(geom, where, i, props, fid, None)

    def positions(self, coords, where: str) -> np.ndarray:
        if not isinstance(coords, list) or not all(isinstance(p, list) for p in coords):
            raise self.fail(
                where, f"coordinates must be an array of positions, found {_describe(coords)}"
            )
        sizes = {len(p) for p in coords}
        if sizes - {2, 3}:
            k = next(k for k, p in enumerate(coords) if len(p) not in (2, 3))
            raise self.fail(
                where,
                f"positions must have 2 or 3 numbers (x, y[, z]), found {coords[k]} "
                f"(position {k}, {len(coords[k])} number{'s' if len(coords[k]) != 1 else ''})",
            )
        if len(sizes) > 1:
            raise self.fail(where, "positions mix 2 and 3 coordinates")
        if not all(
            isinstance(v, int | float) and not isinstance(v, bool) for p in coords for v in p
        ):
            raise self.fail(where, "coordinates must be numbers")
        return np.array(coords, dtype=np.float64).reshape(len(coords), -1)

    def add(self, where: str, pts: np.ndarray, closed: bool, **fields) -> None:
        try:
            self.curves.append(Curve(pts, closed=closed, **fields))
        except CurveError as exc:
            raise self.fail(where, str(exc)) from None

    def array(self, coords, where: str, what: str) -> list:
        if not isinstance(coords, list):
            raise self.fail(
                where, f"coordinates must be an array of {what}, found {_describe(coords)}"
            )
        if not coords:
            raise self.fail(where, f"the geometry is empty (no {what}), so it has no curves")
        return coords

    def geometry(self, geom, where, feature, props, fid, member) -> None:
        if not isinstance(geom, dict) or "type" not in geom:
            raise self.fail(where, f"expected a geometry object, found {_describe(geom)}")
        kind = geom["type"]
        common = {"properties": props, "feature": feature, "feature_id": fid, "member": member}
        coords = geom.get("coordinates")
        if kind in ("Point", "MultiPoint") and self.keep and member is not None:
            self.members[(feature, member)] = geom  # written back in its collection
            return
        if kind in ("Point", "MultiPoint"):
            raise self.fail(
                where,
                f"a {kind} is not a curve; curvesmith reads LineString, Polygon, MultiLineString, "
                "MultiPolygon (and GeometryCollections of them)",
            )
        if kind == "GeometryCollection":
            if member is not None:
                raise self.fail(
                    where, "nested GeometryCollections are not supported (RFC 7946 3.1.8)"
                )
            members = self.array(geom.get("geometries"), where, "geometries")
            for j, g in enumerate(members):
                self.geometry(g, f"{where}, member {j}", feature, props, fid, j)
            return
        if kind == "LineString":
            pts = self.positions(self.array(coords, where, "positions"), where)
            closed = len(pts) >= 4 and bool(np.array_equal(pts[0], pts[-1]))
            self.add(where, pts, closed, kind=kind, **common)
        elif kind == "MultiLineString":
            for k, line in enumerate(self.array(coords, where, "lines")):
                w = f"{where} (MultiLineString part {k})"
                pts = self.positions(self.array(line, w, "positions"), w)
                closed = len(pts) >= 4 and bool(np.array_equal(pts[0], pts[-1]))
                self.add(w, pts, closed, kind=kind, part=k, **common)
        elif kind == "Polygon":
            self.polygon(self.array(coords, where, "rings"), where, kind, 0, common)
        elif kind == "MultiPolygon":
            for k, poly in enumerate(self.array(coords, where, "polygons")):
                w = f"{where} (MultiPolygon part {k})"
                self.polygon(self.array(poly, w, "rings"), w, kind, k, common)
        else:
            raise self.fail(
                where,
                f"unknown geometry type {kind!r}; expected one of {', '.join(_GEOMETRY_TYPES)}",
            )

    def polygon(self, rings, where, kind, part, common) -> None:
        for r, ring in enumerate(rings):
            w = f"{where} ring {r}" + (" (exterior)" if r == 0 else " (hole)")
            pts = self.positions(self.array(ring, w, "positions"), w)
            self.add(w, pts, True, kind=kind, part=part, ring=r, **common)


def _empty(geom) -> bool:
    """Whether `geom` is an empty curve geometry or collection (``"coordinates": []``)."""
    if not isinstance(geom, dict):
        return False
    key = "geometries" if geom.get("type") == "GeometryCollection" else "coordinates"
    return geom.get("type") in _GEOMETRY_TYPES and geom.get(key) == []


def _points_only(geom) -> bool:
    """Whether `geom` is a GeometryCollection of Points and MultiPoints only (none: no)."""
    if not isinstance(geom, dict) or geom.get("type") != "GeometryCollection":
        return False
    members = geom.get("geometries")
    return (
        isinstance(members, list)
        and bool(members)
        and all(isinstance(g, dict) and g.get("type") in ("Point", "MultiPoint") for g in members)
    )


def read_geojson(source: Source, *, others: Literal["error", "keep"] = "error") -> list[Curve]:
    """Read curves from a GeoJSON file (RFC 7946).

    Parameters
    ----------
    source : str or path-like or text file object
        A FeatureCollection, a Feature or a bare geometry.
    others : {"error", "keep"}, optional
        Features whose geometry is NULL, empty, a Point or a MultiPoint: an error (default), or
        kept aside: the result is then a :class:`GeoJSONCurves` holding them (and the
        ``crs`` member, kept without a warning) for :func:`write_geojson` to write back.

    Returns
    -------
    list of Curve
        One curve per line and per ring, in file order, with ``feature``,
        ``part``, ``ring``, ``member``, ``kind``, ``properties`` and
        ``feature_id`` describing where it came from (see the module docstring).

    Raises
    ------
    CurveFormatError
        For malformed JSON (with line and column), a structure that is not
        GeoJSON (naming what was found), Point/MultiPoint, null or empty
        geometries, and curves with too few points.

    Examples
    --------
    >>> import io
    >>> text = '''{"type": "Polygon", "coordinates": [
    ...     [[0, 0], [4, 0], [4, 4], [0, 4], [0, 0]],
    ...     [[1, 1], [1, 2], [2, 2], [2, 1], [1, 1]]]}'''
    >>> [(c.ring, len(c.points), c.closed) for c in read_geojson(io.StringIO(text))]
    [(0, 4, True), (1, 4, True)]
    """
    as_choice(others, ("error", "keep"), name="others")
    text, name = _read_text(source)
    try:
        obj = json.loads(text, parse_constant=_reject_constant)
    except json.JSONDecodeError as exc:
        raise CurveFormatError(
            f"{name}: malformed JSON at line {exc.lineno}, column {exc.colno}: {exc.msg}"
        ) from None
    except CurveFormatError as exc:
        raise CurveFormatError(f"{name}: {exc}") from None
    reader = _GeoJSONReader(name, keep=others == "keep")
    reader.top(obj)
    if others == "keep":
        if not reader.curves:
            raise CurveFormatError(
                f"{name}: none of the {len(reader.others)} features has a curve geometry "
                "(LineString, Polygon, MultiLineString, MultiPolygon)"
            )
        return GeoJSONCurves(reader.curves, reader.others, reader.crs, reader.members)
    return reader.curves


class _Coords:
    """Coordinate arrays of the features being written, by placeholder.

    Features are serialised by :func:`json.dumps` with a placeholder string in place of
    each position array; the writer then streams the positions of each placeholder chunk
    by chunk (:func:`format_rows`), so no feature's coordinates are ever held as one
    list of Python floats or one string. ``%r`` of a float is the text ``json.dumps``
    writes for it, so the file is byte for byte what ``json.dumps`` of the whole
    collection gives.
    """

    def __init__(self) -> None:
        self.nonce = uuid.uuid4().hex
        self.arrays: list[tuple[np.ndarray, bool, bool]] = []
        self.pattern = re.compile(rf'"\\u0000{self.nonce}:(\d+)\\u0000"')

    def add(self, points: np.ndarray, close: bool, reverse: bool = False) -> str:
        """A placeholder for `points` (`close`: repeat the first; `reverse`: rest backwards)."""
        self.arrays.append((points, close, reverse))
        return f"\x00{self.nonce}:{len(self.arrays) - 1}\x00"

    def write(self, out, text: str) -> None:
        """Write `text` (JSON with placeholders) with the positions streamed in."""
        pos = 0
        for m in self.pattern.finditer(text):
            out.write(text[pos : m.start()])
            k = int(m.group(1))
            points, close, reverse = self.arrays[k]
            self.arrays[k] = (np.empty((0, 2)), False, False)  # written: let the array go
            one = ", ".join(["%r"] * points.shape[1])
            out.write("[")
            out.write(f"[{one}]" % tuple(points[0].tolist()))
            rest = points[:0:-1] if reverse else points[1:]  # views: no copy of the ring
            write_rows(out, rest, f", [{one}]")
            if close:
                out.write(f", [{one}]" % tuple(points[0].tolist()))
            out.write("]")
            pos = m.end()
        out.write(text[pos:])


def _oriented_ring(coords: _Coords, points: np.ndarray, ccw: bool, orient: bool) -> str:
    reverse = False
    if orient:
        sign = _orientation(points)
        reverse = (sign < 0 and ccw) or (sign > 0 and not ccw)
    return coords.add(points, True, reverse)


def _line_coords(coords: _Coords, c: Curve) -> str:
    if c.closed:
        return coords.add(c.points, True)
    if len(c.points) >= 4 and np.array_equal(c.points[0], c.points[-1]):
        # GeoJSON has no closedness flag for LineStrings: such a line reads back as a ring.
        warnings.warn(
            f"an open curve of feature {c.feature} ends where it starts; GeoJSON readers "
            "(curvesmith included) will read it back as a closed ring",
            UserWarning,
            stacklevel=4,
        )
    return coords.add(c.points, False)


def _polygon_coords(coords: _Coords, rings: list[Curve], where: str, orient: bool) -> list:
    rings = sorted(rings, key=lambda c: c.ring)
    if rings[0].ring != 0:
        raise CurveFormatError(f"{where}: the polygon has holes but no exterior ring (ring 0)")
    return [_oriented_ring(coords, c.points, c.ring == 0, orient) for c in rings]


def _unique(curves: list[Curve], key, where: str) -> None:
    seen = set()
    for c in curves:
        k = key(c)
        if k in seen:
            raise CurveFormatError(
                f"{where}: two curves have the same (member, part, ring) {k}; give curves of "
                "different geometries distinct feature indices, e.g. curve.replace(feature=i)"
            )
        seen.add(k)


def _geometry(coords: _Coords, curves: list[Curve], where: str, orient: bool) -> dict:
    kinds = {c.kind for c in curves}
    if len(kinds) > 1:
        raise CurveFormatError(
            f"{where}: curves of one geometry have different kinds {sorted(kinds)}; set "
            "member= to make a GeometryCollection or give them distinct features"
        )
    kind = kinds.pop()
    if kind == "LineString":
        if len(curves) > 1:
            raise CurveFormatError(
                f"{where}: {len(curves)} curves of kind LineString in one geometry"
            )
        return {"type": kind, "coordinates": _line_coords(coords, curves[0])}
    if kind == "MultiLineString":
        return {
            "type": kind,
            "coordinates": [_line_coords(coords, c) for c in sorted(curves, key=lambda c: c.part)],
        }
    if kind == "Polygon":
        return {"type": kind, "coordinates": _polygon_coords(coords, curves, where, orient)}
    parts: dict[int, list[Curve]] = {}
    for c in curves:
        parts.setdefault(c.part, []).append(c)
    return {
        "type": kind,
        "coordinates": [
            _polygon_coords(coords, parts[k], f"{where} part {k}", orient) for k in sorted(parts)
        ],
    }


def _features(
    coords: _Coords, curves: list[Curve], orient: bool, kept: dict[tuple[int, int], dict]
) -> list[dict]:
    groups: dict[int, list[Curve]] = {}
    for c in curves:
        groups.setdefault(c.feature, []).append(c)
    kept_of: dict[int, dict[int, dict]] = {}  # feature -> member -> the kept geometry
    for (f, m), g in kept.items():
        kept_of.setdefault(f, {})[m] = g
    features = []
    for feature, group in groups.items():
        where = f"feature {feature}"
        first = group[0]
        for c in group[1:]:
            if c.properties != first.properties or c.feature_id != first.feature_id:
                raise CurveFormatError(
                    f"{where}: its curves have different properties or feature ids; give them "
                    "distinct feature indices to write them as separate features"
                )
        _unique(group, lambda c: (c.member, c.part, c.ring), where)
        members = {c.member for c in group}
        if None in members and len(members) > 1:
            raise CurveFormatError(
                f"{where}: some curves are members of a GeometryCollection and some are not"
            )
        if None in members:
            geometry = _geometry(coords, group, where, orient)
        else:
            by_member: dict[int, list[Curve]] = {}
            for c in group:
                by_member.setdefault(int(c.member or 0), []).append(c)  # every member an int
            built = {
                m: _geometry(coords, by_member[m], f"{where} member {m}", orient) for m in by_member
            }
            # the collection's points, kept aside as read, at their places
            built.update({m: g for m, g in kept_of.get(feature, {}).items() if m not in built})
            geometry = {
                "type": "GeometryCollection",
                "geometries": [built[m] for m in sorted(built)],
            }
        feat: dict[str, Any] = {"type": "Feature"}
        if first.feature_id is not None:
            feat["id"] = first.feature_id
        feat["properties"] = first.properties
        feat["geometry"] = geometry
        features.append(feat)
    return features


def write_geojson(curves: Iterable[Curve], dest: Source, *, orient: bool = True) -> None:
    """Write curves as a GeoJSON FeatureCollection (RFC 7946).

    Parameters
    ----------
    curves : iterable of Curve
        Curves; their ``feature``, ``member``, ``part``, ``ring`` and ``kind``
        say which geometry of which feature they belong to.
    dest : str or path-like or text file object
        The file.
    orient : bool, optional
        Write exterior rings counter-clockwise and holes clockwise (RFC 7946
        section 3.1.6), reversing rings as needed while keeping their first
        vertex. With False rings keep their vertex order.

    Raises
    ------
    CurveFormatError
        If curves of one feature disagree (properties, kinds, duplicate
        (member, part, ring), a polygon without exterior ring) or a property
        cannot be written as JSON (NaN, unknown objects).

    Examples
    --------
    >>> import io
    >>> cw = Curve([[0, 0], [0, 1], [1, 1], [1, 0]], closed=True, kind="Polygon")
    >>> buf = io.StringIO()
    >>> write_geojson([cw], buf)
    >>> json.loads(buf.getvalue())["features"][0]["geometry"]["coordinates"][0]
    [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0], [0.0, 0.0]]
    """
    others = getattr(curves, "others", {}) or {}
    kept = getattr(curves, "members", {}) or {}
    crs = getattr(curves, "crs", None)
    curves = _check_curves(curves)
    coords = _Coords()
    features = _features(coords, curves, bool(orient), kept)
    if others:  # features without curves go back to their places among the others
        keyed = list(zip(dict.fromkeys(c.feature for c in curves), features, strict=True))
        keyed += list(others.items())
        features = [f for _, f in sorted(keyed, key=lambda kf: kf[0])]
    try:
        texts = [
            json.dumps(f, allow_nan=False, ensure_ascii=False, default=_json_default)
            for f in features
        ]
    except (TypeError, ValueError) as exc:
        raise CurveFormatError(f"cannot write the properties as JSON: {exc}") from None
    head = '{"type": "FeatureCollection", '
    if crs is not None:
        head += f'"crs": {json.dumps(crs, ensure_ascii=False)}, '
    with open_destination(dest) as out:
        out.write(head + '"features": [\n')
        for k, text in enumerate(texts):
            coords.write(out, text if k == 0 else ",\n" + text)
        out.write("\n]}\n")


FORMAT = register(
    Format("geojson", "GeoJSON", (".geojson", ".json"), read_geojson, write_geojson, ("json",))
)
