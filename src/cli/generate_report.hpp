// The figures `terrapolis generate` prints and writes beside the DEM: the skeleton against D8.
// SPDX-License-Identifier: MIT
#pragma once
#include <string>

#include "core/progress.hpp"
#include "generate/generator.hpp"

namespace terrapolis::cli {

/// Runs the hydro stage's D8 (priority-flood fill, D8, upstream area, streams from the generator's
/// channel-head area) on `terrain.dem`, checks the skeleton against
/// it (generate/river_checks.hpp), logs the summary and returns the report as JSON text.
std::string skeleton_report(const generate::GeneratedTerrain& terrain, double cell_m, const std::string& method,
                            const Log& log, Progress& progress);

}  // namespace terrapolis::cli
