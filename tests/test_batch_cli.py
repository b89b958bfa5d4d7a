"""``curvesmith batch smooth`` through click."""

import contextlib
import json

import distributed
import numpy as np
import pytest
import shapely
from click.testing import CliRunner

from curvesmith import geo
from curvesmith.cli.geo import batch_group


def test_batch_smooth_command_on_scheduler(tmp_path):
    df = geo.us_counties(states=["19"]).to_crs("EPSG:5070")  # Iowa, 99 counties
    src = tmp_path / "ia.gpkg"
    geo.write_file(df, src)
    out = tmp_path / "ia_out.fgb"
    with distributed.LocalCluster(
        host="127.0.0.1", n_workers=2, processes=True, dashboard_address=":0", silence_logs=40
    ) as cluster:
        result = CliRunner().invoke(
            batch_group,
            [
                "smooth",
                str(src),
                "-o",
                str(out),
                "--scheduler",
                cluster.scheduler_address,
                "--partition-size",
                "30",
                "--coverage",
                "--no-progress",
                "--iterations",
                "2",
            ],
        )
    assert result.exit_code == 0, result.output
    assert "99 features in" in result.output and "0 failed" in result.output
    assert json.loads((tmp_path / "ia_out.fgb.errors.json").read_text()) == []
    back = geo.read_file(out)
    assert list(back["GEOID"]) == list(df["GEOID"])
    assert shapely.coverage_is_valid(back.geometry.values)
    np.testing.assert_allclose(back.area.values, df.area.values, rtol=1e-9)


def test_batch_smooth_usage_errors(tmp_path):
    result = CliRunner().invoke(batch_group, ["smooth", "in.gpkg"])
    assert result.exit_code == 2 and "Missing option '-o'" in result.output
    result = CliRunner().invoke(
        batch_group, ["smooth", "in.gpkg", "-o", "x.gpkg", "--method", "spline"]
    )
    assert result.exit_code == 2


def test_batch_smooth_exits_1_when_features_failed_and_names_file_indices(tmp_path):
    df = geo.us_counties(states=["44"]).to_crs("EPSG:5070")  # Rhode Island, 5 counties
    bowtie = shapely.Polygon([(0, 0), (2e3, 2e3), (2e3, 0), (0, 2e3)])
    df.loc[len(df) - 1, "geometry"] = bowtie  # the file's last feature is invalid
    src = tmp_path / "ri.gpkg"
    geo.write_file(df, src)
    out = tmp_path / "o.gpkg"
    from curvesmith.cli import main

    result = CliRunner().invoke(
        main,
        ["batch", "smooth", str(src), "-o", str(out), "--workers", "1", "--partition-size", "2",
         "--no-progress"],
    )  # fmt: skip
    assert result.exit_code == 1, result.output
    last = len(df) - 1
    assert f"1 of {len(df)} features of {src} failed" in result.output
    assert f"first: feature {last}: CurveError: feature {last} is not valid" in result.output
    errors = json.loads((tmp_path / "o.gpkg.errors.json").read_text())
    assert [e["index"] for e in errors] == [last] and f"feature {last}" in errors[0]["reason"]
    back = geo.read_file(out)  # written, failing feature unchanged
    got = shapely.get_coordinates(back.geometry[last])
    np.testing.assert_array_equal(got, shapely.get_coordinates(bowtie))


def test_an_errors_report_that_cannot_be_written_fails_before_the_work(tmp_path):
    # the report was written last: the output was already there when --errors failed
    src = tmp_path / "ri.gpkg"
    geo.write_file(geo.us_counties(states=["44"]).to_crs("EPSG:32619"), src)
    from curvesmith.cli import main

    out = tmp_path / "out.gpkg"
    for errors in (tmp_path / "missing" / "e.json", tmp_path):
        res = CliRunner().invoke(
            main,
            [
                "batch",
                "smooth",
                str(src),
                "-o",
                str(out),
                "--errors",
                str(errors),
                "--workers",
                "1",
            ],
        )
        assert res.exit_code == 1, res.output
        assert str(errors) in res.output and "Traceback" not in res.output
        assert not out.exists()


def test_points_pass_through_as_in_smooth(tmp_path):
    # batch reported "feature 1 is a Point: only lines and polygons can be smoothed" and
    # exited 1, where smooth writes the point through
    from curvesmith.cli import main

    df = geo.us_counties(states=["44"]).to_crs("EPSG:32619").iloc[:3].copy()
    df.loc[1, "geometry"] = shapely.Point(300_000, 4_600_000)
    df.loc[2, "geometry"] = shapely.MultiPoint([(1, 2), (3, 4)])
    src = tmp_path / "mixed.gpkg"
    geo.write_file(df, src)
    outs = [tmp_path / "batch.gpkg", tmp_path / "plain.gpkg"]
    for cmd, out in ((["batch", "smooth", "--workers", "1"], outs[0]), (["smooth"], outs[1])):
        res = CliRunner().invoke(main, [*cmd, str(src), "-o", str(out)])
        assert res.exit_code == 0, res.output
    a, b = (geo.read_file(o).geometry.values for o in outs)
    assert shapely.equals_exact(a, b, 0.0).all()
    assert a[1].equals(df.geometry.values[1]) and a[2].equals(df.geometry.values[2])
    assert shapely.get_num_coordinates(a[0]) > 2 * shapely.get_num_coordinates(df.geometry[0])


def test_an_error_during_the_progress_bar_is_a_line_of_its_own():
    # the error (and the watchdog's "stopped by SIGTERM") was glued to the bar's last frame
    import click

    from curvesmith.errors import CurveError
    from curvesmith.internals import BatchProgressBar, cli_group

    @click.group(cls=cli_group)
    def tool():
        pass

    @tool.command()
    def run():
        bar = BatchProgressBar(4)
        bar.step()
        raise CurveError("feature 3 failed")

    res = CliRunner().invoke(tool, ["run"])
    assert res.exit_code == 1
    *frames, last = res.stderr.split("\n")[:-1]
    assert frames[-1].endswith("25% Completed |  0.0s") and last == "Error: feature 3 failed"
    assert not BatchProgressBar.line_open


def test_geographic_warning_and_summary_as_in_smooth(tmp_path):
    # batch said "use --equal-area" where smooth says what --equal-area does, and
    # "0 task(s)" when --coverage with --max-shift ran on the client
    from curvesmith.cli import main

    src = tmp_path / "ri.gpkg"
    geo.write_file(geo.us_counties(states=["44"]), src)  # NAD83 degrees
    res = CliRunner().invoke(main, ["smooth", str(src), "-o", str(tmp_path / "a.gpkg")])
    warning = res.stderr.splitlines()[0]
    assert warning.startswith("Warning:") and "--equal-area smooths in" in warning
    res = CliRunner().invoke(
        main,
        ["batch", "smooth", str(src), "-o", str(tmp_path / "b.gpkg"), "--workers", "1",
         "--no-progress", "--coverage", "--max-shift", "0.001"],
    )  # fmt: skip
    assert res.exit_code == 0, res.output
    lines = res.stderr.splitlines()
    assert lines[0] == warning
    assert lines[1].startswith(
        "5 features on the client (--coverage with --keep-angle, --max-shift or --min-segment)"
    )
    # a coverage in degrees is smoothed on the client too (its +-180 and poles kept), and
    # its validity said as smooth says it
    args = ["batch", "smooth", str(src), "-o", str(tmp_path / "c.gpkg"), "--coverage"]
    res = CliRunner().invoke(main, [*args, "--workers", "1", "--no-progress"])
    assert res.exit_code == 0, res.output
    lines = res.stderr.splitlines()
    assert lines[1].startswith(
        "5 features on the client (--coverage in longitude/latitude: ±180° and the poles kept)"
    )
    assert lines[1].endswith("; coverage valid")


def _footprint_layer(path, n, seed=0):
    """`n` rotated rectangles with a notch (7 vertices) on a 50 m grid, in metres."""
    import geopandas

    rng = np.random.default_rng(seed)
    base = np.array([[0, 0], [12, 0], [12, 8], [7, 8], [7, 5], [0, 5], [0, 0]], float)
    th = rng.uniform(0, np.pi, n)
    rot = np.stack([np.c_[np.cos(th), -np.sin(th)], np.c_[np.sin(th), np.cos(th)]], axis=1)
    rings = np.einsum("nij,kj->nki", rot, base)
    k = np.arange(n)
    rings += np.c_[(k % 1000) * 50.0, (k // 1000) * 50.0][:, None, :] + 5e5
    polys = shapely.polygons(rings)
    geo.write_file(geopandas.GeoDataFrame(geometry=polys, crs="EPSG:32633"), path)


def _workers_importing(me) -> bool:
    """Whether psutil process `me` has a spawned child (a worker, not the resource tracker)
    that has run Python for a while: 0.2 s of CPU, importing distributed and curvesmith."""
    import psutil

    for child in me.children():
        with contextlib.suppress(psutil.Error):  # a child that ends meanwhile
            if "spawn_main" in " ".join(child.cmdline()):
                cpu = child.cpu_times()
                return cpu.user + cpu.system > 0.2
    return False


def _ignores_sigint(pid: int) -> bool:
    """Whether process `pid` ignores SIGINT (batch does while it spawns its workers)."""
    import signal

    with open(f"/proc/{pid}/status") as f:
        (mask,) = [ln.split()[1] for ln in f if ln.startswith("SigIgn:")]
    return bool(int(mask, 16) >> (signal.SIGINT - 1) & 1)


@pytest.mark.slow
@pytest.mark.parametrize("when", ["workers starting", "tasks running"])
def test_ctrl_c_is_one_line_and_leaves_nothing(tmp_path, when):
    # Ctrl-C at a terminal sends SIGINT to the whole process group, the Dask workers too:
    # each printed a traceback (several while still starting), and the client's teardown
    # logged tornado's and the scheduler's errors. One line now, and no output.
    import os
    import signal
    import subprocess
    import sys
    import threading
    import time

    import psutil

    src, out = tmp_path / "fp.gpkg", tmp_path / "out.gpkg"
    _footprint_layer(src, 300_000)
    cmd = [sys.executable, "-m", "curvesmith.cli", "batch", "smooth", str(src), "-o", str(out)]
    proc = subprocess.Popen(
        [*cmd, "--iterations", "3", "--workers", "2", "--partition-size", "5000"],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        start_new_session=True,  # its own process group, as a terminal's job
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
    )
    err: list[bytes] = []
    reader = threading.Thread(target=lambda: err.extend(iter(lambda: proc.stderr.read(1), b"")))
    reader.start()
    try:
        me, deadline = psutil.Process(proc.pid), time.monotonic() + 240
        while proc.poll() is None and time.monotonic() < deadline:
            if when == "tasks running":
                ready = b"% Completed" in b"".join(err) and b"100%" not in b"".join(err)
            else:  # the workers exist and still import; the client hears SIGINT again
                ready = _workers_importing(me) and not _ignores_sigint(proc.pid)
            if ready:
                break
            time.sleep(0.002)
        assert proc.poll() is None, b"".join(err)
        os.killpg(proc.pid, signal.SIGINT)
        proc.wait(timeout=60)
        reader.join(timeout=10)
    finally:
        with contextlib.suppress(ProcessLookupError):
            os.killpg(proc.pid, signal.SIGKILL)
    lines = b"".join(err).decode().replace("\r", "\n").splitlines()
    said = [ln for ln in lines if ln.strip() and "Completed |" not in ln]
    assert proc.returncode == 130, (proc.returncode, lines)  # 128 + SIGINT, either way
    assert said in (["Aborted!"], ["Error: stopped by SIGINT"]), lines
    assert sorted(os.listdir(tmp_path)) == ["fp.gpkg"]  # no output, no temporary file


def test_pieces_smoothed_less_are_counted_as_in_smooth(tmp_path):
    # batch's summary left out the pieces smoothed less to stay valid, which smooth counts
    from curvesmith.cli import main

    df = geo.us_counties().to_crs("EPSG:5070")
    src = tmp_path / "c.gpkg"
    geo.write_file(df.iloc[[0, 361, 642, 1092, 1]], src)  # some of them need it
    res = CliRunner().invoke(main, ["smooth", str(src), "-o", str(tmp_path / "a.gpkg")])
    assert res.exit_code == 0, res.output
    (said,) = [p for p in res.stderr.strip().split("; ") if "smoothed less" in p]
    n = int(said.split()[0])
    assert n >= 1 and said == f"{n} piece(s) smoothed less to stay valid"
    res = CliRunner().invoke(
        main,
        ["batch", "smooth", str(src), "-o", str(tmp_path / "b.gpkg"), "--workers", "1",
         "--no-progress"],
    )  # fmt: skip
    assert res.exit_code == 0, res.output
    assert res.stderr.strip().endswith(f"; {said}")


def test_network_summary_and_warning_as_in_smooth(tmp_path):
    # batch --network printed its generic line only, and smooth --network its own words
    # for the geographic-CRS warning
    from curvesmith.cli import main

    df = geo.us_counties(states=["44"])  # NAD83 degrees
    src = tmp_path / "ri_lines.gpkg"
    geo.write_file(df.assign(geometry=df.boundary), src)
    one = CliRunner().invoke(
        main, ["smooth", str(src), "-o", str(tmp_path / "a.gpkg"), "--network"]
    )
    args = ["batch", "smooth", str(src), "-o", str(tmp_path / "b.gpkg"), "--network"]
    many = CliRunner().invoke(main, [*args, "--workers", "1", "--no-progress"])
    assert one.exit_code == many.exit_code == 0, (one.output, many.output)
    (warning, said), (warning_b, summary) = one.stderr.splitlines(), many.stderr.splitlines()
    assert warning == warning_b and "--equal-area smooths in an equal-area projection" in warning
    network = said.split(", ", 1)[1].split("; ")[0]
    assert network.endswith("fixed nodes)") and " lines smoothed as one network (" in network
    assert f"; {network}" in summary


def test_snap_area_change_is_reported_as_in_smooth(tmp_path):
    # `--coverage --snap` said nothing of the areas the snapping changed (smooth neither)
    import geopandas as gpd

    from curvesmith.cli import main

    left = shapely.Polygon([(0, 0), (100, 0), (120, 50), (100, 100), (0, 100)])
    right = shapely.Polygon([(100.4, 0), (200, 0), (200, 100), (100.4, 100), (120.4, 50)])
    src = tmp_path / "pair.gpkg"
    gpd.GeoDataFrame(geometry=[left, right], crs="EPSG:32633").to_file(src)
    snap = ["--coverage", "--snap", "1"]
    res = CliRunner().invoke(main, ["smooth", str(src), "-o", str(tmp_path / "a.gpkg"), *snap])
    assert res.exit_code == 0, res.output
    (said,) = [p for p in res.stderr.strip().split("; ") if p.startswith("--snap changed")]
    res = CliRunner().invoke(
        main,
        ["batch", "smooth", str(src), "-o", str(tmp_path / "b.gpkg"), "--workers", "1",
         "--no-progress", *snap],
    )  # fmt: skip
    assert res.exit_code == 0, res.output
    assert f"; {said}; coverage valid" in res.stderr
