// The lakes a DEM flattens, found tile by tile: the whole grid's mask cell for cell (docs/scale.md).
// SPDX-License-Identifier: MIT
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>

#include "hydro/flat_water.hpp"
#include "hydro/tiled/tiled_flat_water.hpp"
#include "support/georefs.hpp"

namespace terrapolis::hydro::tiled {
namespace {

/// Integer altitudes on a geographic grid (3" cells at 47 N): a noisy slope towards a sea in the
/// west, level lakes in basins (one crossing many tiles, two close together), a dead-level valley
/// floor open downstream (not a lake), small flats, nodata holes. `tolerance`: lakes get +-1 m
/// ripples so that only a 1 m tolerance sees them level.
Dem landscape(unsigned seed, int cols, int rows, bool ripples) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  Dem dem(cols, rows, test::geographic(47.3, 1.0 / 1200));
  struct Lake { double c, r, radius, level; };
  std::vector<Lake> lakes = {{cols * 0.5, rows * 0.5, rows * 0.3, 300},
                             {cols * (0.15 + 0.1 * u(rng)), rows * 0.2, 9, 240},
                             {cols * (0.15 + 0.1 * u(rng)) + 21, rows * 0.2, 9, 240},
                             {cols * 0.85, rows * 0.85, 5, 400}};
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) {
      double z = 20 + 5.0 * c + 40 * std::sin(r * 0.11) + std::floor(6 * u(rng));
      for (const Lake& l : lakes) {
        const double d = std::hypot(c - l.c, r - l.r);
        if (d <= l.radius) z = l.level + (ripples ? double(int(u(rng) * 3) - 1) * 0.5 : 0.0);
        else if (d <= l.radius + 4) z = std::max(z, l.level + 2 + 3 * (d - l.radius));  // the shore rises
      }
      if (r > rows * 0.8 && r < rows * 0.8 + 6 && c < cols * 0.6) z = 180 - c * 0.0;  // a level floor running off west
      if (c < 4) z = -2;                                                                 // the sea
      dem(c, r) = float(std::round(z * 2) / 2);
      if (u(rng) < 0.003) dem(c, r) = std::numeric_limits<float>::quiet_NaN();
    }
  return dem;
}

void expect_same(const Dem& dem, const FlatWaterOptions& options, int tile_size) {
  const FlatWater whole = detect_flat_water(dem, options);
  Raster<std::uint8_t> tiled = dem.like<std::uint8_t>(7);
  SilentProgress quiet;
  const TiledFlatWaterReport report = run_tiled_flat_water(
      dem.cols(), dem.rows(), dem.georef(),
      [&](int c0, int r0, int cols, int rows) {
        EXPECT_TRUE(c0 >= 0 && r0 >= 0 && c0 + cols <= dem.cols() && r0 + rows <= dem.rows());
        Dem w(cols, rows, shifted(dem.georef(), c0, r0));
        for (int y = 0; y < rows; ++y) std::memcpy(&w(0, y), &dem(c0, r0 + y), sizeof(float) * std::size_t(cols));
        return w;
      },
      options, tile_size,
      [&](int, int, const Raster<std::uint8_t>& tile) {
        const GeoTransform& a = tile.georef().transform;
        const GeoTransform& g = dem.georef().transform;
        const int c0 = int(std::lround((a[0] - g[0]) / g[1])), r0 = int(std::lround((a[3] - g[3]) / g[5]));
        for (int y = 0; y < tile.rows(); ++y)
          for (int x = 0; x < tile.cols(); ++x) tiled(c0 + x, r0 + y) = tile(x, y);
      },
      quiet);
  std::size_t differ = 0, water = 0;
  for (std::size_t i = 0; i < dem.size(); ++i) {
    differ += tiled[i] != whole.mask[i];
    water += whole.mask[i];
  }
  EXPECT_EQ(differ, 0u) << "cells that differ from the whole grid's mask (" << water << " water cells), tiles of " << tile_size;
  EXPECT_EQ(report.lakes, whole.lakes);
  EXPECT_NEAR(report.area_km2, whole.area_km2, 1e-9 * (1 + whole.area_km2));
}

TEST(TiledFlatWater, LakesAcrossTilesEqualTheWholeGrid) {
  const Dem dem = landscape(1, 160, 120, false);
  const FlatWaterOptions o{0.3, 0.0, 0.0};
  const FlatWater whole = detect_flat_water(dem, o);
  ASSERT_GE(whole.lakes, 3u);  // the big lake and the two close ones; the valley floor is refused
  for (const int tile : {8, 11, 17, 40, 64, 500}) expect_same(dem, o, tile);
}

TEST(TiledFlatWater, ToleranceSmallLakesAndOff) {
  const Dem dem = landscape(2, 131, 97, true);
  EXPECT_EQ(detect_flat_water(dem, {0.3, 0.0, 0.0}).lakes, 0u);  // rippled: level only within 1 m
  const FlatWaterOptions o{0.3, 1.0, 0.0};
  ASSERT_GE(detect_flat_water(dem, o).lakes, 2u);
  for (const int tile : {9, 23, 50}) expect_same(dem, o, tile);
  expect_same(dem, {0.02, 0.0, 0.0}, 13);  // small flats count too
  expect_same(dem, {0.0, 0.0, 0.0}, 13);   // off
}

TEST(TiledFlatWater, RandomLandscapes) {
  for (unsigned seed = 10; seed < 16; ++seed) {
    const Dem dem = landscape(seed, 70 + int(seed) * 7, 60 + int(seed) * 5, seed % 2 == 1);
    expect_same(dem, {0.1, seed % 2 == 1 ? 1.0 : 0.0, 0.0}, 8 + int(seed));
  }
}

}  // namespace
}  // namespace terrapolis::hydro::tiled
