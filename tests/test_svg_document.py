"""Smoothing an SVG keeps the document: text, images, defs, clip paths, groups (issue 13).

Before, the writer drew a new document of the curves only; text, images, gradients, clip
paths, groups and metadata of the source were lost. Now each element that gave curves is
replaced in place by a ``<path>`` of its smoothed curves, in the element's own coordinates
(under its own and its groups' transforms) with all its attributes, and everything else
is written back as it was.
"""

from __future__ import annotations

import io
import xml.etree.ElementTree as ET
from collections import Counter
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from curvesmith import cca
from curvesmith import io as cio
from curvesmith.cli import main
from curvesmith.geometry import signed_area

SHAPES = {"path", "rect", "circle", "ellipse", "line", "polyline", "polygon"}

DOC = """<svg xmlns="http://www.w3.org/2000/svg" xmlns:xlink="http://www.w3.org/1999/xlink"
  xmlns:inkscape="http://www.inkscape.org/namespaces/inkscape" viewBox="0 0 100 100"
  width="200" height="200">
 <title>a test drawing</title>
 <metadata><rdf>by hand</rdf></metadata>
 <defs>
  <clipPath id="clip"><rect x="0" y="0" width="60" height="60"/></clipPath>
  <linearGradient id="grad"><stop offset="0" stop-color="red"/><stop offset="1"
   stop-color="blue"/></linearGradient>
  <path id="arrow" d="M0 0 L10 0 L10 10 Z"/>
 </defs>
 <g id="layer1" transform="translate(5,7) rotate(10) scale(1.5)" inkscape:label="Layer 1">
  <polygon id="tri" class="shape" points="0,0 20,0 20,20 3,15" fill="url(#grad)"
   clip-path="url(#clip)"/>
 </g>
 <use xlink:href="#arrow" x="30" y="30"/>
 <rect id="box" x="60" y="60" width="30" height="20" rx="3" style="fill:blue;stroke:red"/>
 <circle id="dot" cx="20" cy="80" r="9" stroke="green" fill="none"/>
 <text x="1" y="95" font-size="4">hello <tspan fill="red">world</tspan></text>
 <image href="data:image/png;base64,iVBORw0KGgo=" x="0" y="0" width="10" height="10"/>
</svg>
"""


def _tags(root) -> Counter:
    return Counter(el.tag.rsplit("}", 1)[-1] for el in root.iter())


def _non_shapes(root) -> list[tuple[str, dict, str]]:
    out = []
    for el in root.iter():
        tag = el.tag.rsplit("}", 1)[-1]
        if tag not in SHAPES:
            out.append((tag, dict(el.attrib), (el.text or "").strip()))
    return out


def _smooth(src: Path, out: Path, *args: str):
    res = CliRunner().invoke(main, ["smooth", str(src), "-o", str(out), *args])
    assert res.exit_code == 0, res.output
    return res


def test_everything_but_the_smoothed_shapes_is_written_back(tmp_path):
    src = tmp_path / "doc.svg"
    src.write_text(DOC)
    out = tmp_path / "out.svg"
    res = _smooth(src, out, "--iterations", "2")
    # the <use> of a shape in defs: kept as it was, and said so in one line
    lines = [ln for ln in res.stderr.splitlines() if ln.strip()]
    assert lines == [
        f"Warning: {out}: 1 SVG element(s) drawn through <use> or inside defs, symbol, "
        "clipPath, mask, marker or pattern written back as they were (element 1)"
    ]
    before, after = ET.parse(src).getroot(), ET.parse(out).getroot()
    assert _non_shapes(after) == _non_shapes(before)  # text, image, defs, groups, metadata
    assert after.attrib == before.attrib  # page size and viewBox
    shapes = {el.get("id"): el for el in after.iter() if el.get("id") in ("tri", "box", "dot")}
    assert all(el.tag.endswith("}path") for el in shapes.values())
    assert shapes["tri"].get("clip-path") == "url(#clip)" and shapes["tri"].get("class") == "shape"
    assert shapes["box"].get("style") == "fill:blue;stroke:red"
    assert shapes["dot"].get("stroke") == "green"
    # shapes in defs and clipPath keep their geometry (they are drawn by reference)
    arrow = next(el for el in after.iter() if el.get("id") == "arrow")
    assert arrow.get("d") == "M0 0 L10 0 L10 10 Z"
    assert len([el for el in after.iter() if el.tag.endswith("}rect")]) == 1  # the clip's


def test_smoothed_curves_read_back_where_they_were_drawn(tmp_path):
    src = tmp_path / "doc.svg"
    src.write_text(DOC)
    out = tmp_path / "out.svg"
    _smooth(src, out)
    source, smoothed = cio.read_svg(src), cio.read_svg(out)
    assert [c.feature for c in smoothed] == [c.feature for c in source]
    for a, b in zip(source, smoothed, strict=True):
        if a.properties["id"] == "arrow":  # the <use> clone of a path in defs: unchanged
            assert np.array_equal(a.points, b.points)
            continue
        expected = cca.smooth(a.points, closed=True, iterations=1)
        if a.properties["id"] == "tri":  # under a rotation and scale: a few ulps
            assert np.allclose(b.points, expected, rtol=0, atol=1e-12)
        else:  # untransformed: bit for bit
            assert np.array_equal(b.points, expected)
        assert signed_area(b.points) == pytest.approx(signed_area(a.points), rel=1e-12)


def test_a_document_that_was_written_is_read_the_same_again(tmp_path):
    src = tmp_path / "doc.svg"
    src.write_text(DOC)
    first = cio.read_svg(src)
    buf = io.StringIO()
    with pytest.warns(cio.svg.SVGKeptWarning, match="1 SVG element"):
        cio.write_svg(first, buf)
    again = cio.read_svg(io.StringIO(buf.getvalue()))
    assert all(
        np.allclose(a.points, b.points, atol=1e-12) for a, b in zip(first, again, strict=True)
    )
    assert [c.style for c in again] == [c.style for c in first]


def _shipped_svgs() -> list[Path]:
    import matplotlib
    import pyogrio

    roots = [Path(matplotlib.__file__).parent / "mpl-data", Path(pyogrio.__file__).parent]
    return sorted(p for root in roots for p in root.rglob("*.svg"))


@pytest.mark.slow
def test_shipped_svgs_keep_every_element_that_is_not_smoothed(tmp_path):
    files = _shipped_svgs()
    assert len(files) >= 20
    for k, src in enumerate(files):
        out = tmp_path / f"{k}.svg"
        _smooth(src, out)
        before, after = ET.parse(src).getroot(), ET.parse(out).getroot()
        assert _non_shapes(after) == _non_shapes(before), src.name
        n_before = sum(_tags(before)[t] for t in SHAPES)
        assert sum(_tags(after)[t] for t in SHAPES) == n_before, src.name
        assert len(cio.read_svg(out)) == len(cio.read_svg(src)), src.name
