"""Tests of curvesmith.io: CSV, GeoJSON and SVG readers and writers.

Fixtures in tests/data/io/ are hand-written (see the README there); expected values below are
derived from their coordinates by hand or from analytic geometry (circles, ellipses, Bézier
curves evaluated in the test).
"""

import io
import json
import math
import warnings
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from curvesmith.errors import CurveError, CurveFormatError
from curvesmith.io import (
    FORMATS,
    Curve,
    detect_format,
    read_csv,
    read_curves,
    read_geojson,
    read_svg,
    write_csv,
    write_curves,
    write_geojson,
    write_svg,
)
from oracles import exact_area_sign

DATA = Path(__file__).parent / "data" / "io"


def text(s: str) -> io.StringIO:
    return io.StringIO(s)


def roundtrip(writer, reader, curves, **kw):
    buf = io.StringIO()
    writer(curves, buf, **kw)
    return reader(io.StringIO(buf.getvalue())), buf.getvalue()


def bits_equal(a, b) -> bool:
    """Bit-identical float arrays (distinguishes -0.0 from 0.0)."""
    a, b = np.asarray(a, dtype=np.float64), np.asarray(b, dtype=np.float64)
    return a.shape == b.shape and np.array_equal(a.view(np.int64), b.view(np.int64))


def structure(c: Curve):
    return (c.closed, c.feature, c.member, c.part, c.ring, c.kind, c.properties, c.feature_id)


def signed_area(p) -> float:
    x, y = np.asarray(p)[:, 0], np.asarray(p)[:, 1]
    return 0.5 * float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))


def distance_to_polyline(samples, poly, closed):
    """Plain reference: distance of each sample point to the nearest edge of the polyline."""
    a = np.asarray(poly)
    b = np.roll(a, -1, axis=0) if closed else a[1:]
    a = a if closed else a[:-1]
    d = b - a
    rel = samples[:, None, :] - a[None, :, :]
    t = np.clip(np.sum(rel * d, axis=2) / np.sum(d * d, axis=1), 0.0, 1.0)
    nearest = a[None] + t[..., None] * d[None]
    return np.min(np.linalg.norm(samples[:, None, :] - nearest, axis=2), axis=1)


# ------------------------------------------------------------------------------------------------
# Curve


def test_curve_drops_closing_vertex_and_is_read_only():
    c = Curve([[0, 0], [1, 0], [0, 1], [0, 0]], closed=True, kind="Polygon")
    assert c.points.tolist() == [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]
    assert c.points.dtype == np.float64
    with pytest.raises(ValueError, match="read-only"):
        c.points[0, 0] = 5.0
    d = c.replace(c.points * 2)
    assert d.points.tolist() == [[0.0, 0.0], [2.0, 0.0], [0.0, 2.0]]
    assert structure(d) == structure(c)
    assert c.points[1, 0] == 1.0


def test_curve_replace_changes_fields():
    c = Curve([[0, 0], [1, 0]], closed=False, properties={"a": 1}, feature=3)
    d = c.replace(closed=True, points=[[0, 0], [1, 0], [1, 1]], kind="Polygon")
    assert (d.closed, d.kind, d.feature, d.properties) == (True, "Polygon", 3, {"a": 1})
    assert c.properties is not d.properties or c.properties == {"a": 1}


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"points": [[0, 0], [1, 0]], "closed": False, "kind": "Triangle"}, "kind must be one of"),
        (
            {"points": [[0, 0], [1, 0], [1, 1]], "closed": False, "kind": "Polygon"},
            "must be closed",
        ),
        ({"points": [[0, 0], [1, 0]], "closed": True}, "at least 3 distinct ring points, got 2"),
        ({"points": [[0, 0]], "closed": False}, "at least 2 points, got 1"),
        ({"points": [[0, 0], [1, 0]], "closed": "yes"}, "closed must be True or False"),
        (
            {"points": [[0, 0], [1, 0]], "closed": False, "feature": -1},
            "feature must be an integer",
        ),
        (
            {"points": [[0, 0], [1, 0]], "closed": False, "part": 1},
            "part must be 0 for a LineString",
        ),
        ({"points": [[0, 0, 0, 0], [1, 0, 0, 0]], "closed": False}, r"shape \(N, 2\) or \(N, 3\)"),
        ({"points": [[0, np.nan], [1, 0]], "closed": False}, "must be finite"),
        ({"points": [[0, 0], [1, 0]], "closed": False, "properties": [1]}, "must be a mapping"),
    ],
)
def test_curve_rejects_bad_fields(kwargs, message):
    with pytest.raises(CurveError, match=message):
        Curve(**kwargs)


# ------------------------------------------------------------------------------------------------
# formats


@pytest.mark.parametrize(
    ("name", "fmt"),
    [
        ("a.csv", "csv"),
        ("a.TXT", "csv"),
        ("dir.v2/a.geojson", "geojson"),
        ("a.json", "geojson"),
        ("A.SVG", "svg"),
    ],
)
def test_detect_format_from_suffix(name, fmt):
    assert detect_format(name) == fmt
    assert fmt in FORMATS


def test_detect_format_explicit_wins_and_is_checked():
    assert detect_format("a.csv", "SVG") == "svg"
    assert detect_format("a.csv", "json") == "geojson"
    with pytest.raises(
        CurveFormatError, match="format must be one of csv, geojson, svg, got 'shp'"
    ):
        detect_format("a.csv", "shp")


@pytest.mark.parametrize(
    ("name", "message"),
    [
        ("curve.dat", r"curve\.dat: unknown file suffix '\.dat'; supported suffixes are \.csv, "),
        ("curve", r"curve: no file suffix; supported suffixes are .*\.svg \(SVG\)"),
    ],
)
def test_detect_format_unknown_suffix_lists_supported(name, message):
    with pytest.raises(CurveFormatError, match=message):
        detect_format(name)


def test_read_write_curves_dispatch_on_suffix(tmp_path):
    curves = [Curve([[0, 0], [1, 0.5], [2, 0]], closed=False, properties={"id": "a"})]
    for suffix in (".csv", ".geojson", ".json", ".svg"):
        path = tmp_path / f"c{suffix}"
        write_curves(curves, path)
        back = read_curves(path)
        assert bits_equal(back[0].points, curves[0].points), suffix
        assert back[0].properties["id"] == "a"
    (tmp_path / "x.csv").write_text('{"type": "LineString", "coordinates": [[0, 0], [1, 1]]}')
    assert read_curves(tmp_path / "x.csv", format="geojson")[0].points.tolist() == [[0, 0], [1, 1]]


def test_streams_need_a_format():
    with pytest.raises(
        CurveFormatError, match="cannot detect the format of a stream; pass format="
    ):
        read_curves(text("x,y\n0,0\n1,1\n"))
    with pytest.raises(CurveFormatError, match="cannot detect the format of a stream"):
        write_curves([Curve([[0, 0], [1, 1]], closed=False)], io.StringIO())
    assert len(read_curves(text("x,y\n0,0\n1,1\n"), format="csv")) == 1


def test_missing_file_and_directory(tmp_path):
    missing = tmp_path / "nope.csv"
    with pytest.raises(CurveFormatError, match=r"nope\.csv: no such file"):
        read_curves(missing)
    with pytest.raises(CurveFormatError, match="is a directory"):
        read_csv(tmp_path)
    with pytest.raises(CurveFormatError, match="cannot write the file"):
        write_csv([Curve([[0, 0], [1, 1]], closed=False)], tmp_path / "no" / "dir" / "a.csv")


@pytest.mark.parametrize("reader", [read_csv, read_geojson, read_svg])
@pytest.mark.parametrize("content", ["", "  \n\n \t\n"])
def test_empty_file_names_the_file(tmp_path, reader, content):
    path = tmp_path / "empty.txt"
    path.write_text(content)
    with pytest.raises(CurveFormatError, match=r"empty\.txt: the file is empty"):
        reader(path)


def test_non_utf8_file(tmp_path):
    path = tmp_path / "latin.csv"
    path.write_bytes("x,y,name\n0,0,caf\xe9\n1,1,caf\xe9\n".encode("latin-1"))
    with pytest.raises(CurveFormatError, match=r"latin\.csv: not UTF-8 text"):
        read_csv(path)


def test_writing_nothing_or_not_curves():
    with pytest.raises(CurveFormatError, match="nothing to write"):
        write_csv([], io.StringIO())
    with pytest.raises(CurveError, match="Curve objects, got list at index 0"):
        write_geojson([[[0, 0], [1, 1]]], io.StringIO())


# ------------------------------------------------------------------------------------------------
# CSV


def test_csv_fixture():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        ring, track = read_csv(DATA / "tracks.csv")
    assert ring.points.tolist() == [[0, 0], [4, 0], [4, 3]]
    assert (ring.closed, ring.kind, ring.feature) == (True, "Polygon", 0)
    assert ring.properties == {"id": "ring", "name": "pond"}
    assert track.points.tolist() == [[5.5, -1], [6.25, 0.5], [7, 0.002]]
    assert (track.closed, track.kind, track.feature) == (False, "LineString", 1)
    assert track.properties == {"id": "track", "name": "trail"}


def test_csv_closed_by_repeated_first_row_without_closed_column():
    a, b, c = read_csv(
        text("x,y,id\n0,0,a\n1,0,a\n1,1,a\n0,0,a\n0,0,b\n1,0,b\n0,0,b\n0,0,c\n1,0,c\n1,1,c\n")
    )
    assert a.closed and a.points.shape == (3, 2)
    assert not b.closed and b.points.shape == (3, 2)  # only 3 rows: a back-and-forth line
    assert not c.closed
    assert [x.properties["id"] for x in (a, b, c)] == ["a", "b", "c"]


def test_csv_explicit_closed_column_wins():
    (c,) = read_csv(text("x,y,closed\n0,0,no\n1,0,no\n1,1,no\n0,0,no\n"))
    assert not c.closed and c.points.shape == (4, 2)
    (c,) = read_csv(text("x,y,closed\n0,0,1\n1,0,1\n1,1,1\n"))
    assert c.closed and c.points.shape == (3, 2)


def test_csv_3d_whitespace_tab_semicolon_and_case():
    expected = [[1.0, 2.0, 3.0], [4.0, 5.0, 6.5]]
    for body in (
        "X Y Z\n1 2 3\n4  5 6.5\n",
        "z\tx\ty\n3\t1\t2\n6.5\t4\t5\n",
        "Y;X;Z\n2;1;3\n5;4;6.5\n",
        "# comment\n\nx, y, z\n 1, 2, 3\n4,5,6.5\n\n",
    ):
        (c,) = read_csv(text(body))
        assert c.points.tolist() == expected, body


def test_csv_numeric_ids_and_properties_keep_their_text():
    src = "x,y,id,w,label\n0,0,10,1.50,007\n1,1,10,1.50,007\n2,2,2,0.25,b\n3,3,2,0.25,b\n"
    a, b = read_csv(text(src))
    assert a.properties == {"id": 10, "w": "1.50", "label": "007"}
    assert b.properties == {"id": 2, "w": 0.25, "label": "b"}
    back, out = roundtrip(write_csv, read_csv, [a, b])
    assert [c.properties for c in back] == [a.properties, b.properties]
    assert out.splitlines()[1] == "0.0,0.0,10,1.50,007"


def test_csv_varying_column_is_dropped_with_a_warning():
    with pytest.warns(UserWarning, match=r"column 't' varies along curve 'a'.*dropped"):
        a, b = read_csv(text("x,y,id,t\n0,0,a,1\n1,1,a,2\n0,0,b,5\n1,1,b,5\n"))
    assert "t" not in a.properties
    assert b.properties["t"] == 5


def test_csv_write_layout():
    curves = [
        Curve([[0, 0], [0.1, 1e-300], [3, 2]], closed=True, properties={"id": "r", "k": 2}),
        Curve([[5, 5], [6, -0.0]], closed=False, properties={"id": "s", "note": "a,b"}),
    ]
    buf = io.StringIO()
    write_csv(curves, buf)
    assert buf.getvalue() == (
        "x,y,id,closed,k,note\n"
        "0.0,0.0,r,true,2,\n"
        "0.1,1e-300,r,true,2,\n"
        "3.0,2.0,r,true,2,\n"
        "0.0,0.0,r,true,2,\n"
        '5.0,5.0,s,false,,"a,b"\n'
        '6.0,-0.0,s,false,,"a,b"\n'
    )
    back = read_csv(io.StringIO(buf.getvalue()))
    assert [c.properties for c in back] == [{"id": "r", "k": 2}, {"id": "s", "note": "a,b"}]
    assert bits_equal(back[1].points, curves[1].points)


def test_csv_write_single_open_curve_is_plain_xy():
    buf = io.StringIO()
    write_csv([Curve([[0, 0], [1, 2]], closed=False)], buf)
    assert buf.getvalue() == "x,y\n0.0,0.0\n1.0,2.0\n"


def test_csv_open_curve_ending_at_its_start_keeps_open():
    c = Curve([[0, 0], [1, 0], [1, 1], [0, 0]], closed=False)
    (back,), out = roundtrip(write_csv, read_csv, [c])
    assert "closed" in out.splitlines()[0]
    assert not back.closed and back.points.shape == (4, 2)


def test_csv_generated_ids_without_id_properties():
    curves = [Curve([[0, 0], [1, 1]], closed=False), Curve([[2, 2], [3, 3]], closed=False)]
    back, out = roundtrip(write_csv, read_csv, curves)
    assert out.splitlines()[0] == "x,y,id"
    assert [c.properties["id"] for c in back] == [0, 1]


def test_csv_shared_and_missing_ids_are_made_distinct():
    # Regression: a polygon with a hole whose feature has an id property (GeoJSON), or an SVG
    # path with two subpaths, could not be written to CSV ("id properties must be present and
    # distinct"); neither could a mix of curves with and without ids.
    outer = Curve(
        [[0, 0], [4, 0], [4, 4], [0, 4]], closed=True, kind="Polygon", properties={"id": "lake"}
    )
    hole = outer.replace([[1, 1], [1, 2], [2, 2]], ring=1)
    other = Curve([[5, 5], [6, 6]], closed=False, feature=1)
    taken = Curve([[7, 7], [8, 8]], closed=False, feature=2, properties={"id": "lake#0"})
    back, out = roundtrip(write_csv, read_csv, [outer, hole, other, taken])
    assert out.splitlines()[0] == "x,y,id,closed"
    assert [c.properties["id"] for c in back] == ["lake#1", "lake#2", 2, "lake#0"]
    assert [len(c.points) for c in back] == [4, 3, 2, 2]
    assert [c.closed for c in back] == [True, True, False, False]


@pytest.mark.parametrize(
    ("curves", "message"),
    [
        (
            [Curve([[0, 0], [1, 1]], closed=False), Curve([[0, 0, 0], [1, 1, 1]], closed=False)],
            "cannot write 2D and 3D curves to one CSV file",
        ),
        (
            [Curve([[0, 0], [1, 1]], closed=False, properties={"X": 1})],
            "property 'X' of curve 0 clashes with the CSV column 'x'",
        ),
    ],
)
def test_csv_write_errors(curves, message):
    with pytest.raises(CurveFormatError, match=message):
        write_csv(curves, io.StringIO())


@pytest.mark.parametrize(
    ("body", "message"),
    [
        (
            "0,0\n1,1\n",
            r"bad\.csv: line 1: missing header row; the first line must name the columns",
        ),
        ("a,y\n0,0\n", r"bad\.csv: missing column 'x'; the header has columns \['a', 'y'\]"),
        ("x,z\n0,0\n", "missing column 'y'"),
        ("x,y,X\n0,0,0\n", r"duplicate column names \['x'\]"),
        ("x,y\n", r"bad\.csv: no data rows after the header"),
        ("# only\n# comments\n", "holds only comments and blank lines"),
        ("x,y\n0,0\n1,abc\n", r"bad\.csv: line 3: y value 'abc' is not a number"),
        ("# c\nx,y\n0,0\n\n1,\n", r"line 5: y value '' is not a number"),
        ("x,y\n0,0\n1,nan\n", r"line 3: y value 'nan' is not finite"),
        ("x,y\n0,0\n1,1,1\n", r"line 3: expected 2 fields \(x,y\), got 3"),
        ("x,y,closed\n0,0,maybe\n1,1,maybe\n", r"line 2: closed value 'maybe' is not true/false"),
        (
            "x,y,id,closed\n0,0,a,1\n1,0,a,0\n1,1,a,1\n",
            r"curve 'a' \(lines 2-4\): the closed column must be constant along a curve",
        ),
        ("x,y,id\n0,0,a\n1,1,a\n5,5,b\n", r"curve 'b' \(lines 4-4\): .*at least 2 points, got 1"),
        ("x,y\n0,0\n", r"the curve \(lines 2-2\): .*at least 2 points, got 1"),
        ("x,y,closed\n0,0,true\n1,1,true\n", "at least 3 distinct ring points, got 2"),
    ],
)
def test_csv_bad_input(tmp_path, body, message):
    path = tmp_path / "bad.csv"
    path.write_text(body)
    with pytest.raises(CurveFormatError, match=message):
        read_csv(path)


finite = st.floats(allow_nan=False, allow_infinity=False, width=64)


@st.composite
def polylines(draw, dim=None, distinct=False):
    dim = draw(st.sampled_from([2, 3])) if dim is None else dim
    closed = draw(st.booleans())
    n = draw(st.integers(3 if closed else 2, 8))
    coord = st.integers(-400, 400).map(lambda k: k / 8) if distinct else finite
    pts = draw(
        st.lists(st.lists(coord, min_size=dim, max_size=dim), min_size=n, max_size=n).filter(
            lambda p: (
                not distinct or (all(p[i] != p[i + 1] for i in range(len(p) - 1)) and p[0] != p[-1])
            )
        )
    )
    if closed and pts[0] == pts[-1]:
        pts = [*pts, [v + 1.0 for v in pts[0]]]  # keep three distinct ring points
    return np.array(pts), closed


@given(st.lists(polylines(dim=2), min_size=1, max_size=4), st.booleans())
def test_csv_roundtrip_is_bit_exact(items, with_ids):
    curves = [
        Curve(p, closed=closed, properties={"id": f"c{i}"} if with_ids else {})
        for i, (p, closed) in enumerate(items)
    ]
    back, _ = roundtrip(write_csv, read_csv, curves)
    assert len(back) == len(curves)
    for c, b in zip(curves, back, strict=True):
        assert bits_equal(b.points, c.points)
        assert b.closed == c.closed


@given(polylines(dim=3))
def test_csv_roundtrip_3d(item):
    p, closed = item
    (back,), _ = roundtrip(write_csv, read_csv, [Curve(p, closed=closed)])
    assert bits_equal(back.points, Curve(p, closed=closed).points) and back.closed == closed


# ------------------------------------------------------------------------------------------------
# GeoJSON


def test_geojson_fixture_structure():
    curves = read_geojson(DATA / "features.geojson")
    got = [(c.feature, c.member, c.part, c.ring, c.kind, c.closed, len(c.points)) for c in curves]
    assert got == [
        (0, None, 0, 0, "LineString", False, 3),
        (1, None, 0, 0, "Polygon", True, 4),
        (1, None, 0, 1, "Polygon", True, 4),
        (1, None, 0, 2, "Polygon", True, 3),
        (2, None, 0, 0, "MultiLineString", False, 2),
        (2, None, 1, 0, "MultiLineString", True, 3),
        (3, None, 0, 0, "MultiPolygon", True, 3),
        (3, None, 1, 0, "MultiPolygon", True, 4),
        (3, None, 1, 1, "MultiPolygon", True, 3),
        (4, 0, 0, 0, "LineString", False, 2),
        (4, 1, 0, 0, "Polygon", True, 3),
        (5, None, 0, 0, "LineString", False, 3),
        (6, None, 0, 0, "LineString", False, 2),
    ]
    assert curves[0].feature_id == "road-1" and curves[0].properties == {"name": "road", "lanes": 2}
    assert curves[6].feature_id == 7
    assert curves[4].properties["tags"] == ["a", "b"]
    assert curves[11].points.tolist() == [[0, 0, 100], [1, 0, 101.5], [1, 1, 103.25]]
    assert curves[12].properties == {}


def test_geojson_fixture_roundtrip_keeps_structure_and_orients_rings():
    curves = read_geojson(DATA / "features.geojson")
    back, out = roundtrip(write_geojson, read_geojson, curves)
    assert [structure(c) for c in back] == [structure(c) for c in curves]
    # the fixture's lake exterior is clockwise: written counter-clockwise, first vertex kept
    lake = json.loads(out)["features"][1]["geometry"]["coordinates"]
    assert lake[0] == [[0, 0], [10, 0], [10, 10], [0, 10], [0, 0]]
    for c in back:
        if c.kind in ("Polygon", "MultiPolygon"):
            area = signed_area(c.points)
            assert area > 0 if c.ring == 0 else area < 0, (c.feature, c.part, c.ring)
    for c, b in zip(curves, back, strict=True):
        if c.kind in ("Polygon", "MultiPolygon") and np.sign(signed_area(c.points)) != (
            1 if c.ring == 0 else -1
        ):
            expected = np.concatenate([c.points[:1], c.points[:0:-1]])
        else:
            expected = c.points
        assert bits_equal(b.points, expected)
    # written once, the file is a fixed point
    again, out2 = roundtrip(write_geojson, read_geojson, back)
    assert out2 == out
    assert all(bits_equal(a.points, b.points) for a, b in zip(back, again, strict=True))


def test_geojson_orient_false_keeps_vertex_order():
    curves = read_geojson(DATA / "features.geojson")
    back, _ = roundtrip(write_geojson, read_geojson, curves, orient=False)
    assert all(bits_equal(a.points, b.points) for a, b in zip(curves, back, strict=True))


def test_geojson_smoothed_points_keep_structure():
    curves = read_geojson(DATA / "features.geojson")
    # stand-in for a smoothing step: every curve gets a different number of points
    smoothed = [
        c.replace(np.repeat(c.points, 2, axis=0)[::2] * 1.5 + 0.25) if c.closed else c
        for c in curves
    ]
    back, _ = roundtrip(write_geojson, read_geojson, smoothed)
    assert [structure(c) for c in back] == [structure(c) for c in curves]


def test_geojson_bare_geometry_and_feature():
    (c,) = read_geojson(text('{"type": "LineString", "coordinates": [[0, 0], [1, 2]]}'))
    assert (c.feature, c.kind, c.properties, c.feature_id) == (0, "LineString", {}, None)
    (c,) = read_geojson(
        text(
            '{"type": "Feature", "id": 3, "properties": {"a": 1}, "geometry": '
            '{"type": "LineString", "coordinates": [[0, 0], [1, 2], [3, 3], [0, 0]]}}'
        )
    )
    assert c.closed and c.kind == "LineString" and c.feature_id == 3 and c.properties == {"a": 1}
    _, out = roundtrip(write_geojson, read_geojson, [c])
    geometry = json.loads(out)["features"][0]["geometry"]
    assert geometry == {"type": "LineString", "coordinates": [[0, 0], [1, 2], [3, 3], [0, 0]]}


def test_geojson_unclosed_polygon_ring_is_accepted_and_closed_on_write():
    (c,) = read_geojson(text('{"type": "Polygon", "coordinates": [[[0, 0], [1, 0], [0, 1]]]}'))
    assert c.closed and c.points.shape == (3, 2)
    _, out = roundtrip(write_geojson, read_geojson, [c])
    ring = json.loads(out)["features"][0]["geometry"]["coordinates"][0]
    assert ring == [[0, 0], [1, 0], [0, 1], [0, 0]]


def test_geojson_writes_closed_csv_curves_as_polygons_and_open_as_lines():
    curves = read_csv(DATA / "tracks.csv")
    _, out = roundtrip(write_geojson, read_geojson, curves)
    features = json.loads(out)["features"]
    assert [f["geometry"]["type"] for f in features] == ["Polygon", "LineString"]
    assert features[0]["properties"] == {"id": "ring", "name": "pond"}


@pytest.mark.parametrize(
    ("doc", "message"),
    [
        (
            '{"type": "LineString", "coordinates": [[0, 0], [1, 1]]',
            r"malformed JSON at line 1, column 55: Expecting .,. delimiter",
        ),
        (
            '{"type":\n "Feature",\n "geometry": nul}',
            r"bad\.geojson: malformed JSON at line 3, column 14",
        ),
        ("[1, 2]", r"expected a GeoJSON object with a 'type' member, found an array of 2 values"),
        ('{"features": []}', r"found an object with keys \['features'\] and no 'type'"),
        ('{"type": "Topology"}', r"unknown GeoJSON type 'Topology'"),
        ('{"type": "FeatureCollection", "features": {}}', r"'features' must be an array"),
        ('{"type": "FeatureCollection", "features": []}', "has no features, so no curves"),
        ('{"type": "Point", "coordinates": [0, 0]}', "geometry: a Point is not a curve"),
        (
            '{"type": "FeatureCollection", "features": [{"type": "Feature", "properties": {}, '
            '"geometry": {"type": "LineString", "coordinates": [[0, 0], [1, 1]]}}, '
            '{"type": "Feature", "properties": {}, '
            '"geometry": {"type": "MultiPoint", "coordinates": [[0, 0], [1, 1]]}}]}',
            r"feature 1: a MultiPoint is not a curve; curvesmith reads LineString, Polygon",
        ),
        (
            '{"type": "GeometryCollection", "geometries": [{"type": "LineString", "coordinates": '
            '[[0, 0], [1, 1]]}, {"type": "Point", "coordinates": [0, 0]}]}',
            r"geometry, member 1: a Point is not a curve",
        ),
        (
            '{"type": "Feature", "properties": {}, "geometry": null}',
            r"feature 0: the geometry is null; curvesmith reads only curves",
        ),
        ('{"type": "MultiLineString", "coordinates": []}', r"the geometry is empty \(no lines\)"),
        ('{"type": "LineString", "coordinates": [[0, 0]]}', "at least 2 points, got 1"),
        (
            '{"type": "Polygon", "coordinates": [[[0, 0], [1, 0], [0, 1], [0, 0]], '
            "[[0, 0], [1, 0], [0, 0]]]}",
            r"geometry ring 1 \(hole\): points must have at least 3 distinct ring points, got 2",
        ),
        (
            '{"type": "LineString", "coordinates": [[0, 0], [1, "a"]]}',
            "coordinates must be numbers",
        ),
        (
            '{"type": "LineString", "coordinates": [[0, 0], [1]]}',
            r"2 or 3 numbers .*found \[1\] \(position 1, 1 number\)",
        ),
        ('{"type": "LineString", "coordinates": [[0, 0], [1, 1, 1]]}', "mix 2 and 3 coordinates"),
        ('{"type": "LineString", "coordinates": [[0, 0], [1, NaN]]}', "NaN is not valid JSON"),
        ('{"type": "LineString", "coordinates": [[0, 0], [1, 1e400]]}', "must be finite"),
        ('{"type": "Feature", "properties": [], "geometry": null}', "properties must be an object"),
        (
            '{"type": "GeometryCollection", "geometries": [{"type": "GeometryCollection", '
            '"geometries": []}]}',
            "nested GeometryCollections are not supported",
        ),
        ('{"type": "Circle", "coordinates": [0, 0]}', r"unknown GeoJSON type 'Circle'"),
    ],
)
def test_geojson_bad_input(tmp_path, doc, message):
    path = tmp_path / "bad.geojson"
    path.write_text(doc)
    with pytest.raises(CurveFormatError, match=message):
        read_geojson(path)


def test_geojson_error_from_stream_says_stream():
    with pytest.raises(CurveFormatError, match=r"^<stream>: malformed JSON at line 1, column 1"):
        read_geojson(text("nope"))


def test_geojson_write_errors():
    a = Curve([[0, 0], [1, 1]], closed=False)
    with pytest.raises(CurveFormatError, match=r"two curves have the same \(member, part, ring\)"):
        write_geojson([a, a.replace([[5, 5], [6, 6]])], io.StringIO())
    with pytest.raises(CurveFormatError, match="different properties"):
        write_geojson([a, a.replace(properties={"b": 1}, kind="MultiLineString")], io.StringIO())
    hole = Curve([[0, 0], [1, 0], [0, 1]], closed=True, kind="Polygon", ring=1)
    with pytest.raises(CurveFormatError, match="holes but no exterior ring"):
        write_geojson([hole], io.StringIO())
    with pytest.raises(CurveFormatError, match="different kinds"):
        write_geojson(
            [a.replace(kind="MultiLineString"), hole.replace(ring=0, part=1, kind="MultiPolygon")],
            io.StringIO(),
        )
    with pytest.raises(CurveFormatError, match="cannot write the properties as JSON"):
        write_geojson([a.replace(properties={"v": math.nan})], io.StringIO())


def test_geojson_numpy_property_values_are_written():
    c = Curve([[0, 0], [1, 1]], closed=False, properties={"n": np.int64(3), "v": np.arange(2.0)})
    (back,), _ = roundtrip(write_geojson, read_geojson, [c])
    assert back.properties == {"n": 3, "v": [0.0, 1.0]}


@st.composite
def features(draw):
    """Random features: LineString, MultiLineString, Polygon with holes, MultiPolygon."""
    kind = draw(st.sampled_from(["LineString", "MultiLineString", "Polygon", "MultiPolygon"]))
    dim = draw(st.sampled_from([2, 3]))
    coord = st.lists(finite, min_size=dim, max_size=dim)
    parts = draw(st.integers(1, 3)) if kind.startswith("Multi") else 1
    out = []
    for part in range(parts):
        rings = draw(st.integers(1, 3)) if kind.endswith("Polygon") else 1
        for ring in range(rings):
            closed = kind.endswith("Polygon")
            pts = draw(st.lists(coord, min_size=3 if closed else 2, max_size=7))
            if closed and (pts[0] == pts[-1] or len({tuple(p) for p in pts}) < 3):
                pts = [[float(i), float(i * i)] + [0.5] * (dim - 2) for i in range(3)]
            while not closed and len(pts) >= 4 and pts[0] == pts[-1]:
                # An open GeoJSON LineString that ends where it starts is a ring by the file
                # convention (tested in test_geojson_open_line_ending_at_start_warns); a loop,
                # since dropping one end can leave another repeat (all points equal).
                pts = pts[:-1]
            out.append({"points": pts, "closed": closed, "part": part, "ring": ring, "kind": kind})
    props = draw(
        st.dictionaries(
            st.text(max_size=5), st.one_of(st.integers(-5, 5), finite, st.text(max_size=5))
        )
    )
    return out, props


@given(st.lists(features(), min_size=1, max_size=4))
def test_geojson_roundtrip_is_bit_exact(feats):
    curves = [
        Curve(np.array(c.pop("points")), properties=props, feature=f, **c)
        for f, (items, props) in enumerate(feats)
        for c in [dict(x) for x in items]
    ]
    back, _ = roundtrip(write_geojson, read_geojson, curves, orient=False)
    assert [structure(c) for c in back] == [structure(c) for c in curves]
    assert all(bits_equal(a.points, b.points) for a, b in zip(curves, back, strict=True))
    oriented, _ = roundtrip(write_geojson, read_geojson, curves)
    for c, b in zip(curves, oriented, strict=True):
        assert structure(b) == structure(c)
        if c.closed and c.kind.endswith("Polygon"):
            reversed_ = np.concatenate([c.points[:1], c.points[:0:-1]])
            assert bits_equal(b.points, c.points) or bits_equal(b.points, reversed_)
            assert exact_area_sign(b.points) == (1 if c.ring == 0 else -1) * abs(
                exact_area_sign(c.points)
            )


# ------------------------------------------------------------------------------------------------
# SVG: geometry against analytic curves


def svg_doc(body: str, root: str = "") -> io.StringIO:
    return text(f'<svg xmlns="http://www.w3.org/2000/svg" {root}>{body}</svg>')


@pytest.mark.parametrize("tol", [1e-1, 1e-2, 1e-3, 1e-5])
def test_svg_arc_circle_within_tolerance(tol):
    r, cx, cy = 3.0, 1.0, -2.0
    d = f"M {cx + r} {cy} A {r} {r} 0 1 1 {cx - r} {cy} A {r} {r} 0 1 1 {cx + r} {cy} Z"
    (c,) = read_svg(svg_doc(f'<path d="{d}"/>'), tolerance=tol)
    assert c.closed and c.kind == "Polygon"
    p = c.points - [cx, cy]
    np.testing.assert_allclose(np.hypot(p[:, 0], p[:, 1]), r, rtol=0, atol=1e-12)
    mid = 0.5 * (p + np.roll(p, -1, axis=0))
    deviation = r - np.hypot(mid[:, 0], mid[:, 1])  # sagitta of each chord
    assert deviation.max() <= tol
    assert deviation.max() >= tol / 4  # not wastefully fine either
    area = signed_area(c.points)
    perimeter = np.sum(np.linalg.norm(np.roll(p, -1, axis=0) - p, axis=1))
    # y axis down: sweep-flag 1 is clockwise on screen, positive (CCW) in these coordinates
    assert math.pi * r**2 - perimeter * tol <= area <= math.pi * r**2


def test_svg_circle_and_ellipse_elements_against_analytic_curves():
    tol = 2e-3
    doc = svg_doc(
        '<circle cx="5" cy="6" r="2"/>'
        '<ellipse cx="0" cy="0" rx="8" ry="4" transform="translate(150,70) rotate(30) scale(1,3)"/>'
    )
    circle, ellipse = read_svg(doc, tolerance=tol)
    p = circle.points - [5, 6]
    np.testing.assert_allclose(np.hypot(p[:, 0], p[:, 1]), 2.0, atol=1e-12)
    # the ellipse x = T (8 cos t, 4 sin t) with T = translate rotate scale
    a = math.radians(30)
    linear = np.array([[math.cos(a), -math.sin(a)], [math.sin(a), math.cos(a)]]) @ np.diag([1, 3])
    u = np.linalg.solve(linear, (ellipse.points - [150, 70]).T).T
    np.testing.assert_allclose((u[:, 0] / 8) ** 2 + (u[:, 1] / 4) ** 2, 1.0, atol=1e-12)
    t = np.linspace(0, 2 * np.pi, 6001)
    exact = (linear @ np.array([8 * np.cos(t), 4 * np.sin(t)])).T + np.array([150, 70])
    dist = distance_to_polyline(exact, ellipse.points, closed=True)
    assert dist.max() <= tol
    assert dist.max() >= tol / 10


def test_svg_rotated_elliptic_arc_command():
    # half of the ellipse rx=4, ry=2 rotated by 30 degrees, centred at (10, 10)
    a = math.radians(30)
    rot = np.array([[math.cos(a), -math.sin(a)], [math.sin(a), math.cos(a)]])
    start, end = rot @ [4, 0] + 10, rot @ [-4, 0] + 10
    x0, y0, x1, y1 = (float(v) for v in (*start, *end))
    d = f"M {x0!r} {y0!r} A 4 2 30 0 1 {x1!r} {y1!r}"
    (c,) = read_svg(svg_doc(f'<path d="{d}"/>'), tolerance=1e-3)
    assert not c.closed
    u = (c.points - 10) @ rot  # rotate back
    np.testing.assert_allclose((u[:, 0] / 4) ** 2 + (u[:, 1] / 2) ** 2, 1.0, atol=1e-9)
    assert np.all(u[1:-1, 1] > 0)  # sweep-flag 1: through positive angles, the +y half
    t = np.linspace(0, np.pi, 5001)
    exact = (rot @ np.array([4 * np.cos(t), 2 * np.sin(t)])).T + 10
    assert distance_to_polyline(exact, c.points, closed=False).max() <= 1e-3


def bezier(ctrl, t):
    """Plain de Casteljau evaluation."""
    pts = [np.asarray(ctrl, dtype=float)[:, None, :].repeat(len(t), axis=1)]
    while len(pts[-1]) > 1:
        q = pts[-1]
        pts.append((1 - t)[None, :, None] * q[:-1] + t[None, :, None] * q[1:])
    return pts[-1][0]


@pytest.mark.parametrize("tol", [0.5, 1e-2, 1e-4])
@pytest.mark.parametrize(
    ("d", "ctrl"),
    [
        ("M 0 0 C 10 30 40 -20 50 10", [[0, 0], [10, 30], [40, -20], [50, 10]]),
        ("M 5 5 c 0 40 40 40 40 0", [[5, 5], [5, 45], [45, 45], [45, 5]]),
        ("M 0 0 Q 20 40 40 0", [[0, 0], [20, 40], [40, 0]]),
        ("M 0 0 q 20 40 40 0", [[0, 0], [20, 40], [40, 0]]),
    ],
)
def test_svg_bezier_within_tolerance(d, ctrl, tol):
    (c,) = read_svg(svg_doc(f'<path d="{d}"/>'), tolerance=tol)
    assert bits_equal(c.points[0], ctrl[0]) and bits_equal(c.points[-1], ctrl[-1])
    # vertices are the curve at equal parameter steps ...
    n = len(c.points) - 1
    np.testing.assert_allclose(c.points, bezier(ctrl, np.arange(n + 1) / n), atol=1e-12)
    # ... and the exact curve stays within tol of the polyline, not much closer
    dist = distance_to_polyline(bezier(ctrl, np.linspace(0, 1, 4001)), c.points, closed=False)
    assert tol / 8 <= dist.max() <= tol


def test_svg_relative_smooth_and_arc_commands_match_absolute():
    curves = read_svg(DATA / "shapes.svg", tolerance=1e-3)
    relative, absolute = curves[0], curves[1]
    explicit = read_svg(
        svg_doc(
            '<path d="M 10 10 L 30 10 C 35 10 40 15 40 20 C 40 25 35 30 30 30 '
            'Q 25 30 20 25 Q 15 20 10 20 L 5 20 L 5 15 A 5 5 0 0 1 10 10 Z"/>'
        ),
        tolerance=1e-3,
    )[0]
    np.testing.assert_allclose(relative.points, absolute.points, atol=1e-12)
    np.testing.assert_allclose(explicit.points, absolute.points, atol=1e-12)
    assert relative.closed and absolute.closed
    # the arc from (5, 15) to (10, 10) is a quarter of the circle of radius 5 around (10, 15)
    arc = absolute.points[
        np.flatnonzero((absolute.points[:, 0] <= 10) & (absolute.points[:, 1] <= 15))
    ]
    arc = arc[(arc[:, 0] >= 5) & (arc[:, 1] >= 10)]
    assert len(arc) > 5
    np.testing.assert_allclose(np.hypot(*(arc - [10, 15]).T), 5.0, atol=1e-12)


def test_svg_fixture_elements():
    curves = read_svg(DATA / "shapes.svg", tolerance=1e-2)
    ids = [c.properties.get("id") for c in curves]
    assert ids == [
        "relative",
        "absolute",
        "two-subpaths",
        "two-subpaths",
        "zigzag",
        "square",
        "segment",
        "turned",
        "rounded",
        "circle",
        "ellipse",
        "tri",
    ]
    by_id = {}
    for c in curves:
        by_id.setdefault(c.properties.get("id"), []).append(c)
    closed_sub, open_sub = by_id["two-subpaths"]
    assert closed_sub.points.tolist() == [[50, 10], [60, 10], [60, 20]] and closed_sub.closed
    assert open_sub.points.tolist() == [[70, 10], [80, 10]] and not open_sub.closed
    assert (closed_sub.member, open_sub.member) == (0, 1)
    assert (closed_sub.feature, open_sub.feature) == (2, 2)
    assert by_id["zigzag"][0].points.tolist() == [[100, 10], [110, 20], [120, 10], [130, 20]]
    assert not by_id["zigzag"][0].closed
    assert by_id["square"][0].points.tolist() == [[140, 10], [150, 10], [150, 20], [140, 20]]
    assert by_id["square"][0].closed
    assert by_id["segment"][0].points.tolist() == [[160, 10], [170, 20]]
    # rect (0,0,10,20) rotated by 90 degrees, then translated by (100, 50)
    np.testing.assert_allclose(
        by_id["turned"][0].points, [[100, 50], [100, 60], [80, 60], [80, 50]], atol=1e-12
    )
    # rounded rect: area of a 30 x 20 rectangle minus 4 corners of (1 - pi/4) r^2, r = 5
    rounded = by_id["rounded"][0]
    exact_area = 30 * 20 - (4 - math.pi) * 25
    perimeter = 2 * (20 + 10) + 2 * math.pi * 5
    assert exact_area - perimeter * 1e-2 <= signed_area(rounded.points) <= exact_area
    # use of a defs polygon with x=180, y=80
    assert by_id["tri"][0].points.tolist() == [[180, 80], [184, 80], [180, 83]]
    # viewBox coordinates (200 x 100 on 20 cm x 10 cm): not scaled to pixels
    np.testing.assert_allclose(by_id["circle"][0].points.mean(axis=0), [60, 60], atol=1e-9)


def test_svg_transforms_matrix_and_nested():
    doc = svg_doc(
        '<g transform="matrix(2 0 0 3 1 1)"><g transform="skewX(45)">'
        '<polyline points="0,0 1,0 1,1"/></g></g>'
        '<polygon points="0,0 1,0 0,1" transform="translate(5) scale(-1, 1)"/>'
    )
    line, tri = read_svg(doc)
    # skewX(45): (x, y) -> (x + y, y); then (2x + 1, 3y + 1)
    np.testing.assert_allclose(line.points, [[1, 1], [3, 1], [5, 4]], atol=1e-12)
    np.testing.assert_allclose(tri.points, [[5, 0], [4, 0], [5, 1]], atol=1e-12)


def test_svg_default_tolerance_scales_with_the_drawing():
    def circle(r):
        return read_svg(svg_doc(f'<circle cx="0" cy="0" r="{r}"/>'))[0].points

    small, large = circle(1.0), circle(1000.0)
    assert len(small) == len(large)
    np.testing.assert_allclose(large, 1000.0 * small, rtol=1e-12, atol=1e-9)
    # default tolerance = 1e-4 * diagonal of the box of the control points (2r x 2r)
    p = small
    mid = 0.5 * (p + np.roll(p, -1, axis=0))
    assert (1 - np.hypot(mid[:, 0], mid[:, 1])).max() <= 1e-4 * 2 * math.sqrt(2)


def test_svg_degenerate_subpaths():
    doc = svg_doc('<path d="M 0 0 M 5 5 L 5 5 L 6 5 L 6 5 L 7 6"/><path d="M 0 0 L 1 0 Z"/>')
    a, b = read_svg(doc)
    # the lone moveto and the zero-length lines are dropped
    assert a.points.tolist() == [[5, 5], [6, 5], [7, 6]]
    assert not b.closed and b.points.tolist() == [[0, 0], [1, 0]]  # encloses no area


def test_svg_path_after_close_starts_at_subpath_start():
    (a, b) = read_svg(svg_doc('<path d="M 1 1 L 3 1 L 3 3 Z l 0 -5"/>'))
    assert a.closed and a.points.tolist() == [[1, 1], [3, 1], [3, 3]]
    assert b.points.tolist() == [[1, 1], [1, -4]] and not b.closed
    assert (a.member, b.member) == (0, 1)


@pytest.mark.parametrize(
    ("doc", "message"),
    [
        (
            '<svg xmlns="http://www.w3.org/2000/svg"><text>hi</text>'
            '<rect width="0" height="1"/></svg>',
            r"bad\.svg: contains no drawable path, polyline or polygon",
        ),
        (
            '<svg xmlns="http://www.w3.org/2000/svg"/>',
            "contains no drawable path, polyline or polygon",
        ),
        (
            '<svg xmlns="http://www.w3.org/2000/svg"><path d="M 0 0" display="none"/></svg>',
            "contains no drawable path",
        ),
        (
            '<svg xmlns="http://www.w3.org/2000/svg">\n<path d="M 0 0 L 1 1">\n</svg>',
            r"bad\.svg: malformed XML at line 3, column 3: mismatched tag",
        ),
        ("not xml", r"malformed XML at line 1, column 1"),
        ("<html><body/></html>", r"the root element is not <svg>"),
        (
            '<svg xmlns="http://www.w3.org/2000/svg"><path id="p" d="M 0 0 L x y"/></svg>',
            r'<path id="p"> \(drawable element 0\): malformed path data \'M 0 0 L x y\'',
        ),
    ],
)
def test_svg_bad_input(tmp_path, doc, message):
    path = tmp_path / "bad.svg"
    path.write_text(doc)
    with pytest.raises(CurveFormatError, match=message):
        read_svg(path)


@pytest.mark.parametrize("tol", [0.0, -1.0, math.inf])
def test_svg_tolerance_must_be_positive(tol):
    with pytest.raises(CurveError, match="tolerance must be"):
        read_svg(svg_doc('<circle r="1"/>'), tolerance=tol)


def test_svg_tolerance_too_small_for_drawing():
    with pytest.raises(CurveFormatError, match="tolerance 1e-30 is too small"):
        read_svg(svg_doc('<circle r="1"/>'), tolerance=1e-30)


# ------------------------------------------------------------------------------------------------
# SVG: writing


def test_svg_write_document():
    curves = [
        Curve([[0, 0], [10, 0], [10, 5]], closed=True, properties={"id": "tri<1>", "n": 2}),
        Curve([[0, 10], [5, 12]], closed=False, feature=1),
    ]
    buf = io.StringIO()
    write_svg(curves, buf, fill="#ccc")
    out = buf.getvalue()
    assert 'viewBox="-0.24 -0.24 10.48 12.48"' in out
    assert 'stroke-width="0.03"' in out
    assert 'id="tri&lt;1&gt;"' in out
    assert 'd="M 0.0,0.0 L 10.0,0.0 10.0,5.0 Z"' in out
    assert out.count('fill="#ccc"') == 1 and 'fill="none"' in out
    back = read_svg(io.StringIO(out))
    assert [structure(c) for c in back] == [structure(c) for c in curves]
    assert all(bits_equal(a.points, b.points) for a, b in zip(curves, back, strict=True))


def test_svg_write_rejects_3d():
    with pytest.raises(CurveFormatError, match="SVG is planar: curve 1 has 3D points"):
        write_svg(
            [Curve([[0, 0], [1, 1]], closed=False), Curve([[0, 0, 0], [1, 1, 1]], closed=False)],
            io.StringIO(),
        )


def test_svg_keeps_polygon_with_holes_structure():
    curves = [c for c in read_geojson(DATA / "features.geojson") if c.dim == 2]
    # SVG numbers features by element: renumber after dropping the 3D feature 5
    curves = [c.replace(feature=c.feature - (c.feature > 5)) for c in curves]
    back, out = roundtrip(write_svg, read_svg, curves)
    assert out.count("<path ") == len({c.feature for c in curves})
    assert [structure(c) for c in back] == [structure(c) for c in curves]
    assert all(bits_equal(a.points, b.points) for a, b in zip(curves, back, strict=True))


def test_svg_edited_metadata_falls_back_to_plain_structure():
    curves = [
        Curve([[0, 0], [4, 0], [4, 4]], closed=True, kind="Polygon", properties={"k": 1}),
        Curve([[1, 1], [2, 1], [2, 2]], closed=True, kind="Polygon", ring=1, properties={"k": 1}),
    ]
    buf = io.StringIO()
    write_svg(curves, buf)
    edited = buf.getvalue().replace(" M 1.0,1.0 L 2.0,1.0 2.0,2.0 Z", "")
    (c,) = read_svg(io.StringIO(edited))
    assert (c.kind, c.ring, c.properties) == ("Polygon", 0, {"k": 1})
    broken = buf.getvalue().replace("data-curvesmith='{", "data-curvesmith='[")
    with pytest.raises(CurveFormatError, match="malformed data-curvesmith attribute"):
        read_svg(io.StringIO(broken))


@given(st.lists(polylines(dim=2, distinct=True), min_size=1, max_size=4))
def test_svg_roundtrip(items):
    curves = [
        Curve(p, closed=closed, feature=i, kind="Polygon" if closed else "LineString")
        for i, (p, closed) in enumerate(items)
    ]
    back, _ = roundtrip(write_svg, read_svg, curves)
    assert [structure(c) for c in back] == [structure(c) for c in curves]
    for a, b in zip(curves, back, strict=True):
        np.testing.assert_allclose(b.points, a.points, rtol=0, atol=1e-12)


def test_svg_roundtrip_through_transformed_viewbox(tmp_path):
    # a hand-edited file: viewBox offset and a group transform; the writer's output read back
    curves = [Curve([[0.1, 0.2], [0.3, 0.7], [0.9, 0.4]], closed=True, kind="Polygon")]
    path = tmp_path / "c.svg"
    write_svg(curves, path)
    edited = path.read_text().replace("<g ", '<g transform="translate(0.5 0.25) scale(2)" ', 1)
    path.write_text(edited)
    (c,) = read_svg(path)
    np.testing.assert_allclose(c.points, curves[0].points * 2 + [0.5, 0.25], atol=1e-14)


# ------------------------------------------------------------------------------------------------
# odds and ends


def test_binary_and_named_file_objects(tmp_path):
    path = tmp_path / "c.geojson"
    path.write_text('{"type": "LineString", "coordinates": [[0, 0], [1, 2]]}')
    with open(path, "rb") as fh:
        assert read_geojson(fh)[0].points.tolist() == [[0, 0], [1, 2]]
    with open(path) as fh:  # the name of a real file gives the format
        assert read_curves(fh)[0].kind == "LineString"
    with open(tmp_path / "out.csv", "w") as fh:
        write_curves(read_geojson(path), fh)
    assert (tmp_path / "out.csv").read_text() == "x,y\n0.0,0.0\n1.0,2.0\n"


def test_read_curves_passes_the_svg_tolerance(tmp_path):
    path = tmp_path / "c.svg"
    path.write_text('<svg xmlns="http://www.w3.org/2000/svg"><circle r="1"/></svg>')
    coarse, fine = read_curves(path, tolerance=1e-2)[0], read_curves(path, tolerance=1e-4)[0]
    # chord count grows like tolerance**-1/2: 4 quarter arcs of ceil(pi/2 sqrt(1 / (8 tol)))
    assert len(coarse.points) == 4 * math.ceil(math.pi / 2 * math.sqrt(1 / 8e-2))
    assert len(fine.points) == 4 * math.ceil(math.pi / 2 * math.sqrt(1 / 8e-4))


def test_geojson_orientation_with_extreme_coordinates():
    # the shoelace sum overflows in plain floating point; the sign is still decided exactly
    ring = Curve([[2.0, 8.98846567431158e307], [0.0, 0.0], [0.0, 1.0]], closed=True, kind="Polygon")
    (back,), _ = roundtrip(write_geojson, read_geojson, [ring])
    assert exact_area_sign(ring.points) == -1
    assert bits_equal(back.points, [[2.0, 8.98846567431158e307], [0.0, 1.0], [0.0, 0.0]])
    # nearly degenerate: plain float area of the raw coordinates gets the sign wrong
    sliver = Curve([[1.0, 9007199254740996.0], [0.0, 0.0], [0.0, 1.0]], closed=True, kind="Polygon")
    (back,), _ = roundtrip(write_geojson, read_geojson, [sliver])
    assert exact_area_sign(back.points) == 1


def test_svg_write_options():
    c = Curve([[0, 0], [2, 0], [2, 1]], closed=True, kind="Polygon")
    buf = io.StringIO()
    write_svg([c], buf, stroke="#f00", stroke_width=0.5, fill="blue")
    out = buf.getvalue()
    assert 'stroke="#f00" stroke-width="0.5"' in out and 'fill="blue"' in out
    with pytest.raises(CurveError, match="stroke_width must be > 0, got -1"):
        write_svg([c], io.StringIO(), stroke_width=-1)


def test_svg_arc_with_too_small_radii_is_scaled_up():
    # SVG 1.1 F.6.6: radii too small to reach the end point are scaled up; here to r = 5
    (c,) = read_svg(svg_doc('<path d="M 0 0 A 1 1 0 0 1 10 0"/>'), tolerance=1e-3)
    p = c.points - [5, 0]
    np.testing.assert_allclose(np.hypot(p[:, 0], p[:, 1]), 5.0, atol=1e-12)
    assert p[:, 1].min() == pytest.approx(-5.0, abs=1e-3)  # clockwise on screen: through y < 0
    mid = 0.5 * (p[1:] + p[:-1])
    assert (5.0 - np.hypot(mid[:, 0], mid[:, 1])).max() <= 1e-3


def test_svg_nested_svg_viewport_is_applied():
    doc = svg_doc(
        '<svg x="10" y="20" width="50" height="50" viewBox="0 0 5 5">'
        '<polyline points="0,0 5,5"/></svg>',
        root='viewBox="0 0 100 100" width="1in" height="1in"',
    )
    (c,) = read_svg(doc)
    np.testing.assert_allclose(c.points, [[10, 20], [60, 70]], atol=1e-12)


def test_geojson_open_line_ending_at_start_warns():
    c = Curve([[0, 0], [1, 0], [1, 1], [0, 0]], closed=False)
    buf = io.StringIO()
    with pytest.warns(UserWarning, match="read it back as a closed ring"):
        write_geojson([c], buf)
    (back,) = read_geojson(io.StringIO(buf.getvalue()))
    assert back.closed and back.points.shape == (3, 2)


# The plain-file fast path of the CSV reader must give exactly what the general path gives
# (which a comment line forces); regression for 1e6-vertex files taking ~10 s to read.


def _with_comment(text: str) -> str:
    head, _, rest = text.partition("\n")
    return f"{head}\n# forces the general path\n{rest}"


@given(
    st.lists(
        st.tuples(
            st.sampled_from(["a", "b", " c ", "7", "ü"]),
            st.floats(allow_nan=False, allow_infinity=False, width=64),
            st.floats(allow_nan=False, allow_infinity=False, width=64),
            st.sampled_from(["red", " red", "1.5", ""]),
        ),
        min_size=1,
        max_size=12,
    ),
    st.sampled_from([",", ";", "\t"]),
    st.sampled_from(["\n", "\r\n"]),
)
def test_csv_fast_path_equals_general_path(rows, sep, eol):
    lines = [sep.join(["id", "x", "y", "colour"])]
    lines += [sep.join([i, repr(x), f" {y!r} ", c]) for i, x, y, c in rows]
    text = eol.join(lines) + eol + eol
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # a varying colour column is dropped with a warning
        try:
            general = read_csv(io.StringIO(_with_comment(text)))
        except CurveFormatError as exc:
            with pytest.raises(CurveFormatError, match="points"):
                read_csv(io.StringIO(text))
            assert "points" in str(exc)
            return
        fast = read_csv(io.StringIO(text))
    assert len(fast) == len(general)
    for a, b in zip(fast, general, strict=True):
        assert bits_equal(a.points, b.points)
        assert (a.closed, a.properties, a.feature) == (b.closed, b.properties, b.feature)


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("x,y\n0,0\n1,oops\n2,2\n", "line 3: y value 'oops' is not a number"),
        ("x,y\n0,0\n1,nan\n2,2\n", "line 3: y value 'nan' is not finite"),
        ("x,y\n0,0\n1,1,1\n2,2\n", "line 3: expected 2 fields"),
        ("x,y\n0,0\n\n2,2\n", None),
        ("id;x;y\na;0;0\nb;1;1\nb;2;2\n", "curve 'a' \\(lines 2-2\\): points must have"),
    ],
)
def test_csv_plain_files_report_the_right_line(text, message):
    if message is None:
        assert [c.points.tolist() for c in read_csv(io.StringIO(text))] == [[[0, 0], [2, 2]]]
        return
    with pytest.raises(CurveFormatError, match=message):
        read_csv(io.StringIO(text))
    shifted = message.replace("line 3", "line 4").replace("lines 2-2", "lines 3-3")
    with pytest.raises(CurveFormatError, match=shifted):
        read_csv(io.StringIO(_with_comment(text)))


def test_csv_write_quotes_properties_like_the_csv_module():
    # write_csv formats only the first row of a curve with the csv module and reuses its tail
    props = {"name": 'Lake "Ünter", north', "note": "", "n": 3}
    c = Curve([[0.1, 0.2], [1e-300, -3.0], [5.0, 1e17]], closed=False, properties=props)
    buf = io.StringIO()
    write_csv([c], buf)
    lines = buf.getvalue().splitlines()
    assert lines[1] == '0.1,0.2,"Lake ""Ünter"", north",,3'
    assert lines[3] == '5.0,1e+17,"Lake ""Ünter"", north",,3'
    (back,) = read_csv(io.StringIO(buf.getvalue()))
    assert bits_equal(back.points, c.points) and back.properties == {"name": props["name"], "n": 3}


def _svg_doc(d: str, transform: str = "") -> str:
    return (
        '<svg xmlns="http://www.w3.org/2000/svg" viewBox="-5 -5 400 400">'
        f'<g transform="{transform}"><path id="p" d="{d}"/>'
        '<circle cx="1" cy="2" r="3"/></g></svg>'
    )


@pytest.mark.parametrize(
    "d",
    [
        "M 0,0 L " + " ".join(f"{k},{(k * k) % 7}" for k in range(1, 700)) + " Z",
        "M0 0 " + " ".join(f"{k} {k % 3}" for k in range(1, 700)) + " M 5,5 L 9,9 9,9 Z M 1 1",
        "M 0,0 L " + " ".join(f"{k}.5,{-k}e-1" for k in range(1, 700)) + " Z M 3 3 L 4 4 Z",
        "M 0,0 L 1,1 Z L " + " ".join(f"{k},{k % 5}" for k in range(2, 700)),  # L after Z
        "m 0,0 l " + " ".join(f"{k % 3},1" for k in range(1, 700)),  # relative: general path
    ],
)
@pytest.mark.parametrize("transform", ["", "rotate(30) translate(5 7) scale(2)"])
def test_svg_long_polyline_fast_path_equals_svgelements(monkeypatch, d, transform):
    # Regression: a 10^6-vertex SVG path took minutes (one svgelements object per segment);
    # long absolute M/L/Z data are now parsed directly and must give the same curves.
    import curvesmith.io.svg as cio

    text = _svg_doc(d, transform)
    fast = read_svg(io.StringIO(text))
    monkeypatch.setattr(cio, "FAST_D_MIN", 10**9)
    general = read_svg(io.StringIO(text))
    assert len(fast) == len(general)
    for a, b in zip(fast, general, strict=True):
        assert bits_equal(a.points, b.points)
        assert (a.closed, a.kind, a.feature, a.part, a.member, a.properties) == (
            b.closed,
            b.kind,
            b.feature,
            b.part,
            b.member,
            b.properties,
        )


OUTER = "M 0,0 L 100,0 L 100,100 L 0,100 Z"
INNER_SAME = "M 10,10 L 40,10 L 40,40 L 10,40 Z"  # same winding as OUTER
INNER_OPPOSITE = "M 60,60 L 60,90 L 90,90 L 90,60 Z"
ISLAND = "M 20,20 L 30,20 L 30,30 L 20,30 Z"  # inside INNER_SAME
FAR = "M 200,0 L 210,0 L 210,10 Z"


@pytest.mark.parametrize(
    ("d", "rule", "expected"),
    [
        # evenodd: parity of the nesting depth
        (f"{OUTER} {INNER_SAME}", "evenodd", [(0, 0), (0, 1)]),
        (f"{OUTER} {INNER_SAME} {ISLAND}", "evenodd", [(0, 0), (0, 1), (1, 0)]),
        (f"{INNER_SAME} {OUTER} {FAR}", "evenodd", [(0, 1), (0, 0), (1, 0)]),
        # nonzero (the SVG default): a hole must wind the other way
        (f"{OUTER} {INNER_SAME}", None, [(0, 0), (1, 0)]),
        (f"{OUTER} {INNER_OPPOSITE} {INNER_SAME}", None, [(0, 0), (0, 1), (1, 0)]),
        (f"{OUTER} {FAR}", "evenodd", [(0, 0), (1, 0)]),
    ],
)
def test_svg_compound_path_holes(d, rule, expected):
    # Regression: a donut path (fill-rule evenodd) was read as a MultiPolygon of two
    # overlapping squares, an invalid geometry once written to GeoJSON.
    attr = f' fill-rule="{rule}"' if rule else ""
    svg = f'<svg xmlns="http://www.w3.org/2000/svg"><path d="{d}"{attr}/></svg>'
    curves = read_svg(io.StringIO(svg))
    assert [(c.part, c.ring) for c in curves] == expected
    polygons = {c.part for c in curves}
    assert {c.kind for c in curves} == {"Polygon" if len(polygons) == 1 else "MultiPolygon"}
    doc = json.loads(_geojson_text(curves))
    geometry = doc["features"][0]["geometry"]
    rings = geometry["coordinates"] if geometry["type"] == "Polygon" else None
    if rings is not None:
        # RFC 7946 orientation: exterior counter-clockwise, holes clockwise
        signs = [np.sign(signed_area(np.array(r[:-1]))) for r in rings]
        assert signs == [1] + [-1] * (len(rings) - 1)


def _geojson_text(curves) -> str:
    buf = io.StringIO()
    write_geojson(curves, buf)
    return buf.getvalue()


def test_format_registry_adds_a_format_in_one_registration(tmp_path, monkeypatch):
    from curvesmith.internals import io_core as core
    from curvesmith.io import Format, formats, register

    monkeypatch.setattr(core, "REGISTRY", dict(core.REGISTRY))
    assert formats() == ("csv", "geojson", "svg")

    def read_pts(source):
        rows = Path(source).read_text().split()
        return [Curve([[float(v) for v in r.split(";")] for r in rows], closed=False)]

    def write_pts(curves, dest):
        Path(dest).write_text("\n".join(";".join(map(str, p.tolist())) for p in curves[0].points))

    register(Format("pts", "PTS", (".pts",), read_pts, write_pts))
    assert formats()[-1] == "pts" and detect_format("a.PTS") == "pts"
    write_curves([Curve([[0, 0], [1.5, 2]], closed=False)], tmp_path / "a.pts")
    assert read_curves(tmp_path / "a.pts")[0].points.tolist() == [[0, 0], [1.5, 2]]
    with pytest.raises(CurveError, match=r"\['.csv'\] already belong to 'csv'"):
        register(Format("other", "Other", (".csv",), read_pts, write_pts))
    with pytest.raises(CurveFormatError, match="supported suffixes are .csv, .txt \\(CSV\\)"):
        detect_format("a.xyz")


@pytest.mark.parametrize(
    ("coords", "said"),
    [
        ([[0], [1, 0]], "found [0] (position 0, 1 number)"),
        ([[0, 0], [1, 0], [1, 2, 3, 4]], "found [1, 2, 3, 4] (position 2, 4 numbers)"),
    ],
)
def test_geojson_bad_position_is_named(tmp_path, coords, said):
    # the message gave the set of lengths found ("found [1, 2]"), not the position
    import json as _json

    from curvesmith.errors import CurveFormatError
    from curvesmith.io import read_geojson

    path = tmp_path / "bad.geojson"
    path.write_text(_json.dumps({"type": "LineString", "coordinates": coords}))
    with pytest.raises(CurveFormatError, match="positions must have 2 or 3 numbers") as err:
        read_geojson(path)
    assert said in str(err.value)
