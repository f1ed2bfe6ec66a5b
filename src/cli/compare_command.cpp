// `terrapolis compare RUN_A RUN_B`: what changed between two scenario runs.
// SPDX-License-Identifier: MIT
#include <CLI/CLI.hpp>

#include <cstdio>

#include "cli/command.hpp"
#include "cli/commands_list.hpp"
#include "pipeline/compare.hpp"

namespace terrapolis::cli {
namespace {

class CompareCommand final : public Command {
 public:
  std::string name() const override { return "compare"; }
  std::string summary() const override { return "Compare two run folders: parameters, cities, roads, structures, density"; }
  void setup(CLI::App& app) override {
    app.add_option("RUN_A", a_, "First run folder (holds run.json)")->required();
    app.add_option("RUN_B", b_, "Second run folder")->required();
    app.add_flag("--json", json_, "Machine-readable output");
  }
  void run(Context&) override {
    const auto c = pipeline::compare_runs(pipeline::load_manifest(a_), pipeline::load_manifest(b_));
    if (json_) std::printf("%s\n", c.dump(2).c_str());
    else std::printf("A: %s\nB: %s\n\n%s", a_.c_str(), b_.c_str(), pipeline::format_comparison(c).c_str());
  }

 private:
  std::string a_, b_;
  bool json_ = false;
};

}  // namespace

std::unique_ptr<Command> make_compare_command() { return std::make_unique<CompareCommand>(); }

}  // namespace terrapolis::cli
