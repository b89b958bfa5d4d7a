"""A layer whose smoothing would not fit in memory is refused at once, with advice.

Each cca iteration triples the vertices. ``curvesmith smooth counties.gpkg --coverage
--iterations 10`` (62,727 vertices of Kentucky's and West Virginia's counties) asked
for 3.7 billion vertices: the process took all 24 GB of the machine and was killed by
the system after half a minute, with no message. Now every layer function predicts its
output before smoothing and refuses what exceeds ``MAX_VERTICES`` or the memory
available, naming the most iterations that fit.
"""

from __future__ import annotations

import os

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from curvesmith import CurveError, methods
from curvesmith.errors import OutputSizeError
from curvesmith.internals import validate

shapely = pytest.importorskip("shapely")
geo = pytest.importorskip("curvesmith.geo")
from curvesmith.internals import geo_coverage, geo_packets, geo_smooth  # noqa: E402

BYTES_PER_VERTEX, MAX_VERTICES = validate.BYTES_PER_VERTEX, validate.MAX_VERTICES
check_layer_growth = validate.check_layer_growth

#: the memory the tests pretend is available: a million vertices' worth
FREE = 1_000_000 * BYTES_PER_VERTEX


@pytest.fixture
def little_memory(monkeypatch):
    """A machine with `FREE` bytes available, consulted for every call."""
    monkeypatch.setattr(validate, "available_memory", lambda: FREE)
    monkeypatch.setattr(validate, "MEMORY_CHECKED", 0)


def _squares(n=200, size=100.0):
    """`n` squares side by side (a coverage): 5 coordinates each, 1000 in all for 200."""
    return np.array([shapely.box(i * size, 0.0, (i + 1) * size, size) for i in range(n)])


def test_most_iterations_named():
    with pytest.raises(CurveError) as err:
        check_layer_growth(1000, 17, 3)
    text = str(err.value)
    # 1000 * 3**10 = 59 M fit in MAX_VERTICES (134 M); 3**11 does not
    assert "iterations 17 would turn 1000 vertices into up to 1.29e+11 (x3 per iteration)" in text
    assert f"one call holds at most {MAX_VERTICES}" in text
    assert "use at most 10 iteration(s)" in text
    check_layer_growth(1000, 10, 3)  # fits
    check_layer_growth(10**9, 40, 1)  # a method that does not grow
    check_layer_growth(0, 40, 3)


def test_levels_held_at_once(little_memory):
    # every level up to k held: 1000 * 3**k * 3/2 vertices; 3**5 * 1500 = 364,500 fit
    # into a million, 3**6 * 1500 = 1,093,500 does not
    with pytest.raises(CurveError, match=r"use at most 5 iteration"):
        check_layer_growth(1000, 6, 3, levels=True)
    check_layer_growth(1000, 6, 3)  # 729,000 alone fits
    with pytest.raises(CurveError, match=r"use at most 6 iteration"):
        check_layer_growth(1000, 7, 3)


def test_memory_named(little_memory):
    with pytest.raises(CurveError) as err:
        check_layer_growth(1000, 7, 3, what="vertices of 200 feature(s)")
    text = str(err.value)
    assert "1000 vertices of 200 feature(s) into up to 2.19e+06" in text
    assert "about 0.14 GB of memory (0.064 GB available)" in text
    assert "one call holds at most 1000000 here: use at most 6 iteration(s)" in text


@pytest.mark.parametrize(
    ("call", "most"),
    [
        (lambda g, k: geo.smooth(g, iterations=k), 6),
        (lambda g, k: geo.smooth(g, iterations=k, method="chaikin"), 9),  # x2: 1000 * 2**9
        (lambda g, k: geo.smooth(g, iterations=k, min_segment=1.0), 5),  # levels
        (lambda g, k: geo.smooth(g, iterations=k, max_shift=5.0), 5),
        (lambda g, k: geo.smooth_coverage(g, iterations=k), 6),
        (lambda g, k: geo.smooth_coverage(g, iterations=k, min_segment=1.0), 5),
        (lambda g, k: geo.smooth_network(shapely.boundary(g), iterations=k), 6),
        (lambda g, k: geo_smooth.smooth_to_packet(g, iterations=k), 6),
    ],
    ids=[
        "smooth",
        "smooth-chaikin",
        "smooth-min_segment",
        "smooth-max_shift",
        "coverage",
        "coverage-min_segment",
        "network",
        "packet",
    ],
)
def test_layer_functions_refuse_before_smoothing(little_memory, call, most):
    squares = _squares()
    with pytest.raises(CurveError, match=rf"use at most {most} iteration\(s\)"):
        call(squares, most + 1)
    out = call(squares, most)  # the advice is right: that many fit
    assert out is not None


def test_contours_refused(little_memory):
    z = np.add.outer(np.sin(np.linspace(0, 6, 60)), np.cos(np.linspace(0, 6, 60)))
    with pytest.raises(CurveError, match=r"iterations 12 would turn"):
        geo.contours(z, levels=[0.0, 0.5], iterations=12)


def test_cli_one_line_no_output(little_memory, runner, tmp_path):
    import geopandas as gpd

    src, out = tmp_path / "squares.gpkg", tmp_path / "out.gpkg"
    gpd.GeoDataFrame({"k": range(200)}, geometry=_squares(), crs="EPSG:32633").to_file(src)
    res = runner.invoke(
        __import__("curvesmith.cli", fromlist=["main"]).main,
        ["smooth", str(src), "-o", str(out), "--coverage", "--iterations", "8"],
    )
    assert res.exit_code == 1, res.output
    lines = res.output.strip().splitlines()
    assert len(lines) == 1 and "use at most 6 iteration(s)" in lines[0], res.output
    assert "Traceback" not in res.output
    assert not out.exists() and sorted(p.name for p in tmp_path.iterdir()) == ["squares.gpkg"]


def test_real_counties_beyond_max_vertices():
    """Not a pretend machine: 62,727 vertices, 10 iterations, 3.7 billion: refused at once."""
    counties = geo.us_counties(states=["21", "54"])
    n = int(shapely.get_num_coordinates(counties.geometry.values).sum())
    with pytest.raises(CurveError) as err:
        geo.smooth_coverage(counties.geometry.values, iterations=10)
    most = max(k for k in range(11) if n * 3**k <= MAX_VERTICES)
    assert f"use at most {most} iteration(s)" in str(err.value)
    assert f"{n} vertices of {len(counties)} feature(s)" in str(err.value)


def test_available_memory_is_the_machines():
    free = validate.available_memory()
    if not os.path.exists("/proc/meminfo"):
        pytest.skip("no /proc/meminfo: the memory available is not known here")
    total = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    assert free is not None and 0 < free <= total


@st.composite
def _layers(draw):
    """Polygons with and without holes, multi-parts and lines, uneven vertex counts."""
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    geoms = []
    for _ in range(draw(st.integers(1, 12))):
        n = int(rng.integers(5, 40))
        t = (np.arange(n) + rng.uniform(0, 0.8, n)) * (2 * np.pi / n)  # star-shaped, simple
        r = rng.uniform(50, 100, n)
        c = rng.uniform(-1e4, 1e4, 2)
        ring = c + np.c_[r * np.cos(t), r * np.sin(t)]
        kind = draw(st.sampled_from(["polygon", "holed", "line", "multi"]))
        if kind == "line":
            geoms.append(shapely.LineString(ring))
        elif kind == "holed":
            hole = c + 10 * np.c_[np.cos(t[::-1]), np.sin(t[::-1])]
            geoms.append(shapely.Polygon(ring, [hole]))
        elif kind == "multi":
            geoms.append(shapely.MultiPolygon([shapely.Polygon(ring), shapely.Polygon(ring + 500)]))
        else:
            geoms.append(shapely.Polygon(ring))
    return np.array(geoms, dtype=object)


@settings(max_examples=40, deadline=None)
@given(_layers(), st.sampled_from(["cca", "chaikin"]), st.integers(1, 3))
def test_prediction_bounds_the_output(geoms, method, iterations):
    """What the check predicts (input vertices times growth**iterations) bounds the output."""
    out = geo.smooth(geoms, method=method, iterations=iterations)
    n_in = int(shapely.get_num_coordinates(geoms).sum())
    n_out = int(shapely.get_num_coordinates(np.asarray(out, dtype=object)).sum())
    assert n_out <= n_in * methods.get(method, gis=True).growth ** iterations


def test_batch_refuses_in_the_client(little_memory):
    """The client gathers the whole output: refused before a worker starts."""
    from curvesmith import batch

    with pytest.raises(OutputSizeError, match=r"use at most 6 iteration\(s\)"):
        batch.smooth_partitioned(_squares(), iterations=7, workers=1, partition_size=10)


def test_partition_not_retried_feature_by_feature(little_memory):
    """A partition too large is refused as a whole: one by one, the same output in all."""
    from curvesmith.internals import batch_smooth_partition

    holed = np.array([shapely.box(0, 0, 1e3, 1e3).difference(s) for s in _squares(20, 40.0)])
    options = {"method": "cca", "iterations": 9, "alpha": "regular", "make_valid": False}
    with pytest.raises(OutputSizeError):
        batch_smooth_partition(geo_packets.pack(holed), 0, options)


def test_arcs_not_retried_one_by_one(monkeypatch):
    """The coverage's arcs in one engine call beyond MAX_VERTICES: refused, not split."""
    monkeypatch.setattr(validate, "MAX_VERTICES", 1000)
    arcs = [np.c_[np.linspace(0, 10, 20), np.sin(np.linspace(0, 3, 20)) + k] for k in range(10)]
    loops, frozen = np.zeros(10, dtype=bool), np.zeros(10, dtype=bool)
    with pytest.raises(OutputSizeError):
        geo_coverage.smooth_arc_blocks(
            arcs, loops, frozen, method="cca", iterations=2, alpha="regular"
        )


def test_equal_area_regions_checked_as_one_layer(little_memory, tmp_path):
    """--equal-area smooths region by region but holds every region's output at the end."""
    import geopandas as gpd

    # 2 x 100 squares of 0.1 degree, 1000 vertices, in two regions far apart
    west = [shapely.box(-100 + i * 0.1, 40, -100 + (i + 1) * 0.1, 40.1) for i in range(100)]
    east = [shapely.box(100 + i * 0.1, 40, 100 + (i + 1) * 0.1, 40.1) for i in range(100)]
    src = tmp_path / "two.gpkg"
    gpd.GeoDataFrame(geometry=west + east, crs="EPSG:4326").to_file(src)
    with pytest.raises(OutputSizeError, match=r"into up to 2.19e\+06"):
        geo.smooth_file(src, tmp_path / "out.gpkg", equal_area=True, iterations=7)
    assert not (tmp_path / "out.gpkg").exists()
