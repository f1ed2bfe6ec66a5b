// Single roads, the network routed link after link by importance (reuse, redundancy), maritime links and the output layers.
// SPDX-License-Identifier: MIT
#include "roads/road_network.hpp"

#include <cmath>
#include <numbers>
#include <algorithm>

#include "core/error.hpp"
#include "core/random.hpp"

namespace terrapolis::roads {

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
                               Progress* progress, TargetSearch* shared, const ArcDiscount* discount) {
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
    const SearchResult s = shortest_path(graph, *a, *b, options.search, options.max_nodes, progress, options.max_seconds, shared, discount);
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
    road.chain = cell_chain(t, s.cells, s.structures);
  } else {
    BezierOptions bo = options.bezier;
    bo.max_slope_deg = graph.model().road.slope_deg.threshold == kInfinity ? 15.0 : graph.model().road.slope_deg.threshold;
    const BezierResult br = bezier_route(t, {double(a->col), double(a->row)}, {double(b->col), double(b->row)}, bo);
    road.router = "bezier";
    road.geometry = surface_geometry(t, graph.model(), br.polyline);
    // The same yardstick as the Galin router: the discrete curve priced by the Galin cost model.
    std::vector<Cell> cells;
    for (const GridPoint& p : br.polyline) cells.push_back({int(p.col), int(p.row)});
    road.chain = cell_chain(t, cells);
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
  road.stats = road_stats(t, graph.model(), road.geometry);
  return road;
}

namespace {

/// The roads built so far, as the next searches see them: per cell the most important class on it
/// and the cost factor it gives (ArcDiscount), and which cells the network joins (union-find).
class BuiltRoads {
 public:
  BuiltRoads(const TerrainField& t, const std::array<double, 4>& discount)
      : t_(t), discount_(discount), factor_(t.size(), 1.0f), class_(t.size(), kNone), parent_(t.size()) {
    for (std::size_t i = 0; i < parent_.size(); ++i) parent_[i] = std::uint32_t(i);
    view_.factor = factor_;  // floor 1: no road yet
  }
  const ArcDiscount* discount() const { return view_.floor < 1 ? &view_ : nullptr; }
  bool on_road(std::uint32_t cell) const { return class_[cell] != kNone; }
  bool joined(std::uint32_t a, std::uint32_t b) { return find(a) == find(b); }
  /// Share of the chain's length (m) on cells already carrying a road at both ends of a step.
  double shared_share(const CellChain& chain) const {
    double shared = 0, total = 0;
    for (std::size_t i = 0; i < chain.structures.size(); ++i) {
      const double l = t_.length_m(point(chain.cells[i]), point(chain.cells[i + 1]));
      total += l;
      if (on_road(chain.cells[i]) && on_road(chain.cells[i + 1])) shared += l;
    }
    return total > 0 ? shared / total : 0;
  }
  /// Adds a road: its surface cells become cheaper for the next roads; all its cells are joined.
  void add(const CellChain& chain, RoadClass c) {
    for (std::size_t i = 0; i < chain.structures.size(); ++i) {
      unite(chain.cells[i], chain.cells[i + 1]);
      if (chain.structures[i] != Structure::road || c == RoadClass::maritime) continue;
      for (std::uint32_t cell : {chain.cells[i], chain.cells[i + 1]}) {
        if (class_[cell] <= std::uint8_t(c)) continue;
        class_[cell] = std::uint8_t(c);
        factor_[cell] = float(1.0 - discount_[std::size_t(c)]);
        view_.floor = std::min(view_.floor, double(factor_[cell]));  // the smallest factor on the grid
      }
    }
  }

 private:
  static constexpr std::uint8_t kNone = 0xff;
  GridPoint point(std::uint32_t cell) const { return {double(cell % std::uint32_t(t_.cols())), double(cell / std::uint32_t(t_.cols()))}; }
  std::uint32_t find(std::uint32_t x) {
    while (parent_[x] != x) x = parent_[x] = parent_[parent_[x]];
    return x;
  }
  void unite(std::uint32_t a, std::uint32_t b) {
    a = find(a), b = find(b);
    if (a != b) parent_[std::max(a, b)] = std::min(a, b);
  }
  const TerrainField& t_;
  std::array<double, 4> discount_;
  std::vector<float> factor_;
  std::vector<std::uint8_t> class_;
  std::vector<std::uint32_t> parent_;
  ArcDiscount view_;
};

}  // namespace

CostModel class_model(CostModel model, double max_grade_pct, double min_radius_m) {
  const double deg = std::atan(max_grade_pct / 100) * 180 / std::numbers::pi;
  for (StructureCosts* s : {&model.road, &model.bridge, &model.tunnel}) s->slope_deg.threshold = std::min(s->slope_deg.threshold, deg);
  model.min_curve_radius_m = min_radius_m;
  return model;
}

NetworkResult route_network(const TerrainField& t, const RoadGraph& base, const std::vector<Link>& links, const RoutingOptions& options,
                            Progress& progress) {
  // One graph per road class, under the class's design standards (built when first needed).
  std::array<std::optional<RoadGraph>, 4> graphs;
  auto graph_of = [&](RoadClass c) -> const RoadGraph& {
    const std::size_t k = std::size_t(c);
    if (k >= graphs.size()) return base;
    if (!graphs[k]) graphs[k].emplace(t, class_model(base.model(), options.max_grade_pct[k], options.min_radius_m[k]), base.options());
    return *graphs[k];
  };
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
  // Importance order (Galin et al. 2011): class, then the longer link first (trunks before branches),
  // then the link order.
  std::vector<std::size_t> order(edges.size());
  std::vector<double> span(edges.size());
  for (std::size_t i = 0; i < edges.size(); ++i) {
    order[i] = i;
    span[i] = t.length_m({double(edges[i].a.col), double(edges[i].a.row)}, {double(edges[i].b.col), double(edges[i].b.row)});
  }
  std::stable_sort(order.begin(), order.end(), [&](std::size_t x, std::size_t y) {
    if (links[x].road_class != links[y].road_class) return links[x].road_class < links[y].road_class;
    return span[x] > span[y];
  });
  BuiltRoads built(t, options.reuse_discount);
  std::vector<std::optional<Road>> out(edges.size());
  std::vector<bool> redundant(edges.size(), false);
  ProgressStep step(progress, "roads");
  // One link after the other: each sees every road before it, so the order alone fixes the output
  // (no parallelism across links: any two may share cells). Consecutive links to one end share its
  // target search (the caches hold undiscounted costs, valid whatever the roads built since).
  std::optional<TargetSearch> shared;
  std::size_t shared_end = SIZE_MAX;
  RoadClass shared_class = RoadClass::maritime;
  for (std::size_t k = 0; k < order.size(); ++k) {
    const std::size_t i = order[k];
    const Edge& e = edges[i];
    if (e.a == e.b) continue;
    RoutingOptions o = options;
    o.bezier.seed = splitmix64(options.bezier.seed ^ splitmix64(i));
    const RoadGraph& graph = graph_of(links[i].road_class);
    const auto end = snap_to_land(t, e.b, options.snap_cells);
    if (end && (t.index(end->col, end->row) != shared_end || links[i].road_class != shared_class)) {
      shared.reset();
      shared.emplace(graph, *end);
      shared_end = t.index(end->col, end->row);
      shared_class = links[i].road_class;
    }
    std::optional<Road>& r = out[i];
    r = route_road(t, graph, e.a, e.b, o, nullptr, end ? &*shared : nullptr, built.discount());
    step.update(double(k + 1) / double(edges.size()), std::to_string(k + 1) + " of " + std::to_string(edges.size()) + " roads");
    if (!r) continue;
    r->from = links[i].from;
    r->to = links[i].to;
    r->road_class = r->ferry ? RoadClass::maritime : links[i].road_class;
    if (r->over_budget || r->chain.cells.empty()) continue;
    if (built.shared_share(r->chain) >= options.redundant_share && built.joined(r->chain.cells.front(), r->chain.cells.back())) {
      redundant[i] = true;
      continue;
    }
    built.add(r->chain, r->road_class);
  }
  step.update(1.0);
  NetworkResult result;
  for (std::size_t i = 0; i < edges.size(); ++i) {
    const std::string name = std::to_string(links[i].from) + "-" + std::to_string(links[i].to);
    if (!out[i]) {
      if (!(edges[i].a == edges[i].b)) result.failed.push_back(name);
    } else if (out[i]->over_budget) {
      result.over_budget.push_back(name);
    } else if (redundant[i]) {
      result.redundant.push_back(name);
    } else {
      result.roads.push_back(std::move(*out[i]));
    }
  }
  std::vector<CellChain> chains;
  std::vector<RoadClass> classes;
  for (const Road& r : result.roads) chains.push_back(r.chain), classes.push_back(r.road_class);
  result.layout = network_layout(t, chains, classes);
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

VectorLayer roads_layer(const TerrainField& t, const std::vector<Road>& roads, const RoadNetworkLayout* layout) {
  VectorLayer layer;
  layer.name = "roads";
  layer.geometry = GeometryType::line_string;
  layer.crs = t.georef().crs;
  layer.fields = {{"from", FieldType::integer},      {"to", FieldType::integer},        {"class", FieldType::string},
                  {"router", FieldType::string},     {"length_m", FieldType::real},     {"cost", FieldType::real},
                  {"max_grade_pct", FieldType::real}, {"mean_grade_pct", FieldType::real}, {"bridge_m", FieldType::real},
                  {"tunnel_m", FieldType::real},      {"grade_limit_pct", FieldType::real}, {"over_limit_m", FieldType::real},
                  {"longest_over_limit_m", FieldType::real}, {"water_m", FieldType::real}, {"tight_corners", FieldType::integer}};
  if (layout) layer.fields.push_back({"sections", FieldType::string});
  for (std::size_t i = 0; i < roads.size(); ++i) {
    const Road& r = roads[i];
    Feature f;
    f.parts.push_back(to_crs(t, r.ferry ? r.ferry_line : r.geometry.points));
    std::optional<double> cost;
    if (r.cost) cost = round_to(*r.cost, 0.01);
    f.values = {std::int64_t(r.from), std::int64_t(r.to), std::string(name_of(r.road_class)), r.router, round_to(r.stats.length_m, 0.01), opt(cost),
                round_to(r.stats.max_grade_pct, 0.01), round_to(r.stats.mean_grade_pct, 0.01), round_to(r.stats.bridge_m, 0.01),
                round_to(r.stats.tunnel_m, 0.01)};
    const bool limited = !r.ferry && r.stats.grade_limit_pct < kInfinity;
    f.values.push_back(limited ? FieldValue(round_to(r.stats.grade_limit_pct, 0.01)) : FieldValue(std::monostate{}));
    for (double v : {r.stats.over_limit_m, r.stats.longest_over_limit_m, r.stats.water_m}) f.values.push_back(round_to(v, 0.01));
    f.values.push_back(std::int64_t(r.geometry.tight_corners));
    if (layout) f.values.push_back(id_list(layout->road_sections[i]));
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
