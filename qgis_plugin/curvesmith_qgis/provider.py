"""The "curvesmith" Processing provider and its setting (the path of the program)."""

from __future__ import annotations

from qgis.core import QgsProcessingProvider

from .algorithms import ALGORITHM_CLASSES, CURVESMITH_PATH
from .icon import ICON_PATH, plugin_icon

__all__ = ["CurvesmithProvider"]


class CurvesmithProvider(QgsProcessingProvider):
    """Provider ``curvesmith``: algorithms ``smooth``, ``smoothcoverage``, ``smoothnetwork``."""

    def id(self) -> str:
        """Provider id (algorithm ids are ``curvesmith:<name>``)."""
        return "curvesmith"

    def name(self) -> str:
        """Name in the toolbox and in Processing > Options > Providers."""
        return "curvesmith"

    def longName(self) -> str:
        """Name with what it does."""
        return "curvesmith (area-preserving smoothing)"

    def icon(self):
        """The curvesmith icon."""
        return plugin_icon()

    def svgIconPath(self) -> str:
        """Path of the SVG icon."""
        return ICON_PATH

    def load(self) -> bool:
        """Register the CURVESMITH_PATH setting, then the algorithms."""
        try:
            from processing.core.ProcessingConfig import ProcessingConfig, Setting
        except ImportError:  # no Processing plugin: the program is looked up on PATH
            pass
        else:
            ProcessingConfig.settingIcons[self.name()] = self.icon()
            ProcessingConfig.addSetting(
                Setting(
                    self.name(),
                    CURVESMITH_PATH,
                    "curvesmith program (empty: found on PATH)",
                    "",
                    valuetype=Setting.FILE,
                )
            )
            ProcessingConfig.readSettings()
        self.refreshAlgorithms()
        return True

    def unload(self) -> None:
        """Remove the setting."""
        try:
            from processing.core.ProcessingConfig import ProcessingConfig
        except ImportError:
            return
        ProcessingConfig.removeSetting(CURVESMITH_PATH)

    def loadAlgorithms(self) -> None:
        """Add one instance of every algorithm."""
        for cls in ALGORITHM_CLASSES:
            self.addAlgorithm(cls())
