// Single roads, the network routed by importance (reuse, redundancy; links routed ahead in parallel), maritime links and the output layers.
// SPDX-License-Identifier: MIT
#include "roads/road_network.hpp"

#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <exception>
#include <map>
#include <numbers>

#include "core/error.hpp"
#include "core/random.hpp"
#include "roads/windowed_route.hpp"

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
  const std::optional<Cell> c = cell_at(terrain.georef(), terrain.grid_cols(), terrain.grid_rows(), x, y);
  if (c && !terrain.inside(c->col, c->row)) return std::nullopt;
  return c;
}

std::optional<Cell> cell_at(const Georef& georef, int cols, int rows, double x, double y) {
  // Inverse of the affine geotransform (no CRS operation needed).
  const auto& g = georef.transform;
  const double det = g[1] * g[5] - g[2] * g[4];
  if (det == 0 || !std::isfinite(x) || !std::isfinite(y)) return std::nullopt;
  const double dx = x - g[0], dy = y - g[3];
  const double col = (g[5] * dx - g[2] * dy) / det, row = (-g[4] * dx + g[1] * dy) / det;
  if (!std::isfinite(col) || !std::isfinite(row)) return std::nullopt;
  if (!(col >= 0 && row >= 0 && col < cols && row < rows)) return std::nullopt;
  return Cell{int(std::floor(col)), int(std::floor(row))};
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

/// What the network keeps per grid cell: the cost factor of the roads on it, the most important
/// class among them, and its parent in the union-find of the cells the roads join. Dense arrays
/// when the terrain holds the whole grid; else one ordered map of the road cells (roads by windows:
/// the grid may be far larger than memory, the roads are not), whose cells in a box are found row
/// by row, a range of grid indices each.
class RoadCellTable {
 public:
  static constexpr std::uint8_t kNone = 0xff;
  static constexpr std::uint32_t kRoot = 0xffffffffu;  ///< a cell that is its own parent
  struct Entry {
    float factor = 1;
    std::uint8_t road_class = kNone;
    std::uint32_t parent = kRoot;
  };
  RoadCellTable(std::size_t cells, bool dense) : dense_(dense) {
    if (dense) factor_.assign(cells, 1.0f), class_.assign(cells, kNone), parent_.assign(cells, kRoot);
  }
  Entry get(std::uint32_t cell) const {
    if (dense_) return {factor_[cell], class_[cell], parent_[cell]};
    const auto it = map_.find(cell);
    return it == map_.end() ? Entry{} : it->second;
  }
  void set_class(std::uint32_t cell, std::uint8_t c, float factor) {
    if (dense_) {
      class_[cell] = c, factor_[cell] = factor;
    } else {
      Entry& e = map_[cell];
      e.road_class = c, e.factor = factor;
    }
  }
  void set_parent(std::uint32_t cell, std::uint32_t p) { dense_ ? void(parent_[cell] = p) : void(map_[cell].parent = p); }
  /// The dense factors (empty when sparse), for ArcDiscount on the whole grid.
  const std::vector<float>& dense_factors() const { return factor_; }
  /// Calls f(col, row, factor) for each road cell of the box [c0, c1] x [r0, r1] of a grid `cols`
  /// wide whose factor is below 1 (sparse only).
  template <class F>
  void for_each_factor_in(int c0, int r0, int c1, int r1, int cols, F f) const {
    for (int r = r0; r <= r1; ++r) {
      const std::uint32_t row = std::uint32_t(r) * std::uint32_t(cols);
      for (auto it = map_.lower_bound(row + std::uint32_t(c0)); it != map_.end() && it->first <= row + std::uint32_t(c1); ++it)
        if (it->second.factor < 1) f(int(it->first - row), r, it->second.factor);
    }
  }

 private:
  bool dense_;
  std::vector<float> factor_;
  std::vector<std::uint8_t> class_;
  std::vector<std::uint32_t> parent_;
  std::map<std::uint32_t, Entry> map_;
};

/// The roads built so far, as the next searches see them: per cell the most important class on it
/// and the cost factor it gives (ArcDiscount), and which cells the network joins (union-find).
/// Cells are the grid's indices (the terrain's; a frame's for roads by windows).
class BuiltRoads {
 public:
  BuiltRoads(const TerrainField& t, const std::array<double, 4>& discount)
      : t_(t), discount_(discount), cells_(t.size(), t.holds_values()) {
    view_.factor = cells_.dense_factors();  // floor 1: no road yet
  }
  const ArcDiscount* discount() const { return view_.floor < 1 ? &view_ : nullptr; }
  double floor() const { return view_.floor; }
  /// The factors over a window's cells (its indices) into `out`, for a search by windows.
  void factors_over(const TerrainField& window, std::vector<float>& out) const {
    out.assign(window.size(), 1.0f);
    cells_.for_each_factor_in(window.col0(), window.row0(), window.col0() + window.cols() - 1, window.row0() + window.rows() - 1, t_.cols(),
                              [&](int col, int row, float f) {
                                if (window.inside(col, row)) out[window.index(col, row)] = f;
                              });
  }
  /// The factors over the grid's cells [c0, c1] x [r0, r1] into `out` (row-major), for the reach bound.
  void factors_over(int c0, int r0, int c1, int r1, std::vector<float>& out) const {
    const std::size_t cols = std::size_t(c1 - c0 + 1);
    out.assign(cols * std::size_t(r1 - r0 + 1), 1.0f);
    cells_.for_each_factor_in(c0, r0, c1, r1, t_.cols(),
                              [&](int col, int row, float f) { out[std::size_t(row - r0) * cols + std::size_t(col - c0)] = f; });
  }
  /// The cells whose factor changed, in the order the roads were added (a search routed when the
  /// log held n cells saw every change before n).
  const std::vector<std::uint32_t>& changes() const { return changes_; }
  bool on_road(std::uint32_t cell) const { return cells_.get(cell).road_class != RoadCellTable::kNone; }
  bool joined(std::uint32_t a, std::uint32_t b) { return find(a) == find(b); }
  /// Share of the chain's length (m) on cells already carrying a road at both ends of a step, or
  /// on the given roads (on_existing).
  double shared_share(const CellChain& chain) const {
    return share_on(chain, [&](std::uint32_t a, std::uint32_t b) { return (on_road(a) && on_road(b)) || on_existing(t_, existing_, a, b); });
  }
  /// The same on the given roads only (roads.existing).
  double existing_share(const CellChain& chain) const {
    return existing_.empty() ? 0 : share_on(chain, [&](std::uint32_t a, std::uint32_t b) { return on_existing(t_, existing_, a, b); });
  }
  /// Adds the given roads (roads.existing) before the first link: as roads built, in their order
  /// (the same state at any thread count), and marked.
  void add_existing(const ExistingRoads& given) {
    for (std::size_t k = 0; k < given.chains.size(); ++k) add(given.chains[k], given.classes[k]);
    existing_ = GivenCells(given.chains);
  }
  const GivenCells& existing() const { return existing_; }
  /// Adds a road: its surface cells become cheaper for the next roads; all its cells are joined.
  void add(const CellChain& chain, RoadClass c) {
    for (std::size_t i = 0; i < chain.structures.size(); ++i) {
      unite(chain.cells[i], chain.cells[i + 1]);
      if (chain.structures[i] != Structure::road || c == RoadClass::maritime) continue;
      for (std::uint32_t cell : {chain.cells[i], chain.cells[i + 1]}) {
        const RoadCellTable::Entry e = cells_.get(cell);
        if (e.road_class <= std::uint8_t(c)) continue;
        const float f = float(1.0 - discount_[std::size_t(c)]);
        if (f != e.factor) changes_.push_back(cell);
        cells_.set_class(cell, std::uint8_t(c), f);
        view_.floor = std::min(view_.floor, double(f));  // the smallest factor on the grid
      }
    }
  }

 private:
  template <class On>
  double share_on(const CellChain& chain, On on) const {
    double shared = 0, total = 0;
    for (std::size_t i = 0; i < chain.structures.size(); ++i) {
      const double l = t_.length_m(point(chain.cells[i]), point(chain.cells[i + 1]));
      total += l;
      if (on(chain.cells[i], chain.cells[i + 1])) shared += l;
    }
    return total > 0 ? shared / total : 0;
  }
  GridPoint point(std::uint32_t cell) const { return {double(t_.col_of(cell)), double(t_.row_of(cell))}; }
  std::uint32_t parent(std::uint32_t x) const {
    const std::uint32_t p = cells_.get(x).parent;
    return p == RoadCellTable::kRoot ? x : p;
  }
  std::uint32_t find(std::uint32_t x) {
    while (parent(x) != x) {
      const std::uint32_t up = parent(parent(x));
      cells_.set_parent(x, up);
      x = up;
    }
    return x;
  }
  void unite(std::uint32_t a, std::uint32_t b) {
    a = find(a), b = find(b);
    if (a != b) cells_.set_parent(std::max(a, b), std::min(a, b));
  }
  const TerrainField& t_;
  std::array<double, 4> discount_;
  RoadCellTable cells_;
  std::vector<std::uint32_t> changes_;
  GivenCells existing_;  ///< cells of the given roads (empty: none)
  ArcDiscount view_;
};

}  // namespace

std::size_t links_at_once(const RoutingOptions& options) {
  return options.lookahead > 0 ? options.lookahead
                               : std::max<std::size_t>(1, tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism));
}

CostModel class_model(CostModel model, double max_grade_pct, double min_radius_m) {
  const double deg = std::atan(max_grade_pct / 100) * 180 / std::numbers::pi;
  for (StructureCosts* s : {&model.road, &model.bridge, &model.tunnel}) s->slope_deg.threshold = std::min(s->slope_deg.threshold, deg);
  model.min_curve_radius_m = min_radius_m;
  return model;
}

namespace {

/// One routing of a link and what it saw of the roads before it: how many factor changes of
/// BuiltRoads' log it was routed after, the floor, and the tiles of the cells whose factors it read.
struct Attempt {
  bool routed = false;
  std::optional<Road> road;
  std::exception_ptr error;  ///< rethrown only if the attempt is the one kept
  std::size_t version = 0;
  double floor = 1;
  std::vector<std::uint8_t> tiles;  ///< over tiles [tile_col0, + tile_cols) x [tile_row0, ...) (a window's, by windows)
  int tile_col0 = 0, tile_row0 = 0;
  std::size_t tile_cols = 0;
  std::vector<float> factor;  ///< by windows: the roads' factors over the last window searched
  ArcDiscount seen;           ///< by windows: the discount that window's search read
  bool limited = false;       ///< by windows: decided on the largest window the limit allows
  bool alone = false;         ///< by windows: searched within the whole limit, not its share

  /// Makes `tiles` cover tiles [c0, c1] x [r0, r1] too, keeping its marks.
  void cover(int c0, int r0, int c1, int r1) {
    if (!tiles.empty()) {
      const int rows = int(tiles.size() / tile_cols);
      if (c0 >= tile_col0 && r0 >= tile_row0 && c1 < tile_col0 + int(tile_cols) && r1 < tile_row0 + rows) return;
      c0 = std::min(c0, tile_col0), r0 = std::min(r0, tile_row0);
      c1 = std::max(c1, tile_col0 + int(tile_cols) - 1), r1 = std::max(r1, tile_row0 + rows - 1);
    }
    const std::size_t cols = std::size_t(c1 - c0 + 1);
    std::vector<std::uint8_t> grown(cols * std::size_t(r1 - r0 + 1), 0);
    for (std::size_t k = 0; k < tiles.size(); ++k)
      if (tiles[k]) grown[std::size_t(tile_row0 + int(k / tile_cols) - r0) * cols + std::size_t(tile_col0 + int(k % tile_cols) - c0)] = 1;
    tiles = std::move(grown), tile_col0 = c0, tile_row0 = r0, tile_cols = cols;
  }
};

/// The links routed in importance order, each on the roads of every link before it (the
/// sequential definition), the next links routed ahead, in parallel, on the roads built so far; an
/// attempt is kept only if no road added since changed a factor it read (nor the floor): its
/// search would then have run exactly the same, so the roads are those of routing one link after
/// the other, whatever the threads or the look-ahead (docs/roads.md, "How routing is scheduled").
class NetworkRouter {
 public:
  NetworkRouter(const TerrainField& t, const RoadGraph& base, const std::vector<Link>& links, const RoutingOptions& options,
                Progress& progress, const ExistingRoads* existing, const NetworkWindows* windows)
      : t_(t), base_(base), links_(links), options_(options), windows_(windows), built_(t, options.reuse_discount),
        tile_cols_((std::size_t(t.cols()) >> kShift) + 1), tile_rows_((std::size_t(t.rows()) >> kShift) + 1),
        at_once_(links_at_once(options)) {
    // One graph per road class, under the class's design standards, built before routing (the
    // searches share them read-only).
    for (const Link& l : links) {
      const std::size_t k = std::size_t(l.road_class);
      if (k < graphs_.size() && !graphs_[k])
        graphs_[k].emplace(t, class_model(base.model(), options.max_grade_pct[k], options.min_radius_m[k]), base.options());
    }
    for (std::size_t i = 0; i < links.size(); ++i) {
      const auto a = cell_at(t, links[i].a[0], links[i].a[1]), b = cell_at(t, links[i].b[0], links[i].b[1]);
      if (!a || !b)
        throw bad_input("network: link " + std::to_string(links[i].from) + "-" + std::to_string(links[i].to) + " has an end outside the DEM");
      edges_.push_back({*a, *b});
    }
    // Importance order (Galin et al. 2011): class, then the longer link first (trunks before branches),
    // then the link order.
    order_.resize(edges_.size());
    std::vector<double> span(edges_.size());
    for (std::size_t i = 0; i < edges_.size(); ++i) {
      order_[i] = i;
      span[i] = t.length_m({double(edges_[i].a.col), double(edges_[i].a.row)}, {double(edges_[i].b.col), double(edges_[i].b.row)});
    }
    std::stable_sort(order_.begin(), order_.end(), [&](std::size_t x, std::size_t y) {
      if (links[x].road_class != links[y].road_class) return links[x].road_class < links[y].road_class;
      return span[x] > span[y];
    });
    out_.resize(edges_.size());
    redundant_.assign(edges_.size(), false);
    limited_.assign(edges_.size(), false);
    for (std::size_t a = 0; a < base.surface_arcs(); ++a)
      reach_ = std::max({reach_, std::abs(base.arcs()[a].dcol), std::abs(base.arcs()[a].drow)});
    attempts_.resize(order_.size());
    if (existing) built_.add_existing(*existing);
    step_.emplace(progress, "roads");
  }

  NetworkResult run() {
    NetworkResult result;
    for (std::size_t head = 0; head < order_.size();) {
      const std::vector<std::size_t> todo = next_batch(head, at_once_);
      result.searches += todo.size();
      tbb::parallel_for(std::size_t(0), todo.size(), [&](std::size_t j) { route(todo[j]); });
      while (head < order_.size() && attempts_[head].routed && still_valid(attempts_[head])) {
        // Limited (or refused) on its share of the limit: again alone, on the same roads.
        if (windows_ && !attempts_[head].alone && (attempts_[head].limited || attempts_[head].error)) {
          route(head, true);
          ++result.searches;
        }
        commit(head++);
      }
    }
    step_->update(1.0);
    for (std::size_t i = 0; i < edges_.size(); ++i) {
      const std::string name = std::to_string(links_[i].from) + "-" + std::to_string(links_[i].to);
      if (limited_[i]) result.limited.push_back(name);
      if (!out_[i]) {
        if (!(edges_[i].a == edges_[i].b)) result.failed.push_back(name);
      } else if (out_[i]->over_budget) {
        result.over_budget.push_back(name);
      } else if (redundant_[i]) {
        result.redundant.push_back(name);
      } else {
        result.roads.push_back(std::move(*out_[i]));
      }
    }
    std::vector<CellChain> chains;
    std::vector<RoadClass> classes;
    for (Road& r : result.roads) {
      r.existing_share = built_.existing_share(r.chain);
      chains.push_back(r.chain), classes.push_back(r.road_class);
    }
    result.existing = built_.existing();
    result.layout = network_layout(t_, chains, classes, result.existing);
    return result;
  }

 private:
  static constexpr int kShift = ArcDiscount::kReadTileShift;
  struct Edge {
    Cell a, b;
  };

  const RoadGraph& graph_of(RoadClass c) const { return std::size_t(c) < graphs_.size() ? *graphs_[std::size_t(c)] : base_; }
  std::uint32_t cell_index(Cell c) const { return std::uint32_t(t_.index(c.col, c.row)); }

  /// The head link (routed on the current roads, so always kept) and up to lookahead - 1 next ones
  /// not yet routed or whose attempt the roads added since made stale, to route at once. A link
  /// sharing an end with an earlier uncommitted link is left for later: that link's road will reach
  /// the end, where the search starts or ends, and make the attempt stale.
  std::vector<std::size_t> next_batch(std::size_t head, std::size_t lookahead) const {
    std::vector<std::size_t> todo{head};
    std::vector<std::uint32_t> ends{cell_index(edges_[order_[head]].a), cell_index(edges_[order_[head]].b)};
    for (std::size_t k = head + 1; k < std::min(order_.size(), head + 4 * lookahead) && todo.size() < lookahead; ++k) {
      const Edge& e = edges_[order_[k]];
      const std::uint32_t a = cell_index(e.a), b = cell_index(e.b);
      const bool after_an_end = std::find(ends.begin(), ends.end(), a) != ends.end() || std::find(ends.begin(), ends.end(), b) != ends.end();
      ends.push_back(a), ends.push_back(b);
      if (!after_an_end && (!attempts_[k].routed || !still_valid(attempts_[k]))) todo.push_back(k);
    }
    return todo;
  }

  bool still_valid(const Attempt& at) const {
    if (at.floor != built_.floor()) return false;
    const auto& changes = built_.changes();
    if (at.tiles.empty()) return at.version == changes.size();  // routed without reuse
    const int tile_rows = int(at.tiles.size() / at.tile_cols);
    for (std::size_t j = at.version; j < changes.size(); ++j) {
      const int col = t_.col_of(changes[j]), row = t_.row_of(changes[j]);
      const int c0 = std::max(at.tile_col0, std::max(0, col - reach_) >> kShift);
      const int c1 = std::min(at.tile_col0 + int(at.tile_cols) - 1, std::min(t_.cols() - 1, col + reach_) >> kShift);
      const int r0 = std::max(at.tile_row0, std::max(0, row - reach_) >> kShift);
      const int r1 = std::min(at.tile_row0 + tile_rows - 1, std::min(t_.rows() - 1, row + reach_) >> kShift);
      for (int r = r0; r <= r1; ++r)
        for (int c = c0; c <= c1; ++c)
          if (at.tiles[std::size_t(r - at.tile_row0) * at.tile_cols + std::size_t(c - at.tile_col0)]) return false;
    }
    return true;
  }

  /// Routes the k-th link in importance order on the roads built so far; by windows within the
  /// share of the limit of the links routed at once, or `alone` within all of it.
  void route(std::size_t k, bool alone = false) {
    Attempt& at = attempts_[k];
    at = Attempt{};
    at.routed = true;
    at.alone = alone || at_once_ == 1;
    at.version = built_.changes().size();
    at.floor = built_.floor();
    const std::size_t i = order_[k];
    if (edges_[i].a == edges_[i].b) return;
    RoutingOptions o = options_;
    o.bezier.seed = splitmix64(options_.bezier.seed ^ splitmix64(i));
    try {
      if (windows_) return route_by_windows(at, i, o);
      std::optional<ArcDiscount> seen;
      if (const ArcDiscount* d = built_.discount()) {
        at.tiles.assign(tile_cols_ * tile_rows_, 0);
        at.tile_cols = tile_cols_;
        seen = *d;
        seen->read_tiles = at.tiles.data();
        seen->read_tile_cols = tile_cols_;
      }
      at.road = route_road(t_, graph_of(links_[i].road_class), edges_[i].a, edges_[i].b, o, nullptr, nullptr, seen ? &*seen : nullptr);
    } catch (...) {
      at.error = std::current_exception();
    }
  }

  /// Link i by windows (roads::route_by_windows): the roads built so far over each window, the
  /// tiles its last search read; the road's cells turned into the grid's indices.
  void route_by_windows(Attempt& at, std::size_t i, RoutingOptions o) {
    const std::size_t share = at.alone ? 1 : at_once_;
    WindowOptions window = windows_->window;
    window.max_cells /= share;  // 0 (no limit) stays 0
    window.give_up_at_limit = !at.alone;  // routed again alone: the share's largest window would be wasted
    if (windows_->max_nodes > 0) o.max_nodes = std::min(o.max_nodes, std::max<std::size_t>(1, windows_->max_nodes / share));
    WindowReuse reuse;
    reuse.over_window = [&](const TerrainField& w) -> const ArcDiscount* {
      const ArcDiscount* d = built_.discount();
      if (!d) return nullptr;
      built_.factors_over(w, at.factor);
      // The tiles every window's search read (which windows are searched depends on the earlier
      // ones' roads and bounds): the earlier marks kept, the window's tiles covered.
      at.cover(w.col0() >> kShift, w.row0() >> kShift, (w.col0() + w.cols() - 1) >> kShift, (w.row0() + w.rows() - 1) >> kShift);
      at.seen = ArcDiscount{at.factor, d->floor, at.tiles.data(), at.tile_cols, at.tile_col0, at.tile_row0};
      return &at.seen;
    };
    reuse.over_box = [&](int c0, int r0, int c1, int r1, std::vector<float>& out) { built_.factors_over(c0, r0, c1, r1, out); };
    reuse.read = [&](int c0, int r0, int c1, int r1, const std::vector<std::uint8_t>& cells) {
      at.cover(c0 >> kShift, r0 >> kShift, c1 >> kShift, r1 >> kShift);
      const std::size_t cols = std::size_t(c1 - c0 + 1);
      for (std::size_t k = 0; k < cells.size(); ++k)
        if (cells[k])
          at.tiles[std::size_t(((r0 + int(k / cols)) >> kShift) - at.tile_row0) * at.tile_cols +
                   std::size_t(((c0 + int(k % cols)) >> kShift) - at.tile_col0)] = 1;
    };
    const RoadGraph& g = graph_of(links_[i].road_class);
    WindowedRoad w = roads::route_by_windows(windows_->grid, windows_->read, g.model(), g.options(), edges_[i].a, edges_[i].b, o,
                                             window, nullptr, &reuse);
    std::vector<float>().swap(at.factor);  // held by the links routed ahead until they are committed
    at.seen = ArcDiscount{};                // it pointed at the factors and at tiles since re-laid
    if (w.road)
      for (std::uint32_t& cell : w.road->chain.cells) cell = std::uint32_t(t_.index(w.terrain->col_of(cell), w.terrain->row_of(cell)));
    at.road = std::move(w.road);
    at.limited = w.limited;
  }

  void commit(std::size_t k) {
    Attempt& at = attempts_[k];
    if (at.error) std::rethrow_exception(at.error);
    const std::size_t i = order_[k];
    std::optional<Road>& r = out_[i];
    r = std::move(at.road);
    limited_[i] = at.limited;
    at = Attempt{};
    step_->update(double(k + 1) / double(edges_.size()), std::to_string(k + 1) + " of " + std::to_string(edges_.size()) + " roads");
    if (!r) return;
    r->from = links_[i].from;
    r->to = links_[i].to;
    r->road_class = r->ferry ? RoadClass::maritime : links_[i].road_class;
    if (r->over_budget || r->chain.cells.empty()) return;
    if (built_.shared_share(r->chain) >= options_.redundant_share && built_.joined(r->chain.cells.front(), r->chain.cells.back())) {
      redundant_[i] = true;
      return;
    }
    built_.add(r->chain, r->road_class);
  }

  const TerrainField& t_;
  const RoadGraph& base_;
  const std::vector<Link>& links_;
  const RoutingOptions& options_;
  const NetworkWindows* windows_;  ///< by windows (route_network_by_windows), or nullptr
  std::array<std::optional<RoadGraph>, 4> graphs_;
  std::vector<Edge> edges_;
  std::vector<std::size_t> order_;
  BuiltRoads built_;
  std::vector<std::optional<Road>> out_;
  std::vector<bool> redundant_, limited_;
  std::optional<ProgressStep> step_;  // begun once the links are checked
  const std::size_t tile_cols_, tile_rows_;
  int reach_ = 0;  // cells a surface arc's factors lie from the cell the search marks
  const std::size_t at_once_;  // links routed at once (links_at_once): by windows, each has this share of the limit
  std::vector<Attempt> attempts_;
};

}  // namespace

NetworkResult route_network(const TerrainField& t, const RoadGraph& base, const std::vector<Link>& links, const RoutingOptions& options,
                            Progress& progress, const ExistingRoads* existing) {
  NetworkRouter router(t, base, links, options, progress, existing, nullptr);
  return router.run();
}

NetworkResult route_network_by_windows(const TerrainField& frame, const RoadGraph& base, const std::vector<Link>& links,
                                       const RoutingOptions& options, Progress& progress, const NetworkWindows& windows,
                                       const ExistingRoads* existing) {
  if (frame.holds_values()) throw processing_error("roads by windows: a frame (TerrainField::frame) is expected");
  if (double(frame.grid_cols()) * double(frame.grid_rows()) >= 4294967295.0)
    throw bad_input("roads by windows: grids of 2^32 cells or more are not supported");
  NetworkRouter router(frame, base, links, options, progress, existing, &windows);
  return router.run();
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
  const bool split = layout && layout->with_existing;
  if (split) layer.fields.insert(layer.fields.end(), {{"new_m", FieldType::real}, {"existing_m", FieldType::real}});
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
    if (split) {
      const double existing_m = round_to(r.stats.length_m * r.existing_share, 0.01);
      f.values.push_back(round_to(r.stats.length_m, 0.01) - existing_m);
      f.values.push_back(existing_m);
    }
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
