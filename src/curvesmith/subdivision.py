"""Linear corner cutting: Chaikin, de Rham and Lane–Riesenfeld subdivision.

All three work for open and closed polylines in any dimension ``(N, d)`` and
are vectorized: each refinement step is a handful of array operations (large ragged
batches of de Rham / Chaikin run compiled, bit for bit the same).

* :func:`de_rham` is the corner cutting of de Rham as recalled in section 2 of
  Merrien, *Prescribing the length of a de Rham curve*: every side is divided
  in the ratios ``1 : gamma : 1`` and the two inner division points become
  vertices, ``S_{2i} = alpha S_i + beta S_{i+1}``,
  ``S_{2i+1} = beta S_i + alpha S_{i+1}`` with ``beta = 1 / (gamma + 2)``,
  ``alpha = 1 - beta``. An open polygon with ``s`` sides becomes one with
  ``2 s`` vertices. ``gamma = 2`` is Chaikin's algorithm.
* :func:`lane_riesenfeld` follows Theorem 5 of Käferböck, *Affine arc length
  polylines and curvature continuous uniform B-splines*: one step of degree
  ``n`` is ``mu^n`` applied to the sequence with every vertex doubled, where
  ``mu`` averages neighbours. Degree 1 inserts midpoints, degree 2 is Chaikin,
  degree ``n`` converges to the uniform B-spline of degree ``n``.
  (Theorem 5 as printed numbers the output ``x'_0 .. x'_{N+1}``; the doubled
  sequence has ``2N + 2`` entries and ``mu^n`` removes ``n`` of them, so an open
  step yields ``2N + 2 - n`` vertices — checked numerically in the tests.)

Open polylines may keep their end points (``preserve_endpoints=True``): they are
kept beside the cut points, ``2 (N - 1) + 2`` vertices per step. PostGIS
``ST_ChaikinSmoothing`` keeps the ends of a line always, in place of its first and last
cut point (``2 (N - 1)`` vertices), and applies ``preserveEndPoints`` to rings only.
Points are rows in any dimension, except that an array of 2 or 3 rows with more
than 3 columns is refused as transposed (``(2, N)`` coordinates instead of
``(N, 2)`` points, the usual mix-up); ``closed`` and ``preserve_endpoints`` must
be booleans.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from ._validate import MAX_VERTICES, as_bool, as_float, as_int, as_points, check_growth
from .errors import CurveError

__all__ = [
    "MAX_VERTICES",
    "chaikin",
    "chaikin_ragged",
    "de_rham",
    "de_rham_ragged",
    "lane_riesenfeld",
    "lane_riesenfeld_ragged",
]


def _input_points(points, closed) -> tuple[np.ndarray, bool]:
    """Validate the common arguments; (N, d) rows in any dimension, but not a transposed array."""
    closed = as_bool(closed, name="closed")
    try:
        shape = np.shape(points)
    except ValueError:  # ragged: as_points says what is wrong
        shape = ()
    if len(shape) == 2 and shape[0] in (2, 3) and shape[1] > 3:
        raise CurveError(
            f"points must have shape (N, d) with one point per row, got {shape}: "
            f"{shape[1]} points with {shape[0]} coordinates each look transposed "
            "(pass points.T)"
        )
    p = as_points(points, closed=closed, min_points=3 if closed else 2, dim=None)
    return p, closed


def chaikin(
    points: ArrayLike,
    *,
    closed: bool,
    iterations: int = 1,
    preserve_endpoints: bool = False,
) -> np.ndarray:
    """Chaikin's corner cutting (quarter points of every edge).

    Parameters
    ----------
    points : (N, d) array_like
        Vertices as rows, any dimension. With ``closed=True`` a repeated
        closing vertex is dropped.
    closed : bool
        Treat the input as a closed polygon.
    iterations : int, optional
        Number of refinement steps, >= 0.
    preserve_endpoints : bool, optional
        For open input, keep the first and last vertex beside the cut points (see the
        module's notes on PostGIS). Ignored for closed input.

    Returns
    -------
    ndarray
        A closed n-gon becomes a 2n-gon per step; an open polyline with N
        vertices becomes one with 2(N - 1) vertices (plus 2 kept end points).

    Examples
    --------
    The PostGIS documentation example (area 64 -> 52):

    >>> chaikin([[0, 0], [8, 8], [0, 16]], closed=True).tolist()
    [[2.0, 2.0], [6.0, 6.0], [6.0, 10.0], [2.0, 14.0], [0.0, 12.0], [0.0, 4.0]]
    """
    return de_rham(
        points,
        gamma=2.0,
        closed=closed,
        iterations=iterations,
        preserve_endpoints=preserve_endpoints,
    )


def de_rham(
    points: ArrayLike,
    *,
    gamma: float,
    closed: bool = False,
    iterations: int = 1,
    preserve_endpoints: bool = False,
) -> np.ndarray:
    """De Rham corner cutting with side ratios ``1 : gamma : 1`` (Merrien, section 2).

    Parameters
    ----------
    points : (N, d) array_like
        Vertices as rows, any dimension.
    gamma : float
        Ratio parameter, ``gamma > 1`` (the limit curve is then C^1);
        ``gamma = 2`` is Chaikin.
    closed : bool, optional
        Treat the input as a closed polygon.
    iterations : int, optional
        Number of refinement steps, >= 0.
    preserve_endpoints : bool, optional
        For open input, keep the first and last vertex.

    Returns
    -------
    ndarray
        New vertices. Closed: ``2N`` per step, vertex ``2i`` and ``2i + 1`` on
        edge i (from vertex i to i + 1). Open: ``2(N - 1)`` per step.

    Examples
    --------
    >>> de_rham([[0, 0], [1, 1], [2, 0]], gamma=3.0).tolist()
    [[0.2, 0.2], [0.8, 0.8], [1.2, 0.8], [1.8, 0.2]]
    """
    gamma = as_float(gamma, name="gamma", low=1.0)
    iterations = as_int(iterations, name="iterations", minimum=0)
    p, closed = _input_points(points, closed)
    preserve_endpoints = as_bool(preserve_endpoints, name="preserve_endpoints")
    extra = 0 if closed else (0 if preserve_endpoints else -2)
    check_growth(p.shape[0], iterations, lambda n: 2 * n + extra, limit=MAX_VERTICES)
    beta = 1.0 / (gamma + 2.0)
    alpha = 1.0 - beta
    for _ in range(iterations):
        p = _de_rham_step(p, alpha, beta, closed, preserve_endpoints)
    return p


def _de_rham_step(
    p: np.ndarray, alpha: float, beta: float, closed: bool, keep_ends: bool
) -> np.ndarray:
    m, d = (p.shape[0], p.shape[1]) if closed else (p.shape[0] - 1, p.shape[1])
    extra = 2 if (keep_ends and not closed) else 0
    out = np.empty((2 * m + extra, d))
    body = out[1:-1] if extra else out
    # One coordinate at a time: numpy's loops over (m, d) arrays with a short inner axis
    # and strided output cost ~10x more than 1-D loops (measured at 1e5 vertices).
    # S_2i = a + beta (b - a) = alpha a + beta b ;  S_2i+1 = b - beta (b - a) = beta a + alpha b.
    nxt = np.empty(m)
    step = np.empty(m)
    for k in range(d):
        col = p[:, k]
        a = col[:m]
        if closed:
            nxt[:-1] = col[1:]
            nxt[-1] = col[0]
        else:
            nxt[:] = col[1:]
        np.subtract(nxt, a, out=step)
        step *= beta
        np.add(a, step, out=body[0::2, k])
        np.subtract(nxt, step, out=body[1::2, k])
    if extra:
        out[0] = p[0]
        out[-1] = p[-1]
    return out


def lane_riesenfeld(
    points: ArrayLike,
    *,
    degree: int,
    closed: bool = False,
    iterations: int = 1,
    preserve_endpoints: bool = False,
) -> np.ndarray:
    """Lane–Riesenfeld subdivision of the given degree (Käferböck, Theorem 5).

    One step doubles every vertex and applies ``degree`` rounds of
    neighbour averaging ``mu``. Repeated steps converge to the uniform B-spline
    of that degree with the input as control polygon.

    Parameters
    ----------
    points : (N, d) array_like
        Control polygon, any dimension.
    degree : int
        B-spline degree ``n >= 1``.
    closed : bool, optional
        Periodic (closed) control polygon.
    iterations : int, optional
        Number of refinement steps, >= 0.
    preserve_endpoints : bool, optional
        For open input, keep the first and last vertex.

    Returns
    -------
    ndarray
        Closed: ``2N`` vertices per step. Open: ``2N - degree`` per step (two
        more with `preserve_endpoints`), so an open step needs
        ``2N - degree >= 2``, and steps shrink the polyline when ``N < degree``.

    Notes
    -----
    The closed step averages cyclically, so output vertex ``j`` is the mean of
    doubled entries ``j .. j + degree``, exactly as in the open step; away from
    the seam closed and open outputs agree index for index, and ``degree = 2``
    coincides with :func:`chaikin` vertex for vertex.

    Examples
    --------
    >>> lane_riesenfeld([[0, 0], [4, 0], [4, 4]], degree=2).tolist()
    [[1.0, 0.0], [3.0, 0.0], [4.0, 1.0], [4.0, 3.0]]
    """
    degree = as_int(degree, name="degree", minimum=1)
    iterations = as_int(iterations, name="iterations", minimum=0)
    p, closed = _input_points(points, closed)
    preserve_endpoints = as_bool(preserve_endpoints, name="preserve_endpoints")
    if not closed:
        # an open step keeps 2 n - degree averaged vertices (+ 2 kept ends), which must be a
        # polyline; for n < degree the count shrinks from step to step
        n = p.shape[0]
        for k in range(iterations):
            if 2 * n - degree < 2:
                if k == 0:
                    raise CurveError(
                        f"points must have at least {(degree + 3) // 2} points for an open "
                        f"Lane-Riesenfeld step of degree {degree}, got {p.shape[0]}"
                    )
                raise CurveError(
                    f"iterations must be at most {k} for an open polyline of {p.shape[0]} points "
                    f"and degree {degree} (a step turns n vertices into 2 n - {degree}), "
                    f"got {iterations}"
                )
            grown = 2 * n - degree + (2 if preserve_endpoints else 0)
            if grown == n or grown > MAX_VERTICES:
                break  # stable from here on, or too large (reported below)
            n = grown
    extra = 0 if closed else (2 if preserve_endpoints else 0) - degree
    check_growth(p.shape[0], iterations, lambda n: 2 * n + extra, limit=MAX_VERTICES)
    for _ in range(iterations):
        p = _lane_riesenfeld_step(p, degree, closed, preserve_endpoints)
    return p


def _lane_riesenfeld_step(p: np.ndarray, degree: int, closed: bool, keep_ends: bool) -> np.ndarray:
    q = np.repeat(p, 2, axis=0)
    if closed:
        for _ in range(degree):
            q = 0.5 * (q + np.roll(q, -1, axis=0))
        return q
    for _ in range(degree):
        q = 0.5 * (q[1:] + q[:-1])
    if keep_ends:
        q = np.concatenate([p[:1], q, p[-1:]])
    return q


# --------------------------------------------------------------------------- ragged batches


def _ragged_input(coords, offsets, closed, preserve_endpoints):
    from ._ragged import as_ragged

    rag = as_ragged(coords, offsets, closed=closed, dim=None, compiled=True)
    if rag.points.ndim == 2 and rag.points.shape[1] == 0:
        raise CurveError("coords must have at least one column")
    preserve_endpoints = as_bool(preserve_endpoints, name="preserve_endpoints")
    lengths = np.diff(rag.offsets)
    need = np.where(rag.closed, 3, 2)
    short = np.flatnonzero(lengths < need)
    if short.size:
        k = int(short[0])
        ring = " distinct ring" if rag.closed[k] else ""
        raise CurveError(
            f"coords must have at least {need[k]}{ring} points per curve, "
            f"got {int(lengths[k])} for curve {k}"
        )
    return rag.points, rag.offsets, rag.closed, preserve_endpoints


def _edge_ends(offsets: np.ndarray, closed: np.ndarray):
    """Start and end row of every edge of every curve, and the number of edges per curve."""
    lengths = np.diff(offsets)
    n_edges = np.where(closed, lengths, lengths - 1)
    start = np.repeat(offsets[:-1], n_edges)
    first_edge = np.zeros(lengths.size + 1, dtype=np.int64)
    np.cumsum(n_edges, out=first_edge[1:])
    local = np.arange(first_edge[-1]) - np.repeat(first_edge[:-1], n_edges)
    a = start + local
    b = a + 1
    wrap = closed & (n_edges > 0)
    b[first_edge[1:][wrap] - 1] = offsets[:-1][wrap]  # the closing edge of a ring
    return a, b, n_edges


def de_rham_ragged(
    coords: ArrayLike,
    offsets: ArrayLike,
    *,
    gamma: float,
    closed: bool | ArrayLike = False,
    iterations: int = 1,
    preserve_endpoints: bool = False,
    close_rings: bool = False,
) -> tuple[np.ndarray, np.ndarray]:
    """:func:`de_rham` on many curves in one call (one coordinate array plus offsets).

    Every curve gets exactly (bit for bit) what :func:`de_rham` gives it alone; each
    step is a few whole-array operations over all curves, or, from
    :data:`COMPILED_MIN` input rows, one compiled pass that runs every curve's steps in
    the cache (the same operations in the same order).

    Parameters
    ----------
    coords : (N, d) array_like
        All curves one after the other (the layout of :func:`shapely.to_ragged_array`).
        A closed curve may repeat its first vertex at its end (dropped).
    offsets : (M + 1,) array_like of int
        Curve ``k`` is ``coords[offsets[k]:offsets[k + 1]]``.
    gamma : float
        Ratio parameter, ``gamma > 1``.
    closed : bool or (M,) array_like of bool, optional
        One flag for all curves or one per curve.
    iterations : int, optional
        Number of refinement steps, >= 0.
    preserve_endpoints : bool, optional
        For open curves, keep the first and last vertex.
    close_rings : bool, optional
        Write every closed curve with its first vertex repeated at its end (the layout
        of :func:`shapely.from_ragged_array`); default: not repeated.

    Returns
    -------
    coords : (N', d) ndarray
        The refined curves one after the other (rings without repeated vertex, unless
        `close_rings`).
    offsets : (M + 1,) int64 ndarray
        The curves of the output.

    Examples
    --------
    >>> xy = [[0, 0], [1, 1], [2, 0], [0, 0], [8, 8], [0, 16]]
    >>> out, off = de_rham_ragged(xy, [0, 3, 6], gamma=3.0, closed=[False, True])
    >>> off.tolist(), out[:4].tolist()
    ([0, 4, 10], [[0.2, 0.2], [0.8, 0.8], [1.2, 0.8], [1.8, 0.2]])
    """
    gamma = as_float(gamma, name="gamma", low=1.0)
    iterations = as_int(iterations, name="iterations", minimum=0)
    close_rings = as_bool(close_rings, name="close_rings")
    p, off, cl, keep = _ragged_input(coords, offsets, closed, preserve_endpoints)
    extra = 0 if keep else -2
    check_growth(p.shape[0], iterations, lambda n: 2 * n + extra, limit=MAX_VERTICES)
    beta = 1.0 / (gamma + 2.0)
    if iterations and p.shape[0] >= COMPILED_MIN:
        return _de_rham_compiled(p, off, cl, beta, keep, iterations, close_rings)
    for _ in range(iterations):
        p, off = _de_rham_ragged_step(p, off, cl, beta, keep)
    if close_rings:
        from ._ragged import close_curves

        p, off = close_curves(p, off, cl)
    return p, off


#: Input rows from which the ragged de Rham / Chaikin steps run compiled (every curve's
#: steps in the cache, the last one written straight into the output; the same bits as
#: the numpy steps below). 20,000 footprints, 2 Chaikin steps: 3 ms against numpy's 52.
COMPILED_MIN = 1 << 14


def _de_rham_compiled(p, off, closed, beta, keep, iterations, close_rings):
    from . import _subdivision_kernel as kernel

    n = np.diff(off)
    ends = keep & ~closed
    for _ in range(iterations):
        n = 2 * np.where(closed, n, n - 1) + 2 * ends
    n = n + (closed & close_rings & (n > 0))
    out_off = np.zeros(off.size, dtype=np.int64)
    np.cumsum(n, out=out_off[1:])
    out = kernel.de_rham_ragged(
        np.ascontiguousarray(p, dtype=np.float64), off, closed, beta, bool(keep), iterations,
        out_off, close_rings,
    )  # fmt: skip
    return out, out_off


def chaikin_ragged(
    coords: ArrayLike,
    offsets: ArrayLike,
    *,
    closed: bool | ArrayLike,
    iterations: int = 1,
    preserve_endpoints: bool = False,
    close_rings: bool = False,
) -> tuple[np.ndarray, np.ndarray]:
    """:func:`chaikin` on many curves in one call (one coordinate array plus offsets).

    Parameters
    ----------
    coords, offsets, closed, iterations, preserve_endpoints, close_rings
        As in :func:`de_rham_ragged` (``gamma = 2``).

    Returns
    -------
    coords : (N', d) ndarray
    offsets : (M + 1,) int64 ndarray

    Examples
    --------
    >>> out, off = chaikin_ragged([[0, 0], [8, 8], [0, 16]], [0, 3], closed=True)
    >>> out.tolist() == chaikin([[0, 0], [8, 8], [0, 16]], closed=True).tolist()
    True
    """
    return de_rham_ragged(
        coords,
        offsets,
        gamma=2.0,
        closed=closed,
        iterations=iterations,
        preserve_endpoints=preserve_endpoints,
        close_rings=close_rings,
    )


def _de_rham_ragged_step(p, off, closed, beta, keep_ends):
    a, b, n_edges = _edge_ends(off, closed)
    ends = keep_ends & ~closed
    out_len = 2 * n_edges + 2 * ends
    new_off = np.zeros(off.size, dtype=np.int64)
    np.cumsum(out_len, out=new_off[1:])
    out = np.empty((int(new_off[-1]), p.shape[1]))
    # body rows: after the kept first point of an open curve
    body_start = new_off[:-1] + ends
    first_edge = np.zeros(off.size, dtype=np.int64)
    np.cumsum(n_edges, out=first_edge[1:])
    rows = np.repeat(body_start - 2 * first_edge[:-1], n_edges) + 2 * np.arange(first_edge[-1])
    pa, pb = p[a], p[b]
    step = np.subtract(pb, pa)
    step *= beta
    out[rows] = pa + step
    out[rows + 1] = pb - step
    if ends.any():
        k = np.flatnonzero(ends)
        out[new_off[k]] = p[off[k]]
        out[new_off[k + 1] - 1] = p[off[k + 1] - 1]
    return out, new_off


def lane_riesenfeld_ragged(
    coords: ArrayLike,
    offsets: ArrayLike,
    *,
    degree: int,
    closed: bool | ArrayLike = False,
    iterations: int = 1,
    preserve_endpoints: bool = False,
) -> tuple[np.ndarray, np.ndarray]:
    """:func:`lane_riesenfeld` on many curves in one call (one coordinate array plus offsets).

    Every curve gets exactly (bit for bit) what :func:`lane_riesenfeld` gives it alone.

    Parameters
    ----------
    coords, offsets, closed, iterations, preserve_endpoints
        As in :func:`de_rham_ragged`.
    degree : int
        B-spline degree ``n >= 1``.

    Returns
    -------
    coords : (N', d) ndarray
    offsets : (M + 1,) int64 ndarray

    Raises
    ------
    CurveError
        As :func:`lane_riesenfeld`, naming the curve (an open curve too short for the
        degree).

    Examples
    --------
    >>> xy = [[0, 0], [4, 0], [4, 4], [0, 0], [1, 0], [1, 1]]
    >>> out, off = lane_riesenfeld_ragged(xy, [0, 3, 6], degree=2, closed=[False, True])
    >>> out[:4].tolist()
    [[1.0, 0.0], [3.0, 0.0], [4.0, 1.0], [4.0, 3.0]]
    """
    degree = as_int(degree, name="degree", minimum=1)
    iterations = as_int(iterations, name="iterations", minimum=0)
    p, off, cl, keep = _ragged_input(coords, offsets, closed, preserve_endpoints)
    n = np.diff(off)
    grow = 2 if keep else 0
    for k in range(iterations):
        bad = ~cl & (2 * n - degree < 2)
        if bad.any():
            c = int(np.flatnonzero(bad)[0])
            if k == 0:
                raise CurveError(
                    f"coords must have at least {(degree + 3) // 2} points for an open "
                    f"Lane-Riesenfeld step of degree {degree}, got {int(n[c])} for curve {c}"
                )
            raise CurveError(
                f"iterations must be at most {k} for curve {c} of {int(np.diff(off)[c])} "
                f"points and degree {degree} (a step turns n vertices into 2 n - {degree}), "
                f"got {iterations}"
            )
        n = np.where(cl, 2 * n, 2 * n - degree + grow)
        if n.sum() > MAX_VERTICES:
            break  # reported below
    extra = (2 if keep else 0) - degree
    ext = 0 if cl.all() else extra
    check_growth(p.shape[0], iterations, lambda m: 2 * m + ext, limit=MAX_VERTICES)
    for _ in range(iterations):
        p, off = _lane_riesenfeld_ragged_step(p, off, cl, degree, keep)
    return p, off


def _lane_riesenfeld_ragged_step(p, off, closed, degree, keep_ends):
    q = np.repeat(p, 2, axis=0)
    qoff = 2 * off
    m = closed.size
    lengths = np.diff(qoff)
    ids = np.repeat(np.arange(m), lengths)
    ring_rows = closed[ids]
    for _ in range(degree):
        # next row within the curve: cyclic for rings; for open curves the last row of
        # every curve is dropped after the average (the open step shortens by one)
        nxt = np.arange(1, q.shape[0] + 1)
        last = qoff[1:] - 1
        ring_last = last[closed & (lengths > 0)]
        nxt[ring_last] = qoff[:-1][closed & (lengths > 0)]
        if q.shape[0]:
            nxt[-1] = min(nxt[-1], q.shape[0] - 1)
        q = 0.5 * (q + q[nxt])
        drop = np.zeros(q.shape[0], dtype=bool)
        open_last = last[~closed & (lengths > 0)]
        drop[open_last] = True
        if drop.any():
            q = q[~drop]
            lengths = lengths - (~closed).astype(np.int64)
            qoff = np.zeros(m + 1, dtype=np.int64)
            np.cumsum(lengths, out=qoff[1:])
            ids = np.repeat(np.arange(m), lengths)
            ring_rows = closed[ids]
    del ring_rows
    ends = keep_ends & ~closed
    if not ends.any():
        return q, qoff
    k = np.flatnonzero(ends)
    new_len = lengths + 2 * ends
    new_off = np.zeros(m + 1, dtype=np.int64)
    np.cumsum(new_len, out=new_off[1:])
    out = np.empty((int(new_off[-1]), p.shape[1]))
    body = np.ones(out.shape[0], dtype=bool)
    body[new_off[k]] = False
    body[new_off[k + 1] - 1] = False
    out[body] = q
    out[new_off[k]] = p[off[k]]
    out[new_off[k + 1] - 1] = p[off[k + 1] - 1]
    return out, new_off
