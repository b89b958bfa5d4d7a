"""Real coverages shipped offline by PyPI packages, for tests, the demo and the benchmark."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from .._validate import as_choice
from ..errors import require

__all__ = ["us_counties"]

_FILES = {
    2016: "cb_2016_us_county_500k.shp",
    2010: "gz_2010_us_050_00_500k.shp",
}


def us_counties(*, year: int = 2016, states: Any = None):
    """US counties (US Census Bureau cartographic boundaries, 1:500,000) as a GeoDataFrame.

    The shapefiles are bundled in the ``plotly-geo`` wheel (``_plotly_geo/package_data``),
    so nothing is downloaded. ``year=2016`` (``cb_2016_us_county_500k``: 3233 features,
    about 1.04 million vertices) is a valid coverage (:func:`shapely.coverage_is_valid`);
    ``year=2010`` (``gz_2010_us_050_00_500k``: 3221 features) is an imperfect one, with
    unmatched vertices along some shared borders. The files have no ``.prj``; the Census
    Bureau publishes them in NAD83 geographic coordinates, so the CRS is set to EPSG:4269.

    Parameters
    ----------
    year : {2016, 2010}
        Which of the two bundled files.
    states : sequence of str, optional
        Two-digit state FIPS codes to keep (e.g. ``["19"]`` for Iowa).

    Returns
    -------
    geopandas.GeoDataFrame
        One row per county, in file order, with the file's attribute columns and a
        ``STATEFP`` column (state FIPS) in both years.
    """
    require("_plotly_geo", "geo", "the bundled US county coverage (package plotly-geo)")
    import _plotly_geo
    import pyogrio

    as_choice(year, sorted(_FILES), name="year")
    path = Path(_plotly_geo.__file__).parent / "package_data" / _FILES[year]
    df = pyogrio.read_dataframe(path)
    df = df.set_crs("EPSG:4269", allow_override=True)
    if "STATEFP" not in df.columns:
        df["STATEFP"] = df["STATE"]
    if states is not None:
        keep = {str(s) for s in states}
        df = df[df["STATEFP"].isin(keep)].reset_index(drop=True)
    return df
