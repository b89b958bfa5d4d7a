"""The documentation site builds offline with warnings as errors and documents every public name."""

from __future__ import annotations

import importlib
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

from curvesmith.internals import lazy_modules

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"

pytest.importorskip("sphinx", reason="the docs build needs the dev extra (sphinx)")


def _api_modules() -> list[str]:
    text = (DOCS / "api.rst").read_text(encoding="utf-8")
    return re.findall(r"^   (curvesmith[\w.]*)$", text, flags=re.M)


def test_every_demo_section_has_a_gallery_script():
    from curvesmith.demo import SECTIONS

    scripts = {p.stem.removeprefix("plot_") for p in (ROOT / "examples").glob("plot_*.py")}
    assert scripts == set(SECTIONS)


def test_api_page_lists_every_public_module():

    listed = set(_api_modules())
    public = {f"curvesmith.{n}" for n in lazy_modules} | {
        "curvesmith.geometry",
        "curvesmith.subdivision",
        "curvesmith.errors",
        "curvesmith.demo",
    }
    assert public <= listed


@pytest.mark.slow
def test_docs_build_without_warnings(tmp_path):
    out = tmp_path / "html"
    env = {**os.environ, "MPLBACKEND": "Agg"}
    proc = subprocess.run(
        [
            sys.executable,
            "-m",
            "sphinx",
            "-W",
            "--keep-going",
            "-q",
            "-b",
            "html",
            str(DOCS),
            str(out),
        ],
        capture_output=True,
        text=True,
        env=env,
        timeout=900,
    )
    assert proc.returncode == 0, proc.stderr[-4000:]
    # an API page for every public name of every module on the API page
    missing = []
    for modname in _api_modules():
        module = importlib.import_module(modname)
        for name in getattr(module, "__all__", []):
            obj = getattr(module, name)
            if isinstance(obj, type(sys)):
                page = out / "generated" / f"{obj.__name__}.html"
            else:
                page = out / "generated" / f"{modname}.{name}.html"
            if not page.exists() and not (out / "generated" / f"{modname}.html").read_text(
                encoding="utf-8"
            ).count(f'id="{modname}.{name}"'):
                missing.append(f"{modname}.{name}")
    assert not missing, missing
    cli = (out / "cli.html").read_text(encoding="utf-8")
    for command in ("measure", "smooth", "fair", "keyline", "batch", "demo"):
        assert f"curvesmith-{command}" in cli
    gallery = (out / "auto_examples" / "index.html").read_text(encoding="utf-8")
    assert gallery.count("sphx-glr-thumbcontainer") >= 7
    assert (out / "benchmarks.html").read_text(encoding="utf-8").count("<table") >= 1
