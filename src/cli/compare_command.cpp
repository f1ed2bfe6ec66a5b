// `terrapolis compare RUN_A RUN_B [RUN_C ...]`: what changed between scenario runs (each against the first).
// SPDX-License-Identifier: MIT
#include <CLI/CLI.hpp>

#include <cstdio>
#include <filesystem>

#include "cli/command.hpp"
#include "cli/commands_list.hpp"
#include "cli/schema_options.hpp"
#include "core/error.hpp"
#include "io/output_set.hpp"
#include "io/raster_io.hpp"
#include "io/text_io.hpp"
#include "pipeline/compare.hpp"
#include "terrapolis/version.hpp"

namespace terrapolis::cli {
namespace {

namespace fs = std::filesystem;

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
    file_kind(app.add_option("--changes", changes_, "Also write where the travel times changed (access_minutes*_change.tif: B - A, minutes) into this folder"),
              FileKind::folder_out);
    add_overwrite_flag(app, overwrite_);
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
    if (!save_.empty() || !changes_.empty()) {
      std::vector<std::string> inputs = others_;
      inputs.push_back(a_);
      OutputSet outputs("compare", inputs, overwrite_);
      if (!changes_.empty()) {
        if (others_.size() != 1) throw bad_input("--changes: compares two runs (give RUN_A and one RUN_B)");
        const fs::path dir = outputs.folder(changes_);
        const auto changes = pipeline::access_changes(a_, others_[0]);
        if (changes.empty()) throw bad_input("--changes: " + a_ + " and " + others_[0] + " hold no travel-time raster on the same grid (access_minutes.tif)");
        for (const auto& [name, raster] : changes) {
          WriteOptions w;
          w.description = "Change of the travel time, minutes: B - A (negative: closer in B)";
          w.metadata = {{"TERRAPOLIS_VERSION", version}, {"TERRAPOLIS_COMMAND", "compare"}, {"UNIT", "min"}, {"RUN_A", a_}, {"RUN_B", others_[0]}};
          write_raster((dir / name).string(), raster, w);
          std::size_t closer = 0, farther = 0;
          for (std::size_t i = 0; i < raster.size(); ++i) closer += raster[i] < -1, farther += raster[i] > 1;
          if (!json_) text += "\n" + name + ": " + std::to_string(closer) + " cells over a minute closer in B, " + std::to_string(farther) + " over a minute farther\n";
        }
      }
      if (!save_.empty()) write_text_file(outputs.file(save_), text, false);
      outputs.commit();
    }
    std::fputs(text.c_str(), stdout);
  }

 private:
  std::string a_, save_, changes_;
  std::vector<std::string> others_;
  bool json_ = false, overwrite_ = false;
};

}  // namespace

std::unique_ptr<Command> make_compare_command() { return std::make_unique<CompareCommand>(); }

}  // namespace terrapolis::cli
