"""The global fit on realistic scans (issue 11): order, noise, degenerate curves, quality.

Curves from ``tests/elastica_curves.py``: car-body-like C sections, 1.5 m in mm, uneven
spacing 0.001-11 mm, noise up to 0.3 mm, reversed order, a 5-point glitch.
"""

import itertools
import math
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).parent))
from curvesmith.elastica import ElasticaParams, fit, sample
from curvesmith.errors import CurveError
from curvesmith.internals import chord_walk, point_polyline_distance, walk_to_end
from curvesmith.internals import noise_level as _noise_level
from curvesmith.internals import resample_walk as _resample_walk
from curvesmith.internals import reverse_params as _reverse_params
from curvesmith.internals import savgol as _savgol
from elastica_curves import reference_fit, scan


def brute_distance(x, poly):
    """Plain reference: every point against every segment."""
    best = np.full(len(x), np.inf)
    for a, b in itertools.pairwise(poly):
        d = b - a
        t = np.clip((x - a) @ d / (d @ d), 0.0, 1.0)
        best = np.minimum(best, np.linalg.norm(x - (a + t[:, None] * d), axis=1))
    return best


@pytest.mark.parametrize("shape", ["clothoid", "bezier", "elastica_error"])
def test_reversed_input_gives_the_same_curve(shape):
    pts = scan(shape, noise=0.05, seed=3)
    a = fit(pts, resample=True)
    b = fit(pts[::-1], resample=True)
    assert a.success and b.success
    np.testing.assert_allclose(b.points[::-1], a.points, rtol=0, atol=1e-6)
    assert b.rms == pytest.approx(a.rms, rel=1e-9)
    np.testing.assert_array_equal(b.data[::-1], a.data)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_stays_in_the_basin_under_scanner_noise(seed):
    """0.3 mm noise on a 1.5 m elastica-like section: the fit stays within a fraction of a
    mm of the fit of the noise-free scan (a wrong basin is off by millimetres)."""
    clean = fit(scan("elastica_error", seed=seed), resample=True)
    noisy = fit(scan("elastica_error", noise=0.3, glitch=True, seed=seed), resample=True)
    assert noisy.success and noisy.case == "i"
    dev = point_polyline_distance(noisy.points, clean.points)
    assert dev[3:-3].max() < 0.3 and dev.max() < 1.0, dev.max()  # the noisy ends move most
    assert noisy.rms_deviation < 0.45  # noise 0.3 per coordinate, model error 0.03


def test_model_error_is_success_with_a_message_that_says_so():
    res = fit(scan("clothoid", seed=1), resample=True)
    assert res.success
    assert "converged" in res.message and "model error" in res.message
    assert res.rms > 100 * res.noise
    # the geometric deviation is measured on the input points, not index-paired
    raw = scan("clothoid", seed=1)
    np.testing.assert_allclose(res.deviation, brute_distance(raw, res.points), atol=1e-9)
    assert res.max_deviation == pytest.approx(res.deviation.max())
    tight = fit(scan("clothoid", seed=1), resample=True, tolerance=1.0)
    loose = fit(scan("clothoid", seed=1), resample=True, tolerance=3.0)
    assert tight.within_tolerance is False and "exceeds the tolerance 1" in tight.message
    assert loose.within_tolerance is True and res.within_tolerance is None


def test_fit_spans_the_data_end_to_end_and_drops_repeats():
    pts = scan("bezier", seed=4)
    pts = np.insert(pts, [10, 10, 200], pts[[10, 10, 200]], axis=0)  # repeated points
    res = fit(pts, resample=True)
    np.testing.assert_array_equal(res.data[0], pts[0])
    np.testing.assert_array_equal(res.data[-1], pts[-1])
    chords = np.hypot(*np.diff(res.data, axis=0).T)
    assert np.ptp(chords) < 1e-6 * chords.mean()  # the last chord is equal to the others too
    assert res.max_deviation < 0.7  # model error of the Bezier section, no lost tail


@pytest.mark.parametrize(
    ("radius", "turn", "n", "uneven"),
    [
        (3.0, 2.6, 120, False),
        (500.0, 0.2, 40, False),
        (0.01, 6.0, 300, False),
        (40.0, 4.0, 0, True),
    ],
)
def test_circle_arcs_fit_exactly(radius, turn, n, uneven):
    rng = np.random.default_rng(1)
    if uneven:
        t = np.sort(np.concatenate([[0.0, turn], rng.uniform(0, turn, 400)]))
    else:
        t = np.linspace(0.0, turn, n)
    pts = np.column_stack([7 + radius * np.cos(t), -3 + radius * np.sin(t)])
    res = fit(pts, resample=uneven)
    # resampled, the data are chords of the input polygon (sagitta < 1e-4 radius here)
    exact = (1e-4 if uneven else 1e-9) * radius
    assert res.success and res.case == "circle"
    assert res.max_deviation < exact
    np.testing.assert_allclose(sample(res.params, res.data.shape[0]), res.points, atol=1e-12)
    back = fit(pts[::-1], resample=uneven)  # clockwise
    assert back.case == "circle" and back.max_deviation < exact


def test_straight_lines_fit_exactly():
    t = np.linspace(0.0, 1500.0, 751)
    pts = np.column_stack([12.0 + 0.6 * t, -4.0 + 0.8 * t])
    res = fit(pts)
    assert res.success and res.case == "line" and res.max_deviation < 1e-9
    assert res.params.h == pytest.approx(2.0, rel=1e-12)
    assert res.params.phi == pytest.approx(math.atan2(0.8, 0.6), abs=1e-12)
    uneven = fit(pts[np.r_[0:100:3, 100:751]], resample=True)
    assert uneven.case == "line" and uneven.max_deviation < 1e-9


def test_reverse_params_draw_the_reversed_curve():
    for p in [(1, 2, 0.1, 0.3, 0.05, 0.2, 0.6), (0, 0, 1.0, -2.0, 0.002, 1.0, 3.0)]:
        np.testing.assert_allclose(
            sample(_reverse_params(ElasticaParams(*p), 90), 90),
            sample(p, 90)[::-1],
            atol=1e-9,
        )


def test_savgol_weights_equal_scipy_signal():
    from scipy.signal import savgol_coeffs

    for window, order in ((7, 3), (5, 2)):
        np.testing.assert_allclose(_savgol(window, order), savgol_coeffs(window, order), atol=1e-14)
    clean = sample((0.0, 0.0, 0.1, 0.3, 0.05, 0.2, 0.6), 400)
    assert _noise_level(clean) < 1e-3 * 0.1


def test_point_polyline_distance_matches_brute_force():
    rng = np.random.default_rng(7)
    poly = np.cumsum(rng.normal(size=(300, 2)), axis=0)
    x = poly[rng.integers(0, 300, 500)] + rng.normal(scale=3.0, size=(500, 2))
    np.testing.assert_allclose(
        point_polyline_distance(x, poly), brute_distance(x, poly), atol=1e-12
    )


def test_chord_walk_matches_the_geometry_walk():
    rng = np.random.default_rng(2)
    poly = np.cumsum(rng.normal(size=(400, 2)), axis=0)
    ours, rest = chord_walk(poly, 0.8)
    np.testing.assert_allclose(ours, _resample_walk(poly, 0.8), atol=1e-9)
    assert 0 <= rest < 0.8 + 1e-12
    t = np.linspace(0.0, 3.0, 700) ** 1.5
    smooth = np.column_stack([t, np.sin(t)])
    ends = walk_to_end(smooth, 0.05)
    np.testing.assert_array_equal(ends[-1], smooth[-1])
    chords = np.hypot(*np.diff(ends, axis=0).T)
    assert np.ptp(chords) < 1e-6


def test_bad_tolerance():
    with pytest.raises(CurveError, match="tolerance must be > 0"):
        fit(sample((0, 0, 0.1, 0.3, 0.05, 0.2, 0.6), 30), tolerance=-1.0)


@pytest.mark.slow
@pytest.mark.parametrize("shape", ["bezier", "elastica_error"])
def test_default_fit_within_15_percent_of_the_exhaustive_reference(shape):
    """Target of issue 11 (all five shapes and three variants: benchmarks/bench_elastica_global.py)."""
    pts = scan(shape, noise=0.1, reverse=True, glitch=True, seed=5)
    res = fit(pts, resample=True)
    ref_rms, _ = reference_fit(res.data, thorough=False)
    assert res.rms <= 1.15 * ref_rms, (res.rms, ref_rms)


@pytest.mark.slow
def test_uneven_tilted_section_scan_is_not_fitted_by_a_circle():
    # Regression (found as a user): a 1.5 m section, spacing 0.01-17 mm, 0.1 mm noise in 3D,
    # reversed order, fitted in its PCA plane. The best elastica (rms 0.089 mm) stopped at
    # the evaluation cap and lost to the closed-form circle (rms 3.04 mm), which always counts
    # as converged; the search now picks by rms and gives the best basin one more full solve.
    from curvesmith import elastica, geometry

    rng = np.random.default_rng(7)
    s = np.sort(rng.uniform(0, 1500, 700))
    s[0], s[-1] = 0.0, 1500.0
    k = 1 / 900 + 1 / 2500 * np.sin(s / 700)
    th = np.concatenate([[0], np.cumsum(0.5 * (k[1:] + k[:-1]) * np.diff(s))])
    x = np.concatenate([[0], np.cumsum(np.cos(th[:-1]) * np.diff(s))])
    y = np.concatenate([[0], np.cumsum(np.sin(th[:-1]) * np.diff(s))])
    c, si = np.cos(0.4), np.sin(0.4)
    p = np.c_[x, y, np.zeros_like(x)] @ np.array([[1, 0, 0], [0, c, -si], [0, si, c]]).T
    p = (p + np.array([120.0, -40.0, 300.0]) + rng.normal(0, 0.1, (len(x), 3)))[::-1]
    centre, axes, _ = geometry.pca_frame(p)
    q = (p - centre) @ axes[:2].T
    fit = elastica.fit(q, resample=True)
    assert fit.case not in ("line", "circle")
    assert fit.success
    assert fit.rms < 0.12  # the noise is 0.1 mm per axis; the circle's rms was 3.04 mm
    assert fit.total_iterations < 1000  # seven-parameter solves: 15,986 (variable projection)


@pytest.mark.parametrize(
    "p",
    [
        (0.0, 0.0, 0.1, 0.4, 0.2, 0.3, 0.99),  # case (ii), two periods before the middle
        (1.0, 2.0, 0.1, 0.4, 0.05, 5.3, 0.7),
        (1.0, 2.0, 2.0, 0.4, -0.0016, -8.3, 1.0014),  # the section scan's basin, k > 1
        (0.0, 0.0, 0.1, 0.3, 0.06, 40.0, 3.0),  # 43 periods
        (0.0, 0.0, 0.1, 0.3, 0.02, 0.4, 0.3),
    ],
)
@pytest.mark.parametrize("anchored", [False, True])
def test_variable_projection_jacobian_and_period(p, anchored):
    """On exact data the projected residual vanishes and Kaufman's Jacobian is its exact
    derivative (the dropped Golub-Pereyra term is proportional to the residual): central
    differences agree. The period P(k) that re-centres the phase leaves the curve unchanged."""
    from curvesmith.internals import elastica_varpro as varpro
    from curvesmith.internals import elastica_varpro_period as varpro_period

    p = ElasticaParams(*p)
    data = sample(p, 200)
    prob = varpro.Reduced(data, p, complex(p.x0, p.y0) if anchored else None)
    theta = prob.theta(p)
    np.testing.assert_allclose(prob.zqk(theta), (p.z, p.q, p.k), rtol=1e-13, atol=1e-13)
    assert np.abs(prob.residuals(theta)).max() < 1e-9 * p.h
    np.testing.assert_allclose(np.array(prob.params(theta)), np.array(p), atol=1e-9)
    jac = prob.jacobian_columns(theta)
    for i in range(3):
        step = 1e-6 * max(1.0, abs(theta[i]))
        up, down = theta.copy(), theta.copy()
        up[i] += step
        down[i] -= step
        fd = (prob.residuals(up) - prob.residuals(down)) / (2 * step)
        assert np.abs(fd - jac[i]).max() <= 1e-5 * np.abs(fd).max(), i
    shifted = p._replace(q=p.q + varpro_period(p.k) / p.k)
    np.testing.assert_allclose(sample(shifted, 200), data, atol=1e-12 * max(1.0, p.h * 200))


def test_variable_projection_matches_the_seven_parameter_optimum():
    """From a perturbed start the projected solve and the seven-parameter LM reach the same
    optimum of eq. (4.8) on noisy data (cost to 1e-10, curve to 1e-8 of h)."""
    import importlib

    from curvesmith.internals import elastica_varpro as varpro

    fm = importlib.import_module("curvesmith.elastica.fit")
    rng = np.random.default_rng(4)
    for p in [(0.3, -0.2, 0.05, 0.3, 0.06, 0.4, 0.7), (0.0, 0.0, 1.0, 0.1, 0.004, 0.3, 2.5)]:
        p = ElasticaParams(*p)
        data = sample(p, 150) + rng.normal(scale=0.005 * p.h, size=(150, 2))
        start = p._replace(z=p.z * 1.02, q=p.q + 0.05, k=p.k * 1.03, h=p.h * 0.98)
        reduced, _, status = varpro.solve(data, start, None, 5000, 1e-12)
        full, _, ok, _ = fm._solve(data, start, {}, "lsq", 5000, 1e-12)
        assert status == "converged" and ok
        assert fm._rms(data, reduced) == pytest.approx(fm._rms(data, full), rel=1e-10)
        np.testing.assert_allclose(sample(reduced, 150), sample(full, 150), atol=1e-8 * p.h)
