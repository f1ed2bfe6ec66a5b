// Options of `terrapolis generate --method coast | planar` (the flow and tectonic options are in
// generate_command.cpp, which reads the --coast polygons).
// SPDX-License-Identifier: MIT
#pragma once
#include <CLI/CLI.hpp>

#include <string>

#include "terrain/generator.hpp"

namespace terrapolis::cli {

struct CoastPlanarOptions {
  terrain::CoastParams coast;
  terrain::PlanarParams planar;
  std::string coast_path, grammar = "0.2,0.7,0.1", tree_law = "increasing";

  void add(CLI::App& app);
  /// Copies the parameters into `request`; throws bad_input naming the option at fault.
  void apply(terrain::GenerateRequest& request) const;
};

}  // namespace terrapolis::cli
