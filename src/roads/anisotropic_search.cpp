// Dijkstra, A* and bidirectional A* on the oriented road graph (Galin et al. 2010).
// SPDX-License-Identifier: MIT
#include "roads/anisotropic_search.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>

#include "core/error.hpp"

namespace terrapolis::roads {
namespace {

constexpr double kDeg = 180.0 / std::numbers::pi;

std::uint64_t splitmix64(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

int sector_of(double angle_rad, int m) {
  const double w = 2 * std::numbers::pi / m;
  return int(std::floor(angle_rad / w + 0.5)) % m;
}

}  // namespace

RoadGraph::RoadGraph(const TerrainField& terrain, const CostModel& model, const GraphOptions& options)
    : terrain_(terrain), model_(model), options_(options) {
  if (options.angles < 1 || options.angles > 64) throw bad_input("--angles: must be in 1..64, got " + std::to_string(options.angles));
  const int m = options.angles;
  for (int s = 0; s < 3; ++s) salt_[s] = splitmix64(options.seed * 3 + std::uint64_t(s));
  // The road slope cost as a table over the grade (no atan per sample): 4096 steps up to the
  // threshold's grade; the threshold itself is tested exactly on the grade.
  {
    const double thr = model.road.slope_deg.threshold;
    tan_slope_max_ = thr < 90 ? std::tan(thr / kDeg) : kInfinity;
    const double gmax = thr < 90 ? tan_slope_max_ : std::tan(80 / kDeg);
    lut_step_ = gmax / 4096;
    slope_lut_.resize(4098);
    for (std::size_t i = 0; i < slope_lut_.size(); ++i)
      slope_lut_[i] = model.road.slope_deg(std::min(std::atan(double(i) * lut_step_) * kDeg, thr < 90 ? thr : 90.0));
  }
  step_m_ = model.sample_step_m > 0 ? model.sample_step_m : 0.5 * terrain.min_cell_m();
  cheapest_ = model.cheapest_per_metre();
  // Orientation layers: one block of m sectors per enabled structure, then the "start" orientation.
  int block[3] = {0, -1, -1};
  int blocks = 1;
  if (model.bridge.enabled) block[1] = blocks++;
  if (model.tunnel.enabled) block[2] = blocks++;
  orientations_ = blocks * m + 1;
  for (const MaskArc& a : segment_mask(options.k)) arcs_.push_back({a.dcol, a.drow, Structure::road, block[0] * m + sector_of(a.angle_rad, m), a.angle_rad});
  surface_arcs_ = arcs_.size();
  const double cell = terrain.typical_cell_m();
  for (Structure s : {Structure::bridge, Structure::tunnel}) {
    const StructureCosts& sc = s == Structure::bridge ? model.bridge : model.tunnel;
    if (!sc.enabled) continue;
    const double rmin = sc.min_length_m ? *sc.min_length_m / cell : sc.min_length_cells;
    // Long arcs start beyond the surface mask: shorter crossings are surface arcs.
    const double rmax = sc.max_length_m ? *sc.max_length_m / cell : sc.max_length_cells;
    const auto ring = annulus_mask(std::max(rmin, 1.0), rmax);
    const double keep = ring.empty() ? 0.0 : std::min(1.0, double(sc.samples) / double(ring.size()));
    const std::uint64_t threshold = keep >= 1.0 ? ~std::uint64_t(0) : std::uint64_t(keep * 18446744073709551615.0);
    (s == Structure::bridge ? bridge_keep_ : tunnel_keep_) = threshold;
    if (keep <= 0) continue;
    const int b = block[int(s)];
    for (const MaskArc& a : ring) arcs_.push_back({a.dcol, a.drow, s, b * m + sector_of(a.angle_rad, m), a.angle_rad});
  }
  // Heuristic: per-metre cost against the grade t = tan(slope), the cheapest structure at each
  // grade, sampled every 0.05 deg; its lower convex hull bounds every arc from below (an increasing
  // piecewise-linear function of the slope is concave in the grade, so it lies above its chords).
  {
    std::vector<std::array<double, 2>> pts;
    for (double sdeg = 0; sdeg <= 89.5; sdeg += 0.05) {
      double c = model.road.slope_deg(sdeg) + model.road.water_depth_m.min_value() + model.road.vegetation.min_value();
      if (model.bridge.enabled)
        c = std::min(c, model.bridge.slope_deg(sdeg) + model.bridge.water_depth_m.min_value() + model.bridge.height_m.min_value() +
                                model.bridge.vegetation.min_value());
      if (model.tunnel.enabled)
        c = std::min(c, model.tunnel.slope_deg(sdeg) + model.tunnel.water_depth_m.min_value() + model.tunnel.depth_m.min_value() +
                                model.tunnel.vegetation.min_value());
      if (c == kInfinity) continue;
      pts.push_back({std::tan(sdeg / kDeg), 0.99 * c});
    }
    std::vector<std::array<double, 2>> hull;
    for (const auto& p : pts) {
      while (hull.size() >= 2) {
        const auto& a = hull[hull.size() - 2];
        const auto& b = hull.back();
        if ((b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0]) <= 0) hull.pop_back();
        else break;
      }
      hull.push_back(p);
    }
    kappa_ = kInfinity;
    for (const auto& h : hull) {
      hull_t_.push_back(h[0]);
      hull_c_.push_back(h[1]);
      if (h[0] > 0 && h[1] / h[0] < kappa_) {
        kappa_ = h[1] / h[0];
        best_grade_ = h[0];
      }
    }
    if (kappa_ == kInfinity) kappa_ = 0;
    if (!hull_c_.empty()) cheapest_ = std::min(cheapest_, hull_c_.front());
  }
  // Turn costs: the turn is the angle between the incoming sector and the new arc, less half a
  // sector (the exact incoming direction is only known to within a sector), priced by the stricter
  // of the two structures' curvature functions. m = 1 makes every turn free.
  const StructureCosts* costs[3] = {&model.road, &model.bridge, &model.tunnel};
  turn_.assign(std::size_t(orientations_) * arcs_.size(), 0.0);
  into_.assign(std::size_t(orientations_), {});
  for (std::size_t a = 0; a < arcs_.size(); ++a) into_[std::size_t(arcs_[a].orientation)].push_back(int(a));
  for (int o = 0; o + 1 < orientations_; ++o) {
    const int blk = o / m, sector = o % m;
    Structure in = Structure::road;
    for (int s = 0; s < 3; ++s)
      if (block[s] == blk) in = Structure(s);
    const double centre = sector * 2 * std::numbers::pi / m;
    for (std::size_t a = 0; a < arcs_.size(); ++a) {
      double d = std::fabs(arcs_[a].angle_rad - centre);
      if (d > std::numbers::pi) d = 2 * std::numbers::pi - d;
      const double turn = std::max(0.0, d - std::numbers::pi / m) * kDeg;
      turn_[std::size_t(o) * arcs_.size() + a] =
          std::max(costs[int(in)]->curvature_deg(turn), costs[int(arcs_[a].structure)]->curvature_deg(turn));
    }
  }
}

double RoadGraph::road_slope_cost(double grade) const {
  if (grade > tan_slope_max_) return kInfinity;
  const double x = grade / lut_step_;
  const std::size_t i = std::size_t(x);
  if (i + 1 >= slope_lut_.size()) return model_.road.slope_deg(std::atan(grade) * kDeg);
  const double f = x - double(i);
  return slope_lut_[i] + f * (slope_lut_[i + 1] - slope_lut_[i]);
}

double RoadGraph::surface_cost_per_m(double slope_deg, double depth_m) const {
  return model_.road.slope_deg(slope_deg) + model_.road.water_depth_m(depth_m);
}

bool RoadGraph::arc_sampled(Cell from, int arc) const {
  const Arc& a = arcs_[std::size_t(arc)];
  if (a.structure == Structure::road) return true;
  const std::uint64_t p = terrain_.index(from.col, from.row), q = terrain_.index(from.col + a.dcol, from.row + a.drow);
  const std::uint64_t lo = std::min(p, q), hi = std::max(p, q);
  const std::uint64_t h = splitmix64(salt_[int(a.structure)] ^ (lo * 0x100000001b3ULL + hi));
  return h <= (a.structure == Structure::bridge ? bridge_keep_ : tunnel_keep_);
}

double RoadGraph::arc_cost(Cell from, int arc) const {
  const Arc& a = arcs_[std::size_t(arc)];
  const int c1 = from.col + a.dcol, r1 = from.row + a.drow;
  if (!terrain_.inside(c1, r1)) return kInfinity;
  const GridPoint p0{double(from.col), double(from.row)}, p1{double(c1), double(r1)};
  const double length = terrain_.length_m(p0, p1);
  const int n = std::max(1, int(std::ceil(length / step_m_)));
  const double dl = length / n;
  const double dc = double(a.dcol) / n, dr = double(a.drow) / n;
  double total = 0;
  if (a.structure == Structure::road) {
    const StructureCosts& sc = model_.road;
    const bool veg = terrain_.has_vegetation();
    const double veg0 = veg ? 0.0 : sc.vegetation(0.0);  // without a layer the density is 0 everywhere
    const double water0 = sc.water_depth_m(0.0);
    double z0 = terrain_.surface(from.col, from.row);
    for (int i = 1; i <= n; ++i) {
      const double z1 = i == n ? terrain_.surface(c1, r1) : terrain_.surface_at(from.col + dc * i, from.row + dr * i);
      const double depth = terrain_.depth_at(from.col + dc * (i - 0.5), from.row + dr * (i - 0.5));
      double c = road_slope_cost(std::fabs(z1 - z0) / dl) + veg0 + (depth > 0 ? sc.water_depth_m(depth) : water0);
      if (veg) c += sc.vegetation(terrain_.vegetation_at(from.col + dc * (i - 0.5), from.row + dr * (i - 0.5)));
      c += terrain_.extra_cost_at(Structure::road, from.col + dc * (i - 0.5), from.row + dr * (i - 0.5));  // cost layers (plugins)
      if (c == kInfinity) return kInfinity;
      total += c * dl;
      z0 = z1;
    }
    return total;
  }
  // Bridges and tunnels join two land cells by a straight deck between their surfaces.
  if (terrain_.water(from.col, from.row) || terrain_.water(c1, r1)) return kInfinity;
  const bool bridge = a.structure == Structure::bridge;
  const StructureCosts& sc = bridge ? model_.bridge : model_.tunnel;
  const double za = terrain_.surface(from.col, from.row), zb = terrain_.surface(c1, r1);
  const double per_m_slope = sc.slope_deg(std::atan(std::fabs(zb - za) / length) * kDeg);
  if (per_m_slope == kInfinity) return kInfinity;
  for (int i = 0; i < n; ++i) {
    const double t = (i + 0.5) / n;
    const double col = from.col + dc * (i + 0.5), row = from.row + dr * (i + 0.5);
    const double deck = za + t * (zb - za);
    const double depth = terrain_.depth_at(col, row);
    double c;
    if (bridge) {
      const double h = deck - terrain_.surface_at(col, row);
      if (h < 0) return kInfinity;  // the deck would cut the ground
      c = sc.height_m(h) + sc.water_depth_m(depth);
      c += sc.vegetation(terrain_.vegetation_at(col, row));
    } else {
      const double d = terrain_.ground_at(col, row) - deck;
      if (d < 0) return kInfinity;  // the tube would leave the ground (or the sea floor)
      c = sc.depth_m(d) + sc.water_depth_m(depth);
      c += sc.vegetation(terrain_.vegetation_at(col, row));
    }
    c += terrain_.extra_cost_at(a.structure, col, row);  // cost layers (plugins)
    if (c == kInfinity) return kInfinity;
    total += (c + per_m_slope) * dl;
  }
  return total;
}

double RoadGraph::lower_bound(Cell a, Cell b) const {
  // Any path between the two rows is at least |dcol| x the narrowest of their cell widths wide and
  // |drow| x the shortest cell height (cell widths shrink monotonically polewards); 0.995 absorbs
  // the small variation of cell heights with latitude.
  const double w = std::min(terrain_.metres_x(a.row), terrain_.metres_x(b.row));
  const double h = std::min(terrain_.metres_y(a.row), terrain_.metres_y(b.row));
  const double d = 0.995 * std::hypot((b.col - a.col) * w, (b.row - a.row) * h);
  const double z = std::fabs(double(terrain_.surface(b.col, b.row)) - double(terrain_.surface(a.col, a.row)));
  if (hull_t_.size() < 2 || kappa_ <= 0) return cheapest_ * d;
  if (d <= 0 || z >= best_grade_ * d) return std::max(cheapest_ * d, kappa_ * z);
  const double t = z / d;  // below the best grade: cover D at grade t along the envelope
  const auto it = std::upper_bound(hull_t_.begin(), hull_t_.end(), t);
  const std::size_t j = std::size_t(std::clamp<std::ptrdiff_t>(it - hull_t_.begin(), 1, std::ptrdiff_t(hull_t_.size()) - 1));
  const double f = (t - hull_t_[j - 1]) / (hull_t_[j] - hull_t_[j - 1]);
  return d * (hull_c_[j - 1] + f * (hull_c_[j] - hull_c_[j - 1]));
}

namespace {

struct Node {
  double g;
  std::uint32_t parent;  ///< forward: predecessor; backward: successor towards the goal
  std::int32_t arc;      ///< arc joining the node and its parent
};

struct QueueItem {
  double f;
  std::uint64_t key;
  std::uint32_t node;
  double g;
  bool operator<(const QueueItem& o) const { return f != o.f ? f > o.f : key > o.key; }  // min-heap, ties by key
};

/// One direction of the search: its nodes and its queue. Nodes are stored per cell: a dense array
/// of 4 bytes per grid cell points to the cell's block of `orientations` nodes, allocated on first
/// touch, so a lookup is two array reads and memory follows the explored cells (a 3601 x 3601 SRTM
/// tile needs 52 MB for the cell array; a node is 16 bytes).
struct Frontier {
  static constexpr std::uint32_t kNone = 0xffffffffu;
  Frontier(std::size_t cells, std::uint64_t orientations) : orientations(orientations), block(cells, kNone) {}
  std::uint64_t orientations;
  std::vector<std::uint32_t> block;       ///< per grid cell: its block, or kNone
  std::vector<std::uint32_t> block_cell;  ///< per block: its cell
  std::vector<Node> nodes;                ///< block * orientations + orientation
  std::size_t stored = 0;
  std::vector<QueueItem> heap;
  double top() const { return heap.empty() ? kInfinity : heap.front().f; }
  void push(const QueueItem& q) {
    heap.push_back(q);
    std::push_heap(heap.begin(), heap.end());
  }
  QueueItem pop() {
    std::pop_heap(heap.begin(), heap.end());
    QueueItem q = heap.back();
    heap.pop_back();
    return q;
  }
  std::uint64_t key(std::uint32_t idx) const {
    return std::uint64_t(block_cell[idx / orientations]) * orientations + idx % orientations;
  }
  /// Index of the node of `key`, or kNone when it was never reached.
  std::uint32_t find(std::uint64_t k) const {
    const std::uint32_t b = block[std::size_t(k / orientations)];
    if (b == kNone) return kNone;
    const std::uint32_t idx = std::uint32_t(std::uint64_t(b) * orientations + k % orientations);
    return nodes[idx].g == kInfinity ? kNone : idx;
  }
  /// Relaxes `key` to cost g through `parent`/`arc`; returns the node index.
  std::uint32_t relax(std::uint64_t k, double g, std::uint32_t parent, int arc, bool& improved) {
    std::uint32_t& b = block[std::size_t(k / orientations)];
    if (b == kNone) {
      b = std::uint32_t(block_cell.size());
      block_cell.push_back(std::uint32_t(k / orientations));
      nodes.resize(nodes.size() + orientations, Node{kInfinity, kNone, -1});
    }
    const std::uint32_t idx = std::uint32_t(std::uint64_t(b) * orientations + k % orientations);
    Node& n = nodes[idx];
    improved = g < n.g;
    if (improved) {
      if (n.g == kInfinity) ++stored;
      n = {g, parent, arc};
    }
    return idx;
  }
};

/// Surface arc costs of the cells met so far: a node is expanded once per orientation but its
/// arcs cost the same from every orientation, so they are computed once (lazily, NaN = not yet).
class ArcCache {
 public:
  ArcCache(const RoadGraph& graph) : graph_(graph), n_(graph.surface_arcs()), slot_(graph.terrain().cols() * std::size_t(graph.terrain().rows()), kNone) {}
  /// The cached costs of a cell's surface arcs (NaN = not computed yet); valid until the next call.
  float* row(std::size_t cell_index) {
    std::uint32_t& s = slot_[cell_index];
    if (s == kNone) {
      s = std::uint32_t(costs_.size() / n_);
      costs_.resize(costs_.size() + n_, std::numeric_limits<float>::quiet_NaN());
    }
    return costs_.data() + std::size_t(s) * n_;
  }
  double get(Cell c, float* row, int arc) {
    if (std::size_t(arc) >= n_) return graph_.arc_cost(c, arc);
    float& v = row[arc];
    if (std::isnan(v)) v = float(graph_.arc_cost(c, arc));
    return v;
  }
  double get(Cell c, std::size_t cell_index, int arc) {
    if (std::size_t(arc) >= n_) return graph_.arc_cost(c, arc);
    return get(c, row(cell_index), arc);
  }
  std::size_t cells() const { return costs_.size() / std::max<std::size_t>(1, n_); }

 private:
  static constexpr std::uint32_t kNone = 0xffffffffu;
  const RoadGraph& graph_;
  std::size_t n_;
  std::vector<std::uint32_t> slot_;
  std::vector<float> costs_;
};

}  // namespace

SearchResult shortest_path(const RoadGraph& graph, Cell from, Cell to, SearchMethod method, std::size_t max_nodes,
                           Progress* progress) {
  const TerrainField& t = graph.terrain();
  if (!t.inside(from.col, from.row) || !t.inside(to.col, to.row)) throw bad_input("path: an end point lies outside the DEM");
  SearchResult result;
  const std::uint64_t O = std::uint64_t(graph.orientations());
  auto key_of = [&](Cell c, int o) { return std::uint64_t(t.index(c.col, c.row)) * O + std::uint64_t(o); };
  auto cell_of = [&](std::uint64_t key) {
    const std::uint64_t i = key / O;
    return Cell{int(i % std::uint64_t(t.cols())), int(i / std::uint64_t(t.cols()))};
  };
  auto orient_of = [&](std::uint64_t key) { return int(key % O); };
  const bool use_h = method != SearchMethod::dijkstra;
  const std::size_t goal_index = t.index(to.col, to.row);
  if (from == to) {
    result.found = true;
    result.cost = 0;
    result.cells = {from};
    return result;
  }
  std::optional<ProgressStep> step;
  if (progress) step.emplace(*progress, "route");
  const double h0 = graph.lower_bound(from, to);
  double best_h = h0;
  auto report = [&](double h) {
    if (!step || h0 <= 0) return;
    best_h = std::min(best_h, h);
    if ((result.expanded & 4095) == 0) step->update(std::clamp(1.0 - best_h / h0, 0.0, 1.0));
  };
  const std::vector<RoadGraph::Arc>& arcs = graph.arcs();
  const int na = int(arcs.size());

  Frontier fw(t.size(), O), bw(method == SearchMethod::bidirectional ? t.size() : 0, O);
  ArcCache cache(graph);
  auto check_memory = [&]() {
    if (fw.nodes.size() + bw.nodes.size() + cache.cells() * graph.surface_arcs() / 4 > max_nodes)
      throw processing_error("path: the search stored more than " + std::to_string(max_nodes) +
                             " nodes; use a smaller --k or --angles, or closer end points");
  };
  {
    bool imp;
    const std::uint32_t s = fw.relax(key_of(from, graph.start_orientation()), 0.0, Frontier::kNone, -1, imp);
    fw.push({use_h ? h0 : 0.0, fw.key(s), s, 0.0});
  }

  if (method != SearchMethod::bidirectional) {
    std::uint32_t goal_node = Frontier::kNone;
    while (!fw.heap.empty()) {
      const QueueItem q = fw.pop();
      if (q.g > fw.nodes[q.node].g) continue;  // stale entry
      const std::uint64_t key = q.key;
      const Cell c = cell_of(key);
      if (t.index(c.col, c.row) == goal_index) {
        goal_node = q.node;
        break;
      }
      ++result.expanded;
      report(graph.lower_bound(c, to));
      const int o = orient_of(key);
      float* costs = cache.row(t.index(c.col, c.row));
      for (int a = 0; a < na; ++a) {
        const RoadGraph::Arc& arc = arcs[std::size_t(a)];
        if (!t.inside(c.col + arc.dcol, c.row + arc.drow) || !graph.arc_sampled(c, a)) continue;
        const double turn = graph.turn_cost(o, a);
        if (turn == kInfinity) continue;
        const double e = cache.get(c, costs, a);
        if (e == kInfinity) continue;
        const Cell n{c.col + arc.dcol, c.row + arc.drow};
        const double g = q.g + turn + e;
        bool improved;
        const std::uint32_t idx = fw.relax(key_of(n, arc.orientation), g, q.node, a, improved);
        if (improved) fw.push({g + (use_h ? graph.lower_bound(n, to) : 0.0), fw.key(idx), idx, g});
      }
      check_memory();
    }
    result.nodes = fw.stored;
    if (goal_node == Frontier::kNone) return result;
    result.found = true;
    result.cost = fw.nodes[goal_node].g;
    for (std::uint32_t n = goal_node; n != Frontier::kNone; n = fw.nodes[n].parent) {
      result.cells.push_back(cell_of(fw.key(n)));
      if (fw.nodes[n].arc >= 0) result.structures.push_back(arcs[std::size_t(fw.nodes[n].arc)].structure);
    }
    std::reverse(result.cells.begin(), result.cells.end());
    std::reverse(result.structures.begin(), result.structures.end());
    return result;
  }

  // Bidirectional A*: the backward search runs on reversed arcs from every orientation at the goal.
  // It stops when the best meeting cost mu <= max(top_f, top_b) (Pohl 1971): any cheaper path would
  // cross both open lists below mu.
  for (int o = 0; o < graph.start_orientation(); ++o) {
    bool imp;
    const std::uint32_t s = bw.relax(key_of(to, o), 0.0, Frontier::kNone, -1, imp);
    bw.push({use_h ? h0 : 0.0, bw.key(s), s, 0.0});
  }
  double mu = kInfinity;
  std::uint64_t meet = 0;
  auto try_meet = [&](std::uint64_t key, double g, const Frontier& other) {
    const std::uint32_t j = other.find(key);
    if (j == Frontier::kNone) return;
    const double total = g + other.nodes[j].g;
    if (total < mu || (total == mu && key < meet)) {
      mu = total;
      meet = key;
    }
  };
  while (!fw.heap.empty() || !bw.heap.empty()) {
    if (mu <= std::max(fw.top(), bw.top())) break;
    const bool forward = !fw.heap.empty() && (bw.heap.empty() || fw.heap.size() <= bw.heap.size());
    Frontier& me = forward ? fw : bw;
    Frontier& other = forward ? bw : fw;
    const QueueItem q = me.pop();
    if (q.g > me.nodes[q.node].g) continue;
    ++result.expanded;
    const Cell c = cell_of(q.key);
    const int o = orient_of(q.key);
    report(forward ? graph.lower_bound(c, to) : graph.lower_bound(c, from));
    if (forward) {
      float* costs = cache.row(t.index(c.col, c.row));
      for (int a = 0; a < na; ++a) {
        const RoadGraph::Arc& arc = arcs[std::size_t(a)];
        if (!t.inside(c.col + arc.dcol, c.row + arc.drow) || !graph.arc_sampled(c, a)) continue;
        const double turn = graph.turn_cost(o, a);
        if (turn == kInfinity) continue;
        const double e = cache.get(c, costs, a);
        if (e == kInfinity) continue;
        const Cell n{c.col + arc.dcol, c.row + arc.drow};
        const double g = q.g + turn + e;
        bool improved;
        const std::uint32_t idx = me.relax(key_of(n, arc.orientation), g, q.node, a, improved);
        if (improved) {
          me.push({g + (use_h ? graph.lower_bound(n, to) : 0.0), me.key(idx), idx, g});
          try_meet(me.key(idx), g, other);
        }
      }
    } else {
      // Node (c, o) was reached by an arc of orientation o: its predecessors are c - arc, with
      // any orientation (the start orientation only at the start cell).
      for (int a : graph.arcs_into(o)) {
        const RoadGraph::Arc& arc = arcs[std::size_t(a)];
        const Cell p{c.col - arc.dcol, c.row - arc.drow};
        if (!t.inside(p.col, p.row) || !graph.arc_sampled(p, a)) continue;
        const double e = cache.get(p, t.index(p.col, p.row), a);
        if (e == kInfinity) continue;
        const double hp = use_h ? graph.lower_bound(p, from) : 0.0;
        for (int po = 0; po < graph.orientations(); ++po) {
          if (po == graph.start_orientation() && !(p == from)) continue;
          const double turn = graph.turn_cost(po, a);
          if (turn == kInfinity) continue;
          const double g = q.g + turn + e;
          bool improved;
          const std::uint32_t idx = me.relax(key_of(p, po), g, q.node, a, improved);
          if (improved) {
            me.push({g + hp, me.key(idx), idx, g});
            try_meet(me.key(idx), g, other);
          }
        }
      }
    }
    check_memory();
  }
  result.nodes = fw.stored + bw.stored;
  if (mu == kInfinity) return result;
  result.found = true;
  result.cost = mu;
  for (std::uint32_t n = fw.find(meet); n != Frontier::kNone; n = fw.nodes[n].parent) {
    result.cells.push_back(cell_of(fw.key(n)));
    if (fw.nodes[n].arc >= 0) result.structures.push_back(arcs[std::size_t(fw.nodes[n].arc)].structure);
  }
  std::reverse(result.cells.begin(), result.cells.end());
  std::reverse(result.structures.begin(), result.structures.end());
  for (std::uint32_t n = bw.find(meet); n != Frontier::kNone && bw.nodes[n].parent != Frontier::kNone; n = bw.nodes[n].parent) {
    const Node& nd = bw.nodes[n];
    result.cells.push_back(cell_of(bw.key(nd.parent)));
    result.structures.push_back(arcs[std::size_t(nd.arc)].structure);
  }
  return result;
}

double chain_cost(const RoadGraph& graph, const std::vector<Cell>& cells) {
  const auto& arcs = graph.arcs();
  double total = 0;
  int o = graph.start_orientation();
  for (std::size_t i = 1; i < cells.size(); ++i) {
    const int dc = cells[i].col - cells[i - 1].col, dr = cells[i].row - cells[i - 1].row;
    int arc = -1;
    for (std::size_t a = 0; a < graph.surface_arcs(); ++a)
      if (arcs[a].dcol == dc && arcs[a].drow == dr) arc = int(a);
    if (arc < 0) return kInfinity;
    total += graph.turn_cost(o, arc) + graph.arc_cost(cells[i - 1], arc);
    o = arcs[std::size_t(arc)].orientation;
  }
  return total;
}

}  // namespace terrapolis::roads
