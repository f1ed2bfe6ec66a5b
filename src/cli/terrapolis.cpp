// Entry point of the `terrapolis` command line.
// SPDX-License-Identifier: MIT
#include "cli/command.hpp"

int main(int argc, char** argv) { return terrapolis::cli::run_command_line(argc, argv); }
