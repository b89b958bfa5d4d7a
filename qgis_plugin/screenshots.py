"""Regenerate the README's QGIS pictures (docs/images/qgis_*.png) from a headless QGIS.

Run with the Python that has curvesmith (``python qgis_plugin/screenshots.py``): it writes
the Kentucky and West Virginia counties (plotly-geo's US Census file) to a GeoPackage,
then starts QGIS's own Python (``--qgis-python``, default ``/usr/bin/python3``) on this
same file, offscreen, to draw the plugin's ``icon.png`` (from ``icon.svg``) and

- ``qgis_toolbox.png``: the Processing toolbox searched for "smooth" (QGIS's own Smooth
  beside curvesmith's three algorithms),
- ``qgis_dialog.png``: the "Smooth coverage" dialog with its help panel,
- ``qgis_before_after.png``: four Kentucky counties drawn by QGIS's map renderer: the
  input, QGIS's Smooth (native:smoothgeometry, which opens gaps: red shows through) and
  curvesmith's Smooth coverage (no gaps, every county's area kept).

curvesmith runs from the environment this script was started from (its ``bin`` folder is
put on PATH).
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
IMAGES = HERE.parent / "docs" / "images"
#: Map window (EPSG:5070 metres): where Bourbon, Nicholas, Bath and Montgomery counties
#: (Kentucky) meet, with the winding Licking River and Slate Creek as borders.
CENTER, WIDTH = (1040192.0, 1750240.0), 6000.0


def prepare(folder: Path) -> Path:
    """Write the counties, projected to NAD83 / Conus Albers, to a GeoPackage."""
    import pyogrio

    from curvesmith import geo

    df = geo.us_counties(states=["21", "54"]).to_crs("EPSG:5070")
    path = folder / "counties.gpkg"
    pyogrio.write_dataframe(df, path, layer="counties", dataset_options={"VERSION": "1.2"})
    return path


def main(argv: list[str] | None = None) -> None:
    """Prepare the data here, then draw in QGIS's Python."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--qgis-python", default="/usr/bin/python3")
    parser.add_argument("--out", default=str(IMAGES), help="Folder for the PNGs.")
    parser.add_argument("--center", default=",".join(map(str, CENTER)), help="Map centre x,y.")
    parser.add_argument("--width", type=float, default=WIDTH, help="Map width (metres).")
    parser.add_argument("--in-qgis", nargs=2, metavar=("DATA", "OUT"), help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.in_qgis:
        center = tuple(float(v) for v in args.center.split(","))
        draw(Path(args.in_qgis[0]), Path(args.in_qgis[1]), center, args.width)
        return
    with tempfile.TemporaryDirectory() as tmp:
        data = prepare(Path(tmp))
        env = {k: v for k, v in os.environ.items() if k not in ("VIRTUAL_ENV", "PYTHONPATH")}
        env.update(QT_QPA_PLATFORM="offscreen", HOME=tmp, XDG_RUNTIME_DIR=tmp)
        env["PATH"] = f"{Path(sys.executable).parent}{os.pathsep}{env.get('PATH', '')}"
        Path(args.out).mkdir(parents=True, exist_ok=True)
        cmd = [args.qgis_python, __file__, "--in-qgis", str(data), args.out]
        cmd += ["--center", args.center, "--width", str(args.width)]
        subprocess.run(cmd, env=env, check=True)


# ------------------------------------------------------------------ in QGIS's Python


def _grab(widget, path: Path, size) -> None:
    from qgis.PyQt.QtWidgets import QApplication

    widget.resize(*size)
    widget.show()
    for _ in range(5):
        QApplication.processEvents()
    if not widget.grab().save(str(path)):
        raise RuntimeError(f"cannot write {path}")
    widget.close()


def _toolbox(path: Path) -> None:
    from qgis.core import QgsApplication
    from qgis.gui import QgsFilterLineEdit, QgsProcessingToolboxTreeView
    from qgis.PyQt.QtWidgets import QLabel, QVBoxLayout, QWidget

    box = QWidget()
    box.setWindowTitle("Processing Toolbox")
    layout = QVBoxLayout(box)
    layout.addWidget(QLabel("<b>Processing Toolbox</b>"))
    search = QgsFilterLineEdit()
    search.setText("smooth")
    layout.addWidget(search)
    tree = QgsProcessingToolboxTreeView(box, QgsApplication.processingRegistry())
    tree.setFilterString("smooth")
    tree.expandAll()
    tree.setHeaderHidden(True)
    layout.addWidget(tree)
    _grab(box, path, (380, 330))


def _dialog(path: Path, layer) -> None:
    from processing.gui.AlgorithmDialog import AlgorithmDialog
    from qgis.core import QgsApplication

    alg = QgsApplication.processingRegistry().createAlgorithmById("curvesmith:smoothcoverage")
    dialog = AlgorithmDialog(alg)
    _grab(dialog, path, (900, 560))


def _render(layers, extent, size):
    from qgis.core import QgsMapRendererParallelJob, QgsMapSettings
    from qgis.PyQt.QtCore import QSize
    from qgis.PyQt.QtGui import QColor

    settings = QgsMapSettings()
    settings.setLayers(layers)
    settings.setDestinationCrs(layers[0].crs())
    settings.setOutputSize(QSize(*size))
    settings.setExtent(extent)
    settings.setBackgroundColor(QColor("#d62728"))  # red where no polygon covers
    job = QgsMapRendererParallelJob(settings)
    job.start()
    job.waitForFinished()
    return job.renderedImage()


def _style(layer) -> None:
    from qgis.core import QgsFillSymbol, QgsSingleSymbolRenderer

    props = {"color": "#9ecae1", "outline_color": "#08306b", "outline_width": "0.4"}
    layer.setRenderer(QgsSingleSymbolRenderer(QgsFillSymbol.createSimple(props)))


def _before_after(path: Path, counties, processing, center, width) -> None:
    from qgis.core import QgsRectangle
    from qgis.PyQt.QtCore import QRect, Qt
    from qgis.PyQt.QtGui import QColor, QFont, QImage, QPainter

    native = processing.run(
        "native:smoothgeometry",
        {"INPUT": counties, "ITERATIONS": 3, "OFFSET": 0.25, "OUTPUT": "TEMPORARY_OUTPUT"},
    )["OUTPUT"]
    ours = processing.run(
        "curvesmith:smoothcoverage",
        {"INPUT": counties, "ITERATIONS": 3, "OUTPUT": "TEMPORARY_OUTPUT"},
    )["OUTPUT"]
    for layer in (counties, native, ours):
        _style(layer)
    (x, y), r = center, width / 2
    extent = QgsRectangle(x - r, y - r, x + r, y + r)
    panel, title_h = (420, 420), 34
    titles = [
        "Input counties",
        "QGIS Smooth: gaps (red)",
        "curvesmith Smooth coverage: no gaps",
    ]
    image = QImage(3 * panel[0] + 20, panel[1] + title_h, QImage.Format_RGB32)
    image.fill(QColor("white"))
    painter = QPainter(image)
    painter.setFont(QFont("DejaVu Sans", 12))
    for i, (layer, title) in enumerate(zip((counties, native, ours), titles, strict=True)):
        x = i * (panel[0] + 10)
        painter.drawImage(x, title_h, _render([layer], extent, panel))
        painter.setPen(QColor("black"))
        painter.drawText(QRect(x, 0, panel[0], title_h), Qt.AlignCenter, title)
    painter.end()
    if not image.save(str(path)):
        raise RuntimeError(f"cannot write {path}")


def _icon(svg: Path, png: Path, size: int = 64) -> None:
    """The plugin manager's icon: ``icon.svg`` rasterized."""
    from qgis.PyQt.QtCore import Qt
    from qgis.PyQt.QtGui import QImage, QPainter
    from qgis.PyQt.QtSvg import QSvgRenderer

    image = QImage(size, size, QImage.Format_ARGB32)
    image.fill(Qt.transparent)
    painter = QPainter(image)
    QSvgRenderer(str(svg)).render(painter)
    painter.end()
    if not image.save(str(png)):
        raise RuntimeError(f"cannot write {png}")


def draw(data: Path, out: Path, center=CENTER, width=WIDTH) -> None:
    """In QGIS's Python: load the plugin from this folder and draw the three pictures."""
    from qgis.core import QgsApplication, QgsProject, QgsVectorLayer

    QgsApplication.setPrefixPath("/usr", True)
    app = QgsApplication([], True)
    app.initQgis()
    sys.path.append("/usr/share/qgis/python/plugins")
    from processing.core.Processing import Processing

    Processing.initialize()
    import processing

    sys.path.insert(0, str(HERE))
    import curvesmith_qgis

    plugin = curvesmith_qgis.classFactory(None)
    plugin.initProcessing()
    counties = QgsVectorLayer(f"{data}|layername=counties", "counties", "ogr")
    QgsProject.instance().addMapLayer(counties)
    _icon(HERE / "curvesmith_qgis" / "icon.svg", HERE / "curvesmith_qgis" / "icon.png")
    _toolbox(out / "qgis_toolbox.png")
    _dialog(out / "qgis_dialog.png", counties)
    _before_after(out / "qgis_before_after.png", counties, processing, center, width)
    plugin.unload()
    app.exitQgis()


if __name__ == "__main__":
    main()
