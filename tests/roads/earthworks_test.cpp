// Cut-and-fill along roads: levelled under the carriageway, side slopes bounded, structures untouched.
// SPDX-License-Identifier: MIT
#include <gtest/gtest.h>

#include <cmath>

#include "roads/earthworks.hpp"
#include "roads_fixtures.hpp"

using namespace terrapolis;
using namespace terrapolis::roads;

namespace {
/// A straight road along row 20 (a contour line of a hillside rising 10 m per 10 m cell southwards).
RoadGeometry contour_road(const TerrainField& t, int c0, int c1, double row) {
  RoadGeometry g;
  for (int c = c0; c <= c1; ++c) {
    g.points.push_back({double(c), row});
    g.z.push_back(t.surface_at(c, row));
  }
  g.segments.assign(g.points.size() - 1, Structure::road);
  return g;
}
}  // namespace

TEST(Earthworks, LevelledUnderTheRoadAndSideSlopesBounded) {
  const Dem dem = test::make_dem(40, 40, 10.0, [](int, int r) { return 100.0 + 10.0 * r; });
  const TerrainField terrain(dem, 0.0, 10.0, 0.0);
  const RoadGeometry road = contour_road(terrain, 5, 35, 20.3);
  const EarthworkOptions o;  // half-width 4 m, sides 2:3
  const Dem out = earthworks(dem, terrain, {&road}, o);
  const double deck = 100.0 + 10.0 * 20.3;
  for (int r = 0; r < 40; ++r)
    for (int c = 0; c < 40; ++c) {
      // Hand computation: distance to the centreline, nearest point of the segment run.
      const double dx = c < 5 ? (5 - c) * 10.0 : c > 35 ? (c - 35) * 10.0 : 0.0;
      const double d = std::hypot(dx, (r - 20.3) * 10.0);
      const double allowed = std::max(0.0, d - o.half_width_m) / o.side_slope;
      const double z = dem(c, r);
      if (d > o.half_width_m + o.side_slope * o.max_height_m) {
        EXPECT_EQ(out(c, r), dem(c, r)) << c << "," << r;
        continue;
      }
      EXPECT_NEAR(out(c, r), std::clamp(z, deck - allowed, deck + allowed), 1e-3) << c << "," << r;
    }
  // Row 20 lies 3 m from the centreline: levelled (filled 3 m); row 21, 7 m away, cut by 5 m only.
  EXPECT_NEAR(out(20, 20), deck, 1e-3);
  EXPECT_NEAR(out(20, 21), deck + 3.0 / 1.5, 1e-3);
}

TEST(Earthworks, StructuresUntouchedAndOrderIndependent) {
  const Dem dem = test::make_dem(40, 40, 10.0, [](int c, int r) { return 100.0 + 10.0 * r + 3.0 * std::sin(c); });
  const TerrainField terrain(dem, 0.0, 10.0, 0.0);
  RoadGeometry a = contour_road(terrain, 2, 20, 10.4), b = contour_road(terrain, 10, 30, 13.6);
  for (std::size_t i = 0; i < a.segments.size(); ++i)
    if (i >= 12) a.segments[i] = Structure::bridge;  // the east part of road a is a bridge
  const Dem one = earthworks(dem, terrain, {&a, &b}), two = earthworks(dem, terrain, {&b, &a});
  for (std::size_t k = 0; k < dem.size(); ++k) EXPECT_EQ(one[k], two[k]);
  // Under the bridge (cols 15..20, rows 10..11) and far from road b: the ground is kept.
  const Dem only_a = earthworks(dem, terrain, {&a});
  EXPECT_EQ(only_a(18, 10), dem(18, 10));
  EXPECT_NE(only_a(5, 10), dem(5, 10));
}
