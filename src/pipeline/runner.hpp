// Runs a scenario: every stage in data-flow order into a run folder, with provenance and a summary.
// SPDX-License-Identifier: MIT
#pragma once
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/progress.hpp"
#include "pipeline/scenario.hpp"

namespace terrapolis::pipeline {

/// Names of the stages, in the order data flows through them.
std::vector<std::string> stage_names();

struct RunOptions {
  bool overwrite = false;  ///< replace an existing run folder
  /// Rerun from this stage on, reading the earlier stages' results from the saved run folder.
  std::string from;
  /// Rerun only these stages; earlier ones are read back, later ones keep their saved files (stale).
  std::vector<std::string> only;
  /// Stop after this stage (a new run folder holds the stages up to it); empty: every stage.
  std::string until;
};

/// Runs `scenario` into its output folder, written under a temporary name and renamed at the end
/// (a failed run leaves nothing). Returns the manifest written as run.json.
nlohmann::ordered_json run_scenario(const Scenario& scenario, const RunOptions& options, Progress& progress, const Log& log);

/// The one-screen summary of a manifest (cities per class, roads, structures, timings).
std::string format_summary(const nlohmann::ordered_json& manifest);

}  // namespace terrapolis::pipeline
