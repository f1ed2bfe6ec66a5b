// Tests of Belhadj's growing window (Alg. 1): hand-computed values, constraints kept, thread
// independence, and the tears of fig. 2.3 measured against DMMC on the same sketch.
// SPDX-License-Identifier: MIT
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>

#include "generate/generators.hpp"
#include "generate/growing_window.hpp"
#include "support/determinism.hpp"
#include "support/georefs.hpp"
#include "support/sketches.hpp"

using namespace terrapolis;
using namespace terrapolis::generate;

namespace {

constexpr float nan_f = std::numeric_limits<float>::quiet_NaN();

Georef unit_georef() { return test::projected(30); }

Raster<float> cross_skeleton(int n, float ridge_m, bool zero_borders) { return test::cross_skeleton(unit_georef(), n, ridge_m, zero_borders); }

/// Largest height difference between two 8-neighbours, at least one of them computed, both at
/// least `margin` cells from the border (where a ridge meets the zero border every method jumps).
double largest_jump(const Raster<float>& sketch, const Raster<float>& result, int margin) {
  double worst = 0;
  for (int y = margin; y < result.rows() - margin; ++y)
    for (int x = margin; x < result.cols() - margin; ++x)
      for (const auto& [dx, dy] : {std::pair{1, 0}, {0, 1}, {1, 1}, {1, -1}}) {
        const int u = x + dx, v = y + dy;
        if (u >= result.cols() - margin || v < margin || v >= result.rows() - margin) continue;
        if (!std::isnan(sketch(x, y)) && !std::isnan(sketch(u, v))) continue;
        worst = std::max(worst, std::abs(double(result(u, v)) - result(x, y)));
      }
  return worst;
}

using test::largest_jump_at_constraints;

/// A sparse sketch: about `share` of the cells fixed, heights from a smooth surface.
Raster<float> sparse_sketch(int cols, int rows, double share, std::uint64_t seed) {
  Raster<float> r(cols, rows, unit_georef(), nan_f);
  for (int y = 0; y < rows; ++y)
    for (int x = 0; x < cols; ++x)
      if ((terrain::position_noise(seed, x, y) + 1) / 2 < share) r(x, y) = float(300 + 120 * std::sin(x * 0.07) * std::cos(y * 0.05));
  return r;
}

}  // namespace

TEST(GrowingWindow, HandComputedFiveByFive) {
  // Corners 0, 8 (north-east), 4 (south-west), 12 (south-east), no noise, Triangle-Edge.
  // pas = 1: each corner's three neighbours take it (the only known corner of their squares).
  // pas = 2: (2,0), (0,2), (2,2), (2,4), (4,2) take the known corner of the square below-right of
  // them (the printed loop's last writer): 8, 4, 12, 12, 12. The 2-squares are then subdivided:
  // (2,1) = (8 + 12) / 2, (1,2) = (4 + 12) / 2, (3,2) = (12 + 12) / 2.
  Raster<float> r(5, 5, unit_georef(), nan_f);
  r(0, 0) = 0;
  r(4, 0) = 8;
  r(0, 4) = 4;
  r(4, 4) = 12;
  terrain::MidpointParams p;  // scale 0: no noise
  growing_window(r, p);
  const float expected[5][5] = {{0, 0, 8, 8, 8}, {0, 0, 10, 8, 8}, {4, 8, 12, 12, 12}, {4, 4, 12, 12, 12}, {4, 4, 12, 12, 12}};
  for (int y = 0; y < 5; ++y)
    for (int x = 0; x < 5; ++x) EXPECT_EQ(r(x, y), expected[y][x]) << x << "," << y;
}

TEST(GrowingWindow, ExtrapolationNoiseIsPasTimesS) {
  // One cell fixed at the centre of a 5x5 grid: at pas = 1 its 8 neighbours take 100 plus
  // 1 x s x X, s = S / 65536 m per cell (the thesis's s for 16-bit altitudes).
  Raster<float> r(5, 5, unit_georef(), nan_f);
  r(2, 2) = 100;
  terrain::MidpointParams p;
  p.scale_m = 65536;  // s = 1 m per cell
  p.seed = 9;
  growing_window(r, p);
  for (int y = 1; y <= 3; ++y)
    for (int x = 1; x <= 3; ++x)
      if (x != 2 || y != 2) {
        EXPECT_FLOAT_EQ(r(x, y), float(100 + terrain::position_noise(9, x, y))) << x << "," << y;
      }
  // (0,0) at pas = 2: the square below-right of it holds (2,2) only, so 100 + 2 s X.
  EXPECT_FLOAT_EQ(r(0, 0), float(100 + 2 * terrain::position_noise(9, 0, 0)));
}

TEST(GrowingWindow, ConstraintsKeptExactlyAndEveryCellFilled) {
  for (const auto& [cols, rows] : {std::pair{129, 129}, {100, 70}, {257, 65}})
    for (const auto scheme : {terrain::Subdivision::triangle_edge, terrain::Subdivision::diamond_square}) {
      const Raster<float> sketch = sparse_sketch(cols, rows, 0.02, 4);
      Raster<float> r = sketch;
      terrain::MidpointParams p;
      p.subdivision = scheme;
      p.scale_m = 500;
      p.seed = 3;
      growing_window(r, p);
      for (std::size_t i = 0; i < r.size(); ++i) {
        ASSERT_TRUE(std::isfinite(r[i])) << cols << "x" << rows << " cell " << i;
        if (std::isfinite(sketch[i])) {
          ASSERT_EQ(std::memcmp(&r[i], &sketch[i], sizeof(float)), 0) << cols << "x" << rows << " cell " << i;
        }
      }
    }
}

TEST(GrowingWindow, SameSeedSameBytesWhateverTheThreads) {
  const Raster<float> sketch = sparse_sketch(257, 257, 0.01, 2);
  auto run = [&](int threads, std::uint64_t seed, terrain::Subdivision scheme) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, std::size_t(threads));
    GenerateRequest request;
    request.grid = sketch;
    request.dmmc.top_down.subdivision = scheme;
    request.dmmc.top_down.scale_m = 800;
    request.dmmc.top_down.seed = seed;
    return generate_window(request).dem.values();
  };
  for (const auto scheme : {terrain::Subdivision::triangle_edge, terrain::Subdivision::diamond_square})
    test::expect_same_bytes_at_any_thread_count([&](int threads, std::uint64_t seed) { return run(threads, seed, scheme); });
}

TEST(GrowingWindow, NoTearAlongTheShiftedDiagonal) {
  // §2.1.3: on fig. 1.2's skeleton (no borders) the window joins the shifted counter-diagonal
  // smoothly, where plain subdivision leaves it standing above its neighbours.
  const int n = 65;
  const float ridge = 1000;
  const Raster<float> sketch = cross_skeleton(n, ridge, false);
  for (const auto scheme : {terrain::Subdivision::triangle_edge, terrain::Subdivision::diamond_square}) {
    Raster<float> r = sketch;
    terrain::MidpointParams p;
    p.subdivision = scheme;
    growing_window(r, p);
    const Raster<float> plain_r = test::plain_subdivision(sketch, p);
    const double jump = largest_jump_at_constraints(sketch, r), jump_plain = largest_jump_at_constraints(sketch, plain_r);
    std::printf("fig. 1.2, scheme %d: largest jump at a constraint: growing window %.1f m, plain subdivision %.1f m\n", int(scheme), jump,
                jump_plain);
    EXPECT_LT(jump, 0.05 * ridge) << int(scheme);
    EXPECT_GT(jump_plain, 0.4 * ridge) << int(scheme);
  }
}

TEST(GrowingWindow, TearsBetweenCloseOpposingConstraints) {
  // Fig. 2.3: ridges at 1000 m and borders at 0. The two families grow towards each other as
  // separate surfaces and meet in a small patch: a tear. DMMC's bottom-up pass spreads both over
  // the whole tree first. Measured n/8 = 8 cells from the border, where a ridge cell is 8 cells
  // from the zero border: a smooth surface falls by at most 1000 / 8 = 125 m per cell there.
  const int n = 65;
  const float ridge = 1000;
  const Raster<float> sketch = cross_skeleton(n, ridge, true);
  for (const auto scheme : {terrain::Subdivision::triangle_edge, terrain::Subdivision::diamond_square}) {
    Raster<float> window = sketch, dmmc = sketch;
    terrain::MidpointParams p;
    p.subdivision = scheme;
    growing_window(window, p);
    terrain::DmmcParams dp;
    dp.top_down = p;
    terrain::dmmc(dmmc, dp);
    const double jump_window = largest_jump(sketch, window, n / 8), jump_dmmc = largest_jump(sketch, dmmc, n / 8);
    std::printf("fig. 2.3, scheme %d: largest jump between neighbours: growing window %.1f m, DMMC %.1f m\n", int(scheme),
                jump_window, jump_dmmc);
    EXPECT_GT(jump_window, 0.25 * ridge) << int(scheme);
    EXPECT_GT(jump_window, 2 * jump_dmmc) << int(scheme);
  }
}
