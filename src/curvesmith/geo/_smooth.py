"""Smoothing of shapely geometries, GeoSeries and GeoDataFrames (one feature at a time)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import CurveError, require
from ..geometry import _signed_area
from ._engine import Level, levels_for, resolve_arcs

__all__ = ["GeometryReduction", "SmoothResult", "smooth"]

METHODS = ("cca", "chaikin")


@dataclass(frozen=True)
class GeometryReduction:
    """A piece of a ring or line that was smoothed less so that the output stays valid.

    Attributes
    ----------
    feature : int
        Position of the feature in the input (0 for a single geometry).
    ring : int
        Index of the ring or line inside the feature, in the order of
        ``shapely.get_parts`` then ``shapely.get_rings`` (exterior before interiors).
    start, stop : int
        First and last vertex (inclusive, input numbering after dropping repeated points)
        of the reduced piece.
    iterations : int
        Iterations applied to the piece (0: the piece keeps its input vertices).
    alpha_scale : float
        Factor applied to alpha for the piece.
    """

    feature: int
    ring: int
    start: int
    stop: int
    iterations: int
    alpha_scale: float


@dataclass(frozen=True)
class SmoothResult:
    """Result of :func:`smooth` with ``full_output=True``.

    Attributes
    ----------
    geometry : object
        The smoothed input, of the input's type (shapely geometry, ndarray, GeoSeries or
        GeoDataFrame).
    reductions : tuple of GeometryReduction
        Every piece smoothed at less than the requested strength, to keep rings simple,
        holes off their shells and polygon parts apart. Empty when none was needed.
    n_curves : int
        Number of rings and lines smoothed.
    max_area_change : float
        Largest relative change ``|A' - A| / |A|`` of a ring's signed area (closed rings)
        or of the area between a line and its chord (open lines with non-zero such area).
        With ``method="cca"`` this is round-off (CCA keeps these areas exactly).
    """

    geometry: Any
    reductions: tuple[GeometryReduction, ...]
    n_curves: int
    max_area_change: float


def _shapely():
    return require("shapely", "geo", "geo.smooth")


def make_smoother(method: str, alpha: Any) -> Callable[[np.ndarray, bool, Level], np.ndarray]:
    """Return ``f(points, closed, level)`` smoothing one ring (closed) or piece (fixed ends)."""
    if method == "cca":
        from .. import cca

        def f(pts: np.ndarray, closed: bool, level: Level) -> np.ndarray:
            out = cca.smooth(
                pts,
                closed=closed,
                iterations=level.iterations,
                alpha=scale_alpha(alpha, level.alpha_scale),
            )
            return out if closed else _pin_ends(out, pts)

        return f
    from .. import subdivision

    def g(pts: np.ndarray, closed: bool, level: Level) -> np.ndarray:
        out = subdivision.chaikin(
            pts, closed=closed, iterations=level.iterations, preserve_endpoints=not closed
        )
        return out if closed else _pin_ends(out, pts)

    return g


def smooth_open_many(arcs: list[np.ndarray], *, alpha: Any, level: Level) -> list[np.ndarray]:
    """CCA of many open polylines (fixed ends) in one call, chained with anchors.

    The polylines are concatenated (a shared end vertex once) and every end vertex is an
    anchor, so that each one is smoothed as its own polyline (Gordon 2010, section 5,
    anchor points); an edge joining two consecutive polylines lies between two anchors and
    is dropped again. This replaces thousands of small calls by one vectorized call. The
    output of each polyline is located by its end anchors (returned exactly); should that
    ever be ambiguous, the call falls back to one call per polyline.

    ``cca.smooth`` computes relative to the first vertex of its input, so a polyline
    chained with other neighbours is computed with other rounding, and where one of
    CCA's discrete local decisions (a restriction of Definition 2, a balanced Fig. 11
    edge) sits on its threshold the result can differ (measured on the US counties:
    1e-11 relative typically, a visibly different cut on 20 of 1181 arcs when chaining
    all of them). Callers therefore always chain the same groups
    (:data:`curvesmith.geo._coverage.ARC_BLOCK` consecutive arcs), so that results are
    reproducible in one process and on Dask alike. The areas are exact either way.
    """
    from scipy.spatial import cKDTree

    from .. import cca

    if not arcs:
        return []
    a = scale_alpha(alpha, level.alpha_scale)
    return _open_chunk(arcs, a, level.iterations, cca, cKDTree)


def _open_chunk(arcs, alpha, iterations, cca, kdtree) -> list[np.ndarray]:
    parts, first, last = [], [], []
    n = 0
    prev_end = None
    for xy in arcs:
        if prev_end is not None and np.array_equal(xy[0], prev_end):
            first.append(n - 1)
            parts.append(xy[1:])
        else:
            first.append(n)
            parts.append(xy)
        n += len(parts[-1])
        last.append(n - 1)
        prev_end = xy[-1]
    pts = np.concatenate(parts)
    anchors = np.unique(np.concatenate([first, last]))
    res = cca.smooth(pts, closed=False, iterations=iterations, alpha=alpha, anchors=anchors)
    # locate the anchors (fixed points) in the output, in order
    anc = pts[anchors]
    tol = 64 * np.finfo(float).eps * (np.abs(anc).max(axis=1) + np.abs(pts[0]).max())
    d, k = kdtree(anc).query(res, distance_upper_bound=float(tol.max()))
    hit = np.isfinite(d)
    hit[hit] = d[hit] <= tol[k[hit]]
    pos = np.nonzero(hit)[0]
    # the same node can be an anchor twice (an arc from a node back to it): compare points
    if len(pos) != len(anchors) or np.any(np.abs(res[pos] - anc).max(axis=1) > tol):
        return [
            _pin_ends(cca.smooth(xy, closed=False, iterations=iterations, alpha=alpha), xy)
            for xy in arcs
        ]
    where = np.empty(n, dtype=np.int64)
    where[anchors] = pos
    return [
        _pin_ends(res[where[f] : where[e] + 1].copy(), xy)
        for f, e, xy in zip(first, last, arcs, strict=True)
    ]


def _pin_ends(out: np.ndarray, pts: np.ndarray) -> np.ndarray:
    """Put the fixed end vertices back bit for bit (smoothers may round them by an ulp).

    Neighbouring arcs of a coverage meet at these nodes; exact equality is what keeps the
    rebuilt coverage edge-matched.
    """
    out[0] = pts[0]
    out[-1] = pts[-1]
    return out


def scale_alpha(alpha: Any, scale: float) -> Any:
    """Alpha multiplied by ``scale`` (a float, a callable of the angle, or ``"regular"``)."""
    if scale == 1.0:
        return alpha
    if isinstance(alpha, str):
        from .. import cca

        return lambda angle: scale * np.asarray(cca.alpha_profile(angle))
    if callable(alpha):
        return lambda angle: scale * alpha(angle)
    return float(alpha) * scale


def check_method(method: str, iterations: int, alpha: Any) -> int:
    """Validate the common smoothing options; return iterations as int."""
    from .._validate import as_int

    if method not in METHODS:
        raise CurveError(f"method must be one of {', '.join(METHODS)}, got {method!r}")
    iterations = as_int(iterations, name="iterations", minimum=0)
    if method == "cca" and isinstance(alpha, str) and alpha != "regular":
        raise CurveError(f"alpha must be 'regular', a float or a callable, got {alpha!r}")
    if method == "cca" and not isinstance(alpha, str) and not callable(alpha):
        try:
            a = float(alpha)
        except (TypeError, ValueError):
            raise CurveError(
                f"alpha must be 'regular', a float or a callable, got {alpha!r}"
            ) from None
        if not 0.0 < a < 1.0 / 3.0:
            raise CurveError(f"alpha must be in (0, 1/3), got {alpha!r}")
    return iterations


# --------------------------------------------------------------------------------------------
# input / output containers


def as_geometry_array(geometry: Any) -> tuple[np.ndarray, Callable[[np.ndarray], Any]]:
    """Flatten the accepted inputs to an object array and return a function to wrap back."""
    shapely = _shapely()
    if isinstance(geometry, shapely.Geometry):
        return np.array([geometry], dtype=object), lambda arr: arr[0]
    try:
        import geopandas as gpd
    except ImportError:  # pragma: no cover - geopandas is part of the geo extra
        gpd = None
    if gpd is not None and isinstance(geometry, gpd.GeoDataFrame):
        frame = geometry

        def wrap_frame(arr):
            out = frame.copy()
            out[frame.geometry.name] = gpd.GeoSeries(arr, index=frame.index, crs=frame.crs)
            return out

        return np.asarray(frame.geometry.values, dtype=object), wrap_frame
    if gpd is not None and isinstance(geometry, gpd.GeoSeries):
        series = geometry
        return (
            np.asarray(series.values, dtype=object),
            lambda arr: gpd.GeoSeries(arr, index=series.index, crs=series.crs, name=series.name),
        )
    arr = np.asarray(geometry, dtype=object)
    if arr.ndim != 1:
        raise CurveError(
            f"geometry must be a shapely geometry, a 1-D sequence of them, a GeoSeries or a "
            f"GeoDataFrame, got an array of shape {arr.shape}"
        )
    ok = np.array([g is None or isinstance(g, shapely.Geometry) for g in arr], dtype=bool)
    if not ok.all():
        k = int(np.nonzero(~ok)[0][0])
        raise CurveError(
            f"geometry[{k}] must be a shapely geometry or None, got {type(arr[k]).__name__}"
        )
    return arr, lambda out: out


def prepare(geoms: np.ndarray, *, make_valid: bool, what: str = "geometry") -> np.ndarray:
    """Check types, 2D-ness and validity; drop repeated vertices. Returns a new array."""
    shapely = _shapely()
    geoms = np.asarray(geoms, dtype=object).copy()
    present = np.array([g is not None for g in geoms], dtype=bool)
    if not present.any():
        return geoms
    g = geoms[present]
    pos = np.nonzero(present)[0]
    types = shapely.get_type_id(g)
    is_point = (types == shapely.GeometryType.POINT) | (types == shapely.GeometryType.MULTIPOINT)
    nonempty = ~shapely.is_empty(g)
    if np.any(is_point & nonempty):
        k = int(pos[np.nonzero(is_point & nonempty)[0][0]])
        raise CurveError(
            f"{what}[{k}] is a {geoms[k].geom_type}: only lines and polygons can be smoothed"
        )
    has_z = shapely.has_z(g)
    if np.any(has_z & nonempty):
        k = int(pos[np.nonzero(has_z & nonempty)[0][0]])
        raise CurveError(
            f"{what}[{k}] has Z coordinates; curvesmith.geo smooths planar geometries "
            f"(drop Z with shapely.force_2d)"
        )
    valid = shapely.is_valid(g)
    if not valid.all():
        if not make_valid:
            k = int(np.nonzero(~valid)[0][0])
            reason = shapely.is_valid_reason(g[k])
            raise CurveError(
                f"{what}[{int(pos[k])}] is not valid ({reason}); repair it first or pass "
                f"make_valid=True to repair it with shapely.make_valid"
            )
        fixed = shapely.make_valid(g[~valid], method="structure", keep_collapsed=False)
        g = g.copy()
        g[~valid] = fixed
    g = shapely.remove_repeated_points(g, 0.0)
    geoms[present] = g
    return geoms


# --------------------------------------------------------------------------------------------
# the smoothing itself


def _signed_areas(rings: list[np.ndarray]) -> np.ndarray:
    """Signed areas of many rings (listed without the closing vertex), vectorized."""
    if not rings:
        return np.zeros(0)
    xy = np.concatenate(rings)
    lens = np.array([len(r) for r in rings])
    start = np.concatenate([[0], np.cumsum(lens)[:-1]])
    xy = xy - np.repeat(xy[start], lens, axis=0)  # local origin: no cancellation
    nxt = np.arange(len(xy)) + 1
    nxt[start + lens - 1] = start  # wrap around within each ring
    # the trapezoid form of geometry.signed_area, ring by ring
    terms = (xy[:, 0] - xy[nxt, 0]) * (xy[:, 1] + xy[nxt, 1])
    return 0.5 * np.add.reduceat(terms, start)


def _rel(a: float, b: float, scale: float) -> float:
    return abs(a - b) / scale if scale > 0 else 0.0


class _Curves:
    """All rings/lines of a set of features, in ragged form, to smooth them in one pass."""

    def __init__(self):
        self.xy: list[np.ndarray] = []
        self.closed: list[bool] = []
        self.feature: list[int] = []
        self.ring: list[int] = []
        self.part_ring: list[bool] = []  # True for polygon rings (must stay disjoint)


def _smooth_feature_array(
    geoms: np.ndarray,
    *,
    method: str,
    iterations: int,
    alpha: Any,
) -> tuple[np.ndarray, list[GeometryReduction], int, float]:
    shapely = _shapely()
    out = geoms.copy()
    smoother = make_smoother(method, alpha)
    levels = levels_for(iterations, scalable=(method == "cca"))
    reductions: list[GeometryReduction] = []
    n_curves = 0
    max_change = 0.0
    if iterations == 0:
        return out, reductions, 0, 0.0
    present = np.array([g is not None for g in geoms], dtype=bool)
    idx = np.nonzero(present)[0]
    if len(idx) == 0:
        return out, reductions, 0, 0.0
    g = geoms[idx]
    types = shapely.get_type_id(g)
    empty = shapely.is_empty(g)
    T = shapely.GeometryType
    poly = ~empty & ((types == T.POLYGON) | (types == T.MULTIPOLYGON))
    line = ~empty & ((types == T.LINESTRING) | (types == T.MULTILINESTRING))
    ring = ~empty & (types == T.LINEARRING)
    coll = ~empty & (types == T.GEOMETRYCOLLECTION)

    for mask, smooth_kind in ((poly, _smooth_polygonal), (line, _smooth_lineal)):
        if mask.any():
            res, red, n, ch = smooth_kind(g[mask], idx[mask], smoother, levels)
            out[idx[mask]] = res
            reductions += red
            n_curves += n
            max_change = max(max_change, ch)
    for k in idx[ring]:
        res, red, n, ch = _smooth_linearring(geoms[k], int(k), smoother, levels)
        out[k] = res
        reductions += red
        n_curves += n
        max_change = max(max_change, ch)
    for k in idx[coll]:
        parts = shapely.get_parts(geoms[k])
        sub, red, n, ch = _smooth_feature_array(
            parts, method=method, iterations=iterations, alpha=alpha
        )
        out[k] = shapely.geometrycollections(list(sub))
        reductions += [
            GeometryReduction(int(k), r.ring, r.start, r.stop, r.iterations, r.alpha_scale)
            for r in red
        ]
        n_curves += n
        max_change = max(max_change, ch)
    return out, reductions, n_curves, max_change


def _smooth_polygonal(g, feat_index, smoother, levels):
    shapely = _shapely()
    T = shapely.GeometryType
    was_polygon = shapely.get_type_id(g) == T.POLYGON
    gtype, coords, offsets = shapely.to_ragged_array(g)
    if gtype == T.POLYGON:
        (ring_off, poly_off), geom_off = offsets, np.arange(len(g) + 1)
    else:
        ring_off, poly_off, geom_off = offsets
    n_rings = len(ring_off) - 1
    ring_poly = np.searchsorted(poly_off, np.arange(n_rings), side="right") - 1
    ring_geom = np.searchsorted(geom_off, ring_poly, side="right") - 1
    first_ring_of_geom = np.searchsorted(ring_geom, np.arange(len(g)))
    full = levels[0]
    rings = [coords[ring_off[r] : ring_off[r + 1] - 1] for r in range(n_rings)]
    new = [smoother(xy, True, full) for xy in rings]

    def build(new_rings):
        lens = np.array([len(x) + 1 for x in new_rings], dtype=np.int64)
        offs = np.concatenate([[0], np.cumsum(lens)])
        xy = np.concatenate([np.vstack([x, x[:1]]) for x in new_rings])
        mp = shapely.from_ragged_array(T.MULTIPOLYGON, xy, (offs, poly_off, geom_off))
        res = mp.copy()
        res[was_polygon] = shapely.get_geometry(mp[was_polygon], 0)
        return res

    res = build(new)
    rings_per_geom = np.bincount(ring_geom, minlength=len(g))
    hard = (rings_per_geom > 1) | ~shapely.is_valid(res)
    reductions: list[GeometryReduction] = []
    if hard.any():
        sel = np.nonzero(hard[ring_geom])[0]
        reductions += _resolve_parts(
            rings,
            new,
            sel,
            loops=True,
            groups=ring_geom[sel],
            part_geom=ring_geom,
            first_part=first_ring_of_geom,
            feat_index=feat_index,
            smoother=smoother,
            levels=levels,
        )
        res = build(new)
    a0 = _signed_areas(rings)
    a1 = _signed_areas(new)
    scale = np.where(a0 != 0, np.abs(a0), 1.0)
    change = float(np.max(np.abs(a1 - a0) / scale)) if len(a0) else 0.0
    return res, reductions, n_rings, change


def _resolve_parts(
    parts, new, sel, *, loops, groups, part_geom, first_part, feat_index, smoother, levels
) -> list[GeometryReduction]:
    """Re-smooth the conflicting parts ``sel`` less (in place in `new`); return the reductions."""
    fixed, red = resolve_arcs(
        [parts[r] for r in sel],
        loops=np.full(len(sel), loops, dtype=bool),
        groups=groups,
        frozen=np.zeros(len(sel), dtype=bool),
        smoother=smoother,
        levels=levels,
    )
    for k, r in enumerate(sel):
        new[r] = fixed[k]
    out = []
    for rd in red:
        r = sel[rd.arc]
        gi = part_geom[r]
        out.append(
            GeometryReduction(
                int(feat_index[gi]),
                int(r - first_part[gi]),
                rd.start,
                rd.stop,
                rd.iterations,
                rd.alpha_scale,
            )
        )
    return out


def _smooth_lineal(g, feat_index, smoother, levels):
    shapely = _shapely()
    T = shapely.GeometryType
    was_line = shapely.get_type_id(g) == T.LINESTRING
    gtype, coords, offsets = shapely.to_ragged_array(g)
    if gtype == T.LINESTRING:
        (line_off,), geom_off = offsets, np.arange(len(g) + 1)
    else:
        line_off, geom_off = offsets
    n_lines = len(line_off) - 1
    line_geom = np.searchsorted(geom_off, np.arange(n_lines), side="right") - 1
    first_line_of_geom = np.searchsorted(line_geom, np.arange(len(g)))
    full = levels[0]
    lines = [coords[line_off[r] : line_off[r + 1]] for r in range(n_lines)]
    new = [x if len(x) < 3 else smoother(x, False, full) for x in lines]
    simple_in = shapely.is_simple(
        shapely.linestrings(coords, indices=np.repeat(np.arange(n_lines), np.diff(line_off)))
    )
    simple_out = shapely.is_simple(
        shapely.linestrings(
            np.concatenate(new), indices=np.repeat(np.arange(n_lines), [len(x) for x in new])
        )
    )
    hard = simple_in & ~simple_out
    reductions: list[GeometryReduction] = []
    if hard.any():
        sel = np.nonzero(hard)[0]
        reductions += _resolve_parts(
            lines,
            new,
            sel,
            loops=False,
            groups=np.arange(len(sel)),
            part_geom=line_geom,
            first_part=first_line_of_geom,
            feat_index=feat_index,
            smoother=smoother,
            levels=levels,
        )
    lens = np.array([len(x) for x in new], dtype=np.int64)
    offs = np.concatenate([[0], np.cumsum(lens)])
    ml = shapely.from_ragged_array(T.MULTILINESTRING, np.concatenate(new), (offs, geom_off))
    res = ml.copy()
    res[was_line] = shapely.get_geometry(ml[was_line], 0)
    change = 0.0
    for a, b in zip(lines, new, strict=True):
        area = abs(_signed_area(a))  # between the polyline and its chord
        scale = max(area, 1e-12 * max(float(np.ptp(a, axis=0).max()), 1e-300) ** 2)
        change = max(change, _rel(_signed_area(a), _signed_area(b), scale))
    return res, reductions, n_lines, change


def _smooth_linearring(geom, k, smoother, levels):
    shapely = _shapely()
    xy = shapely.get_coordinates(geom)[:-1]
    fixed, red = resolve_arcs(
        [xy],
        loops=np.ones(1, dtype=bool),
        groups=np.zeros(1, dtype=int),
        frozen=np.zeros(1, dtype=bool),
        smoother=smoother,
        levels=levels,
        check_simple=np.array([bool(shapely.is_simple(geom))]),
    )
    out = shapely.linearrings(fixed[0])
    reductions = [
        GeometryReduction(k, 0, r.start, r.stop, r.iterations, r.alpha_scale) for r in red
    ]
    area = _signed_area(xy)
    change = _rel(area, _signed_area(fixed[0]), abs(area))
    return out, reductions, 1, change


def smooth(
    geometry: Any,
    *,
    method: str = "cca",
    iterations: int = 1,
    alpha: Any = "regular",
    make_valid: bool = False,
    full_output: bool = False,
) -> Any:
    """Smooth shapely geometries, GeoSeries or GeoDataFrames, keeping every ring's area.

    Every ring of a (Multi)Polygon and every LinearRing is smoothed as a closed curve,
    every (Multi)LineString part as an open polyline with its two end points fixed;
    GeometryCollections member by member. With ``method="cca"`` (corner cutting and
    augmentation, Gordon 2010) each ring keeps its signed area, hence its orientation,
    and each line keeps the area between itself and its chord (paper, section 3).

    The output is valid: where smoothing would make a ring self-intersecting, a hole touch
    or cross its shell, two holes or two parts of a MultiPolygon meet, or a simple line
    cross itself, the ring is cut at anchor vertices around the conflict and only the
    conflicting pieces are smoothed less (fewer iterations, then alpha halved twice, then
    not at all). Anchored pieces keep the area against their chord (paper, section 5),
    so the areas are still kept exactly. Every such reduction is reported in
    :attr:`SmoothResult.reductions`.

    Parameters
    ----------
    geometry : shapely.Geometry, sequence of them, GeoSeries or GeoDataFrame
        LineString, LinearRing, Polygon (with holes), Multi* and GeometryCollection.
        ``None`` and empty geometries are passed through unchanged. The index, the other
        columns and the CRS of a GeoSeries/GeoDataFrame are kept.
    method : {"cca", "chaikin"}
        Area-preserving CCA (default) or plain Chaikin corner cutting (shrinks shapes;
        for comparison).
    iterations : int
        Number of smoothing passes (each CCA pass triples the vertices).
    alpha : "regular", float or callable
        CCA cut ratio: the regular-polygon profile of the paper's Table 1, a constant in
        (0, 1/3), or a function of the interior angle in radians. Ignored by Chaikin.
    make_valid : bool
        Repair invalid input polygons with :func:`shapely.make_valid` instead of raising.
    full_output : bool
        Return a :class:`SmoothResult` with the reductions and the area check.

    Returns
    -------
    object or SmoothResult
        The smoothed geometry, of the input's type.

    Raises
    ------
    CurveError
        For points, Z coordinates, invalid polygons (without ``make_valid``), an
        unknown method or a bad ``iterations``/``alpha``.

    Examples
    --------
    >>> import shapely
    >>> from curvesmith import geo
    >>> square = shapely.box(0, 0, 2, 2)
    >>> out = geo.smooth(square, iterations=2)
    >>> len(out.exterior.coords) - 1, round(out.area, 12)
    (36, 4.0)
    """
    iterations = check_method(method, iterations, alpha)
    geoms, wrap = as_geometry_array(geometry)
    geoms = prepare(geoms, make_valid=make_valid)
    out, reductions, n, change = _smooth_feature_array(
        geoms, method=method, iterations=iterations, alpha=alpha
    )
    result = wrap(out)
    if full_output:
        return SmoothResult(result, tuple(reductions), n, change)
    return result
