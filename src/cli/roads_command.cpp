// `terrapolis roads DEM NETWORK OUTDIR`: a road for every kept edge of a city network.
// SPDX-License-Identifier: MIT
#include <CLI/CLI.hpp>

#include <chrono>
#include <cstdio>
#include <filesystem>

#include "cli/command.hpp"
#include "cli/commands_list.hpp"
#include "cli/dem_input.hpp"
#include "cli/road_options.hpp"
#include "cli/schema_options.hpp"
#include "core/error.hpp"
#include "io/output_set.hpp"
#include "io/raster_io.hpp"
#include "io/text_io.hpp"
#include "io/vector_io.hpp"
#include "network/layers.hpp"
#include "roads/road_network.hpp"

namespace terrapolis::cli {
namespace {

/// "existing roads: 90.1 km given (12 lines, 0 outside the DEM); the roads run 60.2 km on them, 20.3 km new (network drawn once)".
std::string existing_line(const roads::ExistingRoads& e, const roads::NetworkResult& r) {
  double given = 0, on = 0, fresh = 0;
  for (double m : e.length_m) given += m / 1000;
  for (const roads::NetworkSection& s : r.layout.sections) (s.existing ? on : fresh) += s.length_m / 1000;
  char line[256];
  std::snprintf(line, sizeof line, "existing roads: %.1f km given (%zu lines, %zu outside the DEM); the roads run %.1f km on them, %.1f km new (network drawn once)",
                given, e.lines, e.outside, on, fresh);
  return line;
}

class RoadsCommand final : public Command {
 public:
  std::string name() const override { return "roads"; }
  std::string summary() const override { return "Route a road for every kept edge of a city network (network.geojson; cities.geojson beside it)"; }

  void setup(CLI::App& app) override {
    dem_.add_to(app);
    file_kind(app.add_option("NETWORK", network_, "network.geojson from the network stage (LineStrings: from, to, kept)")->required(), FileKind::vector_in);
    file_kind(app.add_option("OUTDIR", outdir_, "Folder for roads.geojson, road_sections.geojson, sections.geojson and junctions.geojson (its parent must exist)")->required(), FileKind::folder_out);
    file_kind(app.add_option("--cities", cities_, "Cities (Points: id, class); default: cities.geojson beside NETWORK when present"), FileKind::vector_in);
    app.add_flag("--corridor", corridor_,
                 "Also write corridors.geojson (per section: carriageway and earthworks zone) and add land take, cut, fill and "
                 "vegetation cleared to roads.geojson");
    options_.setup(app, name());
  }

  void run(Context& context) override {
    namespace fs = std::filesystem;
    if (!fs::exists(network_)) throw bad_input(network_ + ": no such file");
    std::string cities_path = cities_;
    if (cities_path.empty()) {
      const fs::path beside = fs::path(network_).parent_path() / "cities.geojson";
      if (fs::exists(beside)) cities_path = beside.string();
    }
    std::vector<std::string> inputs = options_.inputs();
    inputs.insert(inputs.end(), {dem_.path, network_, cities_path});
    OutputSet outputs("roads", inputs, options_.overwrite);
    const fs::path dir = outputs.folder(outdir_);
    const std::string earthworks_path = options_.earthworks.empty() ? "" : outputs.file(options_.earthworks);

    const roads::CostModel model = options_.cost_model();
    const plugin::PluginSet plugins = options_.plugins.load(context.log);
    const Dem dem = dem_.read();
    roads::TerrainField terrain = options_.terrain(dem, plugins, context.progress, context.log);
    const roads::CorridorOptions corridor = options_.corridor_options(dem);
    VectorLayer network = read_vector(network_, dem.georef().crs);
    network.name = network_;  // errors name the file
    std::optional<VectorLayer> cities;
    if (!cities_path.empty()) {
      cities = read_vector(cities_path, dem.georef().crs);
      cities->name = cities_path;
    }
    else context.log.warn("no cities.geojson beside the network: every road is departmental");

    std::optional<roads::ExistingRoads> existing;
    if (const std::string& lines = options_.settings().existing; !lines.empty()) existing = roads::read_existing_roads(lines, terrain);

    const roads::RoadGraph graph(terrain, model, options_.graph());
    const auto t0 = std::chrono::steady_clock::now();
    roads::NetworkResult result = roads::route_network(terrain, graph, network::road_links(network, cities ? &*cities : nullptr), options_.routing(),
                                                       context.progress, existing ? &*existing : nullptr);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    for (const std::string& f : result.failed) context.log.warn("no road under the cost model for edge " + f + " (left out)");
    for (const std::string& f : result.over_budget) context.log.warn("not routed: budget (--max-seconds) for edge " + f);
    VectorLayer roads_layer = roads::roads_layer(terrain, result.roads, &result.layout);
    roads::Corridors corridors;
    double corridor_seconds = 0;
    if (corridor_) {
      const auto t1 = std::chrono::steady_clock::now();
      corridors = roads::road_corridors(terrain, result.roads, corridor, result.existing);
      corridor_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count();
      roads::add_corridor_fields(roads_layer, corridors);
      write_vector((dir / "corridors.geojson").string(), roads::corridors_layer(terrain, corridors));
      write_text_file((dir / "corridors.qml").string(), roads::corridors_qml(), false);
    }
    write_vector((dir / "roads.geojson").string(), roads_layer);
    write_vector((dir / "road_sections.geojson").string(), roads::sections_layer(terrain, result.roads));
    write_vector((dir / "sections.geojson").string(), roads::network_sections_layer(terrain, result.layout));
    write_vector((dir / "junctions.geojson").string(), roads::junctions_layer(terrain, result.layout));
    if (existing) write_vector((dir / "existing_roads.geojson").string(), roads::existing_roads_layer(terrain, *existing));
    options_.write_earthworks(earthworks_path, dem, terrain, result.roads, corridor);
    outputs.commit();
    std::size_t ferries = 0;
    double km = 0;
    for (const auto& r : result.roads) {
      ferries += r.ferry ? 1 : 0;
      km += r.stats.length_m / 1000;
    }
    char line[256];
    std::snprintf(line, sizeof line, "%zu roads (%zu maritime links, %zu failed, %zu not routed: budget, %zu redundant), %zu sections, %zu junctions, %.1f km, %.2f s",
                  result.roads.size(), ferries, result.failed.size(), result.over_budget.size(), result.redundant.size(),
                  result.layout.sections.size(), result.layout.junctions.size(), km, seconds);
    context.log.info(line);
    if (existing) context.log.info(existing_line(*existing, result));
    if (corridor_) context.log.info("corridors: " + roads::corridor_summary(corridors, corridor_seconds));
  }

 private:
  DemInput dem_;
  std::string network_, outdir_, cities_;
  bool corridor_ = false;
  RoadOptions options_;
};

}  // namespace

std::unique_ptr<Command> make_roads_command() { return std::make_unique<RoadsCommand>(); }

}  // namespace terrapolis::cli
