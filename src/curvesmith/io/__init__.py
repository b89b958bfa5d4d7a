r"""Read and write curve files: CSV, GeoJSON and SVG.

Every reader returns a list of :class:`Curve` objects, every writer takes one.
A :class:`Curve` holds the vertices of one polyline or one polygon ring plus
where it came from (feature, part, ring, geometry kind, properties), so that
``read -> transform the points -> write`` gives back a file with the same
structure.

Conventions
-----------
Points and closedness
    ``Curve.points`` is a ``(N, 2)`` or ``(N, 3)`` float64 array. A closed
    curve (a ring) never repeats its first vertex at the end; writers add the
    repeated closing vertex back where the format requires it (CSV, GeoJSON).
    In a file, a curve is closed when the format says so: a ``closed`` column
    (CSV), a Polygon ring (GeoJSON), a ``Z`` command or a ``polygon``,
    ``rect``, ``circle`` or ``ellipse`` element (SVG). Where the format has no
    such flag (a CSV file without ``closed`` column, a GeoJSON LineString),
    a curve of at least 4 vertices whose last vertex repeats the first exactly
    is a closed ring, the usual file convention of GeoJSON/WKT rings; the
    repeat is dropped.
CSV
    A header row is required, with columns ``x``, ``y`` and optionally ``z``
    (case-insensitive, in any order). Several curves are told apart by an
    ``id`` column: rows are grouped by id in order of first appearance, and
    the id is kept as ``properties["id"]``. An optional ``closed`` column
    (``true/false``, ``1/0``, ``yes/no``) must be constant along a curve. Any
    other column that is constant along a curve becomes a property of that
    curve; a column that varies along a curve cannot follow the curve through
    smoothing and is dropped with a ``UserWarning`` that names it. Values are
    separated by commas, tabs or semicolons (taken from the header line) or,
    for a header without any of these, by whitespace; blank lines and lines
    starting with ``#`` are skipped. Property values are read as ``int`` or
    ``float`` when the text is their canonical spelling (so that writing them
    back gives the same text), otherwise as ``str``. The writer puts
    ``x,y[,z]`` first, then ``id`` (when there are several curves or a curve
    has an id), ``closed`` (when a curve is closed, or an open curve ends
    where it starts) and the properties; closed rings repeat their first
    point. Floats are written with ``repr``, the shortest text that reads back
    to the same float, so CSV round trips are bit-exact.
GeoJSON (RFC 7946)
    Read: a FeatureCollection, a Feature or a bare geometry; LineString,
    Polygon (exterior ring and holes), MultiLineString, MultiPolygon and
    GeometryCollections of these. ``Curve.feature`` is the index of the
    feature, ``part`` the index inside a Multi* geometry, ``ring`` 0 for an
    exterior ring or a line and k for the k-th hole, ``member`` the index in
    a GeometryCollection (None otherwise), ``kind`` the geometry type,
    ``properties`` the feature's properties and ``feature_id`` its ``id``.
    Points, MultiPoints, null geometries, empty geometries and nested
    GeometryCollections are refused with a :class:`CurveFormatError` naming
    the feature: they are not curves, and skipping them would silently lose
    data. ``bbox`` and foreign members are not kept; a ``crs`` member (old
    GeoJSON) is dropped with a ``UserWarning`` naming it. Coordinates with a
    third value keep it (``(N, 3)`` points).
    Write: always a FeatureCollection, one feature per distinct
    ``Curve.feature`` (in order of first appearance), its geometry rebuilt
    from ``kind``, ``member``, ``part`` and ``ring``. Rings are closed by
    repeating their first position. With ``orient=True`` (default) exterior
    rings are written counter-clockwise and holes clockwise, as RFC 7946
    section 3.1.6 asks (a reversed ring keeps its first vertex); orientation
    is judged on x and y. Floats are written with ``repr``: round trips are
    bit-exact.
SVG
    Read with `svgelements`: ``path`` (every command, absolute and relative,
    including elliptical arcs), ``polyline``, ``polygon``, ``line``, ``rect``
    (also with rounded corners), ``circle`` and ``ellipse``, also through
    ``use``; ``transform`` attributes are applied; ``display="none"``
    elements and the content of ``defs`` are not drawn and not read. Each
    subpath becomes one curve, closed when it ends with ``Z`` (closed
    subpaths that the fill rule leaves empty inside another one are read as
    holes, see :func:`read_svg`); a lone
    ``moveto`` draws nothing and is skipped, zero-length segments are dropped,
    and a closed subpath with only two distinct vertices (it encloses no
    area) is read as an open curve. Coordinates are the SVG user coordinates
    of the outermost ``svg`` element (its ``viewBox`` coordinates), with the
    y axis pointing down as in SVG: nothing is flipped, so a shape that looks
    counter-clockwise on screen has negative signed area here; flipping for
    display is the plotting code's job. Curved segments are flattened to
    polylines whose maximal distance from the exact curve (chord deviation)
    is at most ``tolerance`` user units; by default ``tolerance`` is
    ``1e-4`` times the diagonal of the drawing's bounding box (of the
    control points). The number of chords per segment follows the classical
    bound ``max |c(t) - chord| <= h**2 / 8 * max |c''|`` for a parameter step
    ``h`` (Wang's formula for Bézier curves; for an elliptic arc
    ``|c''| <= max(rx, ry)`` in the angle parameter), so segments with more
    curvature get more chords; under a transform the tolerance is divided by
    the transform's largest singular value before flattening. Lines and
    polyline vertices are kept exactly.
    Write: one ``<path>`` per feature (``M x,y L ... Z``, one subpath per
    curve, ``fill-rule="evenodd"`` so that holes render as holes), a
    ``viewBox`` fitted to the data with a 2 % margin, a stroke whose width is
    1/400 of the drawing size, and a fill for closed curves when ``fill`` is
    given. The curves' properties and structure (kind, member, part, ring,
    feature id) are stored in a ``data-curvesmith`` JSON attribute, and
    ``properties["id"]`` also as the element ``id``, so reading the file
    back restores them. SVG is planar: 3D curves raise
    :class:`CurveFormatError`.
Errors
    Every problem with a file raises :class:`~curvesmith.errors.CurveFormatError`
    (a :class:`~curvesmith.errors.CurveError`, hence a ``ValueError``) whose
    message starts with the file name (``<stream>`` for an unnamed stream)
    and says what is wrong: missing file, empty file, unknown suffix,
    malformed JSON or XML (with line and column), missing columns,
    non-numeric values (with the line number), curves with too few points,
    non-curve geometries, an SVG without drawable elements.

Examples
--------
>>> import io
>>> curves = read_csv(io.StringIO("x,y\n0,0\n1,0\n1,1\n0,0\n"))
>>> curves[0].closed, curves[0].points.shape
(True, (3, 2))
>>> buf = io.StringIO()
>>> write_geojson(curves, buf)
>>> read_geojson(io.StringIO(buf.getvalue()))[0].kind
'Polygon'
"""

from __future__ import annotations

from . import csv, geojson, scan, svg
from ._core import (
    KINDS,
    Curve,
    Format,
    atomic_path,
    check_destination,
    detect_format,
    formats,
    open_destination,
    read_curves,
    register,
    write_curves,
)
from .csv import read_csv, write_csv
from .geojson import read_geojson, write_geojson
from .svg import read_svg, write_svg

__all__ = [
    "FORMATS",
    "KINDS",
    "Curve",
    "Format",
    "atomic_path",
    "check_destination",
    "csv",
    "detect_format",
    "formats",
    "geojson",
    "open_destination",
    "read_csv",
    "read_curves",
    "read_geojson",
    "read_svg",
    "register",
    "scan",
    "svg",
    "write_csv",
    "write_curves",
    "write_geojson",
    "write_svg",
]

FORMATS = formats()
"""Names of the built-in formats, as accepted by ``format=``."""
