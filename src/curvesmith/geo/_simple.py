"""A compiled, sufficient test that rings are simple, so that GEOS checks only the doubtful ones.

:func:`rings_certainly_simple` says ``True`` for a ring only when it can prove, with
exact sign filters, that no two of its edges meet except neighbours at their shared
vertex. A polygon made of one such ring (at least three vertices) is valid in the sense
of :func:`shapely.is_valid`. ``False`` means "not proven": the caller asks GEOS.

A ring is first tried as star-shaped (``_simple_kernel._star_simple``): about its area
centroid, or its vertex mean, every edge must turn one strict way (the filtered
orientation determinant below) and the direction from the centre must pass the +x ray
exactly once (comparisons only). The direction then turns monotonically through one
revolution, so it is one-to-one on the ring and the ring is simple. This costs one pass
over the vertices (two for the centroid) and clears nearly all footprints and their
smoothed rings; the centre is only a candidate, never trusted.

Otherwise the proof splits the ring at its x-turning vertices into chains whose x strictly
increases or decreases (a vertical edge or a repeated vertex makes the ring doubtful).
A strictly x-monotone chain cannot meet itself. Two chains are the graphs of two
piecewise linear functions over the overlap of their x ranges; their difference is
linear between the x of their vertices, so the chains do not meet iff it has one strict
sign at every vertex of either chain inside the overlap -- except at a turning vertex
the two chains share, where it is zero by construction. A vertex above or below both
ends of the other chain's edge over its x has that sign exactly (two comparisons);
every other sign is that of an orientation determinant, accepted only beyond
Shewchuk's forward error bound for ``orient2d`` (J. R. Shewchuk, Adaptive precision
floating-point arithmetic and fast robust geometric predicates, DCG 18 (1997),
``ccwerrboundA``), so rounding can never turn a touch or a crossing into a proof. NaN
and infinite coordinates, coordinates of 2**500 and more (their products could
overflow), products near underflow and rings with more than ``MAX_CHAINS`` chains are
doubtful.

The chains of a pair are compared only when their bounding boxes overlap, in one merged
walk over their vertices in x order; smoothed footprints have 2-6 chains, so a ring
costs a few passes over its vertices.
"""

from __future__ import annotations

import numpy as np

__all__ = [
    "MAX_CHAINS",
    "NESTING_BUDGET",
    "nesting_certainly_valid",
    "nesting_certainly_valid_rows",
    "rings_certainly_simple",
]

#: Rings with more x-monotone chains than this go to GEOS.
MAX_CHAINS = 32

_kernel = None


def _compiled():
    global _kernel
    if _kernel is None:
        from . import _simple_kernel

        _kernel = _simple_kernel
    return _kernel


def rings_certainly_simple(
    xy: np.ndarray, offsets: np.ndarray, closing: bool, centres: np.ndarray | None = None
) -> np.ndarray:
    """Per ring: True when the ring is proven simple (see the module notes).

    Parameters
    ----------
    xy : (N, 2) float ndarray
        The rings one after the other.
    offsets : (M + 1,) int ndarray
        Ring ``k`` is ``xy[offsets[k]:offsets[k + 1]]``.
    closing : bool
        Whether every ring repeats its first vertex at its end (shapely's layout).
    centres : (M, 2) float64 ndarray, optional
        Per ring a point to try the star proof about first, in one pass (NaN: none; a
        ring smoothed from a ring proven star-shaped is usually star-shaped about the
        same centre). Overwritten in place with the centre that proved each ring by the
        star proof, NaN for the others. The proof is exact whatever the centre.

    Returns
    -------
    (M,) bool ndarray
    """
    k = _compiled()
    offsets = np.ascontiguousarray(offsets, dtype=np.int64)
    m = max(offsets.shape[0] - 1, 0)
    if centres is None:
        centres = np.full((m, 2), np.nan)
    elif centres.shape != (m, 2) or centres.dtype != np.float64 or not centres.flags.c_contiguous:
        raise ValueError(
            f"centres must be a C-contiguous float64 array of shape ({m}, 2) (it is written "
            f"in place), got {centres.dtype} {centres.shape}"
        )
    return k.rings_simple(
        np.ascontiguousarray(xy, dtype=np.float64), offsets, bool(closing), MAX_CHAINS, centres
    )


#: Features whose rings times vertices exceed this are not tested (GEOS decides).
NESTING_BUDGET = 1 << 24


def nesting_certainly_valid(
    xy: np.ndarray,
    ring_offsets: np.ndarray,
    part_offsets: np.ndarray,
    feature_offsets: np.ndarray,
    budget: int = NESTING_BUDGET,
) -> np.ndarray:
    """Per (Multi)Polygon whose rings are simple and pairwise disjoint: whether it is valid.

    The caller must know that the rings are simple and that no two rings of a feature
    meet (the coverage proof knows it). Such a polygon is valid when each hole lies
    inside its shell and in no other hole of its part (then its interior is connected),
    and each part's shell lies outside every other part, or inside one of that part's
    holes (then the parts' interiors are disjoint). Disjoint rings lie wholly inside or
    outside each other, so one vertex of each ring decides, by a crossing count whose
    every side test is Shewchuk's filtered orientation (a sign not certain, NaN or huge
    coordinates: not proven). Cost: per feature, its rings times its vertices at most
    (boxes prune most pairs); features above `budget` are not proven.

    Parameters
    ----------
    xy : (N, 2) float ndarray
        Closed rings (the first vertex repeated), one after the other.
    ring_offsets, part_offsets, feature_offsets : int ndarray
        :func:`shapely.to_ragged_array`'s MultiPolygon offsets: the rows of every ring,
        the rings of every part (its shell first), the parts of every feature.

    Returns
    -------
    (F,) bool ndarray
        True: proven valid; False: not proven (ask GEOS).
    """
    ring_offsets = np.asarray(ring_offsets, dtype=np.int64)
    return nesting_certainly_valid_rows(
        xy, ring_offsets[:-1], ring_offsets[1:], part_offsets, feature_offsets, budget
    )


def nesting_certainly_valid_rows(
    xy: np.ndarray,
    ring_starts: np.ndarray,
    ring_ends: np.ndarray,
    part_offsets: np.ndarray,
    feature_offsets: np.ndarray,
    budget: int = NESTING_BUDGET,
) -> np.ndarray:
    """:func:`nesting_certainly_valid` with the rings picked out of a larger batch.

    Ring ``r`` is rows ``ring_starts[r] .. ring_ends[r] - 1`` of `xy` (not copied).
    """
    k = _compiled()
    return k.nesting_proven(
        np.ascontiguousarray(xy, dtype=np.float64),
        *(
            np.ascontiguousarray(o, dtype=np.int64)
            for o in (ring_starts, ring_ends, part_offsets, feature_offsets)
        ),
        int(budget),
    )
