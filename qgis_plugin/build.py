"""Build the installable QGIS plugin zip: ``python qgis_plugin/build.py [-o DIR]``.

Writes ``DIR/curvesmith_qgis-<version>.zip`` (default DIR: ``dist/`` at the repository
root), the form that QGIS's Plugins > Manage and Install Plugins > Install from ZIP and the
plugin repository take: one top-level folder ``curvesmith_qgis/`` with ``metadata.txt``,
the modules, the icon and the license. Needs only the standard library.
"""

from __future__ import annotations

import argparse
import configparser
import zipfile
from pathlib import Path

__all__ = ["PLUGIN_DIR", "build"]

PLUGIN_DIR = Path(__file__).resolve().parent / "curvesmith_qgis"
_REPO = PLUGIN_DIR.parent.parent


def build(dest: str | Path | None = None) -> Path:
    """Write the plugin zip into `dest` (created if needed) and return its path."""
    meta = configparser.ConfigParser()
    meta.read(PLUGIN_DIR / "metadata.txt", encoding="utf-8")
    version = meta["general"]["version"]
    dest = Path(dest) if dest is not None else _REPO / "dist"
    dest.mkdir(parents=True, exist_ok=True)
    out = dest / f"{PLUGIN_DIR.name}-{version}.zip"
    files = sorted(
        p
        for p in PLUGIN_DIR.rglob("*")
        if p.is_file() and "__pycache__" not in p.parts and p.suffix != ".pyc"
    )
    with zipfile.ZipFile(out, "w", zipfile.ZIP_DEFLATED) as zf:
        for p in files:
            zf.write(p, f"{PLUGIN_DIR.name}/{p.relative_to(PLUGIN_DIR).as_posix()}")
        zf.write(_REPO / "LICENSE", f"{PLUGIN_DIR.name}/LICENSE")
    return out


def main(argv: list[str] | None = None) -> None:
    """Command line entry point."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("-o", "--output", default=None, help="Folder for the zip [dist/].")
    args = parser.parse_args(argv)
    print(build(args.output))


if __name__ == "__main__":
    main()
