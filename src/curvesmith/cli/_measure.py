"""What ``curvesmith measure`` computes, for all curves of a file at once.

The curves are one ragged batch (:mod:`curvesmith._ragged`'s layout): an ``(N, 3)``
coordinate array (z = 0 for planar curves), ``offsets`` and a flag per curve. Every
quantity is computed for all rows in numpy calls and gathered per curve with
``np.add.reduceat`` / ``np.minimum.reduceat``: a layer of 400,000 footprints costs what a
few array passes cost, not a Python call (and four input checks) per ring.

The numbers are those of the single-curve functions applied to each curve (the
definitions of :func:`curvesmith.geometry.curve_length`, :func:`~curvesmith.geometry.signed_area`
and :func:`~curvesmith.geometry.turning_angles`, term for term): edge lengths, the
shoelace terms about each curve's first vertex and the turning angles are the same
floating-point operations on the same numbers; only the order of the sums of a curve's
terms differs (sequential here, pairwise in ``ndarray.sum``), a few ulps.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..geometry import det2

__all__ = ["Measures", "measure_ragged"]


@dataclass(frozen=True)
class Measures:
    """The measures of K curves (arrays of length K).

    Attributes
    ----------
    points : (K,) int64 ndarray
        Vertices (a closed curve's repeated closing vertex not counted).
    length : (K,) float64 ndarray
        Length (perimeter of a closed curve), in the dimension of the curve.
    signed_area : (K,) float64 ndarray
        The shoelace area (CCW positive; for an open polyline the area between it and its
        chord) where `has_area`, else NaN.
    min_turning_angle, max_turning_angle : (K,) float64 ndarray
        The extreme signed turning angles at the distinct vertices (radians) where
        `has_turning`, else NaN.
    zero_length_edges : (K,) int64 ndarray
        Vertices equal to the one before them.
    has_turning : (K,) bool ndarray
        Planar curves with at least 3 distinct vertices.
    has_area : (K,) bool ndarray
        Those of them that are still polygons of 3 vertices without an open polyline's
        last vertex when it equals its first (``A B A`` encloses nothing).

    A value that overflowed (coordinates near the largest float) is inf or NaN where its
    ``has_*`` flag is True: the caller reports it.
    """

    points: np.ndarray
    length: np.ndarray
    signed_area: np.ndarray
    min_turning_angle: np.ndarray
    max_turning_angle: np.ndarray
    zero_length_edges: np.ndarray
    has_turning: np.ndarray
    has_area: np.ndarray


def _next_rows(start: np.ndarray, last: np.ndarray, closed: np.ndarray, n: int) -> np.ndarray:
    """The row after each row in its curve.

    The last row of a closed curve wraps to its first; that of an open one is itself (an
    edge of length zero).
    """
    nxt = np.arange(1, n + 1, dtype=np.int64)
    nxt[last] = np.where(closed, start, last)
    return nxt


def _starts(counts: np.ndarray) -> np.ndarray:
    return np.concatenate([[0], np.cumsum(counts)[:-1]]).astype(np.int64)


def measure_ragged(
    coords: np.ndarray, offsets: np.ndarray, closed: np.ndarray, dims: np.ndarray
) -> Measures:
    """Measure every curve of a ragged batch.

    Parameters
    ----------
    coords : (N, 3) ndarray of float64
        Vertices of all curves, z = 0 for planar ones; closed curves without a repeated
        closing vertex (as :class:`curvesmith.io.Curve` holds them). Finite.
    offsets : (K + 1,) ndarray of int
        Curve ``k`` is ``coords[offsets[k]:offsets[k + 1]]``: at least 2 rows, 3 when closed.
    closed : (K,) ndarray of bool
        Closed rings.
    dims : (K,) ndarray of int
        2 for planar curves, 3 for curves with z.

    Returns
    -------
    Measures
    """
    coords = np.asarray(coords, dtype=np.float64)
    offsets = np.asarray(offsets, dtype=np.int64)
    closed = np.asarray(closed, dtype=bool)
    planar = np.asarray(dims) == 2
    k = len(closed)
    nan = np.full(k, np.nan)
    if k == 0:
        empty, no = np.zeros(0, dtype=np.int64), np.zeros(0, dtype=bool)
        return Measures(empty, nan, nan, nan, nan, empty, no, no)
    n = np.diff(offsets)
    start, last = offsets[:-1], offsets[1:] - 1
    rows = len(coords)

    # consecutive equal vertices (in all the curve's dimensions)
    keep = np.ones(rows, dtype=bool)
    keep[1:] = np.any(coords[1:] != coords[:-1], axis=1)
    keep[start] = True
    zero_edges = n - np.add.reduceat(keep.astype(np.int64), start)

    # length: every edge, the closing one of a closed curve included; the norm as
    # np.linalg.norm forms it (an edge of a planar curve has dz = 0, which adds nothing)
    d = coords[_next_rows(start, last, closed, rows)] - coords
    length = np.add.reduceat(np.sqrt(np.add.reduce(d * d, axis=1)), start)

    # the distinct vertices q of each curve; a closed curve also without a last vertex
    # equal to its first
    cid = np.repeat(np.arange(k), n)
    q_rows = np.flatnonzero(keep)
    q_n = np.bincount(cid[q_rows], minlength=k)
    q_start = _starts(q_n)
    q_last = q_start + q_n - 1
    q = coords[q_rows]
    ends_equal = np.all(q[q_start] == q[q_last], axis=1) & (q_n > 1)
    drop = closed & ends_equal
    if drop.any():
        mask = np.ones(len(q), dtype=bool)
        mask[q_last[drop]] = False
        q, q_n = q[mask], q_n - drop
        q_start = _starts(q_n)
    measured = planar & (q_n >= 3)

    signed_area = nan.copy()
    lo, hi = nan.copy(), nan.copy()
    has_area = np.zeros(k, dtype=bool)
    if measured.any():
        # the planar curves with >= 3 distinct vertices, as a ragged batch of their own
        sel = np.flatnonzero(measured)
        m_n = q_n[sel]
        s = _starts(m_n)
        e = s + m_n - 1
        m_cid = np.repeat(np.arange(len(sel)), m_n)
        p = q[q_start[sel][m_cid] + (np.arange(len(m_cid)) - s[m_cid]), :2]
        signed_area[sel], has_area[sel] = _shoelace(p, s, e, m_n, m_cid)
        lo[sel], hi[sel] = _turning_extremes(p, s, e, closed[sel])
    return Measures(
        n.astype(np.int64), length, signed_area, lo, hi, zero_edges.astype(np.int64),
        measured, has_area,
    )  # fmt: skip


def _shoelace(
    p: np.ndarray, s: np.ndarray, e: np.ndarray, m: np.ndarray, cid: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Signed areas as :func:`curvesmith.geometry.signed_area` forms them, and where they exist.

    A curve whose last vertex equals its first (an open polyline that comes back) is the
    polygon without that repeated vertex, as ``signed_area`` drops it; with fewer than 3
    vertices left (``A B A``) it has no area.
    """
    back = np.all(p[s] == p[e], axis=1)
    if back.any():
        mask = np.ones(len(p), dtype=bool)
        mask[e[back]] = False
        p, m = p[mask], m - back
        cid = np.repeat(np.arange(len(m)), m)
        s = _starts(m)
        e = s + m - 1
    # trapezoid form about the first vertex (geometry._signed_area):
    # 2A = sum_{i < m-1} (x_i - x_{i+1}) (y_i + y_{i+1}) + x_{m-1} y_{m-1}
    rel = p - p[s][cid]
    x, y = rel[:, 0], rel[:, 1]
    terms = np.zeros(len(p))
    terms[:-1] = (x[:-1] - x[1:]) * (y[:-1] + y[1:])
    terms[e] = 0.0
    area = 0.5 * (np.add.reduceat(terms, s) + x[e] * y[e])
    ok = m >= 3
    area[~ok] = np.nan
    return area, ok


def _turning_extremes(
    p: np.ndarray, s: np.ndarray, e: np.ndarray, closed: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Smallest and largest turning angle per curve (:func:`curvesmith.geometry.turning_angles`)."""
    rows = len(p)
    edge = p[_next_rows(s, e, closed, rows)] - p  # edge i: from vertex i to the next
    # each edge scaled by a power of two to a largest component in [0.5, 1) (exact), as
    # geometry._unit_scaled does; the last row of an open curve has no edge (0, scaled by 1)
    _, exp = np.frexp(np.max(np.abs(edge), axis=1))
    edge = np.ldexp(edge, -exp[:, None])
    before = np.arange(-1, rows - 1, dtype=np.int64)  # the edge into vertex i
    before[s] = np.where(closed, e, s)
    a, b = edge[before], edge
    angle = np.arctan2(det2(a, b), np.einsum("ij,ij->i", a, b))
    # an open curve turns at its interior vertices only
    valid = np.ones(rows, dtype=bool)
    valid[s[~closed]] = False
    valid[e[~closed]] = False
    lo = np.minimum.reduceat(np.where(valid, angle, np.inf), s)
    hi = np.maximum.reduceat(np.where(valid, angle, -np.inf), s)
    return lo, hi
