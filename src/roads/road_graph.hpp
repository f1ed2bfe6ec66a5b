// The implicit oriented search graph of Galin et al. 2010: arcs, their costs and lower bounds.
// SPDX-License-Identifier: MIT
#pragma once
#include <cstdint>
#include <span>
#include <vector>

#include "roads/cost_model.hpp"
#include "roads/segment_mask.hpp"
#include "roads/terrain_field.hpp"

namespace terrapolis::roads {

/// A grid cell (col, row), row 0 north.
struct Cell {
  int col = 0, row = 0;
  bool operator==(const Cell&) const = default;
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
/// s / |annulus| by a hash of (seed, structure, offset, position modulo 32; see arc_sampled): a
/// fixed pseudo-random graph, so results do not depend on the search order and the backward search
/// sees exactly the forward arcs.
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
  const GraphOptions& options() const { return options_; }
  std::size_t surface_arcs() const { return surface_arcs_; }

  /// Cost of the straight arc from `from` through arc `arc` (no turn), infinity when forbidden.
  double arc_cost(Cell from, int arc) const;
  /// Curvature cost of taking `arc` from a node of orientation `orientation`.
  double turn_cost(int orientation, int arc) const { return turn_[std::size_t(orientation) * arcs_.size() + std::size_t(arc)]; }
  /// True when the long arc `arc` from `from` exists in the sampled graph (always true for surface
  /// arcs). Each unordered cell pair {p, p + d} is kept with probability s / |annulus| by a hash of
  /// (seed, structure, d, position of its first cell modulo kSamplePeriod): a fixed pseudo-random
  /// graph, periodic in space, so the sampled arcs of a cell come from precomputed lists (no test
  /// per arc during the search) and the backward search sees exactly the forward arcs.
  bool arc_sampled(Cell from, int arc) const;
  static constexpr int kSamplePeriod = 32;
  /// Long arcs are grouped in rings of similar length per structure (Peytavie §4.3.3 annuli cut
  /// into bands), so that the search can price a band only when its cheapest arc could still lie on
  /// a shortest path (lazy evaluation; see shortest_path).
  struct Ring {
    Structure structure = Structure::bridge;
    double min_length_m = 0;  ///< no arc of the ring is shorter, on any row
    /// Lower bound of arc cost + heuristic(target) - heuristic(source) over the ring's arcs, for the
    /// A* heuristic (`with_heuristic`) and for none (Dijkstra).
    double with_heuristic = 0, without_heuristic = 0;
    int next = -1;            ///< next (longer) ring of the same structure, or -1
  };
  const std::vector<Ring>& rings() const { return rings_; }
  /// First ring of a structure, or -1 when it has no long arcs.
  int first_ring(Structure s) const { return first_ring_[int(s)]; }
  /// Surface arcs with a finite turn cost (slot 0) or the sampled arcs of ring r (slot r + 1, any
  /// turn: the caller checks it) that leave cell `c` in orientation `o`.
  std::span<const int> arcs_from(Cell c, int orientation, int slot) const;
  /// Surface arcs (slot 0) or the sampled arcs of ring r (slot r + 1) that reach cell `c` in orientation `o`.
  std::span<const int> arcs_into(Cell c, int orientation, int slot) const;
  /// Structure of the arcs that reach a node of orientation `o` (road for the start orientation).
  Structure structure_of(int orientation) const { return orientation_structure_[std::size_t(orientation)]; }
  /// A lower bound of the cost from a to b: the cheapest way to cover the straight-line distance D
  /// and the height difference Z, min over L >= D of L g(Z/L), where g is the lower convex envelope
  /// of the per-metre cost against the grade (Z = 0 gives the paper's D x cheapest cost per metre).
  double lower_bound(Cell a, Cell b) const;
  /// The lower convex envelope g of lower_bound at a grade (cost per metre; non-decreasing).
  double envelope(double grade) const;
  /// A lower bound of arc_cost(from, arc) for a surface arc, from its two ends and one sample only:
  /// by Jensen's inequality on the lower convex envelope of the road's slope cost, an arc that climbs
  /// Z over L costs at least L x envelope(Z / L), and infinity when Z / L passes the threshold (some
  /// step would) or its middle sample lies on water too deep. Ten times cheaper than the arc's cost.
  double surface_arc_bound(Cell from, int arc) const;
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
  /// Length (m) of surface arc a from row r at [r * surface_arcs_ + a], exactly as length_m gives it
  /// (a function of the row alone: no hypot per arc); empty past kMaxLengthTable entries.
  std::vector<double> surface_length_;
  static constexpr std::size_t kMaxLengthTable = std::size_t(1) << 22;  // 32 MB
  double surface_length_m(int row, int arc) const;
  std::vector<double> slope_lut_;        ///< road slope cost against the grade |dz|/dl, for speed
  double lut_step_ = 1, tan_slope_max_ = kInfinity;
  double road_slope_cost(double grade) const;
  std::vector<double> hull_t_, hull_c_;  ///< lower convex envelope of cost per metre vs grade
  std::vector<double> road_hull_t_, road_hull_c_;  ///< the same for surface roads alone (the slope table)
  double road_floor_ = 0;                ///< surface roads' water and vegetation terms at their minima
  double kappa_ = 0, best_grade_ = 0;    ///< cheapest cost per metre of climb, and its grade
  // Construction phases, in order.
  void build_slope_tables();  ///< the road slope table and its lower convex hull
  void build_envelope();      ///< the heuristic's envelope g over every structure
  void build_rings();
  void build_turns();
  void build_arc_lists();
  std::vector<int> ring_of_;             ///< ring of each long arc (index - surface_arcs_)
  std::vector<Ring> rings_;
  int first_ring_[3] = {-1, -1, -1};
  int period_[3] = {1, 1, 1};  ///< sampling period per structure (1 when every arc is kept)
  int sample_class(Structure s, int col, int row) const;
  bool pair_sampled(int arc, int from_col, int from_row) const;
  std::vector<std::vector<int>> from_, into_;  ///< surface arcs per orientation
  /// Sampled long arcs out of a cell per (class, ring), into a cell per (class, orientation, ring),
  /// flattened: [start[i], start[i + 1]).
  std::vector<std::size_t> long_from_start_, long_into_start_;
  std::vector<int> long_from_, long_into_;
  std::vector<Structure> orientation_structure_;
};

/// Cost under `graph` of a given chain of cells joined by straight surface arcs (each step must be
/// an arc of the graph's mask), the turns priced as the search prices them; infinity when the chain
/// uses a forbidden arc or a step outside the mask. Used to price other tools' paths.
double chain_cost(const RoadGraph& graph, const std::vector<Cell>& cells);

}  // namespace terrapolis::roads
