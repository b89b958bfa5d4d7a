"""Ragged batches of curves: one coordinate array plus offsets.

The layout of :func:`shapely.to_ragged_array` and of
``shapely.get_coordinates`` with offsets: curve ``k`` is the rows
``offsets[k] .. offsets[k + 1] - 1`` of an ``(N, d)`` coordinate array,
``offsets`` has ``M + 1`` entries starting at 0 and ending at ``N``. Closed
curves may repeat their first vertex at the end (the ring convention of
shapely and GeoJSON); it is dropped, as the single-curve functions do.
"""

from __future__ import annotations

import numpy as np

from ._validate import as_points
from .errors import CurveError

__all__ = ["RaggedInput", "as_anchor_mask", "as_ragged", "close_curves", "curve_ids"]

#: Rows from which :func:`as_ragged`, asked for ``compiled``, drops the closing vertices
#: in a compiled pass: 20,000 footprints (190,000 rows) 0.4 ms against numpy's 4-5 ms.
COMPILED_MIN = 1 << 15


class RaggedInput:
    """Validated ragged input (internal).

    Attributes: ``points`` (N, d) without repeated closing vertices, ``offsets``
    (M + 1,) int64, ``closed`` (M,) bool, ``kept`` (N_in,) bool (rows of the input
    kept) and ``dropped_to`` (rows of the input that were dropped closing vertices
    -> index of their curve's first row in the input).
    """

    __slots__ = ("closed", "dropped", "kept", "offsets", "offsets_in", "points")

    def __init__(self, points, offsets, closed, kept, dropped, offsets_in):
        self.points = points
        self.offsets = offsets
        self.closed = closed
        self.kept = kept
        self.dropped = dropped
        self.offsets_in = offsets_in


def curve_ids(offsets: np.ndarray) -> np.ndarray:
    """Curve index of every row: ``(N,)`` int64."""
    return np.repeat(np.arange(offsets.shape[0] - 1, dtype=np.int64), np.diff(offsets))


def _as_offsets(offsets, n: int, name: str = "offsets") -> np.ndarray:
    try:
        off = np.asarray(offsets)
    except (TypeError, ValueError):
        raise CurveError(f"{name} must be a 1-D array of integers, got {offsets!r}") from None
    if off.ndim != 1 or off.size < 1:
        raise CurveError(f"{name} must be a 1-D array of M + 1 integers, got shape {off.shape}")
    integral = np.issubdtype(off.dtype, np.integer) or (
        np.issubdtype(off.dtype, np.floating) and bool(np.all(np.mod(off, 1) == 0))
    )
    if not integral:
        raise CurveError(f"{name} must hold integers, got dtype {off.dtype}")
    off = off.astype(np.int64)
    if off[0] != 0 or off[-1] != n:
        raise CurveError(
            f"{name} must start at 0 and end at the number of coordinates {n}, "
            f"got {int(off[0])} .. {int(off[-1])}"
        )
    if off.size > 1 and np.any(np.diff(off) < 0):
        k = int(np.flatnonzero(np.diff(off) < 0)[0])
        raise CurveError(
            f"{name} must be non-decreasing, got {int(off[k])} before {int(off[k + 1])}"
        )
    return off


def as_ragged(
    coords, offsets, *, closed, dim=2, name: str = "coords", compiled: bool = False
) -> RaggedInput:
    """Validate a ragged batch; drop the repeated closing vertex of every closed curve.

    ``compiled``: a caller that runs numba kernels anyway lets a large batch drop them in
    a compiled pass (the same arrays, bit for bit).
    """
    p = as_points(coords, name=name, min_points=0, dim=dim)
    off = _as_offsets(offsets, p.shape[0])
    m = off.shape[0] - 1
    cl = np.asarray(closed)
    if cl.dtype != np.bool_:
        raise CurveError(f"closed must be True, False or an array of M bools, got {closed!r}")
    if cl.ndim == 0:
        cl = np.full(m, bool(cl))
    elif cl.shape != (m,):
        raise CurveError(f"closed must have shape ({m},) (one flag per curve), got {cl.shape}")
    if compiled and p.shape[0] >= COMPILED_MIN:  # one pass, not numpy's masks and copies
        from ._ragged_kernel import drop_closing

        p_in = p
        p, new_off, kept, rep = drop_closing(np.ascontiguousarray(p), off, cl)
        if p.shape[0] == p_in.shape[0]:
            p = p_in  # nothing dropped: the input array, as below
        return RaggedInput(p, new_off, cl.copy(), kept, np.flatnonzero(rep), off)
    lengths = np.diff(off)
    last = off[1:] - 1
    rep = cl & (lengths >= 2)
    if rep.any():
        k = np.flatnonzero(rep)
        rep[k] = np.all(p[off[k]] == p[last[k]], axis=1)
    kept = np.ones(p.shape[0], dtype=bool)
    dropped = np.flatnonzero(rep)
    if dropped.size:
        kept[last[dropped]] = False
        p = p[kept]
        off = off.copy()
        off[1:] -= np.cumsum(rep)
    return RaggedInput(p, off, cl.copy(), kept, dropped, _as_offsets(offsets, kept.size))


def close_curves(xy: np.ndarray, off: np.ndarray, closed: np.ndarray):
    """Every closed non-empty curve with its first row repeated at its end (ring layout)."""
    add = closed & (np.diff(off) > 0)
    new_off = np.zeros(off.size, dtype=np.int64)
    np.cumsum(np.diff(off) + add, out=new_off[1:])
    out = np.empty((int(new_off[-1]), xy.shape[1]))
    rows = np.arange(xy.shape[0]) + np.repeat(np.cumsum(add) - add, np.diff(off))
    out[rows] = xy
    out[new_off[1:][add] - 1] = xy[off[:-1][add]]
    return out, new_off


def as_anchor_mask(anchors, rag: RaggedInput) -> np.ndarray:
    """Anchors as a fixed mask over the kept rows.

    ``anchors`` is a boolean mask over the input rows, or a sequence of one sequence
    of vertex indices per curve (indices in the curve, as the single-curve functions
    take them; a ring given with its closing vertex repeated may name that index).
    """
    n_in = rag.kept.size
    m = rag.closed.size
    off_in = rag.offsets_in
    arr = None
    try:
        arr = np.asarray(anchors)
    except (TypeError, ValueError):
        arr = None  # ragged nested lists
    if arr is not None and arr.dtype == np.bool_:
        if arr.shape != (n_in,):
            raise CurveError(
                f"anchors must be a boolean mask of shape ({n_in},) or one index sequence "
                f"per curve, got a mask of shape {arr.shape}"
            )
        mask = arr.copy()
    else:
        try:
            per_curve = list(anchors)
        except TypeError:
            raise CurveError(
                f"anchors must be a boolean mask or one index sequence per curve, got {anchors!r}"
            ) from None
        if len(per_curve) != m:
            raise CurveError(
                f"anchors must hold one index sequence per curve ({m}), got {len(per_curve)}"
            )
        from .cca._input import anchor_indices

        mask = np.zeros(n_in, dtype=bool)
        lengths = np.diff(off_in)
        for k, idx in enumerate(per_curve):
            if idx is None or len(idx) == 0:
                continue
            try:
                loc = anchor_indices(idx, int(lengths[k]))
            except CurveError as exc:
                raise CurveError(f"{exc} (curve {k})") from None
            mask[off_in[k] + loc] = True
    if rag.dropped.size:  # a dropped closing vertex is the first vertex again
        last = off_in[1:][rag.dropped] - 1
        mask[off_in[rag.dropped]] |= mask[last]
    return mask[rag.kept]
