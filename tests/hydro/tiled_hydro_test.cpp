// The tile engine against the whole-grid fill, D8 and accumulation, bit for bit.
// SPDX-License-Identifier: MIT
#include "hydro/tiled/tiled_hydro.hpp"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <mutex>
#include <random>
#include <set>
#include <stdexcept>
#include <string>

#include "core/error.hpp"
#include "core/geodesy.hpp"
#include "hydro/accumulation.hpp"
#include "hydro/catchment.hpp"
#include "hydro/depressions.hpp"
#include "hydro/flow_directions.hpp"
#include "hydro/grid.hpp"
#include "hydro/test_grids.hpp"

namespace terrapolis::hydro::tiled {
namespace {

struct Whole {
  Dem filled;
  Raster<std::uint8_t> d8;
  Raster<double> accumulation;
  Raster<std::uint32_t> basins;
};

Whole whole_grid(const Dem& dem, std::optional<double> sea, AccumulationUnit unit) {
  SilentProgress quiet;
  const CellMetrics m = cell_metrics(dem.georef(), dem.cols(), dem.rows());
  Whole w;
  w.filled = fill_depressions(dem, {FillMethod::priority_flood, sea}, quiet);
  w.d8 = d8_directions(w.filled, m, sea, quiet);
  const FlowRouter router(w.filled, w.d8, m, FlowMethod::d8);
  AccumulationOptions a;
  a.unit = unit;
  w.accumulation = accumulate(w.filled, router, m, a, quiet);
  w.basins = drainage_basins(w.d8);
  return w;
}

/// The tiled run's outputs put back together on the whole grid.
/// With `memory_limit_mb` > 0 the engine sizes its tiles from it (`tile_size` ignored).
Whole tiled(const Dem& dem, int tile_size, int concurrent, std::optional<double> sea, AccumulationUnit unit,
            TiledReport* report = nullptr, double memory_limit_mb = 0) {
  Whole w{dem.like<float>(-1.0f), dem.like<std::uint8_t>(77), dem.like<double>(-1.0), dem.like<std::uint32_t>(0xDEADu)};
  if (memory_limit_mb > 0) tile_size = tile_size_for(dem.cols(), dem.rows(), memory_limit_mb, concurrent);
  const TileGrid grid(dem.cols(), dem.rows(), tile_size);
  std::mutex m;
  auto place = [&](auto& whole, int t, const auto& tile) {
    const TileRect r = grid.rect(t);
    ASSERT_EQ(tile.cols(), r.cols);
    ASSERT_EQ(tile.rows(), r.rows);
    // Each tile carries its own georeferencing: its origin is the cell (col0, row0) of the mosaic.
    EXPECT_DOUBLE_EQ(tile.georef().transform[0], dem.georef().transform[0] + r.col0 * dem.georef().transform[1]);
    EXPECT_DOUBLE_EQ(tile.georef().transform[3], dem.georef().transform[3] + r.row0 * dem.georef().transform[5]);
    std::lock_guard lock(m);
    for (int row = 0; row < r.rows; ++row)
      for (int c = 0; c < r.cols; ++c) whole(r.col0 + c, r.row0 + row) = tile(c, row);
  };
  TileSinks sinks;
  sinks.filled = [&](int t, const Dem& z) { place(w.filled, t, z); };
  sinks.d8 = [&](int t, const Raster<std::uint8_t>& d) { place(w.d8, t, d); };
  sinks.accumulation = [&](int t, const Raster<double>& a) { place(w.accumulation, t, a); };
  sinks.basins = [&](int t, const Raster<std::uint32_t>& b) { place(w.basins, t, b); };
  TiledOptions o;
  o.tile_size = memory_limit_mb > 0 ? 0 : tile_size;
  if (memory_limit_mb > 0) o.memory_limit_mb = memory_limit_mb;
  o.concurrent_tiles = concurrent;
  o.sea_level = sea;
  o.unit = unit;
  // A scratch folder of its own: CTest may run the cases of this file at the same time.
  std::string scratch = ::testing::TempDir() + "tiled-XXXXXX";
  if (!mkdtemp(scratch.data())) throw std::runtime_error("mkdtemp failed");
  o.scratch_dir = scratch;
  auto read = [&](int c0, int r0, int cols, int rows) {
    Dem out(cols, rows, {}, NAN);
    for (int r = 0; r < rows; ++r)
      for (int c = 0; c < cols; ++c)
        if (dem.inside(c0 + c, r0 + r)) out(c, r) = dem(c0 + c, r0 + r);
    return out;
  };
  SilentProgress quiet;
  LocalTiles local;
  const TiledReport rep = run_tiled_hydro(dem.cols(), dem.rows(), dem.georef(), read, o, sinks, quiet, local);
  if (report) *report = rep;
  EXPECT_TRUE(std::filesystem::is_empty(scratch)) << "scratch files left behind";
  std::filesystem::remove(scratch);
  return w;
}

template <class T>
bool same_bits(const Raster<T>& a, const Raster<T>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0;
}

template <class T>
std::size_t differences(const Raster<T>& a, const Raster<T>& b) {
  std::size_t n = 0;
  for (std::size_t i = 0; i < a.size(); ++i) n += std::memcmp(&a[i], &b[i], sizeof(T)) != 0;
  return n;
}

void expect_same(const Whole& a, const Whole& b, const std::string& what) {
  EXPECT_TRUE(same_bits(a.filled, b.filled)) << what << ": filled, " << differences(a.filled, b.filled) << " cells differ";
  EXPECT_TRUE(same_bits(a.d8, b.d8)) << what << ": d8, " << differences(a.d8, b.d8) << " cells differ";
  EXPECT_TRUE(same_bits(a.accumulation, b.accumulation))
      << what << ": accumulation, " << differences(a.accumulation, b.accumulation) << " cells differ";
  EXPECT_TRUE(same_bits(a.basins, b.basins)) << what << ": basins, " << differences(a.basins, b.basins) << " cells differ";
}

Georef geographic(double lon, double lat, double step) {
  Georef g;
  g.transform = {lon, step, 0, lat, 0, -step};
  g.crs.wkt = "GEOGCS[\"WGS 84\"]";
  g.crs.name = "WGS 84";
  g.crs.geographic = true;
  return g;
}

/// 96 x 96 cells of 1" near 47 N cut into 3 x 3 tiles of 32: a closed basin centred on the corner
/// of four tiles (its lake, filled, is a flat over the four), a plateau centred on another tile
/// corner (a flat on four tiles), a river meandering across the tile edge x = 32 three times,
/// rough integer noise (ties) and a nodata hole.
Dem landscape() {
  Dem d(96, 96, geographic(9.0, 47.0, 1.0 / 3600), 0.0f);
  std::mt19937_64 rng(17);
  std::uniform_int_distribution<int> noise(0, 2);
  for (int r = 0; r < 96; ++r)
    for (int c = 0; c < 96; ++c) {
      float z = 200.0f + 0.8f * float(r) + float(noise(rng));  // slopes down to the north edge
      const double db = std::hypot(c - 64.0, r - 64.0);  // basin at the corner (64, 64)
      if (db < 14) z = std::min(z, float(150 + std::round(db * 2)));
      const double dp = std::hypot(c - 32.0, r - 64.0);  // plateau at the corner (32, 64)
      if (dp < 9) z = 300.0f;
      // The river: column 32 + 10 sin(r / 6), crossing x = 32 at r = 0, 19, 38, 57.
      const double axis = 32 + 10 * std::sin(r / 6.0);
      if (std::abs(c - axis) < 1.5 && r < 60) z = float(120 + r / 2);
      d(c, r) = z;
    }
  for (int r = 10; r < 14; ++r)
    for (int c = 70; c < 76; ++c) d(c, r) = NAN;
  return d;
}

/// 256 x 256 cells of 1" sloping gently to the west, with a crater 80 m deep and 120 cells wide
/// centred on the corner (128, 128) of four tiles of 128: filled, a lake of about 44 000 cells at
/// one level, higher terrain all around it (the gradient away from it) and its spill point on the
/// west (the gradient towards lower terrain), with integer noise outside the crater.
Dem crater() {
  Dem d(256, 256, geographic(9.0, 47.0, 1.0 / 3600), 0.0f);
  std::mt19937_64 rng(5);
  std::uniform_int_distribution<int> noise(0, 1);
  for (int r = 0; r < 256; ++r)
    for (int c = 0; c < 256; ++c) {
      const double dc = std::hypot(c - 128.0, r - 128.0);
      d(c, r) = dc < 120 ? float(1000 + 0.02 * c - 80 * (1 - dc / 120)) : float(1000 + 0.02 * c + noise(rng));
    }
  return d;
}

TEST(TileGrid, CoversTheMosaicWithNearEqualTiles) {
  const TileGrid g(100, 37, 16);
  EXPECT_EQ(g.across(), 7);
  EXPECT_EQ(g.down(), 3);
  std::vector<int> seen(100 * 37, 0);
  for (int t = 0; t < g.count(); ++t) {
    const TileRect r = g.rect(t);
    EXPECT_GE(r.cols, 14);
    EXPECT_LE(r.cols, 15);
    for (int row = r.row0; row < r.row0 + r.rows; ++row)
      for (int c = r.col0; c < r.col0 + r.cols; ++c) {
        ++seen[std::size_t(row) * 100 + std::size_t(c)];
        EXPECT_EQ(g.tile_of(c, row), t);
      }
  }
  for (int s : seen) EXPECT_EQ(s, 1);
}

TEST(DrainageBasins, OutletsNumberedInRowMajorOrder) {
  // D8 codes (0 E, 2 S, 3 SW, 4 W, 5 NW, 6 N): (0,0) and (3,0) flow off the grid, (2,0) onto
  // nodata, (2,1) keeps its water: the outlets 1, 2, 3, 4 in row-major order.
  Raster<std::uint8_t> d8(4, 2, {}, 0);
  const std::uint8_t codes[8] = {4, 4, 3, 0, 6, kNoData, kTerminal, 4};
  std::copy_n(codes, 8, d8.data());
  const Raster<std::uint32_t> b = drainage_basins(d8);
  const std::uint32_t expected[8] = {1, 1, 2, 3, 1, 0, 4, 4};
  for (int i = 0; i < 8; ++i) EXPECT_EQ(b[std::size_t(i)], expected[i]) << "cell " << i;
  EXPECT_EQ(b.nodata, 0.0);
}

TEST(TiledHydro, LandscapeOnThreeByThreeTilesEqualsTheWholeGrid) {
  const Dem dem = landscape();
  const Whole whole = whole_grid(dem, std::nullopt, AccumulationUnit::area_m2);
  const TileGrid grid(96, 96, 32);
  ASSERT_EQ(grid.count(), 9);
  // The lake of the basin covers cells of the four tiles around (64, 64), at one level.
  std::set<int> lake_tiles;
  const float lake = whole.filled(64, 64);
  EXPECT_GT(lake, dem(64, 64));
  for (int r = 0; r < 96; ++r)
    for (int c = 0; c < 96; ++c)
      if (whole.filled(c, r) == lake && whole.filled(c, r) > dem(c, r)) lake_tiles.insert(grid.tile_of(c, r));
  EXPECT_EQ(lake_tiles.size(), 4u);
  // The river's path from its source crosses the tile edges at least three times.
  int c = 32, r = 59, crossings = 0;
  for (int steps = 0; steps < 1000; ++steps) {
    const std::uint8_t k = whole.d8(c, r);
    if (k >= 8) break;
    const int nc = c + dcol[k], nr = r + drow[k];
    if (!dem.inside(nc, nr)) break;
    crossings += grid.tile_of(nc, nr) != grid.tile_of(c, r);
    c = nc;
    r = nr;
  }
  EXPECT_EQ(r, 0) << "the river reaches the north edge";
  EXPECT_GE(crossings, 3);
  // Its basin (labelled by its outlet on the north edge) covers cells of at least three tiles.
  std::set<int> basin_tiles;
  for (int row = 0; row < 96; ++row)
    for (int col = 0; col < 96; ++col)
      if (whole.basins(col, row) == whole.basins(c, r)) basin_tiles.insert(grid.tile_of(col, row));
  EXPECT_GE(basin_tiles.size(), 3u);
  TiledReport report;
  expect_same(whole, tiled(dem, 32, 2, std::nullopt, AccumulationUnit::area_m2, &report), "tiles of 32");
  EXPECT_EQ(report.tiles, 9);
  EXPECT_GT(report.flat_cells_shared, 0u) << "the lake and the plateau cross tile edges";
  EXPECT_GT(report.links, 0u);
  for (int size : {8, 11, 20, 47, 96}) expect_same(whole, tiled(dem, size, 1, std::nullopt, AccumulationUnit::area_m2), std::to_string(size));
}

TEST(TiledHydro, RandomDemsWithTiesHolesAndSeaEqualTheWholeGrid) {
  for (std::uint64_t seed = 1; seed <= 24; ++seed) {
    std::mt19937_64 rng(seed);
    const int cols = 20 + int(rng() % 60), rows = 20 + int(rng() % 60);
    Dem dem = test::random_dem(cols, rows, seed, seed % 2 == 0);
    // Smooth some of them into wide flats and lakes.
    if (seed % 3 == 0)
      for (auto& v : dem.values())
        if (!std::isnan(v)) v = std::floor(v / 5);
    const std::optional<double> sea = seed % 4 == 1 ? std::optional<double>(1.0) : std::nullopt;
    const AccumulationUnit unit = seed % 5 == 0 ? AccumulationUnit::cells : AccumulationUnit::area_m2;
    const Whole whole = whole_grid(dem, sea, unit);
    const int size = 8 + int(rng() % 20);
    expect_same(whole, tiled(dem, size, 1 + int(seed % 2), sea, unit), "seed " + std::to_string(seed));
  }
}

TEST(TiledHydro, FlatOnFourTilesDrainsWithinAMemoryLimitTheGatherWouldExceed) {
  const Dem dem = crater();
  const Whole whole = whole_grid(dem, std::nullopt, AccumulationUnit::area_m2);
  const double limit_mb = 1.3;
  ASSERT_EQ(TileGrid(256, 256, tile_size_for(256, 256, limit_mb, 1)).count(), 4) << "2 x 2 tiles of 128";
  // The lake: one level, filled cells in the four tiles.
  const TileGrid grid(256, 256, 128);
  const float lake = whole.filled(128, 128);
  std::set<int> lake_tiles;
  std::size_t lake_cells = 0;
  for (int r = 0; r < 256; ++r)
    for (int c = 0; c < 256; ++c)
      if (whole.filled(c, r) == lake && whole.filled(c, r) > dem(c, r)) {
        lake_tiles.insert(grid.tile_of(c, r));
        ++lake_cells;
      }
  EXPECT_EQ(lake_tiles.size(), 4u);
  EXPECT_GT(lake_cells, 40000u);
  TiledReport report;
  expect_same(whole, tiled(dem, 0, 1, std::nullopt, AccumulationUnit::area_m2, &report, limit_mb), "within 1.3 MB");
  EXPECT_EQ(report.tiles, 4);
  // Gathered whole, the lake alone would take 48 bytes a cell: over the limit.
  EXPECT_GE(report.flat_cells_shared, lake_cells);
  EXPECT_GT(48.0 * double(report.flat_cells_shared), limit_mb * 1e6);
  // By tiles: the tile processed at once plus the global state (frames, rings, pieces) fit.
  EXPECT_LE(report.tile_state_bytes * report.concurrent_tiles + report.global_state_bytes, limit_mb * 1e6);
  EXPECT_GE(report.flat_rounds, 2u) << "the tiles exchanged their rings";
  // Smaller tiles: more rounds, the same bits.
  for (int size : {40, 64, 100}) {
    TiledReport small;
    expect_same(whole, tiled(dem, size, 2, std::nullopt, AccumulationUnit::area_m2, &small), "tiles of " + std::to_string(size));
    EXPECT_GT(small.flat_rounds, report.flat_rounds) << size;
  }
}

TEST(TiledHydro, RandomWideFlatsOnRandomTileSizesEqualTheWholeGrid) {
  for (std::uint64_t seed = 100; seed < 140; ++seed) {
    std::mt19937_64 rng(seed);
    // Some only 1 to 3 cells wide: tiles whose outer ring is the whole tile.
    const int cols = seed % 8 == 0 ? 1 + int(rng() % 3) : 30 + int(rng() % 90), rows = 30 + int(rng() % 90);
    Dem dem = test::random_dem(cols, rows, seed, seed % 3 == 0);
    // Coarse steps: flats of hundreds of cells, joined and split by tile edges.
    const float step = float(5 + rng() % 9);
    for (auto& v : dem.values())
      if (!std::isnan(v)) v = std::floor(v / step);
    const std::optional<double> sea = seed % 4 == 1 ? std::optional<double>(0.0) : std::nullopt;
    const Whole whole = whole_grid(dem, sea, AccumulationUnit::area_m2);
    const int size = 8 + int(rng() % 24);
    TiledReport report;
    expect_same(whole, tiled(dem, size, 1 + int(seed % 2), sea, AccumulationUnit::area_m2, &report), "seed " + std::to_string(seed));
  }
}

TEST(TiledHydro, SameBitsWhateverTheThreadCount) {
  const Dem dem = landscape();
  Whole one, two;
  {
    tbb::global_control c(tbb::global_control::max_allowed_parallelism, 1);
    one = tiled(dem, 24, 1, std::nullopt, AccumulationUnit::area_m2);
  }
  two = tiled(dem, 24, 2, std::nullopt, AccumulationUnit::area_m2);
  expect_same(one, two, "1 vs 2 threads");
}

TEST(TiledHydro, FixedPointAccumulationConservesTheArea) {
  // Every cell drains off a tilted plane: the outlets' total is the grid's geodesic area.
  Dem dem(40, 30, geographic(9.0, 47.0, 1.0 / 1200), 0.0f);
  for (int r = 0; r < 30; ++r)
    for (int c = 0; c < 40; ++c) dem(c, r) = float(100 + c + 2 * r);
  const Whole w = tiled(dem, 9, 2, std::nullopt, AccumulationUnit::area_m2);
  const CellMetrics m = cell_metrics(dem.georef(), 40, 30);
  double out = 0;
  for (int r = 0; r < 30; ++r)
    for (int c = 0; c < 40; ++c) {
      const std::uint8_t k = w.d8(c, r);
      if (!dem.inside(c + dcol[k], r + drow[k])) out += w.accumulation(c, r);
    }
  EXPECT_NEAR(out / m.total_area_m2(40), 1.0, 1e-12);
}

TEST(TiledHydro, TileSizeFromTheMemoryLimitKeepsTheStateWithinIt) {
  const int cols = 50000, rows = 40000;  // 2e9 cells, 8 GB as float
  for (double mb : {2048.0, 8192.0}) {  // the global state alone is ~600 bytes / side a cell: ~0.3 GB at 3000
    const int side = tile_size_for(cols, rows, mb, 2);
    const TileGrid g(cols, rows, side);
    EXPECT_LE(2 * kTileBytesPerCell * (side + 4.0) * (side + 4.0), mb * 1e6);
    EXPECT_GT(g.count(), 1);
  }
  EXPECT_THROW(tile_size_for(cols, rows, 64, 2), Error);
}

}  // namespace
}  // namespace terrapolis::hydro::tiled
