"""The QGIS Processing provider, headless: it loads, lists the commands as typed algorithms, runs
hydro and density through processing.run with progress, honours cancel, and its outputs are valid layers.

Usage: TERRAPOLIS_BIN=... /usr/bin/python3 check_provider.py SOURCE_DIR DEM WORK_DIR
"""
import os
import sys

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")
source, dem, work = sys.argv[1], sys.argv[2], sys.argv[3]
sys.path.insert(0, "/usr/share/qgis/python/plugins")  # Debian's processing plugin
sys.path.insert(0, os.path.join(source, "plugins", "qgis"))

from qgis.core import (QgsApplication, QgsProcessingException, QgsProcessingFeedback, QgsProcessingParameterEnum,
                       QgsProcessingParameterFolderDestination, QgsProcessingParameterNumber,
                       QgsProcessingParameterRasterLayer, QgsRasterLayer, QgsVectorLayer, QgsProject)

app = QgsApplication([], False)
app.initQgis()
from processing.core.Processing import Processing  # noqa: E402 (needs the application)
Processing.initialize()
import processing  # noqa: E402

from terrapolis_provider.algorithm import load_layer  # noqa: E402
from terrapolis_provider.provider import TerrapolisProvider  # noqa: E402

provider = TerrapolisProvider()
assert QgsApplication.processingRegistry().addProvider(provider), "the provider does not register"
ids = sorted(a.id() for a in provider.algorithms())
for name in ("info", "hydro", "density", "sites", "network", "path", "roads", "fill", "generate", "run", "compare"):
    assert "terrapolis:" + name in ids, (name, ids)

# Typed parameters, straight from --describe-json.
density = QgsApplication.processingRegistry().algorithmById("terrapolis:density")
assert isinstance(density.parameterDefinition("DEM"), QgsProcessingParameterRasterLayer)
assert isinstance(density.parameterDefinition("OUTDIR"), QgsProcessingParameterFolderDestination)
r_min = density.parameterDefinition("r_min")
assert isinstance(r_min, QgsProcessingParameterNumber) and r_min.defaultValue() == 500.0, r_min
path = QgsApplication.processingRegistry().algorithmById("terrapolis:path")
k = path.parameterDefinition("k")
assert k.minimum() == 1 and k.maximum() == 16 and k.defaultValue() == 5, (k.minimum(), k.maximum(), k.defaultValue())
router = path.parameterDefinition("router")
assert isinstance(router, QgsProcessingParameterEnum) and router.options() == ["galin", "bezier"], router.options()
assert path.parameterDefinition("bridges").defaultValue() is True


class Recorder(QgsProcessingFeedback):
    """Keeps the progress values and texts; cancels at the first progress when asked to."""
    def __init__(self, cancel=False):
        super().__init__()
        self.values, self.texts, self.cancel_at_start = [], [], cancel

    def setProgressText(self, text):  # noqa: N802
        self.texts.append(text)
        super().setProgressText(text)

    def setProgress(self, value):  # noqa: N802
        self.values.append(value)
        super().setProgress(value)
        if self.cancel_at_start:
            self.cancel()


hydro_dir, density_dir = os.path.join(work, "hydro"), os.path.join(work, "density")
feedback = Recorder()
result = processing.run("terrapolis:hydro", {"DEM": dem, "OUTDIR": hydro_dir}, feedback=feedback)
assert result["OUTDIR"] == hydro_dir, result
assert any(v == 100.0 for v in feedback.values) and len(feedback.texts) >= 3, (feedback.values[:5], feedback.texts)
feedback = Recorder()
result = processing.run("terrapolis:density", {"DEM": dem, "OUTDIR": density_dir, "hydrometry": os.path.join(hydro_dir, "hydrometry.tif"),
                                                 "weights": "1,1,1.5,0.5"}, feedback=feedback)
assert any("density" in t for t in feedback.texts), feedback.texts
layers = result["OUTPUT_LAYERS"]
assert any(p.endswith("density.tif") for p in layers), layers
for path_ in layers + [os.path.join(hydro_dir, "streams.geojson")]:
    layer = QgsRasterLayer(path_, "r") if path_.endswith(".tif") else QgsVectorLayer(path_, "v", "ogr")
    assert layer.isValid(), path_
    assert layer.crs().authid() == "EPSG:4326", (path_, layer.crs().authid())
streams = QgsVectorLayer(os.path.join(hydro_dir, "streams.geojson"), "streams", "ogr")
assert streams.featureCount() > 10, streams.featureCount()

# The whole pipeline from the toolbox (few cities, so it is quick): the run folder's layers load.
run_dir = os.path.join(work, "run_from_qgis")
result = processing.run("terrapolis:run", {"set": "dem=%s\nsites.quota_scale=0.01" % dem, "output": run_dir}, feedback=Recorder())
run_layers = result["OUTPUT_LAYERS"]
assert any(p.endswith("roads.geojson") for p in run_layers) and any(p.endswith("density.tif") for p in run_layers), run_layers
assert os.path.exists(os.path.join(run_dir, "project.qgs")), "no project.qgs in the run folder"
for path_ in run_layers:
    assert load_layer(path_).isValid(), path_
# compare: the run against itself, the table shown in the log and saved to a file.
report = os.path.join(work, "compare.txt")
result = processing.run("terrapolis:compare", {"RUN_A": run_dir, "RUN_B": run_dir, "save": report}, feedback=Recorder())
assert result["save"] == report, result
with open(report) as f:
    assert "Parameters that differ:\n  (none)" in f.read(), open(report).read()

# Cancel: the process is killed, the algorithm fails, nothing is written.
cancelled_dir = os.path.join(work, "cancelled")
try:
    processing.run("terrapolis:hydro", {"DEM": dem, "OUTDIR": cancelled_dir}, feedback=Recorder(cancel=True))
    sys.exit("a cancelled run succeeded")
except QgsProcessingException as e:
    assert "cancelled" in str(e), e
assert not os.path.exists(cancelled_dir), "a cancelled run left its folder"
# A failing run reports the error.
try:
    processing.run("terrapolis:density", {"DEM": dem, "OUTDIR": os.path.join(work, "bad"), "weights": "1,2"}, feedback=Recorder())
    sys.exit("a bad run succeeded")
except QgsProcessingException as e:
    assert "exit code 2" in str(e), e
print("QGIS provider: %d algorithms, hydro and density ran, %d layers valid" % (len(ids), len(layers)))
QgsApplication.processingRegistry().removeProvider(provider)
# No app.exitQgis(): with Processing initialised, python3-qgis 3.22 crashes in it at teardown;
# the process exit releases everything anyway.
