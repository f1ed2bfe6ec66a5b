// What makes a run folder usable at once: QGIS styles and project, preview.png.
// SPDX-License-Identifier: MIT
#pragma once
#include <nlohmann/json.hpp>

#include "core/progress.hpp"
#include "pipeline/run_state.hpp"

namespace terrapolis::pipeline {

/// Writes the .qml beside each layer and project.qgs (if outputs.qgis), and preview.png (if
/// outputs.preview), recording them in `manifest["outputs"]`.
void publish(RunState& state, nlohmann::ordered_json& manifest, const Log& log);

}  // namespace terrapolis::pipeline
