"""plot's GIS figures: what is drawn is the layer's own coordinates, and the numbers are right."""

from __future__ import annotations

import numpy as np
import pytest

shapely = pytest.importorskip("shapely", reason="the GIS figures need the geo extra")

from curvesmith import CurveError, geo, plot  # noqa: E402


def _lines(ax):
    return [np.column_stack(line.get_data()) for line in ax.lines]


def test_draw_geometries_draws_every_ring_and_line_exactly():
    hole = shapely.Polygon([(0, 0), (10, 0), (10, 10), (0, 10)], [[(2, 2), (2, 4), (4, 4), (4, 2)]])
    multi = shapely.MultiPolygon([shapely.box(20, 0, 21, 1), shapely.box(22, 0, 23, 1)])
    line = shapely.LineString([(0, 20), (5, 25), (10, 20)])
    _fig, (ax,) = plot.new_axes()
    plot.draw_geometries(ax, [hole, None, multi, shapely.Polygon(), line], color="k", label="x")
    got = _lines(ax)
    rings = (hole.exterior, hole.interiors[0], multi.geoms[0].exterior, multi.geoms[1].exterior)
    want = [shapely.get_coordinates(g) for g in (*rings, line)]
    assert len(got) == 5
    for g, w in zip(got, want, strict=True):
        np.testing.assert_array_equal(g, w)
    assert [ln.get_label() for ln in ax.lines].count("x") == 1  # one legend entry


def test_window_clips_and_limits():
    rng = np.random.default_rng(3)
    pts = np.cumsum(rng.normal(size=(2000, 2)), axis=0) * 10 + [5e5, 4e6]  # metres, UTM-like
    _fig, (ax,) = plot.new_axes()
    window = (
        pts[:, 0].mean() - 50,
        pts[:, 1].mean() - 50,
        pts[:, 0].mean() + 50,
        pts[:, 1].mean() + 50,
    )
    plot.draw_geometries(ax, shapely.LineString(pts), window=window)
    assert ax.get_xlim() == pytest.approx(window[::2]) and ax.get_ylim() == pytest.approx(
        window[1::2]
    )
    drawn = np.vstack(_lines(ax))
    tol = 1e-6
    assert drawn[:, 0].min() >= window[0] - tol and drawn[:, 0].max() <= window[2] + tol
    assert drawn[:, 1].min() >= window[1] - tol and drawn[:, 1].max() <= window[3] + tol


def test_area_change_is_zero_for_cca_and_exact_for_chaikin():
    squares = [shapely.box(i * 10.0, 0, i * 10.0 + s, s) for i, s in enumerate([1, 2, 5, 0.01])]
    runs = {
        "cca": geo.smooth(squares, iterations=2),
        "chaikin": geo.smooth(squares, method="chaikin", iterations=1),
    }
    ax = plot.area_change(squares, runs)
    cca_x, chaikin_x = (line.get_xdata() for line in ax.lines)
    assert np.abs(cca_x).max() < 1e-10
    # one Chaikin step cuts 4 corner triangles of (s/4)^2 / 2 from an s x s square: 12.5 %
    np.testing.assert_allclose(chaikin_x, -12.5, rtol=1e-12)
    np.testing.assert_allclose(ax.lines[0].get_ydata(), np.linspace(0, 1, 4))
    assert [t.get_text() for t in ax.get_legend().get_texts()] == ["cca", "chaikin"]


def test_area_change_refuses_a_layer_of_another_length():
    squares = [shapely.box(0, 0, 1, 1), shapely.box(2, 0, 3, 1)]
    with pytest.raises(CurveError, match=r"after\['smoothed'\] must have one geometry per input"):
        plot.area_change(squares, squares[:1])


def test_layer_before_after_takes_results_frames_and_arrays():
    gpd = pytest.importorskip("geopandas")
    grid = [shapely.box(i, j, i + 1, j + 1) for i in range(4) for j in range(3)]
    df = gpd.GeoDataFrame({"id": range(12)}, geometry=grid, crs="EPSG:3857")
    res = geo.smooth_coverage(df, iterations=2, full_output=True)
    for after in (res, res.geometry, res.geometry.geometry, res.geometry.geometry.values):
        ax = plot.layer_before_after(df, after, title="t")
        assert len(ax.lines) == 24 and ax.get_title() == "t"
        np.testing.assert_array_equal(
            np.column_stack(ax.lines[12].get_data()),
            shapely.get_coordinates(res.geometry.geometry.values[0].exterior),
        )
