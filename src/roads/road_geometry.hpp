// From a grid path to a road: clothoid smoothing in the corridor, 3-D profile, sections, statistics.
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
  /// How the corners of the surface runs were rounded: clothoid pairs, G1 fallback, left sharp.
  int clothoid_corners = 0, g1_corners = 0, sharp_corners = 0;
  /// Corners whose curve is tighter than model.min_curve_radius_m (short legs or a steep slope
  /// left no room), sharp corners included.
  int tight_corners = 0;
  /// Surface runs left as the grid path because their smoothed curve broke the slope threshold.
  int unsmoothed_runs = 0;
};

/// A point of a local metric plane (metres).
struct PlanePoint {
  double x = 0, y = 0;
};

/// The corner a-v-b rounded by a symmetric pair of clothoids (Euler spirals: curvature linear in
/// arc length, from 0 at the tangent points to its maximum at the apex, then back to 0), as road
/// engineers join two straights (Peytavie 2010 §4.4.1; Galin et al. 2010; McCrae & Singh 2009).
/// The spirals start `tangent_m` before v on a-v and end `tangent_m` after v on v-b, tangent to
/// both legs, so the road is G2 (continuous curvature) with the straights. Returns
/// 2 * samples + 1 points evenly spaced in arc length, the tangent points first and last.
/// `tangent_m` > 0, a != v != b, the turn below 180 degrees.
std::vector<PlanePoint> clothoid_corner(PlanePoint a, PlanePoint v, PlanePoint b, double tangent_m, int samples);

/// For a turn of `turn_rad` (0..pi) rounded by clothoid_corner: the tangent length and the
/// distance from the vertex to the apex (the curve's farthest point from the corner), both per
/// metre of spiral length.
struct ClothoidShape {
  double tangent_per_m = 1, apex_per_m = 0;
};
ClothoidShape clothoid_shape(double turn_rad);

/// Smooths the grid path of `path` and builds its profile (Peytavie 2010 §4.4.1-4.4.2).
/// Surface runs between structure ends become straight legs joined at each vertex by a clothoid
/// pair (clothoid_corner) whose tangent length is cut back so that the curve stays within
/// `model.smoothing_tolerance_cells` of the vertex (a corridor around the grid path), the legs are
/// shared with the neighbouring corners, and its grade does not exceed the road slope threshold.
/// Where no clothoid passes the grade check, a quadratic Bézier (G1) is tried the same way, and
/// failing that the corner stays sharp.
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
  double grade_limit_pct = 0;        ///< the model's road slope threshold as a grade (the class's design limit)
  double over_limit_m = 0;           ///< surface length steeper than grade_limit_pct
  double longest_over_limit_m = 0;   ///< the longest run of such surface segments
  double water_m = 0;                ///< surface length on water (no bridge)
};
/// Statistics of a road; the grade limit is `model`'s road slope threshold.
RoadStats road_stats(const TerrainField& terrain, const CostModel& model, const RoadGeometry& road);

/// Consecutive segments of one structure.
struct RoadSection {
  std::string structure;  ///< road, bridge, tunnel, ferry
  std::vector<GridPoint> points;
  double length_m = 0;
};
std::vector<RoadSection> road_sections(const TerrainField& terrain, const RoadGeometry& road);

}  // namespace terrapolis::roads
