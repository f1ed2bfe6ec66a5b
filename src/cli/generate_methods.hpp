// Options of `terrapolis generate --method coast | planar` (the flow and tectonic options are in
// generate_command.cpp, which reads the --coast polygons).
// SPDX-License-Identifier: MIT
#pragma once
#include <CLI/CLI.hpp>

#include <string>

#include "generate/generator.hpp"

namespace terrapolis::cli {

struct CoastPlanarOptions {
  generate::CoastParams coast;
  generate::PlanarParams planar;
  std::string coast_path, grammar = "0.2,0.7,0.1", tree_law = "increasing";

  void add(CLI::App& app);
  /// Copies the parameters into `request`; throws bad_input naming the option at fault.
  void apply(generate::GenerateRequest& request) const;
};

}  // namespace terrapolis::cli
