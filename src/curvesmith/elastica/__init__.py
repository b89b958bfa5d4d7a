"""Discrete Euler elastica: exact solutions, curvature, initial guess and fairing.

Implements Graiff Zurita, Kajiwara & Suzuki, "Fairing of discrete planar curves
by integrable discrete analogue of Euler's elasticae", sections 3-4:

* :func:`tangent_angles`, :func:`curvature`, :func:`segment_length` - discrete
  curves of section 3.1 (eqs. 3.1, 3.4, 4.32, 4.33);
* :func:`sample`, :func:`exact_curvature`, :func:`invariants` - the discrete
  elastica ``p = (x0, y0, h, phi, z, q, k)`` (eqs. 4.2-4.5, one family in the
  continued modulus ``k``: ``k < 1`` has inflections, ``k > 1`` is case (i) with
  modulus ``1/k``), its curvature (3.20) and constants ``alpha``, ``C`` (3.9, 3.18);
* :func:`initial_guess` - the pseudo code of section 4.3;
* :func:`fit` - the closest discrete elastica to data (section 4.2), with
  :func:`needs_resampling` telling whether data need resampling first;
* :func:`fit_segments` - the fewest discrete elasticae, joined G1, within a tolerance.

Examples
--------
>>> import numpy as np
>>> from curvesmith import elastica
>>> pts = elastica.sample((0, 0, 0.05, 0.2, 0.05, 0.1, 0.5), 80)
>>> noisy = pts + np.random.default_rng(0).normal(scale=1e-3, size=pts.shape)
>>> res = elastica.fit(noisy)
>>> err = np.sqrt(np.mean(np.sum((res.points - pts) ** 2, axis=1)))  # to the clean curve
>>> bool(res.success), bool(err < 1e-3), res.case
(True, True, 'ii')
"""

from .exact import (
    ElasticaParams,
    Invariants,
    case_of,
    curvature,
    exact_curvature,
    invariants,
    sample,
    segment_length,
    tangent_angles,
)
from .fit import PARAM_NAMES, SPACING_TOL, FitResult, fit, needs_resampling, spacing_spread
from .guess import initial_guess
from .segments import Joint, Segment, SegmentFit, fit_segments

__all__ = [
    "PARAM_NAMES",
    "SPACING_TOL",
    "ElasticaParams",
    "FitResult",
    "Invariants",
    "Joint",
    "Segment",
    "SegmentFit",
    "case_of",
    "curvature",
    "exact_curvature",
    "fit",
    "fit_segments",
    "initial_guess",
    "invariants",
    "needs_resampling",
    "sample",
    "segment_length",
    "spacing_spread",
    "tangent_angles",
]
