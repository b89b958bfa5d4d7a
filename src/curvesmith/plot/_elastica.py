"""Figures of elastica fits and keylines (Graiff Zurita, Kajiwara, Suzuki)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike

from .._validate import as_choice, as_points
from ._core import _arc_positions, _thin, curvature_along, deviation_along, mark_points, new_axes

if TYPE_CHECKING:
    from matplotlib.axes import Axes


def elastica_fit(
    result: Any,
    data: ArrayLike | None = None,
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
    data : (N, 2) array_like, optional
        The input points to draw (e.g. the raw scan of a fit with ``resample=True``);
        default: ``result.data``, the points as fitted.
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
    from ..elastica import sample

    if ax is None:
        _, (ax,) = new_axes()
    data = _thin(np.asarray(result.data if data is None else data, dtype=float)[:, :2])
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
    prefix = f"{label}: " if label else ""
    if hasattr(result, "segments"):
        elastica_segments(result, raw, ax=ax)
        title = ax.get_title()
        middle = f"max deviation {result.max_deviation:.3g}, rms {result.rms_deviation:.3g}"
    else:
        elastica_fit(result, ax=ax)  # the input as fitted, the start, the fit
        title = f"case ({result.case})" + ("" if result.success else " (failed)")
        noise = "too few points" if result.noise != result.noise else f"{result.noise:.2g}"
        middle = (
            f"max deviation {result.max_deviation:.3g}, rms {result.rms_deviation:.3g} "
            f"(noise {noise})"
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


def elastica_invariant(result: Any, *, ax: Axes | None = None, title: str | None = None) -> Axes:
    """Curvature against the projection ``u_n`` of a fit: a line on a discrete elastica.

    On a discrete elastica the discrete curvature ``kappa_n`` (eq. 4.33) is affine in
    ``u_n = <I, gamma_n>``, the projection on the direction ``I = (sin phi, -cos phi)``
    (Prop. 4.1): ``kappa_n = (mu / Lambda) u_n + A``. The fitted curve's points lie on
    that line; the data's noisy curvatures scatter about it, which shows how well an
    elastica models them.

    Parameters
    ----------
    result : FitResult
        :func:`curvesmith.elastica.fit`'s result.
    ax : matplotlib Axes, optional
    title : str, optional

    Returns
    -------
    matplotlib Axes

    Examples
    --------
    >>> import numpy as np
    >>> from curvesmith import elastica, plot
    >>> truth = elastica.sample((0, 0, 0.1, 0.3, 0.0, 0.2, 0.7), 40)
    >>> ax = plot.elastica_invariant(elastica.fit(truth))
    >>> u, k = ax.lines[1].get_data()
    >>> float(np.ptp(k - np.polyval(np.polyfit(u, k, 1), u))) < 1e-8
    True
    """
    from ..elastica import curvature, invariants

    if ax is None:
        _, (ax,) = new_axes(width=6.0, height=4.4)
    p = result.params
    direction = np.array([np.sin(p.phi), -np.cos(p.phi)])
    pts = np.asarray(result.points, dtype=float)
    data = np.asarray(result.data, dtype=float)[:, :2]
    kappa = curvature(pts)
    u = pts[1:-1] @ direction
    if data.shape[0] == pts.shape[0]:
        u_data, kappa_data = data[1:-1] @ direction, curvature(data, rtol=1.0)
    else:
        u_data, kappa_data = np.empty(0), np.empty(0)
    ax.plot(u_data, kappa_data, ".", color="0.6", label="data (noisy discrete curvature)")
    ax.plot(u, kappa, "o", color="tab:red", ms=3, label="fitted elastica")
    inv = invariants(p)
    slope = inv.mu / inv.Lambda
    ends = np.array([u.min(), u.max()])
    ax.plot(
        ends,
        slope * ends + float(np.mean(kappa - slope * u)),
        "k--",
        lw=1,
        label="(mu / Lambda) u + A",
    )
    ax.set_xlabel("u_n = <I, gamma_n>  (eq. 4.14)")
    ax.set_ylabel("discrete curvature kappa_n  (eq. 4.33)")
    ax.set_title(title or "Prop. 4.1: kappa_n is affine in u_n on a discrete elastica")
    ax.legend(fontsize="small")
    return ax


def elastica_segments(
    result: Any,
    data: ArrayLike | None = None,
    *,
    reference_joints: ArrayLike | None = None,
    ax: Axes | None = None,
    title: str | None = None,
) -> Axes:
    """A multi-segment elastica fit over its data: every segment and the G1 joints.

    Parameters
    ----------
    result : SegmentFit
        :func:`curvesmith.elastica.fit_segments`'s result.
    data : (N, 2) array_like, optional
        The input points (default: the equal-chord data that was fitted).
    reference_joints : (J, 2) array_like, optional
        Known joints (of a synthetic test, or a designer's breaks), drawn as open circles
        beside the fitted ones.
    ax : matplotlib Axes, optional
    title : str, optional
        Default: the number of segments and whether they stay within the tolerance.

    Returns
    -------
    matplotlib Axes

    Examples
    --------
    >>> import numpy as np
    >>> from curvesmith import elastica, plot
    >>> t = np.linspace(0, 3, 200)
    >>> wave = np.c_[10 * t, np.sin(2 * t)]
    >>> res = elastica.fit_segments(wave, 0.05)
    >>> ax = plot.elastica_segments(res, wave)
    >>> [line.get_label() for line in ax.lines][:2]  # doctest: +ELLIPSIS
    ['input', 'segment 0: k = ...']
    """
    if ax is None:
        _, (ax,) = new_axes()
    raw = _thin(np.asarray(result.data if data is None else data, dtype=float)[:, :2])
    ax.plot(*raw.T, ".", color="0.5", ms=2, label="input")
    for i, seg in enumerate(result.segments):
        label = f"segment {i}: k = {seg.params.k:.3g}" if i < 8 else None
        ax.plot(*seg.points.T, "-", lw=1.2, label=label)
    if reference_joints is not None:
        mark_points(ax, reference_joints, label="reference joints", mfc="none", ms=9)
    joints = np.array([result.points[j.vertex] for j in result.joints]).reshape(-1, 2)
    mark_points(ax, joints, label="fitted joints (G1)", marker="x", ms=7)
    verdict = "within" if result.within_tolerance else "misses"
    ax.set_title(
        title or f"{len(result.segments)} elastica segments ({verdict} {result.tolerance:g})"
    )
    ax.set_aspect("equal", adjustable="datalim")
    ax.legend(fontsize="small")
    return ax


def segments_deviation(
    result: Any, data: ArrayLike, *, ax: Axes | None = None, title: str | None = None
) -> Axes:
    """Deviation of every input point from a multi-segment fit along the curve, joints dotted.

    :func:`deviation_along` with the tolerance, and a dotted line at each joint (at the
    input point nearest to it).

    Parameters
    ----------
    result : SegmentFit
        :func:`curvesmith.elastica.fit_segments`'s result.
    data : (N, 2) array_like
        The input points that were fitted (consecutive repeats are dropped, as the fit
        dropped them).
    ax : matplotlib Axes, optional
    title : str, optional
        Default: the maximum deviation and the curvature jumps at the joints.

    Returns
    -------
    matplotlib Axes

    Examples
    --------
    >>> import numpy as np
    >>> from curvesmith import elastica, plot
    >>> t = np.linspace(0, 3, 200)
    >>> wave = np.c_[10 * t, np.sin(2 * t)]
    >>> res = elastica.fit_segments(wave, 0.05)
    >>> ax = plot.segments_deviation(res, wave)
    >>> len(ax.lines) == 2 + len(res.joints)
    True
    """
    from ..errors import CurveError

    if ax is None:
        _, (ax,) = new_axes(width=6.0, height=4.0)
    p = as_points(data, name="data", dim=(2, 3), min_points=2)[:, :2]
    dev = np.asarray(result.deviation, dtype=float)
    if p.shape[0] != dev.size:
        p = p[np.r_[True, np.any(np.diff(p, axis=0) != 0, axis=1)]]
    if p.shape[0] != dev.size:
        raise CurveError(
            f"data must be the {dev.size} points that were fitted, got {p.shape[0]} distinct"
        )
    deviation_along(ax, p, dev, tolerance=result.tolerance)
    arc = _arc_positions(p)
    for j in result.joints:
        near = int(np.argmin(np.hypot(*(p - result.points[j.vertex]).T)))
        ax.axvline(arc[near], color="black", lw=0.8, ls=":")
    jumps = ", ".join(f"{j.curvature_jump:.2g}" for j in result.joints) or "none"
    ax.set_title(
        title
        or f"max deviation {result.max_deviation:.3g}; joints dotted\n"
        f"(G2 not imposed: curvature jumps {jumps})",
        fontsize="medium",
    )
    ax.legend(fontsize="small")
    return ax


def keyline_scans(
    scans: Mapping[str, ArrayLike],
    fits: Sequence[Any] | None = None,
    *,
    ax: Any = None,
    title: str | None = None,
) -> Any:
    """3D keyline scans in their own coordinates, with each fit's inflection on its scan.

    Parameters
    ----------
    scans : dict of str to (N, 3) array_like
        Label to the scanned points.
    fits : sequence of KeylineFit, optional
        :func:`curvesmith.keyline.fit`'s results, one per scan in the same order: their
        estimated inflections, mapped back to the scan's frame, are drawn as black dots.
    ax : matplotlib 3D Axes, optional
        Default: a new figure with one 3D axes.
    title : str, optional

    Returns
    -------
    matplotlib Axes (3D)

    Examples
    --------
    >>> from curvesmith import keyline, plot
    >>> syn = keyline.synthetic_keyline(noise=0.02, seed=1)
    >>> ax = plot.keyline_scans({"K1": syn.points}, [keyline.fit(syn.points, step=1.0)])
    >>> ax.name, [line.get_label() for line in ax.lines]
    ('3d', ['K1'])
    """
    from ..errors import CurveError

    if ax is None:
        import matplotlib.pyplot as plt

        fig = plt.figure(figsize=(7.5, 6.0))
        ax = fig.add_subplot(projection="3d")
    pts = {
        name: as_points(p, name=f"scans[{name!r}]", dim=3, min_points=2)
        for name, p in scans.items()
    }
    if fits is not None and len(fits) != len(pts):
        raise CurveError(f"fits must have one entry per scan ({len(pts)}), got {len(fits)}")
    for k, (name, p) in enumerate(pts.items()):
        ax.plot(p[:, 0], p[:, 1], p[:, 2], lw=0.8, label=name)
        if fits is not None:
            fit = fits[k]
            infl = fit.to_input_frame(
                fit.points[[e.index for e in fit.inflections or (fit.inflection,)]]
            )
            ax.scatter(infl[:, 0], infl[:, 1], zs=infl[:, 2], color="k", s=12)
    if pts:
        ax.set_box_aspect(np.ptp(np.vstack(list(pts.values())), axis=0))
    ax.set_xlabel("x")
    ax.set_ylabel("y")
    ax.set_zlabel("z")
    if title:
        ax.set_title(title)
    ax.legend(fontsize=8, loc="upper left")
    return ax


def keyline_sides(
    fits: Mapping[str, Any],
    *,
    side: str = "left",
    ax: Axes | None = None,
    title: str | None = None,
) -> Axes:
    """One side of several keylines' fits, translated to a common inflection (Fig. 18).

    Each fit's side starts at its pinned inflection; moving those to the origin lines the
    family up, so that similar keylines (tiles of one mould) overlay and an odd one stands
    out.

    Parameters
    ----------
    fits : dict of str to KeylineFit
        Label to :func:`curvesmith.keyline.fit`'s result.
    side : {"left", "right"}, optional
        The first or the last fitted piece of each keyline.
    ax : matplotlib Axes, optional
    title : str, optional

    Returns
    -------
    matplotlib Axes

    Examples
    --------
    >>> from curvesmith import keyline, plot
    >>> syn = keyline.synthetic_keyline(noise=0.02, seed=1)
    >>> ax = plot.keyline_sides({"K1": keyline.fit(syn.points, step=1.0)}, side="right")
    >>> [float(v) for v in ax.lines[0].get_xydata()[0]]
    [0.0, 0.0]
    """
    side = as_choice(side, ("left", "right"), name="side")
    if ax is None:
        _, (ax,) = new_axes(width=10.0, height=3.0)
    for name, fit in fits.items():
        piece = fit.sides[0 if side == "left" else -1][1]
        pts = np.asarray(piece.points, dtype=float)
        ax.plot(*(pts - pts[0]).T, lw=1.2, label=name)
    ax.set_aspect("equal")
    ax.set_xlabel("x'' - x0")
    ax.set_ylabel("y'' - y0")
    ax.set_title(title or f"Fitted {side} sides, inflection at the origin")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0))
    return ax
