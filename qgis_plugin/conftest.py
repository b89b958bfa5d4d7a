"""The plugin imports qgis, which only QGIS's Python has: pytest must not import it."""

collect_ignore = ["curvesmith_qgis", "build.py", "screenshots.py"]
