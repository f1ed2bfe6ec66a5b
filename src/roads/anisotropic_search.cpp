// Dijkstra, A* and bidirectional A* on the oriented road graph (Galin et al. 2010).
// SPDX-License-Identifier: MIT
#include "roads/anisotropic_search.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>
#include <string>

#include "core/error.hpp"
#include "roads/radix_heap.hpp"
#include "roads/relaxed_distance.hpp"

namespace terrapolis::roads {
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

}  // namespace

struct TargetSearch::State {
  State(const RoadGraph& graph, Cell target, std::size_t long_arc_floats)
      : target(target), arcs(graph), long_arcs(graph.terrain().size(), graph.rings().size(), long_arc_floats) {}
  Cell target;
  ArcCache arcs;            ///< surface arc costs: a function of the graph alone
  LongArcCache long_arcs;   ///< long arc costs, likewise
  std::optional<RelaxedDistance> relaxed;  ///< the relaxed reverse search from the target, resumed by each road
};

TargetSearch::TargetSearch(const RoadGraph& graph, Cell target, std::size_t max_nodes)
    : state_(std::make_unique<State>(graph, target, std::min(kLongArcFloats, 4 * max_nodes))) {}
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
    const std::size_t i = std::size_t(key / O_);
    return Cell{t_.col_of(i), t_.row_of(i)};
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
  TargetSearch::State& state = (shared ? *shared : own.emplace(graph, to, max_nodes)).state();
  return PathSearch(graph, from, to, method, max_nodes, progress, max_seconds, state, shared != nullptr, discount).run();
}

}  // namespace terrapolis::roads
