// `terrapolis run A.json B.json ...`: a batch of scenarios, each run in its own process and folder.
// SPDX-License-Identifier: MIT
#pragma once
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "core/progress.hpp"

namespace terrapolis::cli {

/// What `run` was given for a batch: every scenario gets the same overrides.
struct BatchRequest {
  std::vector<std::string> scenarios;    ///< files, or one folder whose *.json are the scenarios
  std::vector<std::string> sets;         ///< --set, for every scenario
  std::optional<std::uint64_t> seed;     ///< --seed
  std::optional<std::string> parent;     ///< -o: the folder that holds one run folder per scenario (named by its file)
  bool overwrite = false;
  std::string from, until;
  std::vector<std::string> only;
  int jobs = 1;                          ///< runs at once
  int threads = 0;                       ///< --threads of the whole batch (0: all cores), shared by the runs at once
};

/// True for several scenario files, or one folder of them.
bool is_batch(const std::vector<std::string>& paths);

/// The scenario files of a batch: `paths` as given, a folder expanded to its *.json files by name.
std::vector<std::string> batch_scenarios(const std::vector<std::string>& paths);

/// Loads every scenario first (a scenario that does not load, or whose run folder another one
/// already takes, is refused and not run), then runs the others `jobs` at a time, each as a
/// `terrapolis run` process of its own (its outputs are those of the same run alone), and prints a
/// table of their outcomes. Throws Error when a run did not succeed: bad_input when every failure
/// was a refusal, processing otherwise; cancelled on SIGINT/SIGTERM (forwarded to the runs).
void run_batch(const BatchRequest& request, const Log& log);

}  // namespace terrapolis::cli
