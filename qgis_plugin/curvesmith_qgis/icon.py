"""The plugin's icon (``icon.svg`` beside this file)."""

from __future__ import annotations

import os

from qgis.PyQt.QtGui import QIcon

__all__ = ["ICON_PATH", "plugin_icon"]

ICON_PATH = os.path.join(os.path.dirname(__file__), "icon.svg")


def plugin_icon() -> QIcon:
    """The curvesmith icon."""
    return QIcon(ICON_PATH)
