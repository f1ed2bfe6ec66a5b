"""A run folder opened in QGIS (headless): its run.json and its project.qgs, for the checks beside."""
import json
import os
import sys

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")
from qgis.core import QgsApplication, QgsProject


def open_run(run):
    """Returns (manifest, project, app) of the run folder; exits naming the problem if it does not open."""
    manifest = json.load(open(os.path.join(run, "run.json")))
    app = QgsApplication([], False)
    app.initQgis()
    project = QgsProject.instance()
    if not project.read(os.path.join(run, "project.qgs")):
        sys.exit("project.qgs does not open: " + project.error())
    return manifest, project, app
