// `terrapolis erode DEM OUT.tif`: hydraulic (virtual pipes) and thermal (angle of repose) erosion of a DEM.
// SPDX-License-Identifier: MIT
#include <CLI/CLI.hpp>

#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>

#include "cli/command.hpp"
#include "cli/commands_list.hpp"
#include "cli/dem_input.hpp"
#include "cli/schema_options.hpp"
#include "core/error.hpp"
#include "erode/erosion.hpp"
#include "io/mask_io.hpp"
#include "io/output_set.hpp"
#include "io/raster_io.hpp"
#include "io/text_io.hpp"
#include "pipeline/stage_options.hpp"
#include "terrapolis/version.hpp"

namespace terrapolis::cli {
namespace {

namespace fs = std::filesystem;

const char* process_name(erode::Process p) {
  return p == erode::Process::hydraulic ? "hydraulic" : p == erode::Process::thermal ? "thermal" : "hydraulic and thermal";
}

class ErodeCommand final : public Command {
 public:
  std::string name() const override { return "erode"; }
  std::string summary() const override { return "Erode a DEM: hydraulic (virtual pipes) and thermal (angle of repose) erosion, for what-if studies"; }

  void setup(CLI::App& app) override {
    dem_.add_to(app);
    file_kind(app.add_option("OUT", output_, "Output GeoTIFF (float32 metres, the DEM's grid, CRS and nodata)")->required(), FileKind::raster_out);
    schema_.setup(app, name());
    file_kind(app.add_option("--report", report_, "Also write the figures as JSON: iterations, eroded, deposited and carried-out m3, largest lowering and raising, time per iteration"),
              FileKind::file_out);
    app.add_flag("--cog", cog_, "Write a Cloud Optimized GeoTIFF");
    add_overwrite_flag(app, overwrite_);
  }

  void run(Context& context) override {
    const pipeline::Scenario scenario = schema_.scenario();
    erode::ErodeOptions options = schema_.settings([&] { return pipeline::erode_options(scenario); });
    const nlohmann::json& section = scenario.resolved["erode"];
    const std::string mask_path = section["mask"].get<std::string>(), angles_path = section["angles"].get<std::string>();
    std::vector<std::string> inputs{dem_.path};
    for (const std::string& p : {mask_path, angles_path})
      if (!p.empty()) inputs.push_back(p);
    OutputSet outputs("erode", inputs, overwrite_);  // refused before any work
    const std::string out = outputs.file(output_);
    const std::string report_file = report_.empty() ? "" : outputs.file(report_);

    const Dem dem = dem_.read();
    const CellMetrics metrics = cell_metrics(dem.georef(), dem.cols(), dem.rows());
    std::optional<Raster<std::uint8_t>> mask;
    if (!mask_path.empty()) mask = read_mask(mask_path, dem.georef(), dem.cols(), dem.rows());
    std::optional<Raster<float>> angles;
    if (!angles_path.empty()) {
      angles = read_resampled(angles_path, dem.georef(), dem.cols(), dem.rows(), Resampling::nearest);
      options.thermal.angles_deg = &*angles;
    }
    erode::ErodeReport report;
    const Dem eroded = schema_.settings([&] { return erode::erode(dem, metrics, options, mask ? &*mask : nullptr, context.progress, &report); });

    const std::string source = fs::path(dem_.path).filename().string();
    WriteOptions w;
    w.cog = cog_;
    w.description = std::string("Elevation (m) after ") + process_name(options.process) + " erosion";
    w.metadata = {{"TERRAPOLIS_VERSION", version}, {"TERRAPOLIS_COMMAND", "erode"}, {"SOURCE_DEM", source},
                  {"TERRAPOLIS_ERODE", section.dump()}, {"TERRAPOLIS_ANGLE_DEG", std::to_string(options.thermal.angle_deg)}, {"UNIT", "m"}};
    write_raster(out, eroded, w);
    if (!report_file.empty()) {
      const nlohmann::ordered_json j = {
          {"terrapolis_version", version}, {"dem", source}, {"options", section}, {"angle_deg", options.thermal.angle_deg},
          {"iterations", report.iterations}, {"eroded_m3", report.eroded_m3}, {"deposited_m3", report.deposited_m3},
          {"carried_out_m3", report.carried_out_m3}, {"water_out_m3", report.water_out_m3},
          {"max_lowering_m", report.max_lowering_m}, {"max_raising_m", report.max_raising_m},
          {"seconds", report.seconds}, {"seconds_per_iteration", report.seconds_per_iteration}};
      write_text_file(report_file, j.dump(2) + "\n", false);
    }
    outputs.commit();
    char line[400];
    std::snprintf(line, sizeof line,
                  "erode: %d iterations (%s), eroded %.6g m3, deposited %.6g m3, carried out %.6g m3, largest lowering %.3f m, raising %.3f m, %.2f ms per iteration; wrote ",
                  report.iterations, process_name(options.process), report.eroded_m3, report.deposited_m3, report.carried_out_m3,
                  report.max_lowering_m, report.max_raising_m, 1000 * report.seconds_per_iteration);
    context.log.info(line + output_);
  }

 private:
  DemInput dem_;
  SchemaOptions schema_;
  std::string output_, report_;
  bool cog_ = false, overwrite_ = false;
};

}  // namespace

std::unique_ptr<Command> make_erode_command() { return std::make_unique<ErodeCommand>(); }

}  // namespace terrapolis::cli
