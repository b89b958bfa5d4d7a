"""Linear corner cutting: Chaikin, de Rham and Lane–Riesenfeld subdivision.

All three work for open and closed polylines in any dimension ``(N, d)`` and
are vectorized: each refinement step is a handful of array operations.

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

Open polylines may keep their end points (``preserve_endpoints=True``), the
behaviour of PostGIS ``ST_ChaikinSmoothing(..., preserveEndPoints => true)``.
Points are rows in any dimension, except that an array of 2 or 3 rows with more
than 3 columns is refused as transposed (``(2, N)`` coordinates instead of
``(N, 2)`` points, the usual mix-up); ``closed`` and ``preserve_endpoints`` must
be booleans.
"""

from __future__ import annotations

import numpy as np

from ._validate import MAX_VERTICES, as_bool, as_float, as_int, as_points, check_growth
from .errors import CurveError

__all__ = ["MAX_VERTICES", "chaikin", "de_rham", "lane_riesenfeld"]


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
    points,
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
        For open input, keep the first and last vertex (PostGIS
        ``preserveEndPoints``). Ignored for closed input.

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
    points,
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
    points,
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
