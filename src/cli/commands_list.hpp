// Factories of the subcommands, one per file in src/cli/.
// SPDX-License-Identifier: MIT
#pragma once
#include <memory>

#include "cli/command.hpp"

namespace terrapolis::cli {

std::unique_ptr<Command> make_info_command();
std::unique_ptr<Command> make_convert_command();
std::unique_ptr<Command> make_density_command();
std::unique_ptr<Command> make_run_command();
std::unique_ptr<Command> make_compare_command();
std::unique_ptr<Command> make_hydro_command();
std::unique_ptr<Command> make_catchment_command();
std::unique_ptr<Command> make_lake_command();
std::unique_ptr<Command> make_skeleton_command();
std::unique_ptr<Command> make_sites_command();
std::unique_ptr<Command> make_network_command();
std::unique_ptr<Command> make_path_command();
std::unique_ptr<Command> make_roads_command();
std::unique_ptr<Command> make_fill_command();
std::unique_ptr<Command> make_erode_command();
std::unique_ptr<Command> make_reconstruct_command();
std::unique_ptr<Command> make_generate_command();
std::unique_ptr<Command> make_calibrate_command();
std::unique_ptr<Command> make_access_command();

}  // namespace terrapolis::cli
