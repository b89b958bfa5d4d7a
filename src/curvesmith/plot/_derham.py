"""Figures of de Rham curves (Merrien): the certified length bracket."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from ._core import new_axes

if TYPE_CHECKING:
    from matplotlib.axes import Axes


def length_bracket(
    bounds: Any,
    *,
    exact: float | None = None,
    levels: int | None = None,
    ax: Axes | None = None,
    title: str | None = None,
) -> Axes:
    """The certified bracket ``l^n <= L <= L^n`` of a de Rham length against the level.

    Parameters
    ----------
    bounds : LengthResult or (lower, upper)
        :func:`curvesmith.derham.length`'s result, or the two sequences of
        :func:`curvesmith.derham.length_sequences`.
    exact : float, optional
        A known length, drawn as a horizontal line (e.g. ``derham.parabola_length``).
    levels : int, optional
        Draw the first ``levels + 1`` levels only (the bounds meet quickly).
    ax : matplotlib Axes, optional
    title : str, optional

    Returns
    -------
    matplotlib Axes

    Examples
    --------
    >>> import numpy as np
    >>> from curvesmith import derham, plot
    >>> res = derham.length(np.array([[0, 0], [1, 1], [2, 0.0]]), gamma=3)
    >>> ax = plot.length_bracket(res)
    >>> [t.get_text() for t in ax.get_legend().get_texts()]
    ['$L^n$ (polygon)', '$l^n$ (midpoint polygon)', 'value 1.20396']
    """
    if ax is None:
        _, (ax,) = new_axes()
    if hasattr(bounds, "lower_sequence"):
        lower, upper = bounds.lower_sequence, bounds.upper_sequence
        value = float(bounds.value) if exact is None else None
    else:
        lower, upper = bounds
        value = None
    lo, up = np.asarray(lower, dtype=float), np.asarray(upper, dtype=float)
    if levels is not None:
        lo, up = lo[: levels + 1], up[: levels + 1]
    n = np.arange(lo.size)
    ax.plot(n, up, "v-", ms=4, label="$L^n$ (polygon)")
    ax.plot(n, lo, "^-", ms=4, label="$l^n$ (midpoint polygon)")
    if exact is not None:
        ax.axhline(exact, color="k", lw=0.8, label=f"exact length {exact:.10f}")
    elif value is not None:
        ax.axhline(value, color="0.5", lw=0.8, ls="--", label=f"value {value:.6g}")
    ax.set_xlabel("level n")
    ax.set_ylabel("length")
    if title:
        ax.set_title(title)
    ax.legend(fontsize=8)
    return ax
