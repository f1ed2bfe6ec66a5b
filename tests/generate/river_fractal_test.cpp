// Tests of Belhadj's fractal terrain with one river (§1.2.3): the necklace is one self-avoiding
// path from one side of the grid to another, its bed never rises downstream, D8 follows it, the
// same seed gives the same bytes at any thread count.
// SPDX-License-Identifier: MIT
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <set>

#include "core/error.hpp"
#include "core/neighbours.hpp"
#include "core/progress.hpp"
#include "generate/generators.hpp"
#include "generate/distance_field.hpp"
#include "generate/river_fractal.hpp"
#include "hydro/hydro.hpp"

using namespace terrapolis;
using namespace terrapolis::generate;

namespace {

GenerateRequest request(int cols, int rows, std::uint64_t seed) {
  GenerateRequest r;
  Georef g;
  g.transform = {500000, 30, 0, 5000000, 0, -30};
  g.crs.wkt = "LOCAL_CS[\"test\"]";
  r.grid = Raster<float>(cols, rows, g, std::numeric_limits<float>::quiet_NaN());
  r.cell_m = 30;
  r.seed = seed;
  r.relief_m = 1500;
  r.dmmc.top_down.subdivision = terrain::Subdivision::diamond_square;
  r.dmmc.top_down.scale_m = 1500;  // s = 1: S the whole relief, as the command's default
  r.dmmc.top_down.hurst = 0.4565;
  r.dmmc.top_down.seed = seed;
  r.river.bed_drop_m = 75;
  return r;
}

bool on_border(int x, int y, int cols, int rows) { return x == 0 || y == 0 || x == cols - 1 || y == rows - 1; }

}  // namespace

TEST(Necklace, ThreeByThreeCrossesFromOneSideToAnother) {
  // 3x3: one split; the river's unit edges start on one side of the grid and end on another, each
  // next to the one before (sides of one unit square).
  for (std::uint64_t seed = 1; seed <= 20; ++seed) {
    const Necklace n = mandelbrot_necklace(3, 3, seed);
    ASSERT_GE(n.line.size(), 2u);
    for (const auto& end : {n.line.front(), n.line.back()})
      EXPECT_TRUE(end[0] == 0 || end[0] == 2 || end[1] == 0 || end[1] == 2) << seed;
    for (std::size_t k = 1; k < n.line.size(); ++k)
      EXPECT_LE(std::abs(n.line[k][0] - n.line[k - 1][0]) + std::abs(n.line[k][1] - n.line[k - 1][1]), 1.0 + 1e-12) << seed;
  }
}

TEST(Necklace, OneSelfAvoidingPathBetweenTwoSides) {
  for (const auto& [cols, rows] : {std::pair{129, 129}, {100, 37}, {513, 257}})
    for (std::uint64_t seed = 1; seed <= 3; ++seed) {
      const Necklace n = mandelbrot_necklace(cols, rows, seed);
      // Every crossed edge is a unit edge, each shares a unit square with the next, none is crossed twice.
      std::set<std::pair<double, double>> seen;
      for (std::size_t k = 0; k < n.line.size(); ++k) {
        const double fx = n.line[k][0] - std::floor(n.line[k][0]), fy = n.line[k][1] - std::floor(n.line[k][1]);
        EXPECT_TRUE((fx == 0.5) != (fy == 0.5)) << "not a unit edge midpoint";
        EXPECT_TRUE(seen.insert({n.line[k][0], n.line[k][1]}).second) << "edge crossed twice";
        if (k > 0) {
          EXPECT_LE(std::abs(n.line[k][0] - n.line[k - 1][0]), 1.0);
          EXPECT_LE(std::abs(n.line[k][1] - n.line[k - 1][1]), 1.0);
        }
      }
      const auto& a = n.line.front();
      const auto& b = n.line.back();
      EXPECT_TRUE(on_border(int(std::floor(a[0])), int(std::floor(a[1])), cols, rows) ||
                  on_border(int(std::ceil(a[0])), int(std::ceil(a[1])), cols, rows));
      EXPECT_TRUE(on_border(int(std::floor(b[0])), int(std::floor(b[1])), cols, rows) ||
                  on_border(int(std::ceil(b[0])), int(std::ceil(b[1])), cols, rows));
      EXPECT_EQ(n.cells.size(), n.edge_of_cell.size());
    }
}

TEST(Necklace, RefusesSizesBeyondSixteenBitKeys) {
  EXPECT_THROW(mandelbrot_necklace(2, 100, 1), Error);
  EXPECT_THROW(mandelbrot_necklace(65536, 3, 1), Error);
}

TEST(RiverFractal, BedNeverRisesDownstreamAndD8FollowsTheRiver) {
  for (const std::uint64_t seed : {1, 2, 3}) {
    const GenerateRequest r = request(257, 257, seed);
    const GeneratedTerrain t = generate_river(r);
    const Necklace n = mandelbrot_necklace(257, 257, seed ^ 0x6e65636b6c616365ull);
    ASSERT_EQ(t.plan.rivers.size(), 1u);
    EXPECT_EQ(t.plan.rivers[0].line, n.line);
    // River cells in the order the river leaves them: never rising, from 75 m to 0 m.
    for (std::size_t k = 1; k < n.cells.size(); ++k) ASSERT_LE(t.dem[n.cells[k]], t.dem[n.cells[k - 1]]) << k;
    EXPECT_FLOAT_EQ(t.dem[n.cells.front()], 75.0f);
    EXPECT_FLOAT_EQ(t.dem[n.cells.back()], 0.0f);
    // D8 on the conditioned DEM: the share of river cells that are D8 streams (>= 0.1 km2), the share
    // whose water goes to another river cell or off the grid, the share of the line near a stream.
    hydro::HydroOptions options;
    options.with_hydrometry = false;
    options.with_streams = false;
    SilentProgress progress;
    const hydro::HydroResult d8 = hydro::run_hydro(t.dem, options, progress);
    std::vector<char> river(t.dem.size(), 0);
    for (const std::size_t i : n.cells) river[i] = 1;
    std::size_t streams = 0, stays = 0;
    for (const std::size_t i : n.cells) {
      streams += d8.accumulation[i] >= 1e5;
      const int x = int(i % 257), y = int(i / 257), k = d8.d8[i];
      if (k < 8) {
        const int u = x + dcol[std::size_t(k)], v = y + drow[std::size_t(k)];
        stays += !t.dem.inside(u, v) || river[std::size_t(v) * 257 + std::size_t(u)];
      }
    }
    std::size_t near = 0;  // points of the river line with a D8 stream cell within one cell
    for (const auto& p : n.line) {
      bool found = false;
      for (int v = int(std::floor(p[1])) - 1; v <= int(std::ceil(p[1])) + 1 && !found; ++v)
        for (int u = int(std::floor(p[0])) - 1; u <= int(std::ceil(p[0])) + 1 && !found; ++u)
          found = t.dem.inside(u, v) && d8.accumulation(u, v) >= 1e5;
      near += found;
    }
    const double stream_share = double(streams) / double(n.cells.size()), stay_share = double(stays) / double(n.cells.size());
    const double near_share = double(near) / double(n.line.size());
    std::printf("seed %d: %zu river cells, %.1f %% D8 streams (>= 0.1 km2), %.1f %% drain into the river or out, %.1f %% of the line "
                "within 1 cell of a D8 stream\n", int(seed), n.cells.size(), 100 * stream_share, 100 * stay_share, 100 * near_share);
    EXPECT_EQ(stay_share, 1.0);
    EXPECT_GT(near_share, 0.85);
    // The generator's own figures say the same.
    for (const auto& [name, value] : t.figures) {
      if (name == "river_cells_draining_into_river_share") {
        EXPECT_DOUBLE_EQ(value, stay_share);
      } else if (name == "river_line_within_1_cell_of_d8_stream_share") {
        EXPECT_DOUBLE_EQ(value, near_share);
      }
    }
  }
}

TEST(RiverFractal, SameSeedSameBytesWhateverTheThreads) {
  auto run = [](int threads, std::uint64_t seed) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, std::size_t(threads));
    return generate_river(request(193, 161, seed)).dem.values();
  };
  const auto one = run(1, 4), two = run(2, 4), other = run(2, 5);
  ASSERT_EQ(one.size(), two.size());
  EXPECT_EQ(std::memcmp(one.data(), two.data(), one.size() * sizeof(float)), 0);
  EXPECT_NE(std::memcmp(one.data(), other.data(), one.size() * sizeof(float)), 0);
}

TEST(RiverFractal, WithoutNoiseEveryCellIsItsEquation) {
  // S = 0: no displacement, so each computed cell is exactly eq. 1.3 (river vertices) or its
  // parents' mean (the others), raised to the river cells it touches; checked against the
  // formulas, the parents read from the result (each cell is set once).
  const int cols = 129, rows = 97;
  const Necklace n = mandelbrot_necklace(cols, rows, 7);
  Raster<float> dem(cols, rows, Georef{}, std::numeric_limits<float>::quiet_NaN());
  RiverFractalParams p;
  p.top_down.subdivision = terrain::Subdivision::diamond_square;
  p.top_down.scale_m = 0;
  p.relief_m = 1000;
  p.bed_drop_m = 50;
  p.convergence = 4;
  river_fractal(dem, n, p);
  std::vector<char> river(dem.size(), 0);
  for (std::size_t k = 0; k < n.cells.size(); ++k) {
    river[n.cells[k]] = 1;
    EXPECT_FLOAT_EQ(dem[n.cells[k]], float(50.0 * (1.0 - double(n.edge_of_cell[k]) / double(n.line.size() - 1))));
  }
  std::vector<double> dist;
  std::vector<std::size_t> nearest;
  distance_to(river, cols, rows, dist, nearest);
  const terrain::SubdivisionTree tree(cols, rows);
  const double r_max = 8;  // ceil(log2 129)
  int vertices = 0;
  for (int y = 0; y < rows; ++y)
    for (int x = 0; x < cols; ++x) {
      const std::size_t i = dem.index(x, y);
      const bool corner = (x == 0 || x == cols - 1) && (y == 0 || y == rows - 1);
      if (river[i] || corner) continue;
      int pc[4], pr[4];
      double w[4];
      const int k = tree.parents(terrain::Subdivision::diamond_square, x, y, pc, pr, w);
      double m = 0;
      for (int q = 0; q < k; ++q) m += w[q] * dem(pc[q], pr[q]);
      const int r = tree.level(x, y);
      double z = m;
      if (n.river_vertex_level[i] == r) {
        const double b = dem[nearest[i]];
        z = std::max(b, b + std::pow(1.0 - r / r_max, 4.0) * (m - b));
        ++vertices;
      }
      float bank = -std::numeric_limits<float>::infinity();
      for (int d = 0; d < 8; ++d)
        if (dem.inside(x + dcol[std::size_t(d)], y + drow[std::size_t(d)]) && river[dem.index(x + dcol[std::size_t(d)], y + drow[std::size_t(d)])])
          bank = std::max(bank, dem(x + dcol[std::size_t(d)], y + drow[std::size_t(d)]));
      ASSERT_FLOAT_EQ(dem[i], std::max(float(z), bank)) << x << "," << y;
    }
  EXPECT_GT(vertices, 10);
}
