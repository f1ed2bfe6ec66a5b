// Single roads, network routing in parallel, maritime links and the output layers.
// SPDX-License-Identifier: MIT
#include "roads/road_network.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cmath>
#include <map>
#include <mutex>

#include "core/error.hpp"
#include "core/random.hpp"

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
                               Progress* progress, TargetSearch* shared) {
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
    const SearchResult s = shortest_path(graph, *a, *b, options.search, options.max_nodes, progress, options.max_seconds, shared);
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

NetworkResult route_network(const TerrainField& t, const RoadGraph& graph, const std::vector<Link>& links, const RoutingOptions& options,
                            Progress& progress) {
  struct Edge {
    Cell a, b;
  };
  std::vector<Edge> edges;
  for (std::size_t i = 0; i < links.size(); ++i) {
    const auto a = cell_at(t, links[i].a[0], links[i].a[1]), b = cell_at(t, links[i].b[0], links[i].b[1]);
    if (!a || !b)
      throw bad_input("network: link " + std::to_string(links[i].from) + "-" + std::to_string(links[i].to) + " has an end outside the DEM");
    edges.push_back({*a, *b});
  }
  // Roads ending at the same cell share one target search (arc costs and the heuristic's reverse
  // search, see TargetSearch): edges are grouped by their end, the groups routed in parallel, each
  // group's roads in edge order on one thread, so the output does not depend on the threads.
  std::vector<std::vector<std::size_t>> groups;
  {
    std::map<std::size_t, std::size_t> group_of;
    for (std::size_t i = 0; i < edges.size(); ++i) {
      const auto [it, fresh] = group_of.try_emplace(t.index(edges[i].b.col, edges[i].b.row), groups.size());
      if (fresh) groups.emplace_back();
      groups[it->second].push_back(i);
    }
  }
  std::vector<std::optional<Road>> out(edges.size());
  ProgressStep step(progress, "roads");
  std::mutex progress_mutex;  // the sink is not thread-safe; a cancel throws out of parallel_for
  std::size_t done = 0;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, groups.size(), 1), [&](const tbb::blocked_range<std::size_t>& range) {
    for (std::size_t g = range.begin(); g != range.end(); ++g) {
      std::optional<TargetSearch> shared;
      if (const auto end = snap_to_land(t, edges[groups[g].front()].b, options.snap_cells)) shared.emplace(graph, *end);
      for (const std::size_t i : groups[g]) {
        RoutingOptions o = options;
        o.bezier.seed = splitmix64(options.bezier.seed ^ splitmix64(i));
        const Edge& e = edges[i];
        if (e.a == e.b) continue;
        out[i] = route_road(t, graph, e.a, e.b, o, nullptr, shared ? &*shared : nullptr);
        if (out[i]) {
          out[i]->from = links[i].from;
          out[i]->to = links[i].to;
          out[i]->road_class = out[i]->ferry ? RoadClass::maritime : links[i].road_class;
        }
        const std::lock_guard<std::mutex> lock(progress_mutex);
        ++done;
        step.update(double(done) / double(edges.size()), std::to_string(done) + " of " + std::to_string(edges.size()) + " roads");
      }
    }
  });
  step.update(1.0);
  NetworkResult result;
  for (std::size_t i = 0; i < edges.size(); ++i) {
    const std::string name = std::to_string(links[i].from) + "-" + std::to_string(links[i].to);
    if (!out[i]) {
      if (!(edges[i].a == edges[i].b)) result.failed.push_back(name);
    } else if (out[i]->over_budget) {
      result.over_budget.push_back(name);
    } else {
      result.roads.push_back(std::move(*out[i]));
    }
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
    f.values = {std::int64_t(r.from), std::int64_t(r.to), std::string(name_of(r.road_class)), r.router, round_to(r.stats.length_m, 0.01), opt(cost),
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
