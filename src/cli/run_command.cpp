// `terrapolis run [SCENARIO.json]`: the whole pipeline from one scenario file into one run folder.
// SPDX-License-Identifier: MIT
#include <CLI/CLI.hpp>

#include <cstdio>

#include "cli/command.hpp"
#include "cli/commands_list.hpp"
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
    file_kind(app.add_option("SCENARIO", file_, "Scenario file (JSON, see schemas/scenario.schema.json); default: the embedded scenario"), FileKind::file_in);
    app.add_option("--set", sets_, "Override a field: stage.field=value (repeatable), e.g. --set density.weights=[1,1,0,0]");
    // The schema's range (a JSON-safe integer): a negative or larger seed is refused, never replaced.
    app.add_option("--seed", seed_, "Seed of the run, 0 .. 2^53-1 (overrides the scenario's)")
        ->check(CLI::Range(std::uint64_t(0), std::uint64_t(9007199254740991)));
    file_kind(app.add_option("-o,--output", output_, "Run folder (overrides the scenario's)"), FileKind::folder_out);
    app.add_flag("--overwrite", overwrite_, "Replace the run folder if it exists");
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
    // As a JSON string (quotes and backslashes escaped); an empty one is the schema's to refuse.
    if (output_) sets_.push_back("output=" + nlohmann::json(*output_).dump());
    const pipeline::Scenario scenario = pipeline::load_scenario(file_, sets_, seed_);
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
  std::string file_, from_, until_;
  std::optional<std::string> output_;
  std::vector<std::string> sets_, only_;
  std::optional<std::uint64_t> seed_;
  bool overwrite_ = false, print_ = false;
};

}  // namespace

std::unique_ptr<Command> make_run_command() { return std::make_unique<RunCommand>(); }

}  // namespace terrapolis::cli
