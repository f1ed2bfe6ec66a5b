// `terrapolis access DEM OUTDIR --to CITIES [--roads ROADS] [--people RASTER]`: travel time to the
// nearest settlement and who lives within 15, 30, 60 minutes (docs/access.md).
// SPDX-License-Identifier: MIT
#include <CLI/CLI.hpp>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "access/access.hpp"
#include "cli/command.hpp"
#include "cli/commands_list.hpp"
#include "cli/dem_input.hpp"
#include "cli/schema_options.hpp"
#include "core/error.hpp"
#include "core/geodesy.hpp"
#include "io/crs.hpp"
#include "io/output_set.hpp"
#include "io/raster_io.hpp"
#include "io/text_io.hpp"
#include "io/vector_io.hpp"
#include "pipeline/inland_water.hpp"
#include "pipeline/descriptions.hpp"
#include "pipeline/stage_options.hpp"
#include "terrapolis/version.hpp"

namespace terrapolis::cli {
namespace {

namespace fs = std::filesystem;

/// The settlements of `path` on the grid of `dem` with their ids (an integer `id` field, else the
/// feature's index) and populations (a `population` field, else 0); points off the grid are counted.
struct Places {
  std::vector<access::Settlement> all;
  std::size_t outside = 0;
};
Places read_places(const std::string& path, const Dem& dem) {
  const VectorLayer layer = read_vector(path, dem.georef().crs);
  if (layer.geometry != GeometryType::point) throw bad_input(path + ": --to: the settlements must be points");
  if (layer.features.empty()) throw bad_input(path + ": --to: holds no settlement");
  const int id_field = layer.field_index("id"), people_field = layer.field_index("population");
  const GridLocator locator(dem.georef());
  Places p;
  for (std::size_t k = 0; k < layer.features.size(); ++k) {
    const Feature& f = layer.features[k];
    const auto px = locator.crs_to_pixel(f.parts[0][0][0], f.parts[0][0][1]);
    const int col = int(std::floor(px[0])), row = int(std::floor(px[1]));
    if (!dem.inside(col, row)) {
      ++p.outside;
      continue;
    }
    std::int32_t id = std::int32_t(k);
    if (id_field >= 0)
      if (const auto* v = std::get_if<std::int64_t>(&f.values[std::size_t(id_field)])) id = std::int32_t(*v);
    double people = 0;
    if (people_field >= 0) {
      const FieldValue& v = f.values[std::size_t(people_field)];
      if (const auto* i = std::get_if<std::int64_t>(&v)) people = double(*i);
      if (const auto* d = std::get_if<double>(&v)) people = *d;
    }
    p.all.push_back({{col, row, id}, people});
  }
  if (p.all.empty()) throw bad_input(path + ": --to: no settlement lies on the DEM");
  return p;
}

class AccessCommand final : public Command {
 public:
  std::string name() const override { return "access"; }
  std::string summary() const override {
    return "Travel time from every cell to the nearest settlement, on foot and by road, and who lives within 15, 30, 60 minutes";
  }

  void setup(CLI::App& app) override {
    dem_.add_to(app);
    file_kind(app.add_option("OUTDIR", out_dir_, "Output folder: access_minutes.tif, access_nearest.tif, access.json (its parent must exist)")
                  ->required(),
              FileKind::folder_out);
    file_kind(app.add_option("--to", to_, "Settlements (points; fields id and population used when present), e.g. a run's cities.geojson")
                  ->required(),
              FileKind::vector_in);
    file_kind(app.add_option("--roads", roads_, "Roads (lines; a class field sets the speed, structure 'tunnel' keeps them underground), "
                                                "e.g. a run's road_sections.geojson or roads.geojson"),
              FileKind::vector_in);
    file_kind(app.add_option("--people", people_, "People per cell on the DEM's grid (e.g. WorldPop put on it with gdalwarp -r sum); "
                                                  "without it the figures are km2 of land"),
              FileKind::raster_in);
    schema_.setup(app, name());
    add_overwrite_flag(app, overwrite_);
  }

  void run(Context& context) override {
    const pipeline::Scenario scenario = schema_.scenario();
    const pipeline::AccessSettings settings = schema_.settings([&] { return pipeline::access_settings(scenario); });
    OutputSet outputs("access", {dem_.path, to_, roads_, people_, scenario.path("/water/water_mask")}, overwrite_);  // refused before any work
    const fs::path dir = outputs.folder(out_dir_);
    const Dem dem = dem_.read();
    const Places places = read_places(to_, dem);
    const double sea_level = scenario.resolved["water"]["sea_level_m"].get<double>();
    // Land as a run sees it: above the sea and off the inland water (flattened lakes, --water-mask).
    const pipeline::InlandWater water = pipeline::inland_water(dem, pipeline::inland_water_settings(scenario), context.progress, context.log);
    Raster<std::uint8_t> land = dem.like<std::uint8_t>(0);
    for (std::size_t i = 0; i < dem.size(); ++i) land[i] = !std::isnan(dem[i]) && dem[i] > sea_level && !water.mask[i];
    const access::RoadCells roads = roads_.empty() ? access::RoadCells{dem.like<float>(0.0f), dem.like<std::uint8_t>(0)}
                                                   : access::road_cells(read_vector(roads_, dem.georef().crs), dem, settings.options);
    // Who is counted: the people raster, or each land cell's area (km2).
    Raster<float> weight = dem.like<float>(0.0f);
    if (!people_.empty()) {
      const RasterHeader h = read_header(people_);
      if (h.cols != dem.cols() || h.rows != dem.rows())
        throw bad_input(people_ + ": --people: is " + std::to_string(h.cols) + "x" + std::to_string(h.rows) + " cells, the DEM " +
                        std::to_string(dem.cols()) + "x" + std::to_string(dem.rows()) + " (put it on the DEM's grid: gdalwarp -r sum)");
      weight = read_resampled(people_, dem.georef(), dem.cols(), dem.rows(), Resampling::nearest);  // the same grid: the same cells
    } else {
      const CellMetrics metrics = cell_metrics(dem.georef(), dem.cols(), dem.rows());
      for (int r = 0; r < dem.rows(); ++r)
        for (int c = 0; c < dem.cols(); ++c)
          if (land(c, r)) weight(c, r) = float(metrics.area_m2[std::size_t(r)] * 1e-6);
    }
    const std::string unit = people_.empty() ? "land_km2" : "people";

    nlohmann::ordered_json levels = nlohmann::ordered_json::object();
    std::string lines;
    access::for_each_level(dem, land, roads, places.all, settings.levels_population, settings.thresholds_minutes, weight, settings.options,
                           context.progress, [&](const access::LevelFigures& f) {
      const bool all = f.level == 0;
      WriteOptions w;
      const std::string minutes_file = all ? "access_minutes.tif" : "access_minutes_" + f.key + ".tif";
      w.description = pipeline::describe_output(minutes_file);
      w.metadata = {{"TERRAPOLIS_VERSION", version}, {"TERRAPOLIS_COMMAND", "access"}, {"UNIT", "min"},
                    {"TERRAPOLIS_ACCESS", scenario.resolved["access"].dump()}};
      write_raster((dir / minutes_file).string(), f.times.minutes, w);
      if (all) {
        w.description = pipeline::describe_output("access_nearest.tif");
        w.metadata[2] = {"UNIT", "id"};
        write_raster((dir / "access_nearest.tif").string(), f.times.nearest, w);
        write_vector((dir / "access_catchments.geojson").string(), access::catchments_layer(f.times, weight, unit, places.all));
      }
      const access::Coverage& c = f.coverage;
      nlohmann::ordered_json within = nlohmann::ordered_json::object();
      char text[160];
      std::snprintf(text, sizeof text, "access: %s (%zu):", all ? "any settlement" : (f.key + "+ people").c_str(), f.destinations);
      lines += text;
      for (std::size_t k = 0; k < settings.thresholds_minutes.size(); ++k) {
        std::snprintf(text, sizeof text, "%g_min", settings.thresholds_minutes[k]);
        within[text] = c.within_people[k];
        std::snprintf(text, sizeof text, " %.1f%% within %g min,", c.total_people > 0 ? 100 * c.within_people[k] / c.total_people : 0.0,
                      settings.thresholds_minutes[k]);
        lines += text;
      }
      std::snprintf(text, sizeof text, " mean %.1f min, p90 %.1f min\n", c.mean_minutes, c.p90_minutes);
      lines += text;
      levels[f.key] = {{"destinations", f.destinations}, {"within", within}, {"unreachable", c.unreachable_people},
                       {"mean_minutes", c.mean_minutes}, {"p90_minutes", c.p90_minutes}, {"unreachable_land_cells", f.times.unreachable_land}};
    });
    double total = 0;
    for (std::size_t i = 0; i < weight.size(); ++i)
      if (weight[i] > 0) total += weight[i];
    const nlohmann::ordered_json report = {{"terrapolis_version", version}, {"dem", fs::path(dem_.path).filename().string()},
                                           {"settlements", places.all.size()}, {"outside_the_dem", places.outside},
                                           {"unit", unit}, {"total", total}, {"options", scenario.resolved["access"]}, {"levels", levels}};
    write_text_file((dir / "access.json").string(), report.dump(2) + "\n", false);
    outputs.commit();
    if (places.outside > 0) context.log.warn(std::to_string(places.outside) + " settlements of " + to_ + " lie outside the DEM: left out");
    context.log.info(lines + "access: wrote " + out_dir_);
  }

 private:
  DemInput dem_;
  SchemaOptions schema_;
  std::string out_dir_, to_, roads_, people_;
  bool overwrite_ = false;
};

}  // namespace

std::unique_ptr<Command> make_access_command() { return std::make_unique<AccessCommand>(); }

}  // namespace terrapolis::cli
