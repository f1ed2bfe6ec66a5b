// Belhadj's hydrometry tile by tile equals the whole grid's bit for bit (docs/scale.md).
// SPDX-License-Identifier: MIT
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <random>

#include "core/error.hpp"
#include "core/geodesy.hpp"
#include "hydro/tiled/tiled_belhadj.hpp"
#include "hydro/tiled/tiled_hydro.hpp"
#include "support/georefs.hpp"

namespace terrapolis::hydro::tiled {
namespace {

/// Integer altitudes (as SRTM's) on a geographic grid at 47 N: a sea to the west, valleys and a
/// flat basin that hold water for many steps, nodata holes.
Dem landscape(unsigned seed, int cols, int rows) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  Dem dem(cols, rows, test::geographic(47.2, 1.0 / 1200));  // 3" cells
  const double p = u(rng) * 6;
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) {
      const double x = double(c) / cols, y = double(r) / rows;
      double z = 600 * x - 60 + 120 * std::sin(11 * x + p) * std::cos(8 * y) + 6 * u(rng);
      if (std::hypot(x - 0.6, y - 0.5) < 0.15) z = 200;  // a dead-level basin floor
      dem(c, r) = float(std::round(z));
      if (u(rng) < 0.005) dem(c, r) = std::numeric_limits<float>::quiet_NaN();
    }
  return dem;
}

std::string scratch() {
  const auto dir = std::filesystem::temp_directory_path() / ("tp_belhadj_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) +
                                                             "_" + ::testing::UnitTest::GetInstance()->current_test_info()->name());
  return dir.string();
}

/// Runs both and compares every cell's bits; returns the tiled report.
TiledBelhadjReport expect_same(const Dem& dem, const BelhadjOptions& options, int tile_size) {
  SilentProgress quiet;
  const BelhadjRun whole = belhadj_hydrometry(dem, cell_metrics(dem.georef(), dem.cols(), dem.rows()), options, quiet);
  Raster<float> tiled = dem.like<float>(-7.0f);
  int reads = 0;
  const std::string dir = scratch();
  const TiledBelhadjReport report = run_tiled_belhadj(
      dem.cols(), dem.rows(), dem.georef(),
      [&](int c0, int r0, int cols, int rows) {
        EXPECT_TRUE(c0 >= 0 && r0 >= 0 && c0 + cols <= dem.cols() && r0 + rows <= dem.rows());
        ++reads;
        Dem w(cols, rows, shifted(dem.georef(), c0, r0));
        for (int y = 0; y < rows; ++y) std::memcpy(&w(0, y), &dem(c0, r0 + y), sizeof(float) * std::size_t(cols));
        return w;
      },
      options, tile_size, 0, dir,
      [&](int t, int, const Raster<float>& tile) {
        const GeoTransform& a = tile.georef().transform;
        const GeoTransform& g = dem.georef().transform;
        const int c0 = int(std::lround((a[0] - g[0]) / g[1])), r0 = int(std::lround((a[3] - g[3]) / g[5]));
        EXPECT_GE(t, 0);
        for (int y = 0; y < tile.rows(); ++y) std::memcpy(&tiled(c0, r0 + y), &tile(0, y), sizeof(float) * std::size_t(tile.cols()));
      },
      quiet);
  EXPECT_EQ(report.iterations, whole.iterations);
  EXPECT_NEAR(report.final_mean, whole.final_mean, 1e-12 * whole.final_mean);  // summed in another order
  std::size_t differ = 0, first = 0;
  for (std::size_t i = 0; i < dem.size(); ++i)
    if (std::memcmp(&tiled[i], &whole.hydrometry[i], sizeof(float)) != 0 && differ++ == 0) first = i;
  EXPECT_EQ(differ, 0u) << "cells that differ from the whole grid, the first at " << first % std::size_t(dem.cols()) << ","
                        << first / std::size_t(dem.cols()) << ": " << tiled[first] << " for " << whole.hydrometry[first];
  EXPECT_TRUE(!std::filesystem::exists(dir) || std::filesystem::is_empty(dir)) << "the Acc of the tiles was left behind";
  std::filesystem::remove_all(dir);
  EXPECT_GT(reads, report.tiles);
  return report;
}

TEST(TiledBelhadj, UntilConvergenceOnManyTilesEqualsTheWholeGrid) {
  const Dem dem = landscape(1, 173, 131);
  BelhadjOptions o;
  o.sea_level = 0.0;
  const TiledBelhadjReport r = expect_same(dem, o, 40);
  EXPECT_GE(r.tiles, 12);
  EXPECT_GT(r.iterations, 5);
  EXPECT_EQ(r.halo, r.iterations + 2);
}

TEST(TiledBelhadj, FedShareNeedsSeveralSearchesForItsStop) {
  // Water gathers in the basin instead of leaving: more than the first pass's 32 steps. The grid is
  // wider than two halos of 72 cells and a tile, so that the halo is what makes the tiles exact.
  const Dem dem = landscape(2, 260, 230);
  BelhadjOptions o;
  o.share = BelhadjShare::fed_neighbours;
  o.sea_level = 0.0;
  o.threshold = 1e-3;
  o.max_iterations = 70;
  const TiledBelhadjReport r = expect_same(dem, o, 33);
  EXPECT_GE(r.searches, 2);
  EXPECT_GT(r.iterations, 32);
}

TEST(TiledBelhadj, ThesisUnitsNoSeaAndFixedIterations) {
  const Dem dem = landscape(3, 90, 140);
  BelhadjOptions o;
  o.vertical = VerticalScale::normalised16;
  o.max_iterations = 9;
  const TiledBelhadjReport r = expect_same(dem, o, 25);
  EXPECT_EQ(r.iterations, 9);
  EXPECT_EQ(r.searches, 1);
}

TEST(TiledBelhadj, OneTileAndRefusals) {
  const Dem dem = landscape(4, 60, 50);
  BelhadjOptions o;
  o.sea_level = 0.0;
  EXPECT_EQ(expect_same(dem, o, 500).tiles, 1);
  SilentProgress quiet;
  auto run = [&](const Dem& d, const BelhadjOptions& opt, double limit_mb) {
    return run_tiled_belhadj(d.cols(), d.rows(), d.georef(), [&](int c0, int r0, int cols, int rows) {
      Dem w(cols, rows, shifted(d.georef(), c0, r0));
      for (int y = 0; y < rows; ++y) std::memcpy(&w(0, y), &d(c0, r0 + y), sizeof(float) * std::size_t(cols));
      return w;
    }, opt, 0, limit_mb, scratch(), [](int, int, const Raster<float>&) {}, quiet);
  };
  // A halo of 162 cells (the safety cap) does not fit 1 MB.
  EXPECT_THROW(run(dem, o, 1), Error);
  Dem sea = dem;
  for (float& v : sea.values()) v = -3;
  EXPECT_THROW(run(sea, o, 100), Error);
}

}  // namespace
}  // namespace terrapolis::hydro::tiled
