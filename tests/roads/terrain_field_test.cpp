// TerrainField helpers: the inlined nearest cell rounds exactly as std::lround.
// SPDX-License-Identifier: MIT
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "roads/terrain_field.hpp"

using terrapolis::roads::nearest_cell;

TEST(TerrainField, NearestCellRoundsAsLround) {
  for (double x : {0.0, -0.0, 0.5, -0.5, 1.5, -1.5, 2.5, 0.49999999999999994, -0.49999999999999994, 1200.5, 1e9 + 0.5,
                   std::nextafter(0.5, 0.0), std::nextafter(2.5, 3.0), std::nextafter(-2.5, -3.0)})
    EXPECT_EQ(nearest_cell(x), std::lround(x)) << x;
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-5000, 5000);
  for (int i = 0; i < 100000; ++i) {
    const double x = u(rng), half = std::floor(x) + 0.5;  // values and exact halves
    ASSERT_EQ(nearest_cell(x), std::lround(x)) << x;
    ASSERT_EQ(nearest_cell(half), std::lround(half)) << half;
  }
}
