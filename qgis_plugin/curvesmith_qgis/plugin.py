"""The QGIS plugin: registers the curvesmith Processing provider."""

from __future__ import annotations

from qgis.core import QgsApplication

from .provider import CurvesmithProvider

__all__ = ["CurvesmithPlugin"]


class CurvesmithPlugin:
    """Adds the "curvesmith" provider to Processing; works without a GUI (``iface=None``).

    Parameters
    ----------
    iface : qgis.gui.QgisInterface or None
        QGIS's interface; None in headless use (``qgis_process``, scripts, tests).
    """

    def __init__(self, iface=None):
        self.iface = iface
        self.provider = None

    def initProcessing(self) -> None:
        """Register the provider (once)."""
        if self.provider is None:
            self.provider = CurvesmithProvider()
            QgsApplication.processingRegistry().addProvider(self.provider)

    def initGui(self) -> None:
        """Called by QGIS when the plugin is loaded with a GUI."""
        self.initProcessing()

    def unload(self) -> None:
        """Remove the provider."""
        if self.provider is not None:
            QgsApplication.processingRegistry().removeProvider(self.provider)
            self.provider = None
