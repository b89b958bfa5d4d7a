"""The `curvesmith fair` command (click command object `fair_command`)."""

import json

import numpy as np
import pytest
from click.testing import CliRunner

from curvesmith import data
from curvesmith.cli.fair import fair_command
from curvesmith.elastica import fit, sample


def cli():
    """The curvesmith group with `fair` registered (the lead registers it in cli/__init__)."""
    from curvesmith.cli import main

    if "fair" not in main.commands:
        main.add_command(fair_command)
    return main


def write_csv(path, pts):
    np.savetxt(path, pts, fmt="%.10f", delimiter=",", header="x,y", comments="")


def read_csv(path):
    return np.loadtxt(path, delimiter=",", skiprows=1)


def test_fair_writes_fit_report_and_plot(tmp_path):
    src = data.path("elastica_wave.csv")
    out, rep, png = tmp_path / "out.csv", tmp_path / "r.json", tmp_path / "p.png"
    result = CliRunner().invoke(
        fair_command, [str(src), "-o", str(out), "--report", str(rep), "--plot", str(png)]
    )
    assert result.exit_code == 0, result.output
    assert "fitted 1 curve" in result.output
    fitted = read_csv(out)
    expected = fit(data.load_points("elastica_wave.csv"))
    np.testing.assert_allclose(fitted, expected.points, atol=1e-8)
    report = json.loads(rep.read_text())
    row = report["curves"][0]
    assert row["success"] and row["case"] == "ii" and not row["resampled"]
    assert abs(row["params"]["k"] - 0.75) < 0.01 and abs(row["params"]["h"] - 1.0) < 0.01
    assert row["rms"] == pytest.approx(expected.rms, rel=1e-9)
    assert png.stat().st_size > 10_000


def test_fair_resamples_uneven_input_when_needed(tmp_path):
    src = data.path("elastica_digitised.csv")
    out, rep = tmp_path / "out.csv", tmp_path / "r.json"
    result = CliRunner().invoke(fair_command, [str(src), "-o", str(out), "--report", str(rep)])
    assert result.exit_code == 0, result.output
    row = json.loads(rep.read_text())["curves"][0]
    assert row["resampled"] and row["success"]
    steps = np.hypot(*np.diff(read_csv(out), axis=0).T)
    np.testing.assert_allclose(steps, row["params"]["h"], rtol=1e-10)
    # --no-resample refuses, naming the spread and pointing to resampling
    result = CliRunner().invoke(cli(), ["fair", str(src), "-o", str(out), "--no-resample"])
    assert result.exit_code == 1
    assert "unevenly spaced" in result.output and "resample" in result.output


@pytest.mark.parametrize("shape", ["clothoid", "bezier", "log_aesthetic"])
@pytest.mark.parametrize("speed", [0.05, 0.12])
def test_fair_resamples_a_smoothly_uneven_scan_by_default(tmp_path, shape, speed):
    # a 1.5 m section curve sampled at 400 points whose speed varies by +-5 % or +-12 %
    # (spacing spread 0.035 / 0.085, inside fit's spacing_tol of 0.25), 0.05 mm noise:
    # paired by index as given, the fit bent to follow the drift (worst deviation 1.3-4.6
    # mm); resampled first it is the curve's own model error (0.6-2.3 mm)
    from curvesmith.elastica import needs_resampling
    from elastica_curves import _arc_param, _dense

    dense = _dense(shape)
    s = _arc_param(dense)
    u = np.linspace(0.0, 1.0, 400)
    arc = (u + speed / (6 * np.pi) * np.sin(6 * np.pi * u)) * s[-1]
    rng = np.random.default_rng(11)
    pts = np.c_[np.interp(arc, s, dense[:, 0]), np.interp(arc, s, dense[:, 1])]
    pts += rng.normal(0.0, 0.05, pts.shape)
    assert needs_resampling(pts) and needs_resampling(pts[::-1])
    src, out, rep = tmp_path / "in.csv", tmp_path / "out.csv", tmp_path / "r.json"
    write_csv(src, pts)
    pts = read_csv(src)  # as the command reads them
    result = CliRunner().invoke(fair_command, [str(src), "-o", str(out), "--report", str(rep)])
    assert result.exit_code == 0, result.output
    row = json.loads(rep.read_text())["curves"][0]
    assert row["resampled"] and row["success"]
    as_given = fit(pts, spacing_tol=1.0)
    best = fit(pts, resample=True)
    assert row["max_deviation"] == pytest.approx(best.max_deviation, rel=1e-9)
    assert row["max_deviation"] < as_given.max_deviation - 0.5  # mm closer to the data
    # the same curve on equal chords with the same noise stays as it is
    even = np.c_[np.interp(u * s[-1], s, dense[:, 0]), np.interp(u * s[-1], s, dense[:, 1])]
    assert not needs_resampling(even + rng.normal(0.0, 0.05, even.shape))


def test_fair_step_option(tmp_path):
    src, out = tmp_path / "in.csv", tmp_path / "out.csv"
    write_csv(src, sample((0.0, 0.0, 0.1, 0.2, 0.05, 0.3, 0.6), 200))
    result = CliRunner().invoke(fair_command, [str(src), "-o", str(out), "--step", "0.25"])
    assert result.exit_code == 0, result.output
    np.testing.assert_allclose(np.hypot(*np.diff(read_csv(out), axis=0).T), 0.25, rtol=1e-4)
    bad = CliRunner().invoke(fair_command, [str(src), "-o", str(out), "--step", "-1"])
    assert bad.exit_code == 2 and "--step" in bad.output


def test_fair_errors_exit_nonzero(tmp_path):
    src, out = tmp_path / "short.csv", tmp_path / "out.csv"
    write_csv(src, np.column_stack((np.arange(4.0), np.arange(4.0) ** 2)))
    result = CliRunner().invoke(cli(), ["fair", str(src), "-o", str(out)])
    assert result.exit_code == 1
    assert "Error: curve 0: points must have at least 5 points" in result.output
    assert not out.exists()


def test_fair_all_points_at_one_place_is_said_so(tmp_path):
    # the CSV reader calls a curve that ends where it starts closed; the error was that
    # the curve is closed, not that it has no extent
    src, out = tmp_path / "one.csv", tmp_path / "out.csv"
    write_csv(src, np.full((50, 2), 5.0))
    result = CliRunner().invoke(cli(), ["fair", str(src), "-o", str(out)])
    assert result.exit_code == 1
    assert result.output.strip() == (
        "Error: curve 0: points must not all coincide, got every point at [5.0, 5.0]"
    )
    assert not out.exists()


def test_fair_reports_no_noise_level_for_a_sparse_curve(tmp_path):
    # 8 points: no noise level is measured; the report is valid JSON (null, not NaN)
    src, out, rep = tmp_path / "few.csv", tmp_path / "out.csv", tmp_path / "r.json"
    pts = sample((0.0, 0.0, 3.0, 0.0, 0.08, 0.3, 0.7), 8)
    write_csv(src, pts)
    result = CliRunner().invoke(cli(), ["fair", str(src), "-o", str(out), "--report", str(rep)])
    assert result.exit_code == 0, result.output
    assert "8 points are too few to tell the data's noise from its bending" in result.output

    def no_nan(text):
        raise AssertionError(f"{text} in the JSON report")

    row = json.loads(rep.read_text(), parse_constant=no_nan)["curves"][0]
    assert row["noise"] is None and row["success"] is True


def test_fair_straight_line_is_an_exact_elastica(tmp_path):
    """Issue 11: a line is an elastica (z = 0), not an error."""
    src, out, rep = tmp_path / "line.csv", tmp_path / "out.csv", tmp_path / "r.json"
    write_csv(src, np.column_stack((np.arange(10.0), np.zeros(10))))
    result = CliRunner().invoke(cli(), ["fair", str(src), "-o", str(out), "--report", str(rep)])
    assert result.exit_code == 0, result.output
    np.testing.assert_allclose(
        read_csv(out), np.column_stack((np.arange(10.0), np.zeros(10))), atol=1e-12
    )
    assert json.loads(rep.read_text())["curves"][0]["case"] == "line"


def test_fair_model_error_is_a_converged_fit_and_tolerance_decides(tmp_path):
    """A curve that is not an elastica (a sine wave of growing amplitude) fits with an rms far
    above its noise: a converged fit (exit 0, issue 11) whose message says it is model error;
    --tolerance below its max deviation exits 1 and writes no output."""
    t = np.linspace(0, 4 * np.pi, 200)
    wave = np.column_stack((t, 0.2 * t * np.sin(t)))
    from curvesmith.internals import resample_walk as equilateral

    src, out, rep = tmp_path / "w.csv", tmp_path / "o.csv", tmp_path / "r.json"
    write_csv(src, equilateral(wave, 0.1))
    loose = CliRunner().invoke(cli(), ["fair", str(src), "-o", str(out), "--report", str(rep)])
    assert loose.exit_code == 0, loose.output
    row = json.loads(rep.read_text())["curves"][0]
    assert row["success"] and row["rms"] > 20 * 1e-6 and "model error" in row["message"]
    assert row["rms"] > 20 * row["noise"]
    out.unlink()
    tol = row["max_deviation"] / 2
    strict = CliRunner().invoke(
        cli(), ["fair", str(src), "-o", str(out), "--tolerance", str(tol), "--report", str(rep)]
    )
    assert strict.exit_code == 1 and "miss the tolerance" in strict.output
    assert not out.exists()
    assert json.loads(rep.read_text())["curves"][0]["within_tolerance"] is False


def test_fair_3d_scan_in_its_plane_and_back(tmp_path):
    """A tilted planar 3D elastica scan (.xyz, no header): faired in its PCA plane, written
    in the input's x, y, z; the report gives the plane."""
    from curvesmith.geometry import pca_frame

    rng = np.random.default_rng(4)
    flat = sample((0.0, 0.0, 2.0, 0.1, 0.0015, 0.3, 3.0), 700)
    q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    pts = np.column_stack([flat, np.zeros(len(flat))]) @ q.T + [100.0, -50.0, 20.0]
    noisy = pts + rng.normal(scale=0.002, size=pts.shape)
    src, out, rep = tmp_path / "scan.xyz", tmp_path / "out.csv", tmp_path / "r.json"
    np.savetxt(src, noisy)
    result = CliRunner().invoke(
        cli(), ["fair", str(src), "-o", str(out), "--report", str(rep), "--max-iter", "800"]
    )
    assert result.exit_code == 0, result.output
    faired = np.loadtxt(out, delimiter=",", skiprows=1)
    assert faired.shape == (700, 3)
    np.testing.assert_allclose(faired, pts, atol=0.01)  # back in scan coordinates
    row = json.loads(rep.read_text())["curves"][0]
    centroid, _, _ = pca_frame(noisy)
    np.testing.assert_allclose(row["plane"]["origin"], centroid, rtol=1e-12)
    assert abs(abs(np.dot(row["plane"]["normal"], q[:, 2])) - 1) < 1e-6
    assert row["plane"]["rms"] == pytest.approx(0.002, rel=0.2)
    assert "Warning" not in result.output
    # a bent (non-planar) scan gets a one-line warning
    bent = pts + np.outer(np.linspace(-1, 1, 700) ** 2, q[:, 2]) * 20.0
    np.savetxt(src, bent)
    result = CliRunner().invoke(cli(), ["fair", str(src), "-o", str(out)])
    assert result.exit_code == 0, result.output
    assert "Warning: curve 0 is not planar" in result.output


def test_fair_writes_dxf_3d_polylines(tmp_path):
    import ezdxf

    src, out = tmp_path / "scan.xyz", tmp_path / "faired.dxf"
    flat = sample((0.0, 0.0, 2.0, 0.1, 0.0015, 0.3, 3.0), 200)
    c, s_ = np.cos(0.4), np.sin(0.4)  # tilted about the y axis, shifted
    pts = np.column_stack([c * flat[:, 0], flat[:, 1], s_ * flat[:, 0] + 3.0])
    np.savetxt(src, pts)
    result = CliRunner().invoke(cli(), ["fair", str(src), "-o", str(out)])
    assert result.exit_code == 0, result.output
    (line,) = list(ezdxf.readfile(out).modelspace())
    assert line.dxftype() == "POLYLINE" and line.is_3d_polyline
    xyz = np.array([tuple(v.dxf.location) for v in line.vertices])
    np.testing.assert_allclose(xyz, pts, atol=1e-6)  # an exact elastica: faired = input


def _point_polyline_distance(p, poly):
    """Plain reference: distance of every point of `p` to the polyline `poly` (any dimension)."""
    a, b = poly[:-1], poly[1:]
    ab = b - a
    t = np.einsum("pkd,kd->pk", p[:, None, :] - a[None], ab) / np.einsum("kd,kd->k", ab, ab)
    near = a[None] + np.clip(t, 0, 1)[..., None] * ab[None]
    return np.sqrt(((p[:, None, :] - near) ** 2).sum(-1)).min(axis=1)


def test_fair_3d_reports_and_warns_the_distance_from_the_plane(tmp_path):
    """A section scan in metres that bulges 2 mm out of its plane: the tolerance is judged in
    the plane (5e-5 m, as the section is faired there), but the report gives the distances
    from the written 3D fit (3.4e-4 m) and a warning says when they exceed the tolerance
    (it passed 1e-4 without a word)."""
    rng = np.random.default_rng(7)
    flat = sample((0.0, 0.0, 2.0, 0.3, 0.06, 0.4, 0.7), 100) / 1000.0
    flat = flat + rng.normal(scale=2e-7, size=flat.shape)
    bulge = 0.002 * np.sin(np.linspace(0, np.pi, len(flat))) * 0.17
    c, s = np.cos(0.4), np.sin(0.4)
    rot = np.array([[1, 0, 0], [0, c, -s], [0, s, c]])
    pts = np.column_stack([flat, bulge]) @ rot.T + [10.0, 20.0, 5.0]
    src, out, rep = tmp_path / "scan.xyz", tmp_path / "out.csv", tmp_path / "r.json"
    np.savetxt(src, pts)
    args = ["fair", str(src), "-o", str(out), "--report", str(rep)]
    result = CliRunner().invoke(cli(), [*args, "--tolerance", "1e-3"])
    assert result.exit_code == 0, result.output
    assert "from the fit in space" not in result.output
    row = json.loads(rep.read_text())["curves"][0]
    written = np.loadtxt(out, delimiter=",", skiprows=1)
    truth = _point_polyline_distance(pts, written)
    assert row["max_deviation_in_space"] == pytest.approx(truth.max(), rel=1e-6)
    assert row["max_deviation"] < 0.3 * row["max_deviation_in_space"]
    assert row["plane"]["max_distance"] <= row["max_deviation_in_space"] <= 1e-3
    assert row["within_tolerance"] and row["within_tolerance_in_space"]
    tol = 0.5 * (row["max_deviation"] + row["max_deviation_in_space"])
    result = CliRunner().invoke(cli(), [*args, "--tolerance", f"{tol:.6g}"])
    assert result.exit_code == 0, result.output
    warning = [ln for ln in result.output.splitlines() if ln.startswith("Warning: curve 0 is")]
    assert len(warning) == 1 and "from the fit in space" in warning[0]
    row = json.loads(rep.read_text())["curves"][0]
    assert row["within_tolerance"] is True and row["within_tolerance_in_space"] is False


@pytest.mark.parametrize("where", ["report", "plot", "suffix"])
def test_fair_checks_every_destination_before_fitting(tmp_path, monkeypatch, where):
    """A report or plot into a missing folder, or an output of unknown suffix, is refused
    before any fit (it was found after the output was written, or after all the fitting)."""
    import curvesmith.elastica as elastica

    def no_fit(*a, **k):
        raise AssertionError("fitted before the destinations were checked")

    monkeypatch.setattr(elastica, "fit", no_fit)
    src, out = data.path("elastica_wave.csv"), tmp_path / "out.csv"
    args = ["fair", str(src), "-o", str(out)]
    if where == "report":
        args += ["--report", str(tmp_path / "missing" / "r.json")]
    elif where == "plot":
        args += ["--plot", str(tmp_path / "missing" / "p.png")]
    else:
        args[3] = str(tmp_path / "out.xyz")
    result = CliRunner().invoke(cli(), args)
    assert result.exit_code == 1 and "Traceback" not in result.output
    assert ("missing" if where != "suffix" else "unknown file suffix '.xyz'") in result.output
    assert not out.exists() and not (tmp_path / "out.xyz").exists()


def test_fair_3d_with_a_repeated_point(tmp_path):
    """A 3D scan with a point recorded twice: the fit drops the repeat, the distances in space
    are of every input point (an in-plane array one shorter could not be combined with them)."""
    flat = sample((0.0, 0.0, 2.0, 0.3, 0.06, 0.4, 0.7), 100)
    pts = np.column_stack([flat, 0.001 * np.sin(np.arange(100))])
    pts = np.insert(pts, 40, pts[40], axis=0)
    src, out, rep = tmp_path / "dup.xyz", tmp_path / "o.csv", tmp_path / "r.json"
    np.savetxt(src, pts)
    result = CliRunner().invoke(
        cli(), ["fair", str(src), "-o", str(out), "--tolerance", "1", "--report", str(rep)]
    )
    assert result.exit_code == 0, result.output
    row = json.loads(rep.read_text())["curves"][0]
    written = np.loadtxt(out, delimiter=",", skiprows=1)
    truth = _point_polyline_distance(pts, written)
    assert row["max_deviation_in_space"] == pytest.approx(truth.max(), rel=1e-9)
    assert row["within_tolerance_in_space"] is True
