// Single roads, network routing in parallel, maritime links and the output layers.
// SPDX-License-Identifier: MIT
#include "roads/road_network.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cmath>
#include <map>
#include <mutex>

#include "core/error.hpp"

namespace terrapolis::roads {
namespace {

}  // namespace

std::optional<Cell> snap_to_land(const TerrainField& t, Cell c, int radius) {
  if (!t.water(c.col, c.row)) return c;
  std::optional<Cell> best;
  double best_d = 1e300;
  for (int dr = -radius; dr <= radius; ++dr)
    for (int dc = -radius; dc <= radius; ++dc) {
      const Cell n{c.col + dc, c.row + dr};
      if (!t.inside(n.col, n.row) || t.water(n.col, n.row)) continue;
      const double d = t.length_m({double(c.col), double(c.row)}, {double(n.col), double(n.row)});
      if (d < best_d) {  // scan order breaks ties: deterministic
        best_d = d;
        best = n;
      }
    }
  return best;
}

namespace {

std::uint64_t mix(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

}  // namespace

std::optional<Cell> cell_at(const TerrainField& terrain, double x, double y) {
  // Inverse of the affine geotransform (no CRS operation needed).
  const auto& g = terrain.georef().transform;
  const double det = g[1] * g[5] - g[2] * g[4];
  if (det == 0 || !std::isfinite(x) || !std::isfinite(y)) return std::nullopt;
  const double dx = x - g[0], dy = y - g[3];
  const double col = (g[5] * dx - g[2] * dy) / det, row = (-g[4] * dx + g[1] * dy) / det;
  if (!std::isfinite(col) || !std::isfinite(row)) return std::nullopt;
  const int c = int(std::floor(col)), r = int(std::floor(row));
  if (!terrain.inside(c, r)) return std::nullopt;
  return Cell{c, r};
}

std::optional<Road> route_road(const TerrainField& t, const RoadGraph& graph, Cell from, Cell to, const RoutingOptions& options,
                               Progress* progress) {
  Road road;
  const auto a = snap_to_land(t, from, options.snap_cells), b = snap_to_land(t, to, options.snap_cells);
  const auto& land = t.land_components();
  auto ferry = [&]() {
    // A maritime link (Belhadj §4.4.4): the two ends cannot be joined on the ground.
    road.ferry = true;
    road.router = "ferry";
    road.cost.reset();
    road.ferry_line = {{double(from.col), double(from.row)}, {double(to.col), double(to.row)}};
    road.stats = {};
    road.stats.length_m = t.length_m(road.ferry_line[0], road.ferry_line[1]);
    return road;
  };
  const bool apart = !a || !b || land[t.index(a->col, a->row)] != land[t.index(b->col, b->row)];
  // Two land masses: only bridges can join them on the ground (an archipelago), else a ferry.
  if (!a || !b || (apart && (options.router == Router::bezier || !graph.model().bridge.enabled))) return ferry();
  if (options.router == Router::galin) {
    const SearchResult s = shortest_path(graph, *a, *b, options.search, options.max_nodes, progress, options.max_seconds);
    if (s.over_budget) {
      road.over_budget = true;
      road.router = "galin";
      return road;
    }
    road.expanded = s.expanded;
    road.rings_priced = s.rings_priced;
    road.relaxed_settled = s.relaxed_settled;
    road.nodes = s.nodes;
    if (!s.found) {
      if (apart) return ferry();
      return std::nullopt;
    }
    road.router = "galin";
    road.cost = s.cost;
    road.geometry = build_road_geometry(t, graph.model(), s);
  } else {
    BezierOptions bo = options.bezier;
    bo.max_slope_deg = graph.model().road.slope_deg.threshold == kInfinity ? 15.0 : graph.model().road.slope_deg.threshold;
    const BezierResult br = bezier_route(t, {double(a->col), double(a->row)}, {double(b->col), double(b->row)}, bo);
    road.router = "bezier";
    road.geometry = surface_geometry(t, graph.model(), br.polyline);
    // The same yardstick as the Galin router: the discrete curve priced by the Galin cost model.
    std::vector<Cell> cells;
    for (const GridPoint& p : br.polyline) cells.push_back({int(p.col), int(p.row)});
    std::vector<Cell> chain;
    bool ok = true;
    for (const Cell& c : cells) {
      if (!chain.empty()) {
        const int dc = c.col - chain.back().col, dr = c.row - chain.back().row;
        if (std::abs(dc) > 1 || std::abs(dr) > 1) ok = false;
      }
      chain.push_back(c);
    }
    const double cost = ok ? chain_cost(graph, chain) : kInfinity;
    if (cost < kInfinity) road.cost = cost;
  }
  road.stats = road_stats(t, road.geometry);
  return road;
}

NetworkResult route_network(const TerrainField& t, const RoadGraph& graph, const VectorLayer& network, const VectorLayer* cities,
                            const RoutingOptions& options, Progress& progress) {
  const int f_from = network.field_index("from"), f_to = network.field_index("to"), f_kept = network.field_index("kept");
  if (f_from < 0 || f_to < 0) throw bad_input(network.name + ": the network needs integer fields 'from' and 'to'");
  if (network.geometry != GeometryType::line_string) throw bad_input(network.name + ": the network must hold LineStrings");
  auto as_int = [](const FieldValue& v) -> std::optional<std::int64_t> {
    if (const auto* i = std::get_if<std::int64_t>(&v)) return *i;
    if (const auto* d = std::get_if<double>(&v)) return std::int64_t(std::llround(*d));
    return std::nullopt;
  };
  std::map<std::int64_t, std::int64_t> city_class;
  if (cities) {
    const int f_id = cities->field_index("id"), f_class = cities->field_index("class");
    if (f_id < 0 || f_class < 0) throw bad_input(cities->name + ": the cities need integer fields 'id' and 'class'");
    for (const Feature& f : cities->features) {
      const auto id = as_int(f.values[std::size_t(f_id)]), cls = as_int(f.values[std::size_t(f_class)]);
      if (id && cls) city_class[*id] = *cls;
    }
  }
  struct Edge {
    std::int64_t from, to;
    Cell a, b;
  };
  std::vector<Edge> edges;
  for (std::size_t i = 0; i < network.features.size(); ++i) {
    const Feature& f = network.features[i];
    if (f_kept >= 0) {
      const auto kept = as_int(f.values[std::size_t(f_kept)]);
      if (kept && *kept == 0) continue;
    }
    if (f.parts.empty() || f.parts[0].size() < 2) continue;
    const auto& line = f.parts[0];
    const auto a = cell_at(t, line.front()[0], line.front()[1]), b = cell_at(t, line.back()[0], line.back()[1]);
    if (!a || !b) throw bad_input(network.name + ": edge " + std::to_string(i) + " has an end outside the DEM");
    edges.push_back({as_int(f.values[std::size_t(f_from)]).value_or(-1), as_int(f.values[std::size_t(f_to)]).value_or(-1), *a, *b});
  }
  std::vector<std::optional<Road>> out(edges.size());
  ProgressStep step(progress, "roads");
  std::mutex progress_mutex;  // the sink is not thread-safe; a cancel throws out of parallel_for
  std::size_t done = 0;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, edges.size(), 1), [&](const tbb::blocked_range<std::size_t>& range) {
    for (std::size_t i = range.begin(); i != range.end(); ++i) {
      RoutingOptions o = options;
      o.bezier.seed = mix(options.bezier.seed ^ mix(i));
      const Edge& e = edges[i];
      if (e.a == e.b) continue;
      out[i] = route_road(t, graph, e.a, e.b, o);
      if (out[i]) {
        out[i]->from = e.from;
        out[i]->to = e.to;
      }
      const std::lock_guard<std::mutex> lock(progress_mutex);
      step.update(double(++done) / double(edges.size()));
    }
  });
  step.update(1.0);
  NetworkResult result;
  for (std::size_t i = 0; i < edges.size(); ++i) {
    const Edge& e = edges[i];
    if (!out[i]) {
      if (!(e.a == e.b)) result.failed.push_back(std::to_string(e.from) + "-" + std::to_string(e.to));
      continue;
    }
    if (out[i]->over_budget) {
      result.over_budget.push_back(std::to_string(e.from) + "-" + std::to_string(e.to));
      continue;
    }
    Road r = std::move(*out[i]);
    const auto ca = city_class.find(e.from), cb = city_class.find(e.to);
    if (ca != city_class.end() && cb != city_class.end()) {
      const double mean = 0.5 * double(ca->second + cb->second);
      r.road_class = mean < 1 ? "motorway" : mean < 2 ? "national" : "departmental";
    } else {
      r.road_class = "departmental";
    }
    result.roads.push_back(std::move(r));
  }
  return result;
}

namespace {
std::vector<std::array<double, 2>> to_crs(const TerrainField& t, const std::vector<GridPoint>& pts) {
  std::vector<std::array<double, 2>> out;
  out.reserve(pts.size());
  for (const GridPoint& p : pts) out.push_back(t.georef().cell_centre(p.col, p.row));
  return out;
}
FieldValue opt(std::optional<double> v) { return v ? FieldValue(*v) : FieldValue(std::monostate{}); }
double round_to(double v, double unit) { return std::round(v / unit) * unit; }
}  // namespace

VectorLayer roads_layer(const TerrainField& t, const std::vector<Road>& roads) {
  VectorLayer layer;
  layer.name = "roads";
  layer.geometry = GeometryType::line_string;
  layer.crs = t.georef().crs;
  layer.fields = {{"from", FieldType::integer},      {"to", FieldType::integer},        {"class", FieldType::string},
                  {"router", FieldType::string},     {"length_m", FieldType::real},     {"cost", FieldType::real},
                  {"max_grade_pct", FieldType::real}, {"mean_grade_pct", FieldType::real}, {"bridge_m", FieldType::real},
                  {"tunnel_m", FieldType::real}};
  for (const Road& r : roads) {
    Feature f;
    f.parts.push_back(to_crs(t, r.ferry ? r.ferry_line : r.geometry.points));
    std::optional<double> cost;
    if (r.cost) cost = round_to(*r.cost, 0.01);
    f.values = {std::int64_t(r.from), std::int64_t(r.to), r.road_class, r.router, round_to(r.stats.length_m, 0.01), opt(cost),
                round_to(r.stats.max_grade_pct, 0.01), round_to(r.stats.mean_grade_pct, 0.01), round_to(r.stats.bridge_m, 0.01),
                round_to(r.stats.tunnel_m, 0.01)};
    layer.features.push_back(std::move(f));
  }
  return layer;
}

VectorLayer sections_layer(const TerrainField& t, const std::vector<Road>& roads) {
  VectorLayer layer;
  layer.name = "road_sections";
  layer.geometry = GeometryType::line_string;
  layer.crs = t.georef().crs;
  layer.fields = {{"road", FieldType::integer}, {"from", FieldType::integer}, {"to", FieldType::integer},
                  {"structure", FieldType::string}, {"length_m", FieldType::real}};
  for (std::size_t i = 0; i < roads.size(); ++i) {
    const Road& r = roads[i];
    if (r.ferry) {
      layer.features.push_back({{to_crs(t, r.ferry_line)}, {std::int64_t(i), std::int64_t(r.from), std::int64_t(r.to), std::string("ferry"),
                                                             round_to(r.stats.length_m, 0.01)}});
      continue;
    }
    for (const RoadSection& s : road_sections(t, r.geometry))
      layer.features.push_back({{to_crs(t, s.points)}, {std::int64_t(i), std::int64_t(r.from), std::int64_t(r.to), s.structure,
                                                        round_to(s.length_m, 0.01)}});
  }
  return layer;
}

}  // namespace terrapolis::roads
