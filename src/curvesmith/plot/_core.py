"""The shared drawing: axes, curves, markers, curvature combs, convergence, deviation."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike

from .. import geometry
from .._validate import as_points

if TYPE_CHECKING:
    from matplotlib.axes import Axes


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


def mark_points(
    ax: Axes,
    points: ArrayLike,
    *,
    names: Sequence[str] | None = None,
    label: str | None = None,
    offsets: Sequence[tuple[float, float]] | None = None,
    fontsize: float = 8,
    **kw: Any,
) -> Axes:
    """Mark points (anchors, joints, nodes, crossings, known truths) and optionally name them.

    Parameters
    ----------
    ax : matplotlib Axes
    points : (K, 2) or (2,) array_like
        The points (a single point may be given as a pair); ``K = 0`` draws nothing.
    names : sequence of str, optional
        A text beside each point.
    label : str, optional
        Legend label (once for all the points).
    offsets : sequence of (dx, dy), optional
        Per point, the text's offset from it in points (default ``(6, 4)`` each).
    fontsize : float, optional
        Of the names.
    **kw
        Marker style passed to ``ax.plot`` (default: black dots, ``marker="o"``,
        ``ms=4``); e.g. ``marker="x", ms=9, mew=2`` or ``mfc="none"`` for open circles.

    Returns
    -------
    matplotlib Axes

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> import matplotlib.pyplot as plt
    >>> from curvesmith import plot
    >>> fig, ax = plt.subplots()
    >>> ax = plot.mark_points(ax, [[0, 0], [1, 2]], names=["A", "B"], label="corners")
    >>> [t.get_text() for t in ax.texts], ax.lines[0].get_label()
    (['A', 'B'], 'corners')
    >>> plt.close(fig)
    """
    from ..errors import CurveError

    p = np.asarray(points, dtype=float).reshape(-1, 2) if np.size(points) else np.empty((0, 2))
    if names is not None and len(names) != len(p):
        raise CurveError(f"names must have one entry per point ({len(p)}), got {len(names)}")
    if offsets is not None and len(offsets) != len(p):
        raise CurveError(f"offsets must have one entry per point ({len(p)}), got {len(offsets)}")
    style: dict[str, Any] = {"marker": "o", "ls": "", "color": "k", "ms": 4}
    style.update(kw)
    ax.plot(p[:, 0], p[:, 1], label=label, **style)
    for i, name in enumerate(names or ()):
        off = (6, 4) if offsets is None else offsets[i]
        ax.annotate(name, tuple(p[i]), textcoords="offset points", xytext=off, fontsize=fontsize)
    return ax


def window_box(ax: Axes, window: Sequence[float], **kw: Any) -> Axes:
    """Outline a zoom window ``(xmin, ymin, xmax, ymax)`` (red by default) on an overview.

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> import matplotlib.pyplot as plt
    >>> from curvesmith import plot
    >>> fig, ax = plt.subplots()
    >>> ax = plot.window_box(ax, (0, 0, 2, 1))
    >>> ax.patches[0].get_width(), ax.patches[0].get_height()
    (2.0, 1.0)
    >>> plt.close(fig)
    """
    from matplotlib.patches import Rectangle

    from ..errors import CurveError

    x0, y0, x1, y1 = (float(v) for v in window)
    if not (x1 > x0 and y1 > y0):
        raise CurveError(f"window must be (xmin, ymin, xmax, ymax) with max > min, got {window}")
    style: dict[str, Any] = {"fill": False, "ec": "red", "lw": 1.5}
    style.update(kw)
    ax.add_patch(Rectangle((x0, y0), x1 - x0, y1 - y0, **style))
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
        from ..errors import CurveError

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
    series: Mapping[str, ArrayLike],
    *,
    ax: Axes | None = None,
    title: str | None = None,
    xlabel: str = "level n",
    ylabel: str = "error",
    logy: bool = True,
    baseline: float | None = None,
):
    """Plot one or more sequences against their index: errors per level, changes per iteration.

    Parameters
    ----------
    series : dict of str to array_like
        Label to values; value ``i`` is drawn at ``x = i``.
    ax : matplotlib Axes, optional
    title : str, optional
    xlabel, ylabel : str, optional
    logy : bool, optional
        Logarithmic y axis (the default, for errors that fall geometrically).
    baseline : float, optional
        A value drawn as a thin black horizontal line (e.g. 0 for a change that should
        stay zero).

    Returns
    -------
    matplotlib Axes

    Examples
    --------
    >>> import numpy as np
    >>> from curvesmith import geometry, plot, subdivision
    >>> square = np.array([[0, 0], [1, 0], [1, 1], [0, 1.0]])
    >>> change = [geometry.signed_area(subdivision.chaikin(square, closed=True, iterations=k)) - 1
    ...           for k in range(4)]
    >>> ax = plot.convergence({"Chaikin": change}, logy=False, baseline=0.0, xlabel="iterations")
    >>> [round(float(v), 4) for v in ax.lines[0].get_ydata()]
    [0.0, -0.125, -0.1562, -0.1641]
    """
    if ax is None:
        _, (ax,) = new_axes()
    for name, values in series.items():
        v = np.asarray(values, dtype=float)
        ax.plot(np.arange(v.size), v, marker="o", ms=3, label=name)
    if baseline is not None:
        ax.axhline(baseline, color="k", lw=0.8)
    if logy:
        ax.set_yscale("log")
    return _labelled(ax, xlabel, ylabel, title)


def _labelled(ax, xlabel: str, ylabel: str, title: str | None):
    """Axis labels, a light grid, the legend and the title of a plot of series."""
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    if title:
        ax.set_title(title)
    return ax


def scaling(
    series: Mapping[str, tuple[ArrayLike, ArrayLike]],
    *,
    ax: Axes | None = None,
    title: str | None = None,
    xlabel: str = "items",
    ylabel: str = "seconds per item",
):
    """Cost per item against the number of items, log-log, one line per method.

    A method whose cost is per call, not per item, falls along the x axis as its calls
    share out; one with a fixed cost per call stays flat and high.

    Parameters
    ----------
    series : dict of str to (sizes, costs)
        Label to the sizes measured (items, vertices, ...) and the cost per item at each.
    ax : matplotlib Axes, optional
    title : str, optional
    xlabel, ylabel : str, optional

    Returns
    -------
    matplotlib Axes

    Raises
    ------
    CurveError
        A series whose sizes and costs differ in length, or a size or cost that is not
        a positive finite number (a log axis cannot show it).

    Examples
    --------
    >>> from curvesmith import plot
    >>> ax = plot.scaling({"one call": ([10, 100, 1000], [5e-5, 8e-6, 2e-6]),
    ...                    "a call each": ([10, 100], [5e-5, 5e-5])}, xlabel="polygons")
    >>> [len(line.get_xdata()) for line in ax.lines], ax.get_xscale(), ax.get_yscale()
    ([3, 2], 'log', 'log')
    >>> import matplotlib.pyplot as plt
    >>> plt.close(ax.figure)
    """
    from ..errors import CurveError

    if ax is None:
        _, (ax,) = new_axes()
    for name, (sizes, costs) in series.items():
        x = np.asarray(sizes, dtype=float).ravel()
        y = np.asarray(costs, dtype=float).ravel()
        if x.shape != y.shape:
            raise CurveError(
                f"series[{name!r}] must have as many costs as sizes, got {x.size} sizes and "
                f"{y.size} costs"
            )
        bad = ~(np.isfinite(x) & np.isfinite(y) & (x > 0) & (y > 0))
        if bad.any():
            k = int(np.flatnonzero(bad)[0])
            raise CurveError(
                f"series[{name!r}] must hold positive finite sizes and costs, got size "
                f"{float(x[k])!r} with cost {float(y[k])!r}"
            )
        ax.plot(x, y, marker="o", ms=4, label=name)
    ax.set_xscale("log")
    ax.set_yscale("log")
    return _labelled(ax, xlabel, ylabel, title)


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
