"""Figures of corner cutting and augmentation (Gordon): the alpha profile."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ._core import new_axes

if TYPE_CHECKING:
    from matplotlib.axes import Axes


#: What each Table 1 control point is (Gordon), and where its label sits (points).
_TABLE1_NAMES = ("0", "40 deg control", "n=3 (9-gon aspect 1)", "n=4", "n=6", "n=12", "limit")
_TABLE1_OFFSETS = ((6, 4), (6, -22), (6, 6), (6, -22), (4, -24), (-6, -26), (-34, -26))


def alpha_profile(
    *, annotate: bool = False, ax: Axes | None = None, title: str | None = None
) -> Axes:
    """CCA's "regular" alpha profile against the interior angle (Gordon, Table 1, Fig. 14).

    The PCHIP profile :func:`curvesmith.cca.alpha_profile` that ``alpha="regular"``
    uses, through the Table 1 control points, and eq. (5)'s regular-polygon value for
    every half-angle beside it.

    Parameters
    ----------
    annotate : bool, optional
        Name every control point (the polygon its value comes from) with its value.
    ax : matplotlib Axes, optional
    title : str, optional

    Returns
    -------
    matplotlib Axes

    Examples
    --------
    >>> from curvesmith import plot
    >>> ax = plot.alpha_profile(annotate=True)
    >>> [line.get_label() for line in ax.lines]
    ['"regular" profile (PCHIP)', 'eq. (5) for every half-angle', 'Table 1 control points']
    >>> ax.texts[3].get_text().split()
    ['n=4', '0.211325']
    """
    from .. import cca

    if ax is None:
        _, (ax,) = new_axes(width=6.5, height=4.3)
    deg = np.linspace(0, 180, 721)
    ax.plot(deg, cca.alpha_profile(np.deg2rad(deg)), lw=1.8, label='"regular" profile (PCHIP)')
    beta = np.linspace(np.pi / 6, np.pi / 2, 200)
    ax.plot(
        np.rad2deg(2 * beta),
        cca.solve_regular_alpha(beta),
        "--",
        lw=1.0,
        color="0.4",
        label="eq. (5) for every half-angle",
    )
    nodes, values = cca.profile_nodes()
    ax.plot(np.rad2deg(nodes), values, "o", color="C3", label="Table 1 control points")
    if annotate:
        for x, v, name, off in zip(
            np.rad2deg(nodes), values, _TABLE1_NAMES, _TABLE1_OFFSETS, strict=True
        ):
            ax.annotate(
                f"{name}\n{v:.6g}", (x, v), textcoords="offset points", xytext=off, fontsize=7
            )
    ax.set_xlabel("interior angle (degrees)")
    ax.set_ylabel("alpha")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="lower right")
    if title:
        ax.set_title(title)
    return ax
