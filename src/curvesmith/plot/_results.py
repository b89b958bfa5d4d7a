"""The small figures that results show in notebooks (their rich representation)."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from ._core import _closed_xy, _draw_lines, _thin, bezier_comb
from ._derham import length_bracket
from ._geo import _geometry_lines

if TYPE_CHECKING:
    pass


def result_figure(result: Any, *, width: float = 3.4, height: float = 2.6):
    """A small figure of a method's result: the curve, the fit over its data, or the layer.

    What a notebook shows beside the numbers (``_repr_html_`` of the results): the
    smoothed or constructed curve (cca, de Rham, affine), the fitted elastica over its
    data points (elastica, keyline), the Bézier path with its curvature comb (curves), the
    bracket of a certified length against the level (de Rham lengths), and the features
    of a geo result. Returns a :class:`matplotlib.figure.Figure` (not attached to pyplot),
    or None for a result with nothing to draw.

    Examples
    --------
    >>> import numpy as np
    >>> from curvesmith import derham, plot
    >>> res = derham.length(np.array([[0, 0], [1, 1], [2, 0.0]]), gamma=3)
    >>> fig = plot.result_figure(res)
    >>> fig.axes[0].get_xlabel()
    'level n'
    """
    from matplotlib.figure import Figure

    name = type(result).__name__
    fig = Figure(figsize=(width, height))
    ax = fig.add_subplot()
    ax.tick_params(labelsize=7)
    r = result
    if name == "LengthResult":
        length_bracket(r, ax=ax)
        ax.xaxis.label.set_fontsize(8)
        ax.yaxis.label.set_fontsize(8)
        ax.legend(fontsize=7)
    elif name in ("CCAResult", "InterpolationResult", "ChainResult"):
        _draw_lines(ax, [r.points], color="tab:blue", lw=1)
    elif name == "RaggedCCAResult":
        off = np.asarray(r.offsets)
        lines = [r.coords[off[k] : off[k + 1]] for k in range(min(len(off) - 1, 3000))]
        _draw_lines(ax, lines, lw=0.8)
    elif name == "Approximation":
        _draw_lines(
            ax, [_closed_xy(r.points, bool(r.closed))], color="tab:blue", lw=1, marker="o", ms=2
        )
    elif name == "FitResult":
        data = _thin(np.asarray(r.data, dtype=float)[:, :2])
        ax.plot(data[:, 0], data[:, 1], ".", ms=2, color="0.5", label="data")
        _draw_lines(ax, [r.points], color="tab:red", lw=1, label="elastica")
        ax.legend(fontsize=7)
    elif name == "KeylineFit":
        _draw_lines(ax, [r.points], color="0.5", lw=0.8)
        fits = [f for f in (r.left, r.right, r.whole, *r.pieces) if f is not None]
        _draw_lines(ax, [f.points for f in fits], color="tab:red", lw=1)
    elif name == "CurveFit":
        bezier_comb(r.segments, closed=bool(r.closed), ax=ax)
        ax.set_title("")
    elif name in ("SmoothResult", "CoverageResult", "NetworkResult", "ContourResult"):
        _draw_lines(ax, _geometry_lines(r.geometry), color="tab:blue", lw=0.6)
    else:
        return None
    fig.tight_layout()
    return fig


def result_svg(result: Any) -> str | None:
    """:func:`result_figure` as an inline SVG document (what notebooks embed), or None."""
    import io

    import matplotlib

    fig = result_figure(result)
    if fig is None:
        return None
    buf = io.StringIO()
    with matplotlib.rc_context({"svg.fonttype": "none"}):
        fig.savefig(buf, format="svg")
    text = buf.getvalue()
    return text[text.index("<svg") :]
