// `terrapolis generate --method coast|planar`. See generate_methods.hpp.
// SPDX-License-Identifier: MIT
#include "cli/generate_methods.hpp"

#include <cmath>
#include <cstdio>
#include <map>

#include "core/error.hpp"
#include "io/vector_io.hpp"

namespace terrapolis::cli {
namespace {

std::string fixed(double v, int decimals) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.*f", decimals, v);
  return buffer;
}

double cell_metres(const Raster<float>& grid) {
  return std::abs(grid.georef().transform[1]) * (grid.georef().crs.linear_unit_m > 0 ? grid.georef().crs.linear_unit_m : 1.0);
}

/// Plan metres (x east, y south from the north-west corner) to the grid's CRS, and back.
std::array<double, 2> to_crs(const Raster<float>& grid, terrain::Point2 p) {
  const auto& t = grid.georef().transform;
  const double cell = cell_metres(grid);
  return {t[0] + p.x / cell * t[1], t[3] + p.y / cell * t[5]};
}
terrain::Point2 to_plan(const Raster<float>& grid, std::array<double, 2> xy) {
  const auto& t = grid.georef().transform;
  const double cell = cell_metres(grid);
  return {(xy[0] - t[0]) / t[1] * cell, (xy[1] - t[3]) / t[5] * cell};
}

VectorLayer skeleton_layer(const Raster<float>& grid) {
  VectorLayer layer;
  layer.name = "skeleton";
  layer.geometry = GeometryType::line_string;
  layer.crs = grid.georef().crs;
  layer.fields = {{"kind", FieldType::string}, {"strahler", FieldType::integer}, {"priority", FieldType::integer},
                  {"discharge_m3s", FieldType::real}, {"river_type", FieldType::string}, {"z_up_m", FieldType::real},
                  {"z_down_m", FieldType::real}};
  return layer;
}

}  // namespace

void CoastOptions::add(CLI::App& app) {
  auto& p = params;
  app.add_option("--coast", coast, "coast: GeoJSON/GeoPackage polygon(s) of the land, in any CRS (default: a seeded island)");
  app.add_option("--grammar", grammar, "coast: P_c,P_s,P_a of the grammar (Génévaux §4.3), summing to 1")->capture_default_str();
  app.add_option("--edge", p.edge_m, "coast: grammar edge length e (m)")->capture_default_str()->check(CLI::PositiveNumber);
  app.add_option("--sigma", p.sigma_m, "coast: least distance between edges σ (m, > e/√2)")->capture_default_str()->check(CLI::PositiveNumber);
  app.add_option("--delta", p.delta_m, "coast: least distance from an edge to the coast δ (m)")->capture_default_str()->check(CLI::NonNegativeNumber);
  app.add_option("--kappa", p.kappa, "coast: greatest slope κ (m/m) between a new node and its neighbours")->capture_default_str()->check(CLI::PositiveNumber);
  app.add_option("--zeta", p.zeta_m, "coast: altitude window ζ (m) of the mixed selection (0: lowest first)")->capture_default_str()->check(CLI::NonNegativeNumber);
  app.add_option("--lambda", p.lambda, "coast: λ of the ridge heights q_z = max(p_z) + λd (paper: 0-0.25)")->capture_default_str()->check(CLI::Range(0.0, 1.0));
  app.add_option("--max-priority", p.max_priority, "coast: priority of the main mouth")->capture_default_str()->check(CLI::Range(0, 12));
  app.add_option("--river-grade", p.river_grade, "coast: rise per metre of a main-priority river edge (m/m)")->capture_default_str()->check(CLI::PositiveNumber);
  app.add_option("--primitive-spacing", p.primitive_spacing_m, "coast: spacing of the terrain primitives (m)")->capture_default_str()->check(CLI::PositiveNumber);
}

GeneratedRegion CoastOptions::run(Raster<float>& grid, std::uint64_t seed, Context& context) {
  params.seed = seed;
  const auto g = parse_triple_probabilities();
  params.p_continue = g[0];
  params.p_symmetric = g[1];
  params.p_asymmetric = g[2];
  const double cell = cell_metres(grid);
  std::vector<std::vector<terrain::Point2>> rings;
  if (coast.empty()) {
    rings = terrain::synthetic_coast(grid.cols() * cell, grid.rows() * cell, seed);
  } else {
    const VectorLayer layer = read_vector(coast, grid.georef().crs);
    if (layer.geometry != GeometryType::polygon) throw bad_input(coast + ": expected polygons (the land), found another geometry");
    for (const Feature& f : layer.features)
      for (const auto& ring : f.parts) {
        std::vector<terrain::Point2> plan;
        for (const auto& xy : ring) plan.push_back(to_plan(grid, xy));
        if (plan.size() > 1 && plan.front().x == plan.back().x && plan.front().y == plan.back().y) plan.pop_back();
        if (plan.size() >= 3) rings.push_back(std::move(plan));
      }
    if (rings.empty()) throw bad_input(coast + ": no polygon");
  }
  const terrain::CoastTerrain t = terrain::generate_coast_terrain(grid, rings, params, &context.progress);

  GeneratedRegion out;
  out.skeleton = skeleton_layer(grid);
  std::map<int, std::size_t> by_priority;
  for (const terrain::RiverNode& n : t.nodes) {
    if (n.parent < 0) continue;
    ++by_priority[n.priority];
    Feature f;
    std::vector<std::array<double, 2>> line;
    for (const terrain::Point2& p : n.course) line.push_back(to_crs(grid, p));
    f.parts.push_back(std::move(line));
    f.values = {std::string("river"), std::int64_t(n.strahler), std::int64_t(n.priority), n.discharge_m3s,
                std::string(hydro::river_type_name(n.type)), n.z, t.nodes[std::size_t(n.parent)].z};
    out.skeleton.features.push_back(std::move(f));
  }
  for (const terrain::RidgeSegment& s : t.ridges) {
    Feature f;
    f.parts.push_back({to_crs(grid, s.a), to_crs(grid, s.b)});
    f.values = {std::string("ridge"), std::monostate{}, std::monostate{}, std::monostate{}, std::monostate{}, std::max(s.za, s.zb),
                std::min(s.za, s.zb)};
    out.skeleton.features.push_back(std::move(f));
  }
  std::size_t streams = 0;
  for (auto [priority, count] : by_priority) streams += count;
  const double low = streams ? double(by_priority[0] + by_priority[1]) / streams : 0;
  const double density = t.land_km2 > 0 ? t.river_km / t.land_km2 : 0;
  std::string histogram;
  for (auto [priority, count] : by_priority) histogram += (histogram.empty() ? "" : " ") + std::to_string(priority) + ":" + std::to_string(count);
  context.log.info("generate: coast method, " + std::to_string(t.mouths) + " mouths, " + std::to_string(t.nodes.size()) + " river nodes, " +
                   fixed(t.land_km2, 1) + " km² of land");
  context.log.info("generate: " + fixed(t.river_km, 1) + " km of river = " + fixed(density, 3) + " km/km² (paper Tab. 2: 0.42-0.46); " +
                   std::to_string(t.terrain_primitives) + " terrain primitives = " + fixed(t.terrain_primitives / std::max(t.land_km2, 1e-9), 1) +
                   " per km² (Tab. 2: about 10), " + std::to_string(t.river_primitives) + " river primitives");
  context.log.info("generate: streams by priority " + histogram + "; priority 0-1: " + fixed(100 * low, 1) + " % (paper §4.3: > 75 % low-priority)");
  context.log.info("generate: time graph " + fixed(t.graph_s, 2) + " s, analysis " + fixed(t.analysis_s, 2) + " s, terrain " + fixed(t.terrain_s, 2) +
                   " s (paper Tab. 1 phases)");
  out.metadata = {{"TERRAPOLIS_GENERATOR", "coast (Genevaux et al. 2013)"},
                  {"TERRAPOLIS_SEED", std::to_string(seed)},
                  {"TERRAPOLIS_GRAMMAR", grammar},
                  {"TERRAPOLIS_EDGE_M", fixed(params.edge_m, 1)},
                  {"TERRAPOLIS_SIGMA_M", fixed(params.sigma_m, 1)},
                  {"TERRAPOLIS_LAMBDA", fixed(params.lambda, 3)},
                  {"TERRAPOLIS_RIVER_KM", fixed(t.river_km, 3)},
                  {"TERRAPOLIS_LAND_KM2", fixed(t.land_km2, 3)},
                  {"TERRAPOLIS_TERRAIN_PRIMITIVES", std::to_string(t.terrain_primitives)},
                  {"TERRAPOLIS_RIVER_PRIMITIVES", std::to_string(t.river_primitives)}};
  return out;
}

std::array<double, 3> CoastOptions::parse_triple_probabilities() const {
  std::array<double, 3> v{};
  char tail = 0;
  if (std::sscanf(grammar.c_str(), "%lf,%lf,%lf%c", &v[0], &v[1], &v[2], &tail) != 3)
    throw bad_input("--grammar: expected P_c,P_s,P_a (e.g. 0.2,0.7,0.1), got '" + grammar + "'");
  return v;
}

void PlanarOptions::add(CLI::App& app) {
  auto& p = params;
  app.add_option("--tree", tree, "planar: the river tree as nested pairs, '.' a source, '(LR)' a confluence (default: random)");
  app.add_option("--nodes", nodes, "planar: confluences of the random increasing binary tree")->capture_default_str()->check(CLI::Range(1, 200000));
  app.add_option("--drop", p.drop_m, "planar: CRIV (m) of DALT = CRIV / Strahler^a, the rise of a river vertex above its parent")
      ->capture_default_str()->check(CLI::PositiveNumber);
  app.add_option("--drop-exponent", p.drop_exponent, "planar: a of DALT")->capture_default_str()->check(CLI::NonNegativeNumber);
  app.add_option("--bank-slope", p.bank_slope, "planar: least facet slope (m/m) towards a river or away from a ridge")
      ->capture_default_str()->check(CLI::NonNegativeNumber);
  app.add_option("--fractalisations", p.fractalisations, "planar: global fractalisations (x4 facets each)")->capture_default_str()->check(CLI::Range(0, 8));
  app.add_option("--meander", p.meander, "planar: C_PONDERAL, pull of new river vertices to a facet centre (0: straight)")
      ->capture_default_str()->check(CLI::NonNegativeNumber);
}

GeneratedRegion PlanarOptions::run(Raster<float>& grid, std::uint64_t seed, Context& context) {
  params.seed = seed;
  const terrain::BinaryTree t = tree.empty() ? terrain::random_increasing_tree(nodes, seed) : terrain::parse_tree(tree, "--tree");
  const double cell = cell_metres(grid);
  const terrain::PlanarMap map = terrain::build_planar_map(t, grid.cols() * cell, grid.rows() * cell, params);
  terrain::rasterise(map, grid, &context.progress);
  GeneratedRegion out;
  out.skeleton = skeleton_layer(grid);
  double river_m = 0;
  for (const auto& e : map.rivers) {
    Feature f;
    f.parts.push_back({to_crs(grid, map.p[std::size_t(e.up)]), to_crs(grid, map.p[std::size_t(e.down)])});
    f.values = {std::string("river"), std::int64_t(e.strahler), std::monostate{}, std::monostate{}, std::monostate{},
                map.z[std::size_t(e.up)], map.z[std::size_t(e.down)]};
    out.skeleton.features.push_back(std::move(f));
    river_m += terrain::norm(map.p[std::size_t(e.up)] - map.p[std::size_t(e.down)]);
  }
  for (auto [a, b] : map.ridges) {
    Feature f;
    f.parts.push_back({to_crs(grid, map.p[std::size_t(a)]), to_crs(grid, map.p[std::size_t(b)])});
    f.values = {std::string("ridge"), std::monostate{}, std::monostate{}, std::monostate{}, std::monostate{},
                std::max(map.z[std::size_t(a)], map.z[std::size_t(b)]), std::min(map.z[std::size_t(a)], map.z[std::size_t(b)])};
    out.skeleton.features.push_back(std::move(f));
  }
  context.log.info("generate: planar method, " + std::to_string(t.size()) + " tree nodes, " + std::to_string(map.p.size()) + " map vertices, " +
                   std::to_string(map.facets.size()) + " facets, " + fixed(river_m / 1000, 1) + " km of river; ridge altitudes from " +
                   std::to_string(map.lp_problems) + " linear programs (" + std::to_string(map.lp_variables) + " unknowns, " +
                   std::to_string(map.lp_constraints) + " inequalities)");
  out.metadata = {{"TERRAPOLIS_GENERATOR", "planar (planar-maps chapter, 6.2-6.3)"},
                  {"TERRAPOLIS_SEED", std::to_string(seed)},
                  {"TERRAPOLIS_TREE_NODES", std::to_string(t.size())},
                  {"TERRAPOLIS_DROP_M", fixed(params.drop_m, 3)},
                  {"TERRAPOLIS_BANK_SLOPE", fixed(params.bank_slope, 4)},
                  {"TERRAPOLIS_FRACTALISATIONS", std::to_string(params.fractalisations)}};
  return out;
}

}  // namespace terrapolis::cli
