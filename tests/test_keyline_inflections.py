"""Keylines with several inflections (issue 11 part 4): split at each, fit each piece.

Test curves: planar S curves 600 mm long whose curvature is ``c prod(s - s_i)`` (so the
inflections are exactly at the arc lengths ``s_i``), scanned at uneven steps (0.02-2 mm),
tilted in 3D, with Gaussian noise of 0.05-0.1 mm per axis.
"""

import itertools
import json
import math

import numpy as np
import pytest

from curvesmith import keyline
from curvesmith.errors import CurveError


def s_curve(zeros, *, turn, noise, seed=0, length=600.0, tilt=0.35):
    """``(scan (M, 3), true inflection points (len(zeros), 3))`` in mm."""
    rng = np.random.default_rng(seed)
    s = np.linspace(0.0, length, 60001)
    kappa = np.prod([s - z * length for z in zeros], axis=0)
    th = np.concatenate([[0.0], np.cumsum(0.5 * (kappa[1:] + kappa[:-1]) * np.diff(s))])
    th *= turn / np.ptp(th)
    e = np.column_stack([np.cos(th), np.sin(th)])
    xy = np.vstack([[0.0, 0.0], np.cumsum(0.5 * (e[1:] + e[:-1]) * np.diff(s)[:, None], axis=0)])
    steps = np.exp(rng.uniform(math.log(0.02), math.log(2.0), size=20000))
    pos = np.concatenate([[0.0], np.cumsum(steps)])
    pos = np.append(pos[pos < length], length)
    c, si = math.cos(tilt), math.sin(tilt)
    rot = np.array([[1.0, 0.0, 0.0], [0.0, c, -si], [0.0, si, c]])
    off = np.array([50.0, -20.0, 300.0])

    def embed(t):
        pts = np.column_stack([np.interp(t, s, xy[:, 0]), np.interp(t, s, xy[:, 1])])
        return np.column_stack([pts, np.zeros(len(t))]) @ rot.T + off

    true = embed(np.array(zeros) * length)
    scan = embed(pos) + rng.normal(scale=noise, size=(pos.size, 3))
    return scan, true


CASES = [((0.3, 0.65), 2.0), ((0.2, 0.5, 0.78), 0.9), ((0.25, 0.4, 0.8), 1.5)]


@pytest.mark.parametrize(("zeros", "turn"), CASES)
@pytest.mark.parametrize(("noise", "seed"), [(0.0, 0), (0.05, 1), (0.1, 2)])
def test_each_inflection_is_found_and_each_piece_fitted(zeros, turn, noise, seed):
    if noise == 0.1 and zeros == (0.25, 0.4, 0.8):
        # its 90 mm middle lobe is 0.6 mm deep: below 10 noise levels, not detectable
        zeros, turn = (0.25, 0.55, 0.8), 1.5
    scan, true = s_curve(zeros, turn=turn, noise=noise, seed=seed)
    res = keyline.fit(scan, step=1.0)
    assert len(res.inflections) == len(zeros)
    found = np.array([res.to_input_frame(e.point[None])[0] for e in res.inflections])
    err = np.linalg.norm(found - true, axis=1)
    assert err.max() < 3.0, err  # within 3 resampling steps (1 mm); the RDP alone: up to 35 mm
    names = [side for side, _ in res.sides]
    assert names == ["left", *[f"middle{i}" for i in range(1, len(zeros))], "right"]
    ranges = res.piece_ranges
    assert ranges[0][0] == 0 and ranges[-1][1] == res.points.shape[0] - 1
    assert all(a[1] == b[0] for a, b in itertools.pairwise(ranges))
    for (side, piece), (first, last, pinned) in zip(res.sides, ranges, strict=True):
        assert piece.success, (side, piece.message)
        assert piece.points.shape[0] == last - first + 1
        np.testing.assert_array_equal(piece.points[0], res.points[pinned])  # pinned there
        # noise-level fits: the pieces between inflections are close to elasticae
        assert piece.rms < 1.5 * noise + 0.05, (side, piece.rms)
    assert res.success and res.left is res.pieces[0] and res.right is res.pieces[-1]


@pytest.mark.parametrize("noise", [0.0, 0.1, 0.3, 0.6])
def test_one_inflection_is_not_split(noise):
    """The paper's keylines (one inflection) keep the paper's path: noise adds no split, also
    with chords shorter than the noise (the polygon's own noise estimate is then too low)."""
    from curvesmith.internals import resample_equilateral_with_positions as _resample_equilateral
    from curvesmith.internals import scan_noise as _scan_noise

    for seed in range(4):
        syn = keyline.synthetic_keyline(noise=noise, seed=seed)
        plane = keyline.fit_plane(syn.points).points2d
        for step in (0.5, 1.0, 2.0):
            poly, _ = _resample_equilateral(np.ascontiguousarray(plane), step)
            sigma = max(_scan_noise(plane), _scan_noise(poly))
            assert len(keyline.estimate_inflections(poly, noise=sigma)) <= 1
        if noise <= 0.1:
            res = keyline.fit(syn.points, step=1.0)
            assert res.pieces == () and res.inflections == ()
            assert [side for side, _ in res.sides] == ["left", "right"]


def test_estimate_inflections_on_a_plain_reference():
    """Exact graphs: y = sin x has its inflections at multiples of pi (to the vertex)."""
    x = np.linspace(0.0, 4.0 * np.pi, 401)
    pts = np.column_stack([x, np.sin(x)])
    est = keyline.estimate_inflections(pts)
    assert [e.index for e in est] == [100, 200, 300]
    np.testing.assert_allclose([e.point[0] for e in est], [np.pi, 2 * np.pi, 3 * np.pi])
    x = np.linspace(-2.0, 2.0, 201)
    assert keyline.estimate_inflections(np.column_stack([x, x**2])) == ()  # convex
    assert [e.index for e in keyline.estimate_inflections(np.column_stack([x, x**3]))] == [100]


def test_explicit_inflections_and_errors():
    scan, _ = s_curve((0.3, 0.65), turn=2.0, noise=0.05, seed=3)
    auto = keyline.fit(scan, step=1.0)
    idx = [e.index for e in auto.inflections]
    given = keyline.fit(scan, step=1.0, inflection=idx)
    assert [e.index for e in given.inflections] == idx
    for a, b in zip(auto.pieces, given.pieces, strict=True):
        np.testing.assert_allclose(a.points, b.points, atol=1e-9)
    with pytest.raises(CurveError, match="increasing vertex indices"):
        keyline.fit(scan, step=1.0, inflection=[idx[1], idx[0]])
    with pytest.raises(CurveError, match=r"at least 5 vertices apart.*piece 2"):
        keyline.fit(scan, step=1.0, inflection=[idx[0], idx[0] + 2])


def test_cli_writes_every_piece(tmp_path):
    from click.testing import CliRunner

    from curvesmith.cli.keyline import keyline_command
    from curvesmith.io import read_curves

    scan, true = s_curve((0.2, 0.5, 0.78), turn=0.9, noise=0.05, seed=4)
    np.savetxt(tmp_path / "s.xyz", scan)
    out = tmp_path / "out"
    result = CliRunner().invoke(keyline_command, [str(tmp_path / "s.xyz"), "-o", str(out)])
    assert result.exit_code == 0, result.output
    ids = [c.properties["id"] for c in read_curves(out / "s_fit.csv")]
    assert ids == ["keyline", "left", "middle1", "middle2", "right"]
    table = json.loads((out / "keyline_table.json").read_text())
    rows = table["rows"]
    assert [r["side"] for r in rows] == ["left", "middle1", "middle2", "right"]
    assert all(r["success"] for r in rows)
    assert set(table["summary"]) == {"left", "middle1", "middle2", "right"}
    # each piece is pinned at an inflection of the polygon written as "keyline"
    poly = read_curves(out / "s_fit.csv")[0].points
    pinned = [r["inflection_index"] for r in rows]
    assert pinned[0] == pinned[1] and pinned[1] < pinned[2] < pinned[3]
    err = [np.linalg.norm(true - poly[j], axis=1).min() for j in pinned[1:]]
    assert max(err) < 3.0


@pytest.mark.parametrize("flip", [False, True])
def test_a_keyline_of_five_scanned_points_splits_in_the_middle_of_its_straight_run(flip):
    # five points of an S: two corners joined by a straight run, on which the curvature
    # vanishes; the RDP method stopped at one end of the run (vertex 159 of 217, sides of
    # 160 and 58 vertices, rms 1.51 and 0.26); the middle of the run is the inflection,
    # and the two sides of this symmetric S are fitted alike
    t = np.linspace(-1.0, 1.0, 5)
    pts = np.c_[100.0 * t, 20.0 * np.sin(np.pi * t), 0.01 * t]
    if flip:
        pts = pts[::-1].copy()
    fit = keyline.fit(pts)
    n = fit.points.shape[0]
    assert abs(fit.inflection.index - (n - 1) / 2) <= 1
    assert fit.inflection.labels[-1] == fit.inflection.index  # the RDP labels, then the move
    left, right = fit.left.rms, fit.right.rms
    assert abs(left - right) <= 0.02 * max(left, right)
