"""curvesmith.geo.contours / read_grid and ``curvesmith contours``: levels never touch, exact areas."""

import geopandas as gpd
import numpy as np
import pytest
import shapely
from click.testing import CliRunner
from matplotlib import cbook
from scipy.ndimage import gaussian_filter

from curvesmith import geo
from curvesmith.cli import main
from curvesmith.errors import CurveError, CurveFormatError
from oracles import exact_area_fraction


def jacksboro():
    """matplotlib's sample DEM (Jacksboro fault, Tennessee; 344 x 403 cells, 236-1076 m)."""
    d = cbook.get_sample_data("jacksboro_fault_dem.npz")
    z = d["elevation"].astype(float)
    ny, nx = z.shape
    # 3 arc-second cells, as metres on the ground (about 90 m; x shrinks with latitude)
    return z, np.arange(nx) * 74.5, np.arange(ny)[::-1] * 92.6


def steep_rough_terrain(seed, n=28):
    """A 120 % slope with 400 m of rough relief on 25 m cells: contours 20 m apart crowd."""
    rng = np.random.default_rng(seed)
    y, x = np.mgrid[0:n, 0:n] * 25.0
    rough = gaussian_filter(rng.normal(size=(n, n)), 1.0)
    return 1.2 * x + 400 * rough / rough.std(), x[0], y[:, 0]


def level_contacts(df):
    """Pairs of lines of different levels that touch or cross."""
    g, lv = df.geometry.values, df["level"].to_numpy()
    i, j = shapely.STRtree(g).query(g, predicate="intersects")
    return int(((i < j) & (lv[i] != lv[j])).sum())


def same_level_contacts(df):
    g, lv = df.geometry.values, df["level"].to_numpy()
    i, j = shapely.STRtree(g).query(g, predicate="intersects")
    keep = (i < j) & (lv[i] == lv[j])
    return {(int(a), int(b)) for a, b in zip(i[keep], j[keep], strict=True)}


# --- lines --------------------------------------------------------------------------------


@pytest.mark.slow
def test_jacksboro_lines_levels_never_touch_areas_exact():
    z, x, y = jacksboro()
    raw = geo.contours(z, x=x, y=y, interval=100, iterations=0)
    res = geo.contours(z, x=x, y=y, interval=100, iterations=2, full_output=True)
    out = res.geometry
    np.testing.assert_array_equal(res.levels, np.arange(300, 1001, 100.0))
    assert len(out) == len(raw) > 100 and list(out.columns) == ["level", "geometry"]
    np.testing.assert_array_equal(out["level"], raw["level"])
    assert level_contacts(raw) == 0 and level_contacts(out) == 0
    assert same_level_contacts(out) == same_level_contacts(raw)
    # every closed contour keeps its enclosed area (exact rational check on the largest ones)
    closed = np.nonzero(raw.geometry.is_ring.to_numpy())[0]
    big = closed[np.argsort(-raw.geometry.length.to_numpy()[closed])[:5]]
    for k in big:
        a0 = exact_area_fraction(shapely.get_coordinates(raw.geometry.iloc[k])[:-1])
        a1 = exact_area_fraction(shapely.get_coordinates(out.geometry.iloc[k])[:-1])
        bound = 64 * np.finfo(float).eps * 4e4 * raw.geometry.iloc[k].length
        assert abs(float(a1 - a0)) <= bound
    assert res.smoothing.max_open_area < 1e-12
    # smoothed: many more vertices; the lines stay within a cell of the raw ones
    n0 = shapely.get_num_coordinates(raw.geometry.values).sum()
    assert shapely.get_num_coordinates(out.geometry.values).sum() > 4 * n0
    near = shapely.buffer(raw.geometry.values, 92.6, quad_segs=2)
    assert shapely.covered_by(out.geometry.values, near).all()


def test_jacksboro_geographic_coordinates_and_default_levels():
    d = cbook.get_sample_data("jacksboro_fault_dem.npz")
    g = geo.read_grid(cbook.get_sample_data("jacksboro_fault_dem.npz", asfileobj=False))
    assert g.z.shape == (344, 403) and g.x[0] == float(d["xmin"]) and g.y[0] == float(d["ymin"])
    res = geo.contours(g, crs="EPSG:4326", full_output=True)
    np.testing.assert_array_equal(res.levels, np.arange(300, 1001, 100.0))  # MaxNLocator
    assert res.geometry.crs.to_epsg() == 4326
    assert level_contacts(res.geometry) == 0


def test_topobathy_negative_levels():
    d = cbook.get_sample_data("topobathy.npz")
    res = geo.contours(
        d["topo"],
        x=d["longitude"],
        y=d["latitude"],
        levels=[-1000, -200, 0, 500, 1500],
        iterations=2,
        full_output=True,
    )
    assert set(res.geometry["level"]) == {-1000.0, -200.0, 0.0, 500.0, 1500.0}
    assert level_contacts(res.geometry) == 0
    assert res.smoothing.max_area_change < 1e-9


def test_bivariate_normal_npy_sample():
    """matplotlib's axes_grid/bivariate_normal.npy read as a .npy grid: nested closed rings."""
    path = cbook.get_sample_data("axes_grid/bivariate_normal.npy", asfileobj=False)
    g = geo.read_grid(path)
    assert g.z.shape == (15, 15) and g.crs is None
    raw = geo.contours(g, levels=[0.2, 0.5, 1.0, 1.5], iterations=0)
    res = geo.contours(g, levels=[0.2, 0.5, 1.0, 1.5], iterations=3, full_output=True)
    out = res.geometry
    assert level_contacts(out) == 0 and len(out) == len(raw)
    for a, b in zip(raw.geometry.values, out.geometry.values, strict=True):
        if a.is_closed:
            da = exact_area_fraction(shapely.get_coordinates(b)[:-1]) - exact_area_fraction(
                shapely.get_coordinates(a)[:-1]
            )
            assert abs(float(da)) <= 64 * np.finfo(float).eps * 15 * a.length
    # the rings of different levels stay nested: each smoothed ring contains the higher ones
    closed = out[out.geometry.is_closed]
    polys = {
        lv: shapely.polygons(shapely.linearrings([shapely.get_coordinates(r) for r in rs]))
        for lv in (0.5, 1.0)
        for rs in [closed.geometry[closed["level"] == lv].values]
    }
    assert len(polys[1.0]) >= 1
    for inner in polys[1.0]:
        assert shapely.contains(polys[0.5], inner).sum() == 1


@pytest.mark.slow
@pytest.mark.parametrize("seed", [0, 1])
def test_steep_terrain_per_line_smoothing_crosses_network_does_not(seed):
    z, x, y = steep_rough_terrain(seed)
    raw = geo.contours(z, x=x, y=y, interval=20, iterations=0)
    assert len(raw) > 1000 and level_contacts(raw) == 0
    per_line_cca = geo.smooth(raw, iterations=2)
    per_line_chaikin = geo.smooth(raw, method="chaikin", iterations=2)
    assert level_contacts(per_line_cca) >= 10
    assert level_contacts(per_line_chaikin) >= 20
    res = geo.contours(z, x=x, y=y, interval=20, iterations=2, full_output=True)
    assert level_contacts(res.geometry) == 0
    assert same_level_contacts(res.geometry) == same_level_contacts(raw)
    assert len(res.smoothing.reductions) > 0
    assert res.smoothing.max_open_area < 1e-12


def test_nan_region_and_values_on_levels():
    # an integer-valued cone: many grid values exactly on the levels; a NaN hole of no data
    yy, xx = np.mgrid[-20:21, -20:21].astype(float)
    z = np.round(100 - 3 * np.hypot(xx, yy))
    z[:6, :6] = np.nan
    res = geo.contours(z, levels=[40, 55, 70, 85], iterations=2, full_output=True)
    out = res.geometry
    assert level_contacts(out) == 0
    assert set(out["level"]) == {40.0, 55.0, 70.0, 85.0}
    # no line enters the no-data corner
    assert not shapely.intersects(out.geometry.values, shapely.box(0, 0, 4.9, 4.9)).any()
    assert out.geometry.is_simple.all()
    bands = geo.contours(z, levels=[40, 55, 70, 85], bands=True, iterations=2, full_output=True)
    assert bands.smoothing.coverage_valid and bands.smoothing.max_area_change < 1e-12
    raw = geo.contours(z, levels=[40, 55, 70, 85], bands=True, iterations=0)
    np.testing.assert_allclose(bands.geometry.area, raw.area, rtol=1e-12)
    nodata = shapely.box(0, 0, 4.9, 4.9)  # the NaN corner (z[:6, :6])
    assert not shapely.intersects(bands.geometry.geometry.values, nodata).any()


def test_contour_errors():
    with pytest.raises(CurveError, match=r"z must be a 2-D grid"):
        geo.contours(np.arange(5.0))
    with pytest.raises(CurveError, match="x must have shape"):
        geo.contours(np.zeros((3, 4)) + np.arange(4), x=np.arange(3))
    with pytest.raises(CurveError, match="interval must be > 0"):
        geo.contours(np.arange(12.0).reshape(3, 4), interval=-1)
    with pytest.raises(CurveError, match="levels or interval"):
        geo.contours(np.arange(12.0).reshape(3, 4), interval=1, levels=[2])
    with pytest.raises(CurveError, match="no finite values"):
        geo.contours(np.full((3, 3), np.nan))


# --- bands --------------------------------------------------------------------------------


@pytest.mark.slow
def test_jacksboro_bands_areas_exact_no_gaps():
    z, x, y = jacksboro()
    raw = geo.contours(z, x=x, y=y, interval=100, bands=True, iterations=0)
    res = geo.contours(z, x=x, y=y, interval=100, bands=True, iterations=2, full_output=True)
    out = res.geometry
    assert list(out.columns) == ["lower", "upper", "geometry"]
    assert out["lower"].iloc[0] == z.min() and out["upper"].iloc[-1] == z.max()
    np.testing.assert_array_equal(out["upper"].iloc[:-1], np.arange(300, 1001, 100.0))
    assert res.smoothing.coverage_valid and res.smoothing.max_area_change < 1e-12
    np.testing.assert_allclose(out.area, raw.area, rtol=1e-12)
    grid_area = (x[-1] - x[0]) * (y[0] - y[-1])
    union = shapely.union_all(out.geometry.values)
    assert abs(union.area - grid_area) < 1e-9 * grid_area
    # the outline of the grid (its corners included) stays where it is: the rectangle, up to
    # the 9 um notches where a grid value on a level was nudged (also in the raw bands)
    np.testing.assert_allclose(union.bounds, (0, 0, x[-1], y[0]), atol=1e-9)
    outline = shapely.union_all(raw.geometry.values).exterior
    assert shapely.hausdorff_distance(union.exterior, outline) < 1e-9
    assert shapely.hausdorff_distance(outline, shapely.box(0, 0, x[-1], y[0]).exterior) < 1e-5
    assert shapely.is_valid(out.geometry.values).all()
    assert (
        shapely.get_num_coordinates(out.geometry.values).sum()
        > 3 * shapely.get_num_coordinates(raw.geometry.values).sum()
    )


# --- grids and the command ----------------------------------------------------------------


def write_asc(path, z, *, x0=500000.0, y0=4100000.0, cell=30.0, nodata=-9999):
    ny, nx = z.shape
    head = f"ncols {nx}\nnrows {ny}\nxllcorner {x0}\nyllcorner {y0}\ncellsize {cell}\n"
    head += f"NODATA_value {nodata}\n"
    body = "\n".join(" ".join(f"{v:g}" for v in row) for row in np.where(np.isnan(z), nodata, z))
    path.write_text(head + body + "\n")


def test_read_grid_formats(tmp_path):
    z = np.arange(20.0).reshape(4, 5)
    np.save(tmp_path / "g.npy", z)
    g = geo.read_grid(tmp_path / "g.npy")
    np.testing.assert_array_equal(g.z, z)
    np.testing.assert_array_equal(g.x, np.arange(5.0))
    np.savez(tmp_path / "g.npz", z=z, x=np.linspace(0, 1, 5), y=np.linspace(10, 13, 4))
    g = geo.read_grid(tmp_path / "g.npz")
    assert g.x[-1] == 1.0 and g.y[-1] == 13.0
    z2 = z.copy()
    z2[0, 0] = np.nan
    write_asc(tmp_path / "g.asc", z2)
    g = geo.read_grid(tmp_path / "g.asc")
    assert np.isnan(g.z[0, 0]) and g.z[3, 4] == 19.0
    assert g.x[0] == 500015.0 and g.y[-1] == 4100015.0 and g.y[0] == 4100015.0 + 90
    with pytest.raises(CurveFormatError, match="no such file"):
        geo.read_grid(tmp_path / "missing.asc")
    (tmp_path / "bad.asc").write_text("ncols 2\nnrows 2\n1 2\n3 4\n")
    with pytest.raises(CurveFormatError, match="not an ESRI ASCII grid"):
        geo.read_grid(tmp_path / "bad.asc")
    (tmp_path / "g.txt").write_text("1 2\n")
    with pytest.raises(CurveFormatError, match="grid format"):
        geo.read_grid(tmp_path / "g.txt")


def test_read_geotiff(tmp_path):
    rasterio = pytest.importorskip("rasterio")
    from rasterio.transform import Affine

    z, _, _ = jacksboro()
    z = z[:60, :80].copy()
    z[:3, :3] = -32768
    path = tmp_path / "dem.tif"
    with rasterio.open(
        path,
        "w",
        driver="GTiff",
        height=60,
        width=80,
        count=1,
        dtype="float32",
        crs="EPSG:32616",
        transform=Affine(90.0, 0.0, 750000.0, 0.0, -90.0, 4070000.0),
        nodata=-32768,
    ) as dst:
        dst.write(z.astype("float32"), 1)
    g = geo.read_grid(path)
    assert g.z.shape == (60, 80) and np.isnan(g.z[0, 0]) and g.z[5, 5] == z[5, 5]
    assert g.x[0] == 750045.0 and g.y[0] == 4069955.0 and "32616" in g.crs
    df = geo.contours(g, interval=50)
    assert df.crs.to_epsg() == 32616 and level_contacts(df) == 0


def test_cli_contours(tmp_path):
    z, _, _ = jacksboro()
    write_asc(tmp_path / "dem.asc", z[:120, :150], cell=90.0)
    out = tmp_path / "lines.gpkg"
    r = CliRunner().invoke(
        main,
        [
            "contours",
            str(tmp_path / "dem.asc"),
            "-o",
            str(out),
            "--interval",
            "50",
            "--crs",
            "EPSG:32616",
        ],
    )
    assert r.exit_code == 0, r.output
    assert "contour lines at" in r.output
    df = gpd.read_file(out)
    assert df.crs.to_epsg() == 32616
    assert "level" in df and (df["level"] % 50 == 0).all() and level_contacts(df) == 0
    bands = tmp_path / "bands.fgb"
    r = CliRunner().invoke(
        main,
        [
            "contours",
            str(tmp_path / "dem.asc"),
            "-o",
            str(bands),
            "--levels",
            "400,600",
            "--bands",
            "--crs",
            "EPSG:32616",
        ],
    )
    assert r.exit_code == 0, r.output
    b = gpd.read_file(bands)
    assert list(b["upper"])[:2] == [400.0, 600.0] and shapely.coverage_is_valid(b.geometry.values)
    r = CliRunner().invoke(
        main,
        ["contours", str(tmp_path / "dem.asc"), "-o", str(out), "--levels", "1", "--interval", "2"],
    )
    assert r.exit_code == 2
    r = CliRunner().invoke(main, ["contours", str(tmp_path / "dem.asc"), "-o", "lines.xyz"])
    assert r.exit_code == 1 and "cannot tell the format of 'lines.xyz'" in r.output
    r = CliRunner().invoke(main, ["contours", str(tmp_path / "nope.asc"), "-o", str(out)])
    assert r.exit_code == 1 and r.output.startswith("Error: no such file")


def test_cli_contours_max_shift_and_min_segment(tmp_path):
    """contours --max-shift / --min-segment: lines and band borders bounded, in map units."""
    z, _, _ = jacksboro()
    write_asc(tmp_path / "dem.asc", z[:120, :150], cell=90.0)
    raw = geo.contours(
        geo.read_grid(tmp_path / "dem.asc"), interval=50.0, iterations=0
    ).geometry.values
    out = tmp_path / "lines.gpkg"
    base = ["contours", str(tmp_path / "dem.asc"), "--crs", "EPSG:32616", "--iterations", "3"]
    r = CliRunner().invoke(main, [*base, "-o", str(out), "--interval", "50", "--max-shift", "6"])
    assert r.exit_code == 0, r.output
    df = gpd.read_file(out)
    shift = shapely.hausdorff_distance(raw, df.geometry.values)
    assert shift.max() <= 6 and (shift > 0).mean() > 0.9 and level_contacts(df) == 0
    r = CliRunner().invoke(main, [*base, "-o", str(out), "--interval", "50", "--min-segment", "40"])
    assert r.exit_code == 0, r.output
    thin = gpd.read_file(out).geometry.values
    full = geo.contours(geo.read_grid(tmp_path / "dem.asc"), interval=50.0, iterations=3)
    assert (
        shapely.get_num_coordinates(thin).sum()
        < 0.3 * shapely.get_num_coordinates(full.geometry.values).sum()
    )
    bands = tmp_path / "bands.gpkg"
    r = CliRunner().invoke(
        main, [*base, "-o", str(bands), "--levels", "400,600", "--bands", "--max-shift", "6"]
    )
    assert r.exit_code == 0, r.output
    b = gpd.read_file(bands).geometry.values
    b0 = geo.contours(
        geo.read_grid(tmp_path / "dem.asc"), levels=[400, 600], bands=True, iterations=0
    ).geometry.values
    assert shapely.coverage_is_valid(b) and shapely.hausdorff_distance(b0, b).max() <= 6
    np.testing.assert_allclose(shapely.area(b), shapely.area(b0), rtol=1e-11)
    r = CliRunner().invoke(main, [*base, "-o", str(out), "--max-shift", "0"])
    assert r.exit_code == 2 and "Invalid value for '--max-shift'" in r.output
