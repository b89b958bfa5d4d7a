"""plot's figures draw the results' own numbers."""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
import pytest

from curvesmith import derham, plot


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    plt.close("all")


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
