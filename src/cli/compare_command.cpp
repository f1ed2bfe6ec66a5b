// `terrapolis compare RUN_A RUN_B`: what changed between two scenario runs.
// SPDX-License-Identifier: MIT
#include <CLI/CLI.hpp>

#include <cstdio>

#include "cli/command.hpp"
#include "cli/commands_list.hpp"
#include "cli/schema_options.hpp"
#include "io/output_set.hpp"
#include "io/text_io.hpp"
#include "pipeline/compare.hpp"

namespace terrapolis::cli {
namespace {

class CompareCommand final : public Command {
 public:
  std::string name() const override { return "compare"; }
  std::string summary() const override { return "Compare two run folders: parameters, cities, roads, structures, density"; }
  void setup(CLI::App& app) override {
    file_kind(app.add_option("RUN_A", a_, "First run folder (holds run.json)")->required(), FileKind::folder_in);
    file_kind(app.add_option("RUN_B", b_, "Second run folder")->required(), FileKind::folder_in);
    app.add_flag("--json", json_, "Machine-readable output");
    file_kind(app.add_option("--save", save_, "Also write the comparison to this file (text, or JSON with --json)"), FileKind::file_out);
    app.add_flag("--overwrite", overwrite_, "Replace the --save file if it exists");
  }
  void run(Context&) override {
    const auto c = pipeline::compare_runs(pipeline::load_manifest(a_), pipeline::load_manifest(b_));
    const std::string text =
        json_ ? c.dump(2) + "\n" : "A: " + a_ + "\nB: " + b_ + "\n\n" + pipeline::format_comparison(c);
    if (!save_.empty()) {
      OutputSet outputs("compare", {a_, b_}, overwrite_);
      write_text_file(outputs.file(save_), text, false);
      outputs.commit();
    }
    std::fputs(text.c_str(), stdout);
  }

 private:
  std::string a_, b_, save_;
  bool json_ = false, overwrite_ = false;
};

}  // namespace

std::unique_ptr<Command> make_compare_command() { return std::make_unique<CompareCommand>(); }

}  // namespace terrapolis::cli
