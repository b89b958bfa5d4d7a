"""How results show themselves in Jupyter: a small figure beside their key numbers.

The result dataclasses of the methods (cca, derham, affine, elastica, keyline, curves and
geo) inherit :class:`RichRepr`, whose ``_repr_html_`` is what Jupyter, VS Code and
nbviewer display for the last value of a cell. The numbers are the ones a user checks
first (what converged, how close, what was kept); the figure is drawn by
:func:`curvesmith.plot.result_figure` and embedded as inline SVG. Without matplotlib the
numbers are shown alone; ``repr`` stays the dataclass's own.
"""

from __future__ import annotations

import math
from html import escape
from typing import Any

__all__ = ["RichRepr", "summary"]


class RichRepr:
    """Mixin for result dataclasses: a rich HTML representation for notebooks."""

    __slots__ = ()

    def _repr_html_(self) -> str:
        rows = "".join(
            f"<tr><th style='text-align:left;padding-right:1em'>{escape(k)}</th>"
            f"<td style='text-align:left'>{escape(_text(v))}</td></tr>"
            for k, v in summary(self)
        )
        figure = ""
        try:
            from .plot import result_svg

            figure = result_svg(self) or ""
        except ImportError:  # matplotlib missing: the numbers alone
            figure = ""
        return (
            f"<div class='curvesmith-result'><b>{escape(type(self).__name__)}</b>"
            f"<div style='display:flex;gap:1em;align-items:flex-start'>{figure}"
            f"<table>{rows}</table></div></div>"
        )


def _text(v: Any) -> str:
    if isinstance(v, bool) or v is None:
        return str(v)
    if isinstance(v, float):
        return "nan" if math.isnan(v) else f"{v:.6g}"
    return str(v)


def _ncoords(geometry: Any) -> int:
    import shapely

    values = getattr(geometry, "geometry", geometry)
    values = getattr(values, "values", values)
    return int(shapely.get_num_coordinates(list(values)).sum()) if len(values) else 0


def summary(result: Any) -> list[tuple[str, Any]]:
    """The key numbers of a result, as ``(label, value)`` pairs (what the notebook shows).

    Examples
    --------
    >>> import numpy as np
    >>> from curvesmith import cca
    >>> res = cca.smooth_with_info(np.array([[0, 0], [2, 0], [2, 1], [0, 1.0]]), closed=True)
    >>> dict(summary(res))["vertices"], dict(summary(res))["success"]
    (12, True)
    """
    name = type(result).__name__
    r = result
    if name == "CCAResult":
        return [
            ("vertices", len(r.points)),
            ("iterations", r.iterations),
            ("alpha reductions", r.reductions),
            ("unsatisfied restrictions", r.unsatisfied),
            ("success", r.success),
            ("message", r.message),
        ]
    if name == "RaggedCCAResult":
        return [
            ("curves", len(r.offsets) - 1),
            ("vertices", len(r.coords)),
            ("iterations", r.iterations),
            ("unsatisfied restrictions", int(r.unsatisfied.sum())),
        ]
    if name == "LengthResult":
        return [
            ("length", r.value),
            ("certified bracket", f"[{r.lower:.15g}, {r.upper:.15g}]"),
            ("width", r.upper - r.lower),
            ("level", r.level),
            ("success", r.success),
            ("message", r.message),
        ]
    if name == "InterpolationResult":
        return [
            ("x", r.x),
            ("length", r.length),
            ("certified bracket", f"[{r.lower:.15g}, {r.upper:.15g}]"),
            ("evaluations", r.evaluations),
            ("certified", r.certified),
            ("success", r.success),
            ("message", r.message),
        ]
    if name == "ChainResult":
        return [
            ("spans", len(r.spans)),
            ("length", r.length),
            ("certified bracket", f"[{r.lower:.15g}, {r.upper:.15g}]"),
            ("success", r.success),
            ("message", r.message),
        ]
    if name == "Approximation":
        return [
            ("vertices", len(r.points)),
            ("closed", r.closed),
            ("area", r.area),
            ("end gap (edges)", r.end_gap),
            ("evaluations", r.evaluations),
            ("success", r.success),
            ("message", r.message),
        ]
    if name == "FitResult":
        p = r.params
        rows: list[tuple[str, Any]] = [
            ("points", len(r.data)),
            ("rms, eq. (4.8)", r.rms),
            ("rms distance", r.rms_deviation),
            ("max distance", r.max_deviation),
            ("noise level", r.noise),
            ("elastica", f"{r.case}, k = {p.k:.6g}, h = {p.h:.6g}"),
            ("iterations", r.total_iterations or r.iterations),
            ("success", r.success),
        ]
        if r.tolerance is not None:
            rows.append(("within tolerance", f"{r.within_tolerance} (T = {r.tolerance:g})"))
        return [*rows, ("message", r.message)]
    if name == "KeylineFit":
        fits = [f for f in (r.left, r.right, r.whole) if f is not None] or [
            f for f in r.pieces if f is not None
        ]
        return [
            ("points", len(r.points)),
            ("step", r.step),
            ("resampling", r.resampling),
            ("pieces fitted", len(fits)),
            ("worst rms", max((f.rms for f in fits), default=float("nan"))),
            ("all converged", all(f.success for f in fits)),
        ]
    if name == "CurveFit":
        return [
            ("segments", len(r.segments)),
            ("degree", r.degree),
            ("closed", r.closed),
            ("max deviation", r.deviation),
            ("tolerance", r.tolerance),
            ("area change", r.area - r.target_area),
            ("curvature jump at inflections", r.inflection_jump),
            ("success", r.success),
        ]
    if name in ("SmoothResult", "CoverageResult", "NetworkResult", "ContourResult"):
        geometry = r.geometry
        rows = [("features", len(geometry)), ("vertices", _ncoords(geometry))]
        if name == "ContourResult":
            return [*rows, ("levels", len(r.levels)), *summary(r.smoothing)[2:]]
        if name == "NetworkResult":
            rows += [("lines", r.n_lines), ("arcs", r.n_arcs), ("nodes", r.n_nodes)]
            rows += [("max area change (closed)", r.max_area_change)]
        elif name == "CoverageResult":
            rows += [("arcs", r.n_arcs), ("nodes", r.n_nodes), ("coverage valid", r.coverage_valid)]
            rows += [("max area change", r.max_area_change)]
        else:
            rows += [("curves", r.n_curves), ("max area change", r.max_area_change)]
        return [*rows, ("pieces smoothed less", len(r.reductions))]
    fields = getattr(result, "__dataclass_fields__", {})
    return [
        (k, getattr(result, k))
        for k in fields
        if isinstance(getattr(result, k), int | float | bool | str)
    ]
