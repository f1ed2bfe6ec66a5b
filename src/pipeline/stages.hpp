// The stages of a run, in data-flow order: what each reads from the scenario, computes and writes.
// SPDX-License-Identifier: MIT
#pragma once
#include <string>
#include <vector>

#include "core/progress.hpp"
#include "pipeline/run_state.hpp"

namespace terrapolis::pipeline {

struct StageDef {
  const char* name;
  /// Scenario keys the stage reads (besides those of the stages before it): a saved result of
  /// the stage can be reused only when they are unchanged.
  std::vector<std::string> sections;
  /// Computes the stage from the state and writes its files into state.folder.
  void (*run)(RunState&, Progress&, const Log&);
  /// Reads the stage's typed results back from its saved files in state.folder (reruns).
  void (*load)(RunState&);
};

/// The stages, in data-flow order: the one list the runner, --help and the docs read.
const std::vector<StageDef>& stages();

}  // namespace terrapolis::pipeline
