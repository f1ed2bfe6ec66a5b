// `terrapolis lake DEM OUTDIR --at LON,LAT --level M | --depth M [--dam LINESTRING --crest M]`.
// SPDX-License-Identifier: MIT
#include <CLI/CLI.hpp>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "cli/command.hpp"
#include "cli/commands_list.hpp"
#include "cli/dem_input.hpp"
#include "cli/schema_options.hpp"
#include "core/error.hpp"
#include "lake/lake.hpp"
#include "pipeline/descriptions.hpp"
#include "pipeline/stage_options.hpp"
#include "io/output_set.hpp"
#include "io/raster_io.hpp"
#include "io/text_io.hpp"
#include "io/vector_io.hpp"
#include "terrapolis/version.hpp"

namespace terrapolis::cli {
namespace {

namespace fs = std::filesystem;

std::string fixed(double v, int digits) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", digits, v);
  return buf;
}

class LakeCommand final : public Command {
 public:
  std::string name() const override { return "lake"; }
  std::string summary() const override { return "Lake or reservoir flooded to a level from a point: depth, shoreline, area, volume"; }

  void setup(CLI::App& app) override {
    dem_.add_to(app);
    file_kind(app.add_option("OUTDIR", out_dir_, "Output folder: depth.tif, shoreline.geojson, lake.json (its parent must exist)")->required(), FileKind::folder_out);
    // --at, --level, --depth, --dam, --crest: the fields of a run's water.reservoirs item.
    options_.setup(app, "lake");
    app.get_option("--at")->required();
    file_kind(app.add_option("--run", run_dir_, "Run folder: report the flooded road length (roads.geojson) and the cities touched (cities.geojson)"), FileKind::folder_in);
    app.add_flag("--cog", cog_, "Write a Cloud Optimized GeoTIFF");
    add_overwrite_flag(app, overwrite_);
    app_ = &app;
  }

  void run(Context& context) override {
    try {
      flood_and_write(context);
    } catch (const Error& e) {
      throw Error(e.kind(), options_.with_flags(e.what()));
    }
  }

 private:
  void flood_and_write(Context& context) {
    // The flags as the scenario's one reservoir, read as a run reads it.
    const pipeline::Scenario scenario = options_.scenario();
    const lake::LakeSpec spec = pipeline::reservoir_spec(scenario.resolved["water"]["reservoirs"][0]);
    const std::string at_text = app_->get_option("--at")->results().front();
    const std::string roads_path = (fs::path(run_dir_) / "roads.geojson").string(), cities_path = (fs::path(run_dir_) / "cities.geojson").string();
    if (!run_dir_.empty() && !fs::is_directory(run_dir_)) throw bad_input(run_dir_ + ": --run: not a folder");
    OutputSet outputs("lake", {dem_.path, run_dir_}, overwrite_);  // refused before any work
    const fs::path dir = outputs.folder(out_dir_);
    const Dem dem = dem_.read();
    const CellMetrics metrics = cell_metrics(dem.georef(), dem.cols(), dem.rows());
    const lake::Lake lake = lake::flood(dem, metrics, spec, context.progress);

    nlohmann::ordered_json report = {
        {"terrapolis_version", version}, {"dem", fs::path(dem_.path).filename().string()}, {"at", {spec.lon, spec.lat}},
        {"seed_cell", {lake.seed_col, lake.seed_row}}, {"level_m", lake.level_m}, {"cells", lake.cells},
        {"area_km2", lake.area_km2}, {"volume_m3", lake.volume_m3}, {"max_depth_m", lake.max_depth_m}, {"spills", lake.spills}};
    if (!spec.dam_lonlat.empty()) report["dam"] = {{"crest_m", *spec.crest_m}, {"cells", lake.dam_cells}};
    std::string extra;
    if (!run_dir_.empty()) {
      const Crs& crs = dem.georef().crs;
      if (fs::exists(roads_path)) {
        const double m = lake::flooded_length_m(lake, read_vector(roads_path, crs));
        report["flooded_road_km"] = m / 1000;
        extra += ", " + fixed(m / 1000, 2) + " km of road flooded";
      }
      if (fs::exists(cities_path)) {
        const auto ids = lake::cities_touched(lake, metrics, read_vector(cities_path, crs));
        report["cities_touched"] = ids;
        extra += ", " + std::to_string(ids.size()) + " cities touched";
      }
      if (!report.contains("flooded_road_km") && !report.contains("cities_touched"))
        throw bad_input(run_dir_ + ": --run: holds neither roads.geojson nor cities.geojson");
    }
    const VectorLayer shoreline = lake::shoreline_layer(lake);
    {
      WriteOptions w;
      w.cog = cog_;
      pipeline::DescriptionTerms terms;
      terms.lake_level_m = lake.level_m;
      w.description = pipeline::describe_output("depth.tif", terms);
      w.metadata = {{"TERRAPOLIS_VERSION", version}, {"TERRAPOLIS_COMMAND", "lake"}, {"SOURCE_DEM", fs::path(dem_.path).filename().string()},
                    {"AT", at_text}, {"LEVEL_M", fixed(lake.level_m, 3)}, {"UNIT", "m"}};
      write_raster((dir / "depth.tif").string(), lake.depth, w);
    }
    write_vector((dir / "shoreline.geojson").string(), shoreline);
    write_text_file((dir / "lake.json").string(), report.dump(2) + "\n", false);
    outputs.commit();
    if (lake.spills) context.log.warn("lake: the water reaches the DEM's edge or nodata: it would spill beyond, area and volume are lower bounds");
    context.log.info("lake: level " + fixed(lake.level_m, 2) + " m, " + fixed(lake.area_km2, 4) + " km2, " + fixed(lake.volume_m3 / 1e6, 4) +
                     " million m3, max depth " + fixed(lake.max_depth_m, 2) + " m" + extra + "; wrote " + out_dir_);
  }


  DemInput dem_;
  SchemaOptions options_;
  CLI::App* app_ = nullptr;
  std::string out_dir_, run_dir_;
  bool cog_ = false, overwrite_ = false;
};

}  // namespace

std::unique_ptr<Command> make_lake_command() { return std::make_unique<LakeCommand>(); }

}  // namespace terrapolis::cli
