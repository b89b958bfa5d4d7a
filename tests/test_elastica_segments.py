"""Multi-segment fairing to a tolerance: ``elastica.fit_segments`` and ``fair --max-segments``.

Test curves: exact discrete elasticae joined G1 (their joints are known), a single elastica,
an Archimedean spiral (no elastica fits it), and a car-body-like section 1.5 m long in mm
with an S-bend and a tight feature-line bend, scanned at uneven steps with noise, reversed,
and (in 3D) with a 5-point glitch off its plane. Every deviation is checked with a plain
point-to-segment distance written here, not the library's.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from click.testing import CliRunner
from scipy.special import ellipj

from curvesmith.elastica import fit_segments, sample
from curvesmith.errors import CurveError
from curvesmith.internals import ChainProblem as _ChainProblem
from curvesmith.internals import segment_chain as _chain


def plain_distance(points, poly):
    """Distance of every point to the polyline: brute force over all segments."""
    points = np.asarray(points, dtype=float)
    a, b = poly[:-1], poly[1:]
    e = b - a
    ee = np.einsum("ij,ij->i", e, e)
    out = np.empty(points.shape[0])
    for start in range(0, points.shape[0], 256):
        p = points[start : start + 256, None, :]
        t = np.clip(np.einsum("mkd,kd->mk", p - a, e) / ee, 0.0, 1.0)
        d = p - a - t[..., None] * e
        out[start : start + 256] = np.sqrt(np.einsum("mkd,mkd->mk", d, d)).min(axis=1)
    return out


def half_angle(s, k):
    """``a = (theta - phi)/2`` of eq. (4.3) from scipy's Jacobi functions (k != 1)."""
    if k < 1:
        sn, cn, dn, _ = ellipj(s, k * k)
        return np.arctan2(k * sn, dn)
    sn, cn, dn, _ = ellipj(k * np.asarray(s), 1 / (k * k))
    return np.arctan2(sn, cn)


def g1_chain(pieces, start=(0.0, 0.0), phi=0.0):
    """Exact discrete elasticae joined G1: each starts at the previous last vertex with its
    vertex tangent ``theta = phi + 2 a`` continued. ``pieces``: (h, z, q, k, n)."""
    out, joints, pos, theta = [], [], start, None
    for h, z, q, k, n in pieces:
        ph = phi if theta is None else theta - 2 * half_angle(q, k)
        pts = sample((*pos, h, ph, z, q, k), n)
        if out:
            joints.append(pts[0])
        out.append(pts if not out else pts[1:])
        pos = tuple(pts[-1])
        theta = ph + 2 * half_angle(z * (n - 1) + q, k)
    return np.vstack(out), np.array(joints)


def section(seed=0, noise=0.05):
    """A 1.5 m car-body-like section (mm): S-bend plus a tight bend, uneven 0.01-11 mm steps."""
    rng = np.random.default_rng(seed)
    s = np.linspace(0.0, 1500.0, 30001)
    kappa = (1 - 2.2 * s / 1500) / 900 + np.exp(-(((s - 1150) / 70) ** 2)) / 160
    theta = np.concatenate([[0.0], np.cumsum(0.5 * (kappa[1:] + kappa[:-1]) * np.diff(s))])
    e = np.column_stack([np.cos(theta), np.sin(theta)])
    dense = np.vstack([[0.0, 0.0], np.cumsum(0.5 * (e[1:] + e[:-1]) * np.diff(s)[:, None], 0)])
    steps = np.exp(rng.uniform(math.log(0.01), math.log(11.0), size=3000))
    pos = np.concatenate([[0.0], np.cumsum(steps)])
    pos = np.append(pos[pos < s[-1]], s[-1])
    pts = np.column_stack([np.interp(pos, s, dense[:, 0]), np.interp(pos, s, dense[:, 1])])
    return pts + rng.normal(scale=noise, size=pts.shape), dense


def check(res, points, tolerance):
    """Every point within the tolerance (plain distance), G1 joints, consistent ranges."""
    dev = plain_distance(points, res.points)
    assert dev.max() <= tolerance
    np.testing.assert_allclose(np.sort(dev), np.sort(res.deviation), atol=1e-9)
    assert res.within_tolerance and res.success
    for a, b in zip(res.segments, res.segments[1:], strict=False):
        assert a.last == b.first
        np.testing.assert_array_equal(a.points[-1], b.points[0])
    for seg in res.segments:  # each segment is the discrete elastica of its own params
        n = seg.last - seg.first + 1
        np.testing.assert_allclose(sample(seg.params, n), seg.points, atol=1e-9)
    for j, (a, b) in enumerate(zip(res.segments, res.segments[1:], strict=False)):
        pa, pb = a.params, b.params
        th_a = pa.phi + 2 * half_angle(pa.z * (a.last - a.first) + pa.q, pa.k)
        th_b = pb.phi + 2 * half_angle(pb.q, pb.k)
        assert abs(math.remainder(th_a - th_b, 2 * math.pi)) < 1e-9
        assert res.joints[j].g1_defect < 1e-9
    return dev


def test_chain_jacobian_matches_central_differences():
    rng = np.random.default_rng(3)
    data = rng.normal(size=(60, 2))
    x = np.array([0.3, -0.2, 0.4, 1.1, 0.04, 0.3, 0.7, 0.9, -0.03, 1.2, 2.5, 1.0, 0.05, -0.4, 1.3])
    sizes = [20, 25, 17]
    prob = _ChainProblem(data, sizes)
    J = prob.jacobian(x)
    for j in range(x.size):
        e = np.zeros_like(x)
        e[j] = 1e-6 * max(1.0, abs(x[j]))
        fd = (prob.residuals(x + e) - prob.residuals(x - e)) / (2 * e[j])
        np.testing.assert_allclose(J[:, j], fd, atol=1e-6 * np.abs(J).max())


def test_chain_equals_sampled_segments_with_continued_tangent():
    """The chain with phi derived from the previous end tangent is the reference G1 chain."""
    pieces = [(1.5, 0.03, 0.2, 0.6, 30), (1.2, -0.02, 0.5, 2.0, 25), (1.4, 0.05, -0.3, 0.9, 21)]
    ref, _ = g1_chain(pieces, start=(2.0, -1.0), phi=0.7)
    x = np.array([2.0, -1.0, 0.7, *[v for p in pieces for v in p[:4]]])
    g, _, _ = _chain(x, [p[4] for p in pieces], False)
    np.testing.assert_allclose(g.view(float).reshape(-1, 2), ref, atol=1e-10)


@pytest.mark.parametrize(
    "pieces",
    [
        [(2.0, 0.01, 0.3, 0.7, 400), (2.0, 0.006, -0.5, 2.5, 401)],
        [(2.0, 0.012, 0.3, 0.7, 300), (2.0, 0.006, -0.5, 2.5, 251), (2.0, 0.01, 1.0, 0.5, 251)],
    ],
    ids=["two", "three"],
)
def test_recovers_g1_pieces_and_their_joints(pieces):
    """Exact elasticae joined G1, 0.02 mm noise, T = 4 noise: as many segments as pieces,
    joints within 2 vertices; reversing the order gives the same segmentation."""
    noise = 0.02
    clean, joints = g1_chain(pieces)
    pts = clean + np.random.default_rng(len(pieces)).normal(scale=noise, size=clean.shape)
    # T = 4 noise: the clean curve itself is ~3.2 noise from the farthest of 800 points
    tol = 4 * noise
    assert plain_distance(pts, clean).max() > 3 * noise
    res = fit_segments(pts, tol)
    check(res, pts, tol)
    assert len(res.segments) == len(pieces)
    found = np.array([res.points[j.vertex] for j in res.joints])
    assert np.hypot(*(found - joints).T).max() <= 2 * 2.0 + 0.1  # 2 vertices of h = 2
    assert all(s.rms < 1.6 * noise for s in res.segments)
    back = fit_segments(pts[::-1], tol)
    assert len(back.segments) == len(pieces)
    assert back.max_deviation == pytest.approx(res.max_deviation, rel=1e-9)
    np.testing.assert_allclose(back.points[::-1], res.points, atol=1e-9)


def test_single_elastica_is_one_segment():
    rng = np.random.default_rng(5)
    clean = sample((10.0, -4.0, 1.5, 0.3, 0.01, 0.2, 0.8), 800)
    pts = clean + rng.normal(scale=0.02, size=clean.shape)
    res = fit_segments(pts, 0.08)
    check(res, pts, 0.08)
    assert len(res.segments) == 1 and res.joints == ()
    assert res.segments[0].first == 0 and res.segments[0].last == 799
    assert res.solves == 0  # the single global fit already meets T


def test_spiral_needs_several_segments_within_tolerance():
    """An Archimedean spiral (curvature ~ 1/r) is no elastica: several G1 segments meet T."""
    t = np.linspace(0.0, 4 * np.pi, 800)
    r = 50 + 20 * t
    pts = np.column_stack([r * np.cos(t), r * np.sin(t)])  # mm, 1.2-2.1 mm steps
    tol = 0.1
    res = fit_segments(pts, tol)
    dev = check(res, pts, tol)
    assert res.single.max_deviation > 10 * tol
    assert 3 <= len(res.segments) <= 10
    assert dev.max() <= tol
    # with one segment fewer than found, T is not met: the result says so
    fewer = fit_segments(pts, tol, max_segments=2)
    assert len(fewer.segments) == 2 and not fewer.within_tolerance
    assert fewer.max_deviation > tol
    assert "not met with 2 segments" in fewer.message


@pytest.mark.slow
def test_realistic_section_scan_reversed():
    """1.5 m section, uneven 0.01-11 mm, 0.05 mm noise: T = 0.25 mm met, order-independent."""
    pts, dense = section(seed=1)
    tol = 0.25
    res = fit_segments(pts, tol)
    check(res, pts, tol)
    assert res.single.max_deviation > tol
    assert 2 <= len(res.segments) <= 6
    # the chain follows the true curve, not the noise
    assert plain_distance(res.points, dense).max() < 0.12
    back = fit_segments(pts[::-1], tol)
    assert len(back.segments) == len(res.segments)
    assert back.max_deviation == pytest.approx(res.max_deviation, rel=1e-9)


def test_bad_arguments():
    pts = sample((0, 0, 1.0, 0.0, 0.03, 0.2, 0.6), 50)
    with pytest.raises(CurveError, match="tolerance must be > 0, got 0"):
        fit_segments(pts, 0.0)
    with pytest.raises(CurveError, match="max_segments"):
        fit_segments(pts, 0.1, max_segments=0)
    with pytest.raises(CurveError, match="points"):
        fit_segments(pts[:3], 0.1)


def cli():
    from curvesmith.cli import main
    from curvesmith.cli.fair import fair_command

    if "fair" not in main.commands:
        main.add_command(fair_command)
    return main


def test_cli_fair_segments_3d_scan_with_glitch(tmp_path):
    """fair --tolerance --max-segments on a tilted 3D section scan with a 5-point glitch off
    its plane: faired in the PCA plane, written in scan coordinates, every point's in-plane
    distance within T; the report lists segments and joints; too few segments exit 1 and
    write nothing."""
    pts2, _ = section(seed=2)
    rng = np.random.default_rng(8)
    q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    pts = np.column_stack([pts2, np.zeros(len(pts2))])
    j = len(pts) // 3
    pts[j : j + 5, 2] += 1.5  # a glitch off the plane
    pts = pts @ q.T + [800.0, -200.0, 350.0]
    src, out, rep = tmp_path / "scan.xyz", tmp_path / "out.csv", tmp_path / "r.json"
    np.savetxt(src, pts)
    tol = 0.25
    args = ["fair", str(src), "-o", str(out), "--tolerance", str(tol), "--report", str(rep)]
    png = tmp_path / "fit.png"
    result = CliRunner().invoke(cli(), [*args, "--max-segments", "8", "--plot", str(png)])
    assert result.exit_code == 0, result.output
    assert "discrete elastica segment(s) joined G1" in result.output
    assert png.stat().st_size > 20_000  # the three panels of plot.fit_figure
    faired = np.loadtxt(out, delimiter=",", skiprows=1)
    row = json.loads(rep.read_text())["curves"][0]
    assert row["within_tolerance"] and row["max_deviation"] <= tol
    assert len(row["segments"]) >= 2 and len(row["joints"]) == len(row["segments"]) - 1
    assert all(j["g1_defect"] < 1e-9 for j in row["joints"])
    assert {"params", "first", "last", "rms", "max_deviation"} <= set(row["segments"][0])
    # back in scan coordinates: the faired curve lies in the scan's plane
    plane = row["plane"]
    normal, origin = np.array(plane["normal"]), np.array(plane["origin"])
    assert np.abs((faired - origin) @ normal).max() < 1e-6
    inplane = (pts - origin) - np.outer((pts - origin) @ normal, normal)
    assert plain_distance(inplane, faired - origin).max() <= tol + 1e-9
    out.unlink()
    few = CliRunner().invoke(cli(), [*args, "--max-segments", "1"])
    assert few.exit_code == 1
    assert "need more than 1 segment (no output written)" in few.output
    assert len(few.output.strip().splitlines()) == 1 and "Traceback" not in few.output
    assert not out.exists()


def test_cli_max_segments_needs_tolerance(tmp_path):
    src = tmp_path / "c.csv"
    np.savetxt(
        src, sample((0, 0, 1.0, 0.0, 0.03, 0.2, 0.6), 50), delimiter=",", header="x,y", comments=""
    )
    r = CliRunner().invoke(cli(), ["fair", str(src), "-o", "-", "--max-segments", "3"])
    assert r.exit_code == 2 and "--max-segments needs --tolerance" in r.output
