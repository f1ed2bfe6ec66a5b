"""QGIS plugin entry point: registers the Terrapolis Processing provider."""
# SPDX-License-Identifier: MIT


def classFactory(iface):  # noqa: N802 (QGIS's name)
    from .plugin import TerrapolisPlugin
    return TerrapolisPlugin(iface)
