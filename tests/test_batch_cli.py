"""``curvesmith batch smooth`` through click."""

import json

import distributed
import numpy as np
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
