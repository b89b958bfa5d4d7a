"""No silent data loss: atomic writes, verified outputs, damaged inputs refused (issue 13.5).

Every writer (CSV, GeoJSON, SVG, and the GIS formats through pyogrio) writes to a temporary
file in the output's folder and renames it into place only after the write was verified, so a
failed write (a full disk) leaves the previous output exactly as it was and no partial file.
"""

from __future__ import annotations

import errno
import json
import os
import shutil
import subprocess
from pathlib import Path

import geopandas as gpd
import numpy as np
import pyogrio
import pytest
import shapely
from click.testing import CliRunner

from curvesmith import cca, geo
from curvesmith import io as cio
from curvesmith.cli import main
from curvesmith.errors import CurveError, CurveFormatError
from curvesmith.internals import Utf8Sink
from oracles import exact_area

FIXTURES = Path(pyogrio.__file__).parent / "tests" / "fixtures"
NATURAL_EARTH = FIXTURES / "naturalearth_lowres" / "naturalearth_lowres.shp"


def _ring(n=400, r=10.0, seed=0):
    rng = np.random.default_rng(seed)
    t = np.linspace(0, 2 * np.pi, n, endpoint=False)
    rr = r * (1 + 0.05 * rng.standard_normal(n))
    return np.column_stack([rr * np.cos(t), rr * np.sin(t)])


def _curves():
    return [cio.Curve(_ring(seed=k) + 30 * k, closed=True, kind="Polygon", feature=k)
            for k in range(3)]  # fmt: skip


def _listing(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.iterdir())


def _one_line_error(res, *fragments):
    assert res.exit_code == 1, res.output
    lines = [ln for ln in res.output.splitlines() if ln.strip()]
    assert len(lines) >= 1 and lines[-1].startswith("Error: "), res.output
    assert "Traceback" not in res.output
    for f in fragments:
        assert f in lines[-1], (f, lines[-1])


@pytest.fixture
def enospc_after(monkeypatch):
    """Make text writes fail with ENOSPC after `limit` bytes (a disk that fills up)."""

    def arm(limit: int):
        original = Utf8Sink.write

        def write(self, text):
            if self.nbytes + len(text.encode()) > limit:
                self.raw.write(text.encode()[: max(0, limit - self.nbytes)])
                raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
            return original(self, text)

        monkeypatch.setattr(Utf8Sink, "write", write)

    return arm


@pytest.mark.parametrize("suffix", [".csv", ".geojson", ".svg"])
def test_text_writer_failing_mid_write_keeps_the_previous_output(tmp_path, enospc_after, suffix):
    out = tmp_path / f"out{suffix}"
    cio.write_curves(_curves()[:1], out)
    good = out.read_bytes()
    enospc_after(4096)
    with pytest.raises(CurveFormatError, match=r"out\..*: cannot write the file: No space left"):
        cio.write_curves(_curves(), out)
    assert out.read_bytes() == good  # not truncated, not deleted
    assert _listing(tmp_path) == [out.name]  # no partial or temporary file left


def test_text_writer_failing_on_a_new_file_leaves_nothing(tmp_path, enospc_after):
    enospc_after(100)
    with pytest.raises(CurveFormatError, match="No space left on device"):
        cio.write_curves(_curves(), tmp_path / "new.csv")
    assert _listing(tmp_path) == []


def test_cli_full_disk_is_one_line_exit_1_and_keeps_the_output(tmp_path, enospc_after):
    src = tmp_path / "in.csv"
    cio.write_curves(_curves(), src)
    out = tmp_path / "out.geojson"
    out.write_text("previous good output\n")
    enospc_after(2000)
    res = CliRunner().invoke(main, ["smooth", str(src), "-o", str(out)])
    _one_line_error(res, str(out), "No space left on device")
    assert out.read_text() == "previous good output\n"
    assert _listing(tmp_path) == ["in.csv", "out.geojson"]


def test_writer_exception_after_validation_leaves_no_partial_file(tmp_path):
    bad = cio.Curve(_ring(), closed=True, kind="Polygon", properties={"x": float("nan")})
    out = tmp_path / "o.geojson"
    with pytest.raises(CurveFormatError, match="JSON"):
        cio.write_curves([bad], out)
    assert _listing(tmp_path) == []


def test_write_to_a_stream_is_unchanged():
    import io

    buf = io.StringIO()
    cio.write_curves(_curves(), buf, format="csv")
    back = cio.read_curves(io.StringIO(buf.getvalue()), format="csv")
    assert all(np.array_equal(a.points, b.points) for a, b in zip(back, _curves(), strict=True))


# ----------------------------------------------------------------------------------------------
# GIS writers


def _frame():
    polys = [shapely.Polygon(_ring(seed=k) * 1000 + [5e5 + 4e4 * k, 4e6]) for k in range(4)]
    return gpd.GeoDataFrame({"name": list("abcd")}, geometry=polys, crs="EPSG:32633")


@pytest.mark.parametrize("suffix", [".gpkg", ".shp", ".fgb", ".geojson"])
def test_gis_writer_failing_mid_write_keeps_the_previous_output(tmp_path, monkeypatch, suffix):
    out = tmp_path / f"out{suffix}"
    geo.write_file(_frame().iloc[:1], out)
    before = {p.name: p.read_bytes() for p in tmp_path.iterdir()}
    real = pyogrio.write_dataframe

    def fail_midway(df, path, **kwargs):
        real(df.iloc[:2], path, **kwargs)  # part of the data reached the disk, then:
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(pyogrio, "write_dataframe", fail_midway)
    with pytest.raises(CurveFormatError, match="No space left on device"):
        geo.write_file(_frame(), out)
    assert {p.name: p.read_bytes() for p in tmp_path.iterdir()} == before


@pytest.mark.parametrize("suffix", [".fgb", ".gpkg"])
def test_gis_writer_reporting_success_with_a_damaged_file_is_caught(tmp_path, monkeypatch, suffix):
    # FlatGeobuf on a full disk: GDAL reported success and left an unreadable file
    out = tmp_path / f"out{suffix}"
    real = pyogrio.write_dataframe

    def truncating(df, path, **kwargs):
        real(df, path, **kwargs)
        os.truncate(path, os.path.getsize(path) // 2)

    monkeypatch.setattr(pyogrio, "write_dataframe", truncating)
    with pytest.raises(CurveFormatError, match="cannot write .*disk may be full"):
        geo.write_file(_frame(), out)
    assert _listing(tmp_path) == []


def test_geopackage_with_a_truncated_geometry_blob_is_caught(tmp_path, monkeypatch):
    # GDAL reports success; one feature's blob lost its tail (WKB header intact): the file
    # reads back with a NULL geometry there, which the read-back check counts
    import sqlite3

    out = tmp_path / "out.gpkg"
    real = pyogrio.write_dataframe

    def damaging(df, path, **kwargs):
        real(df, path, **kwargs)
        con = sqlite3.connect(path)
        for fn in ("ST_IsEmpty", "ST_MinX", "ST_MaxX", "ST_MinY", "ST_MaxY"):  # R-tree triggers
            con.create_function(fn, 1, lambda blob: 0)
        table = con.execute("SELECT table_name FROM gpkg_contents").fetchone()[0]
        fid, blob = con.execute(f'SELECT fid, geom FROM "{table}" LIMIT 1 OFFSET 1').fetchone()
        con.execute(f'UPDATE "{table}" SET geom = ? WHERE fid = ?', (blob[: len(blob) - 9], fid))
        con.commit()
        con.close()

    monkeypatch.setattr(pyogrio, "write_dataframe", damaging)
    with pytest.raises(CurveFormatError, match=r"reads back as 4 features \(1 without geometry\)"):
        geo.write_file(_frame(), out)
    assert _listing(tmp_path) == []


@pytest.mark.filterwarnings("ignore:'crs' was not provided:UserWarning")
def test_shapefile_output_replaces_stale_sidecars(tmp_path):
    out = tmp_path / "o.shp"
    geo.write_file(_frame(), out)
    assert (tmp_path / "o.prj").exists()
    geo.write_file(_frame().set_crs(None, allow_override=True), out)
    assert not (tmp_path / "o.prj").exists()  # an old .prj must not describe the new file
    assert geo.read_file(out).crs is None and len(geo.read_file(out)) == 4


def test_existing_geopackage_is_replaced_not_given_another_layer(tmp_path):
    out = tmp_path / "o.gpkg"
    geo.write_file(_frame(), out, layer="old")
    geo.write_file(_frame().iloc[:2], out)
    assert [str(x) for x in pyogrio.list_layers(out)[:, 0]] == ["o"]
    # a named layer replaces that layer and keeps the others
    geo.write_file(_frame(), out, layer="extra")
    geo.write_file(_frame().iloc[:1], out, layer="extra")
    layers = {str(n) for n in pyogrio.list_layers(out)[:, 0]}
    assert layers == {"o", "extra"} and len(geo.read_file(out, layer="extra")) == 1


def test_a_geopackage_of_several_layers_is_not_replaced_by_one(tmp_path):
    # `smooth lakes.geojson -o project.gpkg` deleted every other layer of project.gpkg
    # without a word (a copy of QGIS's world_map.gpkg lost its four)
    out = tmp_path / "project.gpkg"
    geo.write_file(_frame(), out, layer="roads")
    geo.write_file(_frame(), out, layer="lakes")
    before = out.read_bytes()
    with pytest.raises(CurveFormatError, match=r"holds 2 layers \(roads, lakes\), which writ"):
        geo.write_file(_frame().iloc[:2], out)
    assert out.read_bytes() == before
    src = tmp_path / "zones.geojson"
    geo.write_file(_frame(), src)
    for cmd in (["smooth"], ["batch", "smooth", "--workers", "1", "--no-progress"]):
        res = CliRunner().invoke(main, [*cmd, str(src), "-o", str(out)])
        assert res.exit_code == 1 and res.output.count("\n") == 1, res.output
        assert res.output.startswith(f"Error: {str(out)!r} holds 2 layers (roads, lakes)")
        assert out.read_bytes() == before and _listing(tmp_path) == [
            "project.gpkg",
            "zones.geojson",
        ]
    # a layer of its own, smoothed in place, replaces that layer and keeps the other
    res = CliRunner().invoke(main, ["smooth", str(out), "--layer", "lakes", "-o", str(out)])
    assert res.exit_code == 0, res.output
    assert sorted(str(n) for n in pyogrio.list_layers(out)[:, 0]) == ["lakes", "roads"]
    assert len(geo.read_file(out, layer="roads")) == len(_frame())


# ----------------------------------------------------------------------------------------------
# a real full disk (tmpfs)


@pytest.mark.parametrize("suffix", [".csv", ".geojson", ".svg", ".fgb", ".gpkg", ".shp"])
def test_real_full_disk_keeps_the_previous_output(tiny_disk, suffix):
    out = tiny_disk / f"out{suffix}"
    small = _frame().iloc[:1]
    big = gpd.GeoDataFrame(
        {"name": ["big"]}, geometry=[shapely.Polygon(_ring(n=40000) * 1000)], crs="EPSG:32633"
    )
    if suffix in (".csv", ".svg"):
        cio.write_curves(_curves()[:1], out)
        big_curves = [cio.Curve(_ring(n=40000), closed=True, kind="Polygon")]
        with pytest.raises(CurveFormatError, match="No space left on device"):
            cio.write_curves(big_curves, out)
    else:
        geo.write_file(small, out)
        with pytest.raises(CurveFormatError, match=f"cannot write '{out}'"):
            geo.write_file(big, out)
    before = {p.name for p in tiny_disk.iterdir()}
    assert all(not n.endswith(".tmp") for n in before), before
    if suffix in (".csv", ".svg"):
        assert len(cio.read_curves(out)[0].points) == 400
    else:
        back = geo.read_file(out)
        a, b = shapely.normalize(back.geometry[0]), shapely.normalize(small.geometry[0])
        assert len(back) == 1 and shapely.equals_exact(a, b, 0)


# ----------------------------------------------------------------------------------------------
# damaged inputs


@pytest.fixture
def natural_earth(tmp_path):
    for part in NATURAL_EARTH.parent.iterdir():
        shutil.copy(part, tmp_path / ("ne" + part.suffix))
    return tmp_path / "ne.shp"


@pytest.mark.parametrize("part", [".shp", ".shx", ".dbf"])
def test_truncated_shapefile_is_an_error_not_null_geometries(natural_earth, part):
    cut = natural_earth.with_suffix(part)
    os.truncate(cut, int(cut.stat().st_size * 0.4))
    out = natural_earth.parent / "o.gpkg"
    res = CliRunner().invoke(main, ["smooth", str(natural_earth), "-o", str(out)])
    _one_line_error(res, f"ne{part} is truncated", "damaged")
    assert not out.exists()
    with pytest.raises(CurveFormatError, match="truncated"):
        geo.smooth_file(natural_earth, out)


def test_truncated_geopackage_is_a_one_line_error(tmp_path):
    src = tmp_path / "ne.gpkg"
    geo.write_file(geo.read_file(NATURAL_EARTH), src)
    data = src.read_bytes()
    src.write_bytes(data[: len(data) * 6 // 10])
    out = tmp_path / "o.gpkg"
    res = CliRunner().invoke(main, ["smooth", str(src), "-o", str(out)])
    _one_line_error(res, "cannot read", "ne.gpkg")
    assert not out.exists()


def test_null_geometries_need_allow_null_and_are_counted(tmp_path):
    df = _frame()
    df.loc[2, "geometry"] = None
    df.loc[3, "geometry"] = shapely.Polygon()
    src = tmp_path / "gaps.gpkg"
    geo.write_file(df, src)
    out = tmp_path / "o.gpkg"
    res = CliRunner().invoke(main, ["smooth", str(src), "-o", str(out)])
    _one_line_error(res, "1 of 4 features have no geometry", "feature 2", "--allow-null")
    assert not out.exists()
    res = CliRunner().invoke(main, ["smooth", str(src), "-o", str(out), "--allow-null"])
    assert res.exit_code == 0, res.output
    assert "2 of 4 feature(s) smoothed; 1 without geometry (NULL) and 1 empty" in res.output
    back = geo.read_file(out)
    assert back.geometry.isna().tolist() == [False, False, True, False]
    assert back.geometry.is_empty.tolist()[3]
    np.testing.assert_allclose(back.area[:2], df.area[:2], rtol=1e-12)
    report = geo.smooth_file(src, out, allow_null=True)
    assert (report.n_null, report.n_empty, report.n_features) == (1, 1, 4)
    with pytest.raises(CurveError, match="allow_null=True"):
        geo.smooth_file(src, out)


def test_batch_refuses_null_geometries_and_non_gis_inputs(tmp_path):
    df = _frame()
    df.loc[1, "geometry"] = None
    src = tmp_path / "gaps.gpkg"
    geo.write_file(df, src)
    res = CliRunner().invoke(main, ["batch", "smooth", str(src), "-o", str(tmp_path / "o.gpkg")])
    _one_line_error(res, "1 of 4 features have no geometry")
    csv = tmp_path / "a.csv"
    csv.write_text("x,y\n0,0\n1,0\n1,1\n")
    res = CliRunner().invoke(main, ["batch", "smooth", str(csv), "-o", str(tmp_path / "o.gpkg")])
    assert res.exit_code == 2 and "Traceback" not in res.output
    assert "batch smooth reads GIS files" in res.output


# ----------------------------------------------------------------------------------------------
# in-place runs


@pytest.mark.parametrize("suffix", [".csv", ".geojson", ".svg"])
def test_in_place_smoothing_of_curve_files(tmp_path, suffix):
    path = tmp_path / f"rings{suffix}"
    cio.write_curves(_curves(), path)
    before = cio.read_curves(path)
    res = CliRunner().invoke(main, ["smooth", str(path), "-o", str(path)])
    assert res.exit_code == 0, res.output
    after = cio.read_curves(path)
    assert [len(c.points) for c in after] == [3 * len(c.points) for c in before]
    for a, b in zip(before, after, strict=True):
        assert exact_area(b.points) == pytest.approx(exact_area(a.points), rel=1e-12)
    assert _listing(tmp_path) == [path.name]


@pytest.mark.parametrize("suffix", [".gpkg", ".shp", ".fgb"])
def test_in_place_smoothing_of_gis_files(tmp_path, suffix):
    path = tmp_path / f"zones{suffix}"
    df = _frame()
    geo.write_file(df, path)
    names = _listing(tmp_path)
    res = CliRunner().invoke(main, ["smooth", str(path), "-o", str(path)])
    assert res.exit_code == 0, res.output
    back = geo.read_file(path)
    assert list(back["name"]) == list("abcd")
    assert shapely.get_num_coordinates(back.geometry.values).sum() > 2.5 * 4 * 400
    np.testing.assert_allclose(back.area, df.area, rtol=1e-9)
    assert _listing(tmp_path) == names
    if suffix == ".gpkg":
        assert len(pyogrio.list_layers(path)) == 1  # replaced, not a second layer


# ----------------------------------------------------------------------------------------------
# small traps (issue 13.7)


def test_measure_reads_gis_files(tmp_path):
    df = _frame()
    src = tmp_path / "zones.gpkg"
    geo.write_file(df, src)
    res = CliRunner().invoke(main, ["measure", str(src), "--json"])
    assert res.exit_code == 0, res.output
    rows = json.loads(res.output)["curves"]
    assert [r["feature"] for r in rows] == [0, 1, 2, 3]
    areas = [abs(r["signed_area"]) for r in rows]
    np.testing.assert_allclose(areas, df.area.values, rtol=1e-12)


def test_gis_input_to_stdout_as_geojson(tmp_path):
    src = tmp_path / "zones.gpkg"
    geo.write_file(_frame(), src)
    res = CliRunner().invoke(main, ["smooth", str(src), "-o", "-", "--format", "geojson"])
    assert res.exit_code == 0, res.output
    text = res.output[res.output.index("{") : res.output.rindex("}") + 1]
    assert len(json.loads(text)["features"]) == 4
    res = CliRunner().invoke(main, ["smooth", str(src), "-o", "-"])
    assert res.exit_code == 2 and "--format geojson" in res.output


def test_output_suffix_and_folder_checked_before_the_run(tmp_path, monkeypatch):
    src = tmp_path / "zones.gpkg"
    geo.write_file(_frame(), src)
    called = []
    monkeypatch.setattr(geo, "smooth_file", lambda *a, **k: called.append(1))
    res = CliRunner().invoke(main, ["smooth", str(src), "-o", str(tmp_path / "o.csv")])
    assert res.exit_code == 2 and "a GIS input is written as" in res.output
    res = CliRunner().invoke(main, ["smooth", str(src), "-o", str(tmp_path / "no" / "o.gpkg")])
    _one_line_error(res, "does not exist")
    # a file where the folder should be was said not to exist
    res = CliRunner().invoke(main, ["smooth", str(src), "-o", str(src / "o.gpkg")])
    _one_line_error(res, f"the directory {str(src)!r} is a file, not a directory")
    assert called == []


def test_geojson_null_and_point_features_pass_through(tmp_path):
    closed = [*_ring(60).tolist(), _ring(60)[0].tolist()]
    feats = [
        {"type": "Feature", "properties": {"n": 0}, "geometry": None},
        {"type": "Feature", "properties": {"n": 1},
         "geometry": {"type": "Polygon", "coordinates": [closed]}},
        {"type": "Feature", "properties": {"n": 2},
         "geometry": {"type": "Point", "coordinates": [3.0, 4.0]}},
    ]  # fmt: skip
    crs = {"type": "name", "properties": {"name": "urn:ogc:def:crs:EPSG::2056"}}
    src = tmp_path / "mixed.geojson"
    src.write_text(json.dumps({"type": "FeatureCollection", "crs": crs, "features": feats}))
    with (
        pytest.warns(UserWarning, match="'crs' member .* is not kept"),
        pytest.raises(CurveFormatError, match="feature 0: the geometry is null"),
    ):
        cio.read_geojson(src)  # the API's default stays strict
    out = tmp_path / "o.geojson"
    res = CliRunner().invoke(main, ["smooth", str(src), "-o", str(out)])
    assert res.exit_code == 0, res.output
    assert (
        "2 feature(s) without a curve geometry (NULL, empty, Point, MultiPoint) passed through"
        in (res.output)
    )
    doc = json.loads(out.read_text())
    assert doc["crs"] == crs
    assert [f["properties"]["n"] for f in doc["features"]] == [0, 1, 2]
    assert doc["features"][0] == feats[0] and doc["features"][2] == feats[2]
    ring = np.array(doc["features"][1]["geometry"]["coordinates"][0])
    assert len(ring) == 3 * 60 + 1


def test_geopackage_table_layers_are_skipped_or_named(tmp_path):
    import pandas as pd

    path = tmp_path / "mixed.gpkg"
    pyogrio.write_dataframe(pd.DataFrame({"x": [1, 2]}), path, layer="a_attrs", driver="GPKG")
    geo.write_file(_frame(), path, layer="z_shapes")
    assert len(geo.read_file(path)) == 4  # the first layer with geometries
    with pytest.raises(CurveFormatError, match="'a_attrs' .* is a table without geometries"):
        geo.read_file(path, layer="a_attrs")
    res = CliRunner().invoke(
        main, ["smooth", str(path), "-o", str(tmp_path / "o.gpkg"), "--layer", "a_attrs"]
    )
    _one_line_error(res, "table without geometries", "['z_shapes']")


@pytest.mark.parametrize(
    "args",
    [
        ["smooth", "{src}", "-o", "{out}", "--coverage", "--snap", "-1"],
        ["batch", "smooth", "{src}", "-o", "{out}", "--partition-size", "0"],
        ["batch", "smooth", "{src}", "-o", "{out}", "--workers", "0"],
    ],
)
def test_bad_option_values_are_usage_errors(tmp_path, args):
    src = tmp_path / "zones.gpkg"
    geo.write_file(_frame(), src)
    argv = [a.format(src=src, out=tmp_path / "o.gpkg") for a in args]
    res = CliRunner().invoke(main, argv)
    assert res.exit_code == 2 and "Invalid value" in res.output
    assert not (tmp_path / "o.gpkg").exists()


def test_map_data_to_svg_is_drawn_upright_and_reads_back(tmp_path):
    # a triangle pointing north (y up): in the SVG, its apex must be drawn at the top
    tri = {"type": "Polygon", "coordinates": [[[0, 0], [10, 0], [0, 20], [0, 0]]]}
    src = tmp_path / "t.geojson"
    src.write_text(json.dumps(tri))
    svg, gj = tmp_path / "t.svg", tmp_path / "t2.geojson"
    for out in (svg, gj):
        res = CliRunner().invoke(main, ["smooth", str(src), "-o", str(out)])
        assert res.exit_code == 0, res.output
    text = svg.read_text()
    assert 'transform="scale(1,-1)"' in text
    _, y0, _, h = map(float, text.split('viewBox="')[1].split('"')[0].split())
    back, ref = cio.read_curves(svg)[0].points, cio.read_curves(gj)[0].points
    np.testing.assert_array_equal(back, ref)  # map coordinates again, bit for bit
    top, bottom = ref[:, 1].max(), ref[:, 1].min()
    assert top > 15.0 and bottom < 1.0  # north is +y again
    # the flipped drawing: the apex (largest map y) at the smallest SVG y, the top of the page
    assert y0 < -top < -bottom < y0 + h and y0 > -top - 0.05 * top
    # curves that come from SVG are not flipped again: the document is written back with
    # its one flipping group, and the smoothed curve reads back in map coordinates, y up
    again = tmp_path / "again.svg"
    res = CliRunner().invoke(main, ["smooth", str(svg), "-o", str(again)])
    assert res.exit_code == 0 and again.read_text().count("scale(1,-1)") == 1
    twice = cca.smooth(ref, closed=True, iterations=1)
    np.testing.assert_array_equal(cio.read_curves(again)[0].points, twice)


@pytest.mark.slow
def test_sigterm_during_a_write_leaves_no_temporary_files(tmp_path):
    # SIGTERM is what QGIS's Cancel and job schedulers send: the run must unwind like an
    # error, so the temporary output beside OUT is removed and the old OUT stays as it was
    import signal
    import sys
    import time

    t = np.linspace(0, 2 * np.pi, 400_000, endpoint=False)
    ring = np.c_[np.cos(t), np.sin(t)] * (1 + 0.05 * np.sin(40 * t))[:, None]
    src = tmp_path / "ring.csv"
    np.savetxt(src, ring, delimiter=",", header="x,y", comments="")
    out = tmp_path / "out.csv"
    out.write_text("x,y\n0,0\n1,0\n0,1\n", encoding="utf-8")
    before = out.read_bytes()
    cmd = [sys.executable, "-m", "curvesmith.cli", "smooth", str(src), "-o", str(out)]
    proc = subprocess.Popen(
        [*cmd, "--iterations", "3"], stdout=subprocess.PIPE, stderr=subprocess.PIPE
    )
    deadline = time.monotonic() + 240
    while not list(tmp_path.glob(".out.csv.*.tmp")) and proc.poll() is None:
        assert time.monotonic() < deadline, "the run never started writing"
        time.sleep(0.05)
    assert proc.poll() is None, proc.communicate()
    proc.send_signal(signal.SIGTERM)
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == 128 + signal.SIGTERM
    assert err.decode().strip().splitlines()[-1] == "Error: stopped by SIGTERM"
    assert not list(tmp_path.glob(".out.csv.*")), "temporary output left behind"
    assert out.read_bytes() == before


def test_geojson_points_inside_geometry_collections_pass_through(tmp_path):
    # a GeometryCollection of a Point and a Polygon (and one of Points only): the points
    # are written back where they were, the polygon is smoothed; before, the file failed
    # with "feature 0, member 0: a Point is not a curve"
    closed = [*_ring(40).tolist(), _ring(40)[0].tolist()]
    point = {"type": "Point", "coordinates": [5.0, 5.0]}
    many = {"type": "MultiPoint", "coordinates": [[1.0, 2.0], [3.0, 4.0]]}
    poly = {"type": "Polygon", "coordinates": [closed]}
    feats = [
        {"type": "Feature", "properties": {"n": 0},
         "geometry": {"type": "GeometryCollection", "geometries": [point, poly, many]}},
        {"type": "Feature", "properties": {"n": 1},
         "geometry": {"type": "GeometryCollection", "geometries": [point, many]}},
        {"type": "Feature", "properties": {"n": 2}, "geometry": poly},
    ]  # fmt: skip
    src = tmp_path / "collections.geojson"
    src.write_text(json.dumps({"type": "FeatureCollection", "features": feats}))
    with pytest.raises(CurveFormatError, match="feature 0, member 0: a Point is not a curve"):
        cio.read_geojson(src)  # the API's default stays strict
    out = tmp_path / "o.geojson"
    res = CliRunner().invoke(main, ["smooth", str(src), "-o", str(out)])
    assert res.exit_code == 0, res.output
    assert "1 feature(s) without a curve geometry" in res.output
    assert "2 Point/MultiPoint member(s) of GeometryCollections passed through" in res.output
    doc = json.loads(out.read_text())
    assert [f["properties"]["n"] for f in doc["features"]] == [0, 1, 2]
    members = doc["features"][0]["geometry"]["geometries"]
    assert [g["type"] for g in members] == ["Point", "Polygon", "MultiPoint"]
    assert members[0] == point and members[2] == many
    assert len(members[1]["coordinates"][0]) == 3 * 40 + 1  # smoothed once
    assert doc["features"][1] == feats[1]
    res = CliRunner().invoke(main, ["smooth", str(src), "-o", str(tmp_path / "o.csv")])
    assert res.exit_code == 0, res.output  # a curve format: said to be left out, not kept
    assert "2 Point/MultiPoint member(s) of GeometryCollections not written: CSV holds" in (
        res.output
    )
    assert "1 feature(s) without a curve geometry (NULL, empty, Point, MultiPoint) not written" in (
        res.output
    )
    kept = cio.read_geojson(src, others="keep")
    assert sorted(kept.members) == [(0, 0), (0, 2)] and sorted(kept.others) == [1]
    assert kept.with_curves(list(kept)).members == kept.members


_SPIN = """
import pathlib, sys
import numba
from curvesmith.cli._stop import install_watchdog
from curvesmith.io._core import in_flight

@numba.njit(nogil=True)
def spin(n):
    s = 0.0
    for i in range(n):
        s += (i % 7) * 1e-9
    return s

spin(10)  # compiled before the signal can come
install_watchdog()
tmp = pathlib.Path(sys.argv[1])
tmp.mkdir()
(tmp / "part.gpkg").write_bytes(b"half")
if sys.argv[2:] == ["bar"]:  # batch's progress bar, its line open
    from curvesmith.batch import _ProgressBar

    _ProgressBar(4)
with in_flight(tmp):
    print("ready", flush=True)
    print(spin(10**12))  # minutes inside one compiled call that releases the GIL
"""


@pytest.mark.parametrize("bar", [False, True])
@pytest.mark.parametrize("name", ["SIGTERM", "SIGINT"])
def test_a_signal_stops_a_long_compiled_call_within_seconds(tmp_path, name, bar):
    # Python runs signal handlers between bytecodes only: before the watchdog, a SIGTERM
    # (a scheduler's cancel, `timeout`) waited for the engine's call over the whole layer
    import signal
    import sys
    import time

    signum = getattr(signal, name)
    tmp = tmp_path / ".out.gpkg.abc.tmp"
    proc = subprocess.Popen(
        [sys.executable, "-c", _SPIN, str(tmp), *(["bar"] if bar else [])],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        assert proc.stdout.readline().strip() == "ready", proc.communicate()
        time.sleep(0.3)  # inside spin()
        t0 = time.monotonic()
        proc.send_signal(signum)
        out, err = proc.communicate(timeout=60)
        took = time.monotonic() - t0
    finally:
        proc.kill()  # never left spinning for minutes when the test fails
    assert proc.returncode == 128 + signum, (out, err)
    assert took < 10, took  # GRACE is 1 s; the call itself would take minutes
    assert not tmp.exists(), "temporary output left behind"
    if bar:  # the watchdog's line is a line of its own, after the bar's
        assert err.lstrip("\n").startswith("[  ") and err.endswith(
            f"Completed |  0.0s\nError: stopped by {name}\n"
        )
    else:
        assert err.strip() == f"Error: stopped by {name}"
    assert out == ""
