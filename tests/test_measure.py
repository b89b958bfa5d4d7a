"""``curvesmith measure``: all curves of a file measured at once, equal to the single-curve functions.

The batch computation (``measure_ragged``) is checked against a plain per-curve reference made
of :func:`curvesmith.geometry.curve_length`, :func:`~curvesmith.geometry.signed_area` and
:func:`~curvesmith.geometry.turning_angles` over random batches that mix sizes, closed and open
curves, repeated vertices, polylines that come back to their start and 3D curves; the layer
reader (``curve_table``) against shapely's own accessors on layers with every geometry kind.
"""

import contextlib
import json
from pathlib import Path

import geopandas as gpd
import numpy as np
import pytest
import shapely
from click.testing import CliRunner
from hypothesis import given
from hypothesis import strategies as st

from curvesmith import geometry, internals
from curvesmith.cli import main
from curvesmith.errors import CurveError

EPS = np.finfo(float).eps


def reference(points: np.ndarray, closed: bool) -> dict:
    """One curve measured by the single-curve functions (the measure command of old)."""
    keep = np.ones(len(points), dtype=bool)
    keep[1:] = np.any(points[1:] != points[:-1], axis=1)
    q = points[keep]
    if closed and len(q) > 1 and np.array_equal(q[0], q[-1]):
        q = q[:-1]
    row = {
        "length": geometry.curve_length(points, closed=closed),
        "signed_area": None,
        "min": None,
        "max": None,
        "zero": int((~keep).sum()),
    }
    if points.shape[1] == 2 and len(q) >= 3:
        with contextlib.suppress(CurveError):  # A B A: nothing is enclosed
            row["signed_area"] = geometry.signed_area(q)
        t = geometry.turning_angles(q, closed=closed)
        row["min"], row["max"] = float(t.min()), float(t.max())
    return row


def random_curve(rng: np.random.Generator) -> tuple[np.ndarray, bool]:
    closed = bool(rng.random() < 0.5)
    n = int(rng.choice([2, 3, 4, 5, 8, 13, 40, 200])) + (1 if closed else 0)
    scale = float(10.0 ** rng.integers(-6, 7))
    shift = float(rng.choice([0.0, 1e3, 5e6])) * (scale >= 1)
    dim = 3 if rng.random() < 0.15 else 2
    p = rng.normal(size=(n, dim)) * scale + shift
    if rng.random() < 0.3:  # repeated vertices, as digitising leaves them
        at = rng.integers(0, n, size=rng.integers(1, 4))
        p = np.insert(p, at, p[at], axis=0)
    if not closed and rng.random() < 0.2:  # an open polyline that comes back to its start
        p = np.vstack([p, p[:1]])
    if rng.random() < 0.05:
        p = np.array([p[0], p[1], p[0]])  # A B A
    return p, closed


def _batch(curves):
    dims = np.array([p.shape[1] for p, _ in curves])
    n = np.array([len(p) for p, _ in curves])
    coords = np.zeros((int(n.sum()), 3))
    at = 0
    for p, _ in curves:
        coords[at : at + len(p), : p.shape[1]] = p
        at += len(p)
    offsets = np.concatenate([[0], np.cumsum(n)])
    closed = np.array([c for _, c in curves])
    return coords, offsets, closed, dims


def _check(curves):
    m = internals.measure_ragged(*_batch(curves))
    for k, (p, closed) in enumerate(curves):
        ref = reference(p, closed)
        assert m.points[k] == len(p)
        assert m.zero_length_edges[k] == ref["zero"]
        # the same edge lengths, summed in another order: a few ulps of the sum
        assert m.length[k] == pytest.approx(ref["length"], rel=len(p) * EPS, abs=1e-300)
        if ref["signed_area"] is None:
            assert not m.has_area[k] and np.isnan(m.signed_area[k])
        else:
            assert m.has_area[k]
            # the same shoelace terms about the first vertex; the bound is on the terms' sum
            q = p[:, :2] - p[0, :2]
            bound = len(p) * EPS * float(np.abs(q).max()) ** 2 * len(p)
            assert abs(m.signed_area[k] - ref["signed_area"]) <= bound
        if ref["min"] is None:
            assert not m.has_turning[k]
        else:  # the same floating-point operations on the same numbers: bit for bit
            assert m.has_turning[k]
            assert m.min_turning_angle[k] == ref["min"]
            assert m.max_turning_angle[k] == ref["max"]


@pytest.mark.parametrize("seed", range(12))
def test_measure_ragged_equals_the_single_curve_functions(seed):
    rng = np.random.default_rng(seed)
    curves = [random_curve(rng) for _ in range(int(rng.integers(1, 120)))]
    _check(curves)


@given(st.integers(0, 2**32 - 1), st.integers(1, 30))
def test_measure_ragged_property(seed, k):
    rng = np.random.default_rng(seed)
    _check([random_curve(rng) for _ in range(k)])


def test_measure_ragged_known_values():
    square = np.array([[0, 0], [4, 0], [4, 4], [0, 4]], float)
    zigzag = np.array([[0, 0], [1, 1], [2, 0], [3, 1], [4, 0]], float)
    helix = np.c_[np.cos(np.arange(5)), np.sin(np.arange(5)), np.arange(5)]
    curves = [(square, True), (zigzag, False), (square[::-1], True), (helix, False)]
    m = internals.measure_ragged(*_batch(curves))
    np.testing.assert_array_equal(m.length[:3], [16.0, 4 * np.sqrt(2), 16.0])
    np.testing.assert_array_equal(m.signed_area[:3], [16.0, -2.0, -16.0])
    assert m.min_turning_angle[0] == m.max_turning_angle[0] == pytest.approx(np.pi / 2)
    assert m.min_turning_angle[1] == pytest.approx(-np.pi / 2)
    assert m.max_turning_angle[1] == pytest.approx(np.pi / 2)
    assert m.min_turning_angle[2] == pytest.approx(-np.pi / 2)
    assert not m.has_turning[3] and not m.has_area[3]  # a 3D curve: its length only
    assert m.length[3] == pytest.approx(4 * np.sqrt(2 - 2 * np.cos(1) + 1))


def test_measure_ragged_empty_batch():
    m = internals.measure_ragged(np.zeros((0, 3)), np.zeros(1, int), np.zeros(0, bool), [])
    assert len(m.length) == 0 and len(m.has_area) == 0


# ----------------------------------------------------------------------------------------------
# the layer as curves


MIXED = [
    "POLYGON((0 0, 10 0, 10 10, 0 10, 0 0),(2 2, 2 4, 4 4, 4 2, 2 2))",
    "MULTIPOLYGON(((0 0, 1 0, 1 1, 0 0)),((5 5, 6 5, 6 6, 5 6, 5 5)))",
    None,
    "POINT(1 2)",
    "LINESTRING Z(0 0 0, 1 1 1, 2 0 3)",
    "LINESTRING(0 0, 1 0, 1 1, 0 0)",  # ends where it starts: a ring
    "LINESTRING(0 0, 1 0, 0 0)",  # A B A: no area
    "LINESTRING(0 0, 0 0, 1 0, 1 0, 2 3)",
    "MULTILINESTRING((0 0, 1 1),(2 2, 3 5, 4 4))",
    "GEOMETRYCOLLECTION(POINT(0 0), LINESTRING(0 0, 3 1, 4 4), POLYGON((0 0, 4 0, 4 4, 0 0)))",
    "POLYGON EMPTY",
    "MULTIPOINT(0 0, 1 1)",
    "POLYGON((0 0, 10 0, 10 10, 10 10, 0 10, 0 0))",
]


def mixed_frame():
    geoms = [None if w is None else shapely.from_wkt(w) for w in MIXED]
    return gpd.GeoDataFrame({"name": [f"f{i}" for i in range(len(geoms))]}, geometry=geoms)


def test_curve_table_numbers_the_curves_like_the_geojson_model():
    t = internals.geo_io.curve_table(mixed_frame())
    rows = list(
        zip(t.feature.tolist(), t.part.tolist(), t.ring.tolist(), t.member.tolist(), strict=True)
    )
    assert rows == [
        (0, 0, 0, -1), (0, 0, 1, -1), (1, 0, 0, -1), (1, 1, 0, -1), (4, 0, 0, -1),
        (5, 0, 0, -1), (6, 0, 0, -1), (7, 0, 0, -1), (8, 0, 0, -1), (8, 1, 0, -1),
        (9, 0, 0, 1), (9, 0, 0, 2), (12, 0, 0, -1),
    ]  # fmt: skip
    assert t.kind[[0, 2, 4, 8, 10, 11]].tolist() == [
        "Polygon", "MultiPolygon", "LineString", "MultiLineString", "LineString", "Polygon",
    ]  # fmt: skip
    assert t.n_without == 4  # NULL, Point, empty, MultiPoint
    assert t.closed.tolist() == [True] * 4 + [False, True] + [False] * 5 + [True, True]
    assert t.dims.tolist() == [2] * 4 + [3] + [2] * 8
    # rings without their repeated closing vertex; the rest as shapely holds them
    n = np.diff(t.offsets).tolist()
    assert n == [4, 4, 3, 4, 3, 3, 3, 5, 2, 3, 3, 3, 5]
    np.testing.assert_array_equal(t.coords[t.offsets[4] : t.offsets[5]], [[0, 0, 0], [1, 1, 1],
                                                                          [2, 0, 3]])  # fmt: skip


def test_curve_table_of_a_real_layer_matches_shapely(naturalearth):
    df = gpd.read_file(naturalearth)
    t = internals.geo_io.curve_table(df)
    expected = []
    for g in df.geometry:
        for poly in getattr(g, "geoms", [g]):
            for ring in [poly.exterior, *poly.interiors]:
                expected.append(np.asarray(ring.coords)[:-1])
    assert len(expected) == len(t.closed) and t.closed.all()
    for k, ring in enumerate(expected):
        np.testing.assert_array_equal(t.coords[t.offsets[k] : t.offsets[k + 1], :2], ring)


def test_curve_table_refuses_a_coordinate_that_is_not_finite():
    with np.errstate(invalid="ignore"):
        geoms = [shapely.box(0, 0, 1, 1), shapely.LineString([(0, 0), (np.inf, 1), (2, 2)])]
    with pytest.raises(CurveError, match=r"zones: feature 1 has a coordinate that is not finite"):
        internals.geo_io.curve_table(np.array(geoms, dtype=object), name="zones")


# ----------------------------------------------------------------------------------------------
# the command


@pytest.fixture
def naturalearth():
    import pyogrio

    fixtures = Path(pyogrio.__file__).parent / "tests" / "fixtures"
    path = fixtures / "naturalearth_lowres" / "naturalearth_lowres.shp"
    if not path.exists():
        pytest.skip("pyogrio's test fixture is not installed")
    return path


@pytest.mark.parametrize("suffix", [".gpkg", ".geojson"])
def test_measure_command_on_every_geometry_kind(tmp_path, suffix):
    # the GIS reader (.gpkg) and curvesmith.io (.geojson) give the same rows
    src = tmp_path / f"mixed{suffix}"
    mixed_frame().set_crs("EPSG:32633").to_file(src)
    res = CliRunner().invoke(main, ["measure", str(src), "--json"])
    assert res.exit_code == 0, res.output
    rows = json.loads(res.stdout)["curves"]
    assert len(rows) == 13 and res.stderr.strip() == (
        "4 feature(s) without a curve geometry (NULL, empty, Point, MultiPoint) not measured"
    )
    by = {(r["feature"], r["part"], r["ring"], r["member"]): r for r in rows}
    assert by[(0, 0, 1, None)]["signed_area"] == -4.0  # the hole, clockwise
    assert by[(6, 0, 0, None)]["signed_area"] is None  # A B A
    assert by[(6, 0, 0, None)]["max_turning_angle"] == pytest.approx(np.pi)
    assert by[(9, 0, 0, 2)]["signed_area"] == 8.0 and by[(9, 0, 0, 2)]["closed"] is True
    assert by[(7, 0, 0, None)]["zero_length_edges"] == 2
    assert by[(4, 0, 0, None)]["dimension"] == 3
    assert by[(4, 0, 0, None)]["length"] == pytest.approx(np.sqrt(3) + np.sqrt(6))
    assert by[(12, 0, 0, None)]["points"] == 5 and by[(12, 0, 0, None)]["signed_area"] == 100
    table = CliRunner().invoke(main, ["measure", str(src)]).stdout.splitlines()
    assert table[11].endswith("feature 9 member 1") and table[4].endswith("feature 1 part 1")


def test_measure_command_json_is_one_curve_per_line(tmp_path, naturalearth):
    res = CliRunner().invoke(main, ["measure", str(naturalearth), "--json"])
    assert res.exit_code == 0, res.output
    lines = res.stdout.splitlines()
    data = json.loads(res.stdout)
    assert len(lines) == len(data["curves"]) + 2
    assert json.loads(lines[1].rstrip(",")) == data["curves"][0]
    df = gpd.read_file(naturalearth)
    total = np.zeros(len(df))
    for r in data["curves"]:  # shells less holes: the polygons' areas
        total[r["feature"]] += abs(r["signed_area"]) * (1 if r["ring"] == 0 else -1)
    np.testing.assert_allclose(total, shapely.area(df.geometry.values), rtol=1e-12)


def test_measure_command_layer(tmp_path):
    src = tmp_path / "two.gpkg"
    gpd.GeoDataFrame(geometry=[shapely.box(0, 0, 1, 1)], crs="EPSG:3857").to_file(
        src, layer="small"
    )
    gpd.GeoDataFrame(geometry=[shapely.box(0, 0, 3, 3)] * 2, crs="EPSG:3857").to_file(
        src, layer="big"
    )
    for layer in ("big", "1"):
        res = CliRunner().invoke(main, ["measure", str(src), "--layer", layer, "--json"])
        assert res.exit_code == 0, res.output
        assert [r["signed_area"] for r in json.loads(res.stdout)["curves"]] == [9.0, 9.0]
    res = CliRunner().invoke(main, ["measure", str(src)])
    assert res.stderr.startswith("Warning: two.gpkg has 2 layers with geometries")
    assert "--layer" in res.stderr and len(res.stderr.splitlines()) == 1
    res = CliRunner().invoke(main, ["measure", str(src), "--layer", "lakes"])
    assert res.exit_code == 1 and "lakes" in res.stderr
    csv = tmp_path / "sq.csv"
    csv.write_text("x,y\n0,0\n1,0\n1,1\n")
    res = CliRunner().invoke(main, ["measure", str(csv), "--layer", "big"])
    assert res.exit_code == 2 and "--layer is for GIS files" in res.stderr


def test_measure_command_names_a_bad_coordinate(tmp_path):
    src = tmp_path / "nan.gpkg"
    with np.errstate(invalid="ignore"):
        geoms = [shapely.box(0, 0, 1, 1), shapely.LineString([(0, 0), (np.nan, 1), (2, 2)])]
        gpd.GeoDataFrame(geometry=geoms, crs="EPSG:3857").to_file(src)
    res = CliRunner().invoke(main, ["measure", str(src)])
    assert res.exit_code == 1 and res.stdout == ""
    assert (
        res.stderr == f"Error: {src}: feature 1 has a coordinate that is not finite: [nan, 1.0]\n"
    )


def test_measure_command_refuses_an_overflow(tmp_path):
    src = tmp_path / "big.gpkg"
    big = [shapely.box(0, 0, 1, 1), shapely.box(0, 0, 1e200, 1e200)]
    gpd.GeoDataFrame(geometry=big, crs="EPSG:3857").to_file(src)
    res = CliRunner().invoke(main, ["measure", str(src)])
    assert res.exit_code == 1 and res.stdout == ""
    assert res.stderr.startswith(f"Error: curve 1 of {src}: length, signed_area overflow (inf)")
