"""Area-preserving smoothing of GIS data: geometries, GeoDataFrames, coverages and files.

Needs the ``geo`` extra (shapely >= 2, pyogrio, geopandas): ``pip install 'curvesmith[geo]'``.

Functions
---------
smooth
    Smooth shapely geometries / GeoSeries / GeoDataFrames, ring by ring, keeping each
    ring's area (CCA) and the validity of every feature.
smooth_coverage
    Smooth a polygonal coverage arc by arc so that every polygon keeps its area and
    neighbours still fit together without gaps or overlaps.
read_file, write_file, smooth_file
    GeoPackage, Shapefile, GeoJSON and FlatGeobuf through pyogrio.
"""

from __future__ import annotations

from ._coverage import (
    CoverageReduction,
    CoverageResult,
    Topology,
    coverage_topology,
    smooth_coverage,
)
from ._data import us_counties
from ._engine import Reduction
from ._io import (
    DRIVERS,
    FileSmoothReport,
    GeographicCRSWarning,
    equal_area_crs,
    read_file,
    smooth_file,
    write_file,
)
from ._smooth import GeometryReduction, SmoothResult, smooth

__all__ = [
    "DRIVERS",
    "CoverageReduction",
    "CoverageResult",
    "FileSmoothReport",
    "GeographicCRSWarning",
    "GeometryReduction",
    "Reduction",
    "SmoothResult",
    "Topology",
    "coverage_topology",
    "equal_area_crs",
    "read_file",
    "smooth",
    "smooth_coverage",
    "smooth_file",
    "us_counties",
    "write_file",
]
