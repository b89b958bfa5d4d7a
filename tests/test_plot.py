"""plot's figures draw the results' own numbers."""

from __future__ import annotations

import numpy as np
import pytest

from curvesmith import derham, plot


def test_length_bracket_draws_the_sequences_of_a_result_and_of_length_sequences():
    poly = np.array([[-1.5, -1.0], [-0.4, 0.5], [0.6, 0.7], [1.5, 0.0]])
    res = derham.length(poly, gamma=2.0)
    ax = plot.length_bracket(res)
    up, lo, value = ax.lines
    np.testing.assert_array_equal(up.get_ydata(), res.upper_sequence)
    np.testing.assert_array_equal(lo.get_ydata(), res.lower_sequence)
    assert value.get_ydata()[0] == res.value
    assert (lo.get_ydata() <= res.value).all() and (up.get_ydata() >= res.value).all()

    seq = derham.length_sequences(poly, gamma=2.0, levels=10)
    exact = derham.parabola_length(poly)
    ax = plot.length_bracket(seq, exact=exact, levels=4)
    up, lo, line = ax.lines
    np.testing.assert_array_equal(up.get_xdata(), np.arange(5))
    np.testing.assert_array_equal(lo.get_ydata(), seq[0][:5])
    assert line.get_ydata()[0] == exact and "exact length" in line.get_label()


def test_elastica_fit_draws_data_start_and_fit():
    from curvesmith import elastica

    truth = elastica.sample((2.0, -1.0, 0.1, 0.3, 0.0, 0.2, 0.7), 60)
    noisy = truth + np.random.default_rng(5).normal(scale=1e-3, size=truth.shape)
    res = elastica.fit(noisy)
    for markers in (False, True):
        ax = plot.elastica_fit(res, markers=markers)
        data, start, fit = (np.column_stack(line.get_data()) for line in ax.lines)
        np.testing.assert_array_equal(data, res.data)
        np.testing.assert_array_equal(start, elastica.sample(res.start, res.data.shape[0]))
        np.testing.assert_array_equal(fit, res.points)
        assert ax.get_title().startswith(f"case ({res.case}), k = {res.params.k:.3f}")
    ax = plot.elastica_fit(res, start=False, title="t")
    assert len(ax.lines) == 2 and ax.get_title() == "t"


def test_keyline_figures_draw_the_estimate_and_the_side_fits():
    from curvesmith import keyline

    syn = keyline.synthetic_keyline(noise=0.02, seed=4)
    res = keyline.fit(syn.points, step=1.0)
    est = res.inflection
    ax = plot.inflection_estimate(res)
    poly, rdp, star = (np.column_stack(line.get_data()) for line in ax.lines)
    np.testing.assert_array_equal(poly, res.points)
    np.testing.assert_array_equal(rdp, res.points[list(est.labels)])
    np.testing.assert_array_equal(star[0], res.points[est.index])
    assert [t.get_text() for t in ax.texts] == [
        str(k) for k in range(1, min(9, len(est.labels)) + 1)
    ]
    ax = plot.keyline_fit(res)
    drawn = [np.column_stack(line.get_data()) for line in ax.lines]
    assert len(drawn) == len(res.sides) + 2
    for (_, fit), got in zip(res.sides, drawn[1:-1], strict=True):
        np.testing.assert_array_equal(got, fit.points)


def test_affine_approximation_draws_polyline_spline_and_joins():
    from curvesmith import affine

    t = np.linspace(0.0, 1.0, 800)
    s_curve = np.column_stack([12 * t, 3 * np.sin(2 * np.pi * t)])  # one inflection
    res = affine.approximate(s_curve, vertices=40)
    ax = plot.affine_approximation(res, s_curve, title="t")
    curve, poly, spline, *joins = (np.column_stack(line.get_data()) for line in ax.lines)
    np.testing.assert_array_equal(curve, s_curve)
    np.testing.assert_array_equal(poly, res.points)
    s = affine.bspline(res.points)
    np.testing.assert_allclose(spline[[0, -1]], s([s.t[2], s.t[-3] - 1e-12]), atol=1e-9)
    assert len(joins) == len(res.joins) >= 1
    for j, marker in zip(res.joins, joins, strict=True):
        np.testing.assert_array_equal(marker[0], res.points[j])
    window = (5.0, -1.0, 7.0, 1.0)
    ax = plot.affine_approximation(res, window=window)
    assert ax.get_xlim() == (5.0, 7.0) and ax.get_ylim() == (-1.0, 1.0)


def test_alpha_profile_draws_the_profile_through_table_1():
    from curvesmith import cca

    ax = plot.alpha_profile(title="t")
    profile, eq5, nodes = ax.lines
    deg, alpha = profile.get_data()
    np.testing.assert_array_equal(alpha, cca.alpha_profile(np.deg2rad(deg)))
    want_x, want_y = cca.profile_nodes()
    np.testing.assert_allclose(nodes.get_xdata(), np.rad2deg(want_x))
    np.testing.assert_array_equal(nodes.get_ydata(), want_y)
    # the regular-polygon values of eq. (5) lie on the profile at n = 4, 6, 12 (Table 1)
    for n in (4, 6, 12):
        interior = np.pi * (n - 2) / n
        k = np.argmin(np.abs(np.deg2rad(eq5.get_xdata()) - interior))
        assert eq5.get_ydata()[k] == pytest.approx(
            cca.alpha_profile(np.deg2rad(eq5.get_xdata()[k])), abs=2e-3
        )
    assert ax.get_title() == "t"
