"""The algorithms' parameters as one table, and the ``curvesmith`` command line built from it.

Every Processing parameter besides ``INPUT`` and ``OUTPUT`` is one :class:`Option` row of
:data:`OPTIONS`: its name is the CLI option's in upper case (``--make-valid`` ->
``MAKE_VALID``), its default is the CLI's, and :func:`build_argv` turns the values into
arguments. Adding a CLI option to the plugin is one new row.

This module imports nothing from QGIS, so the table can be checked against the CLI's own
definitions from curvesmith's environment (``tests/test_qgis_plugin.py`` does).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

__all__ = [
    "ALGORITHMS",
    "OPTIONS",
    "AlgorithmSpec",
    "Option",
    "build_argv",
    "is_batch",
    "options_for",
]


@dataclass(frozen=True)
class AlgorithmSpec:
    """One Processing algorithm: which CLI command it runs, on which geometries.

    Attributes
    ----------
    name : str
        Algorithm id within the provider (``curvesmith:<name>``).
    display_name : str
        Name shown in the toolbox.
    flags : tuple of str
        CLI flags the algorithm always passes (``--coverage``, ``--network``).
    geometry : {"polygon_line", "polygon", "line"}
        Geometry types the input may have.
    summary : str
        First paragraph of the help panel.
    """

    name: str
    display_name: str
    flags: tuple[str, ...]
    geometry: str
    summary: str


ALGORITHMS = (
    AlgorithmSpec(
        "smooth",
        "Smooth (area-preserving)",
        (),
        "polygon_line",
        "Smooths every polygon and line of the layer with curvesmith (<code>curvesmith smooth"
        "</code>). The default method, cca (Gordon's corner cutting and augmentation), keeps "
        "the area of every ring exactly, and for a line the area between the line and its "
        "chord; outputs stay valid (pieces that would self-intersect are smoothed less and "
        "reported). Each feature is smoothed on its own: use <i>Smooth coverage</i> for "
        "polygons that share borders.",
    ),
    AlgorithmSpec(
        "smoothcoverage",
        "Smooth coverage (no gaps)",
        ("--coverage",),
        "polygon",
        "Smooths a polygon coverage such as counties or parcels (<code>curvesmith smooth "
        "--coverage</code>): every border that two polygons share is smoothed once, so the "
        "output has no gaps or overlaps, and every polygon keeps its area exactly (cca). "
        "QGIS's own Smooth tool shrinks each polygon and opens gaps between neighbours.",
    ),
    AlgorithmSpec(
        "smoothnetwork",
        "Smooth line network",
        ("--network",),
        "line",
        "Smooths a network of lines such as rivers, roads, boundaries or contour lines "
        "(<code>curvesmith smooth --network</code>): points where lines meet stay fixed, a "
        "piece that two lines share is smoothed once, and no two output lines touch or "
        "cross unless their inputs did. Needs a curvesmith with the <code>--network</code> "
        "option.",
    ),
)

_ALL = tuple(a.name for a in ALGORITHMS)


@dataclass(frozen=True)
class Option:
    """One CLI option as a Processing parameter.

    Attributes
    ----------
    name : str
        Parameter name (the option's long name in upper case, ``-`` as ``_``).
    flag : str
        The CLI option.
    kind : {"enum", "int", "float", "string", "bool"}
        Parameter type; a "bool" is a CLI flag given only when true.
    default : object
        Default value: the CLI's (for "enum" the choice itself, not its index).
    label : str
        Short description shown in the dialog.
    help : str
        Help panel text.
    choices : tuple of str
        Values of an "enum".
    optional : bool
        May be left empty (the option is then not passed).
    minimum : float, optional
        Smallest value of a number.
    advanced : bool
        Shown under "Advanced parameters".
    batch : {"", "trigger", "only"}
        ``"trigger"``: a value runs ``curvesmith batch smooth`` (Dask) instead of
        ``curvesmith smooth``; ``"only"``: passed only in that mode.
    algorithms : tuple of str
        Algorithms that have this parameter.
    """

    name: str
    flag: str
    kind: str
    default: Any
    label: str
    help: str
    choices: tuple[str, ...] = ()
    optional: bool = False
    minimum: float | None = None
    advanced: bool = False
    batch: str = ""
    algorithms: tuple[str, ...] = _ALL


OPTIONS = (
    Option(
        "METHOD",
        "--method",
        "enum",
        "cca",
        "Method",
        "cca keeps every ring's area exactly (and a line's area against its chord); chaikin "
        "is linear corner cutting, which shrinks polygons.",
        choices=("cca", "chaikin"),
    ),
    Option(
        "ITERATIONS",
        "--iterations",
        "int",
        1,
        "Iterations",
        "Smoothing passes; each cca pass triples the number of vertices.",
        minimum=0,
    ),
    Option(
        "ALPHA",
        "--alpha",
        "string",
        "regular",
        "Alpha (cca cut parameter)",
        "cca's cut parameter: 'regular' (Gordon's angle-dependent profile) or a number in "
        "(0, 1/3); larger cuts deeper.",
    ),
    Option(
        "EQUAL_AREA",
        "--equal-area",
        "bool",
        False,
        "Smooth in an equal-area projection",
        "For layers in degrees: smooth in a Lambert azimuthal equal-area projection centred "
        "on the data and project back, so that ground areas are the ones kept.",
    ),
    Option(
        "MAKE_VALID",
        "--make-valid",
        "bool",
        False,
        "Repair invalid polygons first",
        "Repair invalid input polygons (shapely.make_valid) instead of failing on them.",
        algorithms=("smooth", "smoothcoverage"),
    ),
    Option(
        "KEEP_ANGLE",
        "--keep-angle",
        "float",
        None,
        "Keep corners sharper than (degrees)",
        "cca: vertices that turn by more than this angle stay where they are (building "
        "footprints, parcels, field boundaries); every ring still keeps its area. Empty: "
        "no corner is kept.",
        optional=True,
        minimum=0.0,
    ),
    Option(
        "MAX_SHIFT",
        "--max-shift",
        "float",
        None,
        "Largest shift of a boundary (layer units)",
        "Strength in map units: no feature moves farther than this (fewer or shallower "
        "passes for the features that would; per shared border in coverage mode, per piece "
        "between junctions in network mode); areas stay exact. Empty: no bound.",
        optional=True,
        minimum=0.0,
        algorithms=("smooth", "smoothcoverage", "smoothnetwork"),
    ),
    Option(
        "MIN_SEGMENT",
        "--min-segment",
        "float",
        None,
        "Vertex budget: one vertex per (layer units)",
        "At most one vertex per this length of boundary (fewer passes for the features "
        "that would be denser); areas stay exact. Empty: no budget.",
        optional=True,
        minimum=0.0,
        algorithms=("smooth", "smoothcoverage", "smoothnetwork"),
    ),
    Option(
        "SNAP",
        "--snap",
        "float",
        None,
        "Snapping distance to clean the coverage",
        "Clean an imperfect coverage first by snapping vertices closer than this distance "
        "(layer units; shapely.coverage_clean). Empty: no snapping.",
        optional=True,
        minimum=0.0,
        algorithms=("smoothcoverage",),
    ),
    Option(
        "WORKERS",
        "--workers",
        "int",
        None,
        "Dask worker processes (large layers)",
        "Run curvesmith batch smooth on a local Dask cluster with this many worker "
        "processes, for large layers. Empty: one process (curvesmith smooth).",
        optional=True,
        minimum=1,
        advanced=True,
        batch="trigger",
        algorithms=("smooth", "smoothcoverage", "smoothnetwork"),
    ),
    Option(
        "SCHEDULER",
        "--scheduler",
        "string",
        None,
        "Dask scheduler address",
        "Run curvesmith batch smooth on an existing Dask cluster (e.g. tcp://host:8786).",
        optional=True,
        advanced=True,
        batch="trigger",
        algorithms=("smooth", "smoothcoverage", "smoothnetwork"),
    ),
    Option(
        "PARTITION_SIZE",
        "--partition-size",
        "int",
        None,
        "Features per Dask task",
        "Batch mode: features per task (default: about 16 tasks of 1,000 to 50,000 features; "
        "arcs per task in coverage and network mode, default 1,000).",
        optional=True,
        minimum=1,
        advanced=True,
        batch="only",
        algorithms=("smooth", "smoothcoverage", "smoothnetwork"),
    ),
)


def options_for(algorithm: str) -> tuple[Option, ...]:
    """The rows of :data:`OPTIONS` that `algorithm` has, in table order."""
    return tuple(o for o in OPTIONS if algorithm in o.algorithms)


def _given(option: Option, value: Any) -> bool:
    return value is not None and value != "" and not (option.kind == "bool" and not value)


def is_batch(algorithm: str, values: dict[str, Any]) -> bool:
    """Whether `values` ask for ``curvesmith batch smooth`` (a worker count or scheduler)."""
    return any(
        _given(o, values.get(o.name)) for o in options_for(algorithm) if o.batch == "trigger"
    )


def build_argv(
    executable: str, algorithm: str, values: dict[str, Any], source: str, dest: str
) -> list[str]:
    """The command line that runs `algorithm` on `source`, writing `dest`.

    Parameters
    ----------
    executable : str
        The ``curvesmith`` program.
    algorithm : str
        An :data:`ALGORITHMS` name.
    values : dict
        Parameter name -> value; an "enum" value is the choice's index (as QGIS gives it)
        or the choice itself. Missing names take the table's default.
    source, dest : str
        Input and output files.

    Returns
    -------
    list of str
    """
    spec = next(a for a in ALGORITHMS if a.name == algorithm)
    batch = is_batch(algorithm, values)
    argv = [executable, *(("batch", "smooth") if batch else ("smooth",)), source, "-o", dest]
    argv += spec.flags
    for o in options_for(algorithm):
        if o.batch == "only" and not batch:
            continue
        value = values.get(o.name, o.default)
        if not _given(o, value):
            continue
        if o.kind == "bool":
            argv.append(o.flag)
        elif o.kind == "enum":
            argv += [o.flag, o.choices[value] if isinstance(value, int) else str(value)]
        elif o.kind == "int":
            argv += [o.flag, str(int(value))]
        elif o.kind == "float":
            argv += [o.flag, repr(float(value))]
        else:
            argv += [o.flag, str(value).strip()]
    return argv
