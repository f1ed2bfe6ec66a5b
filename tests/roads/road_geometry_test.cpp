// Clothoid corners and road smoothing: curvature linear in arc length, tangency, deviation, ends.
// SPDX-License-Identifier: MIT
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "roads/road_geometry.hpp"
#include "roads_fixtures.hpp"

using namespace terrapolis;
using namespace terrapolis::roads;

namespace {

double distance_to_segment(PlanePoint p, PlanePoint a, PlanePoint b) {
  const double dx = b.x - a.x, dy = b.y - a.y, l2 = dx * dx + dy * dy;
  const double t = l2 > 0 ? std::clamp(((p.x - a.x) * dx + (p.y - a.y) * dy) / l2, 0.0, 1.0) : 0.0;
  return std::hypot(p.x - a.x - t * dx, p.y - a.y - t * dy);
}

double heading(PlanePoint a, PlanePoint b) { return std::atan2(b.y - a.y, b.x - a.x); }

double wrap(double a) {
  while (a > std::numbers::pi) a -= 2 * std::numbers::pi;
  while (a < -std::numbers::pi) a += 2 * std::numbers::pi;
  return a;
}

}  // namespace

TEST(ClothoidCorner, CurvatureIsLinearInArcLengthAndTheCurveIsTangentToBothLegs) {
  for (double turn_deg : {10.0, 45.0, 90.0, 135.0, 170.0}) {
    for (double side : {1.0, -1.0}) {
      const double turn = turn_deg * std::numbers::pi / 180;
      const PlanePoint a{-200, 0}, v{0, 0}, b{150 * std::cos(side * turn), 150 * std::sin(side * turn)};
      const double u = 40;
      const int n = 60;
      const auto pts = clothoid_corner(a, v, b, u, n);
      ASSERT_EQ(pts.size(), std::size_t(2 * n + 1));
      // Ends on the legs, u from the vertex, and tangent to them.
      EXPECT_NEAR(pts.front().x, -u, 1e-9);
      EXPECT_NEAR(pts.front().y, 0, 1e-9);
      EXPECT_NEAR(pts.back().x, u * std::cos(side * turn), 1e-9);
      EXPECT_NEAR(pts.back().y, u * std::sin(side * turn), 1e-9);
      // Evenly spaced in arc length; the spiral length follows from the shape.
      const double spiral = u / clothoid_shape(turn).tangent_per_m;
      const double ds = spiral / n;
      for (std::size_t i = 1; i < pts.size(); ++i)
        EXPECT_NEAR(std::hypot(pts[i].x - pts[i - 1].x, pts[i].y - pts[i - 1].y), ds, 2e-3 * ds) << turn_deg << " " << i;
      // Discrete curvature (turn between chords / chord length) against kappa(s) = turn s / L^2 up to the
      // apex, then back down: linear in arc length, zero at both tangent points.
      const double kmax = turn / spiral;
      for (int i = 1; i < 2 * n; ++i) {
        const double k = wrap(heading(pts[std::size_t(i)], pts[std::size_t(i + 1)]) - heading(pts[std::size_t(i - 1)], pts[std::size_t(i)])) / ds;
        const double s = i <= n ? i * ds : (2 * n - i) * ds;
        if (i == n) continue;  // the apex, where the two spirals meet
        EXPECT_NEAR(side * k, kmax * s / spiral, 0.01 * kmax) << turn_deg << " " << i;
      }
      EXPECT_NEAR(heading(pts[0], pts[1]), 0.0, kmax * ds);                // leaves along a-v
      EXPECT_NEAR(wrap(heading(pts[2 * n - 1], pts[2 * n]) - side * turn), 0.0, kmax * ds);  // joins v-b
      // Never farther from the corner's legs than the apex is from the vertex (the smoothing's bound).
      const double apex = spiral * clothoid_shape(turn).apex_per_m;
      EXPECT_NEAR(std::hypot(pts[std::size_t(n)].x, pts[std::size_t(n)].y), apex, 1e-6 * u);
      for (const PlanePoint& p : pts) EXPECT_LE(std::min(distance_to_segment(p, a, v), distance_to_segment(p, v, b)), apex + 1e-9);
    }
  }
}

TEST(RoadGeometry, ClothoidSmoothingStaysInTheCorridorAndKeepsTheEnds) {
  // Flat ground, 10 m cells: a grid path with turns of 45 to 135 degrees.
  const Dem dem = test::make_dem(40, 40, 10.0, [](int, int) { return 50.0; });
  const TerrainField terrain(dem, 0.0, 10.0, 0.0);
  const CostModel model = default_cost_model();  // tolerance 1 cell
  SearchResult path;
  path.found = true;
  path.cells = {{2, 20}, {7, 20}, {12, 20}, {16, 16}, {20, 12}, {20, 17}, {25, 22}, {30, 22}, {35, 30}};
  path.structures.assign(path.cells.size() - 1, Structure::road);
  const RoadGeometry road = build_road_geometry(terrain, model, path);
  ASSERT_GE(road.points.size(), path.cells.size());
  EXPECT_DOUBLE_EQ(road.points.front().col, 2);
  EXPECT_DOUBLE_EQ(road.points.front().row, 20);
  EXPECT_DOUBLE_EQ(road.points.back().col, 35);
  EXPECT_DOUBLE_EQ(road.points.back().row, 30);
  const double tol_m = model.smoothing_tolerance_cells * 10.0;
  int curved = 0;
  for (const GridPoint& p : road.points) {
    double d = 1e300;
    for (std::size_t i = 1; i < path.cells.size(); ++i)
      d = std::min(d, distance_to_segment({p.col * 10, p.row * 10}, {path.cells[i - 1].col * 10.0, path.cells[i - 1].row * 10.0},
                                          {path.cells[i].col * 10.0, path.cells[i].row * 10.0}));
    EXPECT_LE(d, tol_m + 1e-6) << p.col << "," << p.row;
    if (d > 0.5) ++curved;
  }
  EXPECT_GT(curved, 10);  // the corners were rounded
  for (Structure s : road.segments) EXPECT_EQ(s, Structure::road);
  // No corner left: every bend (45 to 135 degrees here) is spread over at least 8 samples.
  for (std::size_t i = 2; i < road.points.size(); ++i) {
    const PlanePoint p0{road.points[i - 2].col, road.points[i - 2].row}, p1{road.points[i - 1].col, road.points[i - 1].row},
        p2{road.points[i].col, road.points[i].row};
    if (std::hypot(p1.x - p0.x, p1.y - p0.y) < 1e-9 || std::hypot(p2.x - p1.x, p2.y - p1.y) < 1e-9) continue;
    EXPECT_LT(std::fabs(wrap(heading(p1, p2) - heading(p0, p1))), 0.35) << i;
  }
}

TEST(RoadGeometry, NoRoadSteeperThanTheSlopeThresholdOnACone) {
  // A cone 30 deg steep (twice the 15 deg threshold) with a rounded cap and a bumpy skirt: roads
  // across it must wind up and around; neither their smoothing nor the structures' ends may leave
  // the threshold the search kept to (grades are measured on the built geometry, deck included).
  const Dem dem = test::make_dem(64, 64, 10.0, [](int c, int r) {
    const double d = std::hypot(c - 31.5, r - 31.5) * 10.0;
    return 20.0 + std::max(0.0, 250.0 - d * std::tan(30.0 * std::numbers::pi / 180)) + 3.0 * std::sin(c * 0.9) * std::cos(r * 0.7);
  });
  const TerrainField terrain(dem, 0.0, 10.0, 0.0);
  for (const bool structures : {false, true}) {
    CostModel model = default_cost_model();
    model.bridge.enabled = model.tunnel.enabled = structures;
    const RoadGraph graph(terrain, model, {5, 8, 7});
    const double limit_pct = 100.0 * std::tan(model.road.slope_deg.threshold * std::numbers::pi / 180);
    int routed = 0;
    for (const auto& [a, b] : std::vector<std::pair<Cell, Cell>>{{{2, 31}, {61, 33}}, {{31, 2}, {33, 61}}, {{5, 5}, {58, 58}}, {{31, 20}, {60, 40}}}) {
      const SearchResult path = shortest_path(graph, a, b, SearchMethod::astar);
      if (!path.found) continue;
      ++routed;
      const RoadGeometry road = build_road_geometry(terrain, model, path);
      EXPECT_LE(road_stats(terrain, model, road).max_grade_pct, limit_pct + 1e-6) << a.col << "," << a.row << " structures " << structures;
    }
    EXPECT_GE(routed, 3);
  }
}
