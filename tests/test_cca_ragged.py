"""cca.smooth_ragged: many curves in one call give, curve by curve, what smooth gives alone."""

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from curvesmith import cca
from curvesmith.errors import CurveError
from curvesmith.internals import cca_api, cca_chunks, cca_kernel, ragged
from oracles import exact_area


@st.composite
def curves(draw):
    """One curve of a realistic batch: tiny, degenerate, open, closed or long."""
    kind = draw(st.sampled_from(["tiny", "ring", "line", "collinear", "dupes", "long", "spike"]))
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    scale = 10.0 ** draw(st.integers(-3, 6))
    shift = rng.uniform(-1e6, 1e6, size=2) if scale >= 1 else np.zeros(2)
    closed = (kind not in ("line",) and draw(st.booleans())) or kind == "ring"
    if kind == "tiny":
        p = rng.normal(size=(3 if closed else 2, 2))
    elif kind == "ring":
        n = int(rng.integers(4, 13))
        t = np.sort(rng.uniform(0, 2 * np.pi, n))
        r = 1 + 0.4 * rng.uniform(size=n)
        p = np.c_[r * np.cos(t), r * np.sin(t)]
    elif kind == "line":
        n = int(rng.integers(2, 15))
        p = np.c_[np.cumsum(rng.uniform(0.1, 1, n)), rng.normal(size=n)]
    elif kind == "collinear":  # straight vertices among corners
        p = np.array([[0, 0], [1, 0], [2, 0], [2, 1], [1, 1], [0, 1.0]])
    elif kind == "dupes":  # repeated points, closing vertex repeated
        p = np.array([[0, 0], [0, 0], [3, 0], [3, 2], [3, 2], [0, 2], [0, 0.0]])
    elif kind == "spike":
        p = np.array([[0, 0], [4, 0], [4, 1], [2, 1.002], [0, 1.0]])
    else:
        n = int(rng.integers(200, 600))
        t = 2 * np.pi * np.arange(n) / n
        r = 1 + 0.3 * rng.uniform(size=n)
        p = np.c_[r * np.cos(t), r * np.sin(t)]
    if draw(st.booleans()):
        p = p[::-1]
    return p * scale + shift, bool(closed)


def _batch(items):
    xy = np.concatenate([p for p, _ in items])
    off = np.concatenate([[0], np.cumsum([len(p) for p, _ in items])])
    return xy, off, np.array([c for _, c in items])


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.lists(curves(), min_size=1, max_size=12), st.integers(1, 3), st.sampled_from(
    ["regular", 0.25, "callable"]))  # fmt: skip
def test_each_curve_as_in_a_single_call(items, iterations, alpha):
    if alpha == "callable":
        alpha = lambda ang: 0.15 + 0.02 * np.cos(ang)  # noqa: E731
    xy, off, closed = _batch(items)
    res = cca.smooth_ragged_with_info(xy, off, closed=closed, iterations=iterations, alpha=alpha)
    assert res.offsets.shape == (len(items) + 1,)
    for k, (p, cl) in enumerate(items):
        one = cca.smooth_with_info(p, closed=cl, iterations=iterations, alpha=alpha)
        np.testing.assert_array_equal(res.curve(k), one.points)
        assert res.reductions[k] == one.reductions
        assert res.fig11_edges[k] == one.fig11_edges
        assert res.unsatisfied[k] == one.unsatisfied
        if cl:  # the ring's area, to rounding of its coordinates
            a0, a1 = exact_area(p), exact_area(res.curve(k))
            mag = float(np.abs(p).max())
            assert abs(a1 - a0) <= 1e-11 * abs(a0) + 1e-12 * mag * mag
        else:  # open ends fixed, bit for bit
            np.testing.assert_array_equal(res.curve(k)[[0, -1]], p[[0, -1]])
    assert res.success == (res.unsatisfied.sum() == 0)


def test_anchors_per_curve_and_as_mask():
    rng = np.random.default_rng(3)
    rings = [np.c_[np.cos(t), np.sin(t)] * (1 + 0.2 * rng.uniform(size=t.size))[:, None]
             for t in (np.linspace(0, 2 * np.pi, n, endpoint=False) for n in (9, 14, 30))]  # fmt: skip
    line = np.c_[np.arange(12.0), rng.normal(size=12)]
    items = [*rings, line]
    xy = np.concatenate(items)
    off = np.concatenate([[0], np.cumsum([len(p) for p in items])])
    closed = np.array([True, True, True, False])
    anchors = [[0, 4], [], [3, 17, 29], [5]]
    out, oo = cca.smooth_ragged(xy, off, closed=closed, iterations=2, anchors=anchors)
    mask = np.zeros(len(xy), dtype=bool)
    for k, a in enumerate(anchors):
        mask[off[k] + np.asarray(a, dtype=int)] = True
    out2, oo2 = cca.smooth_ragged(xy, off, closed=closed, iterations=2, anchors=mask)
    np.testing.assert_array_equal(out, out2)
    np.testing.assert_array_equal(oo, oo2)
    for k, p in enumerate(items):
        one = cca.smooth(p, closed=bool(closed[k]), iterations=2, anchors=anchors[k] or None)
        got = out[oo[k] : oo[k + 1]]
        np.testing.assert_array_equal(got, one)
        for i in anchors[k]:  # anchored vertices stay, bit for bit
            assert (got == p[i]).all(axis=1).any()


def test_closing_vertex_repeated_or_not_and_anchor_on_it():
    sq = np.array([[0, 0], [2, 0], [2, 1], [0, 1.0]])
    closed_sq = np.vstack([sq, sq[:1]])
    xy = np.vstack([sq, closed_sq])
    out, off = cca.smooth_ragged(xy, [0, 4, 9], closed=True, iterations=2)
    np.testing.assert_array_equal(out[off[0] : off[1]], out[off[1] : off[2]])
    # an anchor on the repeated closing vertex is the first vertex
    a, _ = cca.smooth_ragged(closed_sq, [0, 5], closed=True, anchors=[[4]])
    np.testing.assert_array_equal(a, cca.smooth(sq, closed=True, anchors=[0]))


def test_empty_batch_and_zero_iterations():
    out, off = cca.smooth_ragged(np.zeros((0, 2)), [0], closed=True)
    assert out.shape == (0, 2) and off.tolist() == [0]
    xy = [[0, 0], [0, 0], [1, 0], [1, 1], [0, 1]]
    out, off = cca.smooth_ragged(xy, [0, 5], closed=True, iterations=0)
    np.testing.assert_array_equal(out, cca.smooth(xy, closed=True, iterations=0))


@pytest.mark.parametrize(
    ("args", "kwargs", "match"),
    [
        (
            ([[0, 0], [1, 0], [1, 1]], [0, 2]),
            {"closed": True},
            "end at the number of coordinates 3",
        ),
        (([[0, 0], [1, 0], [1, 1]], [0, 3, 2, 3]), {"closed": True}, "non-decreasing"),
        (([[0, 0], [1, 0], [1, 1]], [0, 3]), {"closed": [True, False]}, r"shape \(1,\)"),
        (([[0, 0], [1, 0], [1, 1]], [0, 3]), {"closed": "yes"}, "closed must be"),
        (
            ([[0, 0], [1, 0], [1, 1], [5, 5], [5, 5]], [0, 3, 5]),
            {"closed": False},
            "got 1 for curve 1",
        ),
        (([[0, 0], [1, 0], [np.nan, 1]], [0, 3]), {"closed": True}, "coords must be finite"),
        (
            ([[0, 0], [1, 0], [1, 1]], [0, 3]),
            {"closed": True, "anchors": [[7]]},
            r"\[0, 3\), got 7 \(curve 0\)",
        ),
        (
            ([[0, 0], [1, 0], [1, 1]], [0, 3]),
            {"closed": True, "anchors": np.ones(2, bool)},
            r"mask of shape \(3,\)",
        ),
    ],
)
def test_bad_input_names_the_argument(args, kwargs, match):
    with pytest.raises(CurveError, match=match):
        cca.smooth_ragged(*args, **kwargs)


def test_close_rings_repeats_the_first_vertex():
    rng = np.random.default_rng(11)
    rings = [rng.normal(size=(n, 2)) for n in (5, 9, 30)]
    line = np.c_[np.arange(6.0), rng.normal(size=6)]
    items = [*rings, line]
    xy = np.concatenate(items)
    off = np.concatenate([[0], np.cumsum([len(p) for p in items])])
    closed = np.array([True, True, True, False])
    for it, anchors in ((2, None), (0, None), (1, [[0], [], [4], [2]])):
        a, ao = cca.smooth_ragged(xy, off, closed=closed, iterations=it, anchors=anchors)
        b, bo = cca.smooth_ragged(
            xy, off, closed=closed, iterations=it, anchors=anchors, close_rings=True
        )
        np.testing.assert_array_equal(np.diff(bo), np.diff(ao) + closed)
        for k in range(4):
            ck = b[bo[k] : bo[k + 1]]
            if closed[k]:
                np.testing.assert_array_equal(ck[:-1], a[ao[k] : ao[k + 1]])
                np.testing.assert_array_equal(ck[-1], ck[0])
            else:
                np.testing.assert_array_equal(ck, a[ao[k] : ao[k + 1]])


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    lengths=st.lists(st.integers(0, 7), min_size=1, max_size=40),
    seed=st.integers(0, 2**32 - 1),
    all_closed=st.booleans(),
)
def test_compiled_drop_of_closing_vertices_is_numpys(lengths, seed, all_closed):
    # as_ragged's compiled pass (large batches of the compiled methods) against its numpy
    # one: the same kept rows (signed zeros too), offsets, kept mask and dropped curves
    rng = np.random.default_rng(seed)
    off = np.concatenate([[0], np.cumsum(lengths)])
    xy = rng.integers(-1, 2, size=(int(off[-1]), 2)) * rng.choice([0.5, -0.0, 1e300])
    for k, n in enumerate(lengths):
        if n >= 2 and rng.random() < 0.6:
            xy[off[k + 1] - 1] = xy[off[k]]  # a repeated closing vertex
    closed = True if all_closed else rng.random(len(lengths)) < 0.7
    want = ragged.as_ragged(xy, off, closed=closed)
    old = ragged.COMPILED_MIN
    try:
        ragged.COMPILED_MIN = 0
        got = ragged.as_ragged(xy, off, closed=closed, compiled=True)
    finally:
        ragged.COMPILED_MIN = old
    for name in ("points", "offsets", "closed", "kept", "dropped", "offsets_in"):
        a, b = getattr(want, name), getattr(got, name)
        assert a.dtype == b.dtype and a.shape == b.shape, name
        np.testing.assert_array_equal(a, b, err_msg=name)
    np.testing.assert_array_equal(np.signbit(want.points), np.signbit(got.points))


@pytest.mark.parametrize("alpha", ["regular", 0.25, "callable"])
def test_blocks_threads_and_closing_vertices_give_the_single_call_bits(monkeypatch, alpha):
    # Small blocks (128 core vertices) and thread groups that cut long rings and lines in
    # the middle: every group writes its rows in place in one buffer (moved only where a
    # group needs more or fewer than the common case); a ring cut between two groups
    # gets its closing vertex afterwards. Each
    # curve must still be, bit for bit, what cca.smooth gives it alone (in the input's
    # frame: the kernel subtracts and adds the origins itself), with the same counts.

    rng = np.random.default_rng(31)
    items = []
    for k in range(7):
        n = int(rng.integers(5, 13)) if k % 2 else int(rng.integers(700, 1500))
        t = 2 * np.pi * np.arange(n) / n
        r = 1 + 0.3 * rng.uniform(size=n)
        p = np.c_[r * np.cos(t), r * np.sin(t)] * 10.0 ** (k - 2) + rng.uniform(-1e6, 1e6, 2)
        if k == 4:
            p = np.insert(p, 300, p[300], axis=0)  # a duplicate: compacted before blocking
        items.append((p, k != 2))  # curve 2: a long open line
    xy, off, closed = _batch(items)
    anchors = [[], [1], [100, 640], [], [5], [], [0, 3]]
    fn = (lambda a: 0.1 + 0.05 * np.cos(a)) if alpha == "callable" else alpha
    singles = [
        cca.smooth_with_info(p, closed=c, iterations=2, alpha=fn, anchors=anchors[k] or None)
        for k, (p, c) in enumerate(items)
    ]
    monkeypatch.setattr(cca_api, "BLOCK", 128)
    monkeypatch.setattr(cca_api, "THREAD_MIN", 100)
    monkeypatch.setattr(ragged, "COMPILED_MIN", 0)  # closing vertices dropped compiled
    assert len(cca_chunks(np.array([0, len(xy) // 2, len(xy)]), 3)) == 2
    for threads in (1, 2, 3):
        for close_rings in (False, True):
            res = cca.smooth_ragged_with_info(
                xy, off, closed=closed, iterations=2, alpha=fn, anchors=anchors,
                threads=threads, close_rings=close_rings,
            )  # fmt: skip
            for k, one in enumerate(singles):
                got = res.curve(k)
                if close_rings and closed[k]:
                    np.testing.assert_array_equal(got[-1], got[0])
                    got = got[:-1]
                np.testing.assert_array_equal(got, one.points)
                assert res.reductions[k] == one.reductions
                assert res.fig11_edges[k] == one.fig11_edges
                assert res.unsatisfied[k] == one.unsatisfied
    assert res.reductions.sum() > 0


def test_curve_units_is_the_table_of_whole_curves():
    rng = np.random.default_rng(8)
    lengths = rng.integers(0, 9, size=50)
    off = np.concatenate([[0], np.cumsum(lengths)]).astype(np.int64)
    closed = rng.uniform(size=50) < 0.6
    K = cca_kernel
    flags = K.U_FIRST | K.U_LAST | np.where(closed, K.U_CLOSED | K.U_RING, 0)
    zero = np.zeros(50, dtype=np.int64)
    want = np.stack([np.arange(50), off[:-1], lengths, zero, lengths, zero, lengths, flags], 1)
    got = K.curve_units(off, closed)
    assert got.dtype == np.int64
    np.testing.assert_array_equal(got, want)


@pytest.mark.parametrize("blocked", [False, True])
def test_a_step_that_outgrows_its_buffer_gives_the_bits_of_one_that_fits(monkeypatch, blocked):
    # a zigzag of equal edges: every inner edge a balanced inflection, so Fig. 11 adds one
    # row per edge, far beyond the spare rows of the one-group buffer (n / 16 + 64): the
    # step runs again on the general path, whose groups finish in buffers of their own
    n = 3000
    zig = np.c_[np.arange(n, dtype=float), np.where(np.arange(n) % 2, 1.0, 0.0)]
    ring = np.c_[np.cos(np.linspace(0, 6, 40)), np.sin(np.linspace(0, 6, 40))]
    xy, off, closed = _batch([(ring, True), (zig * 7.5 + 1e5, False), (ring + 3, True)])
    if blocked:
        monkeypatch.setattr(cca_api, "BLOCK", 256)
    statuses = []
    kernel_step = cca_kernel.step_units

    def counted(*args):
        res = kernel_step(*args)
        statuses.append(int(res[7]))
        return res

    monkeypatch.setattr(cca_kernel, "step_units", counted)
    got = cca.smooth_ragged_with_info(xy, off, closed=closed, iterations=2, threads=1)
    assert got.fig11_edges[1] > 2 * (n // 16 + 64)
    # each step: the units that fit are kept, only the others run again
    assert statuses == [cca_kernel.FULL, cca_kernel.DONE] * 2
    monkeypatch.setattr(cca_kernel, "step_units", kernel_step)
    roomy = cca_api.output_buffers
    monkeypatch.setattr(cca_api, "output_buffers", lambda cap: roomy(4 * cap))
    want = cca.smooth_ragged_with_info(xy, off, closed=closed, iterations=2, threads=1)
    np.testing.assert_array_equal(got.coords, want.coords)
    np.testing.assert_array_equal(got.offsets, want.offsets)
    np.testing.assert_array_equal(got.fig11_edges, want.fig11_edges)
    np.testing.assert_array_equal(got.reductions, want.reductions)


@pytest.mark.parametrize("iterations", [0, 2])
def test_extreme_coordinate_scales_in_one_batch(iterations):
    """Curves at 1e140, 1e-140 and 1 side by side: each scaled by its own power of two,
    every curve bit for bit what cca.smooth gives it alone (a broadcasting error once)."""
    rng = np.random.default_rng(140)
    items = []
    for k, scale in enumerate([1e140, 1.0, 1e-140, 2.0**-1000, 1e300]):
        n = 9 + k
        t = np.sort(rng.uniform(0, 2 * np.pi, n))
        p = np.c_[np.cos(t), np.sin(t)] * (1 + 0.2 * rng.uniform(size=(n, 1))) * scale
        items.append((p, k != 1))
    xy = np.concatenate([p for p, _ in items])
    off = np.r_[0, np.cumsum([len(p) for p, _ in items])]
    closed = np.array([c for _, c in items])
    out, oo = cca.smooth_ragged(xy, off, closed=closed, iterations=iterations, anchors=None)
    for k, (p, c) in enumerate(items):
        np.testing.assert_array_equal(
            out[oo[k] : oo[k + 1]], cca.smooth(p, closed=c, iterations=iterations)
        )
        assert np.isfinite(out[oo[k] : oo[k + 1]]).all()


def test_paused_gc_resumes_the_collector_and_keeps_it_off_when_it_was():
    import gc

    from curvesmith.internals import paused_gc

    assert gc.isenabled()
    with pytest.raises(ZeroDivisionError), paused_gc():
        assert not gc.isenabled()
        1 / 0  # noqa: B018
    assert gc.isenabled()  # resumed on an exception too
    gc.disable()
    try:
        with paused_gc():
            assert not gc.isenabled()
        assert not gc.isenabled()  # a collector that was off stays off
    finally:
        gc.enable()


def test_layer_calls_pause_the_collector_and_resume_it_also_on_errors():
    import gc

    import shapely

    from curvesmith import geo

    boxes = [shapely.box(0, 0, 1, 1), shapely.box(1, 0, 2, 1)]
    seen = []

    def spy(theta):
        seen.append(gc.isenabled())
        return np.full_like(theta, 0.25)

    for call in (
        lambda: geo.smooth(boxes, iterations=1, alpha=spy),
        lambda: geo.smooth_coverage(boxes, iterations=1),
        lambda: geo.smooth_network([shapely.LineString([(0, 0), (1, 1), (2, 0)])]),
    ):
        call()
        assert gc.isenabled()
    assert seen and not any(seen)  # the user's alpha ran with the collector paused
    with pytest.raises(CurveError):
        geo.smooth([shapely.Point(0, 0)])
    assert gc.isenabled()
