// `terrapolis compare RUN_A RUN_B [RUN_C ...]`: what changed between scenario runs (each against the first).
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
  std::string summary() const override {
    return "Compare run folders (the second and any further ones against the first): parameters, cities, roads, structures, density";
  }
  void setup(CLI::App& app) override {
    file_kind(app.add_option("RUN_A", a_, "First run folder (holds run.json)")->required(), FileKind::folder_in);
    file_kind(app.add_option("RUN_B", others_, "Run folder to compare with the first; several (a batch's runs): each against the first")
                  ->required(),
              FileKind::folder_in);
    app.add_flag("--json", json_, "Machine-readable output");
    file_kind(app.add_option("--save", save_, "Also write the comparison to this file (text, or JSON with --json)"), FileKind::file_out);
    app.add_flag("--overwrite", overwrite_, "Replace the --save file if it exists");
  }
  void run(Context&) override {
    const auto a = pipeline::load_manifest(a_);
    std::string text;
    nlohmann::ordered_json all = nlohmann::ordered_json::array();
    for (const auto& b : others_) {
      auto c = pipeline::compare_runs(a, pipeline::load_manifest(b));
      if (!json_) text += (text.empty() ? "" : "\n") + ("A: " + a_ + "\nB: " + b + "\n\n") + pipeline::format_comparison(c);
      all.push_back(std::move(c));
    }
    // One comparison is one object (as it always was); several are an array, in the order given.
    if (json_) text = (others_.size() == 1 ? all[0] : all).dump(2) + "\n";
    if (!save_.empty()) {
      std::vector<std::string> inputs = others_;
      inputs.push_back(a_);
      OutputSet outputs("compare", inputs, overwrite_);
      write_text_file(outputs.file(save_), text, false);
      outputs.commit();
    }
    std::fputs(text.c_str(), stdout);
  }

 private:
  std::string a_, save_;
  std::vector<std::string> others_;
  bool json_ = false, overwrite_ = false;
};

}  // namespace

std::unique_ptr<Command> make_compare_command() { return std::make_unique<CompareCommand>(); }

}  // namespace terrapolis::cli
