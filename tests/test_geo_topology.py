"""The hash kernels of the coverage topology, against plain sorting (numpy.unique)."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("numba")
from hypothesis import given, settings
from hypothesis import strategies as st

from curvesmith.internals import topology_kernel as K

# coordinates as users have them: UTM metres, degrees, the extremes of float64
SCALES = [4.0e5, 1.0, 1e-300, 1e300, 5e-324]


def same_partition(a: np.ndarray, b: np.ndarray) -> bool:
    """Whether two labelings group the items the same way (labels may differ)."""
    pairs = np.unique(np.stack([a, b], axis=1), axis=0)
    return len(pairs) == len(np.unique(a)) == len(np.unique(b))


@st.composite
def point_sets(draw):
    """Rows drawn from a small pool of points (so that many repeat), at any scale."""
    n_pool = draw(st.integers(1, 40))
    n = draw(st.integers(1, 400))
    seed = draw(st.integers(0, 2**32 - 1))
    scale = draw(st.sampled_from(SCALES))
    rng = np.random.default_rng(seed)
    pool = rng.integers(-3, 4, size=(n_pool, 2)) * scale + rng.uniform(size=(n_pool, 2)) * (
        scale * draw(st.sampled_from([0.0, 1e-15, 1.0]))
    )
    return pool[rng.integers(0, n_pool, size=n)] + 0.0


@settings(max_examples=60, deadline=None)
@given(point_sets())
def test_point_ids_are_the_exact_point_partition(xy):
    pid, n = K.point_ids(np.ascontiguousarray(xy))
    _, ref = np.unique(xy, axis=0, return_inverse=True)
    assert n == len(np.unique(xy, axis=0))
    assert same_partition(pid, ref.reshape(-1))
    # numbered in order of first appearance
    _, first = np.unique(pid, return_index=True)
    assert np.array_equal(pid[np.sort(first)], np.arange(n))


def test_point_ids_tell_apart_neighbouring_floats_and_merge_signed_zeros():
    x = 4.0e5
    xy = np.array([[x, 5e6], [np.nextafter(x, 0), 5e6], [x, 5e6], [-0.0, 0.0], [0.0, -0.0]])
    pid, n = K.point_ids(xy + 0.0)  # the caller's -0.0 -> 0.0
    assert n == 3 and list(pid) == [0, 1, 0, 2, 2]


@settings(max_examples=60, deadline=None)
@given(st.integers(1, 300), st.integers(1, 30), st.integers(0, 2**32 - 1))
def test_segment_classes_are_the_unordered_pairs(n, n_points, seed):
    rng = np.random.default_rng(seed)
    a = rng.integers(0, n_points, size=n)
    b = rng.integers(0, n_points, size=n)
    cls, lo, hi = K.segment_classes(a, b, n_points)
    key = np.minimum(a, b) * n_points + np.maximum(a, b)
    assert same_partition(cls, np.unique(key, return_inverse=True)[1].reshape(-1))
    assert np.array_equal(lo[cls], np.minimum(a, b)) and np.array_equal(hi[cls], np.maximum(a, b))
    assert len(lo) == len(np.unique(key))
    # lookups (the frozen edges of coverage_topology): pairs appended after these get the
    # class of the same pair in either direction, and a class of their own (>= the number
    # of classes above) exactly when absent; the classes above do not change
    every = np.arange(n_points * n_points)
    absent = np.setdiff1d(every[every // n_points <= every % n_points], key)  # lo <= hi
    q = absent[: min(len(absent), 50)]
    qa, qb = np.concatenate([b, q // n_points]), np.concatenate([a, q % n_points])
    both, lo2, hi2 = K.segment_classes(np.concatenate([a, qa]), np.concatenate([b, qb]), n_points)
    assert np.array_equal(both[:n], cls) and np.array_equal(lo2[: len(lo)], lo)
    assert np.array_equal(hi2[: len(hi)], hi)
    assert np.array_equal(both[n : 2 * n], cls)
    extra = both[2 * n :]
    assert np.all(extra >= len(lo)) and len(np.unique(extra)) == len(q)


@settings(max_examples=40, deadline=None)
@given(point_sets(), st.integers(0, 2**32 - 1))
def test_lexicographic_first(xy, seed):
    rng = np.random.default_rng(seed)
    lens = rng.integers(1, 8, size=len(xy))
    lens = lens[np.cumsum(lens) <= len(xy)]
    starts = (np.cumsum(lens) - lens).astype(np.int64)
    got = K.lexicographic_first(np.ascontiguousarray(xy), starts, lens.astype(np.int64))
    for s, m, t in zip(starts, lens, got, strict=True):
        run = xy[s : s + m]
        order = np.lexsort((run[:, 1], run[:, 0]))  # x first, then y; stable: first of equals
        assert t == order[0]
