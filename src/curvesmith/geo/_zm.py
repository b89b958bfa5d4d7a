"""Z and M values through planar smoothing: interpolated along the input curve.

Smoothing stays planar: every geo path smooths ``shapely.force_2d(input)``, so the XY of
the output are bit-identical to those of 2D input. Each output vertex then gets its Z
(and M) from the input curve it was built from, by :func:`restore_zm`:

* **Kept vertices** (output vertices whose XY equal an input vertex of the same ring or
  line, in order along it: fixed anchors, coverage and network nodes, line ends, pieces
  left unsmoothed) get that input vertex's values exactly.
* **Every other vertex** lies between two kept vertices. Walking that piece of the output
  in order, each vertex is projected onto the nearest input edge *at or after* the edge
  of the previous vertex, within the next ``WINDOW`` edges of the same piece, and its
  values are interpolated linearly along that edge, ``v = v_a + t (v_b - v_a)`` at the
  foot point's parameter ``t``. The projection never goes backwards, so a vertex is
  never attached to a far part of the ring that happens to be close in XY.
* A ring with no kept vertex at all (a closed CCA ring: every vertex moves) starts at
  the nearest point of the whole ring and walks once around it.
* Input repaired by ``make_valid=True`` is repaired here the same way first (GEOS keeps
  Z/M and interpolates them at new nodes), so its rings pair up with the output's.

Why this is "the edge it was built from" (Gordon 2010, section 3, CCA1): one iteration
puts, for every input edge ``AB``, two cut points ``C, D`` on ``AB`` and the apex ``G``
of the augmenting isosceles triangle on ``CD``, whose foot is the midpoint of ``CD``,
again on ``AB``. The nearest input edge of ``C`` and ``D`` is ``AB`` itself (distance
0), and ``G``'s foot on ``AB`` is the midpoint of ``CD``; further iterations move each
vertex by a fraction of the local edge length. Chaikin's points lie on the edges.

What holds on a tilted plane ``z = a x + b y + c`` (tested): linear interpolation of an
affine function along a segment is exact, so every output vertex gets the plane's value
*at its foot point* ``F`` on the input edge: ``z = a F_x + b F_y + c`` to rounding. A
vertex that lies on an input edge (the cut points ``C, D`` of one CCA pass, every
Chaikin point, kept vertices) is therefore on the plane to rounding; a vertex off the
input curve (an augmentation apex) is off the plane by ``(a, b) . (Q - F)``, at most
``|(a, b)|`` times its distance from the input curve.

Shared arcs get identical values: each piece between two kept vertices is processed in
a canonical direction (from its lexicographically smaller end), and the values depend
only on that piece's input and output vertices, so a coverage arc shared by two
polygons (or a network piece shared by two lines, in either direction) gets the same
values in both, provided the input gives its vertices the same values in both.
A ring without kept vertex is likewise put in a canonical start and orientation.

M values: shapely (GEOS 3.12+) holds XYM and XYZM geometries, so the Python API keeps
them. pyogrio 0.13 reads M-typed layers only by dropping M and cannot write them; the
file paths refuse M in one line (:func:`curvesmith.geo.read_file`).
"""

from __future__ import annotations

import struct

import numpy as np

from ..errors import require

__all__ = ["ZMSource", "restore_zm", "restoring", "split_zm"]

#: How many input edges ahead of the previous vertex's edge a vertex may be projected to.
WINDOW = 6


def _shapely():
    return require("shapely", "geo", "Z/M values")


class ZMSource:
    """The Z/M input of a smoothing call: kept aside while XY is smoothed (see module doc).

    Attributes
    ----------
    geoms : (F,) object ndarray
        The input geometries with their Z/M.
    has_z, has_m : (F,) bool ndarray
        Which features carry Z, M.
    """

    def __init__(self, geoms: np.ndarray, has_z: np.ndarray, has_m: np.ndarray):
        self.geoms, self.has_z, self.has_m = geoms, has_z, has_m

    def restore(self, out: np.ndarray) -> np.ndarray:
        """``out`` (the planar result, same features) with Z/M put back (a new array)."""
        return restore_zm(self, out)


def split_zm(geoms: np.ndarray) -> tuple[np.ndarray, ZMSource | None]:
    """Planar copies of `geoms` and their Z/M source (``None`` when no feature has Z or M)."""
    shapely = _shapely()
    geoms = np.asarray(geoms, dtype=object)
    # one pass over the geometries (2: XY, 3: XYZ or XYM, 4: XYZM, -1: None), then Z and M
    # of the few with more than XY (each pass over a layer costs more than its work)
    dims = shapely.get_coordinate_dimension(geoms) > 2
    if not dims.any():
        return geoms, None
    has_z = np.zeros(len(geoms), dtype=bool)
    has_m = np.zeros(len(geoms), dtype=bool)
    has_z[dims] = shapely.has_z(geoms[dims])
    has_m[dims] = shapely.has_m(geoms[dims])
    dims = has_z | has_m
    flat = geoms.copy()
    flat[dims] = shapely.force_2d(geoms[dims])
    return flat, ZMSource(geoms, has_z, has_m)


def restoring(wrap, source: ZMSource):
    """``wrap`` (the container rebuilder of ``as_geometry_array``) putting Z/M back first."""
    return lambda out: wrap(source.restore(out))


# ------------------------------------------------------------------------------- curves


def _curves(geoms: np.ndarray):
    """Rings and lines of `geoms` in ``get_coordinates`` order, with their feature."""
    shapely = _shapely()
    T = shapely.GeometryType
    parts, pfeat = shapely.get_parts(geoms, return_index=True)
    ptype = shapely.get_type_id(parts)
    while np.any(ptype >= T.MULTIPOINT):  # collections of multi-geometries: flatten
        parts, sub = shapely.get_parts(parts, return_index=True)
        pfeat, ptype = pfeat[sub], shapely.get_type_id(parts)
    poly = ptype == T.POLYGON
    ring_geoms, ring_part = shapely.get_rings(parts[poly], return_index=True)
    ring_part = np.flatnonzero(poly)[ring_part]
    other = np.flatnonzero(~poly)
    curves = np.concatenate([ring_geoms, parts[other]])
    key = np.concatenate([ring_part, other])
    order = np.argsort(key, kind="stable")
    curves, key = curves[order], key[order]
    keep = ~shapely.is_empty(curves)
    return curves[keep], pfeat[key[keep]]


def _pairs(src_feat, out_feat, src_curves, out_curves) -> np.ndarray:
    """For every output curve, the input curve it comes from (same feature)."""
    shapely = _shapely()
    n_feat = int(max(src_feat.max(initial=-1), out_feat.max(initial=-1))) + 1
    ns = np.bincount(src_feat, minlength=n_feat)
    no = np.bincount(out_feat, minlength=n_feat)
    first_s = np.concatenate([[0], np.cumsum(ns)[:-1]])
    first_o = np.concatenate([[0], np.cumsum(no)[:-1]])
    ordinal = np.arange(len(out_feat)) - first_o[out_feat]
    pair = first_s[out_feat] + ordinal
    # features whose rings were restructured (coverage_clean with snap): nearest ring
    for f in np.flatnonzero((ns != no) & (no > 0)):
        if ns[f] == 0:
            pair[out_feat == f] = -1
            continue
        cand = np.arange(first_s[f], first_s[f] + ns[f])
        for j in np.flatnonzero(out_feat == f):
            d = shapely.hausdorff_distance(out_curves[j], src_curves[cand])
            pair[j] = cand[int(np.argmin(d))]
    return pair


def _ragged(curves, dims: int):
    """Coordinates of `curves` without closing vertex; consecutive XY repeats dropped."""
    shapely = _shapely()
    c, idx = shapely.get_coordinates(
        curves, include_z=dims > 0, include_m=dims > 0, return_index=True
    )
    if dims == 0:
        c = np.column_stack([c, np.full((len(c), 2), np.nan)])
    elif c.shape[1] == 3:  # pragma: no cover - shapely returns both when asked for both
        c = np.column_stack([c, np.full(len(c), np.nan)])
    xy = c[:, :2] + 0.0  # -0.0 -> 0.0: exact matches compare bit patterns
    off = np.searchsorted(idx, np.arange(len(curves) + 1)).astype(np.int64)
    closed = np.asarray(shapely.is_closed(curves), dtype=bool) & (np.diff(off) >= 4)
    keep = np.ones(len(xy), dtype=bool)
    keep[off[1:][closed] - 1] = False
    return xy, c[:, 2:], off, closed, keep


def restore_zm(source: ZMSource, out: np.ndarray) -> np.ndarray:
    """Put Z/M back on the planar output `out` of the features of `source`."""
    shapely = _shapely()
    out = np.asarray(out, dtype=object).copy()
    dims = source.has_z | source.has_m
    present = np.array([g is not None for g in out], dtype=bool)
    idx = np.flatnonzero(dims & present)
    if idx.size:
        idx = idx[~shapely.is_empty(out[idx])]
    if idx.size == 0:
        return out
    src = source.geoms[idx].copy()
    invalid = ~shapely.is_valid(src)  # repaired as geo's prepare does (make_valid=True)
    if invalid.any():  # GEOS keeps Z/M and interpolates them at the new nodes
        src[invalid] = shapely.make_valid(src[invalid], method="structure", keep_collapsed=False)
    src_c, src_f = _curves(src)
    out_c, out_f = _curves(out[idx])
    pair = _pairs(src_f, out_f, src_c, out_c)
    sxy, sv, soff, sclosed, skeep = _ragged(src_c, 2)
    oxy, _, ooff, oclosed, okeep = _ragged(out_c, 0)
    # input: drop the closing vertex of rings and consecutive repeats (geo's prepare does)
    sid = np.repeat(np.arange(len(src_c)), np.diff(soff))
    rep = np.zeros(len(sxy), dtype=bool)
    rep[1:] = (sid[1:] == sid[:-1]) & np.all(sxy[1:] == sxy[:-1], axis=1)
    skeep &= ~rep
    sxy, sv, sid = sxy[skeep], sv[skeep], sid[skeep]
    soff = np.searchsorted(sid, np.arange(len(src_c) + 1)).astype(np.int64)
    oid = np.repeat(np.arange(len(out_c)), np.diff(ooff))
    rows = np.flatnonzero(okeep)
    ooff2 = np.searchsorted(oid[rows], np.arange(len(out_c) + 1)).astype(np.int64)
    oxy2 = oxy[rows]
    # exact XY matches of every output vertex among its input curve's vertices
    spair = np.repeat(np.arange(len(src_c)), np.diff(soff)).astype(float)
    opair = pair[oid[rows]].astype(float)
    void = np.dtype((np.void, 24))
    skey = np.ascontiguousarray(np.column_stack([spair, sxy])).view(void).ravel()
    okey = np.ascontiguousarray(np.column_stack([opair, oxy2])).view(void).ravel()
    order = np.argsort(skey, kind="stable")
    lo = np.searchsorted(skey[order], okey, side="left")
    hi = np.searchsorted(skey[order], okey, side="right")
    from ._zm_kernel import interpolate

    vals = np.full((len(oxy2), 2), np.nan)
    ok = pair >= 0
    interpolate(
        sxy,
        np.ascontiguousarray(sv),
        soff,
        np.ascontiguousarray(pair.astype(np.int64)),
        np.ascontiguousarray(ok & oclosed & sclosed[np.maximum(pair, 0)]),
        np.ascontiguousarray(oxy2),
        ooff2,
        lo.astype(np.int64),
        hi.astype(np.int64),
        order.astype(np.int64),
        WINDOW,
        vals,
    )
    # back to every output coordinate: a ring's closing vertex repeats its first
    full = np.empty((len(oxy), 2))
    full[rows] = vals
    closing = ooff[1:][oclosed] - 1
    full[closing] = full[ooff[:-1][oclosed]]
    return _assemble(out, idx, source, oxy, full)


def _assemble(out, idx, source, xy, values):
    """Write the values onto the output features (Z through shapely, M through WKB)."""
    shapely = _shapely()
    feats = out[idx]
    counts = shapely.get_num_coordinates(feats)
    start = np.concatenate([[0], np.cumsum(counts)])
    z_only = source.has_z[idx] & ~source.has_m[idx]
    if z_only.any():
        rows = np.concatenate(
            [np.arange(start[k], start[k + 1]) for k in np.flatnonzero(z_only)]
        ).astype(np.int64)
        g3 = shapely.force_3d(feats[z_only])
        out[idx[z_only]] = shapely.set_coordinates(g3, np.column_stack([xy[rows], values[rows, 0]]))
    for k in np.flatnonzero(~z_only):
        f = int(idx[k])
        sl = slice(start[k], start[k + 1])
        out[f] = _with_dims(
            feats[k], xy[sl], values[sl], bool(source.has_z[f]), bool(source.has_m[f])
        )
    return out


def _with_dims(geom, xy: np.ndarray, values: np.ndarray, has_z: bool, has_m: bool):
    """`geom` rebuilt from ISO WKB with Z and/or M columns (shapely cannot set M)."""
    shapely = _shapely()
    cols = [xy]
    if has_z:
        cols.append(values[:, :1])
    if has_m:
        cols.append(values[:, 1:2])
    coords = np.ascontiguousarray(np.column_stack(cols), dtype="<f8")
    flag = (1000 if has_z else 0) + (2000 if has_m else 0)
    wkb = shapely.to_wkb(shapely.force_2d(geom), flavor="iso", byte_order=1)
    pieces: list[bytes] = []
    pos = 0
    row = 0

    def walk() -> None:
        nonlocal pos, row
        gtype = struct.unpack_from("<I", wkb, pos + 1)[0]
        pieces.append(wkb[pos : pos + 1] + struct.pack("<I", gtype + flag))
        pos += 5
        if gtype == 1:  # point
            pieces.append(coords[row].tobytes())
            row += 1
            pos += 16
            return
        n = struct.unpack_from("<I", wkb, pos)[0]
        pieces.append(wkb[pos : pos + 4])
        pos += 4
        if gtype == 2:  # linestring
            pieces.append(coords[row : row + n].tobytes())
            row += n
            pos += 16 * n
        elif gtype == 3:  # polygon
            for _ in range(n):
                m = struct.unpack_from("<I", wkb, pos)[0]
                pieces.append(wkb[pos : pos + 4])
                pos += 4
                pieces.append(coords[row : row + m].tobytes())
                row += m
                pos += 16 * m
        else:  # multi-geometries and collections
            for _ in range(n):
                walk()

    walk()
    return shapely.from_wkb(b"".join(pieces))
