// QGIS styles (.qml beside each layer) and a project.qgs that opens a run folder with relative paths.
// SPDX-License-Identifier: MIT
#pragma once
#include <string>

#include "pipeline/run_state.hpp"

namespace terrapolis::pipeline {

/// The style of one output as the body of a QGIS 3 style (<pipe> for rasters, <renderer-v2> for vectors).
std::string qgis_style_body(const OutputFile& output, const RunState& state);

/// The whole .qml document of one output's style.
std::string qgis_style(const OutputFile& output, const RunState& state);

/// Writes every vector layer of the run into one GeoPackage at `path`, in the DEM's CRS, each layer
/// named as its GeoJSON (cities, roads...) and styled by default (the layer_styles table QGIS reads).
void write_geopackage(const RunState& state, const std::string& path);

/// Writes `<layer>.qml` beside every layer of the run and `project.qgs` with all layers, grouped by
/// stage and ordered so that points draw over lines over polygons over rasters.
void write_qgis_styles_and_project(const RunState& state);

}  // namespace terrapolis::pipeline
