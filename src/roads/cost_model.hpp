// Transfer functions and the cost model of roads, bridges and tunnels (Peytavie 2010 §4.2).
// SPDX-License-Identifier: MIT
#pragma once
#include <array>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace terrapolis::roads {

inline constexpr double kInfinity = std::numeric_limits<double>::infinity();

/// A transfer function mu(kappa) (Peytavie 2010 §4.2.2): a piecewise-linear curve through
/// `points` (kappa ascending), constant beyond its first and last point, and +infinity for
/// kappa > `threshold` (kappa_0). Costs are >= 0.
struct TransferFunction {
  std::vector<std::array<double, 2>> points;  ///< (kappa, cost) pairs; empty = always 0
  double threshold = kInfinity;               ///< kappa_0; infinity = no threshold
  double operator()(double kappa) const;
  /// Smallest value over [0, threshold] (the curve's minimum; used by the A* heuristic).
  double min_value() const;
};

/// The three kinds of arcs of the search graph.
enum class Structure : int { road = 0, bridge = 1, tunnel = 2 };
const char* structure_name(Structure s);

/// Costs of one kind of arc. Per-metre terms are integrated along an arc; the curvature term is
/// charged once per turn between two arcs (cost units = metres of flat road).
struct StructureCosts {
  bool enabled = true;
  TransferFunction slope_deg;       ///< per metre, slope of the road (degrees, >= 0)
  TransferFunction water_depth_m;   ///< per metre, water depth under the road (m, >= 0)
  TransferFunction curvature_deg;   ///< per turn, turn angle between arcs (degrees, 0..180)
  TransferFunction vegetation;      ///< per metre, vegetation / land-cover density from --vegetation (raster units, e.g. 0..1)
  TransferFunction height_m;        ///< bridges: per metre, deck height above ground or water (m)
  TransferFunction depth_m;         ///< tunnels: per metre, depth below the ground (m)
  /// Bridges/tunnels: length range of the long arcs. Null = the paper's 50..300 m on its 10 m
  /// grid scaled to the DEM's cell size, i.e. 5..30 cells.
  std::optional<double> min_length_m, max_length_m;
  double min_length_cells = 5, max_length_cells = 30;
  /// Bridges/tunnels: a cap (m) on the cell-scaled range, so coarse grids do not build 30 km
  /// crossings (on a 1 km grid, 5..30 cells); a range entirely above it disables the structure.
  std::optional<double> longest_m;
  /// Bridges/tunnels: expected number s of long arcs tried per expansion (Peytavie §4.3.4).
  int samples = 100;
};

/// The cost model c = sum_i mu_i(kappa_i) for the three structures.
struct CostModel {
  StructureCosts road, bridge, tunnel;
  double sample_step_m = 0;             ///< integration step along arcs (m); 0 = half the smallest cell side
  double unknown_water_depth_m = 10;    ///< depth of water cells when the DEM has no bathymetry (m)
  double structure_min_m = 5;           ///< h_B / h_T of the segmentation (Peytavie §4.4.2), m
  double road_radius_m = 10;            ///< road half-width + margin: water is looked for within it (m)
  double smoothing_tolerance_cells = 1; ///< max deviation of the smoothed road from the grid path (cells)
  /// Smallest curve radius of the smoothing (m; 0 = none): a corner's curve may leave the tolerance
  /// to reach it (its grade still checked). Set per road class (roads.min_radius_m), not in the file.
  double min_curve_radius_m = 0;

  /// Cheapest cost per metre of any enabled structure (A* heuristic factor, Peytavie §4.1.2.4).
  double cheapest_per_metre() const;
};

/// The defaults from Peytavie 2010 §4.2.2: slope 15 deg (log-shaped), water 0.5 m for roads,
/// curvature 170 deg roads / 50 deg bridges / 70 deg tunnels, bridges up to 50 m of water and
/// 150 m high, tunnels linear to 15 m depth then constant, at most 1000 m deep.
CostModel default_cost_model();

/// Applies the JSON document in `path` over `base` (only the keys present change), checked against
/// schemas/road_costs.schema.json. Throws bad_input "PATH: /json/pointer: problem".
CostModel load_cost_model(const std::string& path, CostModel base = default_cost_model());
/// Same, from JSON text (`origin` names it in errors).
CostModel parse_cost_model(const std::string& text, const std::string& origin, CostModel base = default_cost_model());
/// The model as JSON (the format load_cost_model reads).
std::string cost_model_json(const CostModel& model);
/// schemas/road_costs.schema.json, the format of the cost file (embedded at build time).
std::string_view road_costs_schema_text();
/// One transfer function from its JSON text {"points": [[kappa, cost], ...], "threshold": x|null}
/// (the format of the cost model file); `origin` names it in errors. Throws bad_input.
TransferFunction parse_transfer_function(const std::string& text, const std::string& origin);

}  // namespace terrapolis::roads
