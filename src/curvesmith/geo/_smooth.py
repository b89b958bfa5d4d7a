"""Smoothing of shapely geometries, GeoSeries and GeoDataFrames (one feature at a time)."""

from __future__ import annotations

import itertools
import warnings
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from .. import methods
from .._gc import gc_paused, paused_gc
from .._rich import RichRepr
from ..errors import CurveError, require
from ..geometry import _signed_area
from ..methods import GisMethod
from ._corners import for_method, with_corners
from ._engine import Level, in_background, levels_for, resolve_arcs
from ._zm import split_zm

__all__ = ["GeometryReduction", "SmoothResult", "smooth"]


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
class SmoothResult(RichRepr):
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
    n_unchanged : int
        With ``max_shift`` / ``min_segment``: features (with a geometry) that no
        strength tried keeps within the bounds, returned as they were.
    """

    geometry: Any
    reductions: tuple[GeometryReduction, ...]
    n_curves: int
    max_area_change: float
    n_unchanged: int = 0


def _shapely():
    return require("shapely", "geo", "geo.smooth")


def make_smoother(
    method: str, alpha: Any, fixed: FixedVertices | None = None
) -> Callable[[np.ndarray, bool, Level], np.ndarray]:
    """Return ``f(points, closed, level)`` smoothing one ring (closed) or piece (fixed ends).

    With `fixed`, the vertices of the piece that are fixed (matched by their
    coordinates) are CCA anchors. The CCA smoother has ``f.batch(pieces, closed, level)``,
    the same curves for a list of pieces in one call of the ragged engine (used by
    :func:`curvesmith.geo._engine.resolve_arcs`).
    """
    spec = methods.get(method, gis=True)
    if spec.keeps_vertices:  # CCA: anchors, and a ragged form for many pieces at once

        def f(pts: np.ndarray, closed: bool, level: Level) -> np.ndarray:
            anchors = None
            if fixed is not None:
                mask = fixed.mask(pts)
                anchors = np.flatnonzero(mask) if mask.any() else None
            out = spec.smooth(
                pts,
                closed=closed,
                iterations=level.iterations,
                alpha=scale_alpha(alpha, level.alpha_scale),
                anchors=anchors,
            )
            return out if closed else _pin_ends(out, pts)

        def many(pieces: list[np.ndarray], closed: bool, level: Level) -> list[np.ndarray]:
            # the same curves as f, piece by piece, in one call of the ragged engine
            lens = np.array([len(x) for x in pieces], dtype=np.int64)
            off = np.zeros(len(pieces) + 1, dtype=np.int64)
            np.cumsum(lens, out=off[1:])
            xy = np.concatenate(pieces)
            mask = fixed.mask(xy) if fixed is not None else None
            out, oo = smooth_batch(method, alpha, xy, off, closed, level, mask)
            return [out[a:b] for a, b in itertools.pairwise(oo.tolist())]

        f.batch = many  # type: ignore[attr-defined]  # the CCA smoother's ragged form
        return f

    def g(pts: np.ndarray, closed: bool, level: Level) -> np.ndarray:
        out = spec.smooth(
            pts, closed=closed, iterations=level.iterations, preserve_endpoints=not closed
        )
        return out if closed else _pin_ends(out, pts)

    return g


def smooth_batch(
    method: str,
    alpha: Any,
    coords: np.ndarray,
    offsets: np.ndarray,
    closed,
    level: Level,
    fixed_mask: np.ndarray | None = None,
    close_rings: bool = False,
    threads: int | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Smooth many rings/lines at one level in one call of the ragged engine.

    ``coords``/``offsets`` as in :func:`curvesmith.cca.smooth_ragged` (rings may repeat
    their first vertex); open curves keep their ends. Returns the smoothed curves and
    their offsets (rings with their first vertex repeated only with ``close_rings``);
    every curve is what the single-curve smoother gives it.
    """
    spec = methods.get(method, gis=True)
    if level.iterations > 0 and spec.name == "cca":
        refused = _cca_refused(coords, offsets, closed)
        if refused is not None:  # a few slivers whose vertices CCA cannot tell apart
            return _smooth_batch_except(
                refused, method, alpha, coords, offsets, closed, level, fixed_mask, close_rings
            )
    if level.iterations == 0:
        from .._ragged import as_ragged

        rag = as_ragged(coords, offsets, closed=closed, dim=2)
        xy, off = rag.points, rag.offsets
    else:
        given = {
            "alpha": scale_alpha(alpha, level.alpha_scale),
            "anchors": fixed_mask if fixed_mask is not None and fixed_mask.any() else None,
            "preserve_endpoints": True,  # open pieces keep their ends
            "close_rings": close_rings,
            # threads: the engine's default (at most the cores, 1 under Dask's workers,
            # which set OMP_NUM_THREADS=1: a layer's partitions run in parallel there);
            # batches below cca's THREAD_MIN vertices run in one thread. Measured on the
            # 2-core machine, interleaved, geo.smooth of 20,000 footprints: median 152 ms
            # against 182 ms in one thread; 200,000: 1.79 s against 1.99 s, 7 % more CPU
            "threads": threads,
        }
        xy, off = spec.smooth_ragged(
            coords,
            offsets,
            closed=closed,
            iterations=level.iterations,
            **{k: v for k, v in given.items() if k in spec.parameters},
        )
        if "close_rings" in spec.parameters:
            return xy, off
    if close_rings and closed is True:
        xy, off = _close_rings(xy, off)
    elif close_rings:
        xy, off = _close_ragged(
            xy, off, np.broadcast_to(np.asarray(closed, dtype=bool), off.size - 1)
        )
    return xy, off


def _cca_refused(coords: np.ndarray, offsets: np.ndarray, closed: Any) -> np.ndarray | None:
    """The curves CCA would refuse (a mask), or None if there are none.

    CCA needs 3 distinct vertices on a ring (2 on a line) once vertices closer than its
    steps can tell apart count as one. Such a curve is a sliver (``make_valid`` leaves
    rings such as ``(4 0, 5 0, 4 0)`` and triangles with a side of 5e-324): its area is
    below the round-off of its coordinates, and it is kept as it is. One cheap pass finds
    the candidates (short curves, a zero gap between neighbours, or between a ring's ends
    that are not the same point); CCA's own de-duplication counts their vertices.
    """
    from ..cca._input import dedupe_ragged
    from ..cca._kernel import refusal_candidates

    n_rows, n = coords.shape[0], offsets.size - 1
    if n_rows < 2 or n == 0:
        return None
    off = np.asarray(offsets, dtype=np.int64)
    cl = np.broadcast_to(np.asarray(closed, dtype=bool), (n,))
    cand = refusal_candidates(np.ascontiguousarray(coords, dtype=np.float64), off, cl)
    if not cand.any():
        return None
    idx = np.flatnonzero(cand)
    sub_xy, sub_off = _take(coords, off, idx)
    _, _, kept = dedupe_ragged(sub_xy, np.zeros(len(sub_xy), dtype=bool), sub_off, cl[idx])
    refused = np.zeros(n, dtype=bool)
    refused[idx] = np.diff(kept) < np.where(cl[idx], 3, 2)
    return refused if refused.any() else None


def _smooth_batch_except(
    refused, method, alpha, coords, offsets, closed, level, fixed_mask, close_rings
):
    """:func:`smooth_batch` with the `refused` curves kept as they are (iterations 0)."""
    off = np.asarray(offsets, dtype=np.int64)
    cl = np.broadcast_to(np.asarray(closed, dtype=bool), (off.size - 1,))
    parts = []
    for sel, lev in ((np.flatnonzero(~refused), level), (np.flatnonzero(refused), Level(0))):
        xy, oo = _take(coords, off, sel)
        mask = None
        if fixed_mask is not None:
            mask, _ = _take(fixed_mask[:, None], off, sel)
            mask = mask[:, 0]
        c = cl[sel]
        parts.append((sel, smooth_batch(method, alpha, xy, oo, c, lev, mask, close_rings)))
    (a_sel, (a_xy, a_off)), (b_sel, (b_xy, b_off)) = parts
    lens = np.zeros(off.size - 1, dtype=np.int64)
    lens[a_sel], lens[b_sel] = np.diff(a_off), np.diff(b_off)
    new_off = np.zeros(off.size, dtype=np.int64)
    np.cumsum(lens, out=new_off[1:])
    out = np.empty((int(new_off[-1]), coords.shape[1]))
    for sel, xy, oo in ((a_sel, a_xy, a_off), (b_sel, b_xy, b_off)):
        ln = np.diff(oo)
        out[np.repeat(new_off[sel] - oo[:-1], ln) + np.arange(oo[-1])] = xy
    return out, new_off


def _close_ragged(xy: np.ndarray, off: np.ndarray, closed: np.ndarray):
    """Repeat the first vertex at the end of the closed curves (shapely's ring layout)."""
    from ..cca import _kernel

    off = np.asarray(off, dtype=np.int64)
    closed = np.asarray(closed, dtype=bool)
    ln = np.diff(off)
    new_off = np.zeros(off.size, dtype=np.int64)
    np.cumsum(ln + (closed & (ln > 0)), out=new_off[1:])
    out = np.empty((int(new_off[-1]), xy.shape[1]))
    _kernel.close_ragged(np.ascontiguousarray(xy, dtype=np.float64), off, closed, out, new_off)
    return out, new_off


class FixedVertices:
    """Vertices that smoothing must keep: given as a mask or as a function of coordinates.

    ``spec`` is a boolean mask over ``shapely.get_coordinates(geometry)`` of the input,
    or a callable taking an ``(N, 2)`` coordinate array and returning an ``(N,)``
    boolean mask. A mask is turned into the set of fixed coordinate values (so that it
    survives the removal of repeated points and ``make_valid``); every vertex at such a
    coordinate is then fixed, wherever it is.
    """

    def __init__(self, spec: Any, geoms: np.ndarray):
        self._fn = None
        self._points = None
        if callable(spec):
            self._fn = spec
            return
        shapely = _shapely()
        mask = np.asarray(spec)
        present = np.array([g is not None for g in geoms], dtype=bool)
        xy = shapely.get_coordinates(geoms[present]) if present.any() else np.zeros((0, 2))
        if mask.dtype != np.bool_ or mask.shape != (xy.shape[0],):
            raise CurveError(
                f"fixed must be a boolean mask over shapely.get_coordinates(geometry) "
                f"(shape ({xy.shape[0]},)) or a callable on (N, 2) coordinates, got "
                f"{'an array of shape ' + str(mask.shape) + ' and dtype ' + str(mask.dtype)}"
            )
        self._points = np.unique(_as_complex(xy[mask]))

    def mask(self, coords: np.ndarray) -> np.ndarray:
        """``(N,)`` bool: which rows of ``coords`` (N, 2) are fixed."""
        if coords.shape[0] == 0:
            return np.zeros(0, dtype=bool)
        if self._fn is not None:
            try:
                out = np.asarray(self._fn(np.array(coords, dtype=float)))
            except Exception as exc:
                raise CurveError(f"fixed callable failed: {type(exc).__name__}: {exc}") from None
            if out.dtype != np.bool_ or out.shape != (coords.shape[0],):
                raise CurveError(
                    f"fixed callable must return a boolean mask of shape ({coords.shape[0]},), "
                    f"got shape {out.shape} and dtype {out.dtype}"
                )
            return out
        assert self._points is not None  # set when there is no callable
        if self._points.size == 0:
            return np.zeros(coords.shape[0], dtype=bool)
        return np.isin(_as_complex(coords), self._points)


def _as_complex(xy: np.ndarray) -> np.ndarray:
    xy = np.ascontiguousarray(xy, dtype=float)
    return xy[:, 0] + 1j * xy[:, 1] if xy.shape[0] else np.zeros(0, dtype=complex)


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

    takes_alpha = "alpha" in methods.get(method, gis=True).parameters
    iterations = as_int(iterations, name="iterations", minimum=0)
    if takes_alpha and isinstance(alpha, str) and alpha != "regular":
        raise CurveError(f"alpha must be 'regular', a float or a callable, got {alpha!r}")
    if takes_alpha and not isinstance(alpha, str) and not callable(alpha):
        try:
            a = float(alpha)
        except (TypeError, ValueError):
            raise CurveError(
                f"alpha must be 'regular', a float or a callable, got {alpha!r}"
            ) from None
        if not 0.0 < a < 1.0 / 3.0:
            raise CurveError(f"alpha must be in (0, 1/3), got {alpha!r}")
    return iterations


def check_layer_size(
    geoms: Any, method: str, iterations: int, *, levels: bool = False, rows: int | None = None
) -> None:
    """Refuse smoothing whose output would not fit in memory (see ``check_layer_growth``).

    `levels`: every level up to `iterations` is held at once. `rows`: the layer's
    coordinates, where the caller has counted them.
    """
    from .._validate import check_layer_growth

    geoms = np.asarray(geoms, dtype=object)
    if iterations == 0 or len(geoms) == 0:
        return
    n = int(_shapely().get_num_coordinates(geoms).sum()) if rows is None else rows
    growth = methods.get(method, gis=True).growth
    what = f"vertices of {len(geoms)} feature(s)"
    check_layer_growth(n, iterations, growth, levels=levels, what=what)


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
    ok = shapely.is_valid_input(arr)  # a geometry or None
    if not ok.all():
        k = int(np.nonzero(~ok)[0][0])
        raise CurveError(
            f"geometry[{k}] must be a shapely geometry or None, got {type(arr[k]).__name__}"
        )
    return arr, lambda out: out


def prepare(
    geoms: np.ndarray, *, make_valid: bool, what: str = "geometry", defer_validity: bool = False
) -> np.ndarray:
    """Check types, 2D-ness and validity; drop repeated vertices. Returns a new array.

    With `defer_validity` the validity is not checked (`make_valid` is not used): the
    caller proves it or asks GEOS, and prepares again without deferring if a geometry is
    not valid (:func:`curvesmith.geo.smooth_coverage` proves it with the coverage).
    """
    return _prepare(geoms, make_valid=make_valid, what=what, defer_validity=defer_validity)[0]


@dataclass(frozen=True)
class _Facts:
    """What :func:`_prepare` learnt about the geometries it returns, for the smoothing.

    ``present``: which entries are not None; the other arrays are over the present ones:
    ``types`` (``get_type_id``), ``empty``, ``holes`` (``get_num_interior_rings``, 0 for
    non-polygons) and, when no geometry was repaired or lost repeated vertices, ``xy`` and
    ``offsets`` (``get_coordinates`` and where each geometry's coordinates start) and
    ``centres`` (per geometry the centre its ring was proven star-shaped about, NaN if
    none; :func:`curvesmith.geo._simple.rings_certainly_simple`), otherwise ``None``.
    """

    present: np.ndarray
    types: np.ndarray
    empty: np.ndarray
    holes: np.ndarray
    xy: np.ndarray | None = None
    offsets: np.ndarray | None = None
    centres: np.ndarray | None = None


def _prepare(
    geoms: np.ndarray,
    *,
    make_valid: bool,
    what: str = "geometry",
    defer_validity: bool = False,
    planar: bool = False,
) -> tuple[np.ndarray, _Facts]:
    """:func:`prepare`, and the facts it computed on the way (no shapely call twice).

    ``planar``: the caller made every geometry 2D (:func:`curvesmith.geo._zm.split_zm`),
    so Z is not looked for. Each pass over a layer's GEOS geometries costs more than its
    work (1-2.5 ms per pass over 20,000 footprints, most of it reaching them in memory),
    so emptiness is read off the coordinate counts.
    """
    shapely = _shapely()
    geoms = np.asarray(geoms, dtype=object).copy()
    present = ~shapely.is_missing(geoms)
    g = geoms[present]
    if not present.any():
        types, empty = shapely.get_type_id(g), shapely.is_empty(g)
        return geoms, _Facts(present, types, empty, shapely.get_num_interior_rings(g))
    xy, owner = shapely.get_coordinates(g, return_index=True)
    off = np.zeros(len(g) + 1, dtype=np.int64)
    np.cumsum(np.bincount(owner, minlength=len(g)), out=off[1:])
    centres = np.full((len(g), 2), np.nan)
    # single-ring polygons proven simple by the compiled test are valid; GEOS checks the
    # rest. The proof (compiled, without the GIL) runs beside the type checks of a layer
    simple = None
    if not defer_validity and beside_worthwhile(xy.shape[0]):
        from ._simple import rings_certainly_simple

        simple = in_background(rings_certainly_simple, xy, off, True, centres)
    try:
        types, empty, holes = _check_types(shapely, geoms, g, present, what, off, planar)
    finally:
        proof = simple.result() if simple is not None else None  # also when a check failed
    if defer_validity:
        proven = valid = np.zeros(len(g), dtype=bool)
    else:
        proven = _certainly_valid_polygons(types, holes, xy, off, centres, proof)
        valid = proven.copy()
        doubt = np.flatnonzero(~valid)
        if doubt.size:
            valid[doubt] = shapely.is_valid(g[doubt])
    changed = False
    if not defer_validity and not valid.all():
        if not make_valid:
            bad = np.flatnonzero(~valid)
            k = int(bad[0])
            reason = shapely.is_valid_reason(g[k])
            more = f" (and {len(bad) - 1} more)" if len(bad) > 1 else ""
            raise CurveError(
                f"{what}[{int(np.flatnonzero(present)[k])}] is not valid ({reason}){more}; "
                "repair it first or pass make_valid=True (--make-valid) to repair it with "
                "shapely.make_valid"
            )
        fixed = shapely.make_valid(g[~valid], method="structure", keep_collapsed=False)
        g = g.copy()
        g[~valid] = fixed
        xy, owner = shapely.get_coordinates(g, return_index=True)
        changed = True
    # remove_repeated_points (a new GEOS geometry each) only where a vertex repeats the
    # previous one: the others would come back with the same coordinates. A ring proven
    # simple has none (every pair of consecutive vertices is an edge of non-zero length)
    if changed or defer_validity:
        rows = _repeating(xy, owner)
    else:
        todo = np.flatnonzero(~proven)
        t_xy, t_off = _take(xy, off, todo)
        t_owner = np.repeat(np.arange(todo.size), np.diff(t_off))
        rows = todo[_repeating(t_xy, t_owner)]
    if rows.size:
        g = g.copy()
        before = g[rows]
        g[rows] = shapely.remove_repeated_points(before, 0.0)
        # GEOS also drops a vertex whose distance to the previous one underflows (5e-324
        # apart), which can collapse a valid ring: such a geometry stays as it was (the
        # smoothing keeps what CCA cannot separate as it is)
        broken = ~shapely.is_valid(g[rows])
        g[rows[broken]] = before[broken]
        changed = True
    geoms[present] = g
    if changed:  # repaired geometries may have changed type, emptiness and rings
        types, empty = shapely.get_type_id(g), shapely.is_empty(g)
        holes = shapely.get_num_interior_rings(g)
        return geoms, _Facts(present, types, empty, holes)
    return geoms, _Facts(present, types, empty, holes, xy, off, centres)


def _check_types(shapely, geoms, g, present, what, off, planar):
    """Types, emptiness and holes of the present geometries `g`; refuses points and Z.

    ``off``: where each one's coordinates start in ``get_coordinates`` (a geometry is
    empty exactly when it has none); ``planar``: Z is known to be absent.
    """
    types = shapely.get_type_id(g)
    empty = off[1:] == off[:-1]
    holes = shapely.get_num_interior_rings(g)
    pos = np.nonzero(present)[0]
    is_point = (types == shapely.GeometryType.POINT) | (types == shapely.GeometryType.MULTIPOINT)
    nonempty = ~empty
    if np.any(is_point & nonempty):
        k = int(pos[np.nonzero(is_point & nonempty)[0][0]])
        raise CurveError(
            f"{what}[{k}] is a {geoms[k].geom_type}: only lines and polygons can be smoothed"
        )
    has_z = np.zeros(len(g), dtype=bool) if planar else shapely.has_z(g)
    if np.any(has_z & nonempty):
        k = int(pos[np.nonzero(has_z & nonempty)[0][0]])
        raise CurveError(
            f"{what}[{k}] has Z coordinates; curvesmith.geo smooths planar geometries "
            f"(drop Z with shapely.force_2d)"
        )
    return types, empty, holes


def _repeating(xy: np.ndarray, owner: np.ndarray) -> np.ndarray:
    """The ``owner`` values (geometries) with a vertex repeating the previous one."""
    rep = np.all(xy[1:] == xy[:-1], axis=1) & (owner[1:] == owner[:-1])
    return np.unique(owner[1:][rep])


def _certainly_valid_polygons(types, holes, xy, off, centres=None, simple=None) -> np.ndarray:
    """Per geometry: True for a Polygon without holes whose ring is proven simple.

    ``types, holes``: ``get_type_id`` and ``get_num_interior_rings`` of the geometries;
    ``xy``: their ``get_coordinates``, geometry ``i`` in rows ``off[i]:off[i + 1]``.
    False means "ask GEOS" (other types, holes, doubtful rings; see
    :mod:`curvesmith.geo._simple`). ``centres`` (``(len(types), 2)``, NaN): filled with
    the centres of the star proofs. ``simple``: the proof of every geometry's
    coordinates as one ring, if already run (``rings_certainly_simple(xy, off, True,
    centres)``).
    """
    shapely = _shapely()
    from ._simple import rings_certainly_simple

    out = np.zeros(len(types), dtype=bool)
    cand = (types == shapely.GeometryType.POLYGON) & (holes == 0)
    if centres is None:
        centres = np.full((len(types), 2), np.nan)
    if not cand.any():
        centres[:] = np.nan
        return out
    if simple is None:
        simple = rings_certainly_simple(xy, off, True, centres)
    out[cand] = simple[cand]
    centres[~cand] = np.nan
    return out


# --------------------------------------------------------------------------------------------
# the smoothing itself


def _ring_areas(xy: np.ndarray, off: np.ndarray) -> np.ndarray:
    """Signed areas of ragged rings (closing vertex repeated or not), compiled, no temporaries."""
    from ..cca import _kernel

    return _kernel.ring_areas(np.ascontiguousarray(xy, dtype=float), off.astype(np.int64))


def signed_areas_ragged(xy: np.ndarray, off: np.ndarray) -> np.ndarray:
    """Signed areas of ragged rings (without closing vertex; open lines: against the chord)."""
    lens = np.diff(off)
    out = np.zeros(lens.size)
    ok = lens > 0
    if not ok.any():
        return out
    start = off[:-1]
    xy = xy - np.repeat(xy[start[ok]], lens[ok], axis=0)  # local origin: no cancellation
    nxt = np.arange(len(xy)) + 1
    nxt[off[1:][ok] - 1] = start[ok]  # wrap around within each ring
    # the trapezoid form of geometry.signed_area, ring by ring
    terms = (xy[:, 0] - xy[nxt, 0]) * (xy[:, 1] + xy[nxt, 1])
    out[ok] = 0.5 * np.add.reduceat(terms, start[ok])
    return out


def _rel(a: float, b: float, scale: float) -> float:
    return abs(a - b) / scale if scale > 0 else 0.0


def _take(xy: np.ndarray, off: np.ndarray, idx: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Curves ``idx`` of a ragged batch, as a ragged batch (no loop per curve)."""
    lens = np.diff(off)[idx]
    new_off = np.zeros(idx.size + 1, dtype=np.int64)
    np.cumsum(lens, out=new_off[1:])
    rows = np.repeat(off[idx] - new_off[:-1], lens) + np.arange(new_off[-1])
    return xy[rows], new_off


def _put(
    xy: np.ndarray, off: np.ndarray, idx: np.ndarray, sub_xy: np.ndarray, sub_off: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Replace the curves ``idx`` (sorted) of a ragged batch by the curves of ``sub``."""
    lens = np.diff(off).copy()
    lens[idx] = np.diff(sub_off)
    new_off = np.zeros(off.size, dtype=np.int64)
    np.cumsum(lens, out=new_off[1:])
    out = np.empty((int(new_off[-1]), xy.shape[1]))
    keep = np.ones(lens.size, dtype=bool)
    keep[idx] = False
    k = np.flatnonzero(keep)
    if k.size:
        kl = np.diff(off)[k]
        src = np.repeat(off[k], kl) + np.arange(kl.sum()) - np.repeat(np.cumsum(kl) - kl, kl)
        dst = np.repeat(new_off[k], kl) + np.arange(kl.sum()) - np.repeat(np.cumsum(kl) - kl, kl)
        out[dst] = xy[src]
    sl = np.diff(sub_off)
    dst = np.repeat(new_off[idx] - sub_off[:-1], sl) + np.arange(sub_off[-1])
    out[dst] = sub_xy
    return out, new_off


def _splice(
    xy: np.ndarray, off: np.ndarray, idx: np.ndarray, sub_xy: np.ndarray, sub_off: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """:func:`_put` for a few curves `idx` of a long batch.

    The rows between them are copied as whole slices (one pass, no index arrays).
    """
    if idx.size == 0:
        return xy, off
    lens = np.diff(off)
    lens[idx] = np.diff(sub_off)
    new_off = np.zeros(off.size, dtype=np.int64)
    np.cumsum(lens, out=new_off[1:])
    out = np.empty((int(new_off[-1]), xy.shape[1]))
    src = 0  # first row of xy not copied yet
    for k, r in enumerate(idx.tolist()):
        a = off[r]
        d = new_off[r] - (a - src)
        out[d : new_off[r]] = xy[src:a]
        out[new_off[r] : new_off[r + 1]] = sub_xy[sub_off[k] : sub_off[k + 1]]
        src = off[r + 1]
    out[new_off[-1] - (off[-1] - src) :] = xy[src:]
    return out, new_off


def _expand(off: np.ndarray, idx: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Rows ``off[i] .. off[i + 1] - 1`` of every ``i`` in `idx`, and their new offsets."""
    lens = (off[1:] - off[:-1])[idx]
    new_off = np.zeros(idx.size + 1, dtype=np.int64)
    np.cumsum(lens, out=new_off[1:])
    rows = np.repeat(off[idx] - new_off[:-1], lens) + np.arange(new_off[-1])
    return rows, new_off


def assemble_polygons(
    xy: np.ndarray,
    ring_off: np.ndarray,
    poly_off: np.ndarray,
    geom_off: np.ndarray,
    was_polygon: np.ndarray,
) -> np.ndarray:
    """(Multi)Polygons from closed ragged rings, in ``shapely.to_ragged_array``'s layout.

    ``was_polygon`` (per geometry): build a Polygon (the geometry has one polygon), else a
    MultiPolygon. All polygons are made in one call, without copying the coordinates of
    the Polygon geometries out first; only the parts of MultiPolygons are copied (by
    GEOS, into their collection).
    """
    shapely = _shapely()
    T = shapely.GeometryType
    ring_off = np.asarray(ring_off, dtype=np.int64)
    poly_off = np.asarray(poly_off, dtype=np.int64)
    geom_off = np.asarray(geom_off, dtype=np.int64)
    was_polygon = np.asarray(was_polygon, dtype=bool)
    with paused_gc():  # geometries are tracked by the cyclic collector: see curvesmith._gc
        parts = shapely.from_ragged_array(T.POLYGON, xy, (ring_off, poly_off))
    n_parts = np.diff(geom_off)
    if was_polygon.all() and np.all(n_parts == 1):  # one polygon per geometry
        return parts
    # a Polygon geometry is its part, a MultiPolygon collects its parts
    out = np.empty(len(was_polygon), dtype=object)
    one = was_polygon & (n_parts == 1)
    out[one] = parts[geom_off[:-1][one]]
    out[was_polygon & (n_parts == 0)] = shapely.Polygon()
    multi = np.flatnonzero(~was_polygon & (n_parts > 0))
    if multi.size:
        rows, _ = _expand(geom_off, multi)
        owner = np.repeat(np.arange(multi.size), n_parts[multi])
        out[multi] = shapely.multipolygons(parts[rows], indices=owner)
    out[~was_polygon & (n_parts == 0)] = shapely.MultiPolygon()
    return out


def _close_rings(xy: np.ndarray, off: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Ragged rings with their first vertex repeated at the end (shapely's ring layout)."""
    return _close_ragged(xy, off, np.ones(len(off) - 1, dtype=bool))


class _RaggedView:
    """``view[r]``: curve r of a ragged batch (``drop_last``: without its closing vertex)."""

    def __init__(self, xy, off, drop_last=False):
        self.xy, self.off, self.cut = xy, off, 1 if drop_last else 0

    def __getitem__(self, r):
        return self.xy[self.off[r] : self.off[r + 1] - self.cut]


def _smooth_feature_array(
    geoms: np.ndarray,
    *,
    method: str,
    iterations: int,
    alpha: Any,
    fixed: FixedVertices | None = None,
    facts: _Facts | None = None,
    ragged_out: list[dict] | None = None,
) -> tuple[np.ndarray, list[GeometryReduction], int, float]:
    """Smooth every feature; ``facts``: :func:`_prepare`'s facts about `geoms`, if known.

    ``ragged_out`` (a list; for a layer of Polygons without holes whose `facts` hold their
    coordinates): the output is not built but appended to it, chunk by chunk, as the dicts
    of :func:`_smooth_polygonal`; the features of the array returned are then None.
    """
    shapely = _shapely()
    out = geoms.copy()
    smoother = make_smoother(method, alpha, fixed)
    levels = levels_for(iterations, scalable=methods.get(method).scalable)
    reductions: list[GeometryReduction] = []
    n_curves = 0
    max_change = 0.0
    if iterations == 0:
        return out, reductions, 0, 0.0
    present = facts.present if facts is not None else ~shapely.is_missing(geoms)
    idx = np.nonzero(present)[0]
    if len(idx) == 0:
        return out, reductions, 0, 0.0
    g = geoms[idx]
    if facts is not None:
        types, empty = facts.types, facts.empty
    else:
        types, empty = shapely.get_type_id(g), shapely.is_empty(g)
    T = shapely.GeometryType
    poly = ~empty & ((types == T.POLYGON) | (types == T.MULTIPOLYGON))
    line = ~empty & ((types == T.LINESTRING) | (types == T.MULTILINESTRING))
    ring = ~empty & (types == T.LINEARRING)
    coll = ~empty & (types == T.GEOMETRYCOLLECTION)
    batch = (method, alpha, fixed)

    for mask, smooth_kind in ((poly, _smooth_polygonal), (line, _smooth_lineal)):
        if not mask.any():
            continue
        # in chunks of about CHUNK_VERTICES input vertices, so that the engine's buffers
        # and the ragged arrays are those of one chunk, not of the whole layer (each curve
        # is smoothed as on its own, so chunking does not change a bit)
        sel = np.flatnonzero(mask)
        # a layer of Polygons without holes: the coordinates _prepare read are the rings
        rxy = roff = rcen = None
        if (
            smooth_kind is _smooth_polygonal
            and facts is not None
            and sel.size == len(g)
            and not np.any((types != T.POLYGON) | (facts.holes != 0))
        ):
            rxy, roff, rcen = facts.xy, facts.offsets, facts.centres
        if ragged_out is not None and rxy is None:
            raise AssertionError("ragged_out needs a layer of Polygons without holes")
        counts = np.diff(roff) if roff is not None else shapely.get_num_coordinates(g[sel])
        for part in _chunks(counts):
            k = sel[part]
            if rxy is not None and roff is not None and rcen is not None:
                a, b = roff[part.start], roff[part.stop]
                rag = rxy[a:b], roff[part.start : part.stop + 1] - a, rcen[part]
                part_out: dict | None = None if ragged_out is None else {}
                res, red, n, ch = _smooth_polygonal(
                    g[k], idx[k], smoother, levels, batch, single_rings=rag, ragged_out=part_out
                )
                if ragged_out is not None and part_out is not None:
                    ragged_out.append(part_out)
            else:
                res, red, n, ch = smooth_kind(g[k], idx[k], smoother, levels, batch)
            out[idx[k]] = res
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
            parts, method=method, iterations=iterations, alpha=alpha, fixed=fixed
        )
        out[k] = shapely.geometrycollections(list(sub))
        reductions += [
            GeometryReduction(int(k), r.ring, r.start, r.stop, r.iterations, r.alpha_scale)
            for r in red
        ]
        n_curves += n
        max_change = max(max_change, ch)
    return out, reductions, n_curves, max_change


#: Output vertices from which :func:`smooth` proves the output beside GEOS building it (a
#: thread's start costs about 0.1 ms). Measured on the 2-core machine, interleaved, 20,000
#: footprints, 15 rounds: median 168 ms against 181 ms proving after the build.
BACKGROUND_MIN = 1 << 16


def beside_worthwhile(n_rows: int) -> bool:
    """Whether to prove `n_rows` output vertices in a thread beside GEOS (2+ cores, big)."""
    from ..cca._input import default_threads

    return n_rows >= BACKGROUND_MIN and default_threads() > 1


#: Input vertices per call of the ragged engine in :func:`smooth` (a layer goes in chunks).
CHUNK_VERTICES = 1 << 20


def _chunks(counts: np.ndarray) -> list[slice]:
    """Consecutive slices of features holding about CHUNK_VERTICES vertices each."""
    ends = np.cumsum(counts)
    cuts = np.searchsorted(ends, np.arange(CHUNK_VERTICES, ends[-1], CHUNK_VERTICES), "right")
    bounds = np.unique(np.concatenate([[0], cuts, [len(counts)]]))
    return [slice(int(a), int(b)) for a, b in itertools.pairwise(bounds)]


def polygon_ragged(g: np.ndarray, was_polygon: np.ndarray):
    """``shapely.to_ragged_array`` of (Multi)Polygons: coordinates, ring, polygon, geometry offsets.

    The ring offsets are int64.
    Polygons without holes (a layer of footprints) skip ``to_ragged_array``'s copies of
    every ring (``shapely.get_rings``): their coordinates are ``get_coordinates`` and each
    one is a ring, the same arrays bit for bit.
    """
    shapely = _shapely()
    T = shapely.GeometryType
    if was_polygon.all() and not shapely.get_num_interior_rings(g).any():
        coords, owner = shapely.get_coordinates(g, return_index=True)
        ring_off = np.zeros(len(g) + 1, dtype=np.int64)
        np.cumsum(np.bincount(owner, minlength=len(g)), out=ring_off[1:])
        ids = np.arange(len(g) + 1, dtype=np.int64)
        return coords, ring_off, ids, ids
    gtype, coords, offsets = shapely.to_ragged_array(g)
    if gtype == T.POLYGON:
        (ring_off, poly_off), geom_off = offsets, np.arange(len(g) + 1)
    else:
        ring_off, poly_off, geom_off = offsets
    return coords, ring_off.astype(np.int64), poly_off, geom_off


def _smooth_polygonal(g, feat_index, smoother, levels, batch, single_rings=None, ragged_out=None):
    """Smooth the (Multi)Polygons ``g``.

    ``single_rings``: ``(xy, offsets, centres)`` when every one is a Polygon without holes
    and these are its coordinates (``get_coordinates``) and the centres of its input's
    star proof (the output proof tries them first).
    ``ragged_out`` (a dict, with ``single_rings`` only): the output is not built; the dict
    receives its closed rings, ``"xy"`` and ``"offsets"`` (ring ``k`` is polygon ``k``),
    and the first value returned is None. GEOS then builds only the polygons whose
    validity the compiled proof leaves in doubt.
    """
    shapely = _shapely()
    method, alpha, fixed = batch
    centres = None
    if single_rings is not None:
        coords, ring_off, centres = single_rings
        centres = centres.copy()  # the proof overwrites it
        was_polygon = np.ones(len(g), dtype=bool)
        poly_off = geom_off = np.arange(len(g) + 1, dtype=np.int64)
    else:
        was_polygon = shapely.get_type_id(g) == shapely.GeometryType.POLYGON
        coords, ring_off, poly_off, geom_off = polygon_ragged(g, was_polygon)
    n_rings = len(ring_off) - 1
    if single_rings is not None:  # ring k is polygon k is geometry k
        ring_poly = ring_geom = first_ring_of_geom = np.arange(n_rings, dtype=np.int64)
    else:
        ring_poly = np.searchsorted(poly_off, np.arange(n_rings), side="right") - 1
        ring_geom = np.searchsorted(geom_off, ring_poly, side="right") - 1
        first_ring_of_geom = np.searchsorted(ring_geom, np.arange(len(g)))
    full = levels[0]
    fmask = fixed.mask(coords) if fixed is not None else None
    # rings come back closed (first vertex repeated), ready for from_ragged_array
    new_xy, new_off = smooth_batch(
        method, alpha, coords, ring_off, True, full, fmask, close_rings=True
    )
    # a feature of one ring proven simple by the compiled test is valid; GEOS checks the
    # rest. The proof and the areas of output and input (compiled, without the GIL) run
    # beside GEOS building the polygons (which holds it)
    from ._simple import rings_certainly_simple

    def proof_and_areas(xy, off, centres):
        proof = rings_certainly_simple(xy, off, True, centres)
        return proof, _ring_areas(xy, off), _ring_areas(coords, ring_off)

    build = assemble_polygons
    if ragged_out is not None:
        assert single_rings is not None  # ring k is geometry k
        res = None
        proven, a1, a0 = proof_and_areas(new_xy, new_off, centres)
    elif beside_worthwhile(new_xy.shape[0]):
        future = in_background(proof_and_areas, new_xy, new_off, centres)
        res = build(new_xy, new_off, poly_off, geom_off, was_polygon)
        proven, a1, a0 = future.result()
    else:
        res = build(new_xy, new_off, poly_off, geom_off, was_polygon)
        proven, a1, a0 = proof_and_areas(new_xy, new_off, centres)
    rings_per_geom = np.bincount(ring_geom, minlength=len(g))
    hard = rings_per_geom > 1  # holes or parts: checked for conflicts anyway
    one = np.flatnonzero(~hard)
    doubt = one[~proven[first_ring_of_geom[one]]]
    if res is None:  # the doubtful ones alone (single rings: ring k is geometry k)
        d_xy, d_off = _take(new_xy, new_off, doubt)
        ids = np.arange(len(doubt) + 1, dtype=np.int64)
        d_geoms = build(d_xy, d_off, ids, ids, np.ones(len(doubt), dtype=bool))
        hard[doubt] = ~shapely.is_valid(d_geoms)
    else:
        hard[doubt] = ~shapely.is_valid(res[doubt])
    reductions: list[GeometryReduction] = []
    rings = _RaggedView(coords, ring_off, drop_last=True)
    if hard.any():
        # only the features with holes or parts, or with an invalid output, are checked
        # for conflicts and re-smoothed locally; their full-strength rings are reused
        sel = np.nonzero(hard[ring_geom])[0]
        new = _RaggedView(new_xy, new_off, drop_last=True)
        repl: dict[int, np.ndarray] = {}
        reductions += _resolve_parts(
            rings,
            repl,
            sel,
            loops=True,
            groups=ring_geom[sel],
            part_geom=ring_geom,
            first_part=first_ring_of_geom,
            feat_index=feat_index,
            smoother=smoother,
            levels=levels,
            initial=[new[r] for r in sel],
        )
        sub = [repl[int(r)] for r in sel]
        sub_off = np.zeros(len(sub) + 1, dtype=np.int64)
        np.cumsum([len(x) for x in sub], out=sub_off[1:])
        sub_xy, sub_off = _close_rings(np.concatenate(sub), sub_off)
        a1[sel] = _ring_areas(sub_xy, sub_off)
        # the hard features alone, renumbered: their rings, polygons and geometries
        hard_idx = np.flatnonzero(hard)
        polys = np.unique(ring_poly[sel])
        p_off = np.append(np.searchsorted(ring_poly[sel], polys), len(sel))
        poly_geom = np.searchsorted(geom_off, polys, side="right") - 1
        g_off = np.append(np.searchsorted(poly_geom, hard_idx), len(polys))
        if res is None:
            new_xy, new_off = _splice(new_xy, new_off, sel, sub_xy, sub_off)
        else:
            res[hard_idx] = build(sub_xy, sub_off, p_off, g_off, was_polygon[hard_idx])
    if ragged_out is not None:
        ragged_out["xy"], ragged_out["offsets"] = new_xy, new_off
    del new_xy
    scale = np.where(a0 != 0, np.abs(a0), 1.0)
    change = float(np.max(np.abs(a1 - a0) / scale)) if len(a0) else 0.0
    return res, reductions, n_rings, change


def _resolve_parts(
    parts,
    new,
    sel,
    *,
    loops,
    groups,
    part_geom,
    first_part,
    feat_index,
    smoother,
    levels,
    initial=None,
) -> list[GeometryReduction]:
    """Re-smooth the conflicting parts ``sel`` less (into `new`); return the reductions.

    ``initial``: the parts already smoothed at full strength (reused as is).
    """
    fixed, red = resolve_arcs(
        [parts[r] for r in sel],
        loops=np.full(len(sel), loops, dtype=bool),
        groups=groups,
        frozen=np.zeros(len(sel), dtype=bool),
        smoother=smoother,
        levels=levels,
        initial=initial,
    )
    for k, r in enumerate(sel):
        new[int(r)] = fixed[k]
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


def _smooth_lineal(g, feat_index, smoother, levels, batch):
    shapely = _shapely()
    method, alpha, fixed = batch
    T = shapely.GeometryType
    was_line = shapely.get_type_id(g) == T.LINESTRING
    gtype, coords, offsets = shapely.to_ragged_array(g)
    if gtype == T.LINESTRING:
        (line_off,), geom_off = offsets, np.arange(len(g) + 1)
    else:
        line_off, geom_off = offsets
    line_off = line_off.astype(np.int64)
    n_lines = len(line_off) - 1
    line_geom = np.searchsorted(geom_off, np.arange(n_lines), side="right") - 1
    first_line_of_geom = np.searchsorted(line_geom, np.arange(len(g)))
    full = levels[0]
    lens = np.diff(line_off)
    todo = np.flatnonzero(lens >= 3)  # 2-point lines stay as they are
    new_xy, new_off = coords, line_off
    if todo.size:
        sub_xy, sub_off = _take(coords, line_off, todo)
        fmask = fixed.mask(sub_xy) if fixed is not None else None
        s_xy, s_off = smooth_batch(method, alpha, sub_xy, sub_off, False, full, fmask)
        new_xy, new_off = _put(coords, line_off, todo, s_xy, s_off)
    simple_in = shapely.is_simple(
        shapely.linestrings(coords, indices=np.repeat(np.arange(n_lines), lens))
    )
    simple_out = shapely.is_simple(
        shapely.linestrings(new_xy, indices=np.repeat(np.arange(n_lines), np.diff(new_off)))
    )
    hard = simple_in & ~simple_out
    reductions: list[GeometryReduction] = []
    if hard.any():
        sel = np.nonzero(hard)[0]
        new = _RaggedView(new_xy, new_off)
        repl: dict[int, np.ndarray] = {int(r): new[r] for r in sel}
        reductions += _resolve_parts(
            _RaggedView(coords, line_off),
            repl,
            sel,
            loops=False,
            groups=np.arange(len(sel)),
            part_geom=line_geom,
            first_part=first_line_of_geom,
            feat_index=feat_index,
            smoother=smoother,
            levels=levels,
        )
        sub = [repl[int(r)] for r in sel]
        sub_off = np.concatenate([[0], np.cumsum([len(x) for x in sub])]).astype(np.int64)
        new_xy, new_off = _put(new_xy, new_off, sel, np.concatenate(sub), sub_off)
    ml = shapely.from_ragged_array(T.MULTILINESTRING, new_xy, (new_off, geom_off))
    res = ml.copy()
    res[was_line] = shapely.get_geometry(ml[was_line], 0)
    # the area between every line and its chord, before and after
    a0 = signed_areas_ragged(coords, line_off)
    a1 = signed_areas_ragged(new_xy, new_off)
    lo = np.minimum.reduceat(coords, line_off[:-1], axis=0)
    hi = np.maximum.reduceat(coords, line_off[:-1], axis=0)
    ext = np.maximum((hi - lo).max(axis=1), 1e-300)
    scale = np.maximum(np.abs(a0), 1e-12 * ext**2)
    change = float(np.max(np.abs(a1 - a0) / scale)) if n_lines else 0.0
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


@gc_paused  # a layer's many Python objects: see curvesmith._gc
def smooth(
    geometry: Any,
    *,
    method: GisMethod = "cca",
    iterations: int = 1,
    alpha: Any = "regular",
    make_valid: bool = False,
    full_output: bool = False,
    fixed: Any = None,
    keep_angle: float | None = None,
    max_shift: float | None = None,
    min_segment: float | None = None,
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
        ``None`` and empty geometries are passed through unchanged. XYZ, XYM and XYZM
        geometries are smoothed in XY exactly as their 2D copies; every new vertex gets
        Z/M interpolated along the input edge it was built from (see ``curvesmith.geo._zm``).
        The index, the other columns and the CRS of a GeoSeries/GeoDataFrame are kept.
    method : {"cca", "chaikin"}
        Area-preserving CCA (default) or plain Chaikin corner cutting (shrinks shapes;
        for comparison).
    iterations : int
        Number of smoothing passes (each CCA pass triples the vertices).
    alpha : "regular", float or callable
        CCA cut ratio: the regular-polygon profile of the paper's Table 1, a constant in
        (0, 1/3), or a function of the interior angle in radians. Ignored by Chaikin.
    make_valid : bool
        Repair invalid input polygons with :func:`shapely.make_valid` instead of raising,
        by its ``method="structure"`` (as PostGIS' ``ST_MakeValid``): shells are unioned
        and holes subtracted, so overlapping parts merge and a hole drawn inside another
        hole (an island in a lake drawn as one polygon) is dropped; the default
        ``"linework"`` method would keep every line, also those of the drawing errors.
    full_output : bool
        Return a :class:`SmoothResult` with the reductions and the area check.
    fixed : (N,) bool array_like or callable, optional
        Vertices that must not move (CCA anchors, paper section 5): a boolean mask over
        ``shapely.get_coordinates(geometry)`` (all coordinates of the input in order,
        rings with their closing vertex), or a function taking an ``(N, 2)`` coordinate
        array and returning such a mask, e.g. ``lambda xy: np.abs(xy[:, 0]) == 180``
        for vertices on the antimeridian. Fixed vertices are kept bit for bit; a mask
        fixes every vertex at the coordinates it selects. Every ring still keeps its
        area (each piece between anchors keeps its area against its chord). Needs
        ``method="cca"``.
    keep_angle : float, optional
        Keep sharp corners: every vertex turning by more than this angle (radians; a
        square corner turns by pi/2) is fixed, as with `fixed`
        (:func:`curvesmith.geo.corner_vertices`). Needs ``method="cca"``.
    max_shift : float, optional
        Strength in map units: no feature's boundary moves farther than this (the
        Hausdorff distance between a feature's input and output, GEOS's discrete one,
        vertices to segments). `iterations` is then the most a feature gets; each
        feature gets the most iterations, from 0 (unchanged) up, that keep it within.
    min_segment : float, optional
        Vertex budget in map units: each feature gets the most iterations whose output
        has at most one vertex per `min_segment` of boundary length (its mean edge is at
        least `min_segment`); a feature already denser than that is left as it is.
        Both bounds keep every ring's area exact and the output valid: a feature's
        output is always that of a whole smoothing at its iteration count.

    Returns
    -------
    object or SmoothResult
        The smoothed geometry, of the input's type.

    Notes
    -----
    All rings (and all lines) of all features are smoothed in one call of the ragged
    engine (:func:`curvesmith.cca.smooth_ragged`), validity is checked for all
    features at once, and only the few features whose output is invalid are re-smoothed
    locally, so a layer of a million small polygons takes seconds.

    Raises
    ------
    CurveError
        For points, invalid polygons (without ``make_valid``), an
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
    from .._validate import as_bool

    iterations = check_method(method, iterations, alpha)
    make_valid = as_bool(make_valid, name="make_valid")
    if max_shift is not None or min_segment is not None:
        return _smooth_within_budget(
            geometry,
            max_shift=max_shift,
            min_segment=min_segment,
            full_output=full_output,
            options={
                "method": method,
                "iterations": iterations,
                "alpha": alpha,
                "make_valid": make_valid,
                "fixed": fixed,
                "keep_angle": keep_angle,
            },
        )
    geoms, wrap = as_geometry_array(geometry)
    given = geoms
    geoms, zm = split_zm(geoms)  # smoothed in XY; Z/M interpolated back (geo._zm)
    if keep_angle is not None:
        methods.needs("keep_angle", method)
    fixed = with_corners(geoms, for_method(fixed, method), keep_angle)
    fixed_spec = None
    if fixed is not None:
        methods.needs("fixed", method)
        fixed_spec = FixedVertices(fixed, geoms)
    still = _all_corners(geoms, fixed) if keep_angle is not None else None
    geoms, facts = _prepare(geoms, make_valid=make_valid, planar=True)  # 2D: split_zm
    if iterations == 0 and not make_valid:
        # nothing to smooth: the input, checked (an invalid polygon is an error), comes back
        # as it was, not cleaned of its repeated vertices
        result = wrap(np.array(given, dtype=object, copy=True))
        return SmoothResult(result, (), 0, 0.0) if full_output else result
    rows = None if facts.xy is None else len(facts.xy)  # (counting them again: 1.5 % of a call)
    check_layer_size(geoms, method, iterations, rows=rows)
    out, reductions, n, change = _smooth_feature_array(
        geoms, method=method, iterations=iterations, alpha=alpha, fixed=fixed_spec, facts=facts
    )
    if still is not None and still.any():
        # every vertex a kept corner (a rectilinear footprint): CCA adds only points on its
        # straight edges (3 iterations made 1,000,000 vertices 11,629,953, 1e-9 m away)
        out = np.array(out, dtype=object, copy=True)
        out[still] = geoms[still]
    _warn_off_the_map(geometry, out)
    result = wrap(out if zm is None else zm.restore(out))
    if full_output:
        return SmoothResult(result, tuple(reductions), n, change)
    return result


def _all_corners(geoms: np.ndarray, fixed: Any) -> np.ndarray | None:
    """Per feature: whether `fixed` (a mask over its coordinates) keeps every vertex."""
    shapely = _shapely()
    if not isinstance(fixed, np.ndarray) or fixed.dtype != bool:
        return None
    geoms = np.asarray(geoms, dtype=object)
    present = np.flatnonzero(~shapely.is_missing(geoms))
    _, which = shapely.get_coordinates(geoms[present], return_index=True)
    if len(which) != len(fixed):
        return None
    loose = np.bincount(which[~fixed], minlength=len(present))  # vertices not kept
    counts = np.bincount(which, minlength=len(present))
    still = np.zeros(len(geoms), dtype=bool)
    still[present] = (loose == 0) & (counts > 0)
    return still


@gc_paused
def smooth_to_packet(
    geoms: np.ndarray,
    *,
    method: GisMethod = "cca",
    iterations: int = 1,
    alpha: Any = "regular",
    make_valid: bool = False,
) -> tuple[Any, tuple[GeometryReduction, ...]] | None:
    """:func:`smooth` of a layer of Polygons without holes, straight to its packet.

    The packet (:mod:`curvesmith.geo._packets`) of what :func:`smooth` returns, bit for
    bit, and its reductions, without building the output geometries: the smoothed rings
    are the packet's coordinates, and GEOS builds only the few polygons whose validity
    the compiled proof leaves in doubt. What a Dask worker sends back (building the
    polygons and then reading their coordinates again was a quarter of its work).

    Returns None when `geoms` is not such a layer (None, empty, holes, other types, Z/M,
    repaired or repeated vertices): the caller then smooths and packs as usual.
    :func:`smooth_packet` does the same from a packet (what a Dask worker receives)
    and is tested against this.
    """
    shapely = _shapely()
    iterations = check_method(method, iterations, alpha)
    geoms = np.asarray(geoms, dtype=object)
    types = shapely.get_type_id(geoms)
    if len(geoms) == 0 or np.any(types != shapely.GeometryType.POLYGON):
        return None
    if shapely.has_z(geoms).any() or shapely.has_m(geoms).any():
        return None
    geoms, facts = _prepare(geoms, make_valid=make_valid, planar=True)
    single = (
        facts.xy is not None
        and facts.present.all()
        and not facts.empty.any()
        and np.all(facts.types == shapely.GeometryType.POLYGON)
        and not facts.holes.any()
    )
    if not single:
        return None
    return _rings_to_packet(geoms, facts, method, iterations, alpha)


def smooth_packet(
    packet: Any,
    *,
    method: GisMethod = "cca",
    iterations: int = 1,
    alpha: Any = "regular",
    make_valid: bool = False,
) -> tuple[Any, tuple[GeometryReduction, ...]] | None:
    """:func:`smooth_to_packet` of the geometries of a packet, without building them.

    For a packet of Polygons without holes (footprints, parcels) the input's facts are
    read off the packet: its coordinates and ring offsets are ``get_coordinates``' of the
    polygons, and the compiled proof of :func:`_prepare` runs on them. GEOS builds only
    the polygons that the proof leaves in doubt, to check them. The same bits as
    ``smooth_to_packet(unpack(packet))``; a Dask worker saves building the partition's
    polygons and reading their coordinates back. Returns None where that call would do
    more than smooth (an invalid polygon: an error or a repair; a repeated vertex; any
    other layer): the caller then takes the usual way.
    """
    from ._packets import POLYGONS
    from ._simple import rings_certainly_simple

    shapely = _shapely()
    iterations = check_method(method, iterations, alpha)
    n = len(packet)
    T = shapely.GeometryType
    if packet.kind != POLYGONS or n == 0 or not packet.filled.all():
        return None
    if np.any(packet.types != T.POLYGON):
        return None
    rings, polys, feats = packet.offsets
    ids = np.arange(n + 1)
    if len(rings) != n + 1 or not (np.array_equal(polys, ids) and np.array_equal(feats, ids)):
        return None  # holes
    xy = np.ascontiguousarray(packet.coords, dtype=np.float64)
    if not xy.flags.writeable:  # (a mapped file of the handover)
        xy = xy.copy()
    off = np.ascontiguousarray(rings, dtype=np.int64)
    types = np.full(n, T.POLYGON, dtype=np.int32)
    holes = np.zeros(n, dtype=np.int32)
    centres = np.full((n, 2), np.nan)
    proof = rings_certainly_simple(xy, off, True, centres)
    proven = _certainly_valid_polygons(types, holes, xy, off, centres, proof)
    doubt = np.flatnonzero(~proven)
    if doubt.size:
        d_xy, d_off = _take(xy, off, doubt)
        d_ids = np.arange(doubt.size + 1)
        d_geoms = shapely.from_ragged_array(T.POLYGON, d_xy, (d_off, d_ids))
        if not shapely.is_valid(d_geoms).all():
            return None  # smooth's error, or its repair with make_valid
        d_owner = np.repeat(np.arange(doubt.size), np.diff(d_off))
        if _repeating(d_xy, d_owner).size:
            return None  # smooth removes repeated vertices first
    facts = _Facts(np.ones(n, dtype=bool), types, np.zeros(n, dtype=bool), holes, xy, off, centres)
    placeholders = np.full(n, None, dtype=object)  # the rings alone are smoothed
    return _rings_to_packet(placeholders, facts, method, iterations, alpha)


def _rings_to_packet(geoms, facts, method, iterations, alpha):
    """The packet and reductions of a layer of Polygons without holes (``facts.xy``)."""
    from ._packets import POLYGONS, GeometryPacket

    shapely = _shapely()
    check_layer_size(geoms, method, iterations, rows=len(facts.xy))
    parts: list[dict] = []
    _, reductions, _, _ = _smooth_feature_array(
        geoms, method=method, iterations=iterations, alpha=alpha, facts=facts, ragged_out=parts
    )
    if len(parts) == 1:
        xy, rings = parts[0]["xy"], parts[0]["offsets"]
    else:
        xy = np.concatenate([q["xy"] for q in parts])
        base = np.cumsum([0] + [len(q["xy"]) for q in parts[:-1]])
        rings = np.concatenate(
            [[0]] + [q["offsets"][1:] + b for q, b in zip(parts, base, strict=True)]
        ).astype(np.int64)
    n = len(geoms)
    ids = np.arange(n + 1, dtype=np.int64)
    packet = GeometryPacket(
        POLYGONS,
        np.full(n, shapely.GeometryType.POLYGON, dtype=np.int8),
        np.ones(n, dtype=bool),
        np.ascontiguousarray(xy, dtype=np.float64),
        (np.asarray(rings, dtype=np.int64), ids, ids),
    )
    return packet, tuple(reductions)


def _warn_off_the_map(geometry: Any, out: np.ndarray) -> None:
    """Warn when smoothing data in a geographic CRS moved vertices beyond ±180° / ±90°.

    Vertices on the antimeridian or a pole move like any other unless they are fixed
    (``fixed=domain_fixed(crs)``, what ``curvesmith smooth`` does for such files).
    """
    crs = getattr(geometry, "crs", None)
    if crs is None or not getattr(crs, "is_geographic", False) or not len(out):
        return
    shapely = _shapely()
    present = out[~shapely.is_missing(out)]
    if not len(present):
        return
    x0, y0, x1, y1 = shapely.total_bounds(present)
    # beyond the domain and beyond the input (Natural Earth has 180.00000000000006 itself)
    a0, b0, a1, b1 = shapely.total_bounds(np.asarray(getattr(geometry, "geometry", geometry)))
    if x0 < min(-180.0, a0) or x1 > max(180.0, a1) or y0 < min(-90.0, b0) or y1 > max(90.0, b1):
        from ._io import GeographicCRSWarning

        warnings.warn(
            f"smoothing in a geographic CRS ({crs.name}) moved vertices beyond ±180°/±90° "
            f"(bounds {x0:.6g}, {y0:.6g}, {x1:.6g}, {y1:.6g}); pass "
            f"fixed=curvesmith.geo.domain_fixed(crs) to keep the vertices on the antimeridian "
            f"and the poles in place, or smooth in a projection",
            GeographicCRSWarning,
            stacklevel=3,
        )


def _smooth_within_budget(
    geometry: Any,
    *,
    max_shift: float | None,
    min_segment: float | None,
    full_output: bool,
    options: dict[str, Any],
) -> Any:
    """:func:`smooth` with the strength (`max_shift`) and density (`min_segment`) bounds.

    Every feature is smoothed at every strength (whole runs, so every candidate is a valid
    output with exact areas): with `max_shift`, one pass at 1/8, 1/4 and 1/2 of the cut
    ratio, then ``1 .. iterations`` passes; each feature takes the strongest that meets
    both bounds. A feature that even one pass at 1/8 moves too far (a large one: a 1 km
    square moves about 19 m) is smoothed once more, alone with the others of its kind, at
    the cut ratio scaled down by the power of 2 that the excess asks for (the shift of one
    shallow pass is about proportional to the cut), halved again up to
    :data:`WEAK_RETRIES` times while it still moves too far; what is left stays as it is
    (``n_unchanged``).
    """
    from .._validate import as_float

    shapely = _shapely()
    if max_shift is not None:
        max_shift = as_float(max_shift, name="max_shift", low=0.0)
    if min_segment is not None:
        min_segment = as_float(min_segment, name="min_segment", low=0.0)
    geoms, wrap = as_geometry_array(geometry)
    geoms = np.asarray(geoms, dtype=object)
    # the chosen features and the run of the moment: up to 1.5 times the strongest run
    check_layer_size(geoms, options["method"], int(options["iterations"]), levels=True)
    present = ~(shapely.is_missing(geoms) | shapely.is_empty(geoms))
    chosen = np.array(geoms, dtype=object, copy=True)
    level = np.full(len(geoms), -1, dtype=int)  # index into `steps`; -1: unchanged
    runs = {}
    excess = None  # per feature, the powers of 2 by which the weakest pass moves too far
    if max_shift is not None:
        from . import _shift

        before = _shift.Linework(geoms[present])  # XY: the shift is measured in the plane
    top = int(options["iterations"])
    # the strengths tried, weakest first: with max_shift, one pass at 1/8, 1/4 and 1/2 of
    # the cut ratio (a shallower cut moves the boundary less), then 1 .. iterations passes
    steps = [(1, scale) for scale in (0.125, 0.25, 0.5)] if max_shift is not None else []
    steps += [(k, 1.0) for k in range(1, top + 1)]
    for j, (k, scale) in enumerate(steps if top else []):
        alpha = _scaled_alpha(options["alpha"], scale)
        res = smooth(geoms, **{**options, "iterations": k, "alpha": alpha}, full_output=True)
        out = np.asarray(res.geometry, dtype=object)
        ok = np.ones(int(present.sum()), dtype=bool)
        if max_shift is not None:
            after = _shift.Linework(out[present])
            within = _shift.shifts_within(before, after, max_shift)
            if j == 0 and max_shift > 0:
                # the weakest pass: by how many powers of 2 it misses, where it does
                far = np.flatnonzero(present)[~within]
                excess = np.zeros(len(geoms), dtype=np.int64)
                excess[far] = _shift.excess_powers(
                    _shift.Linework(geoms[far]), _shift.Linework(out[far]), max_shift
                )
            ok &= within
        if min_segment is not None:
            smoothed = shapely.force_2d(out[present])
            # edges of the output: coordinates minus one per ring or line
            n_edges = shapely.get_num_coordinates(smoothed) - _num_linear(smoothed)
            ok &= shapely.length(smoothed) >= min_segment * np.maximum(n_edges, 1)
        idx = np.flatnonzero(present)[ok]
        chosen[idx] = out[idx]
        level[idx] = j
        runs[j] = res
        if max_shift is None and not ok.any():
            break  # more passes only add vertices (the shift need not grow monotonically)
    reductions = [r for j, res in runs.items() for r in res.reductions if level[r.feature] == j]
    changes = [res.max_area_change for j, res in runs.items() if (level == j).any()]
    n_curves = next(iter(runs.values())).n_curves if runs else 0
    if excess is not None:
        # features that the weakest pass moved too far: shallower single passes, per feature
        # the power of 2 its excess asks for, each group smoothed in one call of its own
        pos = np.flatnonzero(present)
        need = excess[pos]
        left = (level[pos] < 0) & (need > 0)
        for _ in range(WEAK_RETRIES + 1):
            todo = pos[left]
            if not todo.size:
                break
            for m in np.unique(need[left]):
                sub = todo[need[left] == m]
                scale = 0.125 * 2.0 ** -float(m)
                alpha = _scaled_alpha(options["alpha"], scale)
                sub_options = {**options, "iterations": 1, "alpha": alpha}
                given = options.get("fixed")
                if given is not None and not callable(given):
                    # a mask over the input's coordinates: the rows of these features
                    off = np.zeros(len(geoms) + 1, dtype=np.int64)
                    np.cumsum(shapely.get_num_coordinates(geoms), out=off[1:])
                    sub_options["fixed"] = np.asarray(given, dtype=bool)[_expand(off, sub)[0]]
                res = smooth(geoms[sub], **sub_options, full_output=True)
                out = np.asarray(res.geometry, dtype=object)
                ok = _shift.shifts_within(
                    _shift.Linework(geoms[sub]), _shift.Linework(out), max_shift
                )
                if min_segment is not None:
                    two = shapely.force_2d(out)
                    n_edges = shapely.get_num_coordinates(two) - _num_linear(two)
                    ok &= shapely.length(two) >= min_segment * np.maximum(n_edges, 1)
                chosen[sub[ok]] = out[ok]
                level[sub[ok]] = len(steps)
                reductions += [
                    GeometryReduction(
                        int(sub[r.feature]), r.ring, r.start, r.stop, r.iterations, r.alpha_scale
                    )
                    for r in res.reductions
                    if ok[r.feature]
                ]
                if ok.any():
                    changes.append(res.max_area_change)
            done = level[pos] >= 0
            left &= ~done
            need = need + 1  # those still too far: half again
    n_unchanged = int(np.count_nonzero(present & (level < 0))) if top else 0
    result = SmoothResult(
        wrap(chosen), tuple(reductions), n_curves, max(changes, default=0.0), n_unchanged
    )
    return result if full_output else result.geometry


#: Halvings of the cut ratio tried after the first shallow single pass of a feature that
#: the weakest standard strength moves farther than ``max_shift`` (see
#: :func:`_smooth_within_budget`).
WEAK_RETRIES = 2


def _scaled_alpha(alpha: Any, scale: float) -> Any:
    """The CCA cut parameter times `scale` (the regular profile, a constant or a callable)."""
    if scale == 1.0:
        return alpha
    if isinstance(alpha, str):
        from ..cca._profiles import alpha_profile

        return lambda theta: scale * np.asarray(alpha_profile(theta), dtype=float)
    if callable(alpha):
        return lambda theta: scale * np.asarray(alpha(theta), dtype=float)
    return scale * float(alpha)


def _num_linear(geoms: np.ndarray) -> np.ndarray:
    """Rings plus lines of each geometry (each closes or ends once: one edge less)."""
    shapely = _shapely()
    parts, owner = shapely.get_parts(geoms, return_index=True)
    kind = shapely.get_type_id(parts)
    per_part = np.where(kind == 3, shapely.get_num_interior_rings(parts) + 1, 1)
    return np.bincount(owner, weights=per_part, minlength=len(geoms)).astype(int)
