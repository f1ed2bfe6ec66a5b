// The A* heuristic of the road search: the relaxed reverse search (distances to the target on a
// relaxed 2-D graph), and the arc cost caches it shares with the forward search (Galin et al. 2010).
// Internal to anisotropic_search.cpp, its only includer: in an unnamed namespace there, as before the
// split, so that the search's calls into it inline as they did (a named namespace cost 3.5 % on the
// Alps road).
// SPDX-License-Identifier: MIT
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <optional>
#include <vector>

#include "roads/anisotropic_search.hpp"
#include "roads/radix_heap.hpp"
#include "roads/road_graph.hpp"

namespace terrapolis::roads {
namespace {  // internal linkage: see above

constexpr double kDeg = 180.0 / std::numbers::pi;


/// Surface arc costs of the cells met so far: a node is expanded once per orientation but its
/// arcs cost the same from every orientation, so they are computed once (lazily, NaN = not yet).
class ArcCache {
 public:
  ArcCache(const RoadGraph& graph) : graph_(graph), n_(graph.surface_arcs()), slot_(graph.terrain().size(), kNone) {}
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
    discount->read_tiles[std::size_t((c.row >> ArcDiscount::kReadTileShift) - discount->read_tile_row0) * discount->read_tile_cols +
                         std::size_t((c.col >> ArcDiscount::kReadTileShift) - discount->read_tile_col0)] = 1;
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
      const Cell c{t_.col_of(e.cell), t_.row_of(e.cell)};
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
    const Cell c{t_.col_of(i), t_.row_of(i)};
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
    const Cell v{t_.col_of(i), t_.row_of(i)};
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
    const Cell v{t_.col_of(e.cell), t_.row_of(e.cell)};
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
}  // namespace terrapolis::roads
