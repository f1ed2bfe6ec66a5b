// The one list of `terrapolis` subcommands.
// SPDX-License-Identifier: MIT
#include "cli/command.hpp"
#include "cli/commands_list.hpp"

#include <CLI/CLI.hpp>

namespace terrapolis::cli {

void add_overwrite_flag(CLI::App& app, bool& overwrite) {
  app.add_flag("--overwrite", overwrite,
               "Replace the outputs a previous terrapolis command wrote (a file or folder it did not write is refused, never replaced)");
}

std::vector<std::unique_ptr<Command>> all_commands() {
  std::vector<std::unique_ptr<Command>> commands;
  commands.push_back(make_info_command());
  commands.push_back(make_convert_command());
  commands.push_back(make_hydro_command());
  commands.push_back(make_catchment_command());
  commands.push_back(make_lake_command());
  commands.push_back(make_density_command());
  commands.push_back(make_sites_command());
  commands.push_back(make_calibrate_command());
  commands.push_back(make_network_command());
  commands.push_back(make_path_command());
  commands.push_back(make_roads_command());
  commands.push_back(make_access_command());
  commands.push_back(make_fill_command());
  commands.push_back(make_reconstruct_command());
  commands.push_back(make_skeleton_command());
  commands.push_back(make_generate_command());
  commands.push_back(make_erode_command());
  commands.push_back(make_run_command());
  commands.push_back(make_compare_command());
  return commands;
}

}  // namespace terrapolis::cli
