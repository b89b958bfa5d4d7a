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
smooth_network
    Smooth a line network: junctions and ends fixed, every shared piece smoothed once,
    no new contacts, areas kept.
contours, read_grid
    Contour lines and isobands of a grid, smoothed as a network / a coverage.
read_file, write_file, smooth_file
    GeoPackage, Shapefile, GeoJSON and FlatGeobuf through pyogrio.
"""

from __future__ import annotations

from ._contours import ContourResult, Grid, contours, read_grid
from ._corners import corner_vertices
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
    clamp_to_domain,
    domain_edge_mask,
    domain_fixed,
    equal_area_crs,
    read_file,
    smooth_file,
    write_file,
)
from ._network import (
    NetworkReduction,
    NetworkResult,
    NetworkTopology,
    changed_contacts,
    level_contacts,
    network_topology,
    smooth_network,
)
from ._smooth import GeometryReduction, SmoothResult, smooth

__all__ = [
    "DRIVERS",
    "ContourResult",
    "CoverageReduction",
    "CoverageResult",
    "FileSmoothReport",
    "GeographicCRSWarning",
    "GeometryReduction",
    "Grid",
    "NetworkReduction",
    "NetworkResult",
    "NetworkTopology",
    "Reduction",
    "SmoothResult",
    "Topology",
    "changed_contacts",
    "clamp_to_domain",
    "contours",
    "corner_vertices",
    "coverage_topology",
    "domain_edge_mask",
    "domain_fixed",
    "equal_area_crs",
    "level_contacts",
    "network_topology",
    "read_file",
    "read_grid",
    "smooth",
    "smooth_coverage",
    "smooth_file",
    "smooth_network",
    "us_counties",
    "write_file",
]
