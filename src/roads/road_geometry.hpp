// From a grid path to a road: G1 smoothing in the corridor, 3-D profile, sections, statistics.
// SPDX-License-Identifier: MIT
#pragma once
#include <string>
#include <vector>

#include "roads/anisotropic_search.hpp"
#include "roads/cost_model.hpp"
#include "roads/terrain_field.hpp"

namespace terrapolis::roads {

/// A road as a 3-D polyline in grid coordinates: points, deck heights (m) and the structure of
/// each segment (segments.size() == points.size() - 1).
struct RoadGeometry {
  std::vector<GridPoint> points;
  std::vector<double> z;
  std::vector<Structure> segments;
};

/// Smooths the grid path of `path` and builds its profile (Peytavie 2010 §4.4.1-4.4.2).
/// Surface runs between structure ends become a G1 spline: straight legs joined at each vertex by
/// a quadratic Bézier whose tangent points are cut back so that the curve stays within
/// `model.smoothing_tolerance_cells` of the vertex (a corridor around the grid path) and its grade
/// does not exceed the road slope threshold; clothoids (curvature linear in arc length) are not fitted.
/// Bridges and tunnels stay straight, their deck linear between the terrain at their ends, sampled
/// at the integration step. Each segment is then classified by the height of the deck above the
/// surface: above `structure_min_m` bridge, below -structure_min_m tunnel, otherwise road.
RoadGeometry build_road_geometry(const TerrainField& terrain, const CostModel& model, const SearchResult& path);

/// A road on the ground along a given polyline (deck = surface); segments over water are bridges.
RoadGeometry surface_geometry(const TerrainField& terrain, const CostModel& model, const std::vector<GridPoint>& polyline);

struct RoadStats {
  double length_m = 0;
  double max_grade_pct = 0;   ///< steepest grade over the segments, %
  double mean_grade_pct = 0;  ///< length-weighted mean absolute grade, %
  double bridge_m = 0, tunnel_m = 0;
};
RoadStats road_stats(const TerrainField& terrain, const RoadGeometry& road);

/// Consecutive segments of one structure.
struct RoadSection {
  std::string structure;  ///< road, bridge, tunnel, ferry
  std::vector<GridPoint> points;
  double length_m = 0;
};
std::vector<RoadSection> road_sections(const TerrainField& terrain, const RoadGeometry& road);

}  // namespace terrapolis::roads
