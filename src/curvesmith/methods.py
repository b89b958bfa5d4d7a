"""The smoothing methods: one table that the CLI, ``curvesmith.geo`` and ``batch`` read.

Every smoothing method of the library is one :class:`SmoothingMethod` row of
:data:`METHODS`: its name, what it guarantees, the keywords it takes, and its one-curve
and many-curve functions. The CLI's ``--method`` choices, the GIS layer functions'
``method`` check and their messages ("keep_angle needs ...") come from here, so adding a
method is one row (and its functions); nothing else lists the names.

Examples
--------
>>> from curvesmith import methods
>>> sorted(methods.METHODS)
['cca', 'chaikin', 'derham', 'lane_riesenfeld']
>>> methods.gis_names()
('cca', 'chaikin')
>>> m = methods.get("derham")
>>> m.smooth([[0, 0], [3, 0], [3, 3]], closed=False, iterations=1, gamma=2.0).shape
(4, 2)
>>> methods.get("spline")  # doctest: +ELLIPSIS
Traceback (most recent call last):
...
curvesmith.errors.CurveError: method must be one of 'cca', 'chaikin', ..., got 'spline'
>>> methods.get("chaikin").smooth([[0, 0], [3, 0]], closed=False, gamma=3.0)  # doctest: +ELLIPSIS
Traceback (most recent call last):
...
curvesmith.errors.CurveError: gamma applies to method 'derham', not to method 'chaikin' ...
"""

from __future__ import annotations

import importlib
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from types import MappingProxyType
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike

from ._validate import as_choice
from .errors import CurveError

__all__ = [
    "METHODS",
    "GisMethod",
    "MethodName",
    "SmoothingMethod",
    "as_gis",
    "get",
    "gis_names",
    "needs",
]

#: The names of :data:`METHODS`, for annotations (a test keeps the two equal).
MethodName = Literal["cca", "chaikin", "derham", "lane_riesenfeld"]
#: The names of the methods for GIS layers (``gis=True``).
GisMethod = Literal["cca", "chaikin"]


@dataclass(frozen=True)
class SmoothingMethod:
    """One smoothing method and what it guarantees.

    Attributes
    ----------
    name : str
        The name users give (``method=`` in Python, ``--method`` in the CLI).
    summary : str
        One line for help texts.
    keeps_area : bool
        Every closed ring keeps its signed area exactly, and every open curve the area
        between itself and its chord (CCA); the linear methods shrink.
    keeps_vertices : bool
        Chosen vertices can stay where they are (``anchors`` / ``fixed`` /
        ``keep_angle``); the linear methods move every vertex.
    scalable : bool
        The method has a strength below one full iteration (CCA's alpha can be scaled
        down), which the GIS layer functions use to smooth conflicting pieces less.
    gis : bool
        Available for GIS layers (``geo.smooth``, coverages, networks, ``batch``).
    growth : int
        A closed ring's vertex count grows at most this many times per iteration.
    parameters : tuple of str
        The method's own keywords beyond ``closed`` and ``iterations``.
    single : callable
        ``single(points, *, closed, iterations, **parameters) -> ndarray``.
    ragged : callable
        ``ragged(coords, offsets, *, closed, iterations, **parameters) -> (coords, offsets)``,
        every curve bit for bit what `single` gives it.
    """

    name: str
    summary: str
    keeps_area: bool
    keeps_vertices: bool
    scalable: bool
    gis: bool
    growth: int
    parameters: tuple[str, ...]
    single: Callable[..., np.ndarray]
    ragged: Callable[..., tuple[np.ndarray, np.ndarray]]

    def _check(self, params: Mapping[str, Any]) -> None:
        for key in params:
            if key not in self.parameters:
                takers = [m.name for m in METHODS.values() if key in m.parameters]
                where = f"method {' or '.join(map(repr, takers))}" if takers else "no method"
                raise CurveError(
                    f"{key} applies to {where}, not to method {self.name!r} "
                    f"(which takes {', '.join(self.parameters) or 'no options'})"
                )

    def smooth(
        self, points: ArrayLike, *, closed: bool, iterations: int = 1, **parameters: Any
    ) -> np.ndarray:
        """Smooth one curve; `parameters` must be among :attr:`parameters`."""
        self._check(parameters)
        if "close_rings" in parameters:  # a layout of the ragged output
            raise CurveError(
                "close_rings applies to smooth_ragged (many curves in one array), not to "
                "smooth (one curve)"
            )
        return self.single(points, closed=closed, iterations=iterations, **parameters)

    def smooth_ragged(
        self,
        coords: ArrayLike,
        offsets: ArrayLike,
        *,
        closed: Any,
        iterations: int = 1,
        **parameters: Any,
    ) -> tuple[np.ndarray, np.ndarray]:
        """Smooth many curves (one coordinate array plus offsets) in one call."""
        self._check(parameters)
        return self.ragged(coords, offsets, closed=closed, iterations=iterations, **parameters)


def _lazy(module: str, name: str) -> Callable[..., Any]:
    """``curvesmith.<module>.<name>``, imported at its first call.

    ``import curvesmith`` loads no capability module; the table names them all.
    """

    def call(*args: Any, **kw: Any) -> Any:
        return getattr(importlib.import_module(f"{__package__}.{module}"), name)(*args, **kw)

    call.__name__ = call.__qualname__ = name
    return call


_CCA_PARAMETERS = (
    "alpha",
    "anchors",
    "corner_ratio",
    "inflection_ratio",
    "restrict",
    "tilt",
    "balance_tol",
    "max_passes",
    "min_factor",
    "threads",
    "close_rings",  # the ragged function's: rings written with their first vertex repeated
)

#: Every smoothing method by name (read-only).
METHODS: Mapping[str, SmoothingMethod] = MappingProxyType(
    {
        m.name: m
        for m in (
            SmoothingMethod(
                name="cca",
                summary="corner cutting and augmentation: every enclosed area exactly (Gordon)",
                keeps_area=True,
                keeps_vertices=True,
                scalable=True,
                gis=True,
                growth=3,
                parameters=_CCA_PARAMETERS,
                single=_lazy("cca", "smooth"),
                ragged=_lazy("cca", "smooth_ragged"),
            ),
            SmoothingMethod(
                name="chaikin",
                summary="Chaikin's corner cutting (quarter points; shrinks)",
                keeps_area=False,
                keeps_vertices=False,
                scalable=False,
                gis=True,
                growth=2,
                parameters=("preserve_endpoints", "close_rings"),  # close_rings: ragged
                single=_lazy("subdivision", "chaikin"),
                ragged=_lazy("subdivision", "chaikin_ragged"),
            ),
            SmoothingMethod(
                name="derham",
                summary="de Rham corner cutting, ratio 1:gamma:1 (shrinks)",
                keeps_area=False,
                keeps_vertices=False,
                scalable=False,
                gis=False,
                growth=2,
                parameters=("gamma", "preserve_endpoints", "close_rings"),
                single=_lazy("subdivision", "de_rham"),
                ragged=_lazy("subdivision", "de_rham_ragged"),
            ),
            SmoothingMethod(
                name="lane_riesenfeld",
                summary="Lane-Riesenfeld subdivision towards the uniform B-spline of a degree",
                keeps_area=False,
                keeps_vertices=False,
                scalable=False,
                gis=False,
                growth=2,
                parameters=("degree", "preserve_endpoints"),
                single=_lazy("subdivision", "lane_riesenfeld"),
                ragged=_lazy("subdivision", "lane_riesenfeld_ragged"),
            ),
        )
    }
)


def get(name: str, *, gis: bool = False) -> SmoothingMethod:
    """The method called `name`; with ``gis=True`` only the methods for GIS layers.

    Raises
    ------
    CurveError
        Naming ``method`` and listing the valid names.
    """
    return METHODS[as_choice(name, gis_names() if gis else tuple(METHODS), name="method")]


def as_gis(name: str) -> GisMethod | None:
    """`name` (typed as :data:`GisMethod`) if it names a method for GIS layers, else None.

    >>> as_gis("chaikin"), as_gis("derham")
    ('chaikin', None)
    """
    m = get(name)
    return m.name if m.gis else None  # type: ignore[return-value]  # the table's gis rows


def gis_names() -> tuple[str, ...]:
    """The names of the methods available for GIS layers."""
    return tuple(name for name, m in METHODS.items() if m.gis)


def needs(
    option: str,
    method: str,
    *,
    capability: Literal["keeps_vertices", "keeps_area", "scalable"] = "keeps_vertices",
) -> None:
    """Raise if `option` needs a method with `capability` and `method` has not got it.

    The message names the option, the methods that have the capability, and why
    (``keep_angle needs method='cca' (chaikin moves every vertex), got 'chaikin'``).
    """
    m = get(method)
    if getattr(m, capability):
        return
    able = [n for n, x in METHODS.items() if getattr(x, capability)]
    why = {
        "keeps_vertices": "moves every vertex",
        "keeps_area": "does not keep areas",
        "scalable": "has no strength below one iteration",
    }[capability]
    raise CurveError(
        f"{option} needs method={' or '.join(map(repr, able))} ({m.name} {why}), got {method!r}"
    )
