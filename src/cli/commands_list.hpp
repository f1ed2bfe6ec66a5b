// Factories of the subcommands, one per file in src/cli/.
// SPDX-License-Identifier: MIT
#pragma once
#include <memory>

#include "cli/command.hpp"

namespace terrapolis::cli {

std::unique_ptr<Command> make_info_command();
std::unique_ptr<Command> make_fill_command();
std::unique_ptr<Command> make_reconstruct_command();
std::unique_ptr<Command> make_generate_command();

}  // namespace terrapolis::cli
