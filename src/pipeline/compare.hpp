// Comparing two scenario runs from their run.json manifests.
// SPDX-License-Identifier: MIT
#pragma once
#include <string>

#include <nlohmann/json.hpp>

namespace terrapolis::pipeline {

/// Loads RUN/run.json. Throws bad_input naming the folder.
nlohmann::ordered_json load_manifest(const std::string& run_folder);

/// What changed between two runs: every scenario parameter that differs, and every figure of the
/// summaries (cities per class, road length per class, structures, mean density...) with A, B and B - A.
nlohmann::ordered_json compare_runs(const nlohmann::ordered_json& a, const nlohmann::ordered_json& b);

/// The comparison as an aligned text table.
std::string format_comparison(const nlohmann::ordered_json& comparison);

}  // namespace terrapolis::pipeline
