// `terrapolis erode DEM OUT.tif`: hydraulic (virtual pipes), thermal (angle of repose) and layered
// (bedrock and loose material, Peytavie 2010 §2.3) erosion of a DEM.
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
  switch (p) {
    case erode::Process::hydraulic: return "hydraulic";
    case erode::Process::thermal: return "thermal";
    case erode::Process::layered: return "layered";
    case erode::Process::both: break;
  }
  return "hydraulic and thermal";
}

/// A raster the erode section names, on the DEM's grid (nearest resampling); nullopt when unnamed.
std::optional<Raster<float>> read_on_grid(const std::string& path, const Dem& dem) {
  if (path.empty()) return std::nullopt;
  return read_resampled(path, dem.georef(), dem.cols(), dem.rows(), Resampling::nearest);
}

class ErodeCommand final : public Command {
 public:
  std::string name() const override { return "erode"; }
  std::string summary() const override {
    return "Erode a DEM: hydraulic (virtual pipes), thermal (angle of repose) and layered (bedrock and loose material) erosion, for what-if studies";
  }

  void setup(CLI::App& app) override {
    dem_.add_to(app);
    file_kind(app.add_option("OUT", output_, "Output GeoTIFF (float32 metres, the DEM's grid, CRS and nodata)")->required(), FileKind::raster_out);
    schema_.setup(app, name());
    file_kind(app.add_option("--report", report_, "Also write the figures as JSON: iterations, eroded, deposited and carried-out m3, largest lowering and raising, time per iteration"),
              FileKind::file_out);
    file_kind(app.add_option("--loose-out", loose_out_, "Also write the loose material's thickness at the end (float32 metres, the DEM's grid; layered, 0 for the other processes)"),
              FileKind::raster_out);
    app.add_flag("--cog", cog_, "Write a Cloud Optimized GeoTIFF");
    add_overwrite_flag(app, overwrite_);
  }

  void run(Context& context) override {
    const pipeline::Scenario scenario = schema_.scenario();
    erode::ErodeOptions options = schema_.settings([&] { return pipeline::erode_options(scenario); });
    const nlohmann::json& section = scenario.resolved["erode"];
    const std::string mask_path = section["mask"].get<std::string>();
    std::vector<std::string> inputs{dem_.path};
    for (const char* key : {"mask", "angles", "loose", "rockfall"})
      if (const std::string p = section[key].get<std::string>(); !p.empty()) inputs.push_back(p);
    OutputSet outputs("erode", inputs, overwrite_);  // refused before any work
    const std::string out = outputs.file(output_);
    const std::string report_file = report_.empty() ? "" : outputs.file(report_);
    const std::string loose_file = loose_out_.empty() ? "" : outputs.file(loose_out_);

    const Dem dem = dem_.read();
    const CellMetrics metrics = cell_metrics(dem.georef(), dem.cols(), dem.rows());
    std::optional<Raster<std::uint8_t>> mask;
    if (!mask_path.empty()) mask = read_mask(mask_path, dem.georef(), dem.cols(), dem.rows());
    const std::optional<Raster<float>> angles = read_on_grid(section["angles"].get<std::string>(), dem);
    const std::optional<Raster<float>> loose = read_on_grid(section["loose"].get<std::string>(), dem);
    const std::optional<Raster<float>> rockfall = read_on_grid(section["rockfall"].get<std::string>(), dem);
    if (angles) options.thermal.angles_deg = &*angles;
    if (loose) options.layered.loose_m = &*loose;
    if (rockfall) options.layered.rockfall_m = &*rockfall;
    erode::ErodeReport report;
    Raster<float> loose_end;
    const Dem eroded = schema_.settings(
        [&] { return erode::erode(dem, metrics, options, mask ? &*mask : nullptr, context.progress, &report, &loose_end); });

    const std::string source = fs::path(dem_.path).filename().string();
    WriteOptions w;
    w.cog = cog_;
    w.description = std::string("Elevation (m) after ") + process_name(options.process) + " erosion";
    w.metadata = {{"TERRAPOLIS_VERSION", version}, {"TERRAPOLIS_COMMAND", "erode"}, {"SOURCE_DEM", source},
                  {"TERRAPOLIS_ERODE", section.dump()}, {"TERRAPOLIS_ANGLE_DEG", std::to_string(options.thermal.angle_deg)}, {"UNIT", "m"}};
    write_raster(out, eroded, w);
    if (!loose_file.empty()) {
      w.description = "Loose material's thickness (m) after " + std::string(process_name(options.process)) + " erosion";
      write_raster(loose_file, loose_end, w);
    }
    if (!report_file.empty()) {
      const nlohmann::ordered_json j = {
          {"terrapolis_version", version}, {"dem", source}, {"options", section}, {"angle_deg", options.thermal.angle_deg},
          {"iterations", report.iterations}, {"eroded_m3", report.eroded_m3}, {"deposited_m3", report.deposited_m3},
          {"carried_out_m3", report.carried_out_m3}, {"water_out_m3", report.water_out_m3}, {"loosened_m3", report.loosened_m3},
          {"max_lowering_m", report.max_lowering_m}, {"max_raising_m", report.max_raising_m},
          {"seconds", report.seconds}, {"seconds_per_iteration", report.seconds_per_iteration}};
      write_text_file(report_file, j.dump(2) + "\n", false);
    }
    outputs.commit();
    char line[512];
    std::snprintf(line, sizeof line,
                  "erode: %d iterations (%s), eroded %.6g m3, deposited %.6g m3, carried out %.6g m3, rock loosened %.6g m3, largest lowering %.3f m, raising %.3f m, %.2f ms per iteration; wrote ",
                  report.iterations, process_name(options.process), report.eroded_m3, report.deposited_m3, report.carried_out_m3, report.loosened_m3,
                  report.max_lowering_m, report.max_raising_m, 1000 * report.seconds_per_iteration);
    context.log.info(line + output_);
  }

 private:
  DemInput dem_;
  SchemaOptions schema_;
  std::string output_, report_, loose_out_;
  bool cog_ = false, overwrite_ = false;
};

}  // namespace

std::unique_ptr<Command> make_erode_command() { return std::make_unique<ErodeCommand>(); }

}  // namespace terrapolis::cli
