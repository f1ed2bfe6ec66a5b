"""The Processing provider: one algorithm per terrapolis command, built from its description."""
# SPDX-License-Identifier: MIT
from qgis.core import QgsMessageLog, QgsProcessingProvider, Qgis

from . import cli
from .algorithm import TerrapolisAlgorithm


class TerrapolisProvider(QgsProcessingProvider):
    def __init__(self):
        super().__init__()
        self._description = None

    def id(self):
        return "terrapolis"

    def name(self):
        return "Terrapolis"

    def longName(self):  # noqa: N802
        d = self._description
        return "Terrapolis %s" % d["version"] if d else "Terrapolis"

    def loadAlgorithms(self):  # noqa: N802
        try:
            self._description = cli.describe()
        except Exception as e:  # the provider stays empty but QGIS keeps working
            QgsMessageLog.logMessage("Terrapolis: %s" % e, "Processing", Qgis.Warning)
            return
        for command in self._description["commands"]:
            self.addAlgorithm(TerrapolisAlgorithm(command, self._description["global_options"]))
