"""The real client test: open a run's project.qgs in QGIS (headless) and check every layer.

Usage: /usr/bin/python3 check_project.py RUN_FOLDER OUT.png
Checks: every layer valid with a valid CRS (QGIS reads an incomplete <spatialrefsys> as an invalid
CRS while authid() still names it), the project's CRS valid and the DEM's, the expected CRS, extent
and feature count (read from run.json), styles applied (renderer type), every layer's extent
transformed to the project CRS inside the DEM's (vectors in degrees over rasters in metres on a
projected run), the cities drawn over the rasters, and the project renders to a non-empty image.
"""
import os
import sys

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")
from qgis.core import (QgsMapSettings, QgsMapRendererParallelJob,
                       QgsRasterLayer, QgsVectorLayer, QgsCoordinateReferenceSystem, QgsRectangle,
                       QgsCoordinateTransform)
from qgis.PyQt.QtCore import QSize
from qgis.PyQt.QtGui import QColor

from run_project import open_run

run, png = sys.argv[1], sys.argv[2]
manifest, project, app = open_run(run)

expected = {os.path.splitext(o["file"])[0]: o for o in manifest["outputs"] if o["kind"] in ("raster", "vector")}
layers = {l.name(): l for l in project.mapLayers().values()}
missing = set(expected) - set(layers)
if missing:
    sys.exit("layers missing from the project: %s" % sorted(missing))
epsg = manifest["input"]["epsg"]
if not project.crs().isValid():
    sys.exit("the project's CRS is not valid")
if project.crs() != layers["elevation"].crs():
    sys.exit("the project's CRS %s is not the DEM's %s" % (project.crs().authid(), layers["elevation"].crs().authid()))
for name, layer in layers.items():
    if not layer.isValid():
        sys.exit("layer %s is not valid (source %s)" % (name, layer.source()))
    if not layer.crs().isValid():
        sys.exit("layer %s has an invalid CRS (authid '%s')" % (name, layer.crs().authid()))
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
        if out["features"] == 0 and renderer is None:
            continue  # an empty GeoJSON carries no geometry type: QGIS has nothing to style or draw
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

# On the map (the project's CRS) every layer lies over the DEM: vectors in lon/lat are transformed.
# Each city (a cell centre) falls inside the DEM's extent; other layers' bounding boxes, whose
# corners a transformation between lon/lat and a rotated projected grid pushes out, within 10 %.
dem_extent = layers["elevation"].extent()
for name, layer in layers.items():
    to_project = QgsCoordinateTransform(layer.crs(), project.crs(), project)
    if name == "cities":
        inside = dem_extent.buffered(max(dem_extent.width(), dem_extent.height()) * 0.001)
        for feature in layer.getFeatures():
            p = to_project.transform(feature.geometry().asPoint())
            if not inside.contains(p):
                sys.exit("city %s lies at %s in the project CRS, outside the DEM's %s" % (feature["id"], p.toString(), dem_extent.toString()))
        continue
    if isinstance(layer, QgsVectorLayer) and layer.featureCount() == 0:
        continue  # an empty layer has no extent
    extent = to_project.transformBoundingBox(layer.extent())
    if not dem_extent.buffered(max(dem_extent.width(), dem_extent.height()) * 0.1).contains(extent):
        sys.exit("layer %s lies at %s in the project CRS, outside the DEM's %s" % (name, extent.toString(), dem_extent.toString()))

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
# The cities alone, rendered over the DEM's extent in the project CRS: they show (not off the map).
if "cities" in layers and layers["cities"].featureCount() > 0:
    settings.setLayers([layers["cities"]])
    settings.setBackgroundColor(QColor(255, 255, 255, 0))
    job = QgsMapRendererParallelJob(settings)
    job.start()
    job.waitForFinished()
    cities = job.renderedImage()
    drawn = sum(1 for y in range(cities.height()) for x in range(cities.width()) if (cities.pixel(x, y) >> 24) & 255)
    if drawn == 0:
        sys.exit("the cities are not drawn over the DEM's extent in the project CRS")
print("QGIS opened %d layers; rendering has %d colours" % (len(layers), len(colours)))
app.exitQgis()
