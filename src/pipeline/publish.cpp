// Publishing a run folder (QGIS and preview); the formats live in qgis_project.cpp and preview.cpp.
// SPDX-License-Identifier: MIT
#include "pipeline/publish.hpp"

#include "pipeline/preview.hpp"
#include "pipeline/qgis_project.hpp"

namespace terrapolis::pipeline {

void publish(RunState& state, nlohmann::ordered_json& manifest, const Log& log) {
  const auto& outputs = state.scenario.resolved["outputs"];
  if (outputs["qgis"].get<bool>()) {
    write_qgis_styles_and_project(state);
    manifest["outputs"].push_back({{"file", "project.qgs"}, {"stage", "publish"}, {"description", "QGIS project of the run (relative paths)"}, {"kind", "project"}});
    log.detail("wrote project.qgs and the .qml styles");
  }
  if (outputs["geopackage"].get<bool>()) {
    write_geopackage(state, (state.folder / "run.gpkg").string());
    manifest["outputs"].push_back({{"file", "run.gpkg"}, {"stage", "publish"},
                                   {"description", "every vector layer in one GeoPackage, each with its QGIS style"}, {"kind", "geopackage"}});
    log.detail("wrote run.gpkg");
  }
  // A run by tiles reads the rows the preview samples from its VRTs.
  if (outputs["preview"].get<bool>()) {
    write_preview(state, (state.folder / "preview.png").string(), outputs["preview_width"].get<int>());
    manifest["outputs"].push_back({{"file", "preview.png"}, {"stage", "publish"}, {"description", "quicklook of the run"}, {"kind", "image"}});
  }
}

}  // namespace terrapolis::pipeline
