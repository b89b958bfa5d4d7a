"""Results show themselves in Jupyter (issue 17.5): the example notebook runs headless.

``notebooks/results.ipynb`` is executed by nbclient in a fresh kernel; the last value of
every code cell that makes a result must come out as HTML holding an inline SVG figure and
the result's key numbers, as Jupyter would display it.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

nbformat = pytest.importorskip("nbformat")
nbclient = pytest.importorskip("nbclient")
pytest.importorskip("ipykernel")
pytest.importorskip("shapely")

NOTEBOOK = Path(__file__).resolve().parents[1] / "notebooks" / "results.ipynb"


@pytest.fixture(scope="module")
def executed():
    nb = nbformat.read(NOTEBOOK, as_version=4)
    nbclient.NotebookClient(nb, timeout=300, kernel_name="python3").execute()
    return [c for c in nb.cells if c.cell_type == "code"]


def _html(cell) -> str:
    outs = [o for o in cell.outputs if o.get("output_type") == "execute_result"]
    assert outs, cell.source
    return outs[-1]["data"]["text/html"]


@pytest.mark.slow
def test_every_result_cell_shows_a_figure_and_its_numbers(executed):
    kinds = {
        "CCAResult": ["vertices", "success"],
        "LengthResult": ["certified bracket", "level"],
        "Approximation": ["vertices", "end gap"],
        "FitResult": ["rms distance", "max distance", "noise level"],
        "KeylineFit": ["pieces fitted", "worst rms"],
        "CurveFit": ["segments", "max deviation"],
        "SmoothResult": ["features", "max area change"],
    }
    shown = {}
    for cell in executed[1:]:
        html = _html(cell)
        name = re.search(r"<b>(\w+)</b>", html).group(1)
        shown[name] = html
        assert "<svg" in html and "</svg>" in html, name
        for label in kinds[name]:
            assert f">{label}" in html, (name, label)
    assert set(shown) == set(kinds)
    # the numbers are the results' own: cca of a 40-gon, 2 passes, gives 360 vertices
    assert re.search(r">vertices</th><td[^>]*>360<", shown["CCAResult"])
    assert re.search(r">success</th><td[^>]*>True<", shown["CCAResult"])
    rms = float(re.search(r">rms distance</th><td[^>]*>([0-9.e+-]+)<", shown["FitResult"]).group(1))
    assert 0.02 < rms < 1.0  # 0.05 mm noise on a curve that is close to an elastica
    area = re.search(r">max area change</th><td[^>]*>([0-9.e+-]+)<", shown["SmoothResult"])
    assert float(area.group(1)) < 1e-12


def test_rich_repr_without_a_figure_still_shows_the_numbers(monkeypatch):
    """With matplotlib missing the HTML still holds the numbers (no figure)."""
    import builtins

    from curvesmith import cca

    real_import = builtins.__import__

    def no_plot(name, *args, **kwargs):
        if name.endswith("plot") and args and args[2] and "result_svg" in args[2]:
            raise ImportError("no matplotlib")
        return real_import(name, *args, **kwargs)

    res = cca.smooth_with_info(np.array([[0, 0], [2, 0], [2, 1], [0, 1.0]]), closed=True)
    monkeypatch.setattr(builtins, "__import__", no_plot)
    html = res._repr_html_()
    assert "<svg" not in html and ">vertices</th><td style='text-align:left'>12<" in html


def test_fit_figure_draws_both_kinds_of_fit():
    """plot.fit_figure: one row of three panels per fit, segments and joints for a chain."""
    from curvesmith import elastica, plot

    t = np.linspace(0.0, 2.0, 200)
    arc = 100.0 * np.c_[np.cos(t), np.sin(t)]
    x = np.linspace(0.0, 600.0, 300)  # an S with growing bends (mm): 4 segments within 0.3 mm
    wave = np.c_[x, 60.0 * np.sin(2 * np.pi * x / 600.0) + 80.0 * (x / 600.0) ** 4]
    single = elastica.fit(arc)
    chain = elastica.fit_segments(wave, 0.3)
    assert len(chain.segments) >= 2 and chain.within_tolerance
    fig = plot.fit_figure([(single, arc), (chain, chain.data)], labels=["arc", "chain"])
    assert len(fig.axes) == 6
    assert fig.axes[0].get_title().startswith("arc: case (")
    title = f"chain: {len(chain.segments)} elastica segments (within 0.3)"
    assert fig.axes[3].get_title() == title
    legend = [t.get_text() for t in fig.axes[3].get_legend().get_texts()]
    assert "fitted joints (G1)" in legend
    assert f"segment 1: k = {chain.segments[1].params.k:.3g}" in legend
