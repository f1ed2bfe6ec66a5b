// A subcommand of the `terrapolis` command line; every command is registered in commands.cpp.
// SPDX-License-Identifier: MIT
#pragma once
#include <array>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "core/progress.hpp"

namespace CLI { class App; }

namespace terrapolis::cli {

/// What every command receives from the global options.
struct Context {
  Log log;
  Progress& progress;
  int threads = 0;  ///< 0: all cores
};

class Command {
 public:
  virtual ~Command() = default;
  virtual std::string name() const = 0;
  virtual std::string summary() const = 0;
  /// Declares the command's options on its CLI11 subcommand.
  virtual void setup(CLI::App& app) = 0;
  /// Runs with the parsed options. Throws terrapolis::Error.
  virtual void run(Context& context) = 0;
};

/// Declares --overwrite, the same for every command: replace what a previous terrapolis command
/// wrote (OutputSet's contract, docs/safety.md).
void add_overwrite_flag(CLI::App& app, bool& overwrite);

/// Parses the command line and runs its command; returns the exit code (errors printed on stderr).
int run_command_line(int argc, char** argv);

/// Every command, in the order `terrapolis --help` lists them (the one registration point).
std::vector<std::unique_ptr<Command>> all_commands();

/// Runs a command's output writes concurrently, on the threads --threads allows: GDAL compresses
/// each file on few threads, and on large grids writing is a good part of a command's time. Each
/// write is atomic by itself (temporary file, then rename); the first failure is rethrown.
void write_concurrently(const std::vector<std::function<void()>>& writes);

/// Parses a number typed for `option` (core/text.hpp's parse_number). Throws bad_input naming `option`.
double parse_number_option(const std::string& option, const std::string& text);

/// Parses "X,Y" (either may be negative) into two numbers. Throws bad_input naming `option`.
std::array<double, 2> parse_pair(const std::string& option, const std::string& text);

}  // namespace terrapolis::cli
