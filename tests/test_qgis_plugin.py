"""The QGIS plugin (qgis_plugin/curvesmith_qgis): its tables here, its algorithms in a real QGIS.

The QGIS tests start Debian's QGIS headless (system Python, ``QT_QPA_PLATFORM=offscreen``)
in a subprocess that loads the provider from the repository folder and runs every scenario
through ``processing.run`` (``tests/qgis/run_scenarios.py``); curvesmith runs from this
virtual environment, found on PATH, as a user would have it. The outputs are then checked
here with shapely: feature count, attributes, CRS, every polygon's area, validity, gaps, and
the same geometries as curvesmith's own functions give. QGIS is installed from Debian when
missing in CI (as root); elsewhere these tests are skipped with the reason, never in CI.
"""

import importlib.util
import json
import os
import shutil
import subprocess
import sys
import time
import zipfile
from pathlib import Path

import geopandas as gpd
import numpy as np
import pandas as pd
import pyogrio
import pytest
import shapely

from curvesmith import geo
from curvesmith.cli.basic import smooth_command
from curvesmith.cli.geo import batch_smooth_command

REPO = Path(__file__).resolve().parent.parent
PLUGIN_PARENT = REPO / "qgis_plugin"
PLUGIN = PLUGIN_PARENT / "curvesmith_qgis"
RUNNER = Path(__file__).resolve().parent / "qgis" / "run_scenarios.py"
VENV_BIN = Path(sys.executable).parent
#: The folder of the ``curvesmith`` program the plugin runs (default: this environment's).
CLI_BIN = Path(os.environ.get("CURVESMITH_QGIS_TEST_BIN", VENV_BIN))
IN_CI = os.environ.get("CI", "").lower() in ("1", "true", "yes")
STATES = ["21", "54"]  # Kentucky and West Virginia: 175 counties, river borders, an exclave
CRS = "EPSG:5070"  # NAD83 / Conus Albers (metres, equal area)


def _load(name):
    """A plugin module that imports no QGIS, loaded from its file."""
    spec = importlib.util.spec_from_file_location(f"curvesmith_qgis_{name}", PLUGIN / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module
    spec.loader.exec_module(module)
    return module


options = _load("options")
runner = _load("runner")


# ---------------------------------------------------------------- without QGIS


def _cli_defaults(command):
    """Parameter name -> default, as click resolves them for ``IN -o OUT``."""
    ctx = command.make_context(command.name, ["IN", "-o", "OUT"])
    return {p.name: (p, ctx.params[p.name]) for p in command.params}


@pytest.mark.parametrize("option", options.OPTIONS, ids=lambda o: o.name)
def test_parameter_table_matches_the_cli(option):
    """Every parameter is named after its CLI option and has the CLI's default."""
    assert option.name == option.flag.removeprefix("--").upper().replace("-", "_")
    command = batch_smooth_command if option.batch else smooth_command
    param, default = next(v for v in _cli_defaults(command).values() if option.flag in v[0].opts)
    assert default == option.default
    if option.kind == "bool":
        assert param.is_flag and option.default is False
    if option.kind == "enum":
        assert set(option.choices) <= set(param.type.choices)
        assert option.default in option.choices
    if option.kind in ("int", "float"):
        base = {"int": "integer", "float": "float"}[option.kind]
        assert param.type.name in (base, f"{base} range")
        if param.type.name.endswith("range") and param.type.min is not None:
            # the QGIS parameter refuses what the CLI refuses
            assert option.minimum is not None and option.minimum >= param.type.min
    for name in option.algorithms:
        assert name in {a.name for a in options.ALGORITHMS}


def test_fixed_flags_exist_in_the_cli():
    flags = {f for p in smooth_command.params for f in p.opts}
    assert "--coverage" in flags
    # --network comes with issue 14 (curvesmith.geo.smooth_network); test_smoothnetwork
    # runs it through QGIS


def test_build_argv():
    exe = "/opt/cs/bin/curvesmith"

    def argv(algorithm, values):
        return " ".join(options.build_argv(exe, algorithm, values, "a.gpkg", "b.fgb")[1:])

    assert (
        argv("smooth", {}) == "smooth a.gpkg -o b.fgb --method cca --iterations 1 --alpha regular"
    )
    values = {"METHOD": 1, "ITERATIONS": 2, "ALPHA": " 0.2 ", "EQUAL_AREA": True, "SNAP": 0.5}
    assert argv("smoothcoverage", values) == (
        "smooth a.gpkg -o b.fgb --coverage --method chaikin --iterations 2 --alpha 0.2 "
        "--equal-area --snap 0.5"
    )
    # a worker count runs batch smooth, with the batch-only options; empty optionals vanish
    values = {"WORKERS": 2, "SNAP": None, "SCHEDULER": "", "PARTITION_SIZE": 50}
    assert argv("smoothcoverage", values) == (
        "batch smooth a.gpkg -o b.fgb --coverage --method cca --iterations 1 --alpha regular "
        "--workers 2 --partition-size 50"
    )
    # options of other algorithms are not passed
    assert argv("smoothnetwork", {"ITERATIONS": 1, "METHOD": 1, "SNAP": 2.0}) == (
        "smooth a.gpkg -o b.fgb --network --method chaikin --iterations 1 --alpha regular"
    )
    # a network on Dask: batch smooth --network (the whole network noded once, arcs in parallel)
    assert argv("smoothnetwork", {"WORKERS": 2, "PARTITION_SIZE": 600}) == (
        "batch smooth a.gpkg -o b.fgb --network --method cca --iterations 1 --alpha regular "
        "--workers 2 --partition-size 600"
    )
    # the map-unit bounds hold per piece between junctions in network mode
    assert argv("smoothnetwork", {"MAX_SHIFT": 2.5, "MIN_SEGMENT": 4.0}) == (
        "smooth a.gpkg -o b.fgb --network --method cca --iterations 1 --alpha regular "
        "--max-shift 2.5 --min-segment 4.0"
    )
    assert options.build_argv(exe, "smooth", {}, "a", "b")[0] == exe


def test_error_message_is_the_cli_line():
    res = runner.CliResult(1, [], ["Warning: data in degrees", "Error: alpha must be in (0, 1/3)"])
    assert runner.error_message(res) == "alpha must be in (0, 1/3)"
    usage = [
        "Usage: curvesmith smooth [OPTIONS] IN",
        "Try 'curvesmith smooth --help' for help.",
        "Error: No such option '--network'.",
    ]
    text = runner.error_message(runner.CliResult(2, [], usage), "/x/curvesmith")
    assert text.startswith("the installed curvesmith (/x/curvesmith) has no option --network:")
    assert runner.error_message(runner.CliResult(-9, [], [])) == "exited with status -9"
    one = ["Error: Invalid value for '--alpha': 'x'. (see 'curvesmith smooth --help')"]
    assert runner.error_message(runner.CliResult(2, [], one)) == "Invalid value for '--alpha': 'x'."
    one = ["Error: No such option: --network (see 'curvesmith smooth --help')"]
    text = runner.error_message(runner.CliResult(2, [], one), "/x/curvesmith")
    assert text.startswith("the installed curvesmith (/x/curvesmith) has no option --network:")


def test_find_curvesmith(tmp_path, monkeypatch):
    exe = tmp_path / "env" / "bin" / "curvesmith"
    exe.parent.mkdir(parents=True)
    exe.write_text("#!/bin/sh\n")
    exe.chmod(0o755)
    for configured in (exe, exe.parent, exe.parent.parent):  # the program, bin/, the venv
        assert runner.find_curvesmith(str(configured)) == str(exe.resolve())
    with pytest.raises(
        runner.CurvesmithNotFound,
        match="^curvesmith not found: set its path in Processing > Options > Providers",
    ):
        runner.find_curvesmith(str(tmp_path / "nowhere"))
    monkeypatch.setenv("PATH", str(exe.parent))
    assert runner.find_curvesmith("") == str(exe)
    monkeypatch.setenv("PATH", str(tmp_path))
    monkeypatch.setenv("HOME", str(tmp_path))
    with pytest.raises(runner.CurvesmithNotFound, match=r"\(not on PATH\)$"):
        runner.find_curvesmith(None)


def _alive(pid):
    try:
        with open(f"/proc/{pid}/stat") as f:
            return f.read().rsplit(")", 1)[1].split()[0] != "Z"
    except OSError:
        return False


@pytest.mark.skipif(not Path("/proc").is_dir(), reason="reads /proc to see the processes")
def test_run_cli_progress_lines_and_cancel_kill_children(tmp_path):
    """Progress bars become percentages; cancelling kills the program and its children."""
    script = tmp_path / "prog.py"
    pids = tmp_path / "pids"
    script.write_text(
        "import os, subprocess, sys, time\n"
        "child = subprocess.Popen([sys.executable, '-c', 'import time; time.sleep(60)'])\n"
        f"open({str(pids)!r}, 'w').write(f'{{os.getpid()}} {{child.pid}}')\n"
        "print('Warning: something', file=sys.stderr, flush=True)\n"
        "for p in (10, 55):\n"
        "    print(f'\\r[###   ] | {p}% Completed |  0.1s', end='', flush=True)\n"
        "time.sleep(60)\n"
    )
    progress, lines = [], []
    start = time.monotonic()

    def canceled():  # once both pipes said their piece (they are read by two threads)
        return 55.0 in progress and bool(lines)

    with pytest.raises(runner.Cancelled, match="cancelled"):
        runner.run_cli(
            [sys.executable, str(script)],
            is_canceled=canceled,
            on_progress=progress.append,
            on_line=lambda name, line: lines.append((name, line)),
        )
    assert time.monotonic() - start < 20
    assert progress == [10.0, 55.0]
    assert lines == [("stderr", "Warning: something")]
    parent, child = map(int, pids.read_text().split())
    deadline = time.monotonic() + 5  # SIGKILL is delivered asynchronously
    while _alive(child) and time.monotonic() < deadline:
        time.sleep(0.05)
    assert not _alive(parent) and not _alive(child)


def test_run_cli_result():
    code = "import sys; print('out'); print('Error: bad thing', file=sys.stderr); sys.exit(1)"
    res = runner.run_cli(
        [sys.executable, "-c", code],
        is_canceled=lambda: False,
        on_progress=lambda p: None,
        on_line=lambda n, s: None,
    )
    assert (res.returncode, res.stdout, res.stderr) == (1, ["out"], ["Error: bad thing"])


def _build_zip(dest):
    spec = importlib.util.spec_from_file_location(
        "curvesmith_qgis_build", PLUGIN_PARENT / "build.py"
    )
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module.build(dest)


def test_build_zip(tmp_path):
    path = _build_zip(tmp_path)
    assert path.name == "curvesmith_qgis-0.1.0.zip"
    with zipfile.ZipFile(path) as zf:
        names = set(zf.namelist())
        meta = zf.read("curvesmith_qgis/metadata.txt").decode()
    expected = {
        f"curvesmith_qgis/{p.relative_to(PLUGIN).as_posix()}"
        for p in PLUGIN.rglob("*")
        if p.is_file() and "__pycache__" not in p.parts
    }
    assert names == expected | {"curvesmith_qgis/LICENSE"}
    for key in (
        "name=curvesmith",
        "qgisMinimumVersion=3.22",
        "version=0.1.0",
        "icon=icon.png",
        "hasProcessingProvider=yes",
    ):
        assert key in meta.splitlines()


# ---------------------------------------------------------------- in QGIS


def _clean_env(home):
    env = {
        k: v for k, v in os.environ.items() if k not in ("VIRTUAL_ENV", "PYTHONHOME", "PYTHONPATH")
    }
    env.update(QT_QPA_PLATFORM="offscreen", HOME=str(home), XDG_RUNTIME_DIR=str(home))
    return env


def _find_qgis_python(home):
    candidates = [os.environ.get("CURVESMITH_QGIS_PYTHON"), "/usr/bin/python3"]
    for c in candidates:
        if c and Path(c).is_file():
            probe = subprocess.run(
                [
                    c,
                    "-c",
                    "import qgis.core, sys; sys.path.append('/usr/share/qgis/python/plugins'); import processing",
                ],
                env=_clean_env(home),
                capture_output=True,
            )
            if probe.returncode == 0:
                return c
    return None


@pytest.fixture(scope="session")
def qgis_python(tmp_path_factory):
    """The Python that has QGIS; installed from Debian in CI (as root) when missing."""
    home = tmp_path_factory.mktemp("qgis-home")
    found = _find_qgis_python(home)
    if found:
        return found
    if IN_CI and hasattr(os, "geteuid") and os.geteuid() == 0 and shutil.which("apt-get"):
        env = dict(os.environ, DEBIAN_FRONTEND="noninteractive")
        subprocess.run(["apt-get", "update"], check=True, env=env)
        subprocess.run(["apt-get", "install", "-y", "qgis", "python3-qgis"], check=True, env=env)
        found = _find_qgis_python(home)
        if found:
            return found
        pytest.fail(
            "apt-get installed qgis and python3-qgis, but /usr/bin/python3 cannot import qgis"
        )
    if IN_CI:
        pytest.fail(
            "QGIS is missing and cannot be installed here (needs root and apt-get); the QGIS plugin tests must run in CI"
        )
    pytest.skip("QGIS is not installed (apt-get install qgis python3-qgis); these tests run in CI")


@pytest.fixture(scope="session")
def data(tmp_path_factory):
    """Kentucky and West Virginia counties (projected), their shared arcs as lines, Z polygons."""
    d = tmp_path_factory.mktemp("qgis-data")
    counties = geo.us_counties(states=STATES).to_crs(CRS)
    arcs = shapely.get_parts(
        shapely.line_merge(shapely.union_all(shapely.boundary(counties.geometry.values)))
    )
    lines = gpd.GeoDataFrame(
        {
            "arc": np.arange(len(arcs)),
            "length_m": shapely.length(arcs),
            "label": [f"arc {i}" for i in range(len(arcs))],
        },
        geometry=arcs,
        crs=CRS,
    )
    wv = counties[counties["STATEFP"] == "54"].reset_index(drop=True)
    # Z: a plane tilted west-east (metres of height per km), plus a flat county at z = 250
    z_geoms = [
        shapely.Polygon(np.c_[c, 100.0 + 1e-3 * (c[:, 0] - c[0, 0])])
        for c in (shapely.get_coordinates(g.exterior) for g in wv.geometry.values[:6])
    ]
    z_geoms.append(shapely.force_3d(wv.geometry.values[6].exterior, 250.0))
    z_geoms[-1] = shapely.Polygon(shapely.get_coordinates(z_geoms[-1], include_z=True))
    zdf = gpd.GeoDataFrame({"GEOID": wv["GEOID"][:7].values}, geometry=z_geoms, crs=CRS)
    degrees = wv.to_crs("EPSG:4269")
    # a feature without geometry between two counties, as real layers have
    nulls = gpd.GeoDataFrame(
        {"GEOID": ["54001", "none", "54003"]},
        geometry=[wv.geometry[0], None, wv.geometry[1]],
        crs=CRS,
    )
    # for cancelling: the counties 3 x 3 times side by side, so that an uncancelled run
    # takes long on any machine (1,575 features, 0.56 M vertices)
    (x0, y0, x1, y1), gap = counties.total_bounds, 10_000.0
    dx, dy = x1 - x0 + gap, y1 - y0 + gap
    big = pd.concat(
        [
            counties.set_geometry(counties.geometry.translate(i * dx, j * dy))
            for i in range(3)
            for j in range(3)
        ],
        ignore_index=True,
    )
    layers = {
        "counties": counties,
        "lines": lines,
        "z": zdf,
        "degrees": degrees,
        "nulls": nulls,
        "big": big,
    }
    paths = {k: d / f"{k}.gpkg" for k in layers}
    for key, df in layers.items():
        # GeoPackage 1.2: Debian's GDAL warns about the 1.4 files that newer GDALs write
        pyogrio.write_dataframe(df, paths[key], dataset_options={"VERSION": "1.2"})
    return {"dir": d, "paths": paths, **layers}


#: Curved polygons (a disc of radius 1000 m, a half disc with a chord), as a database may hold.
CURVED = [
    ["disc", "CURVEPOLYGON(CIRCULARSTRING(1000 0, 0 1000, -1000 0, 0 -1000, 1000 0))"],
    [
        "half",
        "CURVEPOLYGON(COMPOUNDCURVE(CIRCULARSTRING(1000 0, 0 1000, -1000 0), (-1000 0, 1000 0)))",
    ],
]
CANCEL_AFTER = {"cancel": 2.0, "cancel_batch": 3.0}  # seconds after curvesmith started
SELECTED = [3, 17, 18, 40, 41, 42, 90, 120, 121, 150, 160, 174]


def _scenario(name, algorithm, source, params, **extra):
    return {
        "name": name,
        "algorithm": f"curvesmith:{algorithm}",
        "input": source,
        "params": params,
        **extra,
    }


def _scenarios(data):
    d, p = data["dir"], {k: str(v) for k, v in data["paths"].items()}
    counties, lines = p["counties"], p["lines"]
    return [
        _scenario(
            "smooth_shp", "smooth", counties, {"ITERATIONS": 2, "OUTPUT": str(d / "smooth.shp")}
        ),
        _scenario(
            "coverage",
            "smoothcoverage",
            counties,
            {"ITERATIONS": 2, "OUTPUT": str(d / "coverage.gpkg")},
        ),
        _scenario(
            "coverage_batch",
            "smoothcoverage",
            counties,
            {
                "ITERATIONS": 2,
                "WORKERS": 2,
                "PARTITION_SIZE": 200,
                "OUTPUT": str(d / "coverage_batch.fgb"),
            },
        ),
        _scenario(
            "selected",
            "smoothcoverage",
            counties,
            {"OUTPUT": str(d / "selected.gpkg")},
            select_fids=[i + 1 for i in SELECTED],  # GeoPackage fids count from 1
        ),
        _scenario(
            "lines_temporary",
            "smooth",
            lines,
            {"ITERATIONS": 2, "OUTPUT": "TEMPORARY_OUTPUT"},
            save_temporary_to=str(d / "lines_tmp.gpkg"),
        ),
        _scenario(
            "network", "smoothnetwork", lines, {"ITERATIONS": 2, "OUTPUT": str(d / "network.gpkg")}
        ),
        _scenario(
            "network_bounded",
            "smoothnetwork",
            lines,
            {"ITERATIONS": 3, "MAX_SHIFT": 50.0, "OUTPUT": str(d / "network_bounded.gpkg")},
        ),
        _scenario("z", "smooth", p["z"], {"ITERATIONS": 1, "OUTPUT": str(d / "z_out.gpkg")}),
        _scenario(
            "task",
            "smoothcoverage",
            counties,
            {"ITERATIONS": 1, "OUTPUT": str(d / "task.gpkg")},
            as_task=True,
        ),
        _scenario(
            "nulls", "smooth", p["nulls"], {"ITERATIONS": 1, "OUTPUT": str(d / "nulls_out.gpkg")}
        ),
        _scenario(
            "curved",
            "smooth",
            None,
            {"ITERATIONS": 1, "OUTPUT": str(d / "curved_out.gpkg")},
            memory={"uri": f"CurvePolygon?crs={CRS}&field=name:string", "features": CURVED},
        ),
        _scenario(
            "degrees",
            "smoothcoverage",
            p["degrees"],
            {"ITERATIONS": 1, "OUTPUT": str(d / "deg.gpkg")},
        ),
        _scenario(
            "degrees_equal_area",
            "smoothcoverage",
            p["degrees"],
            {"ITERATIONS": 1, "EQUAL_AREA": True, "OUTPUT": str(d / "deg_ea.gpkg")},
        ),
        _scenario(
            "cancel",
            "smoothcoverage",
            p["big"],
            {"ITERATIONS": 4, "OUTPUT": str(d / "cancelled.gpkg")},
            cancel_after=CANCEL_AFTER["cancel"],
        ),
        _scenario(
            "cancel_batch",
            "smoothcoverage",
            p["big"],
            {"ITERATIONS": 4, "WORKERS": 2, "OUTPUT": str(d / "cancelled_batch.gpkg")},
            cancel_after=CANCEL_AFTER["cancel_batch"],
        ),
        _scenario(
            "bad_alpha",
            "smooth",
            counties,
            {"ALPHA": "abc", "OUTPUT": str(d / "bad.gpkg")},
            gui_like=True,
        ),
        _scenario(
            "bad_alpha_range",
            "smooth",
            counties,
            {"ALPHA": "0.5", "ITERATIONS": 1, "OUTPUT": str(d / "bad2.gpkg")},
            gui_like=True,
        ),
        _scenario(
            "not_found_setting",
            "smooth",
            counties,
            {"OUTPUT": str(d / "nf1.gpkg")},
            gui_like=True,
            setting_path=str(d / "no-such-env"),
        ),
        _scenario(
            "not_found_path",
            "smooth",
            counties,
            {"OUTPUT": str(d / "nf2.gpkg")},
            gui_like=True,
            path_env="/usr/bin:/bin",
        ),
        _scenario(
            "setting_venv",
            "smooth",
            counties,
            {"ITERATIONS": 1, "METHOD": 1, "OUTPUT": str(d / "setting.gpkg")},
            path_env="/usr/bin:/bin",
            setting_path=str(VENV_BIN.parent),
        ),
    ]


@pytest.fixture(scope="session")
def qgis(qgis_python, data, tmp_path_factory):
    """Every scenario run in one headless QGIS session; its results."""
    home = tmp_path_factory.mktemp("qgis-run")
    spec = {"plugin_parent": str(PLUGIN_PARENT), "scenarios": _scenarios(data)}
    (home / "spec.json").write_text(json.dumps(spec))
    env = _clean_env(home)
    env["PATH"] = f"{CLI_BIN}{os.pathsep}{env.get('PATH', '')}"
    proc = subprocess.run(
        [qgis_python, str(RUNNER), str(home / "spec.json"), str(home / "results.json")],
        env=env,
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert proc.returncode == 0, proc.stderr[-4000:]
    return json.loads((home / "results.json").read_text())


def _ran(qgis, name):
    res = qgis["scenarios"][name]
    assert res["ok"], f"{name}: {res['error']}\n{res.get('traceback')}"
    return res


def _read(path):
    return pyogrio.read_dataframe(path)


def _check_attributes_crs(out, src, res, columns):
    assert len(out) == len(src)
    for c in columns:
        assert out[c].tolist() == src[c].tolist(), c
    assert out.crs.equals(src.crs)
    assert res["output_layer"]["crs"] == CRS


def _check_areas(out, src, rtol=1e-9):
    a0, a1 = shapely.area(src.geometry.values), shapely.area(out.geometry.values)
    rel = np.abs(a1 - a0) / a0
    assert rel.max() < rtol, (rel.max(), int(rel.argmax()))
    assert shapely.is_valid(out.geometry.values).all()


def _gaps_and_overlap(polys):
    """Area inside the union's outer boundaries that no polygon covers; area covered twice."""
    union = shapely.union_all(polys)
    filled = shapely.union_all([shapely.Polygon(p.exterior) for p in shapely.get_parts(union)])
    return filled.area - union.area, shapely.area(polys).sum() - union.area


def _parts(geom):
    return sorted(shapely.normalize(shapely.get_parts(geom)).tolist(), key=lambda g: g.wkb)


def _same_geometries(a, b):
    """Same vertices, feature by feature, whatever the ring orientation and start (a Shapefile
    stores outer rings clockwise) and whether a one-part geometry is Multi."""
    return len(a) == len(b) and all(
        len(p) == len(q)
        and all(shapely.equals_exact(u, v, tolerance=0) for u, v in zip(p, q, strict=True))
        for p, q in zip(map(_parts, a.geometry.values), map(_parts, b.geometry.values), strict=True)
    )


@pytest.mark.slow  # a headless QGIS session
def test_provider_in_the_toolbox(qgis):
    prov = qgis["provider"]
    assert (prov["id"], prov["name"]) == ("curvesmith", "curvesmith")
    algs = prov["algorithms"]
    assert sorted(algs) == [
        "curvesmith:smooth",
        "curvesmith:smoothcoverage",
        "curvesmith:smoothnetwork",
    ]
    for spec in options.ALGORITHMS:
        alg = algs[f"curvesmith:{spec.name}"]
        table = options.options_for(spec.name)
        params = {p["name"]: p for p in alg["parameters"]}
        assert list(params) == ["INPUT", *(o.name for o in table), "OUTPUT"]
        for o in table:
            p = params[o.name]
            expected = o.choices.index(o.default) if o.kind == "enum" else o.default
            assert p["default"] == expected, o.name
            assert (p["optional"], p["advanced"], p["help"]) == (o.optional, o.advanced, o.help)
            assert f"<code>{o.flag}</code>" in alg["help"]
    assert qgis["unloaded"]


@pytest.mark.slow  # a headless QGIS session
def test_smooth_to_shapefile_keeps_areas_attributes_crs(qgis, data, tmp_path):
    res = _ran(qgis, "smooth_shp")
    src, out = data["counties"], _read(res["output"])
    _check_attributes_crs(out, src, res, ["GEOID", "NAME", "ALAND", "AWATER"])
    # the input's attributes, names and types, and no float `fid` from the GeoPackage's ids
    assert list(out.columns) == list(src.columns)
    assert out.dtypes.astype(str).tolist() == src.dtypes.astype(str).tolist()
    _check_areas(out, src)
    # the plugin is thin: the same geometries as curvesmith's own file function
    geo.smooth_file(data["paths"]["counties"], tmp_path / "ref.gpkg", iterations=2)
    assert _same_geometries(out, _read(tmp_path / "ref.gpkg"))
    assert any(line[0] == "command" and "--iterations 2" in line[1] for line in res["log"])


@pytest.mark.slow  # a headless QGIS session
def test_smoothcoverage_keeps_areas_and_leaves_no_gaps(qgis, data, tmp_path):
    res = _ran(qgis, "coverage")
    src, out = data["counties"], _read(res["output"])
    _check_attributes_crs(out, src, res, list(src.columns.drop("geometry")))
    _check_areas(out, src)
    polys = out.geometry.values
    total = shapely.area(polys).sum()
    assert shapely.coverage_is_valid(polys)
    gaps, overlap = _gaps_and_overlap(polys)
    assert gaps < 1e-9 * total and abs(overlap) < 1e-9 * total
    # the union (total - overlap) covers what the input covered, to round-off
    assert (
        abs(total - overlap - shapely.coverage_union_all(src.geometry.values).area) < 1e-9 * total
    )
    # feature by feature (curvesmith:smooth) the same counties get gaps and overlaps: the
    # checks above can fail (West Virginia's 55 counties, to keep the test short)
    wv = (src["STATEFP"] == "54").to_numpy()
    per_feature = _read(_ran(qgis, "smooth_shp")["output"]).geometry.values[wv]
    gaps, overlap = _gaps_and_overlap(per_feature)
    assert gaps > 1e5 and overlap > 1e5  # m²
    geo.smooth_file(data["paths"]["counties"], tmp_path / "ref.gpkg", iterations=2, coverage=True)
    assert _same_geometries(out, _read(tmp_path / "ref.gpkg"))


@pytest.mark.slow  # a headless QGIS session
def test_smoothcoverage_batch_mode_same_result_with_progress(qgis):
    res = _ran(qgis, "coverage_batch")
    # a FlatGeobuf written by QGIS has a spatial index, which orders the features by it
    batch = _read(res["output"]).sort_values("GEOID", ignore_index=True)
    single = _read(_ran(qgis, "coverage")["output"]).sort_values("GEOID", ignore_index=True)
    assert len(batch) == len(single)
    assert _same_geometries(batch, single)
    command = next(line[1] for line in res["log"] if line[0] == "command")
    assert " batch smooth " in command and "--workers 2 --partition-size 200" in command
    # Dask's progress bar is mapped into curvesmith's stage (10-90 %): whatever updates it
    # printed (a quick run may print none between 0 % and 100 %; the mapping itself is tested
    # above with a scripted bar) stay inside the stage, in order, and the run ends at 100 %
    progress = res["progress"]
    assert progress == sorted(progress) and progress[-1] == 100
    assert {10.0, 90.0} <= set(progress)
    stage = progress[progress.index(10.0) : progress.index(90.0) + 1]
    assert all(10.0 <= p <= 90.0 for p in stage)


@pytest.mark.slow  # a headless QGIS session
def test_progress_by_stage(qgis):
    progress = _ran(qgis, "coverage")["progress"]
    assert progress == sorted(progress) and progress[-1] == 100
    assert {10.0, 90.0} <= set(progress)  # input written; curvesmith finished


@pytest.mark.slow  # a headless QGIS session
def test_selected_features_only_with_defaults(qgis, data):
    res = _ran(qgis, "selected")
    out = _read(res["output"])
    src = data["counties"].iloc[SELECTED].reset_index(drop=True)
    _check_attributes_crs(out, src, res, ["GEOID", "NAME"])
    _check_areas(out, src)
    command = next(line[1] for line in res["log"] if line[0] == "command")
    assert command.endswith("--coverage --method cca --iterations 1 --alpha regular")
    # one cca iteration (the CLI's default) on the selection only: about 3x the vertices
    assert (
        shapely.get_num_coordinates(out.geometry.values).sum()
        > 2.5 * shapely.get_num_coordinates(src.geometry.values).sum()
    )


def _chord_area(coords):
    """Signed area between an open line and its chord (shoelace about the first vertex)."""
    x, y = (coords - coords[0]).T
    return 0.5 * np.sum(x[:-1] * y[1:] - x[1:] * y[:-1])


@pytest.mark.slow  # a headless QGIS session
def test_lines_to_temporary_layer(qgis, data):
    res = _ran(qgis, "lines_temporary")
    assert res["output_layer"]["provider"] == "memory"
    src, out = data["lines"], _read(res["output"])
    _check_attributes_crs(out, src, res, ["arc", "length_m", "label"])
    for a, b in zip(src.geometry.values, out.geometry.values, strict=True):
        p, q = shapely.get_coordinates(a), shapely.get_coordinates(b)
        assert np.array_equal(p[[0, -1]], q[[0, -1]])  # ends fixed
        assert len(q) > len(p) or len(p) == 2
        scale = shapely.length(a) ** 2
        assert abs(_chord_area(q) - _chord_area(p)) <= 1e-12 * scale


@pytest.mark.slow  # a headless QGIS session
def test_runs_as_a_background_task(qgis, data):
    """As the dialog runs it: a QgsProcessingAlgRunnerTask in a worker thread of the task manager."""
    res = _ran(qgis, "task")
    assert res["worker"]  # feedback came from another thread than the main one
    src, out = data["counties"], _read(res["output"])
    _check_attributes_crs(out, src, res, ["GEOID", "NAME"])
    _check_areas(out, src)
    assert shapely.coverage_is_valid(out.geometry.values)


@pytest.mark.slow  # a headless QGIS session
def test_features_without_geometry_pass_through(qgis, data):
    res = _ran(qgis, "nulls")
    src, out = data["nulls"], _read(res["output"])
    assert out["GEOID"].tolist() == ["54001", "none", "54003"]
    # QGIS 3.22's GeoPackage writer stores a feature without geometry as an empty one (its
    # native algorithms do the same)
    assert out.geometry[1] is None or out.geometry[1].is_empty
    kept, before = out.geometry.values[[0, 2]], src.geometry.values[[0, 2]]
    assert (np.abs(shapely.area(kept) / shapely.area(before) - 1) < 1e-9).all()
    assert (shapely.get_num_coordinates(kept) > shapely.get_num_coordinates(before)).all()


@pytest.mark.slow  # a headless QGIS session
def test_curved_geometries_made_linear(qgis):
    """Circular arcs (GeoPackage, PostGIS) are made polylines first: curvesmith smooths those."""
    res = _ran(qgis, "curved")
    assert res["output_layer"]["wkb_type"] in ("Polygon", "MultiPolygon")
    out = _read(res["output"])
    assert out["name"].tolist() == ["disc", "half"]
    assert shapely.is_valid(out.geometry.values).all()
    assert ["console", "2 of 2 feature(s) smoothed"] in res["log"]  # curvesmith's summary line
    exact = np.array([np.pi, np.pi / 2]) * 1000.0**2
    # QGIS's segmentization (its default tolerance) loses < 0.1 % of a disc; cca keeps the rest
    assert (np.abs(shapely.area(out.geometry.values) / exact - 1) < 1e-3).all()


@pytest.mark.slow  # a headless QGIS session
def test_smoothnetwork(qgis, data):
    """Needs ``curvesmith smooth --network`` (issue 14): fails until that is merged."""
    res = _ran(qgis, "network")
    src, out = data["lines"], _read(res["output"])
    _check_attributes_crs(out, src, res, ["arc", "length_m", "label"])
    a, b = src.geometry.values, out.geometry.values
    ends = shapely.get_coordinates(shapely.boundary(a))
    closed = shapely.is_closed(a)
    for p, q in zip(a[~closed], b[~closed], strict=True):  # junctions and ends fixed
        assert np.array_equal(
            shapely.get_coordinates(p)[[0, -1]], shapely.get_coordinates(q)[[0, -1]]
        )
    # no two lines meet anywhere but at the junctions where their inputs met
    i, j = shapely.STRtree(b).query(b, predicate="intersects")
    keep = i < j
    meet = shapely.intersection(b[i[keep]], b[j[keep]])
    junctions = shapely.MultiPoint(ends)
    assert shapely.covered_by(meet, junctions).all()
    assert shapely.is_simple(b).all()
    assert closed.any()  # a closed line keeps its area
    for p, q in zip(a[closed], b[closed], strict=True):
        pa, pb = (shapely.Polygon(shapely.get_coordinates(g)).area for g in (p, q))
        assert abs(pb / pa - 1) < 1e-9
    # and the lines were smoothed (two cca iterations: up to 9x the vertices)
    assert shapely.get_num_coordinates(b).sum() > 4 * shapely.get_num_coordinates(a).sum()


@pytest.mark.slow  # a headless QGIS session
def test_smoothnetwork_max_shift(qgis, data, tmp_path):
    """MAX_SHIFT in smoothnetwork: every county border line moves at most 50 m, still smoothed,
    and the output is the CLI's (smooth --network --max-shift), bit for bit."""
    res = _ran(qgis, "network_bounded")
    src, out = data["lines"], _read(res["output"])
    shift = shapely.hausdorff_distance(src.geometry.values, out.geometry.values)
    free = shapely.hausdorff_distance(
        src.geometry.values, _read(_ran(qgis, "network")["output"]).geometry.values
    )
    assert shift.max() <= 50.0 < free.max() and (shift > 0).mean() > 0.5
    ref = tmp_path / "cli.gpkg"
    direct = subprocess.run(
        [
            str(CLI_BIN / "curvesmith"),
            "smooth",
            str(data["paths"]["lines"]),
            "-o",
            str(ref),
            "--network",
            "--iterations",
            "3",
            "--max-shift",
            "50",
        ],
        capture_output=True,
        text=True,
    )
    assert direct.returncode == 0, direct.stderr
    assert _same_geometries(out, _read(ref))


@pytest.mark.slow  # a headless QGIS session
def test_z_values(qgis, data, tmp_path):
    """Z goes to curvesmith as it is: kept when curvesmith keeps it, else its one-line error."""
    res = qgis["scenarios"]["z"]
    direct = subprocess.run(
        [
            str(CLI_BIN / "curvesmith"),
            "smooth",
            str(data["paths"]["z"]),
            "-o",
            str(tmp_path / "z.gpkg"),
            "--iterations",
            "1",
        ],
        capture_output=True,
        text=True,
    )
    if direct.returncode != 0:  # this curvesmith refuses Z: the plugin says so, in one line
        error = direct.stderr.strip().splitlines()[-1].removeprefix("Error: ")
        assert res["error"] == f"curvesmith: {error}"
        assert "Z" in error
        return
    assert res["ok"], res["error"]
    out, ref = _read(res["output"]), _read(tmp_path / "z.gpkg")
    assert "Z" in res["output_layer"]["wkb_type"]
    assert shapely.has_z(out.geometry.values).all()
    assert _same_geometries(out, ref)
    assert np.array_equal(
        shapely.get_coordinates(out.geometry.values, include_z=True),
        shapely.get_coordinates(ref.geometry.values, include_z=True),
    )
    flat = shapely.get_coordinates(out.geometry.values[-1], include_z=True)
    assert (flat[:, 2] == 250.0).all()


@pytest.mark.slow  # a headless QGIS session
@pytest.mark.parametrize("name", ["cancel", "cancel_batch"])
def test_cancel_stops_curvesmith(qgis, data, name):
    """Cancelled a few seconds after curvesmith started: it and its children are killed at once."""
    res = qgis["scenarios"][name]
    assert not res["ok"], f"the run ended after {res['elapsed']:.1f} s, before the cancel"
    assert res["error"] == "curvesmith: cancelled, the program was stopped and no output written"
    # an uncancelled run takes 8 s (smooth) and 10 s (batch) on 2 cores: four cca
    # iterations of 0.56 M vertices, 46 M vertices written
    assert res["cancelled_at"] >= CANCEL_AFTER[name]
    assert res["elapsed"] - res["cancelled_at"] < 3
    assert res["descendants"], "curvesmith was not running when cancelled"
    if name == "cancel_batch":  # curvesmith, its process starter and its workers
        assert len(res["descendants"]) >= 3, res["descendants"]
    assert res["alive_after"] == []
    output = {"cancel": "cancelled.gpkg", "cancel_batch": "cancelled_batch.gpkg"}[name]
    assert not (data["dir"] / output).exists()
    command = next(text for kind, text in res["log"] if kind == "command")
    workdir = Path(command.split(" -o ")[0].split()[-1]).parent  # the temporary files' folder
    assert workdir.name.startswith("curvesmith_") and not workdir.exists()


@pytest.mark.parametrize(
    ("name", "message"),
    [
        (
            "bad_alpha",
            "curvesmith: Invalid value for '--alpha': 'abc' is neither 'regular' nor a number.",
        ),
        (
            "bad_alpha_range",
            "curvesmith: Invalid value for '--alpha': '0.5' is not in the open interval (0, 1/3).",
        ),
    ],
)
@pytest.mark.slow  # a headless QGIS session
def test_bad_parameter_one_readable_error(qgis, name, message):
    res = qgis["scenarios"][name]
    assert not res["ok"] and res["error"] is None  # reported, not raised, as in the dialog
    assert res["reported_errors"] == [message]
    assert not any("Traceback" in text for _, text in res["log"])


@pytest.mark.slow  # a headless QGIS session
def test_curvesmith_not_found(qgis, data):
    res = qgis["scenarios"]["not_found_setting"]
    missing = str(data["dir"] / "no-such-env")
    assert res["reported_errors"] == [f"{runner.NOT_FOUND} (no curvesmith program at {missing!r})"]
    res = qgis["scenarios"]["not_found_path"]
    assert res["reported_errors"] == [f"{runner.NOT_FOUND} (not on PATH)"]


@pytest.mark.slow  # a headless QGIS session
def test_path_from_processing_options(qgis, data):
    """The setting may name the virtual environment; curvesmith need not be on PATH."""
    res = qgis["scenarios"]["setting_venv"]
    command = next(line[1] for line in res["log"] if line[0] == "command")
    assert command.startswith(str((VENV_BIN / "curvesmith").resolve()) + " smooth ")
    assert "--method chaikin" in command
    assert res["ok"] and res["output_layer"]["count"] == len(data["counties"])


@pytest.fixture(scope="session")
def qgis_process(qgis_python):
    """Debian's qgis_process program (its wrapper script passes an option the program
    refuses, so the program itself when it is there)."""
    for name in ("qgis_process.bin", "qgis_process"):
        found = shutil.which(name) or shutil.which(name, path="/usr/bin")
        if found:
            return found
    pytest.fail("QGIS is installed but qgis_process is not")


@pytest.mark.slow  # a headless QGIS session
def test_qgis_process_with_the_built_zip(qgis_process, data, tmp_path):
    """The zip installed as a user installs it; qgis_process runs the algorithm headless.

    curvesmith is found on PATH through a link to its program only: an embedded Python
    (qgis_process, QGIS) with a virtual environment's ``bin`` first on PATH takes that
    environment's Python for its own and fails to start.
    """
    plugins = tmp_path / "plugins"
    with zipfile.ZipFile(_build_zip(tmp_path / "dist")) as zf:
        zf.extractall(plugins)
    links = tmp_path / "bin"
    links.mkdir()
    (links / "curvesmith").symlink_to(CLI_BIN / "curvesmith")
    env = _clean_env(tmp_path)
    env.update(QGIS_PLUGINPATH=str(plugins), PATH=f"{links}{os.pathsep}/usr/bin{os.pathsep}/bin")

    def run(*args):
        return subprocess.run(
            [qgis_process, *args], env=env, capture_output=True, text=True, timeout=300
        )

    enabled = run("plugins", "enable", "curvesmith_qgis")
    assert enabled.returncode == 0 and "* curvesmith_qgis" in enabled.stdout
    out = tmp_path / "out.gpkg"
    args = [f"INPUT={data['paths']['counties']}", f"OUTPUT={out}", "ITERATIONS=1"]
    proc = run("--json", "run", "curvesmith:smoothcoverage", "--", *args)
    assert proc.returncode == 0, proc.stderr
    assert json.loads(proc.stdout)["results"]["OUTPUT"] == str(out)
    src, res = data["counties"], _read(out)
    assert res["GEOID"].tolist() == src["GEOID"].tolist()
    _check_areas(res, src)
    assert shapely.coverage_is_valid(res.geometry.values)
    # an error: exit status 1 and curvesmith's line, no traceback
    proc = run("run", "curvesmith:smooth", "--", *args[:2], "ALPHA=abc")
    assert proc.returncode == 1
    assert (
        "curvesmith: Invalid value for '--alpha': 'abc' is neither 'regular' nor a number."
        in proc.stdout + proc.stderr
    )
    assert "Traceback" not in proc.stdout + proc.stderr


@pytest.mark.slow  # a headless QGIS session
def test_geographic_layer_warning_and_equal_area(qgis, data):
    """Data in degrees: curvesmith's warning reaches the log as a warning; with EQUAL_AREA it
    smooths in an equal-area projection and the output is in the input's CRS again."""
    src = data["degrees"]
    plain, ea = _ran(qgis, "degrees"), _ran(qgis, "degrees_equal_area")
    warnings = [text for kind, text in plain["log"] if kind == "warning"]
    assert len(warnings) == 1 and "geographic CRS" in warnings[0] and "--equal-area" in warnings[0]
    assert not [text for kind, text in ea["log"] if kind == "warning"]
    for res in (plain, ea):
        out = _read(res["output"])
        assert res["output_layer"]["crs"] == "EPSG:4269" and out.crs.equals(src.crs)
        assert out["GEOID"].tolist() == src["GEOID"].tolist()
        assert shapely.is_valid(out.geometry.values).all()
    # areas in degrees are what the plain run keeps; ground areas, what the equal-area run keeps
    plain_out = _read(plain["output"])
    assert (
        np.abs(shapely.area(plain_out.geometry.values) / shapely.area(src.geometry.values) - 1)
        < 1e-9
    ).all()
    ground = lambda df: df.to_crs(CRS).area.to_numpy()  # noqa: E731
    ea_change = np.abs(ground(_read(ea["output"])) / ground(src) - 1).max()
    plain_change = np.abs(ground(plain_out) / ground(src) - 1).max()
    # measured: 9.9e-7 (segments are straight in the projection, not in degrees) and 2.0e-5
    assert ea_change < 2e-6 and plain_change > 10 * ea_change
