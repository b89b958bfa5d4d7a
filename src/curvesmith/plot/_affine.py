"""Figures of affine arc length polylines (Käferböck): approximation, affine curvature, G2."""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike

from .._validate import as_int, as_points
from ._core import _closed_xy, _thin, new_axes

if TYPE_CHECKING:
    from matplotlib.axes import Axes


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
    from ..affine import bspline

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


def _middle_parameters(t: np.ndarray, period: float | None) -> np.ndarray:
    """The mean parameter of the four vertices of each middle osculating conic.

    Open: the quadruples ``x_j .. x_{j+3}``; closed (`period`: the sample count): ``x_{i-1}
    .. x_{i+2}``, unwrapped across the seam (the alignment of ``affine.curvature``).
    """
    if period is None:
        return (t[:-3] + t[1:-2] + t[2:-1] + t[3:]) / 4
    n = t.size
    ext = np.concatenate([t[-1:] - period, t, t[:2] + period])
    return ((ext[:n] + ext[1 : n + 1] + ext[2 : n + 2] + ext[3 : n + 3]) / 4) % period


def affine_curvature(
    result: Any,
    exact: Callable[[np.ndarray], ArrayLike] | None = None,
    *,
    samples: int | None = None,
    skip: int = 2,
    ax: Axes | None = None,
    title: str | None = None,
) -> Axes:
    """The discrete affine curvatures ``kappa_i^m`` of an approximation along the curve.

    Each ``kappa_i^m = k_i |A|^(-2/3)`` (Käferböck, eq. 7) is the affine curvature of the
    middle osculating conic of four vertices; it is drawn at the mean parameter of those
    vertices on the approximated samples (Figs. 11 and 13), over the exact affine
    curvature when it is known. For a curve split at inflections, the values that
    straddle a join are left out (they carry no meaning) and the ``skip`` values at both
    ends of every piece, which the optimisation did not use, are drawn as open circles;
    the joins are dotted.

    Parameters
    ----------
    result : Approximation
        :func:`curvesmith.affine.approximate`'s result.
    exact : callable, optional
        ``exact(u)``: the exact affine curvature at the normalised sample parameters
        ``u`` in ``[0, 1]`` (e.g. :func:`curvesmith.affine.bezier_affine_curvature` of a
        Bézier sampled at uniform ``u``), drawn as a line.
    samples : int, optional
        The number of samples that were approximated: the x axis is then
        ``u = t / (samples - 1)`` (``t / samples`` for a closed curve), the curve's own
        parameter if it was sampled at uniform steps. Without it: the sample index ``t``.
    skip : int, optional
        The ``skip`` given to :func:`curvesmith.affine.approximate` (default 2).
    ax : matplotlib Axes, optional
    title : str, optional

    Returns
    -------
    matplotlib Axes

    Examples
    --------
    >>> import numpy as np
    >>> from curvesmith import affine, plot
    >>> ctrl = np.array([[0, 0], [1, 2], [3, 2], [4, 0.0]])
    >>> u = np.linspace(0, 1, 400)
    >>> res = affine.approximate(affine.bezier_curve(ctrl, u), vertices=12)
    >>> exact = lambda v: affine.bezier_affine_curvature(ctrl, v)
    >>> ax = plot.affine_curvature(res, exact, samples=400)
    >>> [line.get_label() for line in ax.lines]
    ['exact affine curvature', 'kappa_i^m = k_i |A|^(-2/3)']
    >>> bool(np.allclose(ax.lines[1].get_ydata(), exact(ax.lines[1].get_xdata()), rtol=0.02))
    True
    """
    from ..errors import CurveError

    if ax is None:
        _, (ax,) = new_axes(width=8.0, height=4.0)
    closed = bool(result.closed)
    t = np.asarray(result.t, dtype=float)
    km = np.asarray(result.kappa_m, dtype=float)
    valid = np.asarray(result.valid, dtype=bool)
    if closed and samples is None:
        raise CurveError("samples is required for a closed approximation (its t wrap at it)")
    if samples is not None:
        samples = as_int(samples, name="samples", minimum=2)
        scale = float(samples if closed else samples - 1)
    else:
        scale = 1.0
    mid = _middle_parameters(t, float(samples) if closed and samples else None) / scale
    if mid.size != km.size:
        raise CurveError(
            f"result has {km.size} kappa_m for {t.size} vertices: not an Approximation"
        )
    if exact is not None:
        lo, hi = (0.0, 1.0) if samples is not None else (float(t.min()), float(t.max()))
        uu = np.linspace(lo, hi, 600)
        ax.plot(
            uu,
            np.asarray(exact(uu), dtype=float),
            color="0.3",
            lw=0.8,
            label="exact affine curvature",
        )
    pieces = int(np.asarray(result.piece_areas).size)
    used = valid.copy()
    if pieces > 1 and skip > 0:
        for run in np.split(np.arange(valid.size), np.flatnonzero(np.diff(valid.astype(int))) + 1):
            if valid[run[0]]:
                used[run[:skip]] = used[run[-skip:]] = False
    ax.plot(mid[used], km[used], "o", ms=3.5, color="tab:blue", label="kappa_i^m = k_i |A|^(-2/3)")
    unused = valid & ~used
    if unused.any():
        ax.plot(
            mid[unused],
            km[unused],
            "o",
            ms=6,
            mfc="none",
            color="tab:red",
            label=f"kappa_i^m not used in the objective (l = {skip})",
        )
    for k, j in enumerate(np.asarray(result.joins, dtype=int)):
        ax.axvline(
            t[j] / scale, color="k", lw=0.6, ls=":", label="join (inflection)" if k == 0 else None
        )
    ax.set_xlabel("sample parameter u" if samples is not None else "sample index t")
    ax.set_ylabel("affine curvature")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    if title:
        ax.set_title(title)
    return ax


def spline_curvature(
    splines: Mapping[str, Any],
    *,
    per_segment: int = 24,
    samples: int = 6000,
    ax: Axes | None = None,
    title: str | None = None,
) -> Axes:
    """Euclidean curvature along planar splines, to see which are curvature continuous.

    The uniform quadratic B-spline of an affine arc length polyline is G2 (Käferböck):
    its curvature is continuous across the knots; a least-squares or interpolating
    quadratic spline of the same data is only C1 and its curvature jumps at every knot.

    Parameters
    ----------
    splines : dict of str to control polygon or scipy BSpline
        Label to either an ``(N, 2)`` control polygon, whose uniform quadratic B-spline
        (:func:`curvesmith.affine.spline_curvature`) is drawn, or a 2-D
        :class:`scipy.interpolate.BSpline` (e.g. from ``make_lsq_spline``), evaluated at
        `samples` uniform parameters.
    per_segment : int, optional
        Samples per segment of a control polygon's spline.
    samples : int, optional
        Samples of a scipy spline.
    ax : matplotlib Axes, optional
    title : str, optional

    Returns
    -------
    matplotlib Axes
        x: the spline parameter normalised to ``[0, 1]``.

    Examples
    --------
    >>> import numpy as np
    >>> from curvesmith import plot
    >>> t = np.linspace(0, 1.5, 9)
    >>> ax = plot.spline_curvature({"arc": np.c_[np.cos(t), np.sin(t)]})
    >>> k = ax.lines[0].get_ydata()
    >>> bool(0.95 < k.min() < k.max() < 1.05)
    True
    """
    from ..affine import spline_curvature as control_curvature
    from ..errors import CurveError

    if ax is None:
        _, (ax,) = new_axes(width=9.0, height=4.0)
    for name, spline in splines.items():
        if hasattr(spline, "derivative"):
            k = int(spline.k)
            lo, hi = float(spline.t[k]), float(spline.t[-k - 1])
            u = np.linspace(lo, hi, as_int(samples, name="samples", minimum=2))
            d1, d2 = np.asarray(spline.derivative(1)(u)), np.asarray(spline.derivative(2)(u))
            if d1.ndim != 2 or d1.shape[1] != 2:
                raise CurveError(
                    f"splines[{name!r}] must be a planar spline, got values of shape {d1.shape}"
                )
            speed = np.hypot(d1[:, 0], d1[:, 1])
            kappa = (d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]) / speed**3
        else:
            u, kappa = control_curvature(
                as_points(spline, name=f"splines[{name!r}]", min_points=3), per_segment=per_segment
            )
            lo, hi = float(u[0]), float(u[-1])
        ax.plot((u - lo) / (hi - lo), kappa, lw=1.0, label=name)
    ax.set_xlabel("normalised spline parameter")
    ax.set_ylabel("Euclidean curvature")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    if title:
        ax.set_title(title)
    return ax
