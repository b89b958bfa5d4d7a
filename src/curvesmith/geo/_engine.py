"""Smooth a set of polylines so that none of them crosses another: the local-reduction engine.

Both :func:`curvesmith.geo.smooth` (the rings of one feature) and
:func:`curvesmith.geo.smooth_coverage` (the shared arcs of a whole coverage) come down to
the same problem: a set of polylines ("arcs") whose ends are fixed nodes, or closed loops
without a node, that must be smoothed so that no two of them meet after smoothing except
at the nodes they already share, and none becomes self-intersecting.

The engine smooths every arc at the full level, then looks for conflicts with a GEOS
spatial index (:class:`shapely.STRtree`, predicate ``intersects``) and resolves each one
*locally*: a conflicting arc is first cut at anchor vertices into pieces (bisection, a loop
into four), and only the pieces that still conflict are smoothed less (fewer iterations,
then a smaller alpha), down to the original vertices. Cutting at anchors keeps the area
guarantee of CCA: the area between a piece and its chord is kept, the chords of the pieces
are fixed, so the area between the whole old and new arc stays zero (CCA section 5,
"anchor points").

Backing off does not stop at the first level at which two pieces no longer meet, which
could leave them a rounding error apart (valid as written, invalid after a reprojection):
two pieces that do not touch in the input (no shared end, input distance ``d > 0``)
conflict as well when their outputs come
closer than the *clearance margin* ``min(MARGIN_EDGE * l, MARGIN_GAP * d)``, with ``l``
the larger mean input edge length of the two pieces' arcs (rings, coverage arcs, network
arcs). Level 0 (the input vertices) always satisfies it, so the resolution still
terminates. Pieces that share an end (neighbours along a ring, arcs at a node) touch in
the input and keep the plain rule (they may meet only at the shared ends).
"""

from __future__ import annotations

import itertools
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

__all__ = ["Level", "Reduction", "in_background", "resolve_arcs"]

#: Pieces with at most this many vertices are not cut further: they are smoothed less.
MIN_PIECE_VERTICES = 16
#: Safety bound on resolution rounds (each round at least splits a piece or lowers a level).
MAX_ROUNDS = 200
#: Clearance margin, as a fraction of the (larger) mean input edge length of two pieces' arcs.
MARGIN_EDGE = 1e-3
#: Clearance margin, as a fraction of the two pieces' distance in the input.
MARGIN_GAP = 0.5
#: From this many pieces on, a full round's pairs are found by the compiled arrangement
#: (:mod:`curvesmith.geo._arrangement_kernel`) instead of GEOS' STRtree and relate.
COMPILED_PAIRS = 64


@dataclass(frozen=True)
class Level:
    """One smoothing strength: ``iterations`` passes with alpha multiplied by ``alpha_scale``.

    ``iterations == 0`` means the piece keeps its original vertices.
    """

    iterations: int
    alpha_scale: float = 1.0


@dataclass(frozen=True)
class Reduction:
    """Where smoothing was reduced to avoid a crossing.

    Attributes
    ----------
    arc : int
        Index of the arc (ring, line or shared coverage arc) in the engine's input.
    start, stop : int
        First and last vertex index (inclusive) of the reduced piece in that arc; for a
        closed loop the index ``n`` denotes vertex 0 again.
    iterations : int
        Iterations actually applied to that piece (0 = left unchanged).
    alpha_scale : float
        Factor applied to alpha for that piece.
    """

    arc: int
    start: int
    stop: int
    iterations: int
    alpha_scale: float


def levels_for(iterations: int, *, scalable: bool) -> list[Level]:
    """Levels from full strength down to unchanged.

    Full iterations first, then one fewer each step, then (when alpha can be scaled) one
    iteration with alpha halved twice, and finally the original vertices.
    """
    levels = [Level(k) for k in range(iterations, 0, -1)]
    if scalable and iterations >= 1:
        levels += [Level(1, 0.5), Level(1, 0.25)]
    levels.append(Level(0))
    return levels


@dataclass
class _Piece:
    arc: int
    start: int
    stop: int
    loop: bool  # an unsplit closed loop without a node
    level: int
    split: bool = False  # cut out of a longer piece by the resolution


@dataclass(frozen=True)
class _PieceTable:
    """The pieces of a round as arrays: arc, first and last vertex, loop, level, closed."""

    arc: np.ndarray
    start: np.ndarray
    stop: np.ndarray
    loop: np.ndarray
    level: np.ndarray
    closed: np.ndarray  # the piece's geometry is closed (GEOS is_closed)

    @classmethod
    def of(cls, pieces: Sequence[_Piece], closed: np.ndarray) -> _PieceTable:
        n = len(pieces)

        def col(name, dtype):
            return np.fromiter((getattr(p, name) for p in pieces), dtype=dtype, count=n)

        return cls(
            col("arc", np.int64), col("start", np.int64), col("stop", np.int64),
            col("loop", bool), col("level", np.int64), np.asarray(closed, dtype=bool),
        )  # fmt: skip

    def renewed(self, src: np.ndarray, changed, fresh, closed) -> _PieceTable:
        """The next round's table: row ``k`` is row ``src[k]``, or (``src[k] < 0``) new."""
        new = _PieceTable.of(fresh, closed)
        kept = src >= 0
        cols = []
        for old, add in zip(self._columns(), new._columns(), strict=True):
            col = np.empty(len(src), dtype=old.dtype)
            col[kept] = old[src[kept]]
            col[changed] = add
            cols.append(col)
        return _PieceTable(*cols)

    def _columns(self):
        return self.arc, self.start, self.stop, self.loop, self.level, self.closed


def _flat(arcs: Sequence[np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """All arcs' vertices one after the other, and where each arc starts."""
    off = np.zeros(len(arcs) + 1, dtype=np.int64)
    np.cumsum(np.fromiter((len(x) for x in arcs), dtype=np.int64, count=len(arcs)), out=off[1:])
    xy = np.concatenate(arcs) if len(arcs) else np.empty((0, 2))
    return xy, off


def _piece_points(xy: np.ndarray, piece: _Piece, closed_arc: bool) -> np.ndarray:
    if piece.loop:
        return xy
    if closed_arc and piece.stop == len(xy):
        return np.vstack([xy[piece.start :], xy[:1]])
    return xy[piece.start : piece.stop + 1]


def resolve_arcs(
    arcs: Sequence[np.ndarray],
    *,
    loops: np.ndarray,
    groups: np.ndarray,
    frozen: np.ndarray,
    smoother: Callable[[np.ndarray, bool, Level], np.ndarray],
    levels: list[Level],
    check_simple: np.ndarray | None = None,
    initial: Sequence[np.ndarray] | None = None,
    start: Sequence[int] | None = None,
    seeds: dict[int, Sequence[np.ndarray]] | None = None,
    initial_ragged: dict | None = None,
    meetings_out: dict | None = None,
) -> tuple[list[np.ndarray], list[Reduction]]:
    """Smooth arcs, reducing locally until no two of them cross.

    Parameters
    ----------
    arcs : sequence of (N_i, 2) ndarray
        Vertices of every arc. A loop (``loops[i]``) lists its vertices once, without
        repeating the first; an open arc has its fixed nodes as first and last vertex.
    loops : (M,) bool ndarray
        Closed loops without a node: smoothed as closed curves.
    groups : (M,) int ndarray
        Arcs conflict only with arcs of the same group (one feature, or one coverage).
    frozen : (M,) bool ndarray
        Arcs that must keep their original vertices.
    smoother : callable ``(points, closed, level) -> points``
        Smooths one piece (closed pieces without repeated vertex, open pieces with fixed
        ends) at a level. When it has a ``batch(list_of_points, closed, level) -> list``
        attribute giving the same curves, the pieces of a round are smoothed through it,
        many at once.
    levels : list of Level
        From full strength to unchanged (the last one must have ``iterations == 0``).
    check_simple : (M,) bool ndarray, optional
        Arcs whose self-intersection must be prevented (default: all). Pass ``False``
        for arcs that are not simple in the input.
    initial : sequence of ndarray, optional
        The arcs already smoothed at full strength (e.g. in parallel), reused as is.
    start : sequence of int, optional
        The level each arc starts at (default 0, full strength): the map-unit bounds of
        :func:`bounded_levels` start an arc at the strongest level within them.
    seeds : dict of int to sequence of ndarray, optional
        Arcs already smoothed at a level (level -> one array per arc), reused as is.
    initial_ragged : dict, optional
        `initial` as one array: ``"xy"`` (every arc after the other, loops closed by
        their first vertex) and ``"off"``, when at hand (saves copying them together).
    meetings_out : dict, optional
        Receives what the first round's compiled arrangement found, so that a later
        proof on the output needs to look again only where arcs changed:
        ``"pairs"``, the arcs ``(a, b)`` of every MEET (``a == b``: an arc meets itself),
        ``"complete"``, whether every pair of arcs was compared (one group, none frozen),
        and ``"changed"``, per arc, whether its output differs from that round's.
        Left empty when the first round did not use the arrangement.

    Returns
    -------
    smoothed : list of (K_i, 2) ndarray
        The smoothed arcs, loops again without repeated first vertex.
    reductions : list of Reduction
        Every piece smoothed at less than full strength.
    """
    import shapely

    n_arcs = len(arcs)
    top = len(levels) - 1
    if check_simple is None:
        check_simple = np.ones(n_arcs, dtype=bool)
    if start is None and seeds is None and initial_ragged is None and meetings_out is None:
        solo = _solo_loops(arcs, loops, groups, frozen)
        if solo.any():
            return _resolve_with_solo_loops(
                solo, arcs, loops, groups, frozen, smoother, levels, check_simple, initial
            )
    # the first round's pieces: every arc whole, at its starting level (as lists: the
    # many arcs of a coverage are set up without a Python loop of their own)
    loop_l = np.asarray(loops, dtype=bool).tolist()
    lens = np.fromiter(map(len, arcs), dtype=np.int64, count=n_arcs)
    last_l = (lens - 1 + np.asarray(loops, dtype=np.int64)).tolist()
    lv = np.zeros(n_arcs, dtype=np.int64) if start is None else np.minimum(start, top)
    top_level = np.where(np.asarray(frozen, dtype=bool), top, lv).astype(np.int64).tolist()
    zeros = itertools.repeat(0)
    pieces: list[_Piece] = list(map(_Piece, range(n_arcs), zeros, last_l, loop_l, top_level))
    cache: dict[tuple[int, int, int, bool, int], np.ndarray] = {}
    known = dict(seeds or {})
    if initial is not None:
        known[0] = initial
    for i, lev in enumerate(top_level):
        if lev in known:
            cache[(i, 0, last_l[i], loop_l[i], lev)] = known[lev][i]

    def smoothed_piece(p: _Piece) -> np.ndarray:
        key = (p.arc, p.start, p.stop, p.loop, p.level)
        out = cache.get(key)
        if out is None:
            pts = _piece_points(arcs[p.arc], p, bool(loops[p.arc]))
            lev = levels[p.level]
            out = pts if lev.iterations == 0 else smoother(pts, p.loop, lev)
            cache[key] = out
        return out

    batch = getattr(smoother, "batch", None)

    def smooth_missing(plist: list[_Piece]) -> None:
        """The pieces of `plist` not smoothed yet, one ragged call per level and kind."""
        todo: dict[tuple[int, bool], dict[tuple, _Piece]] = {}
        for p in plist:
            key = (p.arc, p.start, p.stop, p.loop, p.level)
            if key not in cache and levels[p.level].iterations > 0:
                todo.setdefault((p.level, p.loop), {})[key] = p
        assert batch is not None  # only called when the smoother has a batch
        for (lev, loop), group in todo.items():
            pts = [_piece_points(arcs[p.arc], p, bool(loops[p.arc])) for p in group.values()]
            for key, out in zip(group, batch(pts, loop, levels[lev]), strict=True):
                cache[key] = out

    def ragged_of(plist: list[_Piece]) -> dict:
        """The pieces' coordinates (loops closed) ``"xy"`` and offsets ``"off"``."""
        if batch is not None:
            smooth_missing(plist)
        pts = []
        for p in plist:
            xy = smoothed_piece(p)
            pts.append(np.vstack([xy, xy[:1]]) if p.loop else xy)
        off = np.zeros(len(pts) + 1, dtype=np.int64)
        np.cumsum(np.fromiter((len(x) for x in pts), dtype=np.int64, count=len(pts)), out=off[1:])
        return {"xy": np.concatenate(pts), "off": off}

    simple_orig: dict[tuple[int, int, int, bool], bool] = {}
    in_geom: dict[tuple[int, int, int, bool], Any] = {}
    arc_xy, arc_off = _flat(arcs)
    scale = _mean_edges(arcs, loops, (arc_xy, arc_off))

    def input_geom(p: _Piece):
        """The piece's input vertices as a LineString."""
        key = (p.arc, p.start, p.stop, p.loop)
        val = in_geom.get(key)
        if val is None:
            pts = _piece_points(arcs[p.arc], p, bool(loops[p.arc]))
            if p.loop:
                pts = np.vstack([pts, pts[:1]])
            val = shapely.linestrings(pts)
            in_geom[key] = val
        return val

    def original_simple(p: _Piece) -> bool:
        key = (p.arc, p.start, p.stop, p.loop)
        val = simple_orig.get(key)
        if val is None:
            pts = _piece_points(arcs[p.arc], p, bool(loops[p.arc]))
            if p.loop:
                pts = np.vstack([pts, pts[:1]])
            val = bool(shapely.is_simple(shapely.linestrings(pts)))
            simple_orig[key] = val
        return val

    if initial_ragged is not None and initial is not None and start is None:
        # the first round's pieces are the arcs at full strength (none frozen: they all
        # came from the one call), their coordinates at hand
        ragged: dict | None = dict(initial_ragged)
    else:
        ragged = ragged_of(pieces)
    assert ragged is not None
    to_check = np.arange(len(pieces))
    # per piece, as arrays carried from round to round (only the changed pieces are new)
    table = _PieceTable(
        np.arange(n_arcs, dtype=np.int64), np.zeros(n_arcs, dtype=np.int64),
        np.asarray(last_l, dtype=np.int64), np.asarray(loop_l, dtype=bool),
        np.asarray(top_level, dtype=np.int64), _closed_lines(ragged),
    )  # fmt: skip  # the first round's pieces, as _PieceTable.of(pieces) gives them
    geoms = None  # the first round makes them from `ragged`
    first: dict = {}  # the first round's meetings (see meetings_out)
    for _ in range(MAX_ROUNDS):
        bad, geoms = _conflicts(
            pieces, arcs, geoms, to_check, groups, top, check_simple, original_simple, input_geom,
            scale, ragged, table, (arc_xy, arc_off), first if ragged is not None else None,
        )  # fmt: skip
        ragged = None  # the coordinates of the first round's pieces
        if not bad:
            break
        changed = []
        new_pieces: list[_Piece] = []
        kept_from: list[int] = []  # for every new piece, its old index (-1: new geometry)
        done = 0  # the pieces before a bad one are kept as they are, in order
        for k in sorted(bad):
            new_pieces.extend(pieces[done:k])
            kept_from.extend(range(done, k))
            done = k + 1
            p = pieces[k]
            n_vert = (p.stop - p.start) + (0 if p.loop else 1)
            if n_vert > MIN_PIECE_VERTICES:
                if p.loop:
                    cuts = np.linspace(0, p.stop, 5).round().astype(int)
                else:
                    cuts = np.array([p.start, (p.start + p.stop) // 2, p.stop])
                for a, b in itertools.pairwise(cuts):
                    new_pieces.append(_Piece(p.arc, int(a), int(b), False, p.level, True))
                    changed.append(len(new_pieces) - 1)
                    kept_from.append(-1)
            else:
                new_pieces.append(_Piece(p.arc, p.start, p.stop, p.loop, p.level + 1, p.split))
                changed.append(len(new_pieces) - 1)
                kept_from.append(-1)
        new_pieces.extend(pieces[done:])
        kept_from.extend(range(done, len(pieces)))
        src = np.asarray(kept_from)
        new_geoms = np.empty(len(new_pieces), dtype=object)
        new_geoms[src >= 0] = geoms[src[src >= 0]]
        fresh = [new_pieces[k] for k in changed]
        new_geoms[changed] = _lines(ragged_of(fresh))
        table = table.renewed(src, changed, fresh, shapely.is_closed(new_geoms[changed]))
        pieces, geoms = new_pieces, new_geoms
        to_check = np.asarray(changed, dtype=int)
    else:  # pragma: no cover - each round strictly refines, MAX_ROUNDS is a guard
        raise RuntimeError("conflict resolution did not terminate")

    # assemble arcs from their pieces, in the order of their first vertex (an arc of one
    # piece is that piece's points)
    order = np.lexsort((table.start, table.arc))
    pieces = [pieces[k] for k in order.tolist()]
    arc_of, level_of = table.arc[order], table.level[order]
    n_of = np.bincount(arc_of, minlength=n_arcs)
    first_of = np.zeros(n_arcs + 1, dtype=np.int64)
    np.cumsum(n_of, out=first_of[1:])
    out: list[np.ndarray] = list(map(smoothed_piece, (pieces[k] for k in first_of[:-1].tolist())))
    reductions: list[Reduction] = []
    for k in np.flatnonzero((level_of > 0) & ~np.asarray(frozen, dtype=bool)[arc_of]).tolist():
        p = pieces[k]
        lev = levels[p.level]
        reductions.append(Reduction(p.arc, p.start, p.stop, lev.iterations, lev.alpha_scale))
    for i in np.flatnonzero(n_of > 1).tolist():
        plist = pieces[first_of[i] : first_of[i + 1]]
        parts = [smoothed_piece(plist[0])]
        parts += [smoothed_piece(p)[1:] for p in plist[1:]]
        xy = np.concatenate(parts)
        out[i] = xy[:-1] if loops[i] else xy
    if meetings_out is not None and first:
        # an arc differs from its first-round self when it was cut or smoothed less
        # (the first round's pieces are the arcs, one each, at their starting level)
        changed_arc = np.zeros(n_arcs, dtype=bool)
        changed_arc[arc_of[level_of != np.asarray(top_level)[arc_of]]] = True
        changed_arc[n_of > 1] = True
        meetings_out.update(first, changed=changed_arc)
    return out, reductions


def _solo_loops(arcs, loops, groups, frozen) -> np.ndarray:
    """Per arc: a loop alone in its group, of at most MIN_PIECE_VERTICES vertices, not frozen.

    Such a loop (the ring of a footprint whose output was not valid) meets no other piece
    and is never cut: each round of :func:`resolve_arcs` only smooths it one level less
    until it is simple. :func:`_resolve_with_solo_loops` does those rounds for all of them
    at once, without the rounds' spatial index and pair tests.
    """
    n = len(arcs)
    groups = np.asarray(groups)
    if n == 0:
        return np.zeros(0, dtype=bool)
    lens = np.fromiter(map(len, arcs), dtype=np.int64, count=n)
    _, inv, count = np.unique(groups, return_inverse=True, return_counts=True)
    return (
        np.asarray(loops, dtype=bool)
        & ~np.asarray(frozen, dtype=bool)
        & (count[inv.reshape(-1)] == 1)
        & (lens <= MIN_PIECE_VERTICES)
    )


def _resolve_with_solo_loops(
    solo, arcs, loops, groups, frozen, smoother, levels, check_simple, initial
) -> tuple[list[np.ndarray], list[Reduction]]:
    """:func:`resolve_arcs` when some arcs are `solo` loops (:func:`_solo_loops`).

    The same arcs and reductions: a solo loop ends at the first level (from full strength
    down) at which it is simple as a closed line, or at which it is not checked (not in
    `check_simple`, or its input is not simple), or that leaves it unchanged; its
    reduction is the whole loop, ``0 .. n``. The other arcs go through :func:`resolve_arcs`.
    """
    import shapely

    n_arcs = len(arcs)
    top = len(levels) - 1
    out: list[Any] = [None] * n_arcs
    reductions: list[Reduction] = []
    idx = np.flatnonzero(solo)
    batch = getattr(smoother, "batch", None)

    def smoothed(ks: np.ndarray, level: int) -> list[np.ndarray]:
        lev = levels[level]
        pts = [arcs[k] for k in ks.tolist()]
        if lev.iterations == 0:
            return pts
        if batch is not None:
            return list(batch(pts, True, lev))
        return [smoother(p, True, lev) for p in pts]

    def simple(rings: list[np.ndarray]) -> np.ndarray:
        xy = np.concatenate([np.vstack([r, r[:1]]) for r in rings])
        ids = np.repeat(np.arange(len(rings)), [len(r) + 1 for r in rings])
        return shapely.is_simple(shapely.linestrings(xy, indices=ids))

    cur = [initial[k] for k in idx.tolist()] if initial is not None else smoothed(idx, 0)
    pending, level = idx, 0
    while pending.size:
        for k, xy in zip(pending.tolist(), cur, strict=True):
            out[k] = xy
        if level == top:
            break
        bad = ~simple(cur)
        if bad.any():  # only loops checked, whose input is simple, are smoothed less
            bad[bad] = check_simple[pending[bad]] & simple([arcs[k] for k in pending[bad]])
        pending, level = pending[bad], level + 1
        if pending.size:
            cur = smoothed(pending, level)
            lev = levels[level]
            stops = [len(arcs[k]) for k in pending.tolist()]
            reductions += [
                Reduction(int(k), 0, s, lev.iterations, lev.alpha_scale)
                for k, s in zip(pending.tolist(), stops, strict=True)
            ]
    # a loop smoothed less several times keeps the reduction of its last level
    last: dict[int, Reduction] = {}
    for r in reductions:
        last[r.arc] = r
    reductions = list(last.values())
    rest = np.flatnonzero(~solo)
    if rest.size:
        sub, sub_red = resolve_arcs(
            [arcs[k] for k in rest.tolist()],
            loops=np.asarray(loops, dtype=bool)[rest],
            groups=np.asarray(groups)[rest],
            frozen=np.asarray(frozen, dtype=bool)[rest],
            smoother=smoother,
            levels=levels,
            check_simple=np.asarray(check_simple, dtype=bool)[rest],
            initial=[initial[k] for k in rest.tolist()] if initial is not None else None,
        )
        for k, xy in zip(rest.tolist(), sub, strict=True):
            out[k] = xy
        reductions += [
            Reduction(int(rest[r.arc]), r.start, r.stop, r.iterations, r.alpha_scale)
            for r in sub_red
        ]
    reductions.sort(key=lambda r: (r.arc, r.start))
    return out, reductions


def in_background(fn, *args):
    """``fn(*args)`` started in a thread of its own; returns its future.

    For a compiled kernel that releases the GIL: it runs beside what the caller does
    meanwhile, and ``future.result()`` gives its value or raises its exception.
    """
    from concurrent.futures import ThreadPoolExecutor

    pool = ThreadPoolExecutor(1, thread_name_prefix="curvesmith")
    try:
        return pool.submit(fn, *args)
    finally:
        pool.shutdown(wait=False)  # the thread ends with its task


def _lines(ragged: dict) -> np.ndarray:
    """LineStrings of ragged coordinates (``"xy"``, ``"off"``)."""
    import shapely

    off = ragged["off"]
    owner = np.repeat(np.arange(len(off) - 1), np.diff(off))
    return shapely.linestrings(ragged["xy"], indices=owner)


def _closed_lines(ragged: dict) -> np.ndarray:
    """GEOS' ``is_closed`` of :func:`_lines`, from the coordinates: first vertex equals last."""
    xy, off = ragged["xy"], ragged["off"]
    closed = np.diff(off) > 0
    first, last = off[:-1][closed], off[1:][closed] - 1
    closed[closed] = np.all(xy[first] == xy[last], axis=1)
    return closed


def _mean_edges(arcs: Sequence[np.ndarray], loops: np.ndarray, flat) -> np.ndarray:
    """Mean input edge length of every arc (a loop with its closing edge).

    `flat`: :func:`_flat` of `arcs`.
    """
    cnt = np.array([len(x) for x in arcs], dtype=np.int64)
    if len(arcs) == 0 or cnt.min() == 0:
        return np.array([_mean_edge(x, bool(lp)) for x, lp in zip(arcs, loops, strict=True)])
    xy, off = flat
    d = np.zeros(len(xy))
    d[:-1] = np.hypot(xy[1:, 0] - xy[:-1, 0], xy[1:, 1] - xy[:-1, 1])
    d[off[1:] - 1] = 0.0  # no edge from an arc's last vertex to the next arc
    total = np.add.reduceat(d, off[:-1])
    closing = np.hypot(*(xy[off[1:] - 1] - xy[off[:-1]]).T)
    total = total + np.where(loops, closing, 0.0)
    return total / np.maximum(cnt - 1 + loops.astype(np.int64), 1)


def _mean_edge(xy: np.ndarray, loop: bool) -> float:
    if len(xy) < 2:
        return 0.0
    pts = np.vstack([xy, xy[:1]]) if loop else xy
    return float(np.mean(np.hypot(*np.diff(pts, axis=0).T)))


def _conflicts(
    pieces,
    arcs,
    geoms,
    to_check,
    groups,
    top,
    check_simple,
    original_simple,
    input_geom,
    scale,
    ragged,
    table,
    flat,
    first_meets=None,
) -> tuple[set[int], np.ndarray]:
    """Indices of pieces in a new crossing, self-intersection or near-contact (margin).

    Returns them and `geoms`, the pieces' LineStrings: None in the first round, made
    here from `ragged` (after the compiled arrangement started on the coordinates).

    `ragged`: the pieces' coordinates and offsets, when at hand (else None); `table`: the
    pieces' :class:`_PieceTable`; `flat`: :func:`_flat` of `arcs`; `first_meets`: a dict
    that receives the meetings of a full round's compiled arrangement (see
    :func:`resolve_arcs`' `meetings_out`).
    """
    import shapely

    bad: set[int] = set()
    if len(to_check) == 0:
        return bad, geoms
    arc_of, level, loop, closed = table.arc, table.level, table.loop, table.closed
    grp = groups[arc_of]
    changed = level < top
    found = pending = None
    if len(to_check) == len(pieces) and len(pieces) >= COMPILED_PAIRS:
        # a full round: the compiled arrangement (which releases the GIL) runs in a
        # thread beside the spatial index and the clearance screening
        pending = in_background(
            _meeting_pairs, geoms, pieces, grp, changed, closed, ragged, loop, first_meets
        )
    if geoms is None:
        geoms = _lines(ragged)
    tree = shapely.STRtree(geoms)
    bad |= _near_contacts(
        pieces, geoms, tree, to_check, grp, changed, input_geom, scale[arc_of], ragged, table, flat
    )
    if pending is not None:
        found = pending.result()
    # self-intersections: GEOS decides the candidates (all changed pieces, or those the
    # compiled arrangement saw meet themselves: a superset of the pieces that are not simple)
    cand = to_check[changed[to_check]]
    if found is not None:
        cand = cand[found[3][cand]]
    if len(cand):
        simple = shapely.is_simple(geoms[cand])
        for k in cand[~simple]:
            if check_simple[arc_of[k]] and original_simple(pieces[k]):
                bad.add(int(k))
    # pairs
    if found is not None:
        a, b, hit, _ = found
    else:
        qi, qj = tree.query(geoms[to_check], predicate="intersects")
        qi = to_check[qi]
        keep = (qi != qj) & (grp[qi] == grp[qj]) & (changed[qi] | changed[qj])
        qi, qj = qi[keep], qj[keep]
        if len(qi) == 0:
            return bad, geoms
        a, b = _unique_pairs(np.minimum(qi, qj), np.maximum(qi, qj), len(pieces))
        hit = np.zeros(len(a), dtype=bool)
        # open pieces may only share end points: no interior meets anything of the other
        plain = ~(closed[a] | closed[b])
        if plain.any():
            hit[plain] = ~shapely.relate_pattern(geoms[a[plain]], geoms[b[plain]], "FF*F*****")
    plain = ~(closed[a] | closed[b])
    # a closed piece (a loop, or an arc from a node back to it) may share its node
    rest_idx = np.nonzero(~plain)[0]
    if len(rest_idx):
        ra, rb = a[rest_idx], b[rest_idx]
        inter = shapely.intersection(geoms[ra], geoms[rb])

        def ends(k):
            return np.stack(
                [
                    shapely.get_coordinates(shapely.get_point(geoms[k], 0)),
                    shapely.get_coordinates(shapely.get_point(geoms[k], -1)),
                ],
                axis=1,
            )  # (Q, 2, 2)

        ea, eb = ends(ra), ends(rb)
        same = np.all(ea[:, :, None, :] == eb[:, None, :, :], axis=-1)
        shared = same.any(axis=2) & ~(loop[ra] | loop[rb])[:, None]
        pts = ea[shared]
        owner = np.nonzero(shared)[0]
        allowed = np.full(len(ra), shapely.MultiPoint(), dtype=object)
        if len(pts):
            uniq, inv = np.unique(owner, return_inverse=True)
            allowed[uniq] = shapely.multipoints(pts, indices=inv)
        hit[rest_idx] = ~shapely.is_empty(shapely.difference(inter, allowed))
    for i, j in zip(a[hit], b[hit], strict=True):
        if changed[i]:
            bad.add(int(i))
        if changed[j]:
            bad.add(int(j))
    return bad, geoms


def _meeting_pairs(geoms, pieces, grp, changed, closed, ragged=None, loop=None, meets_out=None):
    """The pairs of a full round that meet, and which of them conflict: ``(a, b, hit, self_meet)``.

    What the STRtree ``intersects`` query and ``relate_pattern(.., "FF*F*****")`` give
    (pairs ``a < b`` of one group, one of them changed, that intersect; `hit` for two
    open pieces meeting other than at common end points), found by the exact compiled
    arrangement (:func:`curvesmith.geo._arrangement_kernel.meetings`). Pairs with a
    closed piece are left to the caller (their `hit` is False here). ``self_meet`` (per
    piece): the piece meets itself other than at the common vertex of consecutive
    segments or its closing vertex; every piece that is not simple is among them (the
    comparison is exact), but a repeated vertex can make a simple one meet itself, so
    the caller asks GEOS about these. None when the kernel cannot decide (the caller
    asks GEOS). `meets_out`: receives ``"pairs"``, the pieces ``(a, b)`` of every MEET
    (``a == b`` for a piece meeting itself), and ``"complete"``, whether every pair was
    compared (one group, every piece changed).
    """
    import shapely

    from ._arrangement_kernel import MEET, meetings

    if ragged:
        xy, off = ragged["xy"], ragged["off"]
    else:
        xy = shapely.get_coordinates(geoms)
        off = np.zeros(len(geoms) + 1, dtype=np.int64)
        np.cumsum(shapely.get_num_coordinates(geoms), out=off[1:])
    if loop is None:
        loop = np.fromiter((p.loop for p in pieces), dtype=bool, count=len(pieces))
    got = meetings(xy, off, loop, grp, changed, self_pairs=True)
    if got is None:
        return None
    sa, sb, v = got
    pa = np.searchsorted(off, sa, "right") - 1
    pb = np.searchsorted(off, sb, "right") - 1
    own = pa == pb
    n = len(off) - 1
    if meets_out is not None:
        hard = v == MEET
        complete = bool(np.all(changed)) and bool(np.all(grp == grp[0])) if n else True
        meets_out.update(pairs=(pa[hard], pb[hard]), complete=complete)
    self_meet = np.zeros(n, dtype=bool)
    self_meet[pa[own & (v == MEET)]] = True
    pa, pb, v = pa[~own], pb[~own], v[~own]
    lo, hi = np.minimum(pa, pb), np.maximum(pa, pb)
    key = lo * n + hi
    uk, inv = np.unique(key, return_inverse=True)
    hit = np.zeros(len(uk), dtype=bool)
    np.logical_or.at(hit, inv.reshape(-1), v == MEET)
    a, b = uk // n, uk % n
    hit &= ~(closed[a] | closed[b])
    return a, b, hit, self_meet


def _unique_pairs(a: np.ndarray, b: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray]:
    """The distinct pairs ``(a[k], b[k])`` of numbers below `n`, sorted by a, then b."""
    key = np.unique(a.astype(np.int64) * n + b)
    return key // n, key % n


def _near_contacts(
    pieces, geoms, tree, to_check, grp, changed, input_geom, scale, ragged, table, flat
) -> set[int]:
    """Changed pieces closer than the clearance margin to a piece they do not touch in the input.

    Candidates are the pairs (of the same group, one of them changed, one of them in
    ``to_check``) whose bounding boxes come within the largest ``MARGIN_EDGE * l`` of
    each other and that share no end vertex; a compiled segment screening keeps those
    within ``MARGIN_EDGE * l``, and only for these few GEOS computes both distances. A
    pair is a conflict when ``0 < d`` and the output distance is below
    ``min(MARGIN_EDGE * l, MARGIN_GAP * d)``. `table`: the pieces' :class:`_PieceTable`;
    `flat`: the arcs' vertices (:func:`_flat`), where the pieces' fixed ends are read.
    """
    import shapely

    r_max = MARGIN_EDGE * float(scale.max()) if len(scale) else 0.0
    box = shapely.bounds(geoms[to_check])
    qi, qj = tree.query(
        shapely.box(box[:, 0] - r_max, box[:, 1] - r_max, box[:, 2] + r_max, box[:, 3] + r_max)
    )
    a, b = to_check[qi], qj
    keep = (a != b) & (grp[a] == grp[b]) & (changed[a] | changed[b])
    a, b = np.minimum(a[keep], b[keep]), np.maximum(a[keep], b[keep])
    if len(a) == 0:
        return set()
    a, b = _unique_pairs(a, b, len(pieces))

    # pieces that share an end vertex touch in the input (ring neighbours, arcs at a node)
    # the fixed end vertices of the pieces (pinned: equal to the input's)
    ks, inv = np.unique(np.concatenate([a, b]), return_inverse=True)
    arc_xy, arc_off = flat
    arc = table.arc[ks]
    first, size = arc_off[arc], arc_off[arc + 1] - arc_off[arc]
    fixed_ends = np.stack(
        [arc_xy[first + table.start[ks]], arc_xy[first + table.stop[ks] % size]], axis=1
    )
    inv = inv.reshape(-1)
    ends_a, ends_b = fixed_ends[inv[: len(a)]], fixed_ends[inv[len(a) :]]
    share = np.all(ends_a[:, :, None, :] == ends_b[:, None, :, :], axis=-1).any(axis=(1, 2))
    share &= ~(table.loop[a] | table.loop[b])
    a, b = a[~share], b[~share]
    if len(a) == 0:
        return set()
    upper = MARGIN_EDGE * np.maximum(scale[a], scale[b])
    close = _within(geoms, a, b, upper, ragged)
    a, b, upper = a[close], b[close], upper[close]
    if len(a) == 0:
        return set()
    lines = np.empty(len(pieces), dtype=object)
    for k in np.unique(np.concatenate([a, b])):
        lines[k] = input_geom(pieces[k])
    d_in = shapely.distance(lines[a], lines[b])
    d_out = shapely.distance(geoms[a], geoms[b])
    near = (d_in > 0) & (d_out < np.minimum(upper, MARGIN_GAP * d_in))
    out: set[int] = set()
    for i, j in zip(a[near], b[near], strict=True):
        if changed[i]:
            out.add(int(i))
        if changed[j]:
            out.add(int(j))
    return out


def _within(geoms, a, b, dist, ragged=None) -> np.ndarray:
    """Per pair: whether ``geoms[a[k]]`` and ``geoms[b[k]]`` come within ``dist[k]``.

    `ragged`: the coordinates and offsets of all of `geoms`, when at hand.
    """
    import shapely

    from ._clearance_kernel import polylines_within

    if ragged:
        return polylines_within(ragged["xy"], ragged["off"], a, b, np.asarray(dist, float))
    ks, inv = np.unique(np.concatenate([a, b]), return_inverse=True)
    xy, owner = shapely.get_coordinates(geoms[ks], return_index=True)
    off = np.zeros(len(ks) + 1, dtype=np.int64)
    np.cumsum(np.bincount(owner, minlength=len(ks)), out=off[1:])
    return polylines_within(
        np.ascontiguousarray(xy), off, inv[: len(a)], inv[len(a) :], np.asarray(dist, float)
    )
