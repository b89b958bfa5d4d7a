"""curvesmith: discrete planar curves with exact geometric guarantees.

Modules
-------
geometry
    Shared primitives: signed area, lengths, angles, intersections.
subdivision
    Linear corner cutting: Chaikin, de Rham, Lane–Riesenfeld.

The most used functions are re-exported here:

>>> import curvesmith as cs
>>> cs.signed_area([[0, 0], [2, 0], [2, 1], [0, 1]])
2.0
"""

from __future__ import annotations

from importlib.metadata import PackageNotFoundError, version

from . import errors, geometry, subdivision
from .errors import CurveError
from .geometry import curve_length, signed_area

try:
    __version__ = version("curvesmith")
except PackageNotFoundError:  # pragma: no cover - running from a source tree
    __version__ = "0.0.0"

__all__ = [
    "CurveError",
    "__version__",
    "curve_length",
    "errors",
    "geometry",
    "signed_area",
    "subdivision",
]
