// Belhadj's stochastic Bézier roads (Belhadj 2007 §4.4.3, Algorithm 16).
// SPDX-License-Identifier: MIT
#pragma once
#include <cstdint>
#include <vector>

#include "roads/terrain_field.hpp"

namespace terrapolis::roads {

struct BezierOptions {
  double threshold = 0.1;        ///< stop when the worst discrete position costs less (cost in [0,1])
  int tries = 20;                ///< new control points drawn per worst position
  int max_evaluations = 1000;    ///< budget: curve evaluations per road (replaces the thesis' 1000 ms so results are reproducible)
  int max_control_points = 24;   ///< the curve's degree stays below this
  double sigma_fraction = 0.25;  ///< std. deviation of the normal offset, as a fraction of the curve's length
  double altitude_weight = 0.25; ///< weight of altitude against slope in a position's cost
  double max_slope_deg = 15;     ///< slope mapped to cost 1 (the road slope threshold)
  std::uint64_t seed = 1;
};

struct BezierResult {
  std::vector<GridPoint> control;  ///< control points of the final curve
  std::vector<GridPoint> polyline; ///< the discretised curve (cell centres), start first
  double cost = 0;                 ///< sum of the position costs (Belhadj's objective)
  double worst = 0;                ///< cost of the worst position
  int evaluations = 0;
  bool satisfied = false;          ///< worst < threshold
};

/// Refines a Bézier curve from `from` to `to` (Belhadj 2007, Algorithm 16): discretise it on the
/// grid (De Casteljau), cost each position from the slope from the previous position and its
/// altitude, each rescaled to [0,1] (|slope| / tan(max_slope), (z - zmin) / (zmax - zmin); water
/// costs 1), mixed by `altitude_weight` and filtered by sqrt (cost layers of plugins: at least
/// e / (1 + e) for e per metre; 10 on a forbidden cell); take the worst position, draw a control
/// point along the curve's normal there (normal law, deviation sigma_fraction x length), insert it
/// at that position's parameter and keep the curve if its total cost drops; else retry (`tries`),
/// then the next worst position. Deterministic for a seed (own Box-Muller on mt19937_64).
BezierResult bezier_route(const TerrainField& terrain, GridPoint from, GridPoint to, const BezierOptions& options);

}  // namespace terrapolis::roads
