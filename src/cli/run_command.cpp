// `terrapolis run [SCENARIO.json]`: the whole pipeline from one scenario file into one run folder.
// SPDX-License-Identifier: MIT
#include <CLI/CLI.hpp>

#include <cstdio>
#include <filesystem>

#include "cli/command.hpp"
#include "cli/commands_list.hpp"
#include "cli/run_batch.hpp"
#include "cli/schema_options.hpp"
#include "pipeline/runner.hpp"
#include "pipeline/scenario.hpp"

namespace terrapolis::cli {
namespace {

class RunCommand final : public Command {
 public:
  std::string name() const override { return "run"; }
  std::string summary() const override {
    return "Run a scenario (JSON) from DEM to roads; without a file, the default scenario on the bundled Corsica DEM";
  }
  void setup(CLI::App& app) override {
    file_kind(app.add_option("SCENARIO", files_,
                             "Scenario file (JSON, see schemas/scenario.schema.json); default: the embedded scenario. Several "
                             "files, or a folder of them, run as a batch: one run folder each, --jobs at once, a table at the end"),
              FileKind::file_in);
    app.add_option("--jobs", jobs_, "Batch: runs at once (each a process of its own, sharing --threads)")->check(CLI::PositiveNumber);
    app.add_option("--set", sets_, "Override a field: stage.field=value (repeatable), e.g. --set density.weights=[1,1,0,0]");
    // --seed: the schema's seed, over the scenario's when given (its range: a negative seed is refused).
    // The run's messages keep naming the scenario's settings by pointer (/seed from a file or --set).
    schema_.setup(app, name(), false);
    file_kind(app.add_option("-o,--output", output_, "Run folder (overrides the scenario's); batch: the folder holding a run folder per scenario, named by its file"),
              FileKind::folder_out);
    add_overwrite_flag(app, overwrite_);
    const std::vector<std::string> stages = pipeline::stage_names();
    app.add_option("--from", from_, "Rerun from this stage on, reading the earlier stages' results back from the run")
        ->check(CLI::IsMember(stages));
    app.add_option("--only", only_, "Rerun only these stages (later stages keep their saved, now stale, results)")
        ->expected(1, -1)
        ->check(CLI::IsMember(stages));
    app.add_option("--until", until_, "Stop after this stage (the run folder holds the stages up to it)")->check(CLI::IsMember(stages));
    app.add_flag("--print-scenario", print_, "Print the resolved scenario (defaults filled) and exit");
  }
  void run(Context& context) override {
    if (schema_.given("/seed")) seed_ = schema_.scenario().resolved["seed"].get<std::uint64_t>();  // checked by the schema, named --seed
    if (is_batch(files_)) {
      if (print_) throw bad_input("--print-scenario: takes one scenario, not a batch");
      run_batch({files_, sets_, seed_, output_, overwrite_, from_, until_, only_, jobs_, context.threads}, context.log);
      return;
    }
    const std::string file = files_.empty() ? std::string() : files_[0];
    // As a JSON string (quotes and backslashes escaped); an empty one is the schema's to refuse.
    // A command-line path is relative to the working folder (the scenario's own paths to its file's).
    const bool elsewhere = !files_.empty() && !std::filesystem::path(files_[0]).parent_path().empty();
    if (output_) sets_.push_back("output=" + nlohmann::json(elsewhere && !output_->empty() ? std::filesystem::absolute(*output_).string() : *output_).dump());
    const pipeline::Scenario scenario = pipeline::load_scenario(file, sets_, seed_);
    if (print_) {
      std::printf("%s\n", scenario.resolved.dump(2).c_str());
      return;
    }
    pipeline::RunOptions options;
    options.overwrite = overwrite_;
    options.from = from_;
    options.only = only_;
    options.until = until_;
    const auto manifest = pipeline::run_scenario(scenario, options, context.progress, context.log);
    if (context.log.level() != LogLevel::quiet) {
      std::printf("%s", pipeline::format_summary(manifest).c_str());
      std::printf("Outputs in %s/ (open project.qgs in QGIS; run.json records what was done)\n", scenario.path("output").c_str());
    }
  }

 private:
  std::vector<std::string> files_;
  std::string from_, until_;
  int jobs_ = 1;
  std::optional<std::string> output_;
  std::vector<std::string> sets_, only_;
  std::optional<std::uint64_t> seed_;
  SchemaOptions schema_;
  bool overwrite_ = false, print_ = false;
};

}  // namespace

std::unique_ptr<Command> make_run_command() { return std::make_unique<RunCommand>(); }

}  // namespace terrapolis::cli
