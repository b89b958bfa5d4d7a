"""The table of smoothing methods: every row tells the truth, and every front end reads it."""

from __future__ import annotations

import numpy as np
import pytest
from click.testing import CliRunner

from curvesmith import CurveError, cca, geometry, methods, subdivision
from curvesmith.cli import main

RNG = np.random.default_rng(20261202)

# the method's own keywords for the comparisons below
PARAMS = {
    "cca": {"alpha": "regular"},
    "chaikin": {"preserve_endpoints": True},
    "derham": {"gamma": 3.0, "preserve_endpoints": True},
    "lane_riesenfeld": {"degree": 3, "preserve_endpoints": True},
}
DIRECT = {
    "cca": cca.smooth,
    "chaikin": subdivision.chaikin,
    "derham": subdivision.de_rham,
    "lane_riesenfeld": subdivision.lane_riesenfeld,
}


def blob(n: int, scale: float = 1.0, noise: float = 0.2) -> np.ndarray:
    """A star-shaped CCW polygon of n vertices with uneven radii and spacing."""
    t = np.sort(RNG.uniform(0, 2 * np.pi, n))
    r = 1.0 + noise * RNG.standard_normal(n).clip(-2, 2)
    return scale * np.c_[r * np.cos(t), r * np.sin(t)]


def test_every_front_end_lists_the_table():
    cmd = main.commands["smooth"]
    choice = next(p for p in cmd.params if p.name == "method").type.choices
    assert tuple(choice) == tuple(methods.METHODS)
    for cmd in (main.commands["batch"].commands["smooth"], main.commands["contours"]):
        opt = next(p for p in cmd.params if p.name == "method")
        assert tuple(opt.type.choices) == methods.gis_names()
    assert methods.gis_names() == ("cca", "chaikin")
    assert set(PARAMS) == set(methods.METHODS)


@pytest.mark.parametrize("name", list(methods.METHODS))
@pytest.mark.parametrize("closed", [True, False])
def test_the_row_calls_the_function(name, closed):
    m = methods.get(name)
    p = blob(11, scale=250.0)
    want = DIRECT[name](p, closed=closed, iterations=2, **PARAMS[name])
    got = m.smooth(p, closed=closed, iterations=2, **PARAMS[name])
    np.testing.assert_array_equal(got, want)


@pytest.mark.parametrize("name", list(methods.METHODS))
def test_ragged_equals_one_curve_at_a_time_bit_for_bit(name):
    m = methods.get(name)
    curves = [
        blob(int(n), scale=float(s))
        for n, s in zip([5, 9, 40, 6, 17], [1e-3, 1, 50, 1e5, 3], strict=True)
    ]
    closed = np.array([True, False, True, False, True])
    off = np.r_[0, np.cumsum([len(c) for c in curves])]
    xy, oo = m.smooth_ragged(
        np.concatenate(curves), off, closed=closed, iterations=2, **PARAMS[name]
    )
    assert len(oo) == len(curves) + 1
    for k, c in enumerate(curves):
        one = m.smooth(c, closed=bool(closed[k]), iterations=2, **PARAMS[name])
        np.testing.assert_array_equal(xy[oo[k] : oo[k + 1]], one)


@pytest.mark.parametrize("name", list(methods.METHODS))
def test_keeps_area_is_true_exactly_when_the_areas_stay(name):
    m = methods.get(name)
    p = blob(23, scale=1000.0)
    a0 = geometry.signed_area(p)
    a1 = geometry.signed_area(m.smooth(p, closed=True, iterations=3, **PARAMS[name]))
    if m.keeps_area:
        assert abs(a1 - a0) <= 1e-12 * abs(a0)
    else:
        assert abs(a1 - a0) > 1e-3 * abs(a0)  # the linear methods shrink


@pytest.mark.parametrize("name", list(methods.METHODS))
def test_keeps_vertices_and_growth(name):
    m = methods.get(name)
    p = blob(12, scale=10.0)
    out = m.smooth(p, closed=True, iterations=1, **PARAMS[name])
    assert len(p) < len(out) <= m.growth * len(p)
    kept = [i for i in range(len(p)) if (out == p[i]).all(axis=1).any()]
    if m.keeps_vertices:
        fixed = m.smooth(p, closed=True, iterations=2, anchors=[0, 5], **PARAMS[name])
        for i in (0, 5):
            assert (fixed == p[i]).all(axis=1).any()
    else:
        assert kept == []  # every vertex moves
        with pytest.raises(CurveError, match="anchors applies to method 'cca'"):
            m.smooth(p, closed=True, anchors=[0])


def test_a_keyword_of_another_method_is_refused_naming_both():
    with pytest.raises(CurveError, match=r"gamma applies to method 'derham', not to method 'cca'"):
        methods.get("cca").smooth(blob(6), closed=True, gamma=2.0)
    with pytest.raises(CurveError, match=r"spin applies to no method, not to method 'chaikin'"):
        methods.get("chaikin").smooth_ragged(blob(6), [0, 6], closed=True, spin=1)


@pytest.mark.parametrize("name", ["cca", "chaikin", "derham"])
def test_close_rings_is_a_layout_of_the_ragged_call_only(name):
    # one curve has no ring layout: a CurveError (was a TypeError of the function)
    extra = {"gamma": 3.0} if name == "derham" else {}
    with pytest.raises(CurveError, match="close_rings applies to smooth_ragged"):
        methods.get(name).smooth(blob(6), closed=True, close_rings=True, **extra)
    xy, off = methods.get(name).smooth_ragged(
        blob(6), [0, 6], closed=True, close_rings=True, **extra
    )
    np.testing.assert_array_equal(xy[-1], xy[0])
    assert off.tolist() == [0, len(xy)]


def test_get_and_needs_messages():
    with pytest.raises(CurveError, match="method must be one of 'cca', 'chaikin', 'derham'"):
        methods.get("bezier")
    with pytest.raises(CurveError, match="method must be one of 'cca', 'chaikin', got 'derham'"):
        methods.get("derham", gis=True)
    methods.needs("keep_angle", "cca")
    with pytest.raises(
        CurveError, match=r"keep_angle needs method='cca' \(chaikin moves every vertex\)"
    ):
        methods.needs("keep_angle", "chaikin")


@pytest.mark.parametrize("name", list(methods.METHODS))
def test_cli_smooth_runs_every_method_like_the_table(tmp_path, name):
    p = blob(9, scale=100.0)
    src = tmp_path / "in.csv"
    src.write_text("x,y\n" + "\n".join(f"{float(x)!r},{float(y)!r}" for x, y in p) + "\n")
    out = tmp_path / "out.csv"
    extra = {"derham": ["--gamma", "3"], "lane_riesenfeld": ["--degree", "3"]}.get(name, [])
    res = CliRunner().invoke(
        main,
        ["smooth", str(src), "-o", str(out), "--method", name, "--iterations", "2", *extra],
    )
    assert res.exit_code == 0, res.output
    got = np.loadtxt(out, delimiter=",", skiprows=1)
    closed = False  # a CSV of points is an open polyline
    want = methods.get(name).smooth(p, closed=closed, iterations=2, **PARAMS[name])
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-12 * 100)


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--method", "chaikin", "--alpha", "0.2"], "--alpha applies to --method cca, not chaikin"),
        (["--gamma", "3"], "--gamma applies to --method derham, not cca"),
        (
            ["--method", "derham", "--degree", "4"],
            "--degree applies to --method lane_riesenfeld, not derham",
        ),
        (["--free-endpoints"], "--preserve-endpoints/--free-endpoints applies to --method chaikin"),
        (["--method", "lane_riesenfeld", "--keep-angle", "30"], "--keep-angle needs --method cca"),
    ],
)
def test_cli_refuses_an_option_of_another_method(tmp_path, args, message):
    src = tmp_path / "in.csv"
    src.write_text("x,y\n0,0\n4,0\n4,4\n0,4\n")
    out = tmp_path / "out.csv"
    res = CliRunner().invoke(main, ["smooth", str(src), "-o", str(out), *args])
    assert res.exit_code == 2
    assert message in res.output and "Traceback" not in res.output
    assert not out.exists()


def test_cli_accepts_another_method_option_at_its_default(tmp_path):
    """Tools that pass every option (the QGIS plugin) stay accepted."""
    src = tmp_path / "in.csv"
    src.write_text("x,y\n0,0\n4,0\n4,4\n0,4\n")
    out = tmp_path / "out.csv"
    args = ["--method", "chaikin", "--alpha", "regular", "--gamma", "2", "--degree", "3"]
    res = CliRunner().invoke(main, ["smooth", str(src), "-o", str(out), *args])
    assert res.exit_code == 0, res.output
    want = subdivision.chaikin(
        np.array([[0, 0], [4, 0], [4, 4], [0, 4]], float), closed=False, preserve_endpoints=True
    )
    np.testing.assert_array_equal(np.loadtxt(out, delimiter=",", skiprows=1), want)
