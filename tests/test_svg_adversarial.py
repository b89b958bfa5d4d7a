"""The SVG reader takes time linear in the path data, on adversarial and on shipped files.

Before, the path-data patterns of ``curvesmith.io.svg`` backtracked exponentially on integer
coordinates when the path also held a curve, a relative command or a lowercase ``z`` (a 152-byte
path of 7 ``L`` and one ``C``: 45 s; matplotlib's logo: over 10 minutes). These tests compare
times of the same reader on inputs 8x longer (ratios measured in one run, never absolute
wall-clock limits), and read every SVG that installed packages ship under a hang guard.
"""

from __future__ import annotations

import contextlib
import io
import signal
import time
from pathlib import Path

import numpy as np
import pytest

from curvesmith.errors import CurveFormatError
from curvesmith.internals import svg_absolute_polyline_pattern, svg_polyline_pattern
from curvesmith.io import read_svg


def _doc(d: str) -> str:
    return f'<svg xmlns="http://www.w3.org/2000/svg"><path d="{d}"/></svg>'


#: Path data that made the old patterns backtrack: integer coordinates followed by a command
#: outside the fast M/L/Z subset, or by a syntax error at the very end.
ADVERSARIAL = {
    "lines then a cubic": lambda n: (
        "M 10 20 " + " ".join(f"L {100 + i} {200 + i}" for i in range(n)) + " C 11 22 33 44 55 66"
    ),
    "relative lines, lowercase z": lambda n: (
        "M 10 20 " + " ".join(f"l {100 + i} {200 + i}" for i in range(n)) + " z"
    ),
    "commas, no spaces, relative curve": lambda n: (
        "M10,20" + "".join(f"L{100 + i},{200 + i}" for i in range(n)) + "c1,2,3,4,5,6z"
    ),
    "integers then garbage": lambda n: (
        "M 10 20 " + " ".join(f"L {100 + i} {200 + i}" for i in range(n)) + " X"
    ),
}


#: 8x the input may take at most this many times as long. Linear time gives ~8x, but the cost
#: per segment steps up a few times once (cache and allocator effects between a few hundred
#: and a few thousand segments, measured on a loaded 2-core machine), so the bound is generous;
#: the old exponential patterns multiplied the time by ~9 per *segment*.
LINEAR_BOUND = 100


def _best_time(fn, repeat: int = 3) -> float:
    best = float("inf")
    for _ in range(repeat):
        t = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t)
    return best


def _read_or_error(d: str) -> None:
    # "integers then garbage" is malformed: one clean error, in linear time
    with contextlib.suppress(CurveFormatError):
        read_svg(io.StringIO(_doc(d)))


@pytest.mark.parametrize("kind", sorted(ADVERSARIAL))
def test_path_patterns_match_in_linear_time(kind):
    make = ADVERSARIAL[kind]
    short, long = make(250), make(2000)
    for pattern in (svg_polyline_pattern, svg_absolute_polyline_pattern):
        # best of many: the machine is shared, a single run can be preempted
        t_short = _best_time(lambda p=pattern: p.fullmatch(short), repeat=15)
        t_long = _best_time(lambda p=pattern: p.fullmatch(long), repeat=15)
        # linear: 8x the input, about 8x the time; exponential growth was x9 per segment
        assert t_long < LINEAR_BOUND * t_short + 2e-3, (kind, t_short, t_long)


@pytest.mark.parametrize("kind", sorted(ADVERSARIAL))
def test_read_svg_linear_on_adversarial_paths(kind):
    make = ADVERSARIAL[kind]
    _read_or_error(make(8))  # the old reader: ~45 s for this one alone
    t_short = _best_time(lambda: _read_or_error(make(100)), repeat=5)
    t_long = _best_time(lambda: _read_or_error(make(800)), repeat=5)
    assert t_long < LINEAR_BOUND * t_short + 2e-3, (kind, t_short, t_long)


def test_seven_lines_and_a_curve_reads_exactly():
    d = "M 10 20 " + " ".join(f"L {100 + i} {200 + i}" for i in range(7)) + " C 11 22 33 44 55 66"
    (curve,) = read_svg(io.StringIO(_doc(d)))
    assert curve.points[:8].tolist() == [[10, 20]] + [[100 + i, 200 + i] for i in range(7)]
    assert curve.points[-1].tolist() == [55, 66]


def _shipped_svgs() -> list[Path]:
    import matplotlib

    roots = [Path(matplotlib.__file__).parent / "mpl-data"]
    try:
        import pyogrio

        roots.append(Path(pyogrio.__file__).parent / "gdal_data")
    except ImportError:  # pragma: no cover - pyogrio is in the geo extra
        pass
    return sorted(p for root in roots for p in root.rglob("*.svg"))


class _Hang(Exception):
    pass


def _on_alarm(signum, frame):
    raise _Hang


def test_every_shipped_svg_reads_without_hanging():
    files = _shipped_svgs()
    names = {p.name for p in files}
    assert "matplotlib.svg" in names and len(files) >= 19
    previous = signal.signal(signal.SIGALRM, _on_alarm)
    results = {}
    try:
        for path in files:
            # a hang guard, not a speed assertion: the old reader ran > 10 min on the logo;
            # every file takes well under a second here
            signal.alarm(120)
            try:
                results[path.name] = len(read_svg(path))
            except _Hang:
                pytest.fail(f"reading {path} did not finish in 120 s")
            finally:
                signal.alarm(0)
    finally:
        signal.signal(signal.SIGALRM, previous)
    assert results["matplotlib.svg"] == 22
    assert all(n >= 1 for n in results.values())


def test_smoothed_svg_keeps_the_source_paint(tmp_path):
    # matplotlib's logo: white and coloured fills, invisible (opacity 0, no paint) background
    # squares. Before, every path came out as a black outline: the invisible squares became
    # visible rounded shapes and the colours were lost.
    from click.testing import CliRunner

    from curvesmith.cli import main

    logo = next(p for p in _shipped_svgs() if p.name == "matplotlib.svg")
    out = tmp_path / "logo.svg"
    res = CliRunner().invoke(main, ["smooth", str(logo), "-o", str(out)])
    assert res.exit_code == 0, res.output
    source = read_svg(logo)
    smoothed = read_svg(out)
    assert len(smoothed) == len(source)
    by_feature = {c.feature: c.style for c in source}
    again = {c.feature: c.style for c in smoothed}
    for k, style in by_feature.items():  # the paint survives a second read (and smoothing)
        for key in ("fill", "opacity", "fill-opacity"):
            if style and key in style:
                assert again[k][key] == style[key], (k, key)
    text = out.read_text()
    fills = {s.get("fill") for s in by_feature.values() if s}
    assert {"#ffffff", "none"} <= fills and len(fills) >= 4  # white, none and the colours
    for paint in fills:
        assert f'fill="{paint}"' in text
    head = text.split("<svg", 1)[1].split(">", 1)[0]  # the page size and viewBox are kept
    assert 'width="72pt"' in head and 'height="72pt"' in head and 'viewBox="0 0 72 72"' in head
    invisible = sum(1 for s in by_feature.values() if s and s.get("opacity") == "0")
    assert invisible >= 1 and text.count('opacity="0"') == invisible


def _transformed(transform: str) -> str:
    return (
        '<svg xmlns="http://www.w3.org/2000/svg"><g><path id="p" d="M 0 0 L 10 0 L 10 10 Z" '
        f'transform="{transform}"/></g></svg>'
    )


@pytest.mark.parametrize(
    "transform",
    ["rotate(bad)", "matrix(1 2 3)", "translate(a,b)", "foo(1)", "rotate(30 1)",
     "scale(2) junk", "translate(10px, 5mm)", "scale(2%)", "skewX()"],
)  # fmt: skip
def test_malformed_transform_is_a_format_error(transform):
    # svgelements raised IndexError on some (a traceback) and ignored others silently
    with pytest.raises(CurveFormatError) as err:
        read_svg(io.StringIO(_transformed(transform)))
    assert f'<path id="p"> has transform={transform!r}, not an SVG transform list' in str(err.value)


@pytest.mark.parametrize(
    ("transform", "matrix"),
    [
        ("translate(3e1 -2.5E-1)", (1, 0, 0, 1, 30, -0.25)),
        (" scale(2) , translate(1 2) ", (2, 0, 0, 2, 2, 4)),
        ("translate(10px, 5px)", (1, 0, 0, 1, 10, 5)),
        ("rotate(0.25turn)", (0, 1, -1, 0, 0, 0)),
        ("rotate(90 5 5)", (0, 1, -1, 0, 10, 0)),
        ("skewX(45deg)", (1, 0, 1, 1, 0, 0)),
        ("", (1, 0, 0, 1, 0, 0)),
    ],
)
def test_valid_transforms_read_as_their_matrix(transform, matrix):
    a, b, c, d, e, f = matrix
    got = read_svg(io.StringIO(_transformed(transform)))[0].points
    ref = read_svg(io.StringIO(_transformed(f"matrix({a} {b} {c} {d} {e} {f})")))[0].points
    assert np.allclose(got, ref, rtol=0, atol=1e-12)
    square = [[0, 0], [10, 0], [10, 10]]
    want = [[a * x + c * y + e, b * x + d * y + f] for x, y in square]
    assert np.allclose(ref, want, rtol=0, atol=1e-12)
