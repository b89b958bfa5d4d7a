"""Public CCA1 functions: one curve (:func:`smooth`) or a ragged batch (:func:`smooth_ragged`).

Both run on the same engine: 2D curves (and planar 3D curves, in the
coordinates of their plane) go through the compiled kernel
:mod:`curvesmith.cca._kernel`, many curves per call; non-planar 3D polylines
through the N-d numpy step :mod:`curvesmith.cca._stepnd`.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from .. import _validate
from .._ragged import as_anchor_mask, as_ragged, close_curves, curve_ids
from .._rich import RichRepr
from .._validate import as_bool, as_float, as_int, as_points, check_growth
from ..errors import CurveError
from . import _stepnd
from ._input import anchor_indices, dedupe, dedupe_ragged, default_threads, plane_frame
from ._profiles import _eval_profile as _profiles_eval
from ._profiles import alpha_function, profile_tables

#: Coordinates outside (_TINY, _HUGE) in absolute value are rescaled by a power of two.
_TINY, _HUGE = 2.0**-400, 2.0**400
#: Below this many vertices a batch step runs in one thread.
THREAD_MIN = 65536
#: Core vertices per block of a long curve (see :func:`_blocks`).
BLOCK = 32768


@dataclass(frozen=True)
class CCAResult(RichRepr):
    """Result of :func:`smooth_with_info`.

    Attributes
    ----------
    points : (M, d) ndarray
        The smoothed polygon or polyline (same as :func:`smooth` returns).
    iterations : int
        Number of CCA1 steps performed.
    reductions : int
        Total number of local alpha decreases (vertices whose profile alpha was
        lowered by the restrictions), summed over all steps.
    reductions_per_step : tuple of int
        The same, per step.
    fig11_edges : int
        Number of balanced inflection edges treated with the two-triangle
        construction of Fig. 11, summed over all steps.
    unsatisfied : int
        Number of edges (summed over steps) where the restrictions do not hold
        in the end: not met within ``max_passes`` passes, or the
        ``min_factor`` floor stopped the decrease; 0 means every restriction held.
    success : bool
        ``unsatisfied == 0``. The area is preserved either way.
    message : str
        Human-readable summary.
    """

    points: np.ndarray
    iterations: int
    reductions: int
    reductions_per_step: tuple[int, ...]
    fig11_edges: int
    unsatisfied: int
    success: bool
    message: str


AlphaSpec = str | float | Callable[[np.ndarray], object]


def smooth(
    points: ArrayLike,
    *,
    closed: bool,
    iterations: int = 1,
    alpha: AlphaSpec = "regular",
    anchors: ArrayLike | None = None,
    corner_ratio: float = 2.0,
    inflection_ratio: float = 0.5,
    restrict: bool = True,
    tilt: float = np.pi / 8,
    balance_tol: float = 1e-9,
    max_passes: int = 16,
    min_factor: float = 0.0,
    threads: int | None = None,
) -> np.ndarray:
    """Area-preserving CCA1 smoothing of a polygon or polyline (Gordon 2010).

    Parameters
    ----------
    points : (N, 2) or (N, 3) array_like
        Vertices as rows. With ``closed=True`` a repeated closing vertex is
        dropped. Consecutive duplicate points are removed first (anchors on a
        removed duplicate move to the kept copy).
    closed : bool
        Closed polygon (signed area preserved) or open polyline (ends fixed,
        area between polyline and chord preserved).
    iterations : int, optional
        Number of CCA1 steps, >= 0.
    alpha : "regular", float or callable, optional
        alpha-profile (section 4): ``"regular"`` (Table 1, PCHIP), a constant
        in (0, 1/3), or a function of the interior angle in radians (array in,
        array out; values in [0, 1/3)). The function must act angle by angle:
        long curves are smoothed in blocks, possibly in several threads at once
        (see `threads`), so it is called on pieces of the angle array.
    anchors : sequence of int, optional
        Indices of input vertices that stay fixed (section 5); the pieces between
        anchors are smoothed as independent polylines, each keeping its area
        against its chord.
    corner_ratio : float, optional
        The constant ``c > 1`` of Definition 2 (``tan(gamma) >= c tan(beta)``).
    inflection_ratio : float, optional
        The constant ``0 < C < 1`` of section 3.2 (``epsilon <= C gamma`` at
        inflection edges).
    restrict : bool, optional
        Apply the restrictions (local alpha decrease). False gives plain CCA1
        with the profile's alphas.
    tilt : float, optional
        Bound (radians, in (0, pi/4]) on the summed tilts of Fig. 11 edges; the
        tilt at step n is ``tilt / 2**n`` (with ``restrict``, at most ``C`` times
        the smaller half turning angle).
    balance_tol : float, optional
        Inflection edges whose net cut area is at most this fraction of the
        mean cut area count as balanced and get the Fig. 11 construction (2D).
    max_passes : int, optional
        Maximum number of restriction passes per step.
    min_factor : float, optional
        Floor of the local decrease, in [0, 1): a restricted alpha never drops
        below ``min_factor`` times the profile's alpha (the ``epsilon < alpha_i``
        of Definition 2). With the default 0 the restrictions are always met, at
        the price of almost uncut corners next to nearly straight vertices
        (Fig. 12); a floor such as 0.5 keeps those corners smoothing, and edges
        where it binds are counted in :attr:`CCAResult.unsatisfied`.
    threads : int, optional
        Threads for long 2D curves: a step over at least 65536 vertices runs in
        blocks of 32768 (with halos; the result does not depend on the blocks
        or the threads), and ``threads`` blocks at a time. Default: the number
        of processors available to this process, at most 4 and at most
        ``OMP_NUM_THREADS`` when that is set (Dask workers set it to 1); 1 for
        no threads.

    Returns
    -------
    (M, d) ndarray
        The smoothed vertices (see the module notes for M).

    Raises
    ------
    CurveError
        Bad shape or values, fewer than 3 (closed) or 2 (open) distinct points,
        parameters out of range, anchors out of range.

    Examples
    --------
    >>> sq = [[0, 0], [1, 0], [1, 1], [0, 1]]
    >>> out = smooth(sq, closed=True, iterations=2)
    >>> out.shape
    (36, 2)
    >>> from curvesmith.geometry import signed_area
    >>> round(signed_area(out), 12)
    1.0
    """
    return smooth_with_info(
        points,
        closed=closed,
        iterations=iterations,
        alpha=alpha,
        anchors=anchors,
        corner_ratio=corner_ratio,
        inflection_ratio=inflection_ratio,
        restrict=restrict,
        tilt=tilt,
        balance_tol=balance_tol,
        max_passes=max_passes,
        min_factor=min_factor,
        threads=threads,
    ).points


def smooth_with_info(
    points: ArrayLike,
    *,
    closed: bool,
    iterations: int = 1,
    alpha: AlphaSpec = "regular",
    anchors: ArrayLike | None = None,
    corner_ratio: float = 2.0,
    inflection_ratio: float = 0.5,
    restrict: bool = True,
    tilt: float = np.pi / 8,
    balance_tol: float = 1e-9,
    max_passes: int = 16,
    min_factor: float = 0.0,
    threads: int | None = None,
) -> CCAResult:
    """Like :func:`smooth`, returning a :class:`CCAResult` with restriction counts.

    Parameters
    ----------
    points, closed, iterations, alpha, anchors, corner_ratio, inflection_ratio
        As in :func:`smooth`.
    restrict, tilt, balance_tol, max_passes, min_factor, threads
        As in :func:`smooth`.

    Returns
    -------
    CCAResult

    Examples
    --------
    A nearly straight vertex next to a sharp corner forces a local decrease
    (Fig. 12):

    >>> res = smooth_with_info([[0, 0], [4, 0], [4.0, 1], [2, 1.01], [0, 1]], closed=True)
    >>> res.reductions > 0, res.success
    (True, True)
    """
    return _smooth_one(
        points,
        closed=closed,
        iterations=iterations,
        alpha=alpha,
        anchors=anchors,
        corner_ratio=corner_ratio,
        inflection_ratio=inflection_ratio,
        restrict=restrict,
        tilt=tilt,
        balance_tol=balance_tol,
        max_passes=max_passes,
        min_factor=min_factor,
        threads=threads,
        engine="compiled",
    )


def _smooth_one(
    points,
    *,
    closed,
    iterations,
    alpha,
    anchors,
    corner_ratio,
    inflection_ratio,
    restrict,
    tilt,
    balance_tol,
    max_passes,
    min_factor,
    threads,
    engine,
) -> CCAResult:
    """:func:`smooth_with_info` on the compiled engine or (``engine="numpy"``) the reference."""
    closed = as_bool(closed, name="closed")
    iterations = as_int(iterations, name="iterations", minimum=0)
    c = as_float(corner_ratio, name="corner_ratio", low=1.0)
    C = as_float(inflection_ratio, name="inflection_ratio", low=0.0, high=1.0)
    tilt = as_float(tilt, name="tilt", low=0.0, high=np.pi / 4, high_open=False)
    balance_tol = as_float(balance_tol, name="balance_tol", low=0.0, high=1.0, low_open=False)
    max_passes = as_int(max_passes, name="max_passes", minimum=1)
    min_factor = as_float(min_factor, name="min_factor", low=0.0, high=1.0, low_open=False)
    threads = default_threads() if threads is None else as_int(threads, name="threads", minimum=1)
    alpha_fn = alpha_function(alpha)
    # not copied: nothing below writes into the points (a zero-step call returns a copy)
    given = as_points(points, closed=closed, min_points=1, dim=(2, 3), copy=False)
    if not given.flags.writeable:  # the compiled kernels are typed for writeable arrays
        given = given.copy()
    raw = given
    one = np.array([0, raw.shape[0]], dtype=np.int64)
    # Coordinates so small or so large that squared edge lengths would underflow or overflow
    # are scaled by a power of two (exact) and scaled back at the end; CCA1 commutes with it.
    zero = None  # whether an edge has length 0, from the same pass as the scale (2D)
    if raw.shape[1] == 2 and engine == "compiled":
        tops, zero = _kernel().scan_curves(raw, one, np.array([closed]))
        top = float(tops[0])
    else:
        top = float(np.abs(raw).max())
    exp2 = math.frexp(top)[1] if top > 0 and not _TINY < top < _HUGE else 0
    if exp2:
        raw = np.ldexp(raw, -exp2)
        zero = None  # the scaled points may have other zero-length edges
    n_in = raw.shape[0]
    fixed = np.zeros(n_in, dtype=bool)
    if anchors is not None:
        # a closed ring given with its closing vertex repeated may name that last index
        repeated = closed and np.shape(points)[0] == n_in + 1
        idx = anchor_indices(anchors, n_in + 1 if repeated else n_in)
        fixed[idx % n_in] = True
    if not closed:
        fixed[0] = fixed[-1] = True
    if raw.shape[1] == 2 and raw.shape[0] > 1 and engine == "compiled":
        # the compiled check first: most curves have no duplicates to remove
        if zero is None:
            zero = _kernel().any_zero_edge(raw, one, np.array([closed]), np.zeros((1, 2)))
        if zero:
            p, fixed = dedupe(raw, fixed, closed)
        else:
            p = raw
    else:
        p, fixed = dedupe(raw, fixed, closed)
    need = 3 if closed else 2
    if p.shape[0] < need:
        raise CurveError(
            f"points must have at least {need} distinct points for a "
            f"{'closed polygon' if closed else 'polyline'} after removing consecutive "
            f"duplicates, got {p.shape[0]}"
        )
    # dedupe leaves consecutive vertices distinct, so "all identical" shows in p[0], p[1]
    if closed and not np.any(p[1] != p[0]):
        raise CurveError("points are all identical: a polygon needs non-zero extent")

    if iterations == 0:
        out = np.ldexp(p, exp2) if exp2 else (p.copy() if p is given else p)
        return CCAResult(out, 0, 0, (), 0, 0, True, "0 CCA1 steps: input returned")
    # every step triples the vertex count (closed 3n, open 3n - 3, Fig. 11 edges one more)
    check_growth(p.shape[0], iterations, lambda n: 3 * n, limit=_validate.MAX_VERTICES)
    fixed_in = fixed
    origin = p[0].copy()
    prm = _Params(alpha_fn, restrict, c, C, tilt, balance_tol, max_passes, min_factor, threads)
    offsets = np.array([0, p.shape[0]], dtype=np.int64)
    frame = None
    if p.shape[1] == 2 and engine == "compiled":
        # the kernel subtracts the origin as it reads and adds it back as it writes
        out, fixed, _, steps = _iterate(
            np.ascontiguousarray(p), fixed, offsets, np.array([closed]), iterations, prm,
            engine, origins=origin.reshape(1, 2),
        )  # fmt: skip
    else:
        q = p - origin
        if q.shape[1] == 3:
            frame = plane_frame(q)
            if frame is not None:
                q = q @ frame.T  # (N, 2) coordinates in the plane
        out, fixed, _, steps = _iterate(
            np.ascontiguousarray(q), fixed, offsets, np.array([closed]), iterations, prm, engine
        )
        if frame is not None:
            out = out @ frame
        out += origin
    red_steps = [int(nred[0]) for nred, _, _ in steps]
    fig11_total = sum(int(nfig[0]) for _, nfig, _ in steps)
    unsat_total = sum(int(nunsat[0]) for _, _, nunsat in steps)
    if fixed_in.any():
        out[fixed] = p[fixed_in]  # fixed vertices (ends, anchors) are returned bit-exact
    if exp2:
        np.ldexp(out, exp2, out=out)
    ok = unsat_total == 0
    msg = (
        f"{iterations} CCA1 step(s), {sum(red_steps)} local alpha reduction(s), "
        f"{fig11_total} Fig. 11 edge(s)"
        + ("" if ok else f"; restrictions not met on {unsat_total} edge(s)")
    )
    return CCAResult(
        points=out,
        iterations=iterations,
        reductions=int(sum(red_steps)),
        reductions_per_step=tuple(red_steps),
        fig11_edges=int(fig11_total),
        unsatisfied=int(unsat_total),
        success=ok,
        message=msg,
    )


# --------------------------------------------------------------------------- input helpers


@dataclass(frozen=True)
class RaggedCCAResult(RichRepr):
    """Result of :func:`smooth_ragged_with_info`: a ragged batch and its counts per curve.

    Attributes
    ----------
    coords : (N', 2) ndarray
        The smoothed curves one after the other, rings without a repeated closing
        vertex (as :func:`smooth` returns them).
    offsets : (M + 1,) int64 ndarray
        Curve ``k`` is ``coords[offsets[k]:offsets[k + 1]]``.
    iterations : int
        Number of CCA1 steps performed.
    reductions, fig11_edges, unsatisfied : (M,) int64 ndarray
        Per curve, summed over the steps: as the fields of :class:`CCAResult`.
    success : bool
        Every restriction held on every curve (``unsatisfied`` is all zero).
    message : str
        Human-readable summary.
    """

    coords: np.ndarray
    offsets: np.ndarray
    iterations: int
    reductions: np.ndarray
    fig11_edges: np.ndarray
    unsatisfied: np.ndarray
    success: bool
    message: str

    def curve(self, k: int) -> np.ndarray:
        """The vertices of curve ``k``, ``(n_k, 2)`` (a view)."""
        return self.coords[self.offsets[k] : self.offsets[k + 1]]


def smooth_ragged(
    coords: ArrayLike,
    offsets: ArrayLike,
    *,
    closed: bool | ArrayLike,
    iterations: int = 1,
    alpha: AlphaSpec = "regular",
    anchors: ArrayLike | None = None,
    corner_ratio: float = 2.0,
    inflection_ratio: float = 0.5,
    restrict: bool = True,
    tilt: float = np.pi / 8,
    balance_tol: float = 1e-9,
    max_passes: int = 16,
    min_factor: float = 0.0,
    threads: int | None = None,
    close_rings: bool = False,
) -> tuple[np.ndarray, np.ndarray]:
    """Area-preserving CCA1 smoothing of many 2D curves in one call.

    Every curve gets exactly what :func:`smooth` gives it alone (the same engine,
    curve by curve; the same bits), with every guarantee per curve: each ring's
    area, each open curve's fixed ends and its area against the chord, the
    restrictions and local alpha decreases. The work is one compiled loop over
    all vertices per step, so a batch of many small curves costs about a
    microsecond per curve instead of a millisecond per :func:`smooth` call.

    Parameters
    ----------
    coords : (N, 2) array_like
        All curves one after the other (the layout of
        :func:`shapely.to_ragged_array`, or of ``shapely.get_coordinates``).
        A closed curve may repeat its first vertex at its end (dropped).
    offsets : (M + 1,) array_like of int
        Curve ``k`` is ``coords[offsets[k]:offsets[k + 1]]``; ``offsets[0] == 0``,
        ``offsets[-1] == N``, non-decreasing.
    closed : bool or (M,) array_like of bool
        One flag for all curves or one per curve.
    iterations, alpha, corner_ratio, inflection_ratio, restrict, tilt, balance_tol
        As in :func:`smooth`, the same for every curve.
    max_passes, min_factor
        As in :func:`smooth`, the same for every curve.
    anchors : (N,) bool array_like or sequence of M sequences of int, optional
        Vertices that stay fixed: a mask over the rows of `coords`, or one
        sequence of vertex indices per curve (indices within the curve, as
        :func:`smooth` takes them).
    threads : int, optional
        Threads: a batch of at least 65536 vertices is split into `threads`
        groups of whole curves (long curves in blocks, as in :func:`smooth`; the
        result does not depend on it). Default as in :func:`smooth`.
    close_rings : bool, optional
        Repeat the first vertex of every closed curve at its end in the output
        (the layout of :func:`shapely.from_ragged_array`); default: not repeated,
        as :func:`smooth` returns rings.

    Returns
    -------
    coords : (N', 2) ndarray
        The smoothed curves one after the other (rings closed only with
        `close_rings`).
    offsets : (M + 1,) int64 ndarray
        The curves of the output.

    Raises
    ------
    CurveError
        Bad shapes or values; a curve with fewer than 3 (closed) or 2 (open)
        distinct points (the message names the curve).

    Examples
    --------
    A square ring and an open zigzag in one call:

    >>> xy = [[0, 0], [1, 0], [1, 1], [0, 1], [0, 0], [0, 0], [1, 1], [2, 0], [3, 1]]
    >>> out, off = smooth_ragged(xy, [0, 5, 9], closed=[True, False], iterations=2)
    >>> off.tolist()
    [0, 36, 64]
    >>> from curvesmith.geometry import signed_area
    >>> round(signed_area(out[off[0] : off[1]]), 12)
    1.0
    >>> out[off[1]].tolist(), out[off[2] - 1].tolist()  # open ends fixed
    ([0.0, 0.0], [3.0, 1.0])
    """
    res = smooth_ragged_with_info(
        coords,
        offsets,
        closed=closed,
        iterations=iterations,
        alpha=alpha,
        anchors=anchors,
        corner_ratio=corner_ratio,
        inflection_ratio=inflection_ratio,
        restrict=restrict,
        tilt=tilt,
        balance_tol=balance_tol,
        max_passes=max_passes,
        min_factor=min_factor,
        threads=threads,
        close_rings=close_rings,
    )
    return res.coords, res.offsets


def smooth_ragged_with_info(
    coords: ArrayLike,
    offsets: ArrayLike,
    *,
    closed: bool | ArrayLike,
    iterations: int = 1,
    alpha: AlphaSpec = "regular",
    anchors: ArrayLike | None = None,
    corner_ratio: float = 2.0,
    inflection_ratio: float = 0.5,
    restrict: bool = True,
    tilt: float = np.pi / 8,
    balance_tol: float = 1e-9,
    max_passes: int = 16,
    min_factor: float = 0.0,
    threads: int | None = None,
    close_rings: bool = False,
) -> RaggedCCAResult:
    """Like :func:`smooth_ragged`, returning a :class:`RaggedCCAResult` with counts per curve.

    Parameters
    ----------
    coords, offsets, closed, iterations, alpha, anchors, corner_ratio, inflection_ratio
        As in :func:`smooth_ragged`.
    restrict, tilt
        As in :func:`smooth_ragged`.
    balance_tol, max_passes, min_factor, threads, close_rings
        As in :func:`smooth_ragged`.

    Returns
    -------
    RaggedCCAResult

    Examples
    --------
    >>> xy = [[0, 0], [4, 0], [4.0, 1], [2, 1.01], [0, 1], [0, 0], [1, 0], [1, 1]]
    >>> res = smooth_ragged_with_info(xy, [0, 5, 8], closed=True)
    >>> res.reductions.tolist(), res.success
    ([3, 0], True)
    """
    iterations = as_int(iterations, name="iterations", minimum=0)
    c = as_float(corner_ratio, name="corner_ratio", low=1.0)
    C = as_float(inflection_ratio, name="inflection_ratio", low=0.0, high=1.0)
    tilt = as_float(tilt, name="tilt", low=0.0, high=np.pi / 4, high_open=False)
    balance_tol = as_float(balance_tol, name="balance_tol", low=0.0, high=1.0, low_open=False)
    max_passes = as_int(max_passes, name="max_passes", minimum=1)
    min_factor = as_float(min_factor, name="min_factor", low=0.0, high=1.0, low_open=False)
    restrict = as_bool(restrict, name="restrict")
    close_rings = as_bool(close_rings, name="close_rings")
    threads = default_threads() if threads is None else as_int(threads, name="threads", minimum=1)
    alpha_fn = alpha_function(alpha)
    rag = as_ragged(coords, offsets, closed=closed, dim=2, compiled=True)
    p, off, cl = rag.points, rag.offsets, rag.closed
    m = cl.size
    lengths = np.diff(off)
    fixed = np.zeros(p.shape[0], dtype=bool)
    if anchors is not None:
        fixed = as_anchor_mask(anchors, rag)
    nonempty = lengths > 0
    opened = ~cl & nonempty
    fixed[off[:-1][opened]] = True
    fixed[off[1:][opened] - 1] = True
    kernel = _kernel()
    # per-curve power-of-two scaling of extreme coordinate scales (see smooth_with_info)
    exp2 = np.zeros(m, dtype=np.int64)
    zero = False  # whether some edge has length 0: duplicates to remove
    if p.shape[0]:
        top, zero = kernel.scan_curves(p, off, cl)  # one pass for the scale and the check
        extreme = (top > 0) & ~((top > _TINY) & (top < _HUGE))
        if extreme.any():
            exp2[extreme] = np.frexp(top[extreme])[1]
            p = np.ldexp(p, -exp2[curve_ids(off)][:, None])
            zero = kernel.any_zero_edge(p, off, cl, np.zeros((m, 2)))  # of the scaled points
    if zero:
        p, fixed, off = dedupe_ragged(p, fixed, off, cl)
    lengths = np.diff(off)
    need = np.where(cl, 3, 2)
    short = np.flatnonzero(lengths < need)
    if short.size:
        k = int(short[0])
        raise CurveError(
            f"coords must have at least {need[k]} distinct points per "
            f"{'closed polygon' if cl[k] else 'polyline'} after removing consecutive "
            f"duplicates, got {int(lengths[k])} for curve {k}"
        )
    starts = off[:-1]
    if m and cl.any():
        flat = cl & np.all(p[starts + 1] == p[starts], axis=1)
        if flat.any():
            raise CurveError(
                f"coords of curve {int(np.flatnonzero(flat)[0])} are all identical: "
                "a polygon needs non-zero extent"
            )
    zeros = np.zeros(m, dtype=np.int64)
    if iterations == 0 or m == 0:
        out = p.copy()
        if exp2.any():
            out = np.ldexp(out, exp2[curve_ids(off)][:, None])
        if close_rings:
            out, off = close_curves(out, off, cl)
        return RaggedCCAResult(out, off, 0, zeros, zeros.copy(), zeros.copy(), True, "0 CCA1 steps")
    check_growth(p.shape[0], iterations, lambda n: 3 * n, limit=_validate.MAX_VERTICES)
    fixed_in = fixed
    origin = np.zeros((m, 2))  # every curve in the frame of its first vertex
    origin[lengths > 0] = p[off[:-1][lengths > 0]]
    prm = _Params(alpha_fn, restrict, c, C, tilt, balance_tol, max_passes, min_factor, threads)
    out, fixed, off_out, steps = _iterate(
        np.ascontiguousarray(p), fixed, off, cl, iterations, prm, "compiled",
        close_out=close_rings, origins=origin,
    )  # fmt: skip
    if fixed_in.any():
        cid_out = curve_ids(off_out)
        _restore_fixed(out, fixed, cid_out, p, fixed_in, curve_ids(off), off_out, off)
    if exp2.any():
        out = np.ldexp(out, exp2[curve_ids(off_out)][:, None])
    if close_rings and (fixed_in.any() or exp2.any()):
        # the closing vertex is the first one, bit for bit (the kernel wrote it as a copy
        # of the first; restoring fixed vertices or the scale may have changed that one)
        out[off_out[1:][cl] - 1] = out[off_out[:-1][cl]]
    red = np.sum([s[0] for s in steps], axis=0)
    fig = np.sum([s[1] for s in steps], axis=0)
    uns = np.sum([s[2] for s in steps], axis=0)
    ok = not uns.any()
    msg = (
        f"{iterations} CCA1 step(s) on {m} curve(s), {int(red.sum())} local alpha "
        f"reduction(s), {int(fig.sum())} Fig. 11 edge(s)"
        + ("" if ok else f"; restrictions not met on {int(uns.sum())} edge(s)")
    )
    return RaggedCCAResult(out, off_out, iterations, red, fig, uns, ok, msg)


def _restore_fixed(out, fixed, cid_out, p, fixed_in, cid, off_out, off):
    """Fixed vertices (ends, anchors) bit-exact from the input, curve by curve."""
    m = off.size - 1
    n_out = np.bincount(cid_out[fixed], minlength=m)
    n_in = np.bincount(cid[fixed_in], minlength=m)
    if np.array_equal(n_out, n_in):
        out[fixed] = p[fixed_in]
        return
    for k in np.flatnonzero(n_out == n_in):  # pragma: no cover - fixed vertices never merge
        a, b = off_out[k], off_out[k + 1]
        out[a:b][fixed[a:b]] = p[off[k] : off[k + 1]][fixed_in[off[k] : off[k + 1]]]


# --------------------------------------------------------------------------- the engine


@dataclass(frozen=True)
class _Params:
    alpha_fn: Callable
    restrict: bool
    c: float
    C: float
    tilt: float
    balance_tol: float
    max_passes: int
    min_factor: float
    threads: int


def _iterate(
    P, fixed, offsets, closed, iterations, prm: _Params, engine: str, close_out=False, origins=None
):
    """``iterations`` CCA1 steps on a batch of ``(N, d)`` points.

    Returns the points, their fixed mask, the offsets and the per-step counts; with
    ``close_out`` (compiled engine) the last step repeats the first vertex of every ring.
    With ``origins`` ``(M, 2)`` (compiled engine, 2D) the points are in the input's frame:
    the first step reads every curve minus its origin and the last one adds it back as it
    writes (the same bits as subtracting before and adding after, with no extra passes).
    """
    steps = []
    for it in range(1, iterations + 1):
        tilt_n = prm.tilt / 2.0**it
        if P.shape[1] != 2 or engine == "numpy":
            P, fixed, offsets, counts = _step_numpy(P, fixed, offsets, closed, prm, tilt_n)
        else:
            last = it == iterations
            P, fixed, offsets, counts = _step_compiled(
                P, fixed, offsets, closed, prm, tilt_n, close_out and last,
                origins if it == 1 else None, origins if last else None,
            )  # fmt: skip
        steps.append(counts)
    return P, fixed, offsets, steps


def _step_numpy(P, fixed, offsets, closed, prm: _Params, tilt_n):
    """The reference: the N-d numpy step curve by curve."""
    m = offsets.size - 1
    outs, fixes, lens = [], [], []
    counts = np.zeros((3, m), dtype=np.int64)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        for k in range(m):
            a, b = offsets[k], offsets[k + 1]
            piece, f, nred, nfig, nunsat = _stepnd.step(
                [np.ascontiguousarray(P[a:b, d]) for d in range(P.shape[1])],
                fixed[a:b],
                bool(closed[k]),
                prm.alpha_fn,
                prm.restrict,
                prm.c,
                prm.C,
                tilt_n,
                prm.balance_tol,
                (prm.max_passes, prm.min_factor),
            )
            outs.append(np.column_stack(piece))
            fixes.append(f)
            lens.append(f.size)
            counts[:, k] = nred, nfig, nunsat
    new_off = np.zeros(m + 1, dtype=np.int64)
    np.cumsum(lens, out=new_off[1:])
    return np.concatenate(outs), np.concatenate(fixes), new_off, tuple(counts)


def _kernel():
    from . import _kernel as kernel  # numba loads (and compiles, once) on first use

    return kernel


def _step_compiled(
    P, fixed, offsets, closed, prm: _Params, tilt_n, close_out=False, org_in=None, org_out=None
):
    """One compiled step; ``org_in`` / ``org_out`` (M, 2): origins subtracted / added."""
    kernel = _kernel()
    brk, coef = profile_tables()
    m = offsets.size - 1
    constant = getattr(prm.alpha_fn, "constant", None)
    alpha_in = np.zeros(0)
    if prm.alpha_fn is _profiles_eval:
        mode, const = kernel.MODE_REGULAR, 0.0
    elif constant is not None:
        mode, const = kernel.MODE_CONSTANT, float(constant)
    else:
        mode, const = kernel.MODE_GIVEN, 0.0
    halo = prm.max_passes + 8
    # a curve of 2 * BLOCK vertices needs a batch of as many (one subtraction for most calls)
    blocked = offsets[-1] >= 2 * BLOCK and 4 * halo <= BLOCK and np.diff(offsets).max() >= 2 * BLOCK
    if org_in is None:
        org_in = np.zeros((m, 2))
    # the angles of a callable need the curves compacted, in their frames; otherwise the
    # step compacts a curve with a zero-length edge itself (a block that meets one makes
    # _run_units give up: the whole curves run then), so no pass looks for them here
    if mode == kernel.MODE_GIVEN and org_in.any():
        Q = np.empty_like(P)
        kernel.to_local(P, offsets, Q)
        P, org_in = Q, np.zeros((m, 2))
    if mode == kernel.MODE_GIVEN:  # the angles of the compacted curves, in one call
        if kernel.any_zero_edge(P, offsets, closed, org_in):
            P, fixed, offsets = kernel.compact_ragged(P, fixed, offsets, closed)
        theta = kernel.angles_ragged(P, offsets, closed)
        free = ~fixed
        opened = ~closed & (np.diff(offsets) > 0)
        free[offsets[:-1][opened]] = False
        free[offsets[1:][opened] - 1] = False
        alpha_in = np.zeros(P.shape[0])
        alpha_in[free] = prm.alpha_fn(theta[free])
    params = (
        mode, const, brk, coef, prm.restrict, prm.c, prm.C, tilt_n, prm.balance_tol,
        prm.max_passes, prm.min_factor,
    )  # fmt: skip
    add = org_out is not None
    org_out = org_out if add else org_in
    run = (P, fixed, alpha_in, org_in, org_out, offsets, closed, params, close_out, add, prm)
    if blocked:
        res = _run_units(kernel, *run, _blocks(offsets, closed, halo))
        if res is not None:
            return res
    return _run_units(kernel, *run, None)


def _units(offsets, closed, blocks):
    """The unit table of :func:`curvesmith.cca._kernel.step_units` and the units' owners.

    Without ``blocks`` the units are the curves (:func:`~curvesmith.cca._kernel.curve_units`,
    one compiled call instead of a dozen small numpy ones: a step of one small polygon
    is mostly such overhead).
    """
    K = _kernel()
    if blocks is None:
        return K.curve_units(offsets, closed), np.arange(offsets.size - 1, dtype=np.int64)
    lengths = np.diff(offsets)
    start, u_off, ucl, core, owner = blocks
    ulen = np.diff(u_off)
    first = np.ones(owner.size, dtype=bool)
    first[1:] = owner[1:] != owner[:-1]
    last = np.ones(owner.size, dtype=bool)
    last[:-1] = owner[1:] != owner[:-1]
    flags = (
        ucl * K.U_CLOSED + first * K.U_FIRST + last * K.U_LAST + closed[owner] * K.U_RING
    ).astype(np.int64)
    table = np.stack(
        [owner, offsets[:-1][owner], lengths[owner], start, ulen, core[:, 0], core[:, 1], flags],
        axis=1,
    ).astype(np.int64)
    return table, owner


def _run_units(kernel, P, fixed, alpha_in, org_in, org_out, offsets, closed, params, close_out,
               add, prm, blocks):  # fmt: skip
    """Run the kernel over units (whole curves, or blocks of long curves), in threads.

    Without ``blocks`` the units are the curves. With ``blocks`` (from :func:`_blocks`)
    the units are blocks with cores, whose outputs the kernel writes one after the
    other; returns None if a block met a zero-length edge (its own wrap edge: the ring
    passes twice through one point), then the caller runs the whole curves.

    The groups of units (one per thread) write into one buffer: every group but the
    last gets exactly the rows it needs when each core vertex gives its two cut points
    and its edge one apex (the common case), so the next group starts right after them
    and no row moves. A group that needs more rows (Fig. 11 edges) stops at the unit
    that does not fit and its other units run into a buffer of their own (copied in
    once the rows of the next groups made room, in place as long as the last group's
    spare rows hold them); a group that needs fewer (fixed vertices, compacted
    duplicates) leaves a gap, and the rows after it move to earlier rows.
    """
    units, owner = _units(offsets, closed, blocks)
    m = offsets.size - 1
    if blocks is None:
        u_off = offsets  # the units are the curves
    else:
        u_off = np.zeros(units.shape[0] + 1, dtype=np.int64)
        np.cumsum(units[:, 4], out=u_off[1:])
    chunks = _chunks(u_off, prm.threads)
    core = units[:, 6] - units[:, 5]
    flags = units[:, 7]
    first = None  # the one group's result, when there is one group
    if len(chunks) == 1:
        # one group (most calls): a buffer of the common case's rows plus room for some
        # Fig. 11 pairs, and the kernel's output returned as it is; when more Fig. 11
        # pairs need more rows, the units that did not fit run on below (step)
        ncore = int(offsets[-1]) if blocks is None else int(core.sum())
        caps = [3 * ncore + ncore // 16 + units.shape[0] + 64]
        OUT, of = output_buffers(caps[0])
        first = kernel.step_units(
            P, fixed, alpha_in, org_in, org_out, units, *params, OUT, of, close_out, add
        )
        if first[7] == kernel.ZERO_EDGE:
            return None
        if first[7] == kernel.DONE:
            R, rf, pos, span = first[:4]
            counts = list(first[4:7])
            if blocks is not None:
                counts = [
                    np.bincount(owner, weights=c, minlength=m).astype(np.int64) for c in counts
                ]
                span = span[(flags & kernel.U_LAST) != 0]
            oo = np.zeros(m + 1, dtype=np.int64)
            oo[1:] = span[:, 1]
            return R[:pos], rf[:pos], oo, tuple(counts)
    else:
        ncore = [int(core[a:b].sum()) for a, b in chunks]
        # the rows of the common case: 3 per core vertex, 1 less per fixed vertex (it is
        # kept) and per open end (no wrap edge), 1 more per ring closed in the group; the
        # last group also some Fig. 11 pairs
        caps = [3 * ncore[-1] + ncore[-1] // 16 + (chunks[-1][1] - chunks[-1][0]) + 64]
        row0 = units[:, 1] + units[:, 3] + units[:, 5]  # first row of every core in P
        nfix = np.zeros(units.shape[0] + 1, dtype=np.int64)
        if fixed.any():
            nfix = np.concatenate([[0], np.cumsum(fixed)])[np.append(row0, P.shape[0])]
        opened = ((flags & kernel.U_LAST) != 0) & ((flags & kernel.U_RING) == 0) & (core > 0)
        ring_end = ((flags & kernel.U_LAST) != 0) & ((flags & kernel.U_RING) != 0)
        rows = []
        for g, (a, b) in enumerate(chunks[:-1]):
            rows.append(3 * ncore[g] - int(nfix[b] - nfix[a]) - int(opened[a:b].sum()))
            if close_out:
                rows[-1] += int(ring_end[a:b].sum())
        caps = rows + caps
        # one buffer: every group writes into its own slice of it
        OUT, of = output_buffers(int(sum(caps)))
    base = np.zeros(len(chunks) + 1, dtype=np.int64)
    np.cumsum(caps, out=base[1:])

    def step(g, res=None):
        """Parts ``(result, first unit, end unit, base row or -1: a buffer of its own)``.

        ``res``: the group's kernel result when it ran already.
        """
        a, b = chunks[g]
        args = (P, fixed, alpha_in, org_in, org_out)
        s, e = base[g], base[g + 1]
        if res is None:
            res = kernel.step_units(*args, units[a:b], *params, OUT[s:e], of[s:e], close_out, add)
        if res[7] != kernel.FULL:
            return [(res, a, b, s)]
        done = a + res[2]
        # the units that did not fit: at most 4 points per vertex, a buffer of their own
        cap = 4 * int(core[done:b].sum()) + (b - done) + 1
        rest = kernel.step_units(
            *args, units[done:b], *params, *output_buffers(cap), close_out, add
        )
        cut = done - a
        rows = int(res[3][cut - 1, 1]) if cut else 0
        head = (res[0], res[1], rows, res[3][:cut], *(c[:cut] for c in res[4:7]), kernel.DONE)
        return [(head, a, done, s), (rest, done, b, -1)]

    if len(chunks) == 1:
        parts = step(0, first)
    else:
        with ThreadPoolExecutor(len(chunks)) as pool:
            parts = [q for qs in pool.map(step, range(len(chunks))) for q in qs]
    if any(r[7] == kernel.ZERO_EDGE for r, *_ in parts):
        return None
    counts = [np.concatenate([r[k] for r, *_ in parts]) for k in (4, 5, 6)]
    if blocks is not None:
        counts = [np.bincount(owner, weights=c, minlength=m).astype(np.int64) for c in counts]
    is_last = (flags & kernel.U_LAST) != 0
    oo = np.zeros(m + 1, dtype=np.int64)
    if len(parts) == 1:
        R, rf, pos, span = parts[0][0][:4]
        oo[1:] = span[is_last, 1]
        return R[:pos], rf[:pos], oo, tuple(counts)
    # the parts' outputs one after the other
    span = np.concatenate([r[3] for r, *_ in parts])
    lens = span[:, 1] - span[:, 0]
    dest = np.zeros(lens.size + 1, dtype=np.int64)
    np.cumsum(lens, out=dest[1:])
    total = int(dest[-1])
    if total <= OUT.shape[0]:
        # in place: the parts in OUT whose rows move to earlier rows, front to back; those
        # whose rows move to later ones (after a part whose rest had a buffer of its own),
        # back to front: none overwrites rows not yet moved. Then the rests are copied in.
        shift = [int(dest[a] - s - r[3][0, 0]) if a < b else 0 for r, a, b, s in parts]
        for (r, a, b, s), d in zip(parts, shift, strict=True):
            if s >= 0 and d < 0:
                kernel.move_rows(OUT, of, OUT, of, r[3] + s, dest[a:b])
        for (r, a, b, s), d in zip(parts[::-1], shift[::-1], strict=True):
            if s >= 0 and d > 0:
                kernel.move_rows_back(OUT, of, r[3] + s, dest[a:b])
        for r, a, b, s in parts:
            if s < 0:
                kernel.move_rows(r[0], r[1], OUT, of, r[3], dest[a:b])
        R, rf = OUT[:total], of[:total]
    else:
        R, rf = np.empty((total, 2)), np.empty(total, dtype=bool)
        for r, a, b, _ in parts:
            kernel.move_rows(r[0], r[1], R, rf, r[3], dest[a:b])
    if close_out:
        # a ring whose units are in two parts: the part of its last unit left the row of
        # its closing vertex empty
        first_u = np.flatnonzero((flags & kernel.U_FIRST) != 0)
        part = np.zeros(units.shape[0], dtype=np.int64)
        for q, (_, a, _, _) in enumerate(parts[1:], start=1):
            part[a:] = q
        split = is_last & ((flags & kernel.U_RING) != 0)
        u = np.flatnonzero(split & (part != part[first_u[owner]]))
        at = dest[u] + lens[u] - 1
        R[at] = R[dest[first_u[owner[u]]]]
        rf[at] = False
    oo[1:] = dest[1:][is_last]
    return R, rf, oo, tuple(counts)


def output_buffers(cap: int):
    """Output buffers of the kernel (numpy's allocator: huge pages for large ones)."""
    return np.empty((cap, 2)), np.empty(cap, dtype=bool)


def _blocks(offsets: np.ndarray, closed: np.ndarray, halo: int):
    """Units for :func:`_run_units`: short curves whole, long ones in blocks with halos.

    CCA1 is local: the output of vertex ``i`` (its cut points and the apex on edge
    ``i``) depends on vertices ``i - 1 .. i + 2`` and on the local alpha decreases,
    and each restriction pass moves a decrease by at most one vertex. So a curve of
    at least ``2 * BLOCK`` vertices is cut into blocks of ``BLOCK`` core vertices,
    each computed with ``halo = max_passes + 8`` vertices on both sides (a block is
    smoothed as a closed curve; its own wrap edge, not an edge of the curve, disturbs
    only the halo; the last block of an open curve stays open at the true end). The
    values are computed by the same arithmetic as for the whole curve, so the result
    is the same to the last bit, and long curves can use ``threads`` threads. A block
    stays in the cache while its steps run over it.

    Returns, per unit, its first vertex relative to its curve's first row (negative
    for the first block of a ring: it wraps around), the units' offsets (their
    lengths), closed flags, cores ``(U, 2)`` and owner curves.
    """
    lengths = np.diff(offsets)
    long = np.flatnonzero(lengths >= 2 * BLOCK)
    u_start, u_len, u_closed, core, owner = [], [], [], [], []
    prev = 0  # first curve not yet listed
    for k in [*long.tolist(), lengths.size]:
        if k > prev:  # the short curves before k: whole units
            sl = lengths[prev:k]
            u_start.append(np.zeros_like(sl))
            u_len.append(sl)
            u_closed.append(closed[prev:k])
            core.append(np.stack([np.zeros_like(sl), sl], axis=1))
            owner.append(np.arange(prev, k))
        if k == lengths.size:
            break
        n = int(lengths[k])
        bs, bl, bc, bcore = [], [], [], []
        for s in range(0, n, BLOCK):
            e = min(n, s + BLOCK)
            if closed[k]:
                lo, hi = s - halo, e + halo
                c = (halo, halo + e - s)
                piece_closed = True
            else:
                lo, hi = max(0, s - halo), min(n, e + halo)
                c = (s - lo, e - lo)
                piece_closed = hi < n  # the true end of an open curve stays open
            bs.append(lo)
            bl.append(hi - lo)
            bc.append(piece_closed)
            bcore.append(c)
        u_start.append(np.array(bs))
        u_len.append(np.array(bl))
        u_closed.append(np.array(bc, dtype=bool))
        core.append(np.array(bcore, dtype=np.int64))
        owner.append(np.full(len(bl), k))
        prev = k + 1
    lens = np.concatenate(u_len).astype(np.int64)
    u_off = np.zeros(lens.size + 1, dtype=np.int64)
    np.cumsum(lens, out=u_off[1:])
    return (
        np.concatenate(u_start).astype(np.int64),
        u_off,
        np.concatenate(u_closed).astype(bool),
        np.concatenate(core).astype(np.int64).reshape(-1, 2),
        np.concatenate(owner).astype(np.int64),
    )


def _chunks(offsets: np.ndarray, threads: int) -> list[tuple[int, int]]:
    """Groups of whole curves with about equal vertex counts, one per thread."""
    m = offsets.size - 1
    n = int(offsets[-1])
    if threads <= 1 or n < THREAD_MIN or m < 2:
        return [(0, m)]
    cuts = np.searchsorted(offsets, np.linspace(0, n, threads + 1)[1:-1])
    bounds = np.unique(np.concatenate([[0], np.clip(cuts, 1, m - 1), [m]]))
    return [(int(a), int(b)) for a, b in itertools.pairwise(bounds)]
