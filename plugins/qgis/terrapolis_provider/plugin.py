"""The QGIS plugin object: adds the provider to the Processing registry and removes it on unload."""
# SPDX-License-Identifier: MIT
from qgis.core import QgsApplication

from .provider import TerrapolisProvider


class TerrapolisPlugin:
    def __init__(self, iface):
        self.iface = iface
        self.provider = None

    def initProcessing(self):  # noqa: N802 (QGIS's name)
        self.provider = TerrapolisProvider()
        QgsApplication.processingRegistry().addProvider(self.provider)

    def initGui(self):  # noqa: N802
        self.initProcessing()

    def unload(self):
        if self.provider is not None:
            QgsApplication.processingRegistry().removeProvider(self.provider)
            self.provider = None
