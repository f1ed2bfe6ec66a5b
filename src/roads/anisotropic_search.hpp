// Anisotropic shortest paths on oriented grid nodes with bridges and tunnels (Galin et al. 2010).
// SPDX-License-Identifier: MIT
#pragma once
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "core/progress.hpp"
#include "roads/road_graph.hpp"

namespace terrapolis::roads {

/// Which search runs on the graph. All four return the same optimal cost on the same graph.
enum class SearchMethod {
  dijkstra,       ///< plain Dijkstra, kept as the reference for tests
  astar,          ///< A* with h = the distance on a relaxed 2-D graph (orientation dropped, long arcs bounded below)
  astar_distance, ///< A* with h = straight-line distance x cheapest cost per metre (Peytavie §4.1.2.2)
  bidirectional,  ///< bidirectional A* with balanced potentials (Ikeda et al. 1994; Goldberg & Harrelson 2005)
};

struct SearchResult {
  bool found = false;
  double cost = kInfinity;
  std::vector<Cell> cells;             ///< the path, start first
  std::vector<Structure> structures;   ///< structure of each arc (cells.size() - 1)
  std::size_t expanded = 0;            ///< nodes expanded (both directions)
  std::size_t nodes = 0;               ///< nodes stored (memory is about 80 bytes per node)
  std::size_t rings_priced = 0;        ///< rings of long arcs priced (the others were never needed)
  std::size_t relaxed_settled = 0;     ///< astar: cells settled by the relaxed reverse search
  bool over_budget = false;            ///< stopped by max_seconds (found = false)
};

/// What successive searches ending at one target share: the arc cost caches and the relaxed reverse
/// search of the A* heuristic (SearchMethod::astar), resumed for each new source. Sharing never
/// changes a cost (the caches hold functions of the graph; the reverse search stays exact). One
/// thread at a time, created and destroyed on the same thread.
class TargetSearch {
 public:
  /// The long arcs' cost cache holds at most min(kLongArcFloats, 4 x max_nodes) floats (past it the
  /// costs are recomputed: the same results), so a search's memory follows its node budget.
  TargetSearch(const RoadGraph& graph, Cell target, std::size_t max_nodes = kLongArcFloats);
  static constexpr std::size_t kLongArcFloats = std::size_t(1) << 25;  ///< 128 MB
  ~TargetSearch();
  TargetSearch(const TargetSearch&) = delete;
  TargetSearch& operator=(const TargetSearch&) = delete;
  struct State;  ///< defined by the search
  State& state() { return *state_; }

 private:
  std::unique_ptr<State> state_;
};

/// Cheaper surface arcs along roads already built (Galin et al. 2011: the next roads reuse them).
/// `factor[cell]` in (0, 1] multiplies a surface arc whose start, middle and end cells carry a road
/// (the largest of the three: the weakest discount); 1 off roads. Bridges and tunnels keep their
/// cost. `floor` is the smallest factor: the heuristic is scaled by it, so it stays a lower bound
/// of the discounted costs and the search stays exact.
struct ArcDiscount {
  std::span<const float> factor;
  double floor = 1;
  /// Optional, for a caller routing roads ahead of the ones they depend on (route_network): the
  /// search sets read_tiles[((row >> kReadTileShift) - read_tile_row0) * read_tile_cols + (col >> kReadTileShift) -
  /// read_tile_col0] for every cell whose arcs' factors it reads, so every factor it read lies within
  /// one arc's reach of a marked tile (the offsets: a window's first tile). nullptr: nothing recorded.
  static constexpr int kReadTileShift = 2;
  std::uint8_t* read_tiles = nullptr;
  std::size_t read_tile_cols = 0;
  int read_tile_col0 = 0, read_tile_row0 = 0;
};

/// Shortest path from `from` to `to` (any final orientation). Nodes are stored per touched cell so
/// memory grows with the explored region only. Long arcs are priced lazily: expanding a node queues
/// one entry per ring keyed by a lower bound of what its arcs could reach, and the ring is priced only
/// if that entry comes to the top of the queue (an exact search: the key never exceeds the key of a
/// node the ring would reach). Throws processing_error when more than `max_nodes` would be
/// stored. Returns found = false when no finite-cost path exists.
/// `max_seconds` > 0: give up after that long (wall clock) and return over_budget = true.
/// `shared`: the state of earlier searches to the same `to` (see TargetSearch), or nullptr.
/// `discount`: road reuse (see ArcDiscount), or nullptr; the caches in `shared` stay valid across
/// discounts (they hold undiscounted costs).
SearchResult shortest_path(const RoadGraph& graph, Cell from, Cell to, SearchMethod method,
                           std::size_t max_nodes = 60'000'000, Progress* progress = nullptr, double max_seconds = 0,
                           TargetSearch* shared = nullptr, const ArcDiscount* discount = nullptr);

}  // namespace terrapolis::roads
