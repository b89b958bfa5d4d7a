"""Ragged subdivision: every curve of a batch gets the bits of the single-curve call."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from curvesmith import subdivision as sd
from curvesmith.errors import CurveError


@st.composite
def batches(draw, dim=2):
    m = draw(st.integers(1, 10))
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    items = []
    for _ in range(m):
        closed = draw(st.booleans())
        n = int(rng.choice([3, 4, 7, 12, 150])) if closed else int(rng.choice([2, 3, 5, 40]))
        p = rng.normal(size=(n, dim)) * 10.0 ** rng.integers(-2, 5) + rng.uniform(-1e5, 1e5)
        if closed and draw(st.booleans()):
            p = np.vstack([p, p[:1]])  # ring convention: closing vertex repeated
        items.append((p, closed))
    return items


def _pack(items):
    xy = np.concatenate([p for p, _ in items])
    off = np.concatenate([[0], np.cumsum([len(p) for p, _ in items])])
    return xy, off, np.array([c for _, c in items])


@settings(max_examples=80, deadline=None)
@given(
    batches(dim=2),
    st.integers(0, 3),
    st.booleans(),
    st.sampled_from([1.5, 2.0, 5.0]),
    st.booleans(),
    st.booleans(),
)
def test_de_rham_and_chaikin_ragged_match_single(
    items, iterations, keep, gamma, compiled, close_rings
):
    # both the numpy steps and the compiled kernel (large batches; here every batch with
    # COMPILED_MIN lowered to 0) give every curve the single call's bits
    xy, off, closed = _pack(items)
    old = sd.COMPILED_MIN
    sd.COMPILED_MIN = 0 if compiled else 1 << 62
    try:
        out, oo = sd.de_rham_ragged(
            xy, off, gamma=gamma, closed=closed, iterations=iterations,
            preserve_endpoints=keep, close_rings=close_rings,
        )  # fmt: skip
        ch, co = sd.chaikin_ragged(
            xy, off, closed=closed, iterations=iterations, preserve_endpoints=keep,
            close_rings=close_rings,
        )  # fmt: skip
    finally:
        sd.COMPILED_MIN = old
    for k, (p, c) in enumerate(items):
        one = sd.de_rham(p, gamma=gamma, closed=c, iterations=iterations, preserve_endpoints=keep)
        two = sd.chaikin(p, closed=c, iterations=iterations, preserve_endpoints=keep)
        got, got2 = out[oo[k] : oo[k + 1]], ch[co[k] : co[k + 1]]
        if close_rings and c:  # the first vertex repeated at the end, bit for bit
            np.testing.assert_array_equal(got[-1], got[0])
            np.testing.assert_array_equal(got2[-1], got2[0])
            got, got2 = got[:-1], got2[:-1]
        np.testing.assert_array_equal(got, one)
        np.testing.assert_array_equal(got2, two)


@settings(max_examples=60, deadline=None)
@given(batches(dim=3), st.integers(0, 3), st.booleans(), st.integers(1, 3))
def test_lane_riesenfeld_ragged_matches_single(items, iterations, keep, degree):
    items = [(p, c) for p, c in items if c or 2 * len(p) - degree >= 2 * 2]
    if not items:
        return
    xy, off, closed = _pack(items)
    try:
        out, oo = sd.lane_riesenfeld_ragged(
            xy, off, degree=degree, closed=closed, iterations=iterations, preserve_endpoints=keep
        )
    except CurveError:  # some open curve too short for the steps: the single call says so
        with pytest.raises(CurveError):
            for p, c in items:
                sd.lane_riesenfeld(
                    p, degree=degree, closed=c, iterations=iterations, preserve_endpoints=keep
                )
        return
    for k, (p, c) in enumerate(items):
        one = sd.lane_riesenfeld(
            p, degree=degree, closed=c, iterations=iterations, preserve_endpoints=keep
        )
        np.testing.assert_array_equal(out[oo[k] : oo[k + 1]], one)


def test_chaikin_ragged_postgis_example_and_errors():
    # two copies of the PostGIS documentation triangle (area 64 -> 52 per step)
    tri = [[0, 0], [8, 8], [0, 16], [0, 0]]
    out, off = sd.chaikin_ragged(tri + tri, [0, 4, 8], closed=True)
    assert off.tolist() == [0, 6, 12]
    assert out[:6].tolist() == [[2, 2], [6, 6], [6, 10], [2, 14], [0, 12], [0, 4]]
    with pytest.raises(CurveError, match="got 2 for curve 1"):
        sd.chaikin_ragged([[0, 0], [1, 0], [1, 1], [0, 0], [1, 1]], [0, 3, 5], closed=True)
    with pytest.raises(CurveError, match=r"at least 3 points for an open .* got 2 for curve 0"):
        sd.lane_riesenfeld_ragged([[0, 0], [1, 0]], [0, 2], degree=3)
    with pytest.raises(CurveError, match="offsets must start at 0"):
        sd.chaikin_ragged([[0, 0], [1, 0]], [1, 2], closed=False)
