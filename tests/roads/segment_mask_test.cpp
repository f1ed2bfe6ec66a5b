// Segment masks: sizes of Peytavie's table 4.1, nesting, no collinear arcs.
// SPDX-License-Identifier: MIT
#include <gtest/gtest.h>

#include <cmath>
#include <numeric>
#include <set>

#include "roads/segment_mask.hpp"

using namespace terrapolis::roads;

TEST(SegmentMask, SizesMatchTheThesisTable) {
  const int expected[] = {8, 16, 32, 48, 80, 96, 144, 176, 224, 256};
  for (int k = 1; k <= 10; ++k) EXPECT_EQ(segment_mask(k).size(), std::size_t(expected[k - 1])) << "k = " << k;
  EXPECT_EQ(segment_mask(11).size(), 336u);
}

TEST(SegmentMask, NestedAndNoCollinearArcs) {
  for (int k = 1; k < 8; ++k) {
    const auto small = segment_mask(k), big = segment_mask(k + 1);
    std::set<std::pair<int, int>> b;
    for (const auto& a : big) b.insert({a.dcol, a.drow});
    for (const auto& a : small) EXPECT_TRUE(b.count({a.dcol, a.drow})) << k;
    std::set<long> angles;
    for (const auto& a : big) {
      EXPECT_EQ(std::gcd(std::abs(a.dcol), std::abs(a.drow)), 1);
      angles.insert(std::lround(a.angle_rad * 1e9));
    }
    EXPECT_EQ(angles.size(), big.size());  // no two arcs share a direction
  }
  EXPECT_THROW(segment_mask(0), std::exception);
}

TEST(SegmentMask, AnnulusHoldsTheCellsBetweenTheRadii) {
  const auto ring = annulus_mask(5, 30);
  // The thesis counts rho = 2728 cells between 50 and 300 m on a 10 m grid.
  EXPECT_NEAR(double(ring.size()), 2728.0, 60.0);
  for (const auto& a : ring) {
    const double d = std::hypot(a.dcol, a.drow);
    EXPECT_GE(d, 5.0);
    EXPECT_LE(d, 30.0);
  }
}
