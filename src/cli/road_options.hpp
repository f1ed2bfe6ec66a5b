// Options shared by the `path` and `roads` commands (one declaration for both: the schema).
// SPDX-License-Identifier: MIT
#pragma once
#include <CLI/CLI.hpp>

#include <optional>
#include <string>

#include "cli/command.hpp"
#include "cli/plugin_options.hpp"
#include "cli/schema_options.hpp"
#include "io/raster_io.hpp"
#include "pipeline/inland_water.hpp"
#include "pipeline/descriptions.hpp"
#include "pipeline/stage_options.hpp"
#include "roads/corridor.hpp"
#include "roads/road_network.hpp"

namespace terrapolis::cli {

/// The schema's roads, seed and water options (x-cli "path" and "roads"), plus --earthworks, the
/// plugins and --overwrite; the settings come from pipeline::roads_settings, as in a run.
struct RoadOptions {
  std::string earthworks;
  bool overwrite = false;
  PluginOptions plugins;
  SchemaOptions schema;

  void setup(CLI::App& app, const std::string& command) {
    schema.setup(app, command);
    file_kind(app.add_option("--earthworks", earthworks,
                             "Also write the DEM after cut-and-fill along the surface roads (GeoTIFF; carriageway --half-width, sides at the --material's angle)"),
              FileKind::raster_out);
    plugins.setup(app, "adds its road cost term (characteristic priced by its transfer functions; galin router)");
    add_overwrite_flag(app, overwrite);
  }

  /// The command's scenario, read once (the first call validates the options and loads --costs).
  const pipeline::Scenario& scenario() const {
    if (!scenario_) scenario_ = schema.scenario();
    return *scenario_;
  }
  const pipeline::RoadsSettings& settings() const {
    if (!settings_) settings_ = schema.settings([&] { return pipeline::roads_settings(scenario()); });
    return *settings_;
  }

  /// The files these options read (the outputs may not replace them).
  std::vector<std::string> inputs() const {
    return {scenario().path("/roads/costs"), settings().vegetation, scenario().path("/roads/corridor/side_angles"), settings().existing,
            scenario().path("/water/water_mask")};
  }

  /// The schema's roads.corridor options, the side-angle map read onto the DEM's grid.
  roads::CorridorOptions corridor_options(const Dem& dem) const {
    pipeline::CorridorSettings c = pipeline::corridor_settings(scenario());
    if (!c.side_angles.empty()) c.options.side_angles_deg = read_resampled(c.side_angles, dem.georef(), dem.cols(), dem.rows(), Resampling::nearest);
    return c.options;
  }
  /// Writes the DEM after the earthworks of the roads to `path` (where the command's OutputSet
  /// stages --earthworks), with the corridor options; nothing when --earthworks is not given.
  void write_earthworks(const std::string& path, const Dem& dem, const roads::TerrainField& terrain, const std::vector<roads::Road>& roads,
                        const roads::CorridorOptions& corridor) const {
    if (earthworks.empty()) return;
    Raster<float> slopes;
    WriteOptions w;
    w.description = pipeline::describe_output("earthworks.tif");
    write_raster(path, roads::earthworks(dem, terrain, geometries(roads), roads::earthwork_options(corridor, slopes)), w);
  }
  static std::vector<const roads::RoadGeometry*> geometries(const std::vector<roads::Road>& roads) {
    std::vector<const roads::RoadGeometry*> out;
    for (const roads::Road& r : roads) out.push_back(&r.geometry);
    return out;
  }

  const roads::CostModel& cost_model() const { return settings().model; }
  /// The roads' terrain as a run builds it: the inland water (flattened lakes, --water-mask),
  /// --vegetation and the plugins' road cost terms.
  roads::TerrainField terrain(const Dem& dem, const plugin::PluginSet& set, Progress& progress, const Log& log) const {
    const pipeline::InlandWater water = pipeline::inland_water(dem, pipeline::inland_water_settings(scenario()), progress, log);
    roads::TerrainField t = pipeline::road_terrain(dem, scenario(), cost_model(), water.mask);
    pipeline::add_road_layers(t, settings(), set, dem, progress, log);
    return t;
  }
  roads::GraphOptions graph() const { return settings().routing.graph; }
  roads::RoutingOptions routing() const { return settings().routing; }

 private:
  mutable std::optional<pipeline::Scenario> scenario_;
  mutable std::optional<pipeline::RoadsSettings> settings_;
};

}  // namespace terrapolis::cli
