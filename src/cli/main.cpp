// The `terrapolis` command line: global options, subcommands, exit codes (main: terrapolis.cpp, mpi_main.cpp).
// SPDX-License-Identifier: MIT
#include <CLI/CLI.hpp>
#include <tbb/global_control.h>

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include "cli/command.hpp"
#include "cli/describe.hpp"
#include "cli/schema_options.hpp"
#include "core/error.hpp"
#include "core/interrupt.hpp"
#include "io/output_set.hpp"
#include "io/raster_io.hpp"
#include "terrapolis/version.hpp"

namespace {

/// True for "-97.3", "-5,2", "-.5": a negative number typed as an option's value.
bool looks_negative_number(const std::string& s) {
  return s.size() > 1 && s[0] == '-' && (std::isdigit(static_cast<unsigned char>(s[1])) || s[1] == '.');
}

/// Joins "--opt -97.29,32.74" into "--opt=-97.29,32.74" so users can type negative coordinates as is.
std::vector<std::string> join_negative_values(int argc, char** argv) {
  std::vector<std::string> args;
  for (int i = 1; i < argc; ++i) {
    std::string a = argv[i];
    if (a.rfind("--", 0) == 0 && a.find('=') == std::string::npos && i + 1 < argc && looks_negative_number(argv[i + 1])) {
      a += "=";
      a += argv[++i];
    }
    args.push_back(a);
  }
  return args;
}

}  // namespace

int terrapolis::cli::run_command_line(int argc, char** argv) {
  using namespace terrapolis;
  CLI::App app{"Terrapolis: from a georeferenced elevation model to a regional urbanisation plan.", "terrapolis"};
  app.set_version_flag("--version", std::string("terrapolis ") + terrapolis::version);
  app.require_subcommand(1);
  app.fallthrough();  // global options may follow the subcommand
  bool quiet = false, verbose = false;
  std::string progress_kind = "console";
  int threads = 0;
  app.add_flag("-q,--quiet", quiet, "Print only errors (no progress, no messages)");
  app.add_flag("-v,--verbose", verbose, "Print details of the work");
  app.add_option("--progress", progress_kind, "Progress on stderr: console (GDAL style), json (one object per line), none")
      ->check(CLI::IsMember({"console", "json", "none"}));
  app.add_option("--threads", threads, "Worker threads (0: all cores); outputs do not depend on it")->check(CLI::NonNegativeNumber);
  bool describe = false;
  app.add_flag("--describe-json", describe, "Print every command and option as JSON (for GUIs such as the QGIS provider) and exit");

  auto commands = cli::all_commands();
  std::vector<std::pair<CLI::App*, cli::Command*>> subs;
  for (auto& c : commands) {
    CLI::App* sub = app.add_subcommand(c->name(), c->summary());
    c->setup(*sub);
    subs.emplace_back(sub, c.get());
  }

  auto args = join_negative_values(argc, argv);
  if (std::find(args.begin(), args.end(), "--describe-json") != args.end()) {  // no subcommand needed
    std::printf("%s\n", cli::describe_cli(app, terrapolis::version).dump(2).c_str());
    return 0;
  }
  std::reverse(args.begin(), args.end());  // CLI11 takes the arguments reversed
  try {
    app.parse(args);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);  // --help, --version
    // One line, as for every other bad input (CLI11's own format adds a second line).
    std::string command = "terrapolis";
    for (auto& [sub, c] : subs)
      if (sub->parsed()) command += " " + sub->get_name();
    std::fprintf(stderr, "terrapolis: error: %s (%s --help lists the options)\n", e.what(), command.c_str());
    return 2;
  }

  std::optional<tbb::global_control> limit;
  if (threads > 0) limit.emplace(tbb::global_control::max_allowed_parallelism, std::size_t(threads));
  SilentProgress silent;
  ConsoleProgress console;
  JsonProgress json;
  Progress& progress = (quiet || progress_kind == "none") ? static_cast<Progress&>(silent)
                       : progress_kind == "json"          ? static_cast<Progress&>(json)
                                                          : static_cast<Progress&>(console);
  cli::Context context{Log(quiet ? LogLevel::quiet : verbose ? LogLevel::verbose : LogLevel::normal), progress, threads};
  init_gdal();
  catch_interrupts();
  try {
    for (auto& [sub, command] : subs)
      if (sub->parsed()) command->run(context);
  } catch (const Error& e) {
    if (e.kind() == ErrorKind::cancelled && interrupt_signal()) {
      // The outputs' temporary folders are gone (removed while the error unwound): say so, exit 128 + signal.
      std::fprintf(stderr, "terrapolis: %s: stopped, no output written\n", e.what());
      return 128 + interrupt_signal();
    }
    std::string message = e.what();
    for (auto& [sub, command] : subs)
      if (sub->parsed()) message = cli::with_flag_names(message, sub->get_name());
    std::fprintf(stderr, "terrapolis: error: %s\n", with_output_names(message).c_str());
    return e.exit_code();
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "terrapolis: error: out of memory\n");
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "terrapolis: error: %s\n", with_output_names(e.what()).c_str());
    return 1;
  }
  return 0;
}
