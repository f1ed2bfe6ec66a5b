// Options shared by the `path` and `roads` commands (one declaration for both).
// SPDX-License-Identifier: MIT
#pragma once
#include <CLI/CLI.hpp>

#include <cstdint>
#include <string>

#include "cli/plugin_options.hpp"
#include "hydro/flat_water.hpp"
#include "io/raster_io.hpp"
#include "roads/earthworks.hpp"
#include "roads/road_network.hpp"

namespace terrapolis::cli {

struct RoadOptions {
  int k = 5, angles = 8;
  std::string costs, vegetation, earthworks;
  bool bridges = true, tunnels = true, overwrite = false;
  std::uint64_t seed = 1;
  double sea_level = 0;
  std::string router = "galin";
  int bezier_evaluations = 1000, bezier_tries = 20;
  double bezier_threshold = 0.1;
  double max_seconds = 0;
  double flat_water_km2 = 1;  ///< the schema's water.flat_water_min_km2
  PluginOptions plugins;

  void setup(CLI::App& app) {
    app.add_option("--router", router, "Router: galin (anisotropic shortest path) or bezier (Belhadj 2007 Alg. 16)")
        ->check(CLI::IsMember({"galin", "bezier"}));
    app.add_option("--k", k, "Segment mask M_k: arcs to (i,j) in [-k,k]^2 with gcd 1 (k = 5: 80 arcs, 11.3 deg)")->check(CLI::Range(1, 16));
    app.add_option("--angles", angles, "Orientation sectors m pricing curvature (1 disables)")->check(CLI::Range(1, 64));
    app.add_option("--costs", costs, "JSON file overriding the default transfer functions");
    app.add_flag("--bridges,!--no-bridges", bridges, "Allow bridges (long arcs over valleys and water); default on");
    app.add_flag("--tunnels,!--no-tunnels", tunnels, "Allow tunnels (long arcs under ridges); default on");
    app.add_option("--vegetation", vegetation, "Raster of vegetation / land-cover density (any GDAL raster, warped onto the DEM grid) priced by the 'vegetation' transfer functions");
    app.add_option("--seed", seed, "Seed of the stochastic bridge/tunnel arcs and of the Bézier router");
    app.add_option("--sea-level", sea_level, "Cells at or below this height (m) and nodata cells are water");
    app.add_option("--bezier-evaluations", bezier_evaluations, "Bézier router budget: curve evaluations per road (replaces the thesis' 1000 ms, for reproducible roads)")->check(CLI::Range(1, 1000000));
    app.add_option("--bezier-threshold", bezier_threshold, "Bézier router: stop when the worst position costs less (0..1)")->check(CLI::Range(0.0, 1.0));
    app.add_option("--bezier-tries", bezier_tries, "Bézier router: control points drawn per worst position")->check(CLI::Range(1, 100000));
    app.add_option("--flat-water-km2", flat_water_km2, "Lakes the DEM shows flat (SRTM): a level surface of at least this area is water (0 = off)")
        ->check(CLI::Range(0.0, 1e6));
    app.add_option("--max-seconds", max_seconds, "Per-road search budget in seconds (wall clock; 0 = none): a road that takes longer is reported 'not routed: budget'")
        ->check(CLI::Range(0.0, 86400.0));
    app.add_option("--earthworks", earthworks, "Also write the DEM after cut-and-fill along the surface roads (GeoTIFF; 8 m carriageway, 2:3 sides)");
    plugins.setup(app, "adds its road cost term (characteristic priced by its transfer functions; galin router)");
    app.add_flag("--overwrite", overwrite, "Replace the outputs a previous terrapolis command wrote");
  }

  /// The files these options read (the outputs may not replace them).
  std::vector<std::string> inputs() const { return {costs, vegetation}; }

  /// The DEM after the earthworks of the roads (empty when --earthworks is not given).
  Dem earthworks_dem(const Dem& dem, const roads::TerrainField& terrain, const std::vector<roads::Road>& roads) const {
    if (earthworks.empty()) return Dem();
    std::vector<const roads::RoadGeometry*> geometries;
    for (const roads::Road& r : roads) geometries.push_back(&r.geometry);
    return roads::earthworks(dem, terrain, geometries);
  }
  /// Writes the levelled DEM to `path` (where the command's OutputSet stages --earthworks).
  void write_earthworks(const std::string& path, const Dem& levelled) const {
    if (earthworks.empty()) return;
    WriteOptions w;
    w.description = "terrain after cut-and-fill along the roads (m)";
    write_raster(path, levelled, w);
  }

  /// Lakes the DEM flattens (hydro::detect_flat_water), for the TerrainField.
  hydro::FlatWater flat_water(const Dem& dem) const { return hydro::detect_flat_water(dem, {flat_water_km2, 0.0, sea_level}); }

  roads::CostModel cost_model() const {
    roads::CostModel m = costs.empty() ? roads::default_cost_model() : roads::load_cost_model(costs);
    if (!bridges) m.bridge.enabled = false;
    if (!tunnels) m.tunnel.enabled = false;
    return m;
  }
  /// Loads --vegetation onto the DEM's grid when given, and adds the plugins' road cost terms.
  void load_layers(roads::TerrainField& terrain, const plugin::PluginSet& set, const Dem& dem, Progress& progress, const Log& log) const {
    if (!vegetation.empty())
      terrain.set_vegetation(read_resampled(vegetation, terrain.georef(), terrain.cols(), terrain.rows(), Resampling::bilinear));
    plugin::add_to_terrain(plugin::road_terms(set, dem, progress, log), terrain);
  }
  roads::GraphOptions graph() const { return {k, angles, seed}; }
  roads::RoutingOptions routing() const {
    roads::RoutingOptions r;
    r.router = router == "bezier" ? roads::Router::bezier : roads::Router::galin;
    r.graph = graph();
    r.bezier.seed = seed;
    r.bezier.max_evaluations = bezier_evaluations;
    r.bezier.threshold = bezier_threshold;
    r.bezier.tries = bezier_tries;
    r.max_seconds = max_seconds;
    return r;
  }
};

}  // namespace terrapolis::cli
