"""One terrapolis command as a Processing algorithm, its parameters typed from --describe-json."""
# SPDX-License-Identifier: MIT
import os
import re

from qgis.core import (QgsProcessing, QgsProcessingAlgorithm, QgsProcessingContext, QgsProcessingException,
                       QgsProcessingParameterBoolean, QgsProcessingParameterEnum, QgsProcessingParameterFile,
                       QgsProcessingParameterFileDestination, QgsProcessingParameterFolderDestination,
                       QgsProcessingParameterMultipleLayers,
                       QgsProcessingParameterNumber, QgsProcessingParameterRasterDestination,
                       QgsProcessingParameterRasterLayer, QgsProcessingParameterString,
                       QgsProcessingParameterVectorLayer, QgsProcessingOutputMultipleLayers,
                       QgsRasterLayer, QgsVectorLayer)

from . import cli

OUTPUT_LAYERS = "OUTPUT_LAYERS"


def parameter_name(option):
    """A Processing parameter name from an option name: "--max-slope" -> "max_slope", "DEM" -> "DEM"."""
    return re.sub(r"[^A-Za-z0-9_]", "_", option["name"].lstrip("-"))


# Units that say nothing a dialog label needs (the schema's x-unit of counts, switches, choices, paths).
SILENT_UNITS = {None, "", "1", "flag", "choice", "path", "list", "name", "object", "CRS"}


def make_parameter(option):
    """The Processing parameter for one option, or None for options the dialog does not offer."""
    name, help_text, kind = parameter_name(option), option["help"], option.get("kind")
    if option.get("unit") not in SILENT_UNITS:
        help_text += " [" + option["unit"] + "]"
    optional = not option["required"]
    default = option.get("default")
    if option["type"] == "boolean":
        return QgsProcessingParameterBoolean(name, help_text, defaultValue=bool(default), optional=True)
    if "choices" in option:
        choices = option["choices"]
        index = choices.index(default) if default in choices else None
        return QgsProcessingParameterEnum(name, help_text, options=choices, defaultValue=index,
                                          optional=optional or index is not None)
    if option["type"] in ("integer", "number"):
        kind_number = QgsProcessingParameterNumber.Integer if option["type"] == "integer" else QgsProcessingParameterNumber.Double
        p = QgsProcessingParameterNumber(name, help_text, type=kind_number, defaultValue=default,
                                         optional=optional or default is not None)
        if "minimum" in option:
            p.setMinimum(option["minimum"])
        if "maximum" in option:
            p.setMaximum(option["maximum"])
        return p
    if kind == "raster_in" and option.get("repeatable"):
        return QgsProcessingParameterMultipleLayers(name, help_text, QgsProcessing.TypeRaster, optional=optional)
    if kind == "raster_in":
        return QgsProcessingParameterRasterLayer(name, help_text, optional=optional)
    if kind == "vector_in":
        return QgsProcessingParameterVectorLayer(name, help_text, [QgsProcessing.TypeVectorAnyGeometry], optional=optional)
    if kind == "file_in":
        return QgsProcessingParameterFile(name, help_text, optional=optional)
    if kind == "folder_in":
        return QgsProcessingParameterFile(name, help_text, behavior=QgsProcessingParameterFile.Folder, optional=optional)
    if kind == "folder_out":
        return QgsProcessingParameterFolderDestination(name, help_text, optional=optional)
    if kind == "raster_out":
        return QgsProcessingParameterRasterDestination(name, help_text, optional=optional)
    if kind == "vector_out":
        return QgsProcessingParameterFileDestination(name, help_text, "GeoJSON (*.geojson);;GeoPackage (*.gpkg)", optional=optional)
    if kind == "file_out":
        return QgsProcessingParameterFileDestination(name, help_text, optional=optional)
    # Free text; repeatable options take one value per line.
    if option.get("repeatable"):
        return QgsProcessingParameterString(name, help_text, multiLine=True, optional=True)
    return QgsProcessingParameterString(name, help_text, defaultValue=default, optional=optional or default is not None)


class TerrapolisAlgorithm(QgsProcessingAlgorithm):
    def __init__(self, command, global_options):
        super().__init__()
        self.command = command
        self.global_options = global_options

    def createInstance(self):  # noqa: N802
        return TerrapolisAlgorithm(self.command, self.global_options)

    def name(self):
        return self.command["name"]

    def displayName(self):  # noqa: N802
        return self.command["name"]

    def shortHelpString(self):  # noqa: N802
        return self.command["summary"]

    def initAlgorithm(self, config=None):  # noqa: N802
        for option in self.command["options"]:
            p = make_parameter(option)
            if p is not None:
                self.addParameter(p)
        self.addOutput(QgsProcessingOutputMultipleLayers(OUTPUT_LAYERS, "Output layers"))

    def arguments(self, parameters, context):
        """The command line for `parameters`: positionals first, then --name=value options."""
        positional, named, outputs = [], [], []
        for option in self.command["options"]:
            name = parameter_name(option)
            if name not in parameters or parameters[name] is None:
                continue
            kind = option.get("kind")
            if option["type"] == "boolean":
                value = self.parameterAsBool(parameters, name, context)
                if value != bool(option.get("default")):
                    names = option.get("names", [option["name"]])
                    negated = [n for n in names if n.startswith("--no-")]
                    if value or negated:
                        named.append(option["name"] if value else negated[0])
                continue
            if "choices" in option:
                value = option["choices"][self.parameterAsEnum(parameters, name, context)]
            elif option["type"] == "integer":
                value = str(self.parameterAsInt(parameters, name, context))
            elif option["type"] == "number":
                value = repr(self.parameterAsDouble(parameters, name, context))
            elif kind == "raster_in" and option.get("repeatable"):
                layers = self.parameterAsLayerList(parameters, name, context)
                value = "\n".join(l.source() for l in layers)
            elif kind == "raster_in":
                layer = self.parameterAsRasterLayer(parameters, name, context)
                value = layer.source() if layer else None
            elif kind == "vector_in":
                layer = self.parameterAsVectorLayer(parameters, name, context)
                value = layer.source().split("|")[0] if layer else None
            elif kind in ("file_in", "folder_in"):
                value = self.parameterAsFile(parameters, name, context)
            elif kind == "folder_out":
                value = self.parameterAsString(parameters, name, context)
                outputs.append((name, "folder", value))
            elif kind in ("raster_out", "vector_out", "file_out"):
                value = self.parameterAsFileOutput(parameters, name, context)
                outputs.append((name, "file", value))
            else:
                value = self.parameterAsString(parameters, name, context)
            if value is None or value == "":
                continue
            if option["positional"]:
                positional.append(value)
            elif option.get("repeatable"):
                named.extend("%s=%s" % (option["name"], v) for v in str(value).splitlines() if v.strip())
            else:
                named.append("%s=%s" % (option["name"], value))
        return [self.command["name"]] + positional + named, outputs

    def processAlgorithm(self, parameters, context, feedback):  # noqa: N802
        args, outputs = self.arguments(parameters, context)
        feedback.pushCommandInfo("terrapolis " + " ".join(args))

        def on_progress(step, fraction):
            feedback.setProgressText(step)
            feedback.setProgress(100.0 * fraction)

        code = cli.run(args, on_progress, feedback.pushInfo, feedback.isCanceled)
        if code is None:
            raise QgsProcessingException("terrapolis %s: cancelled" % self.command["name"])
        if code != 0:
            raise QgsProcessingException("terrapolis %s failed (exit code %d); see the log" % (self.command["name"], code))
        layers = []
        result = {}
        for name, what, path in outputs:
            result[name] = path
            files = [path] if what == "file" else [os.path.join(path, f) for f in sorted(os.listdir(path))] if os.path.isdir(path) else []
            for f in files:
                if f.endswith((".tif", ".geojson", ".gpkg")) and os.path.exists(f):
                    layers.append(f)
                    # Loaded by QGIS with their default style (the .qml beside the file, when present).
                    details = QgsProcessingContext.LayerDetails(os.path.splitext(os.path.basename(f))[0], context.project(), "")
                    context.addLayerToLoadOnCompletion(f, details)
        result[OUTPUT_LAYERS] = layers
        return result


def load_layer(path):
    """A QGIS layer for an output file (used by the tests)."""
    if path.endswith(".tif"):
        return QgsRasterLayer(path, os.path.basename(path))
    return QgsVectorLayer(path, os.path.basename(path), "ogr")
