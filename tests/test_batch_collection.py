"""curvesmith.batch.smooth_collection: dask-geopandas layers smoothed where their partitions are."""

from pathlib import Path

import dask
import dask_geopandas
import distributed
import geopandas as gpd
import numpy as np
import pandas as pd
import pyogrio
import pytest
import shapely

from curvesmith import batch, geo
from curvesmith.errors import CurveError
from curvesmith.geo import GeographicCRSWarning

NATURAL_EARTH = (
    Path(pyogrio.__file__).parent / "tests/fixtures/naturalearth_lowres/naturalearth_lowres.shp"
)


def mixed_layer(seed: int = 3) -> gpd.GeoDataFrame:
    """A layer as a city's: footprints in metres (Web Mercator), some clockwise, uneven
    vertex spacing, courtyards (holes), multi-part buildings, roads, a NULL and an empty."""
    rng = np.random.default_rng(seed)
    geoms = []
    for k in range(240):
        m = int(rng.integers(4, 12))
        # uneven spacing, every gap below pi (a simple, star-shaped ring)
        ang = (np.arange(m) + rng.uniform(-0.35, 0.35, m)) * (2 * np.pi / m)
        r = rng.uniform(6, 25) * (1 + 0.15 * rng.standard_normal(m)).clip(0.6, 1.4)
        c = np.array([5.3e5, 6.1e6]) + rng.uniform(0, 4000, 2)
        ring = np.c_[r * np.cos(ang), r * np.sin(ang)] + c
        geoms.append(shapely.Polygon(ring[::-1] if k % 3 == 0 else ring))
    for _ in range(15):
        c = np.array([5.3e5, 6.1e6]) + rng.uniform(0, 4000, 2)
        outer = shapely.box(*(c - 30), *(c + 30)).buffer(4, quad_segs=2)
        geoms.append(outer.difference(shapely.box(*(c - 10), *(c + 12))))
    for _ in range(10):
        c = np.array([5.3e5, 6.1e6]) + rng.uniform(0, 4000, 2)
        geoms.append(
            shapely.MultiPolygon([shapely.box(*c, *(c + 15)), shapely.box(*(c + 20), *(c + 31))])
        )
    for _ in range(15):
        x = np.cumsum(rng.uniform(3, 40, 30))
        y = np.cumsum(rng.normal(0, 4, 30))
        geoms.append(shapely.LineString(np.c_[x, y] + [5.3e5, 6.1e6]))
    geoms += [None, shapely.Polygon()]
    order = rng.permutation(len(geoms))
    names = [f"b{i:04d}" for i in range(len(geoms))]
    return gpd.GeoDataFrame(
        {"name": names, "height": rng.uniform(3, 60, len(geoms))},
        geometry=np.array(geoms, dtype=object)[order],
        index=pd.Index(names, name="osm_id"),
        crs="EPSG:3857",
    )


def test_collection_equals_geo_smooth_on_the_whole_layer():
    df = mixed_layer()
    ddf = dask_geopandas.from_geopandas(df, npartitions=5)
    lazy = batch.smooth_collection(ddf, iterations=2, keep_angle=np.deg2rad(60))
    assert isinstance(lazy, dask_geopandas.GeoDataFrame)
    assert lazy.npartitions == 5
    out = lazy.compute(scheduler="sync")
    assert list(out.columns) == ["name", "height", "geometry", "smooth_error"]
    assert out.index.equals(df.index) and out.crs == df.crs
    assert out["smooth_error"].isna().all()
    # (Dask stores strings as pyarrow strings: the values, not the dtypes, are the input's)
    assert out["name"].tolist() == df["name"].tolist()
    np.testing.assert_array_equal(out["height"].to_numpy(), df["height"].to_numpy())
    ref = geo.smooth(df.geometry.values, iterations=2, keep_angle=np.deg2rad(60))
    got = out.geometry.values
    present = ~shapely.is_missing(ref)
    assert shapely.is_missing(got).tolist() == (~present).tolist()
    # the same bits as the whole layer in one call, feature by feature
    assert shapely.equals_identical(got[present], ref[present]).all()
    areas = shapely.area(df.geometry.values[present])
    polygons = areas > 0
    np.testing.assert_allclose(shapely.area(got[present][polygons]), areas[polygons], rtol=1e-9)
    assert shapely.is_valid(got[present]).all()


def test_a_geoseries_becomes_a_frame_of_its_column():
    df = mixed_layer(seed=5)
    out = batch.smooth_collection(
        dask_geopandas.from_geopandas(df.geometry, npartitions=3), method="chaikin"
    ).compute(scheduler="sync")
    assert list(out.columns) == ["geometry", "smooth_error"]
    ref = geo.smooth(df.geometry.values, method="chaikin")
    ok = ~shapely.is_missing(ref)
    assert shapely.equals_identical(out.geometry.values[ok], ref[ok]).all()


def test_failing_features_are_kept_as_they_were_and_named():
    df = mixed_layer(seed=7).reset_index(drop=True)  # integer labels, not positions
    df.index = df.index * 10 + 7
    bowtie = shapely.Polygon([(0, 0), (2, 2), (2, 0), (0, 2)])
    spike = shapely.Polygon([(0, 0), (1, 0), (1, 1), (1, 0), (0, 0)])  # no area
    df.loc[df.index[4], "geometry"] = bowtie
    df.loc[df.index[-3], "geometry"] = spike
    ddf = dask_geopandas.from_geopandas(df, npartitions=4)
    out = batch.smooth_collection(ddf, iterations=1, errors="why").compute(scheduler="sync")
    failed = out["why"].dropna()
    assert failed.index.tolist() == [df.index[4], df.index[-3]]
    assert failed.iloc[0].startswith(f"CurveError: feature {df.index[4]} is not valid")
    assert failed.iloc[1].startswith(f"CurveError: feature {df.index[-3]} is not valid")
    assert out.geometry.loc[df.index[4]].equals_exact(bowtie, 0)
    assert out.geometry.loc[df.index[-3]].equals_exact(spike, 0)
    others = out.drop(index=failed.index)
    assert shapely.is_valid(others.geometry.dropna().values).all()
    ref = geo.smooth(df.drop(index=failed.index).geometry.values, iterations=1)
    ok = ~shapely.is_missing(ref)
    assert shapely.equals_identical(others.geometry.values[ok], ref[ok]).all()
    # a label that is not an integer names the feature as it is
    named = df.set_axis([f"k{i}" for i in range(len(df))])
    out = batch.smooth_collection(dask_geopandas.from_geopandas(named, npartitions=2)).compute(
        scheduler="sync"
    )
    assert out.loc["k4", "smooth_error"].startswith("CurveError: feature k4 is not valid")
    # without the column, the failure is the computation's error
    one = dask_geopandas.from_geopandas(df.drop(index=df.index[-3]), npartitions=4)
    with pytest.raises(CurveError, match=f"^feature {df.index[4]} is not valid"):
        batch.smooth_collection(one, errors=None).compute(scheduler="sync")


def test_points_pass_through_as_smooth_file_passes_them():
    df = mixed_layer(seed=9)
    where = df.index[[3, 50, 100]]
    df.loc[where[0], "geometry"] = shapely.Point(5.3e5, 6.1e6)
    df.loc[where[1], "geometry"] = shapely.MultiPoint([(5.3e5, 6.1e6), (5.3e5 + 9, 6.1e6)])
    df.loc[where[2], "geometry"] = shapely.Point()
    out = batch.smooth_collection(
        dask_geopandas.from_geopandas(df, npartitions=3), iterations=2
    ).compute(scheduler="sync")
    assert out["smooth_error"].isna().all()
    assert shapely.equals_identical(
        out.geometry.loc[where].values, df.geometry.loc[where].values
    ).all()
    rest = df.drop(index=where)
    ref = geo.smooth(rest.geometry.values, iterations=2)
    ok = ~shapely.is_missing(ref)
    assert shapely.equals_identical(out.geometry.loc[rest.index].values[ok], ref[ok]).all()


def test_one_bad_feature_among_many_costs_a_few_calls(monkeypatch):
    # Before, a partition with one failing feature was smoothed again a feature at a time:
    # 20,000 calls (12-18x the partition's time). Now its halves are, until the failing
    # feature stands alone: about 2 log2(n) calls of shrinking size, the same result.
    from curvesmith.internals import batch_smooth_partition, geo_packets

    geoms = mixed_layer(seed=11).geometry.values
    geoms = np.concatenate([geoms] * 8)  # 2,256 features
    bad = 1000
    geoms[bad] = shapely.Polygon([(0, 0), (2, 2), (2, 0), (0, 2)])
    calls = []
    smooth = geo.smooth

    def counted(g, **kw):
        calls.append(len(g))
        return smooth(g, **kw)

    monkeypatch.setattr(geo, "smooth", counted)
    packet, errors, _ = batch_smooth_partition(
        geo_packets.pack(geoms), 100, {"method": "cca", "iterations": 1, "keep_angle": 1.0}
    )
    assert [e[0] for e in errors] == [100 + bad]
    assert errors[0][1].startswith(f"CurveError: feature {100 + bad} is not valid")
    assert len(calls) <= 2 * np.log2(len(geoms)) + 2 and sum(calls) <= 3 * len(geoms)
    out = geo_packets.unpack(packet)
    ok = np.arange(len(geoms)) != bad
    ref = smooth(geoms[ok], iterations=1, keep_angle=1.0)
    present = ~shapely.is_missing(ref)
    assert shapely.equals_identical(out[ok][present], ref[present]).all()
    assert out[bad].equals_exact(geoms[bad], 0)


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"iterations": -1}, "iterations"),
        ({"keep_angle": 4.0}, "keep_angle"),
        ({"max_shift": -2.0}, "max_shift"),
        ({"method": "bezier"}, "method"),
        ({"fixed": np.zeros(3, dtype=bool)}, "fixed must be None or a callable"),
        ({"errors": "name"}, "errors names a column of the frame already: 'name'"),
        ({"errors": False}, "errors must be a column name .* got False"),
        ({"errors": ""}, "errors must be a column name .* got ''"),
        ({"make_valid": "False"}, "make_valid must be True or False, got 'False'"),
        ({"alpha": lambda theta: 0.5 + 0 * theta}, "alpha.*tried on one square"),
        ({"fixed": lambda xy: 1 / 0}, "ZeroDivisionError"),
        ({"iterations": 40}, "iterations 40 would turn .*tried on one square"),
    ],
)
def test_bad_options_are_refused_before_anything_runs(kwargs, match):
    ddf = dask_geopandas.from_geopandas(mixed_layer(), npartitions=2)
    with dask.config.set(scheduler="sync"), pytest.raises(CurveError, match=match):
        batch.smooth_collection(ddf, **kwargs)


def test_a_frame_in_memory_is_refused_with_the_way_to_go():
    with pytest.raises(CurveError, match="got GeoDataFrame .*smooth_partitioned"):
        batch.smooth_collection(mixed_layer())


def test_a_frame_without_an_active_geometry_is_refused():
    df = mixed_layer().rename_geometry("shape")
    frame = dask_geopandas.from_geopandas(df, npartitions=2)
    frame = frame.assign(shape2=frame["shape"]).drop(columns="shape")
    with pytest.raises(CurveError, match="no active geometry column .*set_geometry"):
        batch.smooth_collection(frame)


def test_natural_earth_read_smoothed_and_written_by_worker_processes(tmp_path):
    # the layer never passes through the client: the workers read their parts of the
    # Shapefile, smooth them and write the GeoParquet parts
    ref_in = geo.read_file(NATURAL_EARTH)
    with (
        distributed.LocalCluster(
            host="127.0.0.1", n_workers=2, threads_per_worker=1, processes=True,
            dashboard_address=":0", silence_logs=40, timeout="60s",
        ) as cluster,
        distributed.Client(cluster),
    ):  # fmt: skip
        ddf = dask_geopandas.read_file(NATURAL_EARTH, npartitions=3)
        with pytest.warns(GeographicCRSWarning, match=r"geographic CRS \(WGS 84\).*poles stay"):
            out = batch.smooth_collection(ddf, iterations=2)
        out.to_parquet(tmp_path / "smoothed")
    back = gpd.read_parquet(tmp_path / "smoothed")
    assert len(back) == len(ref_in) == 177
    assert back["smooth_error"].isna().all()
    assert list(back["name"]) == list(ref_in["name"])
    # lon/lat: the vertices on the antimeridian (Russia, Fiji, Antarctica) and the poles
    # stay put, and the input's 180.00000000000006 is put on the edge, as curvesmith
    # smooth does
    values = ref_in.geometry.values
    ref = geo.smooth(values, iterations=2, fixed=geo.domain_fixed(ref_in.crs))
    ref = geo.clamp_to_domain(ref, "naturalearth_lowres", values)
    assert shapely.equals_identical(back.geometry.values, ref).all()
    x0, y0, x1, y1 = shapely.total_bounds(back.geometry.values)
    assert shapely.total_bounds(values)[2] > 180.0  # (the input's own rounding)
    assert x0 >= -180.0 and x1 <= 180.0 and y0 >= -90.0 and y1 <= 90.0
    np.testing.assert_allclose(
        shapely.area(back.geometry.values), shapely.area(ref_in.geometry.values), rtol=1e-11
    )


def test_chaikin_in_lon_lat_is_warned_about_degrees_only():
    df = geo.read_file(NATURAL_EARTH).iloc[:20]
    frame = dask_geopandas.from_geopandas(df, npartitions=2)
    with pytest.warns(GeographicCRSWarning) as caught:
        out = batch.smooth_collection(frame, method="chaikin", iterations=2)
    (message,) = [str(w.message) for w in caught]
    assert "smoothing works in degrees" in message and "stay put" not in message
    ref = geo.smooth(df.geometry.values, method="chaikin", iterations=2)
    ref = geo.clamp_to_domain(ref, "naturalearth_lowres", df.geometry.values)
    got = out.compute(scheduler="sync").geometry.values
    assert shapely.equals_identical(got, ref).all()


@pytest.mark.parametrize(
    "call",
    [
        lambda g, v: geo.smooth(g, make_valid=v),
        lambda g, v: geo.smooth_coverage(g, make_valid=v),
        lambda g, v: batch.smooth_partitioned(g, make_valid=v),
    ],
)
@pytest.mark.parametrize("value", ["False", 1, None])
def test_make_valid_is_a_bool_everywhere(call, value):
    # a string 'False' was truthy: the bow-tie was repaired where the caller said not to
    bowtie = np.array([shapely.Polygon([(0, 0), (2, 2), (2, 0), (0, 2)])], dtype=object)
    with pytest.raises(CurveError, match=f"make_valid must be True or False, got {value!r}"):
        call(bowtie, value)
