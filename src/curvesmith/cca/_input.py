"""Input handling of CCA1: duplicates, anchors, the plane of 3D input, default threads."""

from __future__ import annotations

import os

import numpy as np

from ..errors import CurveError
from ..geometry import principal_axes


def default_threads() -> int:
    """Processors available to this process, at most 4 and at most ``OMP_NUM_THREADS``.

    The environment cap follows the convention of numerical libraries (Dask's
    worker processes set ``OMP_NUM_THREADS=1``), so a parallel caller does not
    get threads inside each of its workers.
    """
    try:
        available = len(os.sched_getaffinity(0))
    except (AttributeError, OSError):  # not on Linux
        available = os.cpu_count() or 1
    cap = os.environ.get("OMP_NUM_THREADS", "").strip()
    if cap.isdigit() and int(cap) >= 1:
        available = min(available, int(cap))
    return max(1, min(4, available))


def anchor_indices(anchors, n: int) -> np.ndarray:
    try:
        idx = np.asarray(anchors)
    except (TypeError, ValueError):
        raise CurveError(f"anchors must be a sequence of vertex indices, got {anchors!r}") from None
    idx = idx.reshape(-1)
    if idx.size and not (
        np.issubdtype(idx.dtype, np.integer)
        or (np.issubdtype(idx.dtype, np.floating) and np.all(np.mod(idx, 1) == 0))
    ):
        raise CurveError(f"anchors must be integer vertex indices, got {anchors!r}")
    idx = idx.astype(np.intp)
    bad = (idx < 0) | (idx >= n)
    if bad.any():
        raise CurveError(f"anchors must be vertex indices in [0, {n}), got {int(idx[bad][0])}")
    return idx


def zero_gap(d: np.ndarray) -> np.ndarray:
    """Rows of differences whose squared length is 0 as the steps compute it.

    True for equal points and for points so close that every squared component
    underflows (``|d| < 1.5e-162``): the step would see a zero-length edge, so
    both count as duplicates (otherwise compacting could not remove the edge).
    """
    return ~np.any(d * d > 0, axis=1)


def dedupe(p: np.ndarray, fixed: np.ndarray, closed: bool) -> tuple[np.ndarray, np.ndarray]:
    same = zero_gap(p[1:] - p[:-1])
    if closed and p.shape[0] > 1:
        # drop trailing copies of the first vertex too
        tail = zero_gap(p - p[0])
        tail[0] = False
        k = p.shape[0]
        while k > 1 and tail[k - 1]:
            k -= 1
        if k < p.shape[0]:
            fixed = fixed.copy()
            fixed[0] |= fixed[k:].any()
            p, fixed = p[:k], fixed[:k]
            same = same[: k - 1]
    if not same.any():
        return p, fixed
    keep = np.ones(p.shape[0], dtype=bool)
    keep[1:] = ~same
    group = np.cumsum(keep) - 1
    newfixed = np.zeros(int(group[-1]) + 1, dtype=bool)
    np.logical_or.at(newfixed, group, fixed)
    return p[keep], newfixed


def plane_frame(q: np.ndarray) -> np.ndarray | None:
    """Orthonormal (2, 3) in-plane frame if the 3D points are planar to rounding, else None."""
    centre, _, vt = principal_axes(q)
    centred = q - centre
    extent = float(np.max(np.abs(centred))) if centred.size else 0.0
    if extent == 0.0:
        return vt[:2].copy()
    dist = np.abs(centred @ vt[2])
    if float(dist.max()) <= 64.0 * np.finfo(float).eps * extent:
        return vt[:2].copy()
    return None


# --------------------------------------------------------------------------- the CCA1 step


def dedupe_ragged(
    p: np.ndarray, fixed: np.ndarray, offsets: np.ndarray, closed: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`dedupe` on every curve of a ragged batch at once (no loop per curve).

    Returns the kept points, their fixed mask and the new offsets. The same rules per
    curve: trailing copies of a ring's first vertex go first (their fixed flags move to
    the first vertex), then every vertex equal to its predecessor (its flag moves to
    the kept copy).
    """
    n = p.shape[0]
    if n == 0:
        return p, fixed, offsets
    lengths = np.diff(offsets)
    cid = np.repeat(np.arange(lengths.size), lengths)
    starts = offsets[:-1]
    is_start = np.zeros(n, dtype=bool)
    is_start[starts[lengths > 0]] = True
    fixed = fixed.copy()
    # trailing copies of the first vertex of a ring
    ring_rows = closed[cid]
    keep = np.ones(n, dtype=bool)
    if ring_rows.any():
        tail = zero_gap(p - p[starts[cid]]) & ring_rows & ~is_start
        if tail.any():
            idx = np.arange(n)
            nontail = np.where(tail, -1, idx)
            nonempty = lengths > 0
            last_keep = np.full(lengths.size, -1)
            last_keep[nonempty] = np.maximum.reduceat(nontail, starts[nonempty])
            drop = idx > last_keep[cid]
            if drop.any():
                moved = np.zeros(lengths.size, dtype=bool)
                np.logical_or.at(moved, cid[drop], fixed[drop])
                fixed[starts[moved]] = True
                fixed[drop] = False
                keep &= ~drop
    dup = np.zeros(n, dtype=bool)
    dup[1:] = zero_gap(p[1:] - p[:-1])
    dup &= ~is_start
    dup &= keep
    if not dup.any() and keep.all():
        return p, fixed, offsets
    keep &= ~dup
    kept = np.flatnonzero(keep)
    # OR of the flags of every group: a kept vertex and the duplicates after it
    newfixed = np.logical_or.reduceat(fixed, kept) if kept.size else fixed[:0]
    counts = np.bincount(cid[kept], minlength=lengths.size)
    new_off = np.zeros(lengths.size + 1, dtype=np.int64)
    np.cumsum(counts, out=new_off[1:])
    return p[kept], newfixed, new_off
