"""Figures are drawn by ``curvesmith.plot``: the demo arranges and labels, never draws data.

Every figure a demo section makes is built from public ``plot`` functions that users can
call on their own results; the demo only lays out axes, titles, labels, legends and axis
formats. This test reads the demo's source and fails on any drawing call of matplotlib's
``Axes`` there (``ax.plot``, ``ax.scatter``, ``ax.imshow``, ``ax.annotate``, ...).
"""

from __future__ import annotations

import ast
from pathlib import Path

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
