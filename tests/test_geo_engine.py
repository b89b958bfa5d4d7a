"""The conflict resolution's shortcut for small rings alone in their feature, against its rounds."""

from __future__ import annotations

import numpy as np
import pytest

shapely = pytest.importorskip("shapely")
pytest.importorskip("numba")

from curvesmith.internals import engine_solo_loops, geo_smooth  # noqa: E402
from curvesmith.internals import geo_engine as E  # noqa: E402


def spiky_rings(seed: int, n: int = 600):
    """Star rings of 4-23 vertices (many cross themselves once smoothed), in metres, some
    sharing a group (a feature of two rings), a few frozen."""
    rng = np.random.default_rng(seed)
    arcs = []
    for _ in range(n):
        m = int(rng.integers(4, 24))
        t = np.sort(rng.uniform(0, 2 * np.pi, m))
        r = rng.uniform(0.05, 1.0, m) * rng.uniform(2, 40)
        arcs.append(np.c_[r * np.cos(t), r * np.sin(t)] + rng.uniform(-1e5, 1e5, 2) + [5e5, 5e6])
    groups = np.arange(n)
    groups[7::7] = groups[6::7][: len(groups[7::7])]  # every seventh ring joins the one before
    frozen = rng.uniform(size=n) < 0.05
    return arcs, np.ones(n, dtype=bool), groups, frozen


@pytest.mark.parametrize("seed", range(4))
@pytest.mark.parametrize("iterations", [1, 2, 3])
def test_solo_loops_resolve_as_the_rounds_do(seed, iterations):
    arcs, loops, groups, frozen = spiky_rings(seed)
    solo = engine_solo_loops(arcs, loops, groups, frozen)
    assert 0 < solo.sum() < len(arcs)  # both kinds in the call
    levels = E.levels_for(iterations, scalable=True)
    smoother = geo_smooth.make_smoother("cca", "regular")
    # the check on single rings (`check_simple` False for some) goes the same way
    check = np.random.default_rng(seed).uniform(size=len(arcs)) < 0.9
    args = {"loops": loops, "groups": groups, "frozen": frozen, "smoother": smoother}
    args["levels"] = levels
    fast, fast_red = E.resolve_arcs(arcs, check_simple=check, **args)
    # meetings_out asks for what the rounds record: the rounds run for every arc
    slow, slow_red = E.resolve_arcs(arcs, check_simple=check, meetings_out={}, **args)
    assert len(fast) == len(slow)
    for a, b in zip(fast, slow, strict=True):
        np.testing.assert_array_equal(a, b)
    assert fast_red == slow_red
    assert any(r.arc in np.flatnonzero(solo) for r in fast_red)  # the shortcut reduced some


def test_solo_loops_are_single_small_unfrozen_loops():
    sq = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    big = np.c_[np.cos(np.linspace(0, 6, 17)), np.sin(np.linspace(0, 6, 17))]
    arcs = [sq, sq + 2, sq + 4, big, sq + 6, sq + 8]
    loops = np.array([True, True, True, True, False, True])
    groups = np.array([0, 1, 1, 2, 3, 4])
    frozen = np.array([False, False, False, False, False, True])
    assert engine_solo_loops(arcs, loops, groups, frozen).tolist() == [
        True,  # alone, 4 vertices
        False,  # shares its group
        False,
        False,  # 17 vertices: the rounds cut it into pieces
        False,  # not a loop
        False,  # frozen
    ]
