"""Figures are drawn by ``curvesmith.plot``: the demo arranges and labels, never draws data.

Every figure a demo section makes is built from public ``plot`` functions that users can
call on their own results; the demo only lays out axes, titles, labels, legends and axis
formats. This test reads the demo's source and fails on any drawing call of matplotlib's
``Axes`` there (``ax.plot``, ``ax.scatter``, ``ax.imshow``, ``ax.annotate``, ...).
"""

from __future__ import annotations

import ast
from pathlib import Path

import numpy as np
import pytest

import curvesmith.demo

DEMO = Path(curvesmith.demo.__file__).parent
DRAWING = {
    "plot", "scatter", "imshow", "annotate", "axvline", "axhline", "axvspan", "axhspan",
    "add_patch", "add_collection", "add_line", "fill", "fill_between", "bar", "barh", "hist",
    "contour", "contourf", "pcolormesh", "quiver", "errorbar", "step", "stem", "text",
    "semilogy", "semilogx", "loglog", "plot_surface", "plot_wireframe", "arrow",
}  # fmt: skip


def _drawing_calls(source: str) -> list[str]:
    found = []
    for node in ast.walk(ast.parse(source)):
        if not (isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute)):
            continue
        owner = node.func.value
        if node.func.attr in DRAWING and not (isinstance(owner, ast.Name) and owner.id == "ctx"):
            found.append(f"line {node.lineno}: {ast.unparse(node.func)}(...)")
    return found


@pytest.mark.parametrize("path", sorted(DEMO.glob("*.py")), ids=lambda p: p.name)
def test_demo_draws_only_through_plot(path):
    assert _drawing_calls(path.read_text(encoding="utf-8")) == []


def test_the_check_finds_a_drawing_call():
    """The check itself: raw matplotlib is found, the report's ``ctx.text`` is not."""
    source = (
        "def run(ctx, ax):\n    ctx.text('ok')\n    ax.plot([0, 1])\n    ax.twinx().fill(x, y)\n"
    )
    assert _drawing_calls(source) == ["line 3: ax.plot(...)", "line 4: ax.twinx().fill(...)"]


@pytest.fixture
def ax():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots()
    yield ax
    plt.close(fig)


def test_hillshade_is_north_up_whatever_the_row_order(ax):
    """A DEM stored south-up (y increasing) is drawn like the same DEM stored north-up."""
    from curvesmith import plot

    yy, xx = np.mgrid[0:30, 0:40] * 25.0
    z = 3.0 * xx + 0.02 * (yy - 300.0) ** 2
    plot.hillshade(z, xx[0], yy[:, 0], ax=ax)
    plot.hillshade(z[::-1], xx[0], yy[::-1, 0], ax=ax)
    a, b = (np.asarray(im.get_array()) for im in ax.images)
    assert np.array_equal(a, b)
    assert ax.images[0].get_extent() == ax.images[1].get_extent() == [-12.5, 987.5, -12.5, 737.5]


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (lambda ax, p: p.hillshade(np.zeros((3, 4)), np.arange(3), np.arange(3), ax=ax), "x and y"),
        (lambda ax, p: p.hillshade(np.zeros(5), ax=ax), "2-D array"),
        (
            lambda ax, p: p.hillshade(np.zeros((3, 4)), [0, 2, 1, 3], np.arange(3), ax=ax),
            "strictly monotone",
        ),
        (lambda ax, p: p.mark_points(ax, [[0, 0], [1, 1]], names=["A"]), "names must have"),
        (lambda ax, p: p.window_box(ax, (1, 0, 0, 1)), "window must be"),
        (lambda ax, p: p.keyline_sides({}, side="top", ax=ax), "side"),
        (lambda ax, p: p.z_profile(np.zeros((4, 2)), np.zeros((4, 3)), ax=ax), "before[0]"),
        (
            lambda ax, p: p.scaling({"cca": ([10, 100], [1e-6])}, ax=ax),
            "series['cca'] must have as many costs as sizes, got 2 sizes and 1 costs",
        ),
        (
            lambda ax, p: p.scaling({"cca": ([10, 100], [1e-6, 0.0])}, ax=ax),
            "series['cca'] must hold positive finite sizes and costs, got size 100.0 with cost 0.0",
        ),
        (
            lambda ax, p: p.scaling({"x": ([np.nan], [1.0])}, ax=ax),
            "series['x'] must hold positive finite sizes and costs, got size nan",
        ),
    ],
)
def test_bad_arguments_name_themselves(ax, call, message):
    from curvesmith import plot
    from curvesmith.errors import CurveError

    with pytest.raises(CurveError, match=message.replace("[", r"\[")):
        call(ax, plot)


def test_z_profile_rejects_lines_without_heights(ax):
    shapely = pytest.importorskip("shapely", reason="shapely is in the geo extra")
    from curvesmith import plot
    from curvesmith.errors import CurveError

    flat = shapely.LineString([(0, 0), (1, 1), (2, 0)])
    with pytest.raises(CurveError, match="must be lines with Z"):
        plot.z_profile(flat, flat, ax=ax)


def test_affine_curvature_of_a_closed_curve_wraps_at_the_seam(ax):
    """Closed: kappa_i^m of x_(i-1)..x_(i+2) at their mean parameter, unwrapped across t = N."""
    from curvesmith import affine, plot
    from curvesmith.errors import CurveError

    th = np.linspace(0, 2 * np.pi, 1200, endpoint=False)
    ring = np.c_[2 * np.cos(th) + 0.15 * np.cos(2 * th), np.sin(th) + 0.1 * np.sin(2 * th)]
    res = affine.approximate(ring, vertices=30, closed=True)
    plot.affine_curvature(res, samples=1200, ax=ax)
    u, k = ax.lines[0].get_data()
    assert u.size == k.size == 30 and np.all((u >= 0) & (u < 1))
    t = np.r_[res.t[-1] - 1200, res.t, res.t[:2] + 1200]
    assert u[0] == pytest.approx(((t[0] + t[1] + t[2] + t[3]) / 4 % 1200) / 1200)
    with pytest.raises(CurveError, match="samples is required"):
        plot.affine_curvature(res, ax=ax)


def test_scaling_draws_the_costs_as_given_on_log_axes(ax):
    from curvesmith import plot

    plot.scaling(
        {"one call": ([200, 20_000], [4.0, 2.5]), "a call each": ([200], [50.0])},
        ax=ax,
        xlabel="polygons",
        ylabel="µs per polygon",
        title="t",
    )
    (x0, y0), (x1, y1) = (line.get_data() for line in ax.lines)
    assert x0.tolist() == [200, 20_000] and y0.tolist() == [4.0, 2.5]
    assert x1.tolist() == [200] and y1.tolist() == [50.0]
    assert (ax.get_xscale(), ax.get_yscale()) == ("log", "log")
    assert [t.get_text() for t in ax.get_legend().get_texts()] == ["one call", "a call each"]
    assert (ax.get_xlabel(), ax.get_ylabel(), ax.get_title()) == ("polygons", "µs per polygon", "t")
