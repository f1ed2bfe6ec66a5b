// preview.png: the run at a glance, without a GIS.
// SPDX-License-Identifier: MIT
#pragma once
#include <string>

#include "pipeline/run_state.hpp"

namespace terrapolis::pipeline {

/// Draws hillshade, sea, density, streams, network, roads and cities with a small legend, `width`
/// pixels wide (height from the grid's extent in metres), and writes it as PNG with OpenImageIO.
void write_preview(const RunState& state, const std::string& path, int width);

}  // namespace terrapolis::pipeline
