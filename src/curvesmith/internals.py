"""The internal API: the names below the public ones that the test suite relies on.

Kernels are tested against their plain references, block sizes are shrunk to exercise the
chunked paths, file writers are made to fail midway, and private solvers are checked step by
step. For that the tests need names that are not public, and they reach them only through this
module (``tests/test_vocabulary.py`` checks every test file). So this file is the list of what a
refactoring must keep, or change together with the tests; everything else with a leading
underscore is private to its module.

Not part of the public contract: no deprecation period, but no change without the tests.
"""

from __future__ import annotations

# the input gate: the checks every public function calls, and the vertex cap tests lower;
# the ragged batches' gate (its compiled pass from COMPILED_MIN rows, lowered in tests)
from . import _ragged as ragged
from . import _validate as validate
from ._gc import paused_gc
from ._validate import as_bool, as_choice, as_float, as_int, as_points, check_growth

# affine: the compiled section-4 construction and the Python loop it compiles
from .affine import _kernel as affine_kernel
from .affine.approximation import _construct as affine_construct
from .affine.approximation import _Curve as AffineConstructionCurve

# cca: the compiled 2D kernel, the numpy reference (restriction rules, N-d step, the
# profile's interior angle), the block and thread split of long curves and batches
# (BLOCK, THREAD_MIN are shrunk in tests)
from .cca import _angle as cca_angle
from .cca import _api as cca_api
from .cca import _input as cca_input
from .cca import _kernel as cca_kernel
from .cca import _restrict as cca_restrict
from .cca import _stepnd as cca_stepnd
from .cca._api import _blocks as cca_blocks
from .cca._api import _chunks as cca_chunks
from .cca._api import _smooth_one as cca_smooth_one

# curves: one fitted piece, and the exact point-to-polyline distance of the fit check
from .curves import _Piece as CurvePiece
from .curves import _to_polyline as distance_to_polyline

# derham: the triangle of one de Rham corner
from .derham import _triangle as derham_triangle

# elastica: elliptic functions, scan geometry, the fit's problem and noise estimates
from .elastica import _varpro as elastica_varpro
from .elastica._elliptic import amplitude_dm, ellipj, ellipj_am, sd2_integral
from .elastica._geom import chord_walk, point_polyline_distance, walk_to_end
from .elastica._varpro import _period as elastica_varpro_period
from .elastica.exact import _as_params as elastica_params
from .elastica.exact import _positions_and_jacobian as elastica_positions_and_jacobian
from .elastica.fit import _glitch_free_noise as glitch_free_noise
from .elastica.fit import _noise_level as noise_level
from .elastica.fit import _Problem as ElasticaProblem
from .elastica.fit import _reverse_params as reverse_params
from .elastica.fit import _savgol as savgol
from .elastica.fit import _scan_noise as scan_noise
from .elastica.segments import _chain as segment_chain
from .elastica.segments import _ChainProblem as ChainProblem

# geometry: the unchecked shoelace and the two equilateral resampling rules
from .geometry import _resample_equilateral as resample_equilateral_with_positions
from .geometry import _resample_walk as resample_walk
from .geometry import _signed_area as signed_area_unchecked

# io: the registry and the streaming writer (chunk sizes, a sink made to fail)
from .io import _core as io_core
from .io._core import _Utf8Sink as Utf8Sink
from .io.svg import _ABSOLUTE_POLYLINE_D as svg_absolute_polyline_pattern
from .io.svg import _POLYLINE_D as svg_polyline_pattern

__all__ = [
    "AffineConstructionCurve",
    "ChainProblem",
    "CurvePiece",
    "ElasticaProblem",
    "Utf8Sink",
    "affine_construct",
    "affine_kernel",
    "amplitude_dm",
    "as_bool",
    "as_choice",
    "as_float",
    "as_int",
    "as_points",
    "cca_angle",
    "cca_api",
    "cca_blocks",
    "cca_chunks",
    "cca_input",
    "cca_kernel",
    "cca_restrict",
    "cca_smooth_one",
    "cca_stepnd",
    "check_growth",
    "chord_walk",
    "derham_triangle",
    "distance_to_polyline",
    "elastica_params",
    "elastica_positions_and_jacobian",
    "elastica_varpro",
    "elastica_varpro_period",
    "ellipj",
    "ellipj_am",
    "glitch_free_noise",
    "io_core",
    "lazy_modules",
    "noise_level",
    "paused_gc",
    "point_polyline_distance",
    "ragged",
    "resample_equilateral_with_positions",
    "resample_walk",
    "reverse_params",
    "savgol",
    "scan_noise",
    "sd2_integral",
    "segment_chain",
    "signed_area_unchecked",
    "svg_absolute_polyline_pattern",
    "svg_polyline_pattern",
    "validate",
    "walk_to_end",
]

#: the capability modules ``import curvesmith`` loads on first use
from . import _LAZY as lazy_modules


def __getattr__(name: str):
    """The GIS and CLI internals load on first use (they need the optional extras)."""
    if name in _ON_DEMAND:
        module, attr = _ON_DEMAND[name]
        import importlib

        obj = importlib.import_module(module, __package__)
        return getattr(obj, attr) if attr else obj
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


# name -> (module, attribute or None for the module itself)
_ON_DEMAND: dict[str, tuple[str, str | None]] = {
    "cli_group": (".cli", "_Group"),
    "measure_ragged": (".cli._measure", "measure_ragged"),
    "geo_io": (".geo._io", None),
    "geo_engine": (".geo._engine", None),
    "geo_smooth": (".geo._smooth", None),
    "geo_coverage": (".geo._coverage", None),
    "geo_simple": (".geo._simple", None),
    "geo_packets": (".geo._packets", None),
    "geo_handover": (".geo._handover", None),
    "clearance_kernel": (".geo._clearance_kernel", None),
    "geo_shift": (".geo._shift", None),
    "BatchProgressBar": (".batch", "_ProgressBar"),
    "batch_smooth_partition": (".batch", "_smooth_partition"),
    "BatchWorkers": (".batch", "_Workers"),
    "batch_local_scheduler": (".batch", "_local_scheduler"),
    "lon_arc": (".geo._io", "_lon_arc"),
    "slices": (".geo._io", "_slices"),
    "coverage_ragged": (".geo._coverage", "_ragged"),
    "coverage_patched": (".geo._coverage", "_patched"),
    "geo_chunks": (".geo._smooth", "_chunks"),
    "arrangement_kernel": (".geo._arrangement_kernel", None),
    "coverage_flat_uses": (".geo._coverage", "_flat_uses"),
    "coverage_shells": (".geo._coverage", "_shells"),
    "coverage_output_valid": (".geo._coverage", "_output_valid"),
    "coverage_arc_meetings": (".geo._coverage", "_arc_meetings"),
    "coverage_valid_by_proof": (".geo._coverage", "_valid_by_proof"),
    "engine_meeting_pairs": (".geo._engine", "_meeting_pairs"),
    "engine_closed_lines": (".geo._engine", "_closed_lines"),
    "engine_lines": (".geo._engine", "_lines"),
    "engine_solo_loops": (".geo._engine", "_solo_loops"),
    "EnginePieceTable": (".geo._engine", "_PieceTable"),
    "close_ragged": (".geo._smooth", "_close_ragged"),
    "EnginePiece": (".geo._engine", "_Piece"),
    "simple_kernel": (".geo._simple_kernel", None),
    "topology_kernel": (".geo._topology_kernel", None),
}
__all__ += sorted(_ON_DEMAND)
