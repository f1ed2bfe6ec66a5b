"""The Processing provider: one algorithm per terrapolis command, built from its description."""
# SPDX-License-Identifier: MIT
from qgis.core import QgsMessageLog, QgsProcessingProvider, Qgis

from . import cli
from .algorithm import TerrapolisAlgorithm

# Commands whose result a Processing dialog cannot show (a comparison printed as a table).
SKIPPED = {"compare"}


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
            if command["name"] not in SKIPPED:
                self.addAlgorithm(TerrapolisAlgorithm(command, self._description["global_options"]))
