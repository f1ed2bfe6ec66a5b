// Flooding to a level (Peytavie 2010 §2.4.1) against analytic lakes, ridges and dams.
// SPDX-License-Identifier: MIT
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>

#include "core/error.hpp"
#include "core/geodesy.hpp"
#include "lake/lake.hpp"
#include "support/georefs.hpp"

using namespace terrapolis;
using namespace terrapolis::lake;

namespace {

constexpr double kPi = 3.14159265358979323846;

/// z = k r² about the grid's centre, on square cells of `cell` metres.
Dem paraboloid(int n, double cell, double k) {
  Dem d(n, n, test::projected(cell), 0.0f);
  for (int r = 0; r < n; ++r)
    for (int c = 0; c < n; ++c) {
      const double x = (c + 0.5 - n / 2.0) * cell, y = (r + 0.5 - n / 2.0) * cell;
      d(c, r) = float(k * (x * x + y * y));
    }
  return d;
}

}  // namespace

TEST(Lake, ParaboloidBowlMatchesAnalyticAreaAndVolume) {
  // Level L in z = k r²: a disc of radius sqrt(L/k), area π L / k, volume π L² / (2k).
  const double k = 0.001, level = 10, cell = 1;
  const Dem dem = paraboloid(300, cell, k);
  const CellMetrics m = cell_metrics(dem.georef(), dem.cols(), dem.rows());
  SilentProgress p;
  const Lake lake = flood(dem, m, 150, 150, level, nullptr, p);
  EXPECT_NEAR(lake.area_km2 * 1e6, kPi * level / k, kPi * level / k * 0.002);         // 31,416 m²
  EXPECT_NEAR(lake.volume_m3, kPi * level * level / (2 * k), kPi * level * level / (2 * k) * 0.002);  // 157,080 m³
  EXPECT_NEAR(lake.max_depth_m, level, 0.01);
  EXPECT_FALSE(lake.spills);
  // Depth is level - ground on every flooded cell, NaN elsewhere; the mask agrees.
  for (std::size_t i = 0; i < dem.size(); ++i) {
    if (lake.mask[i] == 1) EXPECT_FLOAT_EQ(lake.depth[i], float(level - dem[i]));
    else EXPECT_TRUE(std::isnan(lake.depth[i]));
  }
}

TEST(Lake, RidgeAboveTheLevelStopsTheFlood) {
  // Two 10 x 10 basins at 0 m, walls at 20 m, split by a ridge at 12 m in column 11.
  Dem dem(23, 12, test::projected(30), 20.0f);
  for (int r = 1; r < 11; ++r)
    for (int c = 1; c < 22; ++c) dem(c, r) = c == 11 ? 12.0f : 0.0f;
  const CellMetrics m = cell_metrics(dem.georef(), dem.cols(), dem.rows());
  SilentProgress p;
  const Lake low = flood(dem, m, 3, 3, 11.5, nullptr, p);
  EXPECT_EQ(low.cells, 100u);  // the west basin only
  EXPECT_NEAR(low.volume_m3, 100 * 900 * 11.5, 1e-6);
  EXPECT_EQ(low.mask(15, 5), 0);
  const Lake high = flood(dem, m, 3, 3, 12.5, nullptr, p);
  EXPECT_EQ(high.cells, 210u);  // over the ridge: both basins and the ridge cells
  EXPECT_NEAR(high.depth(11, 5), 0.5, 1e-6);
  // A gap in the ridge at (11,6) that the west basin touches only by a corner, at (10,5):
  // the propagation is 8-connected (Peytavie's "8 voisins"), so the water goes through.
  Dem corner = dem;
  for (int r = 1; r < 11; ++r) corner(11, r) = 20.0f;
  corner(11, 6) = 0.0f;
  corner(10, 6) = corner(10, 7) = 20.0f;
  EXPECT_EQ(flood(corner, m, 3, 3, 11.5, nullptr, p).cells, 98u + 1u + 100u);
  EXPECT_THROW(flood(dem, m, 11, 5, 11.5, nullptr, p), Error);  // seed on ground above the level
  EXPECT_THROW(flood(dem, m, 30, 5, 11.5, nullptr, p), Error);  // off the grid
}

TEST(Lake, DamHoldsTheReservoirAndLineCellsAre4Connected) {
  // A valley draining east at 1 m per 100 m cell: without a dam, water at 20 m runs off the east edge.
  Dem dem(60, 21, test::projected(100), 0.0f);
  for (int r = 0; r < 21; ++r)
    for (int c = 0; c < 60; ++c) dem(c, r) = float(0.5 * (60 - c) + 5.0 * std::abs(r - 10));
  const CellMetrics m = cell_metrics(dem.georef(), dem.cols(), dem.rows());
  SilentProgress p;
  EXPECT_TRUE(flood(dem, m, 30, 10, 20, nullptr, p).spills);
  // A diagonal dam across the valley, crest 40 m: the water stays west of it.
  Dam dam;
  dam.line = {dem.georef().cell_centre(35, 0), dem.georef().cell_centre(45, 20)};
  dam.crest_m = 40;
  const auto cells = line_cells(dem.georef(), dem.cols(), dem.rows(), dam.line);
  for (std::size_t i = 1; i < cells.size(); ++i) {
    const long dc = std::labs(long(cells[i] % 60) - long(cells[i - 1] % 60)), dr = std::labs(long(cells[i] / 60) - long(cells[i - 1] / 60));
    EXPECT_EQ(dc + dr, 1) << "step " << i;
  }
  const Lake held = flood(dem, m, 30, 10, 20, &dam, p);
  EXPECT_EQ(held.dam_cells, cells.size());
  for (int r = 0; r < 21; ++r)
    for (int c = 46; c < 60; ++c) EXPECT_NE(held.mask(c, r), 1);
  EXPECT_GT(held.cells, 0u);
}

TEST(Lake, GeographicAreaIsTheSumOfEllipsoidalCellAreas) {
  // A flat 0 m grid at 60° N, 0.01° cells, flooded whole: the area is the grid's geodesic area.
  Dem dem(50, 40, test::geographic(60.2, 0.01), 0.0f);
  const CellMetrics m = cell_metrics(dem.georef(), dem.cols(), dem.rows());
  SilentProgress p;
  const Lake lake = flood(dem, m, 10, 10, 1.0, nullptr, p);
  EXPECT_EQ(lake.cells, dem.size());
  EXPECT_NEAR(lake.area_km2, m.total_area_m2(dem.cols()) / 1e6, 1e-9);
  EXPECT_NEAR(lake.volume_m3, m.total_area_m2(dem.cols()), 1e-3);
  EXPECT_TRUE(lake.spills);  // reaches the edge
  // A degree of longitude at 60° is half the one at the equator: the rows' areas say so.
  EXPECT_NEAR(m.area_m2[20] / (0.01 * 111320 * 0.01 * 111320), 0.5, 0.01);
}
