"""Matplotlib figures shared by the demo, the CLI and users: overlays, curvature combs, convergence.

Functions draw into a given ``Axes`` (or create a figure) and return the
``Axes``; they never call ``plt.show``. Curves are drawn with equal axis
scaling.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike

from . import geometry
from ._validate import as_points

if TYPE_CHECKING:
    from matplotlib.axes import Axes

__all__ = [
    "affine_approximation",
    "alpha_profile",
    "area_change",
    "before_after",
    "bezier_comb",
    "comb_before_after",
    "convergence",
    "curvature_along",
    "curvature_comb",
    "deviation_along",
    "draw_curve",
    "draw_geometries",
    "elastica_fit",
    "fit_figure",
    "fit_panels",
    "inflection_estimate",
    "keyline_fit",
    "layer_before_after",
    "length_bracket",
    "new_axes",
    "result_figure",
    "result_svg",
]


def new_axes(ncols: int = 1, *, width: float = 5.5, height: float = 4.5):
    """Create a figure with `ncols` side-by-side axes; return ``(fig, axes)``."""
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, ncols, figsize=(width * ncols, height), squeeze=False)
    return fig, list(axes[0])


def _closed_xy(p: np.ndarray, closed: bool) -> np.ndarray:
    return np.vstack([p, p[:1]]) if closed else p


def draw_curve(
    ax: Axes,
    points: ArrayLike,
    *,
    closed: bool,
    label: str | None = None,
    markers: bool = False,
    **kw,
):
    """Draw a polyline or polygon (closing edge included when `closed`)."""
    p = as_points(points, closed=closed, min_points=2)
    xy = _closed_xy(p, closed)
    style: dict[str, Any] = {"marker": "o", "markersize": 3} if markers else {}
    style.update(kw)
    ax.plot(xy[:, 0], xy[:, 1], label=label, **style)
    ax.set_aspect("equal", adjustable="box")
    return ax


def _describe(p: np.ndarray, closed: bool) -> str:
    length = geometry.curve_length(p, closed=closed)
    text = f"length {length:.6g}"
    if len(p) >= 3:
        area = geometry._signed_area(p)
        text += f", {'area' if closed else 'area vs chord'} {area:.6g}"
    return text


def before_after(
    before: ArrayLike,
    after: Sequence | np.ndarray,
    *,
    closed: bool,
    labels: Sequence[str] = ("before", "after"),
    title: str | None = None,
    ax: Axes | None = None,
):
    """Overlay a curve before and after an operation, annotating length and area.

    Parameters
    ----------
    before : (N, 2) array_like
        Input curve, drawn with its vertices.
    after : (M, 2) array_like or list of them
        One or several results, each drawn and labelled.
    closed : bool
        Whether the curves are closed.
    labels : sequence of str
        Legend labels: the first for `before`, the rest for `after`.
    title : str, optional
        Axes title.
    ax : matplotlib Axes, optional
        Target axes (a new figure otherwise).

    Returns
    -------
    matplotlib Axes
    """
    if ax is None:
        _, (ax,) = new_axes()
    p0 = as_points(before, closed=closed, min_points=2)
    afters = [after] if isinstance(after, np.ndarray) and np.ndim(after) == 2 else list(after)
    if afters and np.ndim(afters[0]) == 1:  # a single curve given as a list of points
        afters = [np.asarray(after)]
    draw_curve(
        ax,
        p0,
        closed=closed,
        markers=True,
        color="0.55",
        lw=1.0,
        label=f"{labels[0]}: {len(p0)} pts, {_describe(p0, closed)}",
    )
    for i, a in enumerate(afters):
        pa = as_points(a, closed=closed, min_points=2)
        name = labels[i + 1] if i + 1 < len(labels) else f"result {i + 1}"
        draw_curve(
            ax, pa, closed=closed, lw=1.6, label=f"{name}: {len(pa)} pts, {_describe(pa, closed)}"
        )
    ax.set_xlabel("x")
    ax.set_ylabel("y")
    if title:
        ax.set_title(title)
    _legend_below(ax)
    return ax


def _legend_below(ax) -> None:
    # Below the x label whatever the axes' height: anchored to the bottom of the tight
    # bounding box of the axes and its labels (call after setting the labels).
    fig = ax.figure
    ax.apply_aspect()  # equal-aspect axes shrink at draw time; measure the final box
    renderer = fig.canvas.get_renderer()
    box = ax.get_tightbbox(renderer).transformed(ax.transAxes.inverted())
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, box.y0 - 0.02), fontsize=8, frameon=False)


def curvature_comb(
    points: ArrayLike,
    curvature: ArrayLike | None = None,
    *,
    closed: bool,
    scale: float | None = None,
    ax: Axes | None = None,
    title: str | None = None,
    color: str = "tab:red",
):
    """Draw a curvature comb: at each vertex a tooth along the normal of length ``-scale * kappa``.

    Parameters
    ----------
    points : (N, 2) array_like
        Curve vertices.
    curvature : (N,) or (N - 2,) array_like, optional
        Signed curvature per vertex (interior vertices for open curves);
        default :func:`curvesmith.geometry.menger_curvature`.
    closed : bool
        Whether the curve is closed.
    scale : float, optional
        Tooth length per unit curvature; default makes the longest tooth 15 %
        of the curve's bounding-box diagonal.
    ax : matplotlib Axes, optional
    title : str, optional
    color : str, optional

    Returns
    -------
    matplotlib Axes
    """
    if ax is None:
        _, (ax,) = new_axes()
    p = as_points(points, closed=closed, min_points=3, distinct=True)
    k = (
        geometry.menger_curvature(p, closed=closed)
        if curvature is None
        else np.asarray(curvature, float)
    )
    mid = p if closed else p[1:-1]
    if k.shape[0] != mid.shape[0]:
        from .errors import CurveError

        raise CurveError(f"curvature must have {mid.shape[0]} values, got {k.shape[0]}")
    prev = np.roll(p, 1, axis=0) if closed else p[:-2]
    nxt = np.roll(p, -1, axis=0) if closed else p[2:]
    t = nxt - prev
    t /= np.maximum(np.linalg.norm(t, axis=1, keepdims=True), 1e-300)
    n = np.c_[-t[:, 1], t[:, 0]]  # left normal
    if scale is None:
        diag = float(np.linalg.norm(p.max(axis=0) - p.min(axis=0)))
        kmax = float(np.max(np.abs(k))) if k.size else 0.0
        scale = 0.15 * diag / kmax if kmax > 0 else 0.0
    tips = mid - scale * k[:, None] * n  # teeth point away from the centre of curvature
    from matplotlib.collections import LineCollection

    ax.add_collection(
        LineCollection(list(np.stack([mid, tips], axis=1)), colors=color, lw=0.7, alpha=0.8)
    )
    ax.plot(tips[:, 0], tips[:, 1], color=color, lw=0.9, label="curvature comb")
    draw_curve(ax, p, closed=closed, color="k", lw=1.2, label="curve")
    ax.legend(loc="best", fontsize=8)
    ax.set_xlabel("x")
    ax.set_ylabel("y")
    if title:
        ax.set_title(title)
    return ax


def convergence(
    series: dict[str, Sequence[float]],
    *,
    ax: Axes | None = None,
    title: str | None = None,
    xlabel: str = "level n",
    ylabel: str = "error",
    logy: bool = True,
):
    """Plot one or more error sequences against their index (log scale by default)."""
    if ax is None:
        _, (ax,) = new_axes()
    for name, values in series.items():
        v = np.asarray(values, dtype=float)
        ax.plot(np.arange(v.size), v, marker="o", ms=3, label=name)
    if logy:
        ax.set_yscale("log")
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    if title:
        ax.set_title(title)
    return ax


def alpha_profile(*, ax: Axes | None = None, title: str | None = None) -> Axes:
    """CCA's "regular" alpha profile against the interior angle (Gordon, Table 1, Fig. 14).

    The PCHIP profile :func:`curvesmith.cca.alpha_profile` that ``alpha="regular"``
    uses, through the Table 1 control points, and eq. (5)'s regular-polygon value for
    every half-angle beside it.

    Parameters
    ----------
    ax : matplotlib Axes, optional
    title : str, optional

    Returns
    -------
    matplotlib Axes

    Examples
    --------
    >>> from curvesmith import plot
    >>> ax = plot.alpha_profile()
    >>> [line.get_label() for line in ax.lines]
    ['"regular" profile (PCHIP)', 'eq. (5) for every half-angle', 'Table 1 control points']
    """
    from . import cca

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
    ax.set_xlabel("interior angle (degrees)")
    ax.set_ylabel("alpha")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="lower right")
    if title:
        ax.set_title(title)
    return ax


def affine_approximation(
    result: Any,
    curve: ArrayLike | None = None,
    *,
    window: Sequence[float] | None = None,
    ax: Axes | None = None,
    title: str | None = None,
) -> Axes:
    """An affine arc length polyline with its quadratic B-spline, over the curve it approximates.

    The polyline of :func:`curvesmith.affine.approximate` (its vertices lie on the curve)
    and its uniform quadratic B-spline, curvature continuous (Käferböck, Fig. 10); the
    vertices shared by the pieces between inflections are marked (Fig. 12).

    Parameters
    ----------
    result : Approximation
        :func:`curvesmith.affine.approximate`'s result.
    curve : (N, 2) array_like, optional
        The dense samples that were approximated, drawn underneath.
    window : (xmin, ymin, xmax, ymax), optional
        A zoom (the spline runs just inside the polyline).
    ax : matplotlib Axes, optional
    title : str, optional

    Returns
    -------
    matplotlib Axes

    Examples
    --------
    >>> import numpy as np
    >>> from curvesmith import affine, plot
    >>> t = np.linspace(0, 2, 400)
    >>> arc = np.column_stack([2 * np.cos(t), np.sin(t)])
    >>> ax = plot.affine_approximation(affine.approximate(arc, vertices=12), arc)
    >>> [line.get_label() for line in ax.lines]
    ['curve', 'affine arc length polyline', 'its quadratic B-spline (G2)']
    """
    from .affine import bspline

    if ax is None:
        _, (ax,) = new_axes()
    zoom = window is not None
    if curve is not None:
        c = as_points(curve, name="curve", min_points=2)
        ax.plot(*_thin(c).T, color="0.6", lw=1.5 if zoom else 3, label="curve")
    pts = np.asarray(result.points, dtype=float)
    closed = bool(result.closed)
    ax.plot(
        *_closed_xy(pts, closed).T,
        "o-",
        color="tab:blue",
        ms=3,
        lw=0.8,
        label="affine arc length polyline",
    )
    s = bspline(pts, closed=closed)
    u = np.linspace(s.t[2], s.t[-3] - 1e-12, 1500)
    ax.plot(*s(u).T, color="tab:red", lw=1, label="its quadratic B-spline (G2)")
    for j in np.asarray(result.joins, dtype=int):
        ax.plot(*pts[j], "s", color="k", ms=8, label=f"shared vertex x_{j}")
    ax.set_aspect("equal")
    if window is not None:
        ax.set_xlim(window[0], window[2])
        ax.set_ylim(window[1], window[3])
    ax.set_xlabel("x")
    ax.set_ylabel("y")
    if title:
        ax.set_title(title)
    return ax


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


def _bezier_curvature(segments: np.ndarray, per_segment: int):
    """Points, unit left normals and exact curvature along Bézier segments."""
    from math import comb

    q = np.asarray(segments, dtype=float)
    d = q.shape[1] - 1
    t = np.linspace(0.0, 1.0, per_segment + 1)

    def bern(deg):
        return np.array([comb(deg, i) * t**i * (1 - t) ** (deg - i) for i in range(deg + 1)])

    pts = np.einsum("im,sij->smj", bern(d), q)
    d1 = d * np.einsum("im,sij->smj", bern(d - 1), np.diff(q, axis=1))
    d2 = d * (d - 1) * np.einsum("im,sij->smj", bern(d - 2), np.diff(q, n=2, axis=1))
    speed = np.hypot(d1[..., 0], d1[..., 1])
    k = (d1[..., 0] * d2[..., 1] - d1[..., 1] * d2[..., 0]) / speed**3
    tang = d1 / speed[..., None]
    nrm = np.stack([-tang[..., 1], tang[..., 0]], axis=-1)
    return pts, nrm, k


def bezier_comb(
    segments: ArrayLike,
    *,
    closed: bool,
    per_segment: int = 24,
    scale: float | None = None,
    ax: Axes | None = None,
    title: str | None = None,
    color: str = "tab:blue",
):
    """Curvature comb of a Bézier path, exact curvature per segment, joints marked.

    Each segment's comb is drawn separately, so a curvature jump at a joint
    shows as a step in the comb's outline (none for a G2 path: the outline is
    continuous). On-curve joints are dots.

    Parameters
    ----------
    segments : (S, 3, 2) or (S, 4, 2) array_like
        Quadratic or cubic segments in order (:attr:`curvesmith.curves.CurveFit.segments`).
    closed : bool
        Closed path (only used for the default scale and title).
    per_segment : int, optional
        Teeth per segment.
    scale : float, optional
        Tooth length per unit curvature; default: longest tooth 15 % of the diagonal.
    ax : matplotlib Axes, optional
    title : str, optional
    color : str, optional

    Returns
    -------
    matplotlib Axes

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> ax = bezier_comb([[[0, 0], [1, 1], [2, 0]], [[2, 0], [3, -1], [4, 0]]], closed=False)
    >>> len(ax.lines) >= 2
    True
    """
    from matplotlib.collections import LineCollection

    q = np.asarray(segments, dtype=float)
    if ax is None:
        _, (ax,) = new_axes()
    pts, nrm, k = _bezier_curvature(q, per_segment)
    flat = pts.reshape(-1, 2)
    if scale is None:
        diag = float(np.linalg.norm(flat.max(axis=0) - flat.min(axis=0)))
        kmax = float(np.max(np.abs(k)))
        scale = 0.15 * diag / kmax if kmax > 0 else 0.0
    tips = pts - scale * k[..., None] * nrm
    ax.add_collection(
        LineCollection(
            list(np.stack([pts.reshape(-1, 2), tips.reshape(-1, 2)], axis=1)),
            colors=color,
            lw=0.5,
            alpha=0.7,
        )
    )
    for i, tip in enumerate(tips):
        ax.plot(
            tip[:, 0], tip[:, 1], color=color, lw=0.9, label="curvature comb" if i == 0 else None
        )
        ax.plot(pts[i, :, 0], pts[i, :, 1], color="k", lw=1.2, label="path" if i == 0 else None)
    ax.plot(q[:, 0, 0], q[:, 0, 1], "o", ms=2.5, color="k", label="joints")
    ax.set_aspect("equal", adjustable="datalim")
    ax.legend(loc="best", fontsize=8)
    if title:
        ax.set_title(title)
    return ax


def comb_before_after(points: ArrayLike, fit: Any, *, closed: bool, title: str | None = None):
    """Side by side: the comb of a dense polyline and of its fitted Bézier path.

    Parameters
    ----------
    points : (N, 2) array_like
        The polyline (e.g. the smoothed curve).
    fit : curvesmith.curves.CurveFit
        Its fit by :func:`curvesmith.curves.fit`.
    closed : bool
    title : str, optional
        Figure title.

    Returns
    -------
    matplotlib Figure

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> from curvesmith import curves
    >>> u = np.linspace(0, 2 * np.pi, 300, endpoint=False)
    >>> p = np.c_[3 * np.cos(u), np.sin(u)]
    >>> fig = comb_before_after(p, curves.fit(p, closed=True, tolerance=0.01), closed=True)
    >>> len(fig.axes)
    2
    """
    fig, (a, b) = new_axes(2)
    p = as_points(points, closed=closed, min_points=3, distinct=True)
    curvature_comb(p, closed=closed, ax=a, title=f"polyline: {len(p)} vertices (Menger curvature)")
    bezier_comb(
        fit.segments,
        closed=closed,
        ax=b,
        title=f"{fit.count} {'quadratic' if fit.degree == 2 else 'cubic'} Béziers, "
        f"max curvature jump {fit.g2_defect:.1e}",
    )
    if title:
        fig.suptitle(title)
    fig.tight_layout()
    return fig


def _arc_positions(p: np.ndarray) -> np.ndarray:
    return np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(p[:, :2], axis=0).T))])


def deviation_along(
    ax: Axes,
    points: ArrayLike,
    deviation: ArrayLike,
    *,
    tolerance: float | None = None,
    label: str | None = None,
    **kw,
):
    """Plot the deviation of each point from a fitted curve against arc length, in data units.

    Unlike an overlay at equal scale, where a 1 mm error on a 1.5 m curve is invisible,
    the y axis is the deviation itself.

    Parameters
    ----------
    ax : matplotlib Axes
    points : (N, 2) or (N, 3) array_like
        The data points, in order along the curve (arc length from them).
    deviation : (N,) array_like
        Their distances to the fitted curve (e.g. ``FitResult.deviation``).
    tolerance : float, optional
        Drawn as a dashed horizontal line.
    label : str, optional
    **kw
        Passed to ``ax.plot``.

    Returns
    -------
    Axes

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> import matplotlib.pyplot as plt
    >>> fig, ax = plt.subplots()
    >>> t = np.linspace(0, 1, 50)
    >>> ax = deviation_along(ax, np.column_stack([t, t**2]), 0.01 * np.sin(9 * t), tolerance=0.01)
    >>> ax.get_ylabel()
    'deviation from the fit'
    >>> plt.close(fig)
    """
    p = as_points(points, dim=(2, 3), min_points=2)
    dev = np.asarray(deviation, dtype=float)
    ax.plot(_arc_positions(p), dev, lw=0.9, label=label or "deviation", **kw)
    if tolerance is not None:
        ax.axhline(tolerance, color="tab:red", ls="--", lw=0.8, label=f"tolerance {tolerance:g}")
    ax.set_xlabel("arc length (data units)")
    ax.set_ylabel("deviation from the fit")
    ax.grid(True, lw=0.3)
    return ax


def curvature_along(
    ax: Axes,
    data: ArrayLike,
    fitted: ArrayLike,
    *,
    data_label: str = "data",
    fit_label: str = "fit",
    span: int = 1,
):
    """Plot the discrete curvature of data and of a fitted curve against arc length.

    Curvature is the Menger curvature (inverse circumradius of three vertices, signed) of
    each polyline, so unevenly spaced data can be compared with an equilateral fit. On
    noisy data use ``span > 1``: the circle through ``p[i - span], p[i], p[i + span]``
    (noise in the curvature falls like ``1 / span^2``).

    Parameters
    ----------
    ax : matplotlib Axes
    data, fitted : (N, 2) and (M, 2) array_like
        The two curves, in the same order along the curve.
    data_label, fit_label : str, optional
    span : int, optional
        Vertex offset of the three points of the data's circles (the fit uses 1).

    Returns
    -------
    Axes

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> import matplotlib.pyplot as plt
    >>> fig, ax = plt.subplots()
    >>> t = np.linspace(0, 1, 40)
    >>> c = np.column_stack([np.cos(t), np.sin(t)])
    >>> ax = curvature_along(ax, c, c)
    >>> ax.get_ylabel()
    'curvature (1 / data unit)'
    >>> plt.close(fig)
    """
    d = as_points(data, min_points=3)
    f = as_points(fitted, name="fitted", min_points=3)
    w = max(1, min(int(span), (d.shape[0] - 1) // 2))
    a, b, c = d[: -2 * w], d[w:-w], d[2 * w :]
    u, v = b - a, c - b
    cross = u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0]
    denom = np.hypot(*u.T) * np.hypot(*v.T) * np.hypot(*(c - a).T)
    k_data = np.divide(2.0 * cross, denom, out=np.zeros_like(cross), where=denom > 0)
    ax.plot(_arc_positions(d)[w:-w], k_data, color="0.4", lw=0.6, label=data_label)
    k_fit = geometry.menger_curvature(f)
    ax.plot(_arc_positions(f)[1:-1], k_fit, color="tab:red", lw=1.2, label=fit_label)
    ax.set_xlabel("arc length (data units)")
    ax.set_ylabel("curvature (1 / data unit)")
    ax.grid(True, lw=0.3)
    ax.legend(fontsize="small")
    return ax


def _thin(xy: np.ndarray, most: int = 4000) -> np.ndarray:
    """At most about `most` rows of a long polyline (every k-th, the last kept)."""
    xy = np.asarray(xy, dtype=float)
    if len(xy) <= most:
        return xy
    step = -(-len(xy) // most)
    return np.vstack([xy[::step], xy[-1:]])


def _draw_lines(ax, lines, **kw) -> None:
    for xy in lines:
        xy = _thin(xy)
        ax.plot(xy[:, 0], xy[:, 1], **kw)
    ax.set_aspect("equal", adjustable="datalim")


def _geometry_lines(geometry, most: int = 3000):
    import shapely

    values = getattr(geometry, "geometry", geometry)
    values = np.asarray(getattr(values, "values", values), dtype=object)
    values = values[[g is not None for g in values]]
    parts = shapely.get_parts(values)
    rings = shapely.get_rings(parts[shapely.get_type_id(parts) == shapely.GeometryType.POLYGON])
    lines = np.concatenate(
        [parts[shapely.get_type_id(parts) != shapely.GeometryType.POLYGON], rings]
    )
    lines = lines[~shapely.is_empty(lines)][:most]
    return [shapely.get_coordinates(g) for g in lines]


def _geometry_values(geometry: Any) -> np.ndarray:
    """The shapely geometries of a result, GeoDataFrame, GeoSeries, array, list or geometry."""
    values = geometry
    while (inner := getattr(values, "geometry", values)) is not values:  # result -> frame -> series
        values = inner
    import shapely

    values = getattr(values, "values", values)
    if values is None or isinstance(values, shapely.Geometry):
        values = [values]
    out = np.empty(len(values), dtype=object)
    out[:] = list(values)
    return out


def draw_geometries(
    ax: Axes,
    geometry: Any,
    *,
    window: Sequence[float] | None = None,
    label: str | None = None,
    **kw: Any,
) -> Axes:
    """Draw the boundaries of GIS geometries: polygon rings and lines, every part.

    Parameters
    ----------
    ax : matplotlib Axes
    geometry : shapely geometry, array or list of them, GeoSeries or GeoDataFrame
        Polygons (their exterior and interior rings are drawn), lines, Multi* and
        collections; None and empty geometries are skipped.
    window : (xmin, ymin, xmax, ymax), optional
        Draw only what lies inside (the lines are clipped, and the axes limited to it): a
        zoom on a layer of millions of vertices stays cheap.
    label : str, optional
        Legend label (given once for all the lines).
    **kw
        Line style passed to ``Axes.plot`` (``color``, ``lw``, ``ls``, ``marker``...).

    Returns
    -------
    matplotlib Axes

    Examples
    --------
    >>> import shapely
    >>> from curvesmith import plot
    >>> fig, (ax,) = plot.new_axes()
    >>> layer = [shapely.box(0, 0, 2, 1), shapely.LineString([(0, 2), (2, 2)])]
    >>> ax = plot.draw_geometries(ax, layer)
    >>> len(ax.lines)
    2
    """
    import shapely

    values = _geometry_values(geometry)
    values = values[[g is not None for g in values]]
    lines = shapely.boundary(values)
    mask = shapely.get_dimensions(values) == 1  # lines are their own drawing, not their ends
    lines[mask] = values[mask]
    if window is not None:
        x0, y0, x1, y1 = (float(v) for v in window)
        lines = shapely.intersection(lines, shapely.box(x0, y0, x1, y1))
        ax.set_xlim(x0, x1)
        ax.set_ylim(y0, y1)
    lines = lines[~shapely.is_empty(lines)]
    first = True
    for part in shapely.get_parts(shapely.get_parts(lines)):
        if shapely.get_type_id(part) == shapely.GeometryType.POINT:
            continue  # a clipped line touching the window in one point
        xy = _thin(shapely.get_coordinates(part))
        ax.plot(xy[:, 0], xy[:, 1], label=label if first else None, **kw)
        first = False
    ax.set_aspect("equal", adjustable="box")
    return ax


def layer_before_after(
    before: Any,
    after: Any,
    *,
    window: Sequence[float] | None = None,
    labels: Sequence[str] = ("input", "smoothed"),
    title: str | None = None,
    ax: Axes | None = None,
) -> Axes:
    """A GIS layer before (grey, wide) and after (blue) smoothing, whole or in a window.

    Parameters
    ----------
    before, after : geometries
        Anything :func:`draw_geometries` takes, e.g. the input GeoDataFrame and
        ``geo.smooth_coverage(...)``'s output.
    window : (xmin, ymin, xmax, ymax), optional
        A zoom (shared borders, junctions: where per-feature smoothing opens gaps).
    labels : (str, str)
        Legend labels.
    title : str, optional
    ax : matplotlib Axes, optional
        Target axes (a new figure otherwise).

    Returns
    -------
    matplotlib Axes

    Examples
    --------
    >>> import shapely
    >>> from curvesmith import geo, plot
    >>> grid = [shapely.box(i, j, i + 1, j + 1) for i in range(3) for j in range(2)]
    >>> ax = plot.layer_before_after(grid, geo.smooth_coverage(grid, iterations=2))
    >>> [t.get_text() for t in ax.get_legend().get_texts()]
    ['input', 'smoothed']
    """
    if ax is None:
        _, (ax,) = new_axes()
    zoom = window is not None
    draw_geometries(ax, before, window=window, label=labels[0], color="0.6", lw=2.5 if zoom else 1)
    draw_geometries(
        ax, after, window=window, label=labels[1], color="tab:blue", lw=1.2 if zoom else 0.6
    )
    if title:
        ax.set_title(title)
    ax.legend(loc="lower left", fontsize=8)
    return ax


def area_change(
    before: Any,
    after: Any,
    *,
    ax: Axes | None = None,
    title: str | None = None,
) -> Axes:
    """The distribution of the relative area change per polygon: the proof a GIS user asks for.

    A cumulative distribution of ``(A_after - A_before) / A_before`` in percent over the
    polygons of a layer, one line per result: CCA's is the vertical line at 0 (round-off),
    Chaikin's lies left of it (every polygon shrinks).

    Parameters
    ----------
    before : geometries
        The input polygons (what :func:`draw_geometries` takes).
    after : geometries, or dict of label to geometries
        One smoothed layer, or several to compare; feature by feature in the order of
        `before`.
    ax : matplotlib Axes, optional
    title : str, optional

    Returns
    -------
    matplotlib Axes

    Examples
    --------
    >>> import shapely
    >>> from curvesmith import geo, plot
    >>> grid = [shapely.box(i, 0, i + 1, 1) for i in range(4)]
    >>> runs = {"cca": geo.smooth(grid), "chaikin": geo.smooth(grid, method="chaikin")}
    >>> ax = plot.area_change(grid, runs)
    >>> [round(float(line.get_xdata().max()), 6) for line in ax.lines]
    [0.0, -12.5]
    """
    import shapely

    if ax is None:
        _, (ax,) = new_axes(width=7, height=4)
    a0 = shapely.area(_geometry_values(before))
    runs = after if isinstance(after, dict) else {"smoothed": after}
    for name, geoms in runs.items():
        a1 = shapely.area(_geometry_values(geoms))
        if a1.shape != a0.shape:
            from .errors import CurveError

            raise CurveError(
                f"after[{name!r}] must have one geometry per input polygon ({a0.size}), "
                f"got {a1.size}"
            )
        ok = a0 > 0
        rel = np.sort((a1[ok] - a0[ok]) / a0[ok]) * 100.0
        ax.plot(rel, np.linspace(0, 1, rel.size), label=name)
    ax.set_xlabel("relative area change per polygon (%)")
    ax.set_ylabel("fraction of polygons")
    if title:
        ax.set_title(title)
    ax.legend()
    ax.grid(alpha=0.3)
    return ax


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


def elastica_fit(
    result: Any,
    *,
    start: bool = True,
    markers: bool = False,
    ax: Axes | None = None,
    title: str | None = None,
) -> Axes:
    """An elastica fit over its data: the input points, the start of the solve, the fit.

    Parameters
    ----------
    result : FitResult
        :func:`curvesmith.elastica.fit`'s result (its ``data`` are the points as fitted).
    start : bool, optional
        Also draw the curve of ``result.start``, where the final solve began (the
        initial guess of section 4.3 unless a start was given).
    markers : bool, optional
        Draw every vertex (squares input, triangles start, circles fit: the paper's
        Fig. 5) instead of lines, for short curves.
    ax : matplotlib Axes, optional
    title : str, optional
        Default: the case, ``k`` and the rms distance.

    Returns
    -------
    matplotlib Axes

    Examples
    --------
    >>> import numpy as np
    >>> from curvesmith import elastica, plot
    >>> truth = elastica.sample((0, 0, 0.1, 0.3, 0.0, 0.2, 0.7), 40)
    >>> ax = plot.elastica_fit(elastica.fit(truth))
    >>> [line.get_label() for line in ax.lines]
    ['input', 'start of the final solve', 'discrete elastica (fit)']
    """
    from .elastica import sample

    if ax is None:
        _, (ax,) = new_axes()
    data = _thin(np.asarray(result.data, dtype=float)[:, :2])
    if markers:
        ax.plot(*data.T, "s", color="black", ms=3.5, mfc="none", label="input")
    else:
        ax.plot(*data.T, ".", color="black", ms=2, label="input")
    if start:
        guess = sample(result.start, result.data.shape[0])
        style: dict[str, Any] = {"marker": "^", "ls": "", "ms": 3.5, "mfc": "none"}
        ax.plot(
            *guess.T,
            color="tab:green",
            label="start of the final solve",
            **(style if markers else {"lw": 0.8}),
        )
    style = {"marker": "o", "ls": "", "ms": 2.5} if markers else {"lw": 1.0}
    ax.plot(*result.points.T, color="tab:red", label="discrete elastica (fit)", **style)
    if title is None:
        title = f"case ({result.case}), k = {result.params.k:.3f}, rms = {result.rms:.3g}"
        title += "" if result.success else " (failed)"
    ax.set_title(title)
    ax.set_aspect("equal", adjustable="datalim")
    ax.legend(fontsize="small")
    return ax


def inflection_estimate(result: Any, *, ax: Axes | None = None, numbered: int = 9) -> Axes:
    """The RDP inflection estimate of a keyline (section 5.3, Fig. 14).

    The equilateral keyline in its principal-axes frame, the RDP points in the order they
    were found (the first `numbered` labelled 1, 2, 3, ...), and the estimated inflection.

    Parameters
    ----------
    result : KeylineFit
        :func:`curvesmith.keyline.fit`'s result.
    ax : matplotlib Axes, optional
    numbered : int, optional
        How many RDP points get their number.

    Returns
    -------
    matplotlib Axes
    """
    if ax is None:
        _, (ax,) = new_axes(width=10, height=3.5)
    xy, est = np.asarray(result.points, dtype=float), result.inflection
    ax.plot(xy[:, 0], xy[:, 1], ".-", color="0.6", ms=2, lw=0.6, label="equilateral keyline")
    lab = np.asarray(est.labels, dtype=int)
    ax.plot(*xy[lab].T, "o", mfc="none", color="C0", ms=6, label="RDP points 1, 2, 3, ...")
    for num, j in enumerate(est.labels[:numbered], start=1):
        ax.annotate(str(num), xy[j], textcoords="offset points", xytext=(3, 6), fontsize=8)
    ax.plot(*xy[est.index], "*", color="C3", ms=14, label=f"estimated inflection ({est.index})")
    ax.set_aspect("equal")
    ax.set_xlabel("x''")
    ax.set_ylabel("y''")
    return ax


def keyline_fit(result: Any, *, ax: Axes | None = None) -> Axes:
    """A keyline's elastica fits: the vertices, each side's fit, the pinned inflection (Fig. 16).

    Parameters
    ----------
    result : KeylineFit
        :func:`curvesmith.keyline.fit`'s result (every side's fit is drawn: left and
        right, or the pieces between several inflections, or the whole).
    ax : matplotlib Axes, optional

    Returns
    -------
    matplotlib Axes

    Examples
    --------
    >>> from curvesmith import keyline, plot
    >>> syn = keyline.synthetic_keyline(noise=0.02, seed=1)
    >>> ax = plot.keyline_fit(keyline.fit(syn.points, step=1.0))
    >>> [line.get_label() for line in ax.lines]
    ['keyline vertices', 'elastica fit, left', 'elastica fit, right', 'pinned (x0, y0)']
    """
    if ax is None:
        _, (ax,) = new_axes(width=10, height=3.5)
    xy = np.asarray(result.points, dtype=float)
    ax.plot(xy[:, 0], xy[:, 1], "s", color="k", ms=2, label="keyline vertices")
    for k, (name, fit) in enumerate(result.sides):
        ax.plot(*fit.points.T, "-", color=f"C{k + 2}", lw=1.6, label=f"elastica fit, {name}")
    ax.plot(*xy[result.inflection.index], "o", color="C0", ms=7, label="pinned (x0, y0)")
    ax.set_aspect("equal")
    ax.set_xlabel("x''")
    ax.set_ylabel("y''")
    return ax


def fit_panels(
    axes: Sequence[Axes], result: Any, data: ArrayLike, *, label: str | None = None
) -> None:
    """Three panels of an elastica fit: the curve over its data, deviation and curvature.

    For :func:`curvesmith.elastica.fit` (with the start of its final solve) and
    :func:`curvesmith.elastica.fit_segments` (each segment and the G1 joints): left the
    input points and the fit, middle the distance of every input point from the fit along
    the curve in data units (:func:`deviation_along`, with the tolerance if one was given),
    right the curvature of data and fit along the curve (:func:`curvature_along`). This is
    what ``curvesmith fair --plot`` draws per curve.

    Parameters
    ----------
    axes : sequence of 3 matplotlib Axes
    result : FitResult or SegmentFit
    data : (N, 2) array_like
        The input points as fitted (in the fit's plane for 3D input).
    label : str, optional
        Prefix of the left panel's title (e.g. ``"curve 3"``).
    """
    raw = np.asarray(data, dtype=float)
    ax = axes[0]
    ax.plot(*raw.T, ".", color="black", ms=2, label="input")
    prefix = f"{label}: " if label else ""
    if hasattr(result, "segments"):
        for i, seg in enumerate(result.segments):
            ax.plot(*seg.points.T, "-", lw=1.0, label=f"segment {i}" if i < 6 else None)
        joints = np.array([result.points[j.vertex] for j in result.joints]).reshape(-1, 2)
        ax.plot(*joints.T, "kx", ms=7, label="joints (G1)")
        verdict = "within" if result.within_tolerance else "misses"
        title = f"{len(result.segments)} elastica segments ({verdict} {result.tolerance:g})"
        middle = f"max deviation {result.max_deviation:.3g}, rms {result.rms_deviation:.3g}"
    else:
        ax.lines[-1].remove()  # the input, drawn again by elastica_fit
        elastica_fit(result, ax=ax)
        title = f"case ({result.case})" + ("" if result.success else " (failed)")
        middle = (
            f"max deviation {result.max_deviation:.3g}, rms {result.rms_deviation:.3g} "
            f"(noise {result.noise:.2g})"
        )
    ax.set_title(prefix + title, fontsize="medium")
    ax.set_aspect("equal", adjustable="datalim")
    ax.legend(fontsize="small")
    deviation_along(axes[1], raw, result.deviation, tolerance=result.tolerance)
    axes[1].set_title(middle, fontsize="medium")
    span = max(1, result.data.shape[0] // 60)
    curvature_along(
        axes[2],
        result.data,
        result.points,
        data_label=f"data (circles over {span} chords)",
        span=span,
    )
    axes[2].set_title("curvature along the curve", fontsize="medium")


def fit_figure(fits: Sequence[Any], *, labels: Sequence[str] | None = None):
    """One row of :func:`fit_panels` per ``(result, data)`` pair; a Figure not tied to pyplot.

    Examples
    --------
    >>> import numpy as np
    >>> from curvesmith import elastica, plot
    >>> t = np.linspace(0.0, 1.5, 80)
    >>> arc = 100.0 * np.c_[np.cos(t), np.sin(t)]
    >>> fig = plot.fit_figure([(elastica.fit(arc), arc)], labels=["arc"])
    >>> len(fig.axes), fig.axes[2].get_title()
    (3, 'curvature along the curve')
    """
    from matplotlib.figure import Figure

    fits = list(fits)
    fig = Figure(figsize=(16.0, 4.2 * len(fits)))
    rows = fig.subplots(len(fits), 3, squeeze=False)
    for k, (row, (result, data)) in enumerate(zip(rows, fits, strict=True)):
        fit_panels(row, result, data, label=None if labels is None else labels[k])
    fig.tight_layout()
    return fig
