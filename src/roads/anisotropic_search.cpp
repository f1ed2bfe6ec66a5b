// Dijkstra, A* and bidirectional A* on the oriented road graph (Galin et al. 2010).
// SPDX-License-Identifier: MIT
#include "roads/anisotropic_search.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>
#include <string>

#include "core/error.hpp"
#include "roads/radix_heap.hpp"

namespace terrapolis::roads {
namespace {

constexpr double kDeg = 180.0 / std::numbers::pi;

struct Node {
  double g;
  std::uint32_t parent;  ///< forward: predecessor; backward: successor towards the goal
  std::int32_t arc;      ///< arc joining the node and its parent
};

struct QueueItem {
  double f;
  std::uint64_t key;
  std::uint32_t node;
  std::int32_t ring;  ///< -1: expand the node; r >= 0: price the node's long arcs of ring r
  double g;
  bool operator<(const QueueItem& o) const {  // min-heap; ties by key then ring, so the order is fixed
    if (f != o.f) return f > o.f;
    if (key != o.key) return key > o.key;
    return ring > o.ring;
  }
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

/// Long-arc costs of the rings priced so far, per cell and ring (a cell's ring is priced once per
/// orientation it is expanded in, about 6 times on an Alpine road, but its arcs cost the same from
/// each), computed lazily (NaN = not yet) and kept as floats. Bounded: past `cap` values it stops
/// storing and the costs are recomputed, with the same rounding, so the cache never changes a result.
class LongArcCache {
 public:
  LongArcCache(std::size_t cells, std::size_t rings, std::size_t cap) : rings_(rings), cap_(cap), slot_(rings ? cells : 0, kNone) {}
  /// The costs of ring r of a cell whose list holds n arcs, or nullptr when the cache is full; valid
  /// until the next call.
  float* ring(std::size_t cell, int r, std::size_t n) {
    std::uint32_t& s = slot_[cell];
    if (s == kNone) {
      if (heads_.size() + values_.size() + rings_ > cap_) return nullptr;
      s = std::uint32_t(heads_.size() / rings_);
      heads_.resize(heads_.size() + rings_, kNone);
    }
    std::uint32_t& h = heads_[std::size_t(s) * rings_ + std::size_t(r)];
    if (h == kNone) {
      if (heads_.size() + values_.size() + n > cap_) return nullptr;
      h = std::uint32_t(values_.size());
      values_.resize(values_.size() + n, std::numeric_limits<float>::quiet_NaN());
    }
    return values_.data() + h;
  }

 private:
  static constexpr std::uint32_t kNone = 0xffffffffu;
  std::size_t rings_, cap_;
  std::vector<std::uint32_t> slot_, heads_;
  std::vector<float> values_;
};

/// The factor of a surface arc along roads already built (ArcDiscount): the largest of its start,
/// middle and end cells' (the weakest discount); 1 without reuse.
double reuse_factor(const RoadGraph& graph, const ArcDiscount* discount, Cell c, int a) {
  if (!discount) return 1.0;
  if (discount->read_tiles)
    discount->read_tiles[std::size_t(c.row >> ArcDiscount::kReadTileShift) * discount->read_tile_cols +
                         std::size_t(c.col >> ArcDiscount::kReadTileShift)] = 1;
  const RoadGraph::Arc& arc = graph.arcs()[std::size_t(a)];
  const auto f = [&](int col, int row) { return discount->factor[graph.terrain().index(col, row)]; };
  return double(std::max({f(c.col, c.row), f(c.col + arc.dcol / 2, c.row + arc.drow / 2), f(c.col + arc.dcol, c.row + arc.drow)}));
}

/// Distances to the target on a relaxed 2-D graph: nodes are cells (the orientation dropped, so no
/// turn is priced), arcs are every surface arc and every sampled bridge or tunnel arc at its exact
/// cost (a long arc integrated only when a cheap bound of its cost could improve its source). Every arc of the oriented graph costs at least its relaxed
/// arc, so the relaxed distance is an admissible and consistent heuristic for it, and on relief it
/// is far tighter than the straight-line bound: it knows where the valleys and passes are.
/// Computed lazily by a reverse A* from the target guided by the straight-line bound towards the
/// source and resumed on demand (Reverse Resumable A*, Silver 2005): `exact(v)` settles v; `bound(v)`
/// never searches and returns the exact distance when v is settled, else the A* bound
/// F - lower_bound(v, source) (F the smallest key still queued), which only grows.
/// With road reuse (ArcDiscount) the surface arcs cost their discounted price, so the distances
/// bound the discounted costs themselves, and the straight-line guide is scaled by the smallest
/// factor to stay consistent: the forward search keeps a tight heuristic along and off the roads.
class RelaxedDistance {
 public:
  RelaxedDistance(const RoadGraph& graph, Cell target, Cell source, ArcCache* cache, LongArcCache* long_cache, const ArcDiscount* discount)
      : graph_(graph), t_(graph.terrain()), source_(source), cache_(cache), long_cache_(long_cache), discount_(discount),
        guide_scale_(discount ? discount->floor : 1.0) {
    if (scratch_in_use_) own_.emplace();  // a nested search on this thread gets its own arrays
    else scratch_in_use_ = true;
    Scratch& s = scratch();
    if (s.g.size() != t_.size()) {
      s.g.assign(t_.size(), kInfinity);
      s.closed.assign(t_.size(), 0);
      s.touched.clear();
    }
    const CostModel& m = graph.model();
    fixed_[1] = m.bridge.height_m.min_value() + m.bridge.water_depth_m.min_value() + m.bridge.vegetation.min_value();
    fixed_[2] = m.tunnel.depth_m.min_value() + m.tunnel.water_depth_m.min_value() + m.tunnel.vegetation.min_value();
    // Deck slope cost against the grade as a table of lower bounds: entry i is the smallest cost at
    // any grade >= i x step. Each piece of the curve is monotone in the grade, so that minimum is at
    // i x step or at a breakpoint beyond it.
    for (int st = 1; st < 3; ++st) {
      const TransferFunction& f = st == 1 ? m.bridge.slope_deg : m.tunnel.slope_deg;
      tan_max_[st] = f.threshold < 90 ? std::tan(f.threshold / kDeg) : kInfinity;
      const double gmax = f.threshold < 90 ? tan_max_[st] : std::tan(89.5 / kDeg);
      constexpr std::size_t kSteps = 2048;
      grade_step_[st] = gmax / kSteps;
      auto& table = slope_floor_[st];
      table.assign(kSteps + 1, kInfinity);
      double beyond = f(std::min(f.threshold, std::atan(gmax) * kDeg));
      for (std::size_t i = kSteps + 1; i-- > 0;) {
        const double lo_deg = std::min(f.threshold, std::atan(double(i) * grade_step_[st]) * kDeg), hi_deg = std::atan(double(i + 1) * grade_step_[st]) * kDeg;
        for (const auto& p : f.points)
          if (p[0] >= lo_deg && (p[0] < hi_deg || i == kSteps) && p[0] <= f.threshold) beyond = std::min(beyond, p[1]);
        beyond = std::min(beyond, f(lo_deg));
        table[i] = beyond;
      }
      if (f.points.empty()) table.assign(kSteps + 1, 0.0);
    }
    ring_offset_.assign(graph.rings().size(), 0.0);
    for (std::size_t r = 0; r < graph.rings().size(); ++r) {
      const int st = int(graph.rings()[r].structure);
      ring_offset_[r] = 0.75 * ring_margin(st) * graph.rings()[r].min_length_m;
    }
    relax(t_.index(target.col, target.row), 0.0);
  }
  ~RelaxedDistance() {
    Scratch& s = scratch();
    for (std::size_t i : s.touched) s.g[i] = kInfinity, s.closed[i] = 0;
    s.touched.clear();
    if (!own_) scratch_in_use_ = false;
  }
  RelaxedDistance(const RelaxedDistance&) = delete;
  RelaxedDistance& operator=(const RelaxedDistance&) = delete;

  /// The relaxed distance from v to the target (infinity when none), settling v if needed.
  double exact(Cell v) {
    const std::size_t i = t_.index(v.col, v.row);
    Scratch& s = scratch();
    while (!s.closed[i] && settle_next()) {
    }
    return s.closed[i] ? s.g[i] : kInfinity;
  }
  /// A lower bound of the relaxed distance from v without searching (exact when v is settled).
  double bound(Cell v) {
    const std::size_t i = t_.index(v.col, v.row);
    Scratch& s = scratch();
    if (s.closed[i]) return s.g[i];
    if (heap_.empty()) return kInfinity;
    return std::max(0.0, heap_.floor() - guide(v));
  }
  bool settled(Cell v) { return scratch().closed[t_.index(v.col, v.row)] != 0; }
  std::size_t settled_cells() const { return settled_; }
  /// Guides the search towards another source. Settled distances stay exact whatever the guide (a
  /// consistent heuristic never settles a cell early), so re-keying the queue with the new source's
  /// straight-line bound resumes an exact search: every road ending at the target shares it.
  void set_source(Cell source) {
    if (source == source_) return;
    source_ = source;
    heap_.rekey([&](Entry& e) {
      const Cell c{int(e.cell % std::size_t(t_.cols())), int(e.cell / std::size_t(t_.cols()))};
      e.f = e.g + guide(c) + (e.ring >= 0 ? ring_offset_[std::size_t(e.ring)] : 0.0);
    });
  }

 private:
  struct Entry {
    double f, g;
    std::size_t cell;
    int ring;  ///< -1: settle the cell; r >= 0: relax the long arcs of ring r into the (settled) cell
  };
  struct Scratch {
    std::vector<double> g;
    std::vector<std::uint8_t> closed;
    std::vector<std::size_t> touched;
  };
  static inline thread_local Scratch shared_;
  static inline thread_local bool scratch_in_use_ = false;
  Scratch& scratch() { return own_ ? *own_ : shared_; }

  void relax(std::size_t i, double g) {
    Scratch& s = scratch();
    if (s.closed[i] || g >= s.g[i]) return;
    if (s.g[i] == kInfinity) s.touched.push_back(i);
    s.g[i] = g;
    const Cell c{int(i % std::size_t(t_.cols())), int(i / std::size_t(t_.cols()))};
    push({g + guide(c), g, i, -1});
  }
  void push(const Entry& e) { heap_.push(e); }
  /// The least of (relaxed long-arc cost - lower_bound across the arc) per metre for structure st,
  /// >= 0: an arc of length L into v gives its source w a key at least f(v) + L x margin, since
  /// lower_bound(v, w) <= L envelope(grade) (the envelope is convex and non-decreasing). Each grade
  /// step of the table is taken against the envelope at the step's steep end.
  double ring_margin(int st) const {
    const auto& table = slope_floor_[st];
    double margin = kInfinity;
    for (std::size_t i = 0; i < table.size(); ++i) {
      if (table[i] == kInfinity) continue;
      margin = std::min(margin, (1 - 1e-6) * (table[i] + fixed_[st]) - graph_.envelope(double(i + 1) * grade_step_[st]) - 0.01);
    }
    return margin == kInfinity ? 0.0 : std::max(0.0, margin);
  }
  /// The A* guide towards the source (scaled with road reuse; a smaller guide only widens the
  /// ring margins, so the ring offsets stay valid).
  double guide(Cell c) const { return guide_scale_ * graph_.lower_bound(c, source_); }
  /// Settles the next cell; false when the queue is empty.
  bool settle_next() {
    Scratch& s = scratch();
    while (!heap_.empty()) {
      const Entry e = heap_.pop();
      if (e.ring >= 0) {
        relax_ring(e);
        continue;
      }
      if (s.closed[e.cell] || e.g > s.g[e.cell]) continue;
      s.closed[e.cell] = 1;
      ++settled_;
      expand(e.cell, e.g);
      return true;
    }
    return false;
  }
  /// Relaxes the arcs into cell i (settled at distance d).
  void expand(std::size_t i, double d) {
    const Cell v{int(i % std::size_t(t_.cols())), int(i / std::size_t(t_.cols()))};
    const auto& arcs = graph_.arcs();
    for (std::size_t a = 0; a < graph_.surface_arcs(); ++a) {
      const Cell u{v.col - arcs[a].dcol, v.row - arcs[a].drow};
      if (!t_.inside(u.col, u.row)) continue;
      const std::size_t ui = t_.index(u.col, u.row);
      if (scratch().closed[ui]) continue;
      // The cheap bound first: most arcs into v cannot improve u, and need no integral.
      const double factor = reuse_factor(graph_, discount_, u, int(a));
      const double lb = graph_.surface_arc_bound(u, int(a)) * factor;
      if (lb == kInfinity || d + lb >= scratch().g[ui]) continue;
      const double e = (cache_ ? cache_->get(u, ui, int(a)) : double(float(graph_.arc_cost(u, int(a))))) * factor;
      if (e < kInfinity) relax(ui, d + e);
    }
    // Long arcs join two land cells. They wait in the queue, one entry per ring, keyed by f(v) plus
    // a lower bound of what an arc of the ring adds to its source's key (ring_margin), as the
    // forward search's rings do: most are never relaxed, the search ending first.
    if (graph_.rings().empty() || t_.water(v.col, v.row)) return;
    const double f = d + guide(v);
    for (Structure st : {Structure::bridge, Structure::tunnel}) {
      const int r = graph_.first_ring(st);
      if (r >= 0) push({f + ring_offset_[std::size_t(r)], d, i, r});
    }
  }
  /// Relaxes the long arcs of ring e.ring into the settled cell e.cell, then queues its next ring.
  void relax_ring(const Entry& e) {
    const Cell v{int(e.cell % std::size_t(t_.cols())), int(e.cell / std::size_t(t_.cols()))};
    const auto& arcs = graph_.arcs();
    const double d = e.g, zv = t_.surface(v.col, v.row);
    const RoadGraph::Ring& ring = graph_.rings()[std::size_t(e.ring)];
    const int st = int(ring.structure);
    const double floor = fixed_[st] + slope_floor_[st].front();
    const auto& table = slope_floor_[st];
    // Sampled pairs are unordered: the long arcs out of v list the cells w whose arc w -> v exists.
    const std::span<const int> list = graph_.arcs_from(v, 0, e.ring + 1);
    float* costs = nullptr;
    for (std::size_t k = 0; k < list.size(); ++k) {
      const int a = list[k];
      const Cell w{v.col + arcs[std::size_t(a)].dcol, v.row + arcs[std::size_t(a)].drow};
      if (!t_.inside(w.col, w.row) || t_.water(w.col, w.row)) continue;
      const std::size_t wi = t_.index(w.col, w.row);
      if (scratch().closed[wi] || d + (1 - 1e-6) * ring.min_length_m * floor >= scratch().g[wi]) continue;  // cannot improve w
      // As arc_cost prices the arc w -> v: the deck slope from the two surfaces over its length,
      // here bounded from the table (no atan, no curve lookup per arc).
      const double length = t_.length_m({double(w.col), double(w.row)}, {double(v.col), double(v.row)});
      if (d + (1 - 1e-6) * length * floor >= scratch().g[wi]) continue;
      const double grade = std::fabs(zv - double(t_.surface(w.col, w.row))) / length;
      if (grade > tan_max_[st] * (1 + 1e-9)) continue;  // the deck breaks the slope threshold
      const double slope = table[std::min(table.size() - 1, std::size_t(grade / grade_step_[st]))];
      if (d + (1 - 1e-6) * length * (slope + fixed_[st]) >= scratch().g[wi]) continue;
      // Then the arc's own cost: a bridge that would cut the ground, a tunnel that would leave it or
      // a deep crossing costs what the forward search will pay (a long arc costs the same both ways:
      // the same samples along the same deck), so the heuristic is tight at the structures too.
      if (!costs) costs = long_cache_->ring(e.cell, e.ring, list.size());
      double exact;
      if (costs) {
        if (std::isnan(costs[k])) costs[k] = float(graph_.arc_cost(v, a));
        exact = costs[k];
      } else {
        exact = double(float(graph_.arc_cost(v, a)));
      }
      // 1e-6 covers the float rounding of the priced long arcs.
      if (exact < kInfinity) relax(wi, d + (1 - 1e-6) * exact);
    }
    if (ring.next >= 0) {
      Entry next = e;
      next.ring = ring.next;
      next.f = d + guide(v) + ring_offset_[std::size_t(ring.next)];
      push(next);
    }
  }

  const RoadGraph& graph_;
  const TerrainField& t_;
  Cell source_;
  ArcCache* cache_;              ///< shared with later searches to the target, or nullptr (the arcs
                                 ///< it prices are each priced once: caching them costs more)
  LongArcCache* long_cache_;     ///< the long arc costs, shared with the forward search
  const ArcDiscount* discount_;  ///< road reuse, or nullptr
  const double guide_scale_;     ///< the smallest discount factor, 1 without reuse
  std::optional<Scratch> own_;
  RadixHeap<Entry> heap_;  ///< keys only grow: the guide is consistent
  double fixed_[3] = {0, 0, 0};
  std::vector<double> slope_floor_[3];  ///< per structure: lower bounds of the deck slope cost by grade step
  double grade_step_[3] = {1, 1, 1}, tan_max_[3] = {kInfinity, kInfinity, kInfinity};
  std::vector<double> ring_offset_;     ///< per ring: 0.75 x ring_margin x the ring's shortest arc
  std::size_t settled_ = 0;
};

}  // namespace

struct TargetSearch::State {
  State(const RoadGraph& graph, Cell target)
      : target(target), arcs(graph), long_arcs(graph.terrain().size(), graph.rings().size(), std::size_t(1) << 25) {}  // at most 128 MB
  Cell target;
  ArcCache arcs;            ///< surface arc costs: a function of the graph alone
  LongArcCache long_arcs;   ///< long arc costs, likewise
  std::optional<RelaxedDistance> relaxed;  ///< the relaxed reverse search from the target, resumed by each road
};

TargetSearch::TargetSearch(const RoadGraph& graph, Cell target) : state_(std::make_unique<State>(graph, target)) {}
TargetSearch::~TargetSearch() = default;

namespace {

/// One run of shortest_path: the state its steps share (the two frontiers, the caches, the relaxed
/// reverse search, the best meeting point) and the steps themselves.
class PathSearch {
 public:
  PathSearch(const RoadGraph& graph, Cell from, Cell to, SearchMethod method, std::size_t max_nodes, Progress* progress,
             double max_seconds, TargetSearch::State& state, bool state_shared, const ArcDiscount* discount)
      : graph_(graph), t_(graph.terrain()), arcs_(graph.arcs()), discount_(discount),
        h_scale_(discount ? discount->floor : 1.0), from_(from), to_(to), max_nodes_(max_nodes),
        max_seconds_(max_seconds), O_(std::uint64_t(graph.orientations())), use_h_(method != SearchMethod::dijkstra),
        bidir_(method == SearchMethod::bidirectional), relaxed_(method == SearchMethod::astar),
        goal_index_(t_.index(to.col, to.row)), cache_(state.arcs), long_cache_(state.long_arcs), fw_(t_.size(), O_),
        bw_(bidir_ ? t_.size() : 0, O_) {
    if (progress) step_.emplace(*progress, "route");
    h0_ = best_h_ = graph.lower_bound(from, to);
    if (relaxed_) {
      // With road reuse the roads built since the last search changed the discounted costs: the
      // relaxed search starts again (its arc caches, of undiscounted costs, stay shared).
      if (state.relaxed && !discount) state.relaxed->set_source(from);
      else state.relaxed.reset(), state.relaxed.emplace(graph, to, from, state_shared ? &cache_ : nullptr, &long_cache_, discount);
      rel_ = &*state.relaxed;
      settled_before_ = rel_->settled_cells();
    }
  }

  SearchResult run() { return bidir_ ? run_bidirectional() : run_unidirectional(); }

 private:
  // The clock is read every 1024 pops (about a millisecond of search).
  bool out_of_time() {
    return max_seconds_ > 0 && (pops_++ & 1023) == 0 &&
           std::chrono::duration<double>(std::chrono::steady_clock::now() - started_).count() > max_seconds_;
  }
  std::uint64_t key_of(Cell c, int o) const { return std::uint64_t(t_.index(c.col, c.row)) * O_ + std::uint64_t(o); }
  Cell cell_of(std::uint64_t key) const {
    const std::uint64_t i = key / O_;
    return Cell{int(i % std::uint64_t(t_.cols())), int(i / std::uint64_t(t_.cols()))};
  }
  int orient_of(std::uint64_t key) const { return int(key % O_); }
  void report(double h) {
    if (!step_ || h0_ <= 0) return;
    best_h_ = std::min(best_h_, h);
    if ((result_.expanded & 4095) == 0) step_->update(std::clamp(1.0 - best_h_ / h0_, 0.0, 1.0));
  }
  // Queue keys. A*: g + h(v), h(v) = lower_bound(v, to); Dijkstra: g. Bidirectional A* uses the
  // balanced potential p(v) = (h_to(v) - h_from(v)) / 2 (Ikeda et al. 1994; Goldberg & Harrelson
  // 2005): forward key g + p(v), backward key g - p(v). Both heuristics are consistent, so the
  // reduced arc costs l(u,v) - p(u) + p(v) are >= 0 in both directions and the search may stop as
  // soon as top_f + top_b >= mu, the best meeting cost (the bidirectional Dijkstra rule on the
  // reduced costs).
  // Road reuse (ArcDiscount): the straight-line bounds hold for the undiscounted costs, so times the
  // smallest factor they bound the discounted ones and stay consistent; the relaxed distance is
  // computed on the discounted costs (RelaxedDistance).
  double potential(Cell v) {
    if (!use_h_) return 0.0;
    if (relaxed_) return std::max(h_scale_ * graph_.lower_bound(v, to_), rel_->bound(v));
    if (!bidir_) return h_scale_ * graph_.lower_bound(v, to_);
    return h_scale_ * 0.5 * (graph_.lower_bound(v, to_) - graph_.lower_bound(v, from_));
  }
  double ring_offset(int r) const {
    const RoadGraph::Ring& ring = graph_.rings()[std::size_t(r)];
    // The relaxed distance is consistent but leaves no margin to add (its long arcs are already
    // bounded by their structure's floor), so a ring waits only behind its node. With a scaled
    // heuristic s h: arc + s dh >= s (arc + dh) + (1 - s) arc, so the bound mixes the two.
    if (relaxed_) return 0.0;
    if (!use_h_) return ring.without_heuristic;
    return h_scale_ * ring.with_heuristic + (1 - h_scale_) * ring.without_heuristic;
  }
  double reuse(Cell c, int a) const { return reuse_factor(graph_, discount_, c, a); }
  // Long arcs are priced as floats in both directions, cached or not, so every search sees the same costs.
  double long_cost(Cell from_cell, int a) const { return double(float(graph_.arc_cost(from_cell, a))); }
  void check_memory() const {
    if (fw_.nodes.size() + bw_.nodes.size() + cache_.cells() * graph_.surface_arcs() / 4 > max_nodes_)
      throw processing_error("path: the search stored more than " + std::to_string(max_nodes_) +
                             " nodes; use a smaller --k or --angles, or closer end points");
  }
  void try_meet(std::uint64_t key, double g, const Frontier& other) {
    if (!bidir_) return;
    const std::uint32_t j = other.find(key);
    if (j == Frontier::kNone) return;
    const double total = g + other.nodes[j].g;
    if (total < mu_ || (total == mu_ && key < meet_)) {
      mu_ = total;
      meet_ = key;
    }
  }
  // Forward: the arcs of `slot` (0 surface, r + 1 ring r) out of the node of q.
  void expand_forward(const QueueItem& q, int slot) {
    const Cell c = cell_of(q.key);
    const int o = orient_of(q.key);
    const std::span<const int> list = graph_.arcs_from(c, o, slot);
    float* costs = slot == 0 ? cache_.row(t_.index(c.col, c.row)) : long_cache_.ring(t_.index(c.col, c.row), slot - 1, list.size());
    for (std::size_t i = 0; i < list.size(); ++i) {
      const int a = list[i];
      const RoadGraph::Arc& arc = arcs_[std::size_t(a)];
      const Cell n{c.col + arc.dcol, c.row + arc.drow};
      if (!t_.inside(n.col, n.row)) continue;
      const double turn = graph_.turn_cost(o, a);
      if (turn == kInfinity) continue;  // long arcs: the lists do not depend on the orientation
      double e;
      if (slot == 0) {
        e = cache_.get(c, costs, a) * reuse(c, a);
      } else if (costs) {
        if (std::isnan(costs[i])) costs[i] = float(long_cost(c, a));
        e = costs[i];
      } else {
        e = long_cost(c, a);
      }
      if (e == kInfinity) continue;
      const double g = q.g + turn + e;
      bool improved;
      const std::uint32_t idx = fw_.relax(key_of(n, arc.orientation), g, q.node, a, improved);
      if (improved) {
        const double f = g + potential(n);
        if (f == kInfinity) continue;  // the target cannot be reached from n
        fw_.push({f, fw_.key(idx), idx, -1, g});
        try_meet(fw_.key(idx), g, bw_);
      }
    }
  }
  // Backward: the arcs of `slot` into the node of q, from every orientation of their source.
  void expand_backward(const QueueItem& q, int slot) {
    const Cell c = cell_of(q.key);
    const int o = orient_of(q.key);
    for (int a : graph_.arcs_into(c, o, slot)) {
      const RoadGraph::Arc& arc = arcs_[std::size_t(a)];
      const Cell p{c.col - arc.dcol, c.row - arc.drow};
      if (!t_.inside(p.col, p.row)) continue;
      const double e = slot == 0 ? cache_.get(p, t_.index(p.col, p.row), a) * reuse(p, a) : long_cost(p, a);
      if (e == kInfinity) continue;
      const double hp = potential(p);
      for (int po = 0; po < graph_.orientations(); ++po) {
        if (po == graph_.start_orientation() && !(p == from_)) continue;
        const double turn = graph_.turn_cost(po, a);
        if (turn == kInfinity) continue;
        const double g = q.g + turn + e;
        bool improved;
        const std::uint32_t idx = bw_.relax(key_of(p, po), g, q.node, a, improved);
        if (improved) {
          bw_.push({g - hp, bw_.key(idx), idx, -1, g});
          try_meet(bw_.key(idx), g, fw_);
        }
      }
    }
  }
  // Pops one entry of a direction and processes it; returns false when it is the goal (A*).
  bool step_once(bool forward) {
    Frontier& me = forward ? fw_ : bw_;
    const QueueItem q = me.pop();
    if (q.g > me.nodes[q.node].g) return true;  // stale: the node was reached more cheaply since
    const Cell c = cell_of(q.key);
    if (relaxed_ && q.ring < 0 && !rel_->settled(c)) {
      // Queued with a bound of the relaxed distance: settle it, and queue the node again if its
      // key grew (keys only grow to admissible values, so the search stays exact).
      const double f = q.g + std::max(h_scale_ * graph_.lower_bound(c, to_), rel_->exact(c));
      if (f > q.f) {
        if (f < kInfinity) me.push({f, q.key, q.node, -1, q.g});
        return true;
      }
    }
    const double node_key = forward ? q.g + potential(c) : q.g - potential(c);
    if (q.ring >= 0) {
      forward ? expand_forward(q, q.ring + 1) : expand_backward(q, q.ring + 1);
      const int next = graph_.rings()[std::size_t(q.ring)].next;
      if (next >= 0) me.push({node_key + ring_offset(next), q.key, q.node, next, q.g});
      ++result_.rings_priced;
      return true;
    }
    if (!bidir_ && t_.index(c.col, c.row) == goal_index_) {
      goal_node_ = q.node;
      return false;
    }
    ++result_.expanded;
    report(forward ? graph_.lower_bound(c, to_) : graph_.lower_bound(c, from_));
    forward ? expand_forward(q, 0) : expand_backward(q, 0);
    // Long arcs wait in the queue, one entry per ring, keyed by the node's key plus a lower bound of
    // what an arc of the ring adds to it: a ring is priced only if that key comes up before the end.
    for (Structure s : {Structure::bridge, Structure::tunnel}) {
      if (!forward && graph_.structure_of(orient_of(q.key)) != s) continue;  // arcs into the node are of its structure
      const int r = graph_.first_ring(s);
      if (r >= 0) me.push({node_key + ring_offset(r), q.key, q.node, r, q.g});
    }
    check_memory();
    return true;
  }
  /// Appends the forward path ending at node n (start first).
  void forward_path(std::uint32_t n) {
    for (; n != Frontier::kNone; n = fw_.nodes[n].parent) {
      result_.cells.push_back(cell_of(fw_.key(n)));
      if (fw_.nodes[n].arc >= 0) result_.structures.push_back(arcs_[std::size_t(fw_.nodes[n].arc)].structure);
    }
    std::reverse(result_.cells.begin(), result_.cells.end());
    std::reverse(result_.structures.begin(), result_.structures.end());
  }
  SearchResult run_unidirectional() {
    bool imp;
    const std::uint32_t s = fw_.relax(key_of(from_, graph_.start_orientation()), 0.0, Frontier::kNone, -1, imp);
    fw_.push({potential(from_), fw_.key(s), s, -1, 0.0});
    while (!fw_.heap.empty()) {
      if (out_of_time()) {
        result_.over_budget = true;
        break;
      }
      if (!step_once(true)) break;
    }
    result_.nodes = fw_.stored;
    if (rel_) result_.relaxed_settled = rel_->settled_cells() - settled_before_;
    if (goal_node_ == Frontier::kNone || result_.over_budget) return result_;
    result_.found = true;
    result_.cost = fw_.nodes[goal_node_].g;
    forward_path(goal_node_);
    return result_;
  }
  SearchResult run_bidirectional() {
    bool imp;
    const std::uint32_t s = fw_.relax(key_of(from_, graph_.start_orientation()), 0.0, Frontier::kNone, -1, imp);
    fw_.push({potential(from_), fw_.key(s), s, -1, 0.0});
    for (int o = 0; o < graph_.start_orientation(); ++o) {
      const std::uint32_t b = bw_.relax(key_of(to_, o), 0.0, Frontier::kNone, -1, imp);
      bw_.push({-potential(to_), bw_.key(b), b, -1, 0.0});
    }
    while (!fw_.heap.empty() && !bw_.heap.empty()) {
      if (fw_.top() + bw_.top() >= mu_) break;
      if (out_of_time()) {
        result_.over_budget = true;
        mu_ = kInfinity;
        break;
      }
      step_once(fw_.top() <= bw_.top());
    }
    result_.nodes = fw_.stored + bw_.stored;
    if (mu_ == kInfinity) return result_;
    result_.found = true;
    result_.cost = mu_;
    forward_path(fw_.find(meet_));
    for (std::uint32_t n = bw_.find(meet_); n != Frontier::kNone && bw_.nodes[n].parent != Frontier::kNone; n = bw_.nodes[n].parent) {
      const Node& nd = bw_.nodes[n];
      result_.cells.push_back(cell_of(bw_.key(nd.parent)));
      result_.structures.push_back(arcs_[std::size_t(nd.arc)].structure);
    }
    return result_;
  }

  const std::chrono::steady_clock::time_point started_ = std::chrono::steady_clock::now();
  const RoadGraph& graph_;
  const TerrainField& t_;
  const std::vector<RoadGraph::Arc>& arcs_;
  const ArcDiscount* discount_;  ///< road reuse, or nullptr
  const double h_scale_;         ///< the heuristic's factor: the smallest discount factor, 1 without reuse
  const Cell from_, to_;
  const std::size_t max_nodes_;
  const double max_seconds_;
  const std::uint64_t O_;  ///< orientations per cell
  const bool use_h_, bidir_, relaxed_;
  const std::size_t goal_index_;
  ArcCache& cache_;
  LongArcCache& long_cache_;
  Frontier fw_, bw_;
  RelaxedDistance* rel_ = nullptr;
  std::size_t settled_before_ = 0, pops_ = 0;
  std::optional<ProgressStep> step_;
  double h0_ = 0, best_h_ = 0;
  SearchResult result_;
  double mu_ = kInfinity;  ///< bidirectional: the best meeting cost, at node key meet_
  std::uint64_t meet_ = 0;
  std::uint32_t goal_node_ = Frontier::kNone;  ///< A*, Dijkstra: the goal node when it is popped
};

}  // namespace

SearchResult shortest_path(const RoadGraph& graph, Cell from, Cell to, SearchMethod method, std::size_t max_nodes,
                           Progress* progress, double max_seconds, TargetSearch* shared, const ArcDiscount* discount) {
  const TerrainField& t = graph.terrain();
  if (!t.inside(from.col, from.row) || !t.inside(to.col, to.row)) throw bad_input("path: an end point lies outside the DEM");
  if (from == to) {
    SearchResult result;
    result.found = true;
    result.cost = 0;
    result.cells = {from};
    return result;
  }
  if (shared && !(shared->state().target == to)) throw processing_error("path: a shared target search used for another target");
  std::optional<TargetSearch> own;
  TargetSearch::State& state = (shared ? *shared : own.emplace(graph, to)).state();
  return PathSearch(graph, from, to, method, max_nodes, progress, max_seconds, state, shared != nullptr, discount).run();
}

}  // namespace terrapolis::roads
