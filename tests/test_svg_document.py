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
 <use xlink:href="#arrow" x="70" y="10"/>
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
    # the two <use> of a shape in defs: kept as it was, and said so in one line
    lines = [ln for ln in res.stderr.splitlines() if ln.strip()]
    assert lines == [
        f"Warning: {out}: 2 SVG element(s) drawn more than once through <use>, referenced by "
        "other elements, or inside a clipPath, mask, marker, pattern or scaled symbol, "
        "written back as they were (element 1, 2)"
    ]
    before, after = ET.parse(src).getroot(), ET.parse(out).getroot()
    assert _non_shapes(after) == _non_shapes(before)  # text, image, defs, groups, metadata
    assert after.attrib == before.attrib  # page size and viewBox
    shapes = {el.get("id"): el for el in after.iter() if el.get("id") in ("tri", "box", "dot")}
    assert all(el.tag.endswith("}path") for el in shapes.values())
    assert shapes["tri"].get("clip-path") == "url(#clip)" and shapes["tri"].get("class") == "shape"
    assert shapes["box"].get("style") == "fill:blue;stroke:red"
    assert shapes["dot"].get("stroke") == "green"
    # a shape in defs drawn twice, and a clipPath's, keep their geometry
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
        if a.properties["id"] == "arrow":  # the <use> clones of a path in defs: unchanged
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
    with pytest.warns(cio.svg.SVGKeptWarning, match="2 SVG element"):
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


FIGMA = """<svg width="44" height="51" viewBox="0 0 44 51" xmlns="http://www.w3.org/2000/svg"
  xmlns:xlink="http://www.w3.org/1999/xlink">
<g id="Canvas" transform="translate(-1640 -2453)">
 <g id="g1"><use xlink:href="#path0_fill" transform="translate(1641 2455)" fill="#4E4E4E"/></g>
 <g id="g2"><use xlink:href="#path1_fill" transform="translate(1660 2470) scale(2)"/></g>
 <use xlink:href="#path2" transform="translate(1650 2490)"/>
 <text><textPath xlink:href="#path2">on the path</textPath></text>
</g>
<defs>
 <path id="path0_fill" d="M0 0 L12 1 L14 9 L6 14 L-1 8 Z"/>
 <path id="path1_fill" d="M0 0 C 3 -2 6 2 9 0 L 9 6 L 0 6 Z"/>
 <path id="path2" d="M0 0 L10 0 L10 5 L0 5 Z"/>
</defs>
</svg>
"""


def test_a_path_in_defs_drawn_once_is_smoothed_where_it_is_defined(tmp_path):
    # Figma and Illustrator export every path in defs, drawn by one <use>: those were
    # written back unchanged (the whole drawing, for such a file), while `smooth` said it
    # smoothed them. Now each is rewritten in its own coordinates; one that a textPath
    # also follows stays as it was.
    src, out = tmp_path / "figma.svg", tmp_path / "out.svg"
    src.write_text(FIGMA)
    res = _smooth(src, out)
    lines = [ln for ln in res.stderr.splitlines() if ln.strip()]
    assert lines == [
        f"Warning: {out}: 1 SVG element(s) drawn more than once through <use>, referenced by "
        "other elements, or inside a clipPath, mask, marker, pattern or scaled symbol, "
        "written back as they were (element 2)"
    ]
    source, smoothed = cio.read_svg(src), cio.read_svg(out)
    assert [len(c.points) for c in source] == [5, len(source[1].points), 4]
    for a, b in zip(source[:2], smoothed[:2], strict=True):
        expected = cca.smooth(a.points, closed=True, iterations=1)
        assert np.allclose(b.points, expected, rtol=0, atol=1e-9)  # document coordinates
        assert signed_area(b.points) == pytest.approx(signed_area(a.points), rel=1e-12)
    assert np.array_equal(smoothed[2].points, source[2].points)
    after = ET.parse(out).getroot()
    ns = {"s": "http://www.w3.org/2000/svg"}
    defs = {el.get("id"): el for el in after.find("s:defs", ns)}
    assert set(defs) == {"path0_fill", "path1_fill", "path2"}  # still in defs, with their ids
    assert defs["path2"].get("d") == "M0 0 L10 0 L10 5 L0 5 Z"
    assert defs["path0_fill"].get("d") != "M0 0 L12 1 L14 9 L6 14 L-1 8 Z"
    uses = [el for el in after.iter() if el.tag.endswith("}use")]
    assert len(uses) == 3  # the <use> elements draw them as before


def test_curves_of_a_document_fit_only_what_is_rewritten(tmp_path):
    # `smooth --curves` printed a fitted curve for each shape drawn by reference and then
    # wrote the document back unchanged, with Python's warning text (file, line, code)
    src, out = tmp_path / "doc.svg", tmp_path / "out.svg"
    src.write_text(DOC)
    res = CliRunner().invoke(
        main, ["smooth", str(src), "-o", str(out), "--curves", "cubic", "--iterations", "3"]
    )
    assert res.exit_code == 0, res.output
    lines = [ln for ln in res.stderr.splitlines() if ln.strip()]
    assert lines[1:3] == [
        "curve 1: written back as it was (see the warning)",
        "curve 2: written back as it was (see the warning)",
    ]
    assert "cubic segment(s)" in lines[0] and "cubic segment(s)" in lines[3]
    assert lines[-1] == (
        f"Warning: {out}: 2 SVG element(s) drawn more than once through <use>, referenced by "
        "other elements, or inside a clipPath, mask, marker, pattern or scaled symbol, "
        "written back as they were (element 1, 2)"
    )
    assert not any("SVGKeptWarning" in ln for ln in lines)
    arrow = next(el for el in ET.parse(out).getroot().iter() if el.get("id") == "arrow")
    assert arrow.get("d") == "M0 0 L10 0 L10 10 Z"


def test_a_scaled_symbol_stays_as_it_was(tmp_path):
    # a <symbol viewBox> is drawn scaled onto its <use>'s width and height, which the
    # reader does not apply: rewriting it would smooth it in the wrong units
    doc = """<svg xmlns="http://www.w3.org/2000/svg" xmlns:xlink="http://www.w3.org/1999/xlink"
  viewBox="0 0 100 100">
 <symbol id="s" viewBox="0 0 10 10" preserveAspectRatio="none">
  <path id="p" d="M1 1 L9 1 L9 9 L5 6 L1 9 Z"/></symbol>
 <use xlink:href="#s" x="50" y="40" width="40" height="20"/>
 <polygon id="q" points="0,0 20,0 20,20 3,15"/>
</svg>"""
    src, out = tmp_path / "sym.svg", tmp_path / "out.svg"
    src.write_text(doc)
    res = _smooth(src, out)
    assert "scaled symbol" in res.stderr
    p = next(el for el in ET.parse(out).getroot().iter() if el.get("id") == "p")
    assert p.get("d") == "M1 1 L9 1 L9 9 L5 6 L1 9 Z"
