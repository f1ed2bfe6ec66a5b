// Anisotropic shortest paths on oriented grid nodes with bridges and tunnels (Galin et al. 2010).
// SPDX-License-Identifier: MIT
#pragma once
#include <cstdint>
#include <vector>

#include "core/progress.hpp"
#include "roads/cost_model.hpp"
#include "roads/segment_mask.hpp"
#include "roads/terrain_field.hpp"

namespace terrapolis::roads {

/// A grid cell (col, row), row 0 north.
struct Cell {
  int col = 0, row = 0;
  bool operator==(const Cell&) const = default;
};

/// Which search runs on the graph. All three return the same optimal cost on the same graph.
enum class SearchMethod {
  dijkstra,       ///< plain Dijkstra, kept as the reference for tests
  astar,          ///< A* with h = straight-line distance x cheapest cost per metre (Peytavie §4.1.2.2)
  bidirectional,  ///< bidirectional A*, Pohl's symmetric stopping rule (Peytavie §4.1.2.3)
};

struct GraphOptions {
  int k = 5;                 ///< segment mask M_k (1..16)
  int angles = 8;            ///< orientation sectors m (1 = curvature not priced), 1..64
  std::uint64_t seed = 1;    ///< seed of the stochastic bridge/tunnel arcs
};

/// The implicit search graph of Galin et al. 2010 (Peytavie 2010 §4.1-4.3): nodes are (cell,
/// orientation), where the orientation is the structure and angle sector of the arc that reached
/// the cell; arcs are the segment mask M_k (surface roads) and, when enabled, long bridge and tunnel
/// arcs r_i..r_e long (annulus masks) of which each unordered cell pair is kept with probability
/// s / |annulus| by a hash of (seed, structure, pair): a fixed pseudo-random graph, so results do not
/// depend on the search order and the backward search sees exactly the forward arcs.
/// Arc cost = integral of the per-metre cost sampled every `sample_step_m` along the segment
/// (midpoint rule) + the curvature cost of the turn from the previous arc. Infinite-cost arcs are
/// never used. Reentrant: const methods may run concurrently.
class RoadGraph {
 public:
  RoadGraph(const TerrainField& terrain, const CostModel& model, const GraphOptions& options);

  /// One arc kind: offset, structure, outgoing orientation.
  struct Arc {
    int dcol = 0, drow = 0;
    Structure structure = Structure::road;
    int orientation = 0;       ///< orientation of a node reached through this arc
    double angle_rad = 0;
  };
  const std::vector<Arc>& arcs() const { return arcs_; }
  int orientations() const { return orientations_; }   ///< including the "start" orientation (the last)
  int start_orientation() const { return orientations_ - 1; }
  const TerrainField& terrain() const { return terrain_; }
  const CostModel& model() const { return model_; }
  std::size_t surface_arcs() const { return surface_arcs_; }

  /// Cost of the straight arc from `from` through arc `arc` (no turn), infinity when forbidden.
  double arc_cost(Cell from, int arc) const;
  /// Curvature cost of taking `arc` from a node of orientation `orientation`.
  double turn_cost(int orientation, int arc) const { return turn_[std::size_t(orientation) * arcs_.size() + std::size_t(arc)]; }
  /// True when the long arc `arc` from `from` exists in the sampled graph (always true for surface arcs).
  bool arc_sampled(Cell from, int arc) const;
  /// Arcs that reach a node of orientation `o`.
  const std::vector<int>& arcs_into(int orientation) const { return into_[std::size_t(orientation)]; }
  /// A lower bound of the cost from a to b: the cheapest way to cover the straight-line distance D
  /// and the height difference Z, min over L >= D of L g(Z/L), where g is the lower convex envelope
  /// of the per-metre cost against the grade (Z = 0 gives the paper's D x cheapest cost per metre).
  double lower_bound(Cell a, Cell b) const;
  /// Per-metre cost of a surface road at a point with a given slope (deg) (for reports).
  double surface_cost_per_m(double slope_deg, double depth_m) const;

 private:
  const TerrainField& terrain_;
  CostModel model_;
  GraphOptions options_;
  std::vector<Arc> arcs_;
  std::size_t surface_arcs_ = 0;
  int orientations_ = 1;
  double step_m_ = 1, cheapest_ = 1;
  std::uint64_t bridge_keep_ = 0, tunnel_keep_ = 0;  ///< hash thresholds of the sampling
  std::uint64_t salt_[3] = {0, 0, 0};                ///< per-structure hash salt from the seed
  std::vector<double> turn_;
  std::vector<double> slope_lut_;        ///< road slope cost against the grade |dz|/dl, for speed
  double lut_step_ = 1, tan_slope_max_ = kInfinity;
  double road_slope_cost(double grade) const;
  std::vector<double> hull_t_, hull_c_;  ///< lower convex envelope of cost per metre vs grade
  double kappa_ = 0, best_grade_ = 0;    ///< cheapest cost per metre of climb, and its grade
  std::vector<std::vector<int>> into_;
};

struct SearchResult {
  bool found = false;
  double cost = kInfinity;
  std::vector<Cell> cells;             ///< the path, start first
  std::vector<Structure> structures;   ///< structure of each arc (cells.size() - 1)
  std::size_t expanded = 0;            ///< nodes expanded (both directions)
  std::size_t nodes = 0;               ///< nodes stored (memory is about 80 bytes per node)
};

/// Shortest path from `from` to `to` (any final orientation). Nodes are kept in hash maps so memory
/// grows with the explored region only; throws processing_error when more than `max_nodes` would be
/// stored. Returns found = false when no finite-cost path exists.
SearchResult shortest_path(const RoadGraph& graph, Cell from, Cell to, SearchMethod method,
                           std::size_t max_nodes = 60'000'000, Progress* progress = nullptr);

/// Cost under `graph` of a given chain of cells joined by straight surface arcs (each step must be
/// an arc of the graph's mask), the turns priced as the search prices them; infinity when the chain
/// uses a forbidden arc or a step outside the mask. Used to price other tools' paths.
double chain_cost(const RoadGraph& graph, const std::vector<Cell>& cells);

}  // namespace terrapolis::roads
