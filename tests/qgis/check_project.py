"""The real client test: open a run's project.qgs in QGIS (headless) and check every layer.

Usage: /usr/bin/python3 check_project.py RUN_FOLDER OUT.png
Checks: every layer valid, the expected CRS, extent and feature count (read from run.json),
styles applied (renderer type), and the project renders to a non-empty image.
"""
import json
import os
import sys

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")
from qgis.core import (QgsApplication, QgsProject, QgsMapSettings, QgsMapRendererParallelJob,
                       QgsRasterLayer, QgsVectorLayer, QgsCoordinateReferenceSystem, QgsRectangle)
from qgis.PyQt.QtCore import QSize
from qgis.PyQt.QtGui import QColor

run, png = sys.argv[1], sys.argv[2]
manifest = json.load(open(os.path.join(run, "run.json")))
app = QgsApplication([], False)
app.initQgis()
project = QgsProject.instance()
if not project.read(os.path.join(run, "project.qgs")):
    sys.exit("project.qgs does not open: " + project.error())

expected = {os.path.splitext(o["file"])[0]: o for o in manifest["outputs"] if o["kind"] in ("raster", "vector")}
layers = {l.name(): l for l in project.mapLayers().values()}
missing = set(expected) - set(layers)
if missing:
    sys.exit("layers missing from the project: %s" % sorted(missing))
epsg = manifest["input"]["epsg"]
for name, layer in layers.items():
    if not layer.isValid():
        sys.exit("layer %s is not valid (source %s)" % (name, layer.source()))
    out = expected[name]
    if isinstance(layer, QgsRasterLayer):
        if epsg and layer.crs().authid() != "EPSG:%d" % epsg:
            sys.exit("raster %s has CRS %s, expected EPSG:%d" % (name, layer.crs().authid(), epsg))
        if layer.width() != manifest["summary"]["terrain"]["cols"] or layer.height() != manifest["summary"]["terrain"]["rows"]:
            sys.exit("raster %s is %dx%d" % (name, layer.width(), layer.height()))
        renderer = layer.renderer().type()
        wanted = {"hillshade": "singlebandgray"}.get(name)
        if wanted and renderer != wanted:
            sys.exit("raster %s renderer %s, expected %s" % (name, renderer, wanted))
        if name != "hillshade" and renderer not in ("singlebandpseudocolor", "paletted"):
            sys.exit("raster %s is not styled (renderer %s)" % (name, renderer))
    else:
        if layer.crs().authid() != "EPSG:4326":
            sys.exit("vector %s has CRS %s, expected EPSG:4326 (RFC 7946)" % (name, layer.crs().authid()))
        if layer.featureCount() != out["features"]:
            sys.exit("vector %s has %d features, run.json says %d" % (name, layer.featureCount(), out["features"]))
        renderer = layer.renderer()
        if renderer.type() not in ("categorizedSymbol", "singleSymbol", "graduatedSymbol"):
            sys.exit("vector %s is not styled" % name)
        if renderer.type() == "categorizedSymbol":
            # The style names a real field and each feature falls in one of its classes.
            field = renderer.classAttribute()
            if layer.fields().indexOf(field) < 0:
                sys.exit("vector %s is styled by a field %s it does not have" % (name, field))
            values = {str(c.value()) for c in renderer.categories()}
            for feature in ([] if "" in values else layer.getFeatures()):  # "": a class for every other value
                if str(feature[field]) not in values:
                    sys.exit("vector %s: %s = %s has no class in its style %s" % (name, field, feature[field], sorted(values)))
    # Every layer lies inside the DEM's extent.
    dem = layers["elevation"]
    if not dem.extent().buffered(dem.extent().width() * 0.01).contains(
            layer.extent() if isinstance(layer, QgsRasterLayer) else QgsRectangle(layer.extent())) and isinstance(layer, QgsRasterLayer):
        sys.exit("layer %s is outside the DEM" % name)

settings = QgsMapSettings()
settings.setLayers([l for l in project.layerTreeRoot().layerOrder() if l.isValid()])
settings.setDestinationCrs(layers["elevation"].crs())
settings.setExtent(layers["elevation"].extent())
settings.setOutputSize(QSize(400, 400))
settings.setBackgroundColor(QColor(255, 255, 255))
job = QgsMapRendererParallelJob(settings)
job.start()
job.waitForFinished()
image = job.renderedImage()
image.save(png)
colours = set()
for y in range(0, image.height(), 10):
    for x in range(0, image.width(), 10):
        colours.add(image.pixel(x, y))
if len(colours) < 20:
    sys.exit("the rendered project is nearly empty (%d colours)" % len(colours))
print("QGIS opened %d layers; rendering has %d colours" % (len(layers), len(colours)))
app.exitQgis()
