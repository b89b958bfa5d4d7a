"""curvesmith: discrete planar curves with exact geometric guarantees.

Modules
-------
geometry
    Shared primitives: signed area, lengths, angles, intersections, curvature.
subdivision
    Linear corner cutting: Chaikin, de Rham, Lane–Riesenfeld (any dimension).
cca
    Area-preserving smoothing by corner cutting and augmentation (Gordon).
derham
    Certified de Rham curve lengths; G1 curves of a prescribed length (Merrien).
affine
    Affine arc length polylines, affine curvature, G2 quadratic B-splines (Käferböck).
elastica
    Discrete Euler elastica: exact solutions, initial guess and fit
    (Graiff Zurita, Kajiwara, Suzuki).
keyline
    The scan-to-keyline pipeline of the elastica paper (plane fit, resampling,
    inflection estimate, two-sided fit).
curves
    Fewest G2 quadratic or cubic Bézier segments within a tolerance, areas exact.
glyphs
    Font glyph contours refitted as curvature continuous quadratic B-splines.
io
    Curve files, one module per format (CSV, GeoJSON, SVG, scan tables, fonts).
plot
    Matplotlib figures: overlays, curvature combs, convergence plots.
geo, batch
    Shapely/GeoPandas geometries, coverages and files (extra ``geo``) and Dask
    batch processing (extra ``dask``).

Capability modules are imported on first use, so ``import curvesmith`` is cheap.

The most used functions are re-exported here:

>>> import curvesmith as cs
>>> cs.signed_area([[0, 0], [2, 0], [2, 1], [0, 1]])
2.0
"""

from __future__ import annotations

import importlib
from importlib.metadata import PackageNotFoundError, version

from . import errors, geometry, subdivision
from .errors import CurveError
from .geometry import curve_length, signed_area

try:
    __version__ = version("curvesmith")
except PackageNotFoundError:  # pragma: no cover - running from a source tree
    __version__ = "0.0.0"

# Capability modules load on first use (``cs.cca``, ``from curvesmith import affine``):
# ``import curvesmith`` and the CLI start fast, and geo/batch need optional extras.
_LAZY = (
    "affine",
    "batch",
    "cca",
    "curves",
    "derham",
    "elastica",
    "geo",
    "glyphs",
    "io",
    "keyline",
    "methods",
    "plot",
)

__all__ = [
    "CurveError",
    "__version__",
    "affine",
    "batch",
    "cca",
    "curve_length",
    "curves",
    "derham",
    "elastica",
    "errors",
    "geo",
    "geometry",
    "glyphs",
    "io",
    "keyline",
    "methods",
    "plot",
    "signed_area",
    "subdivision",
]


def __getattr__(name: str):
    if name in _LAZY:
        return importlib.import_module(f"{__name__}.{name}")
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))
