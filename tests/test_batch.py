"""curvesmith.batch: Dask partitions, order, errors report, coverage mode, scheduler address."""

import json
from pathlib import Path

import distributed
import numpy as np
import pytest
import shapely

from curvesmith import batch, geo
from curvesmith.errors import CurveError


@pytest.fixture(scope="module")
def cluster():
    """A scheduler and two worker processes on 127.0.0.1, started by the test (bounded)."""
    lc = distributed.LocalCluster(
        host="127.0.0.1",
        n_workers=2,
        threads_per_worker=1,
        processes=True,
        dashboard_address=":0",
        silence_logs=40,
        timeout="60s",
    )
    try:
        yield lc
    finally:
        lc.close(timeout=30)


@pytest.fixture(scope="module")
def counties_file(tmp_path_factory):
    df = geo.us_counties(states=["19", "31"]).to_crs("EPSG:5070")  # Iowa and Nebraska
    bad = df.copy()
    bad.loc[7, "geometry"] = shapely.Polygon([(0, 0), (2, 2), (2, 0), (0, 2)])  # bow-tie
    d = tmp_path_factory.mktemp("batch")
    geo.write_file(df, d / "good.gpkg")
    geo.write_file(bad, d / "bad.gpkg")
    return d, df


def test_file_on_existing_scheduler_keeps_order_and_reports_failures(cluster, counties_file):
    d, df = counties_file
    out = d / "out.gpkg"
    rep = batch.smooth_file(
        d / "bad.gpkg",
        out,
        scheduler=cluster.scheduler_address,
        partition_size=40,
        iterations=2,
        progress=False,
    )
    n = len(df)
    assert rep.n_features == n
    assert rep.n_partitions == -(-n // 40)
    assert [e.index for e in rep.errors] == [7]
    assert "not valid (Self-intersection" in rep.errors[0].reason
    report = json.loads((d / "out.gpkg.errors.json").read_text())
    assert report == [{"index": 7, "reason": rep.errors[0].reason}]
    back = geo.read_file(out)
    assert list(back["GEOID"]) == list(df["GEOID"])
    assert back.crs == df.crs
    assert back.geometry.iloc[7].equals(shapely.Polygon([(0, 0), (2, 2), (2, 0), (0, 2)]))
    ok = np.arange(n) != 7
    a_in = shapely.area(df.geometry.values[ok])
    a_out = shapely.area(back.geometry.values[ok])
    np.testing.assert_allclose(a_out, a_in, rtol=1e-9)
    assert shapely.is_valid(back.geometry.values[ok]).all()


def test_partitioned_equals_sequential(cluster, counties_file):
    _, df = counties_file
    with distributed.Client(cluster.scheduler_address) as client:
        out, errors, n_tasks, _ = batch.smooth_partitioned(
            df, client=client, partition_size=25, iterations=1
        )
    assert errors == () and n_tasks == -(-len(df) // 25)
    ref = geo.smooth(df, iterations=1)
    assert list(out.index) == list(df.index)
    assert all(
        shapely.equals_exact(a, b, 0.0) for a, b in zip(out.geometry, ref.geometry, strict=True)
    )


def test_coverage_mode_in_parallel_over_arcs(cluster, counties_file):
    d, df = counties_file
    out = d / "cov.fgb"
    rep = batch.smooth_file(
        d / "good.gpkg",
        out,
        coverage=True,
        scheduler=cluster.scheduler_address,
        partition_size=300,
        progress=False,
    )
    assert rep.coverage_valid is True
    assert rep.errors == ()
    assert rep.n_partitions >= 2
    back = geo.read_file(out)
    assert list(back["GEOID"]) == list(df["GEOID"])
    assert shapely.coverage_is_valid(back.geometry.values)
    np.testing.assert_allclose(back.area.values, df.area.values, rtol=1e-9)
    ref = geo.smooth_coverage(df)
    assert all(
        shapely.equals_exact(a, b, 0.0) for a, b in zip(back.geometry, ref.geometry, strict=True)
    )


def test_default_local_cluster(tmp_path):
    df = geo.us_counties(states=["10"]).to_crs("EPSG:5070")  # Delaware, 3 counties
    geo.write_file(df, tmp_path / "de.shp")
    rep = batch.smooth_file(
        tmp_path / "de.shp", tmp_path / "o.shp", workers=1, partition_size=2, progress=False
    )
    assert rep.n_features == 3 and rep.n_partitions == 2 and rep.errors == ()
    assert json.loads((tmp_path / "o.shp.errors.json").read_text()) == []
    back = geo.read_file(tmp_path / "o.shp")
    np.testing.assert_allclose(back.area.values, df.area.values, rtol=1e-9)


def test_bad_options(tmp_path):
    with pytest.raises(CurveError, match="partition_size must be an integer >= 1, got 0"):
        batch.smooth_file(tmp_path / "x.gpkg", tmp_path / "y.gpkg", partition_size=0)
    with pytest.raises(CurveError, match="workers must be an integer >= 1, got 0"):
        batch.smooth_partitioned([shapely.box(0, 0, 1, 1)], workers=0)


def test_partitioned_linear_rings_and_none(cluster):
    t = np.linspace(0, 2 * np.pi, 12, endpoint=False)
    ring = shapely.LinearRing(np.column_stack([np.cos(t), 0.5 * np.sin(t)]))
    geoms = [ring, None, shapely.box(0, 0, 1, 1), ring]
    with distributed.Client(cluster.scheduler_address) as client:
        out, errors, n_tasks, _ = batch.smooth_partitioned(geoms, client=client, partition_size=2)
    assert errors == () and n_tasks == 2
    assert isinstance(out[0], shapely.LinearRing) and out[1] is None
    ref = geo.smooth(geoms)
    assert all(
        (a is None and b is None) or shapely.equals_exact(a, b, 0.0)
        for a, b in zip(out, ref, strict=True)
    )


def test_partitioned_polygon_and_line_layers_exact_with_types(cluster, counties_file):
    # the ragged packets: holes, MultiPolygons of one and of several parts, empties and
    # NULLs come back as geo.smooth gives them, type for type and bit for bit; a line layer too
    _, df = counties_file
    g = list(df.geometry.values[:30])
    hole = shapely.Polygon(g[0].exterior, [shapely.affinity.scale(g[0], 0.3, 0.3).exterior])
    polys = [*g[:10], hole, shapely.MultiPolygon([g[11]]), shapely.MultiPolygon(g[12:14])]
    polys += [None, shapely.Polygon(), shapely.MultiPolygon(), *g[14:]]
    lines = [None if p is None or p.is_empty else p.exterior for p in polys[:10]]
    lines = [shapely.LineString(ln.coords) if ln is not None else None for ln in lines]
    lines += [shapely.MultiLineString([lines[0], lines[1]]), shapely.LineString()]
    with distributed.Client(cluster.scheduler_address) as client:
        for layer in (polys, lines):
            out, errors, _, _ = batch.smooth_partitioned(
                layer, client=client, partition_size=4, iterations=2
            )
            ref = geo.smooth(layer, iterations=2)
            assert errors == ()
            for a, b in zip(out, ref, strict=True):
                assert (a is None) == (b is None)
                if a is not None:
                    assert a.geom_type == b.geom_type
                    assert shapely.to_wkb(a) == shapely.to_wkb(b)


def test_z_kept_and_equal_to_the_single_process_run(cluster, counties_file, tmp_path):
    """Z (issue 14.3): batch gives the Z of geo.smooth_file, per feature and in coverage mode."""
    _, df = counties_file
    xy = shapely.get_coordinates(df.geometry.values)
    z = 300.0 + 1e-3 * (xy[:, 0] - xy[:, 0].min()) + 40.0 * np.sin(xy[:, 1] / 9e3)
    zdf = df.assign(
        geometry=shapely.set_coordinates(
            shapely.force_3d(df.geometry.values), np.column_stack([xy, z])
        )
    )
    src = tmp_path / "z.gpkg"
    geo.write_file(zdf, src)
    for coverage in (False, True):
        out, ref = tmp_path / f"b{coverage}.gpkg", tmp_path / f"r{coverage}.gpkg"
        rep = batch.smooth_file(
            src,
            out,
            coverage=coverage,
            scheduler=cluster.scheduler_address,
            partition_size=60,
            progress=False,
        )
        assert rep.errors == ()
        geo.smooth_file(src, ref, coverage=coverage)
        a, b = geo.read_file(out).geometry.values, geo.read_file(ref).geometry.values
        assert shapely.has_z(a).all()
        assert np.array_equal(
            shapely.get_coordinates(a, include_z=True), shapely.get_coordinates(b, include_z=True)
        )


def _contour_lines():
    """Raw 50 m contours of matplotlib's Jacksboro DEM (766 lines, open and closed)."""
    from matplotlib import cbook

    d = cbook.get_sample_data("jacksboro_fault_dem.npz")
    z = d["elevation"].astype(float)
    ny, nx = z.shape
    return geo.contours(
        z, x=np.arange(nx) * 74.5, y=np.arange(ny)[::-1] * 92.6, interval=50, iterations=0
    ).set_crs("EPSG:32616")


def test_network_mode_equals_smooth_network(cluster, tmp_path):
    """batch smooth --network (issue 14 e): the whole network is noded on the client, the
    arcs are smoothed on the workers in whole blocks, conflicts resolved on the client: the
    output is smooth --network's, bit for bit (also with Z, and through the CLI)."""
    from click.testing import CliRunner

    from curvesmith.cli import main

    lines = _contour_lines()
    xy = shapely.get_coordinates(lines.geometry.values)
    lines = lines.assign(
        geometry=shapely.set_coordinates(
            shapely.force_3d(lines.geometry.values), np.column_stack([xy, 0.01 * xy[:, 0]])
        )
    )
    src = tmp_path / "contours.gpkg"
    geo.write_file(lines, src)
    ref = tmp_path / "ref.gpkg"
    r = CliRunner().invoke(
        main, ["smooth", str(src), "-o", str(ref), "--network", "--iterations", "2"]
    )
    assert r.exit_code == 0, r.output
    out = tmp_path / "batch.gpkg"
    rep = batch.smooth_file(
        src,
        out,
        network=True,
        iterations=2,
        scheduler=cluster.scheduler_address,
        partition_size=100,
        progress=False,
    )
    assert rep.errors == () and rep.n_partitions >= 3  # open arcs in 2 blocks, loops in chunks
    a, b = geo.read_file(out), geo.read_file(ref)
    assert list(a["level"]) == list(b["level"])
    assert shapely.has_z(a.geometry.values).all()
    assert np.array_equal(
        shapely.get_coordinates(a.geometry.values, include_z=True),
        shapely.get_coordinates(b.geometry.values, include_z=True),
    )
    cli_out = tmp_path / "cli.gpkg"
    r = CliRunner().invoke(
        main,
        [
            "batch",
            "smooth",
            str(src),
            "-o",
            str(cli_out),
            "--network",
            "--iterations",
            "2",
            "--scheduler",
            cluster.scheduler_address,
            "--no-progress",
        ],
    )
    assert r.exit_code == 0, r.output
    c = geo.read_file(cli_out)
    assert all(shapely.equals_exact(p, q, 0.0) for p, q in zip(c.geometry, b.geometry, strict=True))
    r = CliRunner().invoke(
        main, ["batch", "smooth", str(src), "-o", str(cli_out), "--network", "--coverage"]
    )
    assert r.exit_code == 2 and "--network cannot be combined with --coverage" in r.output


@pytest.mark.slow
def test_equal_area_batch_is_per_region_like_smooth_file(cluster, tmp_path):
    # Before, batch projected the whole world into one equal-area projection: 4 features
    # failed, exit 1, and the file held invalid geometries. Now the regions, projections and
    # checks are geo's: the same bits as geo.smooth_file, every feature valid, ground areas
    # kept to the per-region accuracy
    from pathlib import Path

    import geopandas as gpd
    import pyogrio
    from pyproj import Geod

    src = Path(pyogrio.__file__).parent / "tests" / "fixtures" / "naturalearth_lowres"
    src = src / "naturalearth_lowres.shp"
    one, many = tmp_path / "one.gpkg", tmp_path / "many.gpkg"
    ref = geo.smooth_file(src, one, equal_area=True, iterations=2)
    rep = batch.smooth_file(
        src,
        many,
        equal_area=True,
        iterations=2,
        scheduler=cluster.scheduler_address,
        partition_size=16,
        progress=False,
    )
    assert rep.errors == () and rep.n_partitions > 10  # several regions, several tasks
    # the features a projection would fold, smoothed in the file's CRS: reported alike
    assert rep.not_equal_area == ref.not_equal_area and len(rep.not_equal_area) >= 1
    a, b = gpd.read_file(one), gpd.read_file(many)
    assert all(x.equals_exact(y, 0.0) for x, y in zip(a.geometry, b.geometry, strict=True))
    assert shapely.is_valid(b.geometry.values).all()
    geod = Geod(ellps="WGS84")
    world = gpd.read_file(src)
    before = np.array([abs(geod.geometry_area_perimeter(g)[0]) for g in world.geometry])
    after = np.array([abs(geod.geometry_area_perimeter(g)[0]) for g in b.geometry])
    assert np.max(np.abs(after / before - 1)) < 1e-3  # worst 0.057 % (geo's equal-area test)


@pytest.mark.parametrize(
    ("n", "size"),
    [(0, 1000), (10, 1000), (16_000, 1000), (16_001, 1001), (400_000, 25_000), (10**7, 50_000)],
)
def test_default_partition_size(n, size):
    # 1,000 features per task (the old default) on 398,222 footprints: 399 tasks, 12.6 s of
    # smoothing on 2 workers; 20 tasks: 7.7 s
    assert batch.features_per_task(None, n) == size
    assert batch.features_per_task(7, n) == 7
    with pytest.raises(CurveError, match="partition_size must be an integer >= 1, got 0"):
        batch.features_per_task(0, n)


def test_progress_bar_is_dasks_format_drawn_per_result(cluster, capsys, monkeypatch):
    # the client draws the bar as results arrive (distributed's progress() blocked until all
    # tasks were done, so no result was decoded while the workers computed); the QGIS
    # plugin reads the percentage of this format
    import re

    from curvesmith.internals import BatchProgressBar

    rng = np.random.default_rng(2)
    geoms = [shapely.box(x, 0, x + 1, 1 + rng.uniform()) for x in range(0, 200, 2)]
    seen = []
    real = BatchProgressBar.step

    def step(bar):
        seen.append(bar.done)
        real(bar)

    monkeypatch.setattr(BatchProgressBar, "step", step)
    with distributed.Client(cluster.scheduler_address) as client:
        out, errors, n_tasks, _ = batch.smooth_partitioned(
            geoms, client=client, partition_size=10, progress=True
        )
    assert errors == () and n_tasks == 10 and seen == list(range(10))
    frames = capsys.readouterr().err.split("\r")
    pct = [int(m.group(1)) for f in frames if (m := re.search(r"\|\s*(\d{1,3})% Completed", f))]
    assert pct == [0, 10, 20, 30, 40, 50, 60, 70, 80, 90, 100]
    assert frames[-1].startswith("[" + "#" * 40 + "] | 100% Completed |")
    ref = geo.smooth(geoms)
    assert all(shapely.equals_exact(a, b, 0.0) for a, b in zip(out, ref, strict=True))


def _gpkg_blobs(path):
    import sqlite3

    with sqlite3.connect(path) as con:
        (table,) = con.execute("select table_name from gpkg_contents").fetchone()
        return [row[0] for row in con.execute(f'select geom from "{table}" order by fid')]


@pytest.mark.parametrize("coverage", [False, True])
def test_empty_multipolygon_written_back_as_read(cluster, tmp_path, coverage):
    # GDAL stores POLYGON EMPTY of a MultiPolygon layer as MULTIPOLYGON(POLYGON EMPTY);
    # batch wrote MULTIPOLYGON EMPTY where geo.smooth_file keeps the bytes that were read
    df = geo.us_counties(states=["44"]).to_crs("EPSG:5070")
    g = [shapely.MultiPolygon([p]) if p.geom_type == "Polygon" else p for p in df.geometry]
    g[2] = shapely.Polygon()
    src = tmp_path / "e.gpkg"
    geo.write_file(df.assign(geometry=g), src)
    read = _gpkg_blobs(src)[2]
    assert read.endswith(bytes.fromhex("010600000001000000010300000000000000"))
    out, ref = tmp_path / "b.gpkg", tmp_path / "r.gpkg"
    kw = {"coverage": coverage}
    batch.smooth_file(src, out, scheduler=cluster.scheduler_address, progress=False, **kw)
    geo.smooth_file(src, ref, **kw)
    assert _gpkg_blobs(out) == _gpkg_blobs(ref)
    assert _gpkg_blobs(out)[2] == read


def test_coverage_in_lon_lat_keeps_the_antimeridian_as_smooth_file(cluster, tmp_path):
    # batch --coverage of Natural Earth failed ('feature 159: smoothing moved a vertex to
    # (180.15..., -86.81...), outside the longitude/latitude domain') where smooth_file
    # keeps the arcs on +-180 degrees and the poles in place
    import pyogrio

    src = (
        Path(pyogrio.__file__).parent / "tests/fixtures/naturalearth_lowres/naturalearth_lowres.shp"
    )
    out, ref = tmp_path / "b.gpkg", tmp_path / "r.gpkg"
    with pytest.warns(geo.GeographicCRSWarning):
        rep = batch.smooth_file(
            src, out, coverage=True, scheduler=cluster.scheduler_address, progress=False
        )
    with pytest.warns(geo.GeographicCRSWarning):
        geo.smooth_file(src, ref, coverage=True)
    assert rep.errors == () and rep.geographic and rep.coverage_valid is True
    assert rep.n_partitions == 0  # the fixed vertices: smooth_coverage on the client
    assert _gpkg_blobs(out) == _gpkg_blobs(ref)
    xy = shapely.get_coordinates(geo.read_file(out).geometry.values)
    assert np.abs(xy[:, 0]).max() == 180.0 and np.abs(xy[:, 1]).max() <= 90.0
