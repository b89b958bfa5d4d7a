"""Smoothing of polygonal coverages: shared arcs smoothed once, polygons rebuilt from them."""

from __future__ import annotations

import functools
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .. import methods
from .._gc import gc_paused
from .._rich import RichRepr
from ..errors import CurveError, OutputSizeError
from ..methods import GisMethod
from . import _zm
from ._corners import for_method, with_corners
from ._engine import in_background, levels_for, resolve_arcs
from ._smooth import (
    FixedVertices,
    _shapely,
    _take,
    as_geometry_array,
    assemble_polygons,
    check_layer_size,
    check_method,
    make_smoother,
    prepare,
    smooth_batch,
)

#: Arcs are handed to Dask workers in blocks of this many consecutive arcs. Every arc is
#: smoothed as its own curve of a ragged batch, so the blocks do not change the result.
ARC_BLOCK = 512

__all__ = [
    "CoverageReduction",
    "CoverageResult",
    "Topology",
    "coverage_topology",
    "smooth_coverage",
]


@dataclass(frozen=True)
class CoverageReduction:
    """A piece of a shared arc smoothed less, to keep it from crossing another arc.

    Attributes
    ----------
    arc : int
        Arc index in :attr:`Topology.arcs`.
    polygons : tuple of int
        Positions of the features whose boundary contains the arc.
    start, stop : int
        First and last vertex (inclusive) of the piece in the arc.
    iterations : int
        Iterations applied to the piece (0: unchanged).
    alpha_scale : float
        Factor applied to alpha for the piece.
    """

    arc: int
    polygons: tuple[int, ...]
    start: int
    stop: int
    iterations: int
    alpha_scale: float


@dataclass(frozen=True)
class Topology:
    """The arc-node structure of a coverage.

    Attributes
    ----------
    arcs : tuple of (K_i, 2) ndarray
        Vertices of every arc. An open arc runs between two nodes (its first and last
        vertex, which may coincide); a loop (``loops[i]``) is a closed ring without any node
        (an island, or a hole filled by one polygon) and lists its vertices once.
    loops : (M,) bool ndarray
        Which arcs are loops.
    frozen : (M,) bool ndarray
        Arcs made of invalid coverage edges (:func:`shapely.coverage_invalid_edges`): kept
        unchanged so that no gap or overlap can appear there.
    arc_polygons : tuple of tuple of int
        For every arc, the positions of the features it bounds (two for a shared arc,
        one on the outer boundary, more only in an invalid coverage).
    rings : tuple of tuple of (int, bool)
        For every ring (in ``shapely.to_ragged_array`` order), its arcs in order with a
        flag ``True`` when traversed in the arc's own direction.
    n_nodes : int
        Number of distinct nodes (junctions of three or more edges, or points where the
        set of polygons along the boundary changes).
    uses : tuple of three (U,) ndarray, optional
        `rings` flattened: the ring, the arc and the direction flag of every use, in
        order (from :func:`coverage_topology`; computed from `rings` when absent).
    """

    arcs: tuple[np.ndarray, ...]
    loops: np.ndarray
    frozen: np.ndarray
    arc_polygons: tuple[tuple[int, ...], ...]
    rings: tuple[tuple[tuple[int, bool], ...], ...]
    n_nodes: int
    ring_offsets: tuple[np.ndarray, np.ndarray]
    was_polygon: np.ndarray
    ring_sign: np.ndarray | None = None
    uses: tuple[np.ndarray, np.ndarray, np.ndarray] | None = field(
        default=None, repr=False, compare=False
    )

    @functools.cached_property
    def _ends(self) -> tuple[np.ndarray, np.ndarray]:
        """The first and the last vertex of every arc, ``(M, 2)`` each (computed once)."""
        first = np.array([a[0] for a in self.arcs]).reshape(-1, 2)
        last = np.array([a[-1] for a in self.arcs]).reshape(-1, 2)
        return first, last


@dataclass(frozen=True)
class CoverageResult(RichRepr):
    """Result of :func:`smooth_coverage` with ``full_output=True``.

    Attributes
    ----------
    geometry : object
        The smoothed coverage, of the input's type.
    n_arcs, n_nodes : int
        Size of the arc-node structure that was smoothed.
    reductions : tuple of CoverageReduction
        Arc pieces smoothed less than requested because they would have crossed another
        arc (or themselves).
    invalid_edges : dict of int to float
        Features with invalid coverage edges in the input (overlaps, unmatched vertices
        along a shared border, gaps narrower than ``gap_width``): position -> total length
        of those edges. Their arcs are kept unchanged.
    max_area_change : float
        Largest relative area change ``|A' - A| / A`` of a feature (against the input
        after the optional snapping). Round-off with ``method="cca"``.
    coverage_valid : bool or None
        :func:`shapely.coverage_is_valid` on the result (None when ``validate=False``).
    input_coverage_valid : bool
        The same test on the input (after snapping).
    snap_area_change : float
        With ``snap``: the largest relative area change ``|A_s - A| / A`` that the
        snapping itself made (before any smoothing; ``max_area_change`` is measured
        after it); 0 without.
    """

    geometry: Any
    n_arcs: int
    n_nodes: int
    reductions: tuple[CoverageReduction, ...]
    invalid_edges: dict[int, float]
    max_area_change: float
    coverage_valid: bool | None
    input_coverage_valid: bool
    snap_area_change: float = 0.0


def coverage_topology(polygons: Any, *, frozen_edges: Any = None) -> Topology:
    """Split a coverage into arcs between nodes.

    A valid coverage (:func:`shapely.coverage_is_valid`, checked with GEOS) has identical
    vertices along every shared border, so no noding is needed: shared edges are found by
    exact comparison of their end vertices, nodes are the vertices with other than two
    distinct incident edges or where the set of polygons along the boundary changes, and
    every ring is cut at its nodes into arcs. On a valid coverage this gives the same arcs
    as GEOS noding and merging (``shapely.line_merge(shapely.union_all(boundaries))``),
    which the tests check, at a fraction of the time.

    Parameters
    ----------
    polygons : sequence of Polygon / MultiPolygon
        Non-empty polygons (already validated).
    frozen_edges : sequence of geometry, optional
        Per polygon, lines made of its own edges to keep fixed (as returned by
        :func:`shapely.coverage_invalid_edges`).

    Returns
    -------
    Topology
    """
    from ._arrangement_kernel import ring_orientation
    from ._topology_kernel import (
        lexicographic_first,
        node_flags,
        point_ids,
        segment_classes,
    )

    shapely = _shapely()
    T = shapely.GeometryType
    g = np.asarray(polygons, dtype=object)
    was_polygon = shapely.get_type_id(g) == T.POLYGON
    gtype, coords, offsets = shapely.to_ragged_array(g)
    if gtype == T.POLYGON:
        (ring_off, poly_off), geom_off = offsets, np.arange(len(g) + 1)
    else:
        ring_off, poly_off, geom_off = offsets
    n_rings = len(ring_off) - 1
    ring_poly = np.searchsorted(poly_off, np.arange(n_rings), side="right") - 1
    ring_geom = np.searchsorted(geom_off, ring_poly, side="right") - 1

    # vertices (without the repeated closing one) and their point ids (exact coordinates)
    is_last = np.zeros(len(coords), dtype=bool)
    is_last[ring_off[1:] - 1] = True
    vert = np.nonzero(~is_last)[0]
    xy_all = coords[vert]
    xy_all += 0.0  # -0.0 -> 0.0
    extra = np.empty((0, 2))
    extra_idx = np.empty(0, dtype=np.int64)
    if frozen_edges is not None:
        fr = np.asarray(frozen_edges, dtype=object)
        fr = fr[np.array([f is not None for f in fr], dtype=bool)]
        fr = fr[~shapely.is_empty(fr)]
        if len(fr):
            extra, extra_idx = shapely.get_coordinates(shapely.get_parts(fr), return_index=True)
            extra = extra + 0.0
    pts = np.vstack([xy_all, extra])
    pid_all, n_pts = point_ids(pts)  # exact coordinates, hashed
    pid = pid_all[: len(vert)]

    # segments: vertex k -> k+1 of every ring (cyclic), classed by their unordered points
    n_vert = np.diff(ring_off) - 1
    seg_off = np.concatenate([[0], np.cumsum(n_vert)])  # per ring, into vert / segments
    nxt = np.arange(len(vert)) + 1
    nxt[seg_off[1:] - 1] = seg_off[:-1]  # cyclic successor within the ring
    prev = np.arange(len(vert)) - 1
    prev[seg_off[:-1]] = seg_off[1:] - 1  # cyclic predecessor
    # the frozen edges' segments are classed after the rings' ones: classes follow first
    # appearance, so a frozen segment that is a ring edge has a class below n_cls
    fa = fb = np.empty(0, dtype=np.int64)
    if len(extra):
        epid = pid_all[len(vert) :]
        same = extra_idx[1:] == extra_idx[:-1]
        fa, fb = epid[:-1][same], epid[1:][same]
    n_ring_segs = len(vert)
    cls, cls_lo, cls_hi = segment_classes(
        np.concatenate([pid, fa]), np.concatenate([pid[nxt], fb]), n_pts
    )
    cls, frozen_of = cls[:n_ring_segs], cls[n_ring_segs:]
    n_cls = int(cls.max()) + 1 if n_ring_segs else 0
    cls_lo, cls_hi = cls_lo[:n_cls], cls_hi[:n_cls]
    seg_ring = np.repeat(np.arange(n_rings), n_vert)
    seg_geom = ring_geom[seg_ring]
    count = np.bincount(cls, minlength=n_cls)
    gmin = np.full(n_cls, np.iinfo(np.int64).max)
    gmax = np.full(n_cls, -1)
    np.minimum.at(gmin, cls, seg_geom)
    np.maximum.at(gmax, cls, seg_geom)
    frozen_cls = np.zeros(n_cls, dtype=bool)
    frozen_cls[frozen_of[frozen_of < n_cls]] = True

    # nodes: points with other than two distinct edges, or where the edge signature changes
    deg = np.bincount(cls_lo, minlength=n_pts) + np.bincount(cls_hi, minlength=n_pts)
    node = node_flags(pid, cls, prev, deg, count, gmin, gmax, frozen_cls)
    n_nodes = len(np.unique(pid[node]))

    # every ring rotated to start at its first node (a ring without one: at its smallest
    # point id, lexicographically first), then cut into runs at its nodes: the segments
    # of all rings in that order are a permutation of the segments
    total = int(seg_off[-1])
    has_node = np.zeros(n_rings, dtype=bool)
    first_node = np.zeros(n_rings, dtype=np.int64)
    at = np.flatnonzero(node)
    if at.size:
        rr, pos = np.unique(seg_ring[at], return_index=True)
        has_node[rr] = True
        first_node[rr] = at[pos] - seg_off[rr]
    rot = first_node
    bare = np.flatnonzero(~has_node & (n_vert > 0))
    if bare.size:  # every ring without a node starts at its lexicographically first point
        rot = rot.copy()
        rot[bare] = lexicographic_first(xy_all, seg_off[:-1][bare], n_vert[bare])
    base = np.repeat(seg_off[:-1], n_vert)
    j = np.arange(total) - base
    perm = base + (np.repeat(rot, n_vert) + j) % np.repeat(n_vert, n_vert)
    start_flag = node[perm] | (j == 0)
    run_start = np.flatnonzero(start_flag)
    run_end = np.append(run_start[1:], total)
    run_ring = seg_ring[perm[run_start]]
    run_loop = ~has_node[run_ring]
    cls_perm = cls[perm]
    key = np.minimum.reduceat(cls_perm, run_start)
    first_pid = pid[perm[run_start]]
    first_cls = cls_perm[run_start]
    # arcs numbered in order of their first run; later runs of an arc find its direction
    _, first_occ, inv = np.unique(key, return_index=True, return_inverse=True)
    arc_order = np.argsort(first_occ, kind="stable")
    arc_of_key = np.empty(len(first_occ), dtype=np.int64)
    arc_of_key[arc_order] = np.arange(len(first_occ))
    run_arc = arc_of_key[inv.reshape(-1)]
    def_run = first_occ[arc_order]
    fwd = (first_pid == first_pid[def_run[run_arc]]) & (first_cls == first_cls[def_run[run_arc]])
    # arc vertices: the run's segment starts, and an open run's end vertex
    d0, d1, dloop = run_start[def_run], run_end[def_run], run_loop[def_run]
    n_seg = d1 - d0
    n_pts_arc = n_seg + (~dloop).astype(np.int64)
    arc_off = np.zeros(len(def_run) + 1, dtype=np.int64)
    np.cumsum(n_pts_arc, out=arc_off[1:])
    t = np.arange(arc_off[-1]) - np.repeat(arc_off[:-1], n_pts_arc)
    src_pos = np.repeat(d0, n_pts_arc) + np.minimum(t, np.repeat(n_seg - 1, n_pts_arc))
    vsel = perm[src_pos]
    tail = t == np.repeat(n_seg, n_pts_arc)  # the end vertex of an open arc
    vsel[tail] = nxt[vsel[tail]]
    arc_xy = xy_all[vsel]
    arcs = [arc_xy[i:j] for i, j in zip(arc_off[:-1].tolist(), arc_off[1:].tolist(), strict=True)]
    c0s = first_cls[def_run]
    loops = dloop
    frozen = frozen_cls[c0s]
    arc_polys: list[tuple[int, ...]] = []
    lo_l, hi_l, few = gmin[c0s].tolist(), gmax[c0s].tolist(), (count[c0s] <= 2).tolist()
    for c0, lo_g, hi_g, two in zip(c0s.tolist(), lo_l, hi_l, few, strict=True):
        if two:  # one or two polygons along the arc: the least and the greatest
            arc_polys.append((lo_g,) if lo_g == hi_g else (lo_g, hi_g))
        else:
            arc_polys.append(tuple(sorted({int(x) for x in seg_geom[cls == c0]})))
    ring_first = np.searchsorted(run_ring, np.arange(n_rings + 1))
    pairs = list(zip(run_arc.tolist(), fwd.tolist(), strict=True))
    rings = [tuple(pairs[ring_first[r] : ring_first[r + 1]]) for r in range(n_rings)]
    return Topology(
        arcs=tuple(arcs),
        loops=np.asarray(loops, dtype=bool),
        frozen=np.asarray(frozen, dtype=bool),
        arc_polygons=tuple(arc_polys),
        rings=tuple(rings),
        n_nodes=n_nodes,
        ring_offsets=(poly_off, geom_off),
        was_polygon=was_polygon,
        ring_sign=ring_orientation(coords, np.asarray(ring_off, dtype=np.int64)),
        uses=(run_ring.astype(np.int64), run_arc.astype(np.int64), fwd.astype(bool)),
    )


def rebuild(topo: Topology, arcs: list[np.ndarray]) -> np.ndarray:
    """Polygons from (smoothed) arcs, in the topology's ring order."""
    coords, offs = ring_coordinates(topo, arcs)
    poly_off, geom_off = topo.ring_offsets
    return assemble_polygons(coords, offs, poly_off, geom_off, topo.was_polygon)


def ring_coordinates(
    topo: Topology, arcs: list[np.ndarray], uses=None, ragged=None
) -> tuple[np.ndarray, np.ndarray]:
    """The rings rebuilt from (smoothed) arcs: closed coordinates and ring offsets.

    Every ring is its arcs in order (reversed where the ring runs against the arc), each
    without its last vertex (the next arc's first) unless it is a loop, and the ring's
    first vertex again at the end. `uses`: :func:`_flat_uses` of the topology; `ragged`:
    :func:`_ragged` of `arcs` (loops closed), when at hand.
    """
    from ._arrangement_kernel import gather_rings

    ring, arc, fwd = _flat_uses(topo) if uses is None else uses
    n_rings = len(topo.rings)
    u_off = np.searchsorted(ring, np.arange(n_rings + 1))
    if ragged is not None:
        X, a_off = ragged
        loops = np.asarray(topo.loops, bool)
        return gather_rings(X, a_off, loops, arc, fwd, u_off, True)
    lens = np.fromiter((len(x) for x in arcs), dtype=np.int64, count=len(arcs))
    a_off = np.zeros(len(arcs) + 1, dtype=np.int64)
    np.cumsum(lens, out=a_off[1:])
    allxy = np.concatenate(arcs) if len(arcs) else np.empty((0, 2))
    return gather_rings(
        np.ascontiguousarray(allxy, dtype=np.float64), a_off, np.asarray(topo.loops, bool),
        arc, fwd, u_off,
    )  # fmt: skip


@gc_paused  # a layer's many Python objects: see curvesmith._gc
def smooth_coverage(
    polygons: Any,
    *,
    method: GisMethod = "cca",
    iterations: int = 1,
    alpha: Any = "regular",
    snap: float | None = None,
    gap_width: float = 0.0,
    make_valid: bool = False,
    validate: bool = True,
    full_output: bool = False,
    map_arcs: Callable[[Topology], list[np.ndarray]] | None = None,
    fixed: Any = None,
    keep_angle: float | None = None,
    max_shift: float | None = None,
    min_segment: float | None = None,
) -> Any:
    """Smooth a polygonal coverage so that every polygon keeps its area and no gap opens.

    The coverage is split into arcs between nodes (:func:`coverage_topology`); every arc is
    smoothed once, as a CCA polyline with its two end nodes fixed (a loop without nodes as
    a closed CCA ring), and every polygon is rebuilt from its arcs. Because CCA keeps the
    area between a polyline and its chord (Gordon 2010, section 3, end edges, Fig. 9), the
    signed area between an old arc and its smoothed version is zero, so every polygon keeps
    its area, and because neighbours share the very same smoothed arc there are no gaps or
    overlaps. Arcs that would cross another arc (or themselves) are cut at anchor vertices
    and the conflicting pieces smoothed less (reported in
    :attr:`CoverageResult.reductions`).

    Imperfect coverages are detected with :func:`shapely.coverage_invalid_edges` and
    reported per polygon; the arcs made of invalid edges are kept unchanged, so the
    smoothing adds no gap or overlap that was not in the input. With ``snap`` the coverage
    is first cleaned by :func:`shapely.coverage_clean` (vertices snapped within ``snap``,
    overlaps merged into a neighbour); areas are then compared against the cleaned input.

    Parameters
    ----------
    polygons : sequence of Polygon / MultiPolygon, GeoSeries or GeoDataFrame
        The coverage. ``None`` and empty geometries are passed through unchanged.
    method : {"cca", "chaikin"}
        Area-preserving CCA (default) or Chaikin (for comparison; shrinks polygons).
    iterations : int
        Smoothing passes per arc.
    alpha : "regular", float or callable
        CCA cut ratio (see :func:`curvesmith.geo.smooth`).
    snap : float, optional
        Snapping distance for :func:`shapely.coverage_clean` (in CRS units).
    gap_width : float
        Gaps narrower than this are reported as invalid edges.
    make_valid : bool
        Repair invalid input polygons with :func:`shapely.make_valid` instead of raising,
        by its ``method="structure"`` (as PostGIS' ``ST_MakeValid``): shells are unioned
        and holes subtracted, so overlapping parts merge and a hole drawn inside another
        hole (an island in a lake drawn as one polygon) is dropped; the default
        ``"linework"`` method would keep every line, also those of the drawing errors.
    validate : bool
        Check the result with :func:`shapely.coverage_is_valid`. Its verdict is proven by
        a compiled test of the arcs and nodes where it can be (:func:`certainly_valid`,
        exact; the input is tested the same way) and asked of GEOS otherwise.
    full_output : bool
        Return a :class:`CoverageResult`.
    map_arcs : callable, optional
        ``map_arcs(topology) -> list of arrays``: the first, full-strength smoothing of
        every arc, e.g. run in parallel (:mod:`curvesmith.batch` passes a Dask map here).
        Conflicts are then resolved here as usual. Not used with `fixed`.
    fixed : (N,) bool array_like or callable, optional
        Vertices that must not move, as in :func:`curvesmith.geo.smooth`: a mask over
        ``shapely.get_coordinates(polygons)`` or a callable on ``(N, 2)`` coordinates.
        Every arc through a fixed vertex is anchored there (the areas stay exact).
        Needs ``method="cca"``.
    keep_angle : float, optional
        Keep sharp corners: every vertex turning by more than this angle (radians; a
        square corner turns by pi/2) is fixed (:func:`curvesmith.geo.corner_vertices`).
        Needs ``method="cca"``.
    max_shift, min_segment : float, optional
        Strength and vertex budget in map units, arc by arc: every shared arc gets the
        strongest level (1 .. iterations passes, then shallower cuts) whose Hausdorff
        distance from its input is at most `max_shift` and that has at most one vertex per
        `min_segment` of its length; an arc with no such level keeps its input. A polygon's
        boundary is a union of arcs, so it moves no farther than `max_shift`; areas stay
        exact and the coverage gap-free.

    Returns
    -------
    object or CoverageResult
        The smoothed coverage, of the input's type.

    Examples
    --------
    >>> import shapely
    >>> from curvesmith import geo
    >>> top = shapely.Polygon([(0, 1), (1, 1), (2, 1), (2, 2), (0, 2)])
    >>> cells = [shapely.box(0, 0, 1, 1), shapely.box(1, 0, 2, 1), top]
    >>> res = geo.smooth_coverage(cells, iterations=2, full_output=True)
    >>> [round(p.area, 12) for p in res.geometry], bool(shapely.coverage_is_valid(res.geometry))
    ([1.0, 1.0, 2.0], True)
    """
    from .._validate import as_bool

    make_valid = as_bool(make_valid, name="make_valid")
    shapely = _shapely()
    iterations = check_method(method, iterations, alpha)
    geoms, wrap = as_geometry_array(polygons)
    given, wrap_given = geoms, wrap  # what iterations=0 gives back
    # with max_shift / min_segment every level is held at once
    bounded = max_shift is not None or min_segment is not None
    check_layer_size(geoms, method, iterations, levels=bounded)
    geoms, zm = _zm.split_zm(geoms)  # smoothed in XY; Z/M interpolated back (geo._zm)
    if zm is not None:
        wrap = _zm.restoring(wrap, zm)
    if keep_angle is not None:
        methods.needs("keep_angle", method)
    fixed = with_corners(geoms, for_method(fixed, method), keep_angle)
    fixed_spec = None
    if fixed is not None:
        methods.needs("fixed", method)
        fixed_spec = FixedVertices(fixed, geoms)
        map_arcs = None
    # in the plain case the compiled coverage proof also proves the polygons of one ring
    # valid (_polygons_valid); GEOS checks the others
    if snap is not None:
        snap = float(snap)
        if not snap >= 0.0:
            raise CurveError(f"snap must be >= 0, got {snap}")
    gap_width = float(gap_width)
    if not gap_width >= 0.0:
        raise CurveError(f"gap_width must be >= 0, got {gap_width}")
    plain = snap is None and gap_width == 0.0
    geoms_in = geoms
    geoms, idx, g = _coverage_input(geoms_in, make_valid, plain)
    snap_change = 0.0
    if snap is not None:
        cleaned = shapely.remove_repeated_points(
            shapely.coverage_clean(g, snapping_distance=snap), 0.0
        )
        # a snap distance as wide as a feature snaps it away: refused, not written empty
        # (two polygons 170 m wide, snap 200: one came back empty, the other halved)
        gone = np.flatnonzero(shapely.is_empty(cleaned) & ~shapely.is_empty(g))
        if len(gone):
            k = int(gone[0])
            raise CurveError(
                f"snap {snap:g} removes {len(gone)} feature(s) entirely (geometry[{idx[k]}], "
                f"area {float(shapely.area(g[k])):.6g}); use a snap distance well below the "
                "features' widths"
            )
        before = shapely.area(g)
        if len(g):
            moved = np.abs(shapely.area(cleaned) - before) / np.where(before > 0, before, 1.0)
            snap_change = float(np.max(moved))
        g = cleaned
    # the compiled proof (certainly_valid) for the plain case; GEOS decides the rest
    topo, uses, input_valid = None, None, False
    if plain and len(g):
        topo, uses, input_valid = _proven_topology(g)
        if not _polygons_valid(g, topo, uses, input_valid):
            # an invalid polygon: prepared as without the deferral (its error, or repairs)
            geoms, idx, g = _coverage_input(geoms_in, make_valid, False)
            topo, uses, input_valid = _proven_topology(g) if len(g) else (None, None, False)
    out = geoms.copy()
    if len(g) == 0:
        res = wrap(out)
        return (
            CoverageResult(res, 0, 0, (), {}, 0.0, True if validate else None, True)
            if (full_output)
            else res
        )
    if not input_valid:
        input_valid = bool(shapely.coverage_is_valid(g, gap_width=gap_width))
    if input_valid:
        invalid, bad = None, np.zeros(len(g), dtype=bool)
    else:
        invalid = shapely.coverage_invalid_edges(g, gap_width=gap_width)
        bad = ~shapely.is_empty(invalid)
    invalid_report = (
        {int(idx[k]): float(shapely.length(invalid[k])) for k in np.nonzero(bad)[0]}
        if invalid is not None
        else {}
    )
    if topo is None or bad.any():
        topo = coverage_topology(g, frozen_edges=invalid if bad.any() else None)
        uses = None
    bounded = max_shift is not None or min_segment is not None  # every level tried at once
    initial = map_arcs(topo) if (map_arcs is not None and iterations > 0 and not bounded) else None
    rag: dict = {}
    smoothed, reductions = smooth_arcs(
        topo,
        method=method,
        iterations=iterations,
        alpha=alpha,
        initial=initial,
        fixed=fixed_spec,
        max_shift=max_shift,
        min_segment=min_segment,
        ragged_out=rag,
    )
    if uses is None:
        uses = _flat_uses(topo)
    ragged = (rag["xy"], rag["off"]) if rag else _ragged(smoothed, topo.loops)
    # the output proof's longest part, the arcs' meetings, runs while the polygons are built
    first = rag.get("meetings")
    meets = in_background(_arc_meetings, *ragged, topo.loops, first) if validate else None
    coords, offs = ring_coordinates(topo, smoothed, uses, ragged)
    poly_off, geom_off = topo.ring_offsets
    new = assemble_polygons(coords, offs, poly_off, geom_off, topo.was_polygon)
    out[idx] = new
    a0 = shapely.area(g)
    a1 = shapely.area(new)
    change = float(np.max(np.abs(a1 - a0) / np.where(a0 > 0, a0, 1.0)))
    valid = None
    if validate:
        valid = _output_valid(topo, uses, smoothed, coords, offs, new, ragged, meets)
    if iterations == 0 and snap is None and not make_valid:
        # nothing smoothed: the input as it was, not rebuilt from its arcs (which would
        # start rings elsewhere and drop repeated vertices); checked and reported as above
        res = wrap_given(np.array(given, dtype=object, copy=True))
    else:
        res = wrap(out)
    if not full_output:
        return res
    red = tuple(
        CoverageReduction(
            r.arc,
            tuple(int(idx[p]) for p in topo.arc_polygons[r.arc]),
            r.start,
            r.stop,
            r.iterations,
            r.alpha_scale,
        )
        for r in reductions
    )
    return CoverageResult(
        res, len(topo.arcs), topo.n_nodes, red, invalid_report, change, valid, input_valid,
        snap_change,
    )  # fmt: skip


def _coverage_input(geoms, make_valid: bool, defer_validity: bool):
    """The prepared geometries, the positions of the non-empty ones and these: ``(all, idx, g)``."""
    shapely = _shapely()
    geoms = prepare(geoms, make_valid=make_valid, what="polygons", defer_validity=defer_validity)
    present = np.array([g is not None for g in geoms], dtype=bool)
    present[present] = ~shapely.is_empty(geoms[present])
    types = shapely.get_type_id(geoms[present])
    T = shapely.GeometryType
    okt = (types == T.POLYGON) | (types == T.MULTIPOLYGON)
    if not okt.all():
        k = int(np.nonzero(present)[0][np.nonzero(~okt)[0][0]])
        raise CurveError(
            f"polygons[{k}] is a {geoms[k].geom_type}: a coverage contains only "
            f"Polygons and MultiPolygons"
        )
    idx = np.nonzero(present)[0]
    return geoms, idx, geoms[idx]


def _proven_topology(g: np.ndarray) -> tuple[Topology, Any, bool]:
    """The topology of a coverage, its ring uses and whether :func:`certainly_valid` proves it."""
    topo = coverage_topology(g)
    uses = _flat_uses(topo)
    proven = certainly_valid(topo.arcs, topo.loops, uses, _shells(topo), topo.ring_sign, g)
    return topo, uses, proven


def _polygons_valid(g: np.ndarray, topo: Topology, uses, proven: bool) -> bool:
    """Whether every polygon is valid: by the coverage proof where it can tell, else GEOS."""
    shapely = _shapely()
    doubt = ~_valid_by_proof(topo, uses, g) if proven else np.ones(len(g), dtype=bool)
    return not doubt.any() or bool(shapely.is_valid(g[doubt]).all())


def _valid_by_proof(topo: Topology, uses, polygons: np.ndarray, rings=None) -> np.ndarray:
    """Per polygon of a coverage that :func:`certainly_valid` proved: whether it is valid.

    `polygons`: the coverage's geometries, built from the topology's rings (the input,
    or the rebuilt output). The arcs are simple and meet only at their end nodes (part
    (a) of the proof). So a ring that passes through no node twice is simple (two of its
    arcs that are not consecutive could meet only at a node it passes twice), and two
    rings of one feature that share no node and no arc do not meet at all. A Polygon of
    one such ring is valid (its orientation is not zero: the proof checks it); a feature
    of several such rings is valid when they nest as a valid (Multi)Polygon's do, which
    :func:`curvesmith.geo._simple.nesting_certainly_valid` decides from one vertex per
    ring. False: not proven (GEOS decides). `rings`: ``(coords, offsets)`` of the
    polygons' rings in the topology's order (closed), when at hand.
    """
    from ._simple import nesting_certainly_valid, nesting_certainly_valid_rows
    from ._smooth import _expand, polygon_ragged
    from ._topology_kernel import point_ids

    ring, arc, fwd = uses
    poly_off, geom_off = topo.ring_offsets
    n_geoms = len(geom_off) - 1
    ring_poly = np.searchsorted(poly_off, ring, side="right") - 1
    feat = np.searchsorted(geom_off, ring_poly, side="right") - 1  # the feature of every use
    first, last = topo._ends
    on_node = ~np.asarray(topo.loops, dtype=bool)[arc]  # a loop's ring has no node
    start = np.where(fwd[:, None], first[arc], last[arc])[on_node]  # the node a use leaves
    nid, n_ids = point_ids(np.ascontiguousarray(start) + 0.0)
    doubt = np.zeros(n_geoms, dtype=bool)
    # a node passed twice by the rings of one feature (by one ring, or by two), or an arc
    # used twice in one feature (a loop in two of its rings)
    for owner, item, n_items in (
        (feat[on_node], nid, max(n_ids, 1)),
        (feat, arc, max(len(topo.arcs), 1)),
    ):
        key = np.sort(owner * n_items + item)
        doubt[key[1:][key[1:] == key[:-1]] // n_items] = True
    n_rings = np.diff(poly_off[geom_off])  # of every feature
    one_ring = topo.was_polygon & (n_rings == 1)
    valid = one_ring & ~doubt
    # the other features: rings simple and disjoint, so their nesting decides (a feature
    # without rings, which a large snap distance leaves, is GEOS's to judge)
    cand = np.flatnonzero(~one_ring & ~doubt & (n_rings > 0))
    if len(cand) == 0:
        return valid
    if rings is None:  # the rings as shapely gives them: the topology's order
        g = np.asarray(polygons, dtype=object)[cand]
        xy, ring_off, part_off, feat_off = polygon_ragged(g, topo.was_polygon[cand])
        valid[cand] = nesting_certainly_valid(xy, ring_off, part_off, feat_off)
    else:  # the rebuilt rings, read in place
        part_idx, feat_off = _expand(geom_off, cand)
        ring_idx, part_off = _expand(poly_off, part_idx)
        xy, r_off = rings
        valid[cand] = nesting_certainly_valid_rows(
            xy, r_off[ring_idx], r_off[ring_idx + 1], part_off, feat_off
        )
    return valid


#: Threads of the one engine call that smooths all arcs of a coverage (None: cca's default,
#: up to 4, 1 in Dask workers, which set OMP_NUM_THREADS=1). Unlike a layer's many small
#: rings, the arcs are one large batch: 2 threads took the counties' arcs from 0.23-0.30 s
#: to 0.14-0.25 s wall (CPU the same to a third more); the result does not depend on it.
ARC_THREADS: int | None = None


def smooth_arc_blocks(
    arcs,
    loops,
    frozen,
    *,
    method: str,
    iterations: int,
    alpha: Any,
    fixed: FixedVertices | None = None,
    ragged_out: dict | None = None,
) -> tuple[list[np.ndarray], list[tuple[int, str]]]:
    """Full-strength smoothing of arcs: all of them in one call of the ragged engine.

    Open arcs keep their end nodes, loops are closed curves, frozen arcs are kept. Every
    arc gets what the single-curve smoother gives it alone, whatever the other arcs of
    the call (so Dask blocks and one process agree bit for bit). If the batch fails, the
    arcs are smoothed one by one to isolate the failing ones: an arc whose smoothing
    fails is kept unchanged and returned in the errors list as ``(position, reason)``.
    `ragged_out`: receives ``"xy"`` and ``"off"``, the smoothed arcs in the layout of
    :func:`_ragged` (loops closed), when every arc was smoothed in the one call.
    """
    from ._engine import Level

    level = Level(iterations)
    out: list[np.ndarray] = list(arcs)
    errors: list[tuple[int, str]] = []
    todo = np.flatnonzero(~np.asarray(frozen, dtype=bool))
    if iterations == 0 or todo.size == 0:
        return out, errors
    xy = np.concatenate([arcs[k] for k in todo])
    off = np.zeros(todo.size + 1, dtype=np.int64)
    np.cumsum([len(arcs[k]) for k in todo], out=off[1:])
    closed = np.asarray(loops, dtype=bool)[todo]
    try:
        fmask = fixed.mask(xy) if fixed is not None else None
        new_xy, new_off = smooth_batch(
            method, alpha, xy, off, closed, level, fmask, close_rings=True, threads=ARC_THREADS
        )
    except OutputSizeError:  # arc by arc, the same output would be held
        raise
    except Exception:  # isolate the failing arcs, one by one
        smoother = make_smoother(method, alpha, fixed)
        for k in todo:
            try:
                out[k] = smoother(arcs[k], bool(loops[k]), level)
            except Exception as exc:  # the arc stays unchanged and is reported
                errors.append((int(k), f"{type(exc).__name__}: {exc}"))
        return out, errors
    for k, a, b, loop in zip(todo, new_off[:-1], new_off[1:], closed, strict=True):
        out[k] = new_xy[a : b - 1] if loop else new_xy[a:b]  # a loop without its closing vertex
    if ragged_out is not None and todo.size == len(arcs):
        ragged_out["xy"], ragged_out["off"] = new_xy, new_off
    return out, errors


def smooth_arcs(
    topo: Topology,
    *,
    method,
    iterations,
    alpha,
    initial=None,
    fixed=None,
    max_shift=None,
    min_segment=None,
    ragged_out=None,
):
    """Smooth the arcs of a topology with conflict resolution; returns (arcs, reductions).

    `ragged_out`: receives ``"xy"`` and ``"off"``, the smoothed arcs in the layout of
    :func:`_ragged`, when they are at hand (the full-strength arcs, nothing reduced), and
    ``"meetings"``, what the resolution's first round found of their meetings (see
    :func:`curvesmith.geo._engine.resolve_arcs`' `meetings_out`), for :func:`_arc_meetings`.

    With `max_shift` / `min_segment` every arc starts at the strongest level within them
    (:func:`bounded_levels`); an arc that the resolution then leaves outside them (a piece
    cut at anchors can move differently) keeps its input vertices, and the resolution runs
    again.
    """
    smoother = make_smoother(method, alpha, fixed)
    levels = levels_for(iterations, scalable=methods.get(method).scalable)
    if iterations == 0:
        return list(topo.arcs), []
    if max_shift is not None or min_segment is not None:
        return smooth_arcs_bounded(
            topo.arcs,
            topo.loops,
            topo.frozen,
            levels=levels,
            smoother=smoother,
            method=method,
            alpha=alpha,
            fixed=fixed,
            max_shift=max_shift,
            min_segment=min_segment,
        )
    rag: dict = {}
    if initial is None:
        initial, errors = smooth_arc_blocks(
            topo.arcs,
            topo.loops,
            topo.frozen,
            method=method,
            iterations=iterations,
            alpha=alpha,
            fixed=fixed,
            ragged_out=rag,
        )
        if errors:
            k, reason = errors[0]
            raise CurveError(f"arc {k} (features {topo.arc_polygons[k]}) failed: {reason}")
    first: dict = {}
    out, reductions = resolve_arcs(
        topo.arcs,
        loops=topo.loops,
        groups=np.zeros(len(topo.arcs), dtype=int),
        frozen=topo.frozen,
        smoother=smoother,
        levels=levels,
        initial=initial,
        initial_ragged=rag or None,
        meetings_out=first,
    )
    if ragged_out is not None and rag:
        if reductions:  # the full-strength arcs with the reduced ones put in
            rag = _patched(rag, out, initial, topo.loops, {r.arc for r in reductions})
        ragged_out.update(rag)
        if first:
            ragged_out["meetings"] = first
    return out, reductions


def _patched(rag: dict, arcs, initial, loops, reduced: set[int]) -> dict:
    """:func:`_ragged` of `arcs` from `rag`, that of the full-strength arcs `initial`.

    An arc that was not reduced is its full-strength smoothing, the very array of
    `initial` (a view of its rows of ``rag["xy"]``, as :func:`smooth_arc_blocks` made
    it), so the runs of such arcs between the few reduced ones are copied as blocks
    (the US counties: 11 of 11,159 arcs reduced, 12 ms against 54 ms for concatenating
    every arc again).
    """
    n = len(arcs)
    changed = np.fromiter(
        (k in reduced or a is not b for k, (a, b) in enumerate(zip(arcs, initial, strict=True))),
        dtype=bool,
        count=n,
    )
    idx = np.flatnonzero(changed)
    sub_xy, sub_off = _ragged([arcs[k] for k in idx], np.asarray(loops, dtype=bool)[idx])
    xy, off = rag["xy"], rag["off"]
    lens = np.diff(off)
    lens[idx] = np.diff(sub_off)
    new_off = np.zeros(off.size, dtype=np.int64)
    np.cumsum(lens, out=new_off[1:])
    out = np.empty((int(new_off[-1]), xy.shape[1]))
    prev = 0  # first arc of the current run of unchanged arcs
    for j, k in enumerate([*idx.tolist(), n]):
        if k > prev:  # arcs prev .. k - 1 in one block
            out[new_off[prev] : new_off[k]] = xy[off[prev] : off[k]]
        if k < n:
            out[new_off[k] : new_off[k + 1]] = sub_xy[sub_off[j] : sub_off[j + 1]]
        prev = k + 1
    return {"xy": out, "off": new_off}


def _arc_lines(arcs, ring: np.ndarray):
    """The arcs as LineStrings (loops closed by repeating their first vertex)."""
    import shapely

    pts = [np.vstack([x, x[:1]]) if r else x for x, r in zip(arcs, ring, strict=True)]
    return shapely.linestrings(
        np.concatenate(pts), indices=np.repeat(np.arange(len(pts)), [len(x) for x in pts])
    )


def _ragged(arcs, ring: np.ndarray):
    """Coordinates and offsets of the arcs (loops closed by repeating their first vertex)."""
    from ._engine import _flat
    from ._smooth import _close_ragged

    xy, off = _flat(arcs)
    ring = np.asarray(ring, dtype=bool)
    if ring.any():
        xy, off = _close_ragged(xy, off, ring)
    return np.ascontiguousarray(xy, dtype=np.float64), off


def shifts_within(before, after, max_shift: float) -> np.ndarray:
    """Per arc: whether it moved no farther than `max_shift` (discrete Hausdorff distance).

    `before` and `after` are ``(coordinates, offsets)`` of :func:`_ragged`. The same measure
    as :func:`shapely.hausdorff_distance` (every vertex of each within `max_shift` of the
    other polyline), decided by a compiled search instead of computed pair by pair (GEOS
    compares every vertex with every segment: 38 s of 40 on Jacksboro's contour lines).
    """
    from ._clearance_kernel import shifts_within as kernel

    n = len(before[1]) - 1
    arcs = np.arange(n + 1, dtype=np.int64)  # one polyline per arc
    (xa, offa), (xb, offb) = before, after
    return kernel(xa, offa, arcs, xb, offb, arcs, np.full(n, float(max_shift)))


def bounded_levels(
    arcs,
    loops,
    frozen,
    levels,
    *,
    method: str,
    alpha: Any,
    fixed: FixedVertices | None = None,
    max_shift: float | None = None,
    min_segment: float | None = None,
) -> tuple[np.ndarray, dict[int, list[np.ndarray]]]:
    """The strongest level of every arc within the map-unit bounds, and the arcs at them.

    An arc's shift is the Hausdorff distance between its input and output polylines (a
    feature's boundary is a union of arcs, so it moves no farther than its farthest arc);
    its density is its length per edge. Every level is computed for all arcs in one ragged
    call; an arc that meets the bounds at no level keeps its input (the last level).
    """
    import shapely

    from ._smooth import _scaled_alpha

    top = len(levels) - 1
    start = np.full(len(arcs), top, dtype=int)

    ring = np.asarray(loops, dtype=bool)
    before_xy = _ragged(arcs, ring) if max_shift is not None else None
    seeds: dict[int, list[np.ndarray]] = {}
    open_ = ~np.asarray(frozen, dtype=bool)
    for j, lev in enumerate(levels[:-1]):
        todo = open_ & (start == top)
        if not todo.any():
            break
        out, _ = smooth_arc_blocks(
            arcs,
            loops,
            ~todo,
            method=method,
            iterations=lev.iterations,
            alpha=_scaled_alpha(alpha, lev.alpha_scale),
            fixed=fixed,
        )
        ok = todo.copy()
        if max_shift is not None:
            ok &= shifts_within(before_xy, _ragged(out, ring), max_shift)
        if min_segment is not None:
            edges = np.array([len(x) if r else len(x) - 1 for x, r in zip(out, ring, strict=True)])
            ok &= shapely.length(_arc_lines(out, ring)) >= min_segment * np.maximum(edges, 1)
        start[ok] = j
        seeds[j] = out
    return start, seeds


def smooth_arcs_bounded(
    arcs, loops, frozen, *, levels, smoother, method, alpha, fixed, max_shift, min_segment
):
    """Arcs smoothed within the map-unit bounds, with conflict resolution (coverage, network).

    Returns ``(arcs, reductions)`` as :func:`curvesmith.geo._engine.resolve_arcs`.
    """
    import shapely

    from .._validate import as_float

    if max_shift is not None:
        max_shift = as_float(max_shift, name="max_shift", low=0.0)
    if min_segment is not None:
        min_segment = as_float(min_segment, name="min_segment", low=0.0)
    frozen = np.array(frozen, dtype=bool, copy=True)
    ring = np.asarray(loops, dtype=bool)

    before = _ragged(arcs, ring)
    for _ in range(len(arcs) + 1):  # every round freezes at least one more arc
        start, seeds = bounded_levels(
            arcs,
            loops,
            frozen,
            levels,
            method=method,
            alpha=alpha,
            fixed=fixed,
            max_shift=max_shift,
            min_segment=min_segment,
        )
        out, reductions = resolve_arcs(
            arcs,
            loops=loops,
            groups=np.zeros(len(arcs), dtype=int),
            frozen=frozen,
            smoother=smoother,
            levels=levels,
            start=start,
            seeds=seeds,
        )
        bad = np.zeros(len(out), dtype=bool)
        if max_shift is not None:
            bad |= ~shifts_within(before, _ragged(out, ring), max_shift)
        if min_segment is not None:
            edges = np.array([len(x) if r else len(x) - 1 for x, r in zip(out, ring, strict=True)])
            changed = np.array([not np.array_equal(a, b) for a, b in zip(out, arcs, strict=True)])
            length = shapely.length(_arc_lines(out, ring))
            bad |= changed & (length < min_segment * np.maximum(edges, 1))
        bad &= ~frozen
        if not bad.any():
            return out, reductions
        frozen |= bad  # these arcs keep their input; resolve the others around them again
    raise AssertionError("unreachable: each round freezes one more arc")  # pragma: no cover


def _shells(topo: Topology) -> np.ndarray:
    """Per ring: whether it is the exterior ring of its polygon."""
    poly_off = topo.ring_offsets[0]
    shell = np.zeros(int(poly_off[-1]), dtype=bool)
    shell[poly_off[:-1]] = True
    return shell


def _output_valid(topo, uses, smoothed, coords, offs, new, ragged=None, meets=None) -> bool:
    """:func:`shapely.coverage_is_valid` of the rebuilt polygons, proven when possible.

    The proof (:func:`certainly_valid`) needs valid polygons: part (a) of it makes the
    rings of every feature simple and disjoint where they pass through no node twice and
    share none (:func:`_valid_by_proof`), and then one vertex per ring tells whether they
    nest validly. GEOS checks the other features (a hole touching its shell at a node).
    """
    import shapely

    from ._arrangement_kernel import ring_orientation

    if uses is None:
        uses = _flat_uses(topo)
    ends = topo._ends
    sign = ring_orientation(coords, offs)
    shells = _shells(topo)
    if certainly_valid(
        smoothed, topo.loops, uses, shells, sign, new, ends=ends, ragged=ragged, meets=meets
    ):
        doubt = ~_valid_by_proof(topo, uses, new, (coords, offs))
        if not doubt.any() or shapely.is_valid(new[doubt]).all():
            return True
    return bool(shapely.coverage_is_valid(new))


def _flat_uses(topo: Topology) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Every (ring, arc, forward) use of the topology's rings, as three arrays."""
    if topo.uses is not None:
        return topo.uses
    lens = np.fromiter((len(r) for r in topo.rings), dtype=np.int64, count=len(topo.rings))
    flat = [u for r in topo.rings for u in r]
    arc = np.fromiter((k for k, _ in flat), dtype=np.int64, count=len(flat))
    fwd = np.fromiter((f for _, f in flat), dtype=bool, count=len(flat))
    return np.repeat(np.arange(len(topo.rings)), lens), arc, fwd


def _orient_signs(o, p, q) -> np.ndarray:
    """Exact orientation signs of q against o -> p, row by row (filter, then rationals)."""
    from ._arrangement_kernel import orient_exact
    from ._simple_kernel import _CCW_ERR, _TINY

    left = (o[:, 0] - q[:, 0]) * (p[:, 1] - q[:, 1])
    right = (o[:, 1] - q[:, 1]) * (p[:, 0] - q[:, 0])
    det = left - right
    err = _CCW_ERR * (np.abs(left) + np.abs(right))
    sign = np.where(det > err, 1, np.where(-det > err, -1, 0))
    unsure = np.flatnonzero((sign == 0) | ~(np.abs(left) + np.abs(right) > _TINY))
    for k in unsure:
        sign[k] = orient_exact(o[k], p[k], q[k])
    return sign


def _arc_meetings(X: np.ndarray, off: np.ndarray, loops: np.ndarray, first=None) -> bool:
    """Part (a) of :func:`certainly_valid`: whether no two segments of the arcs meet (MEET).

    False also when the exact comparison could not decide. `first`: what the conflict
    resolution's first round found of the arcs' meetings, when every pair was compared
    there (``resolve_arcs(meetings_out=...)``): the arcs it left unchanged keep their
    verdicts, a pair of them that met fails at once, and only the pairs with a changed
    arc are compared again: each changed arc with itself and with every arc whose
    bounding box meets its own (two segments can meet only then). The US counties,
    12 arcs changed of 11,159: 10-20 ms against 0.13-0.18 s for every pair again.
    """
    from ._arrangement_kernel import MEET, meetings
    from ._clearance_kernel import polyline_boxes

    n = len(off) - 1
    loops = np.asarray(loops, dtype=bool)
    if first is not None and first.get("complete"):
        changed = first["changed"]
        a, b = first["pairs"]
        if np.any(~changed[a] & ~changed[b]):
            return False
        idx = np.flatnonzero(changed)
        if idx.size == 0:
            return True
        if idx.size <= 256:  # else every pair again: many arcs changed
            box = polyline_boxes(X, off)
            near = np.zeros(n, dtype=bool)
            near[idx] = True
            for k in idx:
                near |= (
                    (box[:, 0] <= box[k, 1]) & (box[:, 1] >= box[k, 0])
                    & (box[:, 2] <= box[k, 3]) & (box[:, 3] >= box[k, 2])
                )  # fmt: skip  # (x0, x1, y0, y1)
            sub = np.flatnonzero(near)
            xs, offs = _take(X, off, sub)
            got = meetings(
                xs, offs, loops[sub], np.zeros(sub.size, np.int64), changed[sub], self_pairs=True
            )
            return got is not None and not np.any(got[2] == MEET)
    got = meetings(X, off, loops, np.zeros(n, np.int64), np.ones(n, bool), self_pairs=True)
    return got is not None and not np.any(got[2] == MEET)


def certainly_valid(
    arcs, loops, uses, shell, ring_sign, polygons, *, ends=None, ragged=None, meets=None
) -> bool:
    """Whether the polygons rebuilt from `arcs` are proven to form a valid coverage.

    A sufficient test of :func:`shapely.coverage_is_valid` (gap width 0) for valid
    polygons whose rings are the arc sequences `uses` (``(ring, arc, forward)``); False
    means "not proven" (ask GEOS). The polygons form a valid coverage (interiors
    disjoint, shared borders with the same vertices) when

    (a) the arcs meet only at shared end nodes: no crossing, touch or collinear overlap
        anywhere else, and every arc is simple (:func:`_arrangement_kernel.meetings`,
        exact);
    (b) every arc is used by at most one ring with the interior on its left and at most
        one with the interior on its right (``shell[r]`` and the ring's orientation
        ``ring_sign[r]`` give the side);
    (c) at every node, in the exact angular order of its half-edges, every wedge between
        two consecutive half-edges is covered by as many polygons as seen from either of
        them;
    (d) on every connected component of the arcs, a vertex inside one of its arcs (not a
        node) lies in no polygon's interior.

    With (a) the arcs form a plane graph, and the number ``c(e)`` of polygons whose
    interior contains an arc ``e`` is constant along it. A wedge at a node is covered by
    ``c(e) + L(e)`` polygons, ``L(e)`` those that use ``e`` with the interior on the
    wedge's side, so (c) makes ``c`` equal on consecutive half-edges, hence constant on
    each component, and (d) measures it on one arc (by (a) its vertex is on no other
    arc, and on the boundary of the polygons that use it): 0. By (b) every face next to
    an arc is then covered at most once: no overlaps. With (a) two segments of different
    polygons are equal or meet only at a common vertex, so the borders match vertex for
    vertex. Conversely a
    valid coverage passes, except where a vertex lies on another edge of its own polygon
    (a hole touching its shell), a component has only single-segment arcs (no probe
    vertex) or an exact sign is undecided: then GEOS decides.
    `ends`: the arcs' input end nodes, which the output arcs must keep; `ragged`:
    :func:`_ragged` of `arcs`, when at hand; `meets`: a future of :func:`_arc_meetings`
    (its verdict on part (a)) of that ragged form, started earlier (in a thread, while the
    polygons were built).
    """
    import shapely

    from ._topology_kernel import point_ids

    n_arcs = len(arcs)
    if n_arcs == 0 or np.any(ring_sign == 0):
        return False
    loops = np.asarray(loops, dtype=bool)
    X, off = _ragged(arcs, loops) if ragged is None else ragged
    lens = np.diff(off) - loops  # vertices of every arc (a loop's first not repeated)
    if np.any(lens < 1):
        return False
    first = X[off[:-1]]
    last = X[off[1:] - 1 - loops]
    if ends is not None and not (
        np.array_equal(first[~loops], ends[0][~loops])
        and np.array_equal(last[~loops], ends[1][~loops])
    ):
        return False
    # (a)
    if not (meets.result() if meets is not None else _arc_meetings(X, off, loops)):
        return False
    # (b)
    ring, arc, fwd = uses
    inside_left = (shell == (ring_sign > 0))[ring] == fwd  # interior left of the arc
    left = np.bincount(arc[inside_left], minlength=n_arcs)
    right = np.bincount(arc[~inside_left], minlength=n_arcs)
    if left.max() > 1 or right.max() > 1:
        return False
    # (c) half-edges at nodes: (node point, next vertex, arc, outgoing)
    opn = np.flatnonzero(~loops)
    lens = lens[opn]
    if np.any(lens < 2):
        return False
    nxt = X[off[opn] + 1]
    prv = X[off[opn + 1] - 2]
    node_xy = np.concatenate([first[opn], last[opn]])
    dir_xy = np.concatenate([nxt, prv])
    h_arc = np.concatenate([opn, opn])
    h_out = np.concatenate([np.ones(len(opn), bool), np.zeros(len(opn), bool)])
    if len(h_arc):
        upper = (dir_xy[:, 1] > node_xy[:, 1]) | (
            (dir_xy[:, 1] == node_xy[:, 1]) & (dir_xy[:, 0] > node_xy[:, 0])
        )
        ang = np.arctan2(dir_xy[:, 1] - node_xy[:, 1], dir_xy[:, 0] - node_xy[:, 0])
        ang = np.where(ang < 0.0, ang + 2.0 * np.pi, ang)  # [0, 2 pi), as the halves
        order = np.lexsort((ang, ~upper, node_xy[:, 1], node_xy[:, 0]))
        node_xy, dir_xy, h_arc, h_out, upper = (
            node_xy[order], dir_xy[order], h_arc[order], h_out[order], upper[order]
        )  # fmt: skip
        new = np.ones(len(h_arc), bool)
        new[1:] = np.any(node_xy[1:] != node_xy[:-1], axis=1)
        node_id = np.cumsum(new) - 1
        start = np.flatnonzero(new)
        deg = np.diff(np.append(start, len(h_arc)))
        if deg.min() < 2:
            return False
        # exact order check of consecutive half-edges of a node
        same = ~new[1:]
        i = np.flatnonzero(same)
        if len(i):
            ok_half = upper[i] >= upper[i + 1]  # upper half first
            both = upper[i] == upper[i + 1]
            sgn = _orient_signs(node_xy[i], dir_xy[i], dir_xy[i + 1])
            if not np.all(ok_half & (~both | (sgn > 0))):
                return False
        # wedge from half-edge h to the next one (cyclically) at its node
        nxt_h = np.arange(len(h_arc)) + 1
        end = start + deg
        wrap = nxt_h == end[node_id]
        nxt_h[wrap] = start[node_id[wrap]]
        seen_here = np.where(h_out, left[h_arc], right[h_arc])  # wedge left of outgoing h
        seen_next = np.where(h_out[nxt_h], right[h_arc[nxt_h]], left[h_arc[nxt_h]])
        if not np.array_equal(seen_here, seen_next):
            return False
    # (d) one vertex per connected component of the arc graph, inside an arc (not a node)
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    pts = np.concatenate([first[opn], last[opn]])
    pid, n_nodes = point_ids(np.ascontiguousarray(pts, dtype=np.float64) + 0.0)
    lp = np.flatnonzero(loops)
    reps = [X[off[lp] + 1] if len(lp) else np.empty((0, 2))]
    if n_nodes:
        m = len(opn)
        graph = coo_matrix((np.ones(m), (pid[:m], pid[m:])), shape=(n_nodes, n_nodes))
        n_comp, comp = connected_components(graph, directed=False)
        long_arc = lens >= 3  # an arc with a vertex that is not a node
        comp_of_arc = comp[pid[:m]]
        have, one = np.unique(comp_of_arc[long_arc], return_index=True)
        if len(have) < n_comp:
            return False  # a component of single-segment arcs only: GEOS decides
        reps.append(X[off[opn[np.flatnonzero(long_arc)[one]]] + 1])
    probe = shapely.points(np.concatenate(reps))
    tree = shapely.STRtree(np.asarray(polygons, dtype=object))
    hit = tree.query(probe, predicate="within")
    return hit.shape[1] == 0
