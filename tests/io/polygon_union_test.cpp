// Unions of polygons (GEOS through OGR): overlaps counted once, invalid pieces repaired, not refused.
// SPDX-License-Identifier: MIT
#include <gtest/gtest.h>

#include "core/polygon_area.hpp"
#include "io/polygon_union.hpp"

using namespace terrapolis;

namespace {

Polygon square(double x0, double y0, double side) { return {{{{x0, y0}, {x0 + side, y0}, {x0 + side, y0 + side}, {x0, y0 + side}}}}; }

Crs metres() {
  Crs crs;
  crs.wkt = "projected";
  return crs;
}

}  // namespace

TEST(PolygonUnion, OverlapsCountOnce) {
  const std::vector<Polygon> united = polygon_union({square(0, 0, 10), square(5, 0, 10)});
  ASSERT_EQ(united.size(), 1u);
  EXPECT_NEAR(polygons_area_m2(metres(), united), 150.0, 1e-9);
}

TEST(PolygonUnion, ARingCrossingItselfIsRepairedNotRefused) {
  // A bow tie (two triangles of 25 m² meeting at (5, 5)) beside a square: GEOS refuses to unite the
  // invalid ring as it is; repaired, its two triangles are kept, and the square overlapping one of
  // them counts once (a corridor's swept piece folded at rounding's scale once failed a whole run).
  const Polygon bow_tie{{{{0, 0}, {10, 10}, {10, 0}, {0, 10}}}};
  const std::vector<Polygon> united = polygon_union({bow_tie, square(8, 4, 4)});
  ASSERT_FALSE(united.empty());
  // Triangles (0,0)-(5,5)-(0,10) and (10,0)-(10,10)-(5,5): 25 m² each; the square [8, 12] x [4, 8]
  // overlaps the right one over x in [8, 10] where the triangle spans |y - 5| <= x - 5.
  const double overlap = 2.0 * 4.0;  // the triangle holds [4, 8] of y for every x in [8, 10]
  EXPECT_NEAR(polygons_area_m2(metres(), united), 25 + 25 + 16 - overlap, 1e-9);
}
