// `terrapolis path DEM --from LON,LAT --to LON,LAT OUT.geojson`: one road between two points.
// SPDX-License-Identifier: MIT
#include <CLI/CLI.hpp>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "cli/command.hpp"
#include "cli/commands_list.hpp"
#include "cli/dem_input.hpp"
#include "cli/road_options.hpp"
#include "cli/schema_options.hpp"
#include "core/error.hpp"
#include "io/crs.hpp"
#include "io/output_set.hpp"
#include "io/raster_io.hpp"
#include "io/text_io.hpp"
#include "io/vector_io.hpp"
#include "roads/road_network.hpp"
#include "roads/windowed_route.hpp"
#include "pipeline/by_tiles.hpp"

namespace terrapolis::cli {
namespace {

class PathCommand final : public Command {
 public:
  std::string name() const override { return "path"; }
  std::string summary() const override { return "Lay one road between two points: anisotropic shortest path with bridges and tunnels (Galin et al. 2010)"; }

  void setup(CLI::App& app) override {
    dem_.add_to(app);
    app.add_option("--from", from_, "Start point LON,LAT (or X,Y with --crs dem)")->required();
    app.add_option("--to", to_, "End point LON,LAT (or X,Y with --crs dem)")->required();
    file_kind(app.add_option("OUT", out_, "Output road (.geojson or .gpkg)")->required(), FileKind::vector_out);
    app.add_option("--crs", crs_, "CRS of --from/--to: lonlat (WGS 84) or dem (the DEM's CRS)")->check(CLI::IsMember({"lonlat", "dem"}));
    app.add_option("--search", search_, "Search: astar (heuristic: relaxed 2-D distance), astar-distance (heuristic: straight-line bound), bidir (bidirectional A*, straight-line bound), dijkstra")
        ->check(CLI::IsMember({"astar", "astar-distance", "bidir", "dijkstra"}));
    file_kind(app.add_option("--sections", sections_, "Also write the road/bridge/tunnel sections to this file"), FileKind::vector_out);
    file_kind(app.add_option("--corridor", corridor_, "Also write the carriageway and earthworks zone of each section to this file "
                                            "(polygons with cut, fill, clearing); the road gains land take, cut, fill and clearing"),
              FileKind::vector_out);
    file_kind(app.add_option("--evaluate", evaluate_, "Instead of routing, print the cost under the cost model of the first line of this file "
                                            "(e.g. another tool's path), walked cell by cell; OUT is not written"), FileKind::vector_in);
    options_.setup(app, name());
  }

  void run(Context& context) override {
    roads::RoutingOptions routing = options_.routing();
    routing.search = search_ == "bidir"            ? roads::SearchMethod::bidirectional
                     : search_ == "dijkstra"       ? roads::SearchMethod::dijkstra
                     : search_ == "astar-distance" ? roads::SearchMethod::astar_distance
                                                   : roads::SearchMethod::astar;
    std::vector<std::string> inputs = options_.inputs();
    inputs.insert(inputs.end(), {dem_.path, evaluate_});
    OutputSet outputs("path", inputs, options_.overwrite);
    const std::string out = evaluate_.empty() ? outputs.file(out_) : "";
    const std::string sections = evaluate_.empty() && !sections_.empty() ? outputs.file(sections_) : "";
    const std::string earthworks = evaluate_.empty() && !options_.earthworks.empty() ? outputs.file(options_.earthworks) : "";
    const std::string corridor = evaluate_.empty() && !corridor_.empty() ? outputs.file(corridor_) : "";
    // QGIS loads a .qml beside a layer of the same name.
    const std::string corridor_style =
        corridor.empty() ? "" : outputs.file(std::filesystem::path(corridor_).replace_extension(".qml").string());
    const roads::CostModel model = options_.cost_model();
    const plugin::PluginSet plugins = options_.plugins.load(context.log);
    const pipeline::TileSettings tiles = options_.schema.settings([&] { return pipeline::tile_settings(options_.scenario()); });
    std::optional<Dem> dem;  // the whole DEM; none by windows
    std::unique_ptr<roads::TerrainField> terrain;
    std::optional<roads::Road> road;
    roads::CorridorOptions corridor_options;
    auto t0 = std::chrono::steady_clock::now();  // the search (by windows: their reads too)
    if (tiles.given()) {
      check_windows_allowed(plugins);
      const pipeline::CorridorSettings settings = pipeline::corridor_settings(options_.scenario());
      corridor_options = settings.options;
      if (!settings.side_angles.empty() && !corridor.empty())  // the windows' margin counts the map's shallowest angle
        corridor_options.least_side_angle_deg = pipeline::least_side_angle(settings.side_angles, DemWindowReader(dem_.path, dem_.options()).header());
      // The inland water's tiles, gone before the outputs are committed.
      const ScratchFolder scratch((std::filesystem::path(out).parent_path() / ".inland_water").string());
      t0 = std::chrono::steady_clock::now();
      roads::WindowedRoad w = route_by_windows(routing, model, corridor_options, tiles, scratch.path(), context);
      if (w.limited && !w.road)
        throw processing_error("path: no road found within the windows --memory-limit allows (raise it, or route on the whole DEM)");
      terrain = std::move(w.terrain);
      road = std::move(w.road);
      if (!settings.side_angles.empty() && terrain)  // the map on the last window, which holds the corridor
        corridor_options.side_angles_deg = read_resampled(settings.side_angles, terrain->georef().window(terrain->col0(), terrain->row0()),
                                                          terrain->cols(), terrain->rows(), Resampling::nearest);
    } else {
      dem.emplace(dem_.read());
      terrain = std::make_unique<roads::TerrainField>(options_.terrain(*dem, plugins, context.progress, context.log));
      corridor_options = options_.corridor_options(*dem);
      const auto a = locate("--from", from_, terrain->georef(), dem->cols(), dem->rows());
      const auto b = locate("--to", to_, terrain->georef(), dem->cols(), dem->rows());
      if (a == b) throw bad_input("--from/--to: both points fall in the same cell");
      for (const auto& [opt, c] : {std::pair{"--from", a}, std::pair{"--to", b}}) {
        if (dem->is_nodata(dem->index(c.col, c.row))) throw bad_input(std::string(opt) + ": the point is on a nodata cell of " + dem_.path);
        if (!roads::snap_to_land(*terrain, c, routing.snap_cells))
          throw bad_input(std::string(opt) + ": the point is in the sea (no land within " + std::to_string(routing.snap_cells) + " cells)");
      }
      const roads::RoadGraph graph(*terrain, model, options_.graph());
      if (!evaluate_.empty()) {
        std::printf("cost %.3f\n", evaluate(graph, *terrain, *dem));
        return;
      }
      t0 = std::chrono::steady_clock::now();
      road = roads::route_road(*terrain, graph, a, b, routing, &context.progress);
    }
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (!road) throw processing_error("path: no road joins the two points under the cost model (slope or water thresholds)");
    if (road->over_budget) {
      context.log.warn("not routed: budget (--max-seconds); nothing written");
      return;
    }
    std::vector<roads::Road> roads{*road};
    roads[0].from = 0;
    roads[0].to = 1;
    roads[0].road_class = road->ferry ? roads::RoadClass::maritime : roads::RoadClass::departmental;
    VectorLayer layer = roads::roads_layer(*terrain, roads);
    const VectorLayer sections_layer = roads::sections_layer(*terrain, roads);
    roads::Corridors corridors;
    double corridor_seconds = 0;
    if (!corridor.empty()) {
      const auto t1 = std::chrono::steady_clock::now();
      corridors = roads::road_corridors(*terrain, roads, corridor_options);
      corridor_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count();
      roads::add_corridor_fields(layer, corridors);
    }
    write_vector(out, layer);
    if (!sections.empty()) write_vector(sections, sections_layer);
    if (!corridor.empty()) {
      write_vector(corridor, roads::corridors_layer(*terrain, corridors));
      write_text_file(corridor_style, roads::corridors_qml(), false);
    }
    if (dem) options_.write_earthworks(earthworks, *dem, *terrain, roads, corridor_options);
    outputs.commit();
    const auto& s = road->stats;
    char cost[64] = "none (it breaks a threshold of the cost model)";  // Bézier roads may
    if (road->cost) std::snprintf(cost, sizeof cost, "%.1f", *road->cost);
    char line[512];
    std::snprintf(line, sizeof line,
                  "%s: %.0f m, cost %s, max grade %.1f %%, mean grade %.1f %%, bridges %.0f m, tunnels %.0f m; %zu nodes expanded, %zu rings of long arcs priced, %zu stored, %zu relaxed cells settled, %.2f s",
                  road->router.c_str(), s.length_m, cost, s.max_grade_pct, s.mean_grade_pct, s.bridge_m, s.tunnel_m,
                  road->expanded, road->rings_priced, road->nodes, road->relaxed_settled, seconds);
    context.log.info(line);
    if (!corridor.empty()) context.log.info("corridor: " + roads::corridor_summary(corridors, corridor_seconds));
    const auto& g = road->geometry;
    if (g.clothoid_corners + g.g1_corners + g.sharp_corners > 0)
      context.log.detail("corners: " + std::to_string(g.clothoid_corners) + " clothoid pairs, " + std::to_string(g.g1_corners) +
                         " quadratic (G1) fallbacks, " + std::to_string(g.sharp_corners) + " left sharp");
  }

 private:
  roads::Cell locate(const std::string& option, const std::string& text, const Georef& georef, int cols, int rows) const {
    const auto v = parse_pair(option, text);
    std::array<double, 2> xy = v;
    if (crs_ == "lonlat") {
      if (std::fabs(v[1]) > 90) throw bad_input(option + ": latitude " + std::to_string(v[1]) + " is outside -90..90 (give LON,LAT)");
      const GridLocator locator(georef);
      xy = locator.lonlat_to_crs(v[0], v[1]);
    }
    const auto cell = roads::cell_at(georef, cols, rows, xy[0], xy[1]);
    if (!cell) throw bad_input(option + ": the point " + text + " lies outside " + dem_.path);
    return *cell;
  }

  /// What reads the whole DEM, refused with --memory-limit (naming the option).
  void check_windows_allowed(const plugin::PluginSet& plugins) const {
    const auto refuse = [](const std::string& what) { throw bad_input(what + ": reads the whole DEM; not with --memory-limit"); };
    if (!evaluate_.empty()) refuse("--evaluate");
    if (options_.routing().router != roads::Router::galin) refuse("--router bezier");
    if (!options_.earthworks.empty()) refuse("--earthworks");
    if (!plugins.empty()) refuse("--plugin");
    if (!pipeline::inland_water_settings(options_.scenario()).reservoirs.empty()) refuse("water.reservoirs");
  }

  /// The road by windows of the DEM (roads::route_by_windows): the inland water by tiles into
  /// `scratch` first (pipeline::inland_water_by_tiles), the bathymetry rule over bands of rows, then
  /// windows that hold the road's costs and its corridor, within the memory limit.
  roads::WindowedRoad route_by_windows(const roads::RoutingOptions& routing, const roads::CostModel& model,
                                       const roads::CorridorOptions& corridor, const pipeline::TileSettings& tiles,
                                       const std::string& scratch, Context& context) const {
    const DemWindowReader reader(dem_.path, dem_.options());
    const RasterHeader& h = reader.header();
    const pipeline::Scenario& scenario = options_.scenario();
    const roads::Cell a = locate("--from", from_, h.georef, h.cols, h.rows), b = locate("--to", to_, h.georef, h.cols, h.rows);
    if (a == b) throw bad_input("--from/--to: both points fall in the same cell");
    for (const auto& [opt, c] : {std::pair{"--from", a}, std::pair{"--to", b}})
      if (reader.read(c.col, c.row, 1, 1).is_nodata(0)) throw bad_input(std::string(opt) + ": the point is on a nodata cell of " + dem_.path);
    const DemWindowReader lakes(
        pipeline::inland_water_mosaic(reader, pipeline::inland_water_settings(scenario), tiles, scratch, context.progress, context.log),
        ReadOptions{});
    const double budget_mb = tiles.limit_mb() - reserve_reader_memory(tiles.limit_mb());
    const pipeline::RoadWindows w = pipeline::road_windows(reader, lakes, h.georef, scenario, model, roads::corridor_reach_m(corridor), budget_mb,
                                                           options_.settings().vegetation);
    roads::RoutingOptions bounded = routing;
    bounded.max_nodes = std::min(routing.max_nodes, w.max_nodes);
    for (const auto& [opt, c] : {std::pair{"--from", a}, std::pair{"--to", b}}) {  // as on the whole DEM: an end in the sea refused
      const int s = routing.snap_cells, c0 = std::max(0, c.col - s), r0 = std::max(0, c.row - s);
      const roads::TerrainField near = w.read(c0, r0, std::min(h.cols, c.col + s + 1) - c0, std::min(h.rows, c.row + s + 1) - r0);
      if (!roads::snap_to_land(near, c, s))
        throw bad_input(std::string(opt) + ": the point is in the sea (no land within " + std::to_string(s) + " cells)");
    }
    roads::WindowedRoad road;
    try {
      road = roads::route_by_windows(w.grid, w.read, model, options_.graph(), a, b, bounded, w.window, &context.progress);
    } catch (const Error& e) {
      if (e.kind() != ErrorKind::processing) throw;
      throw Error(e.kind(), std::string(e.what()) + " (--memory-limit " + std::to_string(int(tiles.limit_mb())) + " allows " +
                                std::to_string(bounded.max_nodes) + ")");
    }
    if (road.limited)
      context.log.warn("path by windows: no window --memory-limit allows proved the road the whole grid's; the largest window's answer is kept");
    context.log.detail("path by windows: " + std::to_string(road.windows) + " windows searched, the largest " +
                       std::to_string(road.largest_cells) + " cells of the " + std::to_string(h.cols) + " x " + std::to_string(h.rows) + " DEM");
    context.log.detail("the memory limit allows windows of " + std::to_string(w.window.max_cells) + " cells and " +
                       std::to_string(bounded.max_nodes) + " search nodes");
    return road;
  }

  /// Cost of a polyline walked through 8-neighbour steps (a D8 path such as r.drain's).
  double evaluate(const roads::RoadGraph& graph, const roads::TerrainField& terrain, const Dem& dem) const {
    const VectorLayer layer = read_vector(evaluate_, dem.georef().crs);
    if (layer.features.empty() || layer.features[0].parts.empty()) throw bad_input(evaluate_ + ": no line to evaluate");
    std::vector<roads::Cell> chain;
    for (const auto& f : layer.features)
      for (const auto& part : f.parts)
        for (const auto& v : part) {
          const auto c = roads::cell_at(terrain, v[0], v[1]);
          if (!c) throw bad_input(evaluate_ + ": a vertex lies outside the DEM");
          while (!chain.empty() && !(chain.back() == *c)) {  // 8-neighbour steps towards the vertex
            roads::Cell n = chain.back();
            n.col += (c->col > n.col) - (c->col < n.col);
            n.row += (c->row > n.row) - (c->row < n.row);
            chain.push_back(n);
          }
          if (chain.empty()) chain.push_back(*c);
        }
    return roads::chain_cost(graph, chain);
  }

  std::string evaluate_;
  DemInput dem_;
  std::string from_, to_, out_, crs_ = "lonlat", search_ = "astar", sections_, corridor_;
  RoadOptions options_;
};

}  // namespace

std::unique_ptr<Command> make_path_command() { return std::make_unique<PathCommand>(); }

}  // namespace terrapolis::cli
