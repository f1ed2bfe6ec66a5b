// Flooding to a level (Peytavie 2010 §2.4.1) against analytic lakes, ridges and dams.
// SPDX-License-Identifier: MIT
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <random>

#include "core/error.hpp"
#include "core/geodesy.hpp"
#include "io/crs.hpp"
#include "lake/lake.hpp"
#include "support/georefs.hpp"
#include "support/windows.hpp"

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

namespace {

/// Random valleys: Gaussian hills and pits over a tilted plane, on a UTM 32N grid of 90 m cells or a
/// WGS 84 grid of 3 seconds, with a few nodata holes.
Dem random_valleys(std::mt19937& rng, bool geographic) {
  Georef g = geographic ? test::geographic(46.5, 1.0 / 1200) : test::projected(90);
  g.crs = crs_from_user(geographic ? "EPSG:4326" : "EPSG:32632");
  const int cols = 700, rows = 600;
  Dem d(cols, rows, g, 0.0f);
  std::uniform_real_distribution<double> u(0, 1);
  struct Bump { double x, y, a, s; };
  std::vector<Bump> bumps(40);
  for (Bump& b : bumps) b = {u(rng) * cols, u(rng) * rows, -300 + 900 * u(rng), 20 + 100 * u(rng)};
  const double tilt_x = u(rng) - 0.5, tilt_y = u(rng) - 0.5;
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) {
      double z = 500 + tilt_x * c + tilt_y * r;
      for (const Bump& b : bumps) z += b.a * std::exp(-((c - b.x) * (c - b.x) + (r - b.y) * (r - b.y)) / (2 * b.s * b.s));
      d(c, r) = float(z);
    }
  for (int h = 0; h < 3; ++h) {  // holes of nodata
    const int c0 = int(u(rng) * (cols - 20)), r0 = int(u(rng) * (rows - 20));
    for (int r = r0; r < r0 + 15; ++r)
      for (int c = c0; c < c0 + 15; ++c) d(c, r) = NAN;
  }
  return d;
}

}  // namespace

TEST(Lake, ByWindowsTheWholeGridsLake) {
  // flood_by_windows reads a window around the seed and grows it until the water stays inside: the
  // same cells, depths, figures and spill as the flood of the whole grid, on random valleys, seeds,
  // depths and dams; some lakes must outgrow the first window, some reach the grid's edge.
  std::mt19937 rng(20261206);
  std::uniform_real_distribution<double> u(0, 1);
  SilentProgress p;
  int grown = 0, spilled = 0, dammed = 0;
  for (int trial = 0; trial < 16; ++trial) {
    const Dem dem = random_valleys(rng, trial % 2 == 1);
    const int cols = dem.cols(), rows = dem.rows();
    const CellMetrics metrics = cell_metrics(dem.georef(), cols, rows);
    const GridLocator locator(dem.georef());
    int col = 0, row = 0;
    do col = int(u(rng) * cols), row = int(u(rng) * rows);
    while (std::isnan(dem(col, row)));
    LakeSpec spec;
    const auto at = locator.cell_lonlat(col, row);
    spec.lon = at[0], spec.lat = at[1];
    spec.depth_m = 5 + 120 * u(rng);
    if (trial % 3 == 0) {  // a dam across the seed's column, 40 cells east
      spec.dam_lonlat = {locator.cell_lonlat(std::min(cols - 1, col + 40), std::max(0, row - 60)),
                         locator.cell_lonlat(std::min(cols - 1, col + 40), std::min(rows - 1, row + 60))};
      spec.crest_m = double(dem(col, row)) + *spec.depth_m + 10;
      ++dammed;
    }
    const Lake whole = flood(dem, metrics, spec, p);
    int reads = 0;
    const WindowLake w = flood_by_windows(
        dem.georef(), cols, rows,
        [&](int c0, int r0, int n, int m) {
          ++reads;
          return test::window_of(dem, c0, r0, n, m);
        },
        spec, dem.size(), p);
    SCOPED_TRACE("trial " + std::to_string(trial));
    EXPECT_EQ(w.lake.cells, whole.cells);
    EXPECT_EQ(w.lake.area_km2, whole.area_km2);
    EXPECT_EQ(w.lake.volume_m3, whole.volume_m3);
    EXPECT_EQ(w.lake.max_depth_m, whole.max_depth_m);
    EXPECT_EQ(w.lake.level_m, whole.level_m);
    EXPECT_EQ(w.lake.spills, whole.spills);
    EXPECT_EQ(w.lake.dam_cells, whole.dam_cells);
    EXPECT_EQ(w.lake.seed_col, col);
    std::size_t mismatches = 0;
    for (int r = 0; r < rows; ++r)
      for (int c = 0; c < cols; ++c) {
        const int x = c - w.col0, y = r - w.row0;
        const bool in = w.lake.mask.inside(x, y) && w.lake.mask(x, y) == 1;
        if (in != (whole.mask(c, r) == 1) || (in && w.lake.depth(x, y) != whole.depth(c, r))) ++mismatches;
      }
    EXPECT_EQ(mismatches, 0u);
    grown += reads > 1;
    spilled += whole.spills;
    // Too little memory for the lake's window is refused, naming the seed.
    if (reads > 1) {
      const auto read = [&](int c0, int r0, int n, int m) { return test::window_of(dem, c0, r0, n, m); };
      EXPECT_THROW(flood_by_windows(dem.georef(), cols, rows, read, spec, 257 * 257, p), Error);
    }
  }
  EXPECT_GE(grown, 3);
  EXPECT_GE(spilled, 2);
  EXPECT_GE(dammed, 5);
}
