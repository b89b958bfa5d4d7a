"""Smoothing of line networks: junctions fixed, shared pieces smoothed once, no new contacts.

Rivers, roads, boundaries and contour lines are networks: lines end on other lines, share
vertices, cross, or run along each other. Smoothing each line on its own (what per-line
Chaikin, PostGIS ``ST_ChaikinSmoothing`` or QGIS "Smooth" do) moves those meeting points and
makes neighbouring lines cross. :func:`smooth_network` instead

1. *nodes* the network: every crossing of two segments and every end or vertex lying on
   the interior of another segment becomes a vertex of both lines (computed by GEOS,
   :func:`shapely.intersection` on the candidate segment pairs of a
   :class:`shapely.STRtree`), so that all contacts are shared vertices;
2. finds the *nodes* -- line ends, vertices where other than two distinct edges meet,
   crossings, and optional fixed points -- and cuts every line at them into *arcs*; a piece
   two lines share (identical edges) is one arc;
3. smooths every arc once with its two end nodes fixed (a closed line that meets nothing
   as a closed ring), and resolves the contacts smoothing would create locally with the
   engine of the coverage mode (:func:`curvesmith.geo._engine.resolve_arcs`): a conflicting
   arc is cut at anchors and only the conflicting pieces are smoothed less;
4. rebuilds every line from its arcs.

With CCA (Gordon 2010) every arc keeps the signed area between itself and its chord
(section 3, end edges, Fig. 9; section 5, anchor points), so the signed area between an
input line and its smoothed version is zero, and a closed line keeps its enclosed area: its
chords are fixed and each arc keeps its area against its chord.

Coordinates are handled as ``(N, 2)`` XY rows throughout; the per-vertex ``fixed`` mask of
the internal engine (:func:`network_topology`) is where further fixed vertices (sharp
corners, for instance) can be added.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from .. import methods
from .._gc import gc_paused
from .._rich import RichRepr
from ..errors import CurveError
from ..geometry import _signed_area  # trapezoid shoelace about the first vertex
from ..methods import GisMethod
from . import _zm
from ._corners import with_corners
from ._coverage import smooth_arcs_bounded
from ._engine import Level, levels_for, resolve_arcs
from ._smooth import _shapely, as_geometry_array, check_layer_size, check_method, make_smoother

__all__ = [
    "NetworkReduction",
    "NetworkResult",
    "NetworkTopology",
    "changed_contacts",
    "level_contacts",
    "network_topology",
    "smooth_network",
]

#: Open arcs are smoothed in blocks of this many consecutive arcs, one chained CCA call each.
ARC_BLOCK = 512


@dataclass(frozen=True)
class NetworkReduction:
    """A piece of an arc smoothed less, to keep it from touching another line (or itself).

    Attributes
    ----------
    arc : int
        Arc index in :attr:`NetworkTopology.arcs`.
    features : tuple of int
        Positions of the features whose lines contain the arc.
    start, stop : int
        First and last vertex (inclusive) of the piece in the arc.
    iterations : int
        Iterations applied to the piece (0: unchanged).
    alpha_scale : float
        Factor applied to alpha for the piece.
    """

    arc: int
    features: tuple[int, ...]
    start: int
    stop: int
    iterations: int
    alpha_scale: float


@dataclass(frozen=True)
class NetworkResult(RichRepr):
    """Result of :func:`smooth_network` with ``full_output=True``.

    Attributes
    ----------
    geometry : object
        The smoothed network, of the input's type.
    n_lines : int
        Lines smoothed (LineStrings, parts of MultiLineStrings, LinearRings).
    n_arcs, n_nodes : int
        Size of the arc-node structure: arcs between nodes, and fixed nodes.
    n_inserted : int
        Vertices inserted by noding (crossings, ends on the interior of a segment,
        overlapping segments).
    reductions : tuple of NetworkReduction
        Arc pieces smoothed less than requested because they would have touched or
        crossed another arc (or themselves).
    max_area_change : float
        Closed lines: largest relative change ``|A' - A| / |A|`` of the enclosed signed
        area. Round-off with ``method="cca"``.
    max_open_area : float
        Open lines: largest signed area between an input line and its output (the closed
        polygon input + reversed output), divided by the line's squared length.
        Round-off with ``method="cca"``.
    """

    geometry: Any
    n_lines: int
    n_arcs: int
    n_nodes: int
    n_inserted: int
    reductions: tuple[NetworkReduction, ...]
    max_area_change: float
    max_open_area: float


@dataclass(frozen=True)
class NetworkTopology:
    """The arc-node structure of a noded line network.

    Attributes
    ----------
    lines : tuple of (N_i, 2) ndarray
        Every line after noding (closed lines without their repeated closing vertex).
    closed : (L,) bool ndarray
        Which lines are closed.
    arcs : tuple of (K_j, 2) ndarray
        Vertices of every arc: open arcs from node to node (the two may coincide), loops
        (``loops[j]``) listed once without a node.
    loops : (M,) bool ndarray
        Closed lines that meet no node.
    arc_lines : tuple of tuple of int
        For every arc, the lines that contain it (more than one for a shared piece).
    runs : tuple of tuple of (int, bool)
        For every line, its arcs in order with ``True`` when traversed in the arc's own
        direction. A closed line with nodes starts at its first node.
    nodes : (K, 2) ndarray
        Coordinates of the nodes.
    n_inserted : int
        Vertices inserted by noding.
    """

    lines: tuple[np.ndarray, ...]
    closed: np.ndarray
    arcs: tuple[np.ndarray, ...]
    loops: np.ndarray
    arc_lines: tuple[tuple[int, ...], ...]
    runs: tuple[tuple[tuple[int, bool], ...], ...]
    nodes: np.ndarray
    n_inserted: int


def _node_lines(lines: list[np.ndarray], closed: np.ndarray, fixed: list[np.ndarray]):
    """Insert every contact point of two segments as a vertex of both.

    Returns the new lines, their fixed masks (inserted vertices are not fixed: they become
    nodes by their degree) and the number of inserted vertices.
    """
    shapely = _shapely()
    n_v = np.array([len(x) for x in lines], dtype=np.int64)
    v_off = np.concatenate([[0], np.cumsum(n_v)])
    xy = np.concatenate(lines)
    part = np.repeat(np.arange(len(lines)), n_v)
    # segments k -> k+1, cyclic for closed lines
    n_s = np.where(closed, n_v, n_v - 1)
    s_part = np.repeat(np.arange(len(lines)), n_s)
    s_off = np.concatenate([[0], np.cumsum(n_s)])
    s_k = np.arange(len(s_part)) - s_off[s_part]
    a = v_off[s_part] + s_k
    b = v_off[s_part] + (s_k + 1) % n_v[s_part]
    segs = shapely.linestrings(np.stack([xy[a], xy[b]], axis=1))
    i, j = shapely.STRtree(segs).query(segs, predicate="intersects")
    keep = i < j
    i, j = i[keep], j[keep]
    # consecutive segments of a line meet at their shared vertex; they overlap only if the
    # line turns back on itself (collinear, same direction away from the shared vertex)
    share = np.full(len(i), -1, dtype=np.int64)
    for p, q in ((a, a), (a, b), (b, a), (b, b)):
        hit = p[i] == q[j]
        share[hit] = p[i][hit]
    adj = share >= 0
    if adj.any():
        ia, ja, sv = i[adj], j[adj], share[adj]
        oi = np.where(a[ia] == sv, b[ia], a[ia])
        oj = np.where(a[ja] == sv, b[ja], a[ja])
        di, dj = xy[oi] - xy[sv], xy[oj] - xy[sv]
        cross = di[:, 0] * dj[:, 1] - di[:, 1] * dj[:, 0]
        dot = np.einsum("ij,ij->i", di, dj)
        back = (cross == 0) & (dot > 0)
        keep = ~adj
        keep[np.nonzero(adj)[0][back]] = True
        i, j = i[keep], j[keep]
    n_inserted = 0
    if len(i):
        inter = shapely.intersection(segs[i], segs[j])
        pts, idx = shapely.get_coordinates(inter, return_index=True)
        pts = pts + 0.0  # -0.0 -> 0.0
        ins_seg = np.concatenate([i[idx], j[idx]])
        ins_xy = np.concatenate([pts, pts])
        pa, pb = xy[a[ins_seg]], xy[b[ins_seg]]
        new = np.any(ins_xy != pa, axis=1) & np.any(ins_xy != pb, axis=1)
        ins_seg, ins_xy, pa, pb = ins_seg[new], ins_xy[new], pa[new], pb[new]
        d = pb - pa
        t = np.einsum("ij,ij->i", ins_xy - pa, d) / np.einsum("ij,ij->i", d, d)
        t = np.clip(t, 0.0, 1.0)
        # merge: vertex k of a line sorts before the points inserted on its segment k
        key_part = np.concatenate([part, s_part[ins_seg]])
        key_k = np.concatenate([np.arange(len(xy)) - v_off[part], s_k[ins_seg]])
        key_t = np.concatenate([np.full(len(xy), -1.0), t])
        all_xy = np.concatenate([xy, ins_xy])
        all_fixed = np.concatenate([np.concatenate(fixed), np.zeros(len(ins_xy), dtype=bool)])
        order = np.lexsort((key_t, key_k, key_part))
        key_part, all_xy, all_fixed = key_part[order], all_xy[order], all_fixed[order]
        dup = np.zeros(len(all_xy), dtype=bool)
        dup[1:] = (key_part[1:] == key_part[:-1]) & np.all(all_xy[1:] == all_xy[:-1], axis=1)
        # an inserted point equal to the vertex after it (three segments through a point)
        n_inserted = int(len(ins_xy) - dup.sum())
        keep = ~dup
        key_part, all_xy, all_fixed = key_part[keep], all_xy[keep], all_fixed[keep]
        cut = np.searchsorted(key_part, np.arange(len(lines) + 1))
        lines = [all_xy[cut[k] : cut[k + 1]] for k in range(len(lines))]
        fixed = [all_fixed[cut[k] : cut[k + 1]] for k in range(len(lines))]
    return lines, fixed, n_inserted


def network_topology(
    lines: list[np.ndarray], closed: Any, *, fixed: list[np.ndarray] | None = None
) -> NetworkTopology:
    """Node a set of lines and split them into arcs between nodes.

    Parameters
    ----------
    lines : list of (N_i, 2) ndarray
        Vertices of every line, without consecutive duplicates; a closed line listed
        without its repeated closing vertex.
    closed : (L,) bool array_like
        Which lines are closed.
    fixed : list of (N_i,) bool ndarray, optional
        Vertices that must stay where they are (become nodes).

    Returns
    -------
    NetworkTopology

    Notes
    -----
    Nodes are the ends of open lines, the fixed vertices, and every point with other than
    two distinct incident edges (a junction, a crossing, a point where a line touches
    itself, where two lines come together or part); an arc is a maximal run of edges
    between nodes. Edges are identified by the exact coordinates of their two ends, so a
    piece that several lines share is one arc.
    """
    closed = np.asarray(closed, dtype=bool)
    if fixed is None:
        fixed = [np.zeros(len(x), dtype=bool) for x in lines]
    lines, fixed, n_inserted = _node_lines(list(lines), closed, list(fixed))
    n_v = np.array([len(x) for x in lines], dtype=np.int64)
    v_off = np.concatenate([[0], np.cumsum(n_v)])
    xy = np.concatenate(lines)
    order = np.lexsort((xy[:, 1], xy[:, 0]))
    sp = xy[order]
    first = np.ones(len(sp), dtype=bool)
    first[1:] = np.any(sp[1:] != sp[:-1], axis=1)
    pid = np.empty(len(sp), dtype=np.int64)
    pid[order] = np.cumsum(first) - 1
    n_pts = int(first.sum())
    # segments (cyclic for closed lines) and their classes by unordered point ids
    n_s = np.where(closed, n_v, n_v - 1)
    s_part = np.repeat(np.arange(len(lines)), n_s)
    s_off = np.concatenate([[0], np.cumsum(n_s)])
    s_k = np.arange(len(s_part)) - s_off[s_part]
    pa = pid[v_off[s_part] + s_k]
    pb = pid[v_off[s_part] + (s_k + 1) % n_v[s_part]]
    lo, hi = np.minimum(pa, pb), np.maximum(pa, pb)
    ukeys, cls = np.unique(lo * n_pts + hi, return_inverse=True)
    count = np.bincount(cls, minlength=len(ukeys))
    pmin = np.full(len(ukeys), np.iinfo(np.int64).max)
    pmax = np.full(len(ukeys), -1)
    np.minimum.at(pmin, cls, s_part)
    np.maximum.at(pmax, cls, s_part)
    deg = np.bincount(ukeys // n_pts, minlength=n_pts) + np.bincount(ukeys % n_pts, minlength=n_pts)
    node = (deg[pid] != 2) | np.concatenate(fixed)
    ends = np.concatenate([v_off[:-1][~closed], v_off[1:][~closed] - 1])
    node[ends] = True
    # where the set of lines along an edge changes (another line ends there)
    sig = np.stack([count, pmin, pmax], axis=1)[cls]
    for p in range(len(lines)):
        if n_s[p] < 2:
            continue
        ss = sig[s_off[p] : s_off[p + 1]]
        change = np.any(ss[1:] != ss[:-1], axis=1)
        node[v_off[p] + 1 : v_off[p] + n_s[p]] |= change
        if closed[p]:
            node[v_off[p]] |= bool(np.any(ss[0] != ss[-1]))
    node_pid = np.unique(pid[node])
    is_node_pt = np.zeros(n_pts, dtype=bool)
    is_node_pt[node_pid] = True
    node = is_node_pt[pid]  # a point is a node for every line through it

    arc_index: dict[int, int] = {}
    arcs: list[np.ndarray] = []
    loops: list[bool] = []
    arc_first: list[tuple[int, int]] = []
    arc_lines: list[set[int]] = []
    runs_all: list[tuple[tuple[int, bool], ...]] = []
    for p in range(len(lines)):
        v0, v1 = v_off[p], v_off[p + 1]
        c = cls[s_off[p] : s_off[p + 1]]
        rp = pid[v0:v1]
        lxy = lines[p]
        n = len(lxy)
        nodes = np.nonzero(node[v0:v1])[0]
        if closed[p] and len(nodes) == 0:
            start = int(np.argmin(rp))
            vidx = np.roll(np.arange(n), -start)
            runs = [(vidx, c[vidx], True)]
        elif closed[p]:
            bounds = np.append(nodes, nodes[0] + n)
            runs = [
                (np.arange(s, e + 1) % n, c[np.arange(s, e) % n], False)
                for s, e in itertools.pairwise(bounds)
            ]
        else:
            runs = [(np.arange(s, e + 1), c[s:e], False) for s, e in itertools.pairwise(nodes)]
        line_runs = []
        for vidx, segs, is_loop in runs:
            key = int(segs.min())
            head = (int(rp[vidx[0]]), int(segs[0]))
            k = arc_index.get(key)
            if k is None:
                k = len(arcs)
                arc_index[key] = k
                arcs.append(lxy[vidx])
                loops.append(is_loop)
                arc_first.append(head)
                arc_lines.append({p})
                line_runs.append((k, True))
            else:
                arc_lines[k].add(p)
                line_runs.append((k, arc_first[k] == head))
        runs_all.append(tuple(line_runs))
    return NetworkTopology(
        lines=tuple(lines),
        closed=closed,
        arcs=tuple(arcs),
        loops=np.array(loops, dtype=bool),
        arc_lines=tuple(tuple(sorted(s)) for s in arc_lines),
        runs=tuple(runs_all),
        nodes=sp[first][node_pid] if len(node_pid) else np.empty((0, 2)),
        n_inserted=n_inserted,
    )


def rebuild_lines(topo: NetworkTopology, arcs: list[np.ndarray]) -> list[np.ndarray]:
    """Lines from (smoothed) arcs; closed lines repeat their first vertex at the end."""
    out = []
    for p, runs in enumerate(topo.runs):
        parts = []
        for k, fwd in runs:
            xy = arcs[k] if fwd else arcs[k][::-1]
            parts.append(xy)
        if topo.closed[p]:
            if len(runs) == 1 and topo.loops[runs[0][0]]:
                ring = parts[0]
            else:
                ring = np.concatenate([x[:-1] for x in parts])
            out.append(np.vstack([ring, ring[:1]]))
        else:
            out.append(np.concatenate([parts[0]] + [x[1:] for x in parts[1:]]))
    return out


def _smooth_open_chained(arcs: list[np.ndarray], alpha: Any, iterations: int) -> list[np.ndarray]:
    """CCA of many open arcs (fixed ends) in one call, chained with anchors (section 5).

    The arcs are concatenated and every arc end is an anchor, so each arc is smoothed as its
    own polyline; the joining edges lie between two anchors and are left out again. CCA
    returns anchors bit for bit, which locates every arc in the output; when that is
    ambiguous (an anchor's coordinates also produced elsewhere) the arcs are smoothed one
    by one.
    """
    from .. import cca

    parts, firsts, lasts = [], [], []
    n = 0
    prev_end = None
    for xy in arcs:
        if prev_end is not None and np.array_equal(xy[0], prev_end):
            firsts.append(n - 1)  # consecutive arcs meeting at a node share the anchor
            parts.append(xy[1:])
        else:
            firsts.append(n)
            parts.append(xy)
        n += len(parts[-1])
        lasts.append(n - 1)
        prev_end = xy[-1]
    pts = np.concatenate(parts)
    anchors = np.array(sorted(set(firsts) | set(lasts)), dtype=np.int64)
    res = cca.smooth(pts, closed=False, iterations=iterations, alpha=alpha, anchors=anchors)
    anc = pts[anchors]
    # rows of res equal to some anchor point
    both = np.concatenate([anc, res])
    order = np.lexsort((both[:, 1], both[:, 0]))
    sb = both[order]
    grp = np.cumsum(np.concatenate([[True], np.any(sb[1:] != sb[:-1], axis=1)])) - 1
    gid = np.empty(len(both), dtype=np.int64)
    gid[order] = grp
    anchor_groups = np.zeros(grp[-1] + 1, dtype=bool)
    anchor_groups[gid[: len(anc)]] = True
    pos = np.nonzero(anchor_groups[gid[len(anc) :]])[0]
    if len(pos) != len(anchors) or not np.array_equal(res[pos], anc):
        return [cca.smooth(xy, closed=False, iterations=iterations, alpha=alpha) for xy in arcs]
    where = np.empty(n, dtype=np.int64)
    where[anchors] = pos
    out = []
    for f, e, xy in zip(firsts, lasts, arcs, strict=True):
        o = res[where[f] : where[e] + 1].copy()
        o[0], o[-1] = xy[0], xy[-1]
        out.append(o)
    return out


def _initial(topo_arcs, loops, frozen, *, method, iterations, alpha, smoother):
    """Full-strength smoothing of every arc (chained CCA blocks for the open ones)."""
    out = list(topo_arcs)
    level = Level(iterations)
    todo = [k for k in range(len(out)) if not frozen[k]]
    open_idx = [k for k in todo if not loops[k]]
    loop_idx = [k for k in todo if loops[k]]
    if method == "cca":
        for b0 in range(0, len(open_idx), ARC_BLOCK):
            block = open_idx[b0 : b0 + ARC_BLOCK]
            for k, xy in zip(
                block, _smooth_open_chained([out[k] for k in block], alpha, iterations), strict=True
            ):
                out[k] = xy
    else:
        loop_idx = todo
    for k in loop_idx:
        out[k] = smoother(out[k], bool(loops[k]), level)
    return out


def _line_parts(geoms: np.ndarray):
    """Lines of the non-empty features: coordinates, feature, kind."""
    shapely = _shapely()
    T = shapely.GeometryType
    present = np.array([g is not None for g in geoms], dtype=bool)
    present[present] = ~shapely.is_empty(geoms[present])
    idx = np.nonzero(present)[0]
    types = shapely.get_type_id(geoms[idx])
    ok = (types == T.LINESTRING) | (types == T.MULTILINESTRING) | (types == T.LINEARRING)
    if not ok.all():
        k = int(idx[np.nonzero(~ok)[0][0]])
        raise CurveError(
            f"geometry[{k}] is a {geoms[k].geom_type}: a line network contains only "
            f"LineStrings, MultiLineStrings and LinearRings"
        )
    has_z = shapely.has_z(geoms[idx])
    if has_z.any():
        k = int(idx[np.nonzero(has_z)[0][0]])
        raise CurveError(
            f"geometry[{k}] has Z coordinates; curvesmith.geo smooths planar geometries "
            f"(drop Z with shapely.force_2d)"
        )
    parts, pfeat = shapely.get_parts(geoms[idx], return_index=True)
    parts = shapely.remove_repeated_points(parts, 0.0)
    coords, cidx = shapely.get_coordinates(parts, return_index=True)
    coords = coords + 0.0
    if not np.isfinite(coords).all():
        k = int(idx[pfeat[cidx[np.nonzero(~np.isfinite(coords).all(axis=1))[0][0]]]])
        raise CurveError(f"geometry[{k}] has non-finite coordinates")
    cut = np.searchsorted(cidx, np.arange(len(parts) + 1))
    lines, closed = [], []
    for p in range(len(parts)):
        xy = coords[cut[p] : cut[p + 1]]
        if len(xy) < 2 or not np.any(xy[1:] != xy[:-1]):
            raise CurveError(
                f"geometry[{int(idx[pfeat[p]])}] has a line with fewer than 2 distinct points"
            )
        is_closed = len(xy) >= 4 and np.array_equal(xy[0], xy[-1])
        closed.append(is_closed)
        lines.append(xy[:-1] if is_closed else xy)
    return idx, types, idx[pfeat], lines, np.array(closed, dtype=bool)


@gc_paused  # a layer's many Python objects: see curvesmith._gc
def smooth_network(
    geometry: Any,
    *,
    method: GisMethod = "cca",
    iterations: int = 1,
    alpha: Any = "regular",
    fixed_points: Any = None,
    full_output: bool = False,
    map_arcs: Any = None,
    keep_angle: float | None = None,
    max_shift: float | None = None,
    min_segment: float | None = None,
) -> Any:
    """Smooth a line network: junctions and ends fixed, shared pieces once, no new contacts.

    Every line is noded against all others (crossings, ends on other lines and overlapping
    segments become shared vertices), cut at the nodes -- line ends, junctions, crossings,
    points where lines come together or part, and ``fixed_points`` -- into arcs, and every
    arc is smoothed once with its end nodes fixed (a closed line meeting nothing as a
    closed ring). A piece that two lines share is one arc, so it stays identical in both.
    Where smoothing would make two arcs touch or cross (or one cross itself), the
    conflicting arc is cut at anchor vertices and only the conflicting pieces are smoothed
    less (:attr:`NetworkResult.reductions`), so the output lines meet exactly where the
    input lines met, at the same points, and nowhere else.

    With ``method="cca"`` each arc keeps the signed area between itself and its chord
    (Gordon 2010, section 3, Fig. 9; section 5), hence the signed area between every input
    line and its output is zero and every closed line keeps its enclosed area, to
    round-off.

    Parameters
    ----------
    geometry : sequence of LineString / MultiLineString / LinearRing, GeoSeries or GeoDataFrame
        The network. ``None`` and empty geometries pass through unchanged; the index, the
        other columns and the CRS of a GeoSeries / GeoDataFrame are kept.
    method : {"cca", "chaikin"}
        Area-preserving CCA (default) or Chaikin (for comparison; ends still fixed).
    iterations : int
        Smoothing passes per arc (each CCA pass triples the vertices).
    alpha : "regular", float or callable
        CCA cut ratio (see :func:`curvesmith.geo.smooth`).
    fixed_points : (K, 2) array_like or sequence of shapely Points, optional
        Further points to keep fixed: every input vertex with exactly these coordinates
        becomes a node.
    keep_angle : float, optional
        Keep sharp corners: every vertex turning by more than this angle (radians) becomes
        a node, as a fixed point (:func:`curvesmith.geo.corner_vertices`).
    max_shift, min_segment : float, optional
        Strength and vertex budget in map units, arc by arc: every arc gets the strongest
        level (1 .. iterations passes, then shallower cuts) whose Hausdorff distance from
        its input is at most `max_shift` and that has at most one vertex per `min_segment`
        of its length; an arc with no such level keeps its input. A line is a union of
        arcs, so it moves no farther than `max_shift`; the area balance stays exact.
    full_output : bool
        Return a :class:`NetworkResult`.
    map_arcs : callable, optional
        ``map_arcs(topology, frozen) -> list of arrays``: the first, full-strength
        smoothing of every arc (``topology.arcs``, ``topology.loops``), e.g. run in
        parallel (:mod:`curvesmith.batch` passes a Dask map over blocks of arcs here);
        conflicts are then resolved here as usual.

    Returns
    -------
    object or NetworkResult
        The smoothed network, of the input's type. LineStrings stay LineStrings,
        MultiLineStrings keep their parts; a closed line with nodes starts at its first
        node, one without at an arbitrary vertex (its start is not a junction).

    Raises
    ------
    CurveError
        For other geometry types, lines of fewer than two distinct points,
        an unknown method or a bad ``iterations``/``alpha``.

    Examples
    --------
    Two roads ending on a third: the junctions stay, the pieces between them are smoothed,
    and the area between each input road and its output is zero.

    >>> import shapely
    >>> from curvesmith import geo
    >>> main = shapely.LineString([(0, 0), (2, 1), (4, 0), (6, 1), (8, 0)])
    >>> side = shapely.LineString([(4, 0), (5, -2), (4, -4)])
    >>> res = geo.smooth_network([main, side], iterations=2, full_output=True)
    >>> res.n_nodes, res.n_arcs, res.reductions
    (4, 3, ())
    >>> res.geometry[1].coords[0], bool(shapely.touches(*res.geometry))
    ((4.0, 0.0), True)
    """
    shapely = _shapely()
    iterations = check_method(method, iterations, alpha)
    geoms, wrap = as_geometry_array(geometry)
    # with max_shift / min_segment every level is held at once
    bounded = max_shift is not None or min_segment is not None
    check_layer_size(geoms, method, iterations, levels=bounded)
    geoms, zm = _zm.split_zm(np.asarray(geoms, dtype=object).copy())  # Z/M: geo._zm
    if zm is not None:
        wrap = _zm.restoring(wrap, zm)
    idx, types, line_feat, lines, closed = _line_parts(geoms)
    empty = NetworkResult(wrap(geoms), 0, 0, 0, 0, (), 0.0, 0.0)
    if not lines:
        return empty if full_output else empty.geometry
    fixed = [np.zeros(len(x), dtype=bool) for x in lines]
    if keep_angle is not None:  # sharp corners become nodes, like fixed points
        corners = shapely.get_coordinates(geoms[[g is not None for g in geoms]])
        corners = corners[with_corners(geoms, None, keep_angle)]
        if fixed_points is not None:
            corners = np.concatenate([_points_array(fixed_points).reshape(-1, 2), corners])
        fixed_points = corners
    if fixed_points is not None:
        fp = _points_array(fixed_points)
        if len(fp):
            keys = {tuple(p) for p in fp.tolist()}
            fixed = [np.array([tuple(v) in keys for v in x.tolist()], dtype=bool) for x in lines]
    topo = network_topology(lines, closed, fixed=fixed)
    frozen = np.array([len(a) < 3 for a in topo.arcs], dtype=bool)
    smoother = make_smoother(method, alpha)
    if iterations == 0:
        new_arcs, red = list(topo.arcs), []
    elif max_shift is not None or min_segment is not None:
        new_arcs, red = smooth_arcs_bounded(
            topo.arcs,
            topo.loops,
            frozen,
            levels=levels_for(iterations, scalable=methods.get(method).scalable),
            smoother=smoother,
            method=method,
            alpha=alpha,
            fixed=None,
            max_shift=max_shift,
            min_segment=min_segment,
        )
    else:
        if map_arcs is not None:  # e.g. on Dask (curvesmith.batch)
            initial = map_arcs(topo, frozen)
        else:
            initial = _initial(
                topo.arcs,
                topo.loops,
                frozen,
                method=method,
                iterations=iterations,
                alpha=alpha,
                smoother=smoother,
            )
        new_arcs, red = resolve_arcs(
            topo.arcs,
            loops=topo.loops,
            groups=np.zeros(len(topo.arcs), dtype=int),
            frozen=frozen,
            smoother=smoother,
            levels=levels_for(iterations, scalable=methods.get(method).scalable),
            initial=initial,
        )
    new_lines = rebuild_lines(topo, new_arcs)
    # area checks, against the noded input lines
    max_closed, max_open = 0.0, 0.0
    for p, (a_in, a_out) in enumerate(zip(topo.lines, new_lines, strict=True)):
        if closed[p]:
            area = _signed_area(a_in)
            change = abs(_signed_area(a_out[:-1]) - area)
            max_closed = max(max_closed, change / abs(area) if area != 0 else change)
        else:
            length2 = float(np.sum(np.linalg.norm(np.diff(a_in, axis=0), axis=1))) ** 2
            between = abs(_signed_area(np.vstack([a_in, a_out[::-1][1:-1]])))
            max_open = max(max_open, between / length2 if length2 > 0 else 0.0)
    # back to features
    T = shapely.GeometryType
    part_geoms = np.empty(len(new_lines), dtype=object)
    ring_feat = np.isin(line_feat, idx[types == T.LINEARRING])
    for p, xy in enumerate(new_lines):
        part_geoms[p] = shapely.linearrings(xy) if ring_feat[p] else shapely.linestrings(xy)
    out = geoms.copy()
    starts = np.searchsorted(line_feat, idx)
    stops = np.searchsorted(line_feat, idx, side="right")
    for f, t, s, e in zip(idx, types, starts, stops, strict=True):
        if t == T.MULTILINESTRING:
            out[f] = shapely.multilinestrings(list(part_geoms[s:e]))
        else:
            out[f] = part_geoms[s]
    res = wrap(out)
    if not full_output:
        return res
    reductions = tuple(
        NetworkReduction(
            r.arc,
            tuple(sorted({int(line_feat[p]) for p in topo.arc_lines[r.arc]})),
            r.start,
            r.stop,
            r.iterations,
            r.alpha_scale,
        )
        for r in red
    )
    return NetworkResult(
        geometry=res,
        n_lines=len(lines),
        n_arcs=len(topo.arcs),
        n_nodes=len(topo.nodes),
        n_inserted=topo.n_inserted,
        reductions=reductions,
        max_area_change=float(max_closed),
        max_open_area=float(max_open),
    )


def _points_array(points: Any) -> np.ndarray:
    shapely = _shapely()
    arr = np.asarray(points, dtype=object)
    if arr.size and all(isinstance(g, shapely.Geometry) for g in arr.ravel()):
        return shapely.get_coordinates(arr.ravel()) + 0.0
    try:
        fp = np.asarray(points, dtype=float)
    except (TypeError, ValueError):
        raise CurveError(
            f"fixed_points must be (K, 2) coordinates or shapely Points, got {points!r}"
        ) from None
    if fp.size == 0:
        return np.empty((0, 2))
    if fp.ndim != 2 or fp.shape[1] != 2:
        raise CurveError(f"fixed_points must have shape (K, 2), got {fp.shape}")
    return fp + 0.0


def changed_contacts(before: Any, after: Any, *, tol: float = 1e-6) -> int:
    """How many pairs of lines changed how they meet: a new contact, a lost one, or a moved point.

    The measure of what smoothing did to a network (0 for :func:`smooth_network`): a pair of
    lines that touch in one output but not the other counts once, and so does a pair that
    meets at a point in both whose contact moved by more than `tol`.

    Parameters
    ----------
    before, after : array of shapely geometries
        The lines before and after, in the same order.
    tol : float, optional
        Distance (in the data's units) a point contact may move and still count as kept.

    Returns
    -------
    int

    Examples
    --------
    >>> import numpy as np, shapely
    >>> a = np.array([shapely.LineString([(0, 0), (2, 0)]), shapely.LineString([(1, -1), (1, 1)])])
    >>> b = np.array([a[0], shapely.LineString([(1, 0.5), (1, 1)])])
    >>> changed_contacts(a, a), changed_contacts(a, b)
    (0, 1)
    """
    shapely = _shapely()
    before = np.asarray(before, dtype=object)
    after = np.asarray(after, dtype=object)
    if before.shape != after.shape:
        raise CurveError(
            f"before and after must hold the same lines, got {before.shape} and {after.shape}"
        )

    def pairs(g):
        i, j = shapely.STRtree(g).query(g, predicate="intersects")
        keep = i < j
        return {(int(a), int(b)) for a, b in zip(i[keep], j[keep], strict=True)}

    p0, p1 = pairs(before), pairs(after)
    moved = 0
    for a, b in p0 & p1:
        x0 = shapely.intersection(before[a], before[b])
        if shapely.get_dimensions(x0) == 0:
            x1 = shapely.intersection(after[a], after[b])
            moved += bool(shapely.hausdorff_distance(x0, x1) > tol)
    return len(p0 ^ p1) + moved


def level_contacts(geoms: Any, levels: ArrayLike) -> int:
    """Pairs of contour lines of different levels that touch or cross (0 for a sound map).

    Parameters
    ----------
    geoms : array of shapely geometries
        The lines.
    levels : (N,) array_like
        The level of each line.

    Returns
    -------
    int

    Examples
    --------
    >>> import numpy as np, shapely
    >>> g = np.array([shapely.LineString([(0, 0), (2, 0)]), shapely.LineString([(1, -1), (1, 1)])])
    >>> level_contacts(g, [10, 20]), level_contacts(g, [10, 10])
    (1, 0)
    """
    shapely = _shapely()
    g = np.asarray(geoms, dtype=object)
    lv = np.asarray(levels)
    if lv.shape != g.shape:
        raise CurveError(f"levels must have one value per line ({g.shape[0]}), got {lv.shape}")
    i, j = shapely.STRtree(g).query(g, predicate="intersects")
    return int(((i < j) & (lv[i] != lv[j])).sum())
