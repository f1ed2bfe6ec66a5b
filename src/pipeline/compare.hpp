// Comparing two scenario runs from their run.json manifests.
// SPDX-License-Identifier: MIT
#pragma once
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/raster.hpp"

namespace terrapolis::pipeline {

/// Loads RUN/run.json. Throws bad_input naming the folder.
nlohmann::ordered_json load_manifest(const std::string& run_folder);

/// What changed between two runs: every scenario parameter that differs, and every figure of the
/// summaries (cities per class, road length per class, structures, mean density...) with A, B and B - A.
nlohmann::ordered_json compare_runs(const nlohmann::ordered_json& a, const nlohmann::ordered_json& b);

/// Where the travel times changed: for each access_minutes*.tif both run folders hold on the same
/// grid, B - A in minutes (negative: closer in B, after a new road; NaN where either run reaches
/// nothing), named "<stem>_change.tif". Files on different grids are skipped (another DEM).
std::vector<std::pair<std::string, Raster<float>>> access_changes(const std::string& run_a, const std::string& run_b);

/// The comparison as an aligned text table.
std::string format_comparison(const nlohmann::ordered_json& comparison);

}  // namespace terrapolis::pipeline
