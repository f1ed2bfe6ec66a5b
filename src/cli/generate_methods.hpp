// Options of `terrapolis generate --method coast | planar | river` (the flow and tectonic options are in
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
  generate::RiverFractalParams river;
  std::string coast_path, grammar = "0.2,0.7,0.1", tree_law = "increasing";
  double river_drop_share = 0.05;  ///< river: the bed's drop as a share of --relief when --river-drop is not given
  CLI::Option* river_drop = nullptr;

  void add(CLI::App& app);
  /// Copies the parameters into `request` (request.relief_m set); throws bad_input naming the option at fault.
  void apply(generate::GenerateRequest& request) const;
};

}  // namespace terrapolis::cli
