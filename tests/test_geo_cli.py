"""smooth_geofile: the GIS-file path of ``curvesmith smooth``."""

import numpy as np
import pytest
import shapely

from curvesmith import geo
from curvesmith.cli.geo import is_geofile, smooth_geofile
from curvesmith.errors import CurveError


def test_is_geofile():
    assert is_geofile("a.gpkg") and is_geofile("A.SHP") and is_geofile("x.fgb")
    assert not is_geofile("a.geojson") and is_geofile("a.geojson", coverage=True)
    assert not is_geofile("a.csv", coverage=True)


def test_smooth_geofile_coverage_with_summary(tmp_path, capsys):
    df = geo.us_counties(states=["44"])  # Rhode Island in NAD83 degrees
    src = tmp_path / "ri.gpkg"
    geo.write_file(df, src, layer="counties")
    out = tmp_path / "ri_out.gpkg"
    rep = smooth_geofile(
        str(src), str(out), coverage=True, layer="counties", alpha="0.2", iterations=2
    )
    err = capsys.readouterr().err
    assert "Warning:" in err and "geographic CRS" in err
    assert "5 features smoothed" in err and "coverage valid" in err
    assert rep.coverage_valid
    back = geo.read_file(out, layer="counties")
    np.testing.assert_allclose(
        shapely.area(back.geometry.values), shapely.area(df.geometry.values), rtol=1e-9
    )


def test_smooth_geofile_equal_area_no_warning(tmp_path, capsys):
    df = geo.us_counties(states=["44"])
    src = tmp_path / "ri.shp"
    geo.write_file(df, src)
    smooth_geofile(str(src), str(tmp_path / "o.fgb"), equal_area=True, layer="0")
    assert "Warning" not in capsys.readouterr().err


def test_smooth_geofile_bad_method_and_alpha(tmp_path):
    src = tmp_path / "x.gpkg"
    geo.write_file(geo.us_counties(states=["10"]), src)
    with pytest.raises(CurveError, match="--method derham is not available for GIS files"):
        smooth_geofile(str(src), str(tmp_path / "o.gpkg"), method="derham")
    with pytest.raises(CurveError, match="--alpha must be 'regular' or a number, got 'big'"):
        smooth_geofile(str(src), str(tmp_path / "o.gpkg"), alpha="big")
