// The density model tile by tile equals the whole grid bit for bit (docs/scale.md).
// SPDX-License-Identifier: MIT
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <algorithm>
#include <random>

#include "core/error.hpp"
#include "density/tiled_density.hpp"
#include "hydro/tiled/tiled_hydro.hpp"
#include "support/georefs.hpp"

namespace terrapolis::density {
namespace {

constexpr float nan_f = std::numeric_limits<float>::quiet_NaN();

/// Integer altitudes (as SRTM's) on a geographic grid at 60 N (discs 2:1 in columns): a sea to
/// the west, hills, a plateau above 400 m, cliffs, nodata holes, and a lake in the water mask.
struct Landscape {
  Dem dem;
  Raster<float> hydrometry;
  Raster<std::uint8_t> lake, excluded, rivers;
};

Landscape landscape(unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  Landscape l;
  l.dem = Dem(150, 110, test::geographic(60.4, 1.0 / 240));  // 15" cells: ~230 x 460 m
  l.hydrometry = l.dem.like<float>(0);
  l.lake = l.dem.like<std::uint8_t>(0);
  l.excluded = l.dem.like<std::uint8_t>(0);
  l.rivers = l.dem.like<std::uint8_t>(0);
  const double p1 = u(rng) * 6, p2 = u(rng) * 6;
  for (int r = 0; r < l.dem.rows(); ++r)
    for (int c = 0; c < l.dem.cols(); ++c) {
      const double x = c / 150.0, y = r / 110.0;
      double z = 900 * x - 120 + 260 * std::sin(9 * x + p1) * std::cos(7 * y + p2) + 40 * u(rng);
      if (x > 0.55 && y > 0.3 && y < 0.7) z = std::max(z, 450.0 + 5 * std::floor(u(rng) * 3));  // a plateau with steps
      l.dem(c, r) = float(std::round(std::max(z, -5.0)));
      if (u(rng) < 0.01 || (std::hypot(c - 100, r - 20) < 4)) l.dem(c, r) = nan_f;
      l.hydrometry(c, r) = float(u(rng));
      if (std::hypot(c - 70, r - 80) < 6) l.lake(c, r) = 1;
      if (c > 120 && r > 90) l.excluded(c, r) = 1;
      if (std::abs(r - 55 - int(20 * std::sin(c / 17.0 + p1))) < 1 && c > 30) l.rivers(c, r) = u(rng) < 0.5 ? 1 : 7;  // a river of two codes
    }
  return l;
}

template <class T>
Raster<T> window_of(const Raster<T>& r, int c0, int r0, int cols, int rows) {
  Raster<T> w(cols, rows, hydro::tiled::shifted(r.georef(), c0, r0));
  for (int y = 0; y < rows; ++y) std::memcpy(&w(0, y), &r(c0, r0 + y), sizeof(T) * std::size_t(cols));
  return w;
}

template <class T>
void expect_same_bits(const Raster<T>& whole, const std::vector<Raster<T>>& tiles, const std::vector<Window>& rects, const char* what) {
  std::size_t differ = 0;
  for (std::size_t t = 0; t < tiles.size(); ++t)
    for (int y = 0; y < rects[t].rows; ++y)
      differ += std::memcmp(&whole(rects[t].x0, rects[t].y0 + y), &tiles[t](0, y), sizeof(T) * std::size_t(rects[t].cols)) != 0;
  EXPECT_EQ(differ, 0u) << what << ": rows of tiles that differ from the whole grid";
}

void check_tiles_equal_whole(const Landscape& l, const DensityOptions& options, int tile_size, bool rivers = false) {
  SilentProgress quiet;
  DensityOptions whole_options = options;
  whole_options.water_mask = l.lake;
  whole_options.exclusion_masks = {l.excluded};
  if (rivers) whole_options.rivers = l.rivers;
  const DensityResult whole = compute_density(l.dem, l.hydrometry, whole_options, quiet);
  std::vector<Window> rects;
  std::vector<DensityResult> tiles;
  auto read = [&](int c0, int r0, int cols, int rows, bool) {
    EXPECT_TRUE(c0 >= 0 && r0 >= 0 && c0 + cols <= l.dem.cols() && r0 + rows <= l.dem.rows());
    WindowInputs in{window_of(l.dem, c0, r0, cols, rows), window_of(l.hydrometry, c0, r0, cols, rows), options};
    in.options.water_mask = window_of(l.lake, c0, r0, cols, rows);
    in.options.exclusion_masks = {window_of(l.excluded, c0, r0, cols, rows)};
    if (rivers) in.options.rivers = window_of(l.rivers, c0, r0, cols, rows);
    return in;
  };
  const TiledDensityReport report = run_tiled_density(
      l.dem.cols(), l.dem.rows(), l.dem.georef(), read, options, tile_size, 0, ::testing::TempDir(),
      [&](int, int, const DensityResult& tile) {
        const GeoTransform& t = tile.density.georef().transform;
        const GeoTransform& g = l.dem.georef().transform;
        rects.push_back({int(std::lround((t[0] - g[0]) / g[1])), int(std::lround((t[3] - g[3]) / g[5])), tile.density.cols(), tile.density.rows()});
        tiles.push_back(tile);
      },
      quiet);
  ASSERT_EQ(int(tiles.size()), report.tiles);
  EXPECT_GE(report.tiles, tile_size < 60 ? 6 : 1);
  // The halo follows the latitude: more columns than rows (cells twice as tall as wide at 60 N).
  EXPECT_GT(report.halo_cols, report.halo_rows);
  auto layer = [&](auto member) {
    std::vector<std::decay_t<decltype(whole.*member)>> v;
    for (const auto& t : tiles) v.push_back(t.*member);
    return v;
  };
  expect_same_bits(whole.coast, layer(&DensityResult::coast), rects, "coast");
  expect_same_bits(whole.plateau, layer(&DensityResult::plateau), rects, "plateau");
  expect_same_bits(whole.plain, layer(&DensityResult::plain), rects, "plain");
  expect_same_bits(whole.hydrometry, layer(&DensityResult::hydrometry), rects, "hydrometry");
  expect_same_bits(whole.density, layer(&DensityResult::density), rects, "density");
  expect_same_bits(whole.buildable, layer(&DensityResult::buildable), rects, "buildable");
  if (needs_terrain_terms(options))
    for (std::size_t k = 0; k < kTerrainCount; ++k) {
      std::vector<Raster<float>> terms;
      for (const auto& t : tiles) terms.push_back(t.terrain[k]);
      expect_same_bits(whole.terrain[k], terms, rects, kTerrainTerms[k]);
    }
  const DensityStats &a = whole.stats, &b = report.stats;
  EXPECT_EQ(a.cells, b.cells);
  EXPECT_EQ(a.known_cells, b.known_cells);
  EXPECT_EQ(a.water_cells, b.water_cells);
  EXPECT_EQ(a.buildable_cells, b.buildable_cells);
  EXPECT_EQ(a.histogram, b.histogram);
  EXPECT_EQ(a.coast_max, b.coast_max);
  EXPECT_EQ(a.plateau_max, b.plateau_max);
  EXPECT_NEAR(a.mean_density, b.mean_density, 1e-12);
  EXPECT_NEAR(a.land_area_km2, b.land_area_km2, 1e-9 * a.land_area_km2);
  EXPECT_GT(a.water_cells, 100u);
  EXPECT_GT(a.buildable_cells, 1000u);
}

DensityOptions test_options() {
  DensityOptions o;
  o.r_min_m = 600;
  o.r_max_m = 4000;
  o.max_slope_deg = 20;
  o.river_bed_cap = 0.97;
  o.plain_max_variation_m = 60;
  return o;
}

TEST(TiledDensity, TilesEqualTheWholeGridBitForBit) {
  const Landscape l = landscape(3);
  for (int tile : {9, 23, 40, 64, 200}) {
    SCOPED_TRACE(tile);
    check_tiles_equal_whole(l, test_options(), tile);
  }
}

TEST(TiledDensity, BandedDiscsNodataIsSeaAndThreads) {
  const Landscape l = landscape(11);
  DensityOptions o = test_options();
  o.ring_bands = 4;  // discs of more rows than bands: banded shapes
  o.nodata_is_sea = true;
  o.weights = {-1, 0.5, 1.5, 1};
  for (int threads : {1, 2}) {
    SCOPED_TRACE(threads);
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, std::size_t(threads));
    check_tiles_equal_whole(l, o, 31);
  }
}

TEST(TiledDensity, TileSizeFromMemoryLimit) {
  // 64 bytes a window cell: a 1 MB limit holds 15 625 cells, (89 + 2 x 10) x (89 + 2 x 20) (sides
  // tried in steps of 7/8 from 32768: 102 is too large).
  EXPECT_EQ(density_tile_size_for(10000, 10000, 10, 20, 0, 1.0), 89);
  EXPECT_THROW(density_tile_size_for(10000, 10000, 60, 60, 0, 1.0), Error);
  // Tiles larger than the mosaic cost no more than the mosaic: the largest side is returned.
  EXPECT_EQ(density_tile_size_for(50, 40, 5, 5, 0, 1.0), 1 << 15);
}

TEST(TiledDensity, TerrainTermsEqualTheWholeGridsRanksAndDistances) {
  // The fitted preset's terms (ranks among the whole grid's land, distances to the sea, the lake
  // and the rivers) on tiles of 9 to 64 cells, with and without rivers; the terms themselves and
  // the density are compared.
  const Landscape l = landscape(7);
  DensityOptions o = test_options();
  o.terrain_weights = {0.5, -0.7, 1.2, 0.8, -0.3, 0.4};
  for (int tile : {9, 23, 64}) {
    SCOPED_TRACE(tile);
    check_tiles_equal_whole(l, o, tile, true);
  }
  o.terrain_weights = {0, 0, 1, 0, 0, 0};
  o.terrain_terms = true;
  check_tiles_equal_whole(l, o, 31, false);
}

TEST(LandRanks, SharesBelowWithTiesHalfOnTheRoundedValues) {
  // 1, 2, 2, 3: a quarter below 2 and half the ties, 0.5; 1 and 3 at 0.125 and 0.875. -0 is 0.
  const float values[] = {2, 1, nan_f, 3, 2, -0.0f, 0.0f};
  LandRanks r;
  r.add(values, 5);
  r.finish();
  EXPECT_EQ(r.count(), 4u);
  EXPECT_FLOAT_EQ(r.rank(1), 0.125f);
  EXPECT_FLOAT_EQ(r.rank(2), 0.5f);
  EXPECT_FLOAT_EQ(r.rank(3), 0.875f);
  EXPECT_TRUE(std::isnan(r.rank(nan_f)));
  // Between 1024 and 2048 a key is 0.5 m wide: 2000 and 2000.25 tie, 2000.5 does not.
  const float close[] = {2000, 2000.25f, 2000.5f, -5, -4};
  LandRanks c;
  c.add(close, 5);
  c.add(values + 5, 2);  // -0 and +0: one value
  c.finish();
  EXPECT_FLOAT_EQ(c.rank(-5), 0.5f / 7);
  EXPECT_FLOAT_EQ(c.rank(-4), 1.5f / 7);
  EXPECT_FLOAT_EQ(c.rank(0), 3.0f / 7);
  EXPECT_FLOAT_EQ(c.rank(2000), 5.0f / 7);
  EXPECT_FLOAT_EQ(c.rank(2000.25f), 5.0f / 7);
  EXPECT_FLOAT_EQ(c.rank(2000.5f), 6.5f / 7);
}

TEST(DistanceStrips, EqualTheWholeGridsTransformOnAnyBandsAndStrips) {
  // Random features on a geographic grid (rows of different widths); budgets from one row and one
  // column to the whole grid: the distances must be distance_to_m's bit for bit.
  std::mt19937 rng(5);
  for (int trial = 0; trial < 9; ++trial) {
    const int cols = 20 + int(rng() % 60), rows = 15 + int(rng() % 50);
    const Georef g = trial % 2 ? test::geographic(55.0 + trial, 1.0 / 120) : test::projected(90, 75);
    const CellMetrics m = cell_metrics(g, cols, rows);
    std::vector<std::vector<std::uint8_t>> features(2, std::vector<std::uint8_t>(std::size_t(cols) * std::size_t(rows), 0));
    for (auto& f : features)
      for (auto& v : f) v = rng() % 97 == 0;
    if (trial == 3) std::fill(features[1].begin(), features[1].end(), 0);  // no feature at all: infinity
    for (double budget : {1.0, 5e3, 4e4, 1e9}) {
      SCOPED_TRACE(testing::Message() << "trial " << trial << ", budget " << budget);
      SilentProgress quiet;
      int bands = 0;
      DistanceStrips strips(m, cols, rows, 2, ::testing::TempDir(), budget, [&](int r0, int n) {
        ++bands;
        std::vector<std::vector<std::uint8_t>> band;
        for (const auto& f : features) band.emplace_back(f.begin() + std::ptrdiff_t(r0) * cols, f.begin() + std::ptrdiff_t(r0 + n) * cols);
        return band;
      }, quiet);
      if (budget == 1.0) {
        EXPECT_EQ(bands, rows);
      }
      for (int k = 0; k < 2; ++k) {
        EXPECT_EQ(strips.any(k), std::find(features[std::size_t(k)].begin(), features[std::size_t(k)].end(), 1) != features[std::size_t(k)].end());
        const std::vector<float> whole = distance_to_m(features[std::size_t(k)], m, cols, rows);
        // A window anywhere: to the grid's last row and column, or inside.
        const int c0 = int(rng() % std::uint32_t(cols / 2)), r0 = int(rng() % std::uint32_t(rows / 2));
        const int wc = trial % 3 ? cols - c0 : 1 + int(rng() % std::uint32_t(cols - c0)), wr = trial % 3 ? rows - r0 : 1 + int(rng() % std::uint32_t(rows - r0));
        const std::vector<float> w = strips.window(k, c0, r0, wc, wr);
        std::size_t differ = 0;
        for (int r = r0; r < r0 + wr; ++r)
          for (int c = c0; c < c0 + wc; ++c)
            differ += std::memcmp(&whole[std::size_t(r) * std::size_t(cols) + std::size_t(c)],
                                  &w[std::size_t(r - r0) * std::size_t(wc) + std::size_t(c - c0)], sizeof(float)) != 0;
        EXPECT_EQ(differ, 0u) << "feature " << k;
      }
    }
  }
}

}  // namespace
}  // namespace terrapolis::density
