"""Open a run's run.gpkg in QGIS (headless), as a user dropping the file in: every vector layer.

Usage: /usr/bin/python3 check_geopackage.py RUN_FOLDER
Checks: run.gpkg holds every vector output of run.json (same names, same feature counts), each
layer valid with a valid CRS, and each loads with its default style from the layer_styles table:
the renderer QGIS builds from the style is the one project.qgs gives the same layer's GeoJSON.
"""
import os
import sys

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")
from qgis.core import QgsVectorLayer

from run_project import open_run

run = sys.argv[1]
manifest, project, app = open_run(run)
in_project = {l.name(): l for l in project.mapLayers().values()}
gpkg = os.path.join(run, "run.gpkg")
vectors = [o for o in manifest["outputs"] if o["kind"] == "vector"]
if not vectors:
    sys.exit("run.json lists no vector output")
for out in vectors:
    name = os.path.splitext(out["file"])[0]
    options = QgsVectorLayer.LayerOptions(True, True)  # load the default style (from layer_styles)
    layer = QgsVectorLayer("%s|layername=%s" % (gpkg, name), name, "ogr", options)
    if not layer.isValid():
        sys.exit("run.gpkg: layer %s does not open" % name)
    if not layer.crs().isValid():
        sys.exit("run.gpkg: layer %s has an invalid CRS" % name)
    if layer.featureCount() != out["features"]:
        sys.exit("run.gpkg: layer %s has %d features, run.json says %d" % (name, layer.featureCount(), out["features"]))
    wanted = in_project[name].renderer()
    got = layer.renderer()
    if wanted is None or got is None:
        continue  # an empty GeoJSON has no geometry type to style
    if got.type() != wanted.type():
        sys.exit("run.gpkg: layer %s renders as %s, the project as %s (its style did not load)" % (name, got.type(), wanted.type()))
    if got.type() == "categorizedSymbol" and (got.classAttribute() != wanted.classAttribute() or
                                               len(got.categories()) != len(wanted.categories())):
        sys.exit("run.gpkg: layer %s is classed by %s, the project by %s" % (name, got.classAttribute(), wanted.classAttribute()))
print("run.gpkg: %d layers open styled in QGIS" % len(vectors))
