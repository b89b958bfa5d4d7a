"""curvesmith.geo file I/O and smooth_file: formats, layers, order, attributes, CRS."""

import contextlib

import geopandas as gpd
import numpy as np
import pyogrio
import pytest
import shapely

from curvesmith import geo
from curvesmith.errors import CurveError, CurveFormatError


def sample_frame(crs="EPSG:3857"):
    polys = [
        shapely.Polygon([(0, 0), (4, 0), (4, 3), (2, 4), (0, 3)], [[(1, 1), (1, 2), (2, 2)]]),
        shapely.MultiPolygon([shapely.box(10, 0, 12, 2), shapely.box(13, 0, 14, 5)]),
        shapely.Polygon([(20, 0), (25, 1), (22, 6)]),
    ]
    return gpd.GeoDataFrame(
        {"name": ["c", "a", "b"], "pop": [30, 10, 20]},
        geometry=polys,
        crs=crs,
    )


def ring_areas(geoms):
    out = []
    for g in geoms:
        for part in shapely.get_parts(g):
            for ring in shapely.get_rings(part):
                out.append(shapely.area(shapely.Polygon(ring)) * (1 if ring.is_ccw else -1))
    return np.array(out)


@pytest.mark.parametrize("suffix", [".gpkg", ".shp", ".geojson", ".fgb"])
def test_round_trip_every_format(tmp_path, suffix):
    df = sample_frame()
    src = tmp_path / f"in{suffix}"
    geo.write_file(df, src)
    out = tmp_path / f"out{suffix}"
    rep = geo.smooth_file(src, out, iterations=2)
    assert rep.n_features == 3 and rep.crs is not None and not rep.geographic
    back = geo.read_file(out)
    assert len(back) == 3
    assert list(back["name"]) == ["c", "a", "b"]
    assert list(back["pop"]) == [30, 10, 20]
    assert back.crs == df.crs
    assert shapely.is_valid(back.geometry.values).all()
    np.testing.assert_allclose(shapely.area(back.geometry.values), df.area.values, rtol=1e-9)
    if suffix != ".shp":  # a Shapefile stores rings in its own orientation
        np.testing.assert_allclose(
            ring_areas(back.geometry.values), ring_areas(df.geometry.values), rtol=1e-9
        )


@pytest.mark.parametrize("suffix", [".gpkg", ".shp", ".geojson", ".fgb"])
def test_coordinates_read_back_bit_for_bit(tmp_path, suffix):
    # GDAL's GeoJSON writer rounded to 15 decimals: 1/3 degree came back 3e-17 off
    rng = np.random.default_rng(3)
    t = np.sort(rng.uniform(0, 2 * np.pi, 40))
    for scale, shift in ((1 / 3, 0.0), (1e-3, 7 / 9), (170.0, 0.0), (3e5, 5e6)):
        ring = np.c_[np.cos(t), np.sin(t)] * scale + shift
        df = gpd.GeoDataFrame(geometry=[shapely.Polygon(ring)], crs="EPSG:4326")
        path = tmp_path / f"p{suffix}"
        geo.write_file(df, path)
        back = shapely.get_coordinates(geo.read_file(path).geometry.values)
        np.testing.assert_array_equal(np.unique(back, axis=0), np.unique(ring, axis=0))


def test_layers_select_and_unknown(tmp_path):
    path = tmp_path / "two.gpkg"
    geo.write_file(sample_frame(), path, layer="first")
    other = sample_frame().iloc[:1]
    geo.write_file(other, path, layer="second")
    assert len(geo.read_file(path, layer="second")) == 1
    assert len(geo.read_file(path, layer=0)) == 3
    out = tmp_path / "out.gpkg"
    geo.smooth_file(path, out, layer="second")
    assert [str(x) for x in pyogrio.list_layers(out)[:, 0]] == ["second"]
    with pytest.raises(
        CurveFormatError, match=r"layer 'third' not found .* layers: \['first', 'second'\]"
    ):
        geo.read_file(path, layer="third")
    with pytest.raises(CurveFormatError, match=r"layer must be an index in \[0, 1\]"):
        geo.read_file(path, layer=5)


@pytest.mark.parametrize("kind", ["polygons", "mixed", "lines_z", "unknown"])
def test_geopackage_written_in_slices_equals_one_write(tmp_path, monkeypatch, kind):
    """A large GeoPackage is written in slices (append) and read back in slices: the file
    holds the same layer type, features, order, attributes and NULLs as one write."""
    from curvesmith.internals import geo_io as _io
    from curvesmith.internals import slices

    rng = np.random.default_rng(5)
    n = 40
    boxes = [
        shapely.box(x, 0, x + rng.uniform(1, 3), rng.uniform(1, 4)) for x in range(0, 5 * n, 5)
    ]
    if kind == "polygons":
        geoms = boxes
    elif kind == "mixed":  # Polygons first, the MultiPolygons only in later slices
        geoms = boxes[:30] + [
            shapely.MultiPolygon([b, shapely.box(-9, -9, -8, -8)]) for b in boxes[30:]
        ]
    elif kind == "lines_z":
        geoms = [
            shapely.LineString([(x, 0, 1.5), (x + 1, 2, 2.5), (x + 3, 1, 0)]) for x in range(n)
        ]
    else:  # lines and polygons: "Unknown"
        geoms = boxes[:20] + [shapely.LineString([(x, 0), (x + 1, 2)]) for x in range(20)]
    geoms = list(geoms)
    geoms[3] = None  # a NULL geometry in the first slice
    df = gpd.GeoDataFrame(
        {"k": np.arange(n), "name": [f"f{i}" for i in range(n)]}, geometry=geoms, crs="EPSG:32633"
    )
    one = tmp_path / "one.gpkg"
    geo.write_file(df, one)
    monkeypatch.setattr(_io, "WRITE_CHUNK_VERTICES", 37)
    assert len(slices(np.asarray(df.geometry.values, dtype=object))) > 3
    reads = []
    real_read = pyogrio.raw.read

    def counting_read(*args, **kwargs):
        reads.append(kwargs.get("where"))
        return real_read(*args, **kwargs)

    monkeypatch.setattr(pyogrio.raw, "read", counting_read)
    many = tmp_path / "many.gpkg"
    geo.write_file(df, many)
    assert len(reads) > 3 and None not in reads  # read back slice by slice, by FID range
    monkeypatch.undo()
    # FIDs numbered otherwise (the ranges find nothing): checked again by position, passes
    reads.clear()

    def renumbered_read(*args, **kwargs):
        reads.append(kwargs.get("where") or kwargs.get("max_features"))
        if "where" in kwargs:
            kwargs["where"] = "FID < 0"
        return real_read(*args, **kwargs)

    monkeypatch.setattr(_io, "WRITE_CHUNK_VERTICES", 37)
    monkeypatch.setattr(pyogrio.raw, "read", renumbered_read)
    other = tmp_path / "other.gpkg"
    geo.write_file(df, other)
    assert any(isinstance(r, str) for r in reads) and any(isinstance(r, int) for r in reads)
    monkeypatch.undo()
    assert len(geo.read_file(other)) == n
    a, b = pyogrio.read_info(one), pyogrio.read_info(many)
    assert a["geometry_type"] == b["geometry_type"]
    assert a["features"] == b["features"] == n
    assert list(a["fields"]) == list(b["fields"]) and list(a["dtypes"]) == list(b["dtypes"])
    ra, rb = geo.read_file(one), geo.read_file(many)
    assert list(ra["k"]) == list(rb["k"]) == list(range(n))
    assert list(ra["name"]) == list(rb["name"])
    ga, gb = np.asarray(ra.geometry.values), np.asarray(rb.geometry.values)
    assert ga[3] is None and gb[3] is None and rb.crs == df.crs
    keep = np.arange(n) != 3
    assert shapely.equals_identical(ga[keep], gb[keep]).all()
    # a named layer added to an existing GeoPackage keeps the other layers
    geo.write_file(df.iloc[:5], many, layer="small")
    monkeypatch.setattr(_io, "WRITE_CHUNK_VERTICES", 37)
    geo.write_file(df, many, layer="big")
    layers = {str(x) for x in pyogrio.list_layers(many)[:, 0]}
    assert layers == {"many", "small", "big"}
    assert len(geo.read_file(many, layer="big")) == n
    assert len(geo.read_file(many, layer="small")) == 5


def test_missing_file_and_unknown_suffix(tmp_path):
    with pytest.raises(CurveFormatError, match="no such file"):
        geo.read_file(tmp_path / "nope.gpkg")
    with pytest.raises(CurveFormatError, match=r"cannot tell the format of .*\.txt"):
        geo.write_file(sample_frame(), tmp_path / "x.txt")


def test_shapefile_rejects_mixed_types(tmp_path):
    df = gpd.GeoDataFrame(
        {"k": [1, 2]},
        geometry=[shapely.box(0, 0, 1, 1), shapely.LineString([(0, 0), (1, 1), (2, 0)])],
        crs="EPSG:3857",
    )
    with pytest.raises(
        CurveFormatError, match="a Shapefile holds one geometry type, got LineString, Polygon"
    ):
        geo.write_file(df, tmp_path / "mixed.shp")
    src = tmp_path / "mixed.gpkg"
    geo.write_file(df, src)
    geo.smooth_file(src, tmp_path / "mixed_out.gpkg")
    assert list(geo.read_file(tmp_path / "mixed_out.gpkg").geom_type) == ["Polygon", "LineString"]


def test_geographic_crs_warns_and_equal_area_keeps_ground_area(tmp_path):
    df = geo.us_counties(states=["44"])  # Rhode Island, NAD83 degrees
    src = tmp_path / "ri.fgb"
    geo.write_file(df, src)
    with pytest.warns(geo.GeographicCRSWarning, match="geographic CRS"):
        rep = geo.smooth_file(src, tmp_path / "deg.fgb", coverage=True)
    assert rep.geographic and not rep.equal_area and rep.coverage_valid
    rep = geo.smooth_file(src, tmp_path / "ea.fgb", coverage=True, equal_area=True)
    assert rep.equal_area
    out = geo.read_file(tmp_path / "ea.fgb")
    assert out.crs == df.crs
    laea = geo.equal_area_crs(df)
    ground_in = df.to_crs(laea).area.values
    ground_out = out.to_crs(laea).area.values
    np.testing.assert_allclose(ground_out, ground_in, rtol=1e-9)
    assert shapely.coverage_is_valid(out.geometry.values)


def test_equal_area_needs_crs(tmp_path):
    df = sample_frame(crs=None)
    src = tmp_path / "nocrs.gpkg"
    with pytest.warns(UserWarning, match="'crs' was not provided"):
        geo.write_file(df, src)
    with pytest.raises(CurveError, match="equal_area needs a CRS"):
        geo.smooth_file(src, tmp_path / "o.gpkg", equal_area=True)


def test_geojson_coverage_mode(tmp_path):
    df = geo.us_counties(states=["10"])  # Delaware: 3 counties
    src = tmp_path / "de.geojson"
    geo.write_file(df.to_crs("EPSG:5070"), src)
    out = tmp_path / "de_out.geojson"
    rep = geo.smooth_file(src, out, coverage=True, iterations=2)
    assert rep.coverage and rep.coverage_valid and rep.n_features == 3
    back = geo.read_file(out)
    assert shapely.coverage_is_valid(back.geometry.values)
    src_df = geo.read_file(src)
    np.testing.assert_allclose(back.area.values, src_df.area.values, rtol=1e-9)


def test_invalid_feature_in_file_needs_make_valid(tmp_path):
    df = sample_frame()
    df.loc[1, "geometry"] = shapely.Polygon([(0, 0), (2, 2), (2, 0), (0, 2)])
    src = tmp_path / "bad.gpkg"
    geo.write_file(df, src)
    with pytest.raises(CurveError, match=r"geometry\[1\] is not valid"):
        geo.smooth_file(src, tmp_path / "o.gpkg")
    geo.smooth_file(src, tmp_path / "o.gpkg", make_valid=True)
    assert shapely.is_valid(geo.read_file(tmp_path / "o.gpkg").geometry.values).all()


def test_geopackage_written_without_journal_then_synced_and_options_restored(tmp_path, monkeypatch):
    """The GeoPackage goes out with SQLite's journal and syncs off, is fsynced before it
    replaces anything, and GDAL's options are as before afterwards (a user's own kept)."""
    from curvesmith.internals import geo_io

    # pyogrio reads a config option "OFF" back as False
    seen, synced = [], []
    real_write = pyogrio.write_dataframe

    def spy(*a, **kw):
        seen.append({k: pyogrio.get_gdal_config_option(k) for k in geo_io.GPKG_WRITE_OPTIONS})
        return real_write(*a, **kw)

    monkeypatch.setattr(pyogrio, "write_dataframe", spy)
    monkeypatch.setattr(geo_io, "fsync_path", lambda p: synced.append((p, p.is_file())))
    df = sample_frame()
    geo.write_file(df, tmp_path / "a.gpkg")
    assert seen == [{"OGR_SQLITE_JOURNAL": False, "OGR_SQLITE_SYNCHRONOUS": False}]
    # the temporary file, synced while it exists, before the rename
    assert len(synced) == 1 and synced[0][0] != tmp_path / "a.gpkg" and synced[0][1]
    assert all(pyogrio.get_gdal_config_option(k) is None for k in geo_io.GPKG_WRITE_OPTIONS)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.gpkg"]  # no journal left
    back = geo.read_file(tmp_path / "a.gpkg")
    assert list(back["name"]) == ["c", "a", "b"]
    assert shapely.equals(back.geometry.values, df.geometry.values).all()
    # a journal mode the user chose is theirs: kept while writing and after
    pyogrio.set_gdal_config_options({"OGR_SQLITE_JOURNAL": "DELETE"})
    try:
        geo.write_file(df, tmp_path / "b.gpkg")
        assert seen[-1] == {"OGR_SQLITE_JOURNAL": "DELETE", "OGR_SQLITE_SYNCHRONOUS": False}
        assert pyogrio.get_gdal_config_option("OGR_SQLITE_JOURNAL") == "DELETE"
        assert pyogrio.get_gdal_config_option("OGR_SQLITE_SYNCHRONOUS") is None
    finally:
        pyogrio.set_gdal_config_options({"OGR_SQLITE_JOURNAL": None})
    # other formats are written with GDAL's options untouched and not synced here
    geo.write_file(df, tmp_path / "c.fgb")
    assert seen[-1] == {"OGR_SQLITE_JOURNAL": None, "OGR_SQLITE_SYNCHRONOUS": None}
    assert len(synced) == 2


@pytest.mark.parametrize("suffix", [".shp", ".fgb", ".gpkg", ".geojson"])
def test_write_file_with_an_empty_geometry(tmp_path, suffix):
    # Shapefile and FlatGeobuf have no empty geometry (GDAL writes NULL): the read-back
    # check expected no NULL and refused the file, blaming a full disk
    df = gpd.GeoDataFrame(
        {"a": [1, 2, 3]},
        geometry=[shapely.box(0, 0, 10, 10), shapely.Polygon(), None],
        crs="EPSG:3857",
    )
    out = tmp_path / f"o{suffix}"
    geo.write_file(df, out)
    back = geo.read_file(out)
    assert back["a"].tolist() == [1, 2, 3]
    assert shapely.equals(back.geometry.values[0], df.geometry.values[0])
    second = back.geometry.values[1]
    if suffix in (".shp", ".fgb"):
        assert second is None
    else:
        assert second is None or shapely.is_empty(second)
    assert back.geometry.values[2] is None


def _field_types(path):
    info = pyogrio.read_info(path)
    types = zip(info["ogr_types"], info["ogr_subtypes"], strict=True)
    return dict(zip(info["fields"], types, strict=True))


@pytest.mark.parametrize("suffix", [".gpkg", ".fgb"])
def test_field_types_survive_read_smooth_write(tmp_path, suffix):
    # pyogrio's default reader turns an Integer/Boolean field with a NULL into float64 and a
    # Date into datetime64, which were written back as Real and DateTime
    import datetime as dt

    import pandas as pd
    import pyarrow as pa
    from click.testing import CliRunner

    from curvesmith.cli import main

    df = gpd.GeoDataFrame(
        {
            "i32": pd.array([1, None, 3], dtype="Int32"),
            "i64": pd.array([10, 20, None], dtype="Int64"),
            # beyond float64's integers (2**53): read as float64, 2**53 + 1 was written 2**53
            "wide": pd.array([2**53 + 1, None, -(2**63)], dtype="Int64"),
            # 2**63 - 1 (a common sentinel) failed the cast from float64: a TypeError
            "edge": pd.array([2**63 - 1, None, -(2**63) + 1], dtype="Int64"),
            "i16": pd.array([None, 2, 3], dtype="Int16"),
            "flag": pd.array([True, None, False], dtype="boolean"),
            "ok": np.array([1, 2, 3], dtype=np.int32),
            "day": pd.array(
                [dt.date(2020, 1, 31), None, dt.date(1999, 12, 1)], dtype=pd.ArrowDtype(pa.date32())
            ),
            "name": ["a", None, "c"],
        },
        geometry=[shapely.box(k * 20, 0, k * 20 + 10, 10) for k in range(3)],
        crs="EPSG:32633",
    )
    src, out = tmp_path / f"in{suffix}", tmp_path / f"out{suffix}"
    opts = {"layer_options": {"SPATIAL_INDEX": "NO"}} if suffix == ".fgb" else {}  # in order
    pyogrio.write_dataframe(df, src, use_arrow=True, **opts)
    want = _field_types(src)
    assert want["i16"] == ("OFTInteger", "OFSTInt16")
    assert want["day"][0] == ("OFTDate" if suffix == ".gpkg" else "OFTDateTime")  # FGB: no Date
    back = geo.read_file(src)
    assert back["i32"].tolist()[::2] == [1, 3] and back["i32"].isna().tolist() == [0, 1, 0]
    assert (
        back["wide"].tolist()[::2] == [2**53 + 1, -(2**63)] and str(back["wide"].dtype) == "Int64"
    )
    assert str(back["i32"].dtype) == "Int32" and str(back["flag"].dtype) == "boolean"
    assert back["ok"].dtype == np.int32  # no NULL: numpy's type, as before
    res = CliRunner().invoke(main, ["smooth", str(src), "-o", str(out)])
    assert res.exit_code == 0, res.output
    assert _field_types(out) == want
    got = pyogrio.read_dataframe(out, use_arrow=True)

    def values(col):
        return [None if pd.isna(v) else v for v in col]

    for col in ("i32", "i64", "wide", "edge", "i16", "flag", "ok", "name"):
        assert values(got[col]) == values(df[col]), col
    days = [None if pd.isna(v) else pd.Timestamp(v).date() for v in got["day"]]
    assert days == [dt.date(2020, 1, 31), None, dt.date(1999, 12, 1)]


@pytest.mark.parametrize("suffix", [".gpkg", ".fgb", ".geojson"])
@pytest.mark.filterwarnings("ignore:Non-conformant content")  # GDAL on a GPKG's offsets
def test_date_times_keep_their_utc_offsets(tmp_path, suffix):
    # a DateTime field whose values have different offsets (a GPS log across a DST change,
    # field teams in two zones) was read as UTC by pyogrio's default and written back as
    # UTC: the same instants, but the offsets of the file were lost
    import datetime as dt

    from click.testing import CliRunner

    from curvesmith.cli import main

    def tz(h):
        return dt.timezone(dt.timedelta(hours=h))

    df = gpd.GeoDataFrame(
        {
            "mixed": [
                dt.datetime(2024, 3, 30, 23, 59, 58, tzinfo=tz(1)),
                dt.datetime(2024, 3, 31, 3, 0, 1, tzinfo=tz(2)),
                None,
                dt.datetime(2024, 6, 1, 10, tzinfo=tz(-5)),
            ],
            "one_zone": [dt.datetime(2024, 1, k + 1, 12, tzinfo=tz(9)) for k in range(4)],
            "naive": [dt.datetime(2024, 1, 1, k) for k in range(4)],
        },
        geometry=[shapely.box(k * 20, 0, k * 20 + 10, 10) for k in range(4)],
        crs="EPSG:32633",
    )
    src, out = tmp_path / f"in{suffix}", tmp_path / f"out{suffix}"
    opts = {"layer_options": {"SPATIAL_INDEX": "NO"}} if suffix == ".fgb" else {}  # in order
    pyogrio.write_dataframe(df, src, **opts)
    as_text = pyogrio.read_dataframe(src, datetime_as_string=True)
    assert as_text["mixed"][1].endswith("+02:00")  # the file has the offsets
    back = geo.read_file(src)
    assert back["mixed"][3] == df["mixed"][3] and back["mixed"][3].utcoffset().days == -1
    res = CliRunner().invoke(main, ["smooth", str(src), "-o", str(out)])
    assert res.exit_code == 0, res.output
    assert _field_types(out) == _field_types(src)
    got = pyogrio.read_dataframe(out, datetime_as_string=True)
    for col in ("mixed", "one_zone", "naive"):
        assert got[col].fillna("NULL").tolist() == as_text[col].fillna("NULL").tolist(), col


def test_reading_says_what_it_chose_or_could_not_find(tmp_path):
    # several layers and no layer=: the first was read without a word; a Shapefile without
    # its .dbf (no attributes) or .prj (no CRS) too
    import shutil
    import warnings

    from click.testing import CliRunner

    from curvesmith.cli import main
    from curvesmith.internals import geo_io

    df = geo.us_counties(states=["10"])
    gpkg = tmp_path / "two.gpkg"
    geo.write_file(df, gpkg, layer="a")
    geo.write_file(df.iloc[:1], gpkg, layer="b")
    with pytest.warns(
        geo_io.InputWarning, match=r"2 layers with geometries \(a, b\): reading the first, 'a'"
    ):
        assert len(geo.read_file(gpkg)) == len(df)
    with warnings.catch_warnings():
        warnings.simplefilter("error", geo_io.InputWarning)
        assert len(geo.read_file(gpkg, layer="b")) == 1
    shp = tmp_path / "c.shp"
    geo.write_file(df, shp)
    for part, said in ((".dbf", "no attributes"), (".prj", "no CRS")):
        bare = tmp_path / f"bare{part[1:]}"
        bare.mkdir()
        for sib in tmp_path.glob("c.*"):
            if sib.suffix != part:
                shutil.copy(sib, bare / sib.name)
        with pytest.warns(geo_io.InputWarning, match=f"c.shp has no {part} beside it: .*{said}"):
            geo.read_file(bare / "c.shp")
    out = tmp_path / "o.gpkg"
    res = CliRunner().invoke(main, ["smooth", str(gpkg), "-o", str(out)])
    assert res.exit_code == 0, res.output
    lines = [ln for ln in res.stderr.splitlines() if "layers with geometries" in ln]
    assert len(lines) == 1 and lines[0].startswith("Warning: two.gpkg has 2 layers")


@pytest.mark.parametrize(
    ("crs", "expected"),
    [
        ("EPSG:5070", True),
        ("EPSG:3035", True),
        ("EPSG:6933", True),
        ("EPSG:8857", True),
        ("ESRI:54008", True),
        ("ESRI:54009", False),  # Mollweide: PROJ's is spherical
        ("EPSG:2163", False),  # Lambert azimuthal on the sphere
        ("EPSG:32633", False),
        ("EPSG:4326", False),
    ],
)
def test_is_equal_area_crs(crs, expected):
    import pyproj

    from curvesmith.internals import geo_io

    assert geo_io.is_equal_area_crs(pyproj.CRS(crs)) is expected


def test_equal_area_on_data_in_an_equal_area_crs_smooths_them_in_it(tmp_path):
    # they were projected to another equal-area projection and back, which bent their straight
    # edges: US counties in Albers came back with areas off by 1.8e-5 instead of 3e-15
    df = geo.us_counties(states=["20"]).to_crs("EPSG:5070")
    src = tmp_path / "ks.gpkg"
    geo.write_file(df, src)
    outs = {}
    for flag in (False, True):
        out = tmp_path / f"o{flag}.gpkg"
        report = geo.smooth_file(src, out, equal_area=flag)
        assert report.equal_area is flag
        outs[flag] = geo.read_file(out).geometry.values
    assert shapely.to_wkb(outs[True]).tolist() == shapely.to_wkb(outs[False]).tolist()
    np.testing.assert_allclose(
        shapely.area(outs[True]), shapely.area(df.geometry.values), rtol=1e-13
    )


@pytest.mark.parametrize("chunk", [None, 50])
def test_geopackage_keeps_its_geometry_column_name(tmp_path, monkeypatch, chunk):
    # QGIS-made GeoPackages name the column "WKT" or "shape"; the output said "geom"
    from curvesmith.internals import geo_io

    if chunk is not None:  # written in several slices: the name is the first slice's
        monkeypatch.setattr(geo_io, "WRITE_CHUNK_VERTICES", chunk)
    df = geo.us_counties(states=["10", "44"])
    src, out = tmp_path / "in.gpkg", tmp_path / "out.gpkg"
    pyogrio.write_dataframe(df, src, layer_options={"GEOMETRY_NAME": "shape"})
    assert pyogrio.read_info(src)["geometry_name"] == "shape"
    back = geo.read_file(src)
    geo.write_file(back, out)
    info = pyogrio.read_info(out)
    assert info["geometry_name"] == "shape" and info["features"] == len(df)
    assert shapely.equals(geo.read_file(out).geometry.values, back.geometry.values).all()


@pytest.mark.parametrize("suffix", [".gpkg", ".fgb", ".geojson", ".shp"])
def test_nested_geojson_properties_stay_json(tmp_path, suffix):
    # pyogrio reads a GeoJSON property holding an object or an array as Python objects and
    # wrote them back with str(): "{'x': [1, 2]}", which no program reads as JSON
    import json

    from click.testing import CliRunner

    from curvesmith.cli import main

    values = [{"x": [1, 2], "name": "Zürich"}, [3, {"y": None}], None, "plain"]
    feats = [
        {"type": "Feature", "properties": {"k": k, "tags": v},
         "geometry": {"type": "Polygon", "coordinates": [[[k, 0], [k + 1, 0], [k, 1], [k, 0]]]}}
        for k, v in enumerate(values)
    ]  # fmt: skip
    src = tmp_path / "nested.geojson"
    src.write_text(json.dumps({"type": "FeatureCollection", "features": feats}), "utf-8")
    out = tmp_path / f"o{suffix}"
    res = CliRunner().invoke(main, ["smooth", str(src), "-o", str(out), "--allow-null"])
    assert res.exit_code == 0, res.output
    if suffix == ".geojson":  # GDAL's writer turns the JSON text into the nested value
        got = [f["properties"]["tags"] for f in json.loads(out.read_text("utf-8"))["features"]]
        assert got == values
        return
    text = pyogrio.read_dataframe(out)["tags"].tolist()
    assert [json.loads(t) for t in text[:2]] == values[:2]
    assert text[2] is None or text[2] != text[2]  # NULL
    assert text[3] == "plain"


def _fids(path):
    import sqlite3

    with contextlib.closing(sqlite3.connect(path)) as con:
        layers = [r[0] for r in con.execute("SELECT table_name FROM gpkg_contents")]
        return {
            t: [r[0] for r in con.execute(f'SELECT fid FROM "{t}" ORDER BY rowid')] for t in layers
        }


@pytest.mark.parametrize("chunk", [None, 20])
def test_geopackage_keeps_its_feature_ids_and_layer_name(tmp_path, monkeypatch, chunk):
    # the features were numbered 1..n again (France went from fid 144 to 35 in QGIS's
    # world map, breaking joins and relations on fid), and the layer was named after the
    # output file; ogr2ogr keeps both
    import pandas as pd

    from curvesmith.internals import geo_io

    if chunk is not None:  # written in slices: the later ones are appended
        monkeypatch.setattr(geo_io, "WRITE_CHUNK_VERTICES", chunk)
    boxes = [shapely.box(k * 20, 0, k * 20 + 10, 10) for k in range(6)]
    df = gpd.GeoDataFrame({"fid": [2, 4, 5, 6, 9, 10], "a": range(6)}, geometry=boxes, crs=32633)
    src, out = tmp_path / "in.gpkg", tmp_path / "out.gpkg"
    pyogrio.write_dataframe(df, src, layer="parcels", layer_options={"FID": "fid"})
    assert _fids(src) == {"parcels": [2, 4, 5, 6, 9, 10]}
    geo.smooth_file(src, out)
    assert _fids(out) == {"parcels": [2, 4, 5, 6, 9, 10]}
    assert list(geo.read_file(out)["a"]) == list(range(6))
    # a frame of read_file's is a plain frame: combined, sorted, filtered (its attrs held
    # the ids once, and pandas' concat compared them: "truth value of an array is
    # ambiguous"); written, its rows are not paired with ids of other rows
    back = geo.read_file(src)
    assert "fid" not in back.columns and list(back["a"]) == list(range(6))
    both = pd.concat([back.iloc[:3], back.iloc[3:]])
    assert list(both["a"]) == list(range(6))
    geo.write_file(back.sort_values("a", ascending=False), out)
    assert list(_fids(out)) == ["parcels"]  # the layer's name
    assert list(geo.read_file(out)["a"]) == [5, 4, 3, 2, 1, 0]


@pytest.mark.parametrize("how", ["smooth", "batch", "in place"])
def test_cli_keeps_feature_ids(tmp_path, how):
    from click.testing import CliRunner

    from curvesmith.cli import main

    boxes = [shapely.box(k * 20, 0, k * 20 + 10, 10) for k in range(4)]
    df = gpd.GeoDataFrame({"fid": [3, 7, 8, 20], "a": range(4)}, geometry=boxes, crs=32633)
    src = tmp_path / "in.gpkg"
    pyogrio.write_dataframe(df, src, layer="polys", layer_options={"FID": "fid"})
    pyogrio.write_dataframe(df.iloc[:1], src, layer="other", append=False)
    out = src if how == "in place" else tmp_path / "out.gpkg"
    args = {
        "smooth": ["smooth", str(src), "-o", str(out), "--layer", "polys"],
        "batch": ["batch", "smooth", str(src), "-o", str(out), "--layer", "polys",
                  "--no-progress", "--workers", "1"],
        "in place": ["smooth", str(src), "-o", str(out), "--layer", "polys"],
    }[how]  # fmt: skip
    res = CliRunner().invoke(main, args)
    assert res.exit_code == 0, res.output
    assert _fids(out)["polys"] == [3, 7, 8, 20]


@pytest.mark.parametrize("chunk", [None, 37])
def test_new_geopackages_are_version_1_2(tmp_path, monkeypatch, chunk):
    """GDAL 3.6 (Debian's, QGIS 3.22-3.28) warns about GeoPackage 1.4; every GDAL reads 1.2."""
    import sqlite3

    from curvesmith.internals import geo_io

    if chunk is not None:  # written in slices: the first creates the file
        monkeypatch.setattr(geo_io, "WRITE_CHUNK_VERTICES", chunk)
    df = geo.us_counties(states=["44"]).to_crs("EPSG:5070")
    path = tmp_path / "ri.gpkg"
    geo.write_file(df, path)
    version = sqlite3.connect(path).execute("pragma user_version").fetchone()[0]
    assert version == 10200
    out = tmp_path / "smoothed.gpkg"
    geo.smooth_file(path, out, iterations=1)
    assert sqlite3.connect(out).execute("pragma user_version").fetchone()[0] == 10200
    assert len(geo.read_file(out)) == len(df)
