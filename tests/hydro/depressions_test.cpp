// Priority-Flood filling, breaching and flat resolution: golden cases, invariants, differential tests.
// SPDX-License-Identifier: MIT
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>

#include <tbb/global_control.h>

#include "core/geodesy.hpp"
#include "hydro/depressions.hpp"
#include "hydro/flow_directions.hpp"
#include "hydro/test_grids.hpp"

using namespace terrapolis;
using namespace terrapolis::hydro;
using terrapolis::hydro::test::grid;
using terrapolis::hydro::test::random_dem;

namespace {

/// Slow, obvious fill: the water level W is the smallest level from which a path to an outlet
/// never has to climb above W: relax W(c) = max(z(c), min W(neighbour)) until nothing changes.
Dem slow_fill(const Dem& dem, std::optional<double> sea = std::nullopt) {
  Dem w = dem;
  for (int r = 0; r < dem.rows(); ++r)
    for (int c = 0; c < dem.cols(); ++c)
      if (!std::isnan(dem(c, r)) && !touches_outside(dem, c, r) && !is_sea(dem(c, r), sea)) w(c, r) = INFINITY;
  for (bool changed = true; changed;) {
    changed = false;
    for (int r = 1; r < dem.rows() - 1; ++r)
      for (int c = 1; c < dem.cols() - 1; ++c) {
        if (std::isnan(dem(c, r)) || touches_outside(dem, c, r) || is_sea(dem(c, r), sea)) continue;
        float lowest = INFINITY;
        for (int k = 0; k < 8; ++k) lowest = std::min(lowest, w(c + dcol[k], r + drow[k]));
        const float level = std::max(dem(c, r), lowest);
        if (level < w(c, r)) {
          w(c, r) = level;
          changed = true;
        }
      }
  }
  return w;
}

/// Follows D8 from every valid cell; returns false if some path loops or ends in a terminal cell.
bool every_cell_drains(const Raster<std::uint8_t>& d8) {
  for (int r = 0; r < d8.rows(); ++r)
    for (int c = 0; c < d8.cols(); ++c) {
      int cc = c, rr = r;
      for (std::size_t steps = 0;; ++steps) {
        const int k = d8(cc, rr);
        if (k == kNoData && steps > 0) break;  // flowed into a nodata hole: an outlet
        if (k == kNoData) break;
        if (k == kTerminal) return false;
        cc += dcol[k];
        rr += drow[k];
        if (!d8.inside(cc, rr)) break;
        if (steps > d8.size()) return false;
      }
    }
  return true;
}

/// True when both DEMs hold the same bits in every cell (NaN nodata included).
bool same_bits(const Dem& a, const Dem& b, std::size_t* first_difference) {
  for (std::size_t i = 0; i < a.size(); ++i)
    if (std::memcmp(&a[i], &b[i], sizeof(float)) != 0) {
      *first_difference = i;
      return false;
    }
  return true;
}

/// Smooth random terrain with integer ties: valleys and basins many rows tall, so that depressions
/// and their spill paths cross the strip cuts; optional nodata holes.
Dem basin_dem(int cols, int rows, std::uint64_t seed, bool holes) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> phase(0, 6.3), noise(0, 3);
  const double a = phase(rng), b = phase(rng);
  std::vector<float> v(std::size_t(cols) * std::size_t(rows));
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c)
      v[std::size_t(r) * std::size_t(cols) + std::size_t(c)] =
          std::floor(float(20 + 8 * std::sin(c / 3.0 + a) * std::cos(r / 4.0 + b) + noise(rng)));
  if (holes) {
    std::uniform_int_distribution<int> pick(0, int(v.size()) - 1);
    for (int h = 0; h < int(v.size()) / 40; ++h) v[std::size_t(pick(rng))] = NAN;
  }
  return grid(cols, rows, std::move(v), 30.0);
}

}  // namespace

TEST(Depressions, PitIsRaisedToItsSpill) {
  // 5x5: border at 3, ring at 5, pit at 1: the pit is raised to 5 (the ring spills over at 5).
  Dem dem = grid(5, 5, {3, 3, 3, 3, 3,  //
                        3, 5, 5, 5, 3,  //
                        3, 5, 1, 5, 3,  //
                        3, 5, 5, 5, 3,  //
                        3, 3, 3, 3, 3});
  SilentProgress p;
  const Dem filled = fill_depressions(dem, {}, p);
  EXPECT_EQ(filled(2, 2), 5.0f);
  for (std::size_t i = 0; i < dem.size(); ++i)
    if (i != 12) {
      EXPECT_EQ(filled[i], dem[i]);
    }
  const Dem eps = fill_depressions(dem, {FillMethod::epsilon, {}}, p);
  EXPECT_EQ(eps(2, 2), std::nextafter(5.0f, INFINITY));
  const Dem breached = fill_depressions(dem, {FillMethod::breach, {}}, p);
  EXPECT_EQ(breached(2, 2), 1.0f);  // breaching lowers a path instead of raising the pit
  int lowered = 0;
  for (std::size_t i = 0; i < dem.size(); ++i) {
    EXPECT_LE(breached[i], dem[i]);
    lowered += breached[i] < dem[i];
  }
  EXPECT_GE(lowered, 2);  // one ring cell and one border cell carved down to 1
}

TEST(Depressions, SeaLevelCellsAreOutlets) {
  // A closed basin whose bottom is below sea level stays as it is with --sea-level 0.
  Dem dem = grid(5, 5, {9, 9, 9, 9, 9,  //
                        9, 5, 5, 5, 9,  //
                        9, 5, -2, 5, 9,  //
                        9, 5, 5, 5, 9,  //
                        9, 9, 9, 9, 9});
  SilentProgress p;
  const Dem filled = fill_depressions(dem, {FillMethod::priority_flood, 0.0}, p);
  for (std::size_t i = 0; i < dem.size(); ++i) EXPECT_EQ(filled[i], dem[i]);
  const Dem plain = fill_depressions(dem, {}, p);
  EXPECT_EQ(plain(2, 2), 9.0f);
}

TEST(Depressions, RandomisedAgainstSlowFill) {
  SilentProgress p;
  for (std::uint64_t seed = 1; seed <= 30; ++seed) {
    const Dem dem = random_dem(17 + int(seed % 5), 13 + int(seed % 7), seed, seed % 2 == 0);
    const Dem filled = fill_depressions(dem, {}, p);
    const Dem expected = slow_fill(dem);
    for (std::size_t i = 0; i < dem.size(); ++i) {
      if (std::isnan(dem[i])) {
        EXPECT_TRUE(std::isnan(filled[i]));
        continue;
      }
      ASSERT_EQ(filled[i], expected[i]) << "seed " << seed << " cell " << i;
      ASSERT_GE(filled[i], dem[i]);
    }
    // Epsilon: never lowers, never below the plain fill, and every cell drains strictly.
    const Dem eps = fill_depressions(dem, {FillMethod::epsilon, {}}, p);
    const CellMetrics m = cell_metrics(dem.georef(), dem.cols(), dem.rows());
    for (std::size_t i = 0; i < dem.size(); ++i)
      if (!std::isnan(dem[i])) {
        ASSERT_GE(eps[i], filled[i]);
      }
    // After conditioning and flat resolution, every cell drains to an outlet, for every method.
    for (FillMethod method : {FillMethod::priority_flood, FillMethod::epsilon, FillMethod::breach}) {
      const Dem z = fill_depressions(dem, {method, {}}, p);
      if (method == FillMethod::breach)
        for (std::size_t i = 0; i < dem.size(); ++i)
          if (!std::isnan(dem[i])) {
            ASSERT_LE(z[i], dem[i]);
          }
      const auto d8 = d8_directions(z, m, std::nullopt, p);
      ASSERT_TRUE(every_cell_drains(d8)) << "seed " << seed << " method " << int(method);
    }
  }
}

TEST(Depressions, FlatDrainsTowardsLowerAndAwayFromHigher) {
  // A 7x5 flat at 5 walled by 9 on three sides, open on the east side at 1: every flat cell drains,
  // and cells next to the wall point away from it.
  Dem dem = grid(7, 5, {9, 9, 9, 9, 9, 9, 9,  //
                        9, 5, 5, 5, 5, 5, 1,  //
                        9, 5, 5, 5, 5, 5, 1,  //
                        9, 5, 5, 5, 5, 5, 1,  //
                        9, 9, 9, 9, 9, 9, 9});
  SilentProgress p;
  const Dem filled = fill_depressions(dem, {}, p);
  const CellMetrics m = cell_metrics(dem.georef(), dem.cols(), dem.rows());
  const auto d8 = d8_directions(filled, m, std::nullopt, p);
  EXPECT_TRUE(every_cell_drains(d8));
  EXPECT_EQ(d8(5, 2), 0);  // the low edge flows east, steepest
  for (int c = 1; c <= 4; ++c) EXPECT_EQ(dcol[d8(c, 2)], 1) << c;  // towards the outlet
  EXPECT_EQ(drow[d8(1, 1)], 1);  // next to the north wall: away from it (south-east)
}

TEST(Depressions, StripFillEqualsSerialFill) {
  // The parallel plain fill (strips joined through their spillover graph) against the serial flood
  // and the slow fixed point: nodata holes, sea-level outlets, depressions across the cuts, grids
  // with fewer rows than strips, 1 and 2 threads.
  SilentProgress p;
  for (int threads : {1, 2}) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, std::size_t(threads));
    for (std::uint64_t seed = 1; seed <= 120; ++seed) {
      std::mt19937_64 rng(seed * 7919);
      const int cols = 1 + int(rng() % 30), rows = 1 + int(rng() % 40);
      const bool holes = seed % 3 != 0;
      const Dem dem = seed % 2 == 0 ? random_dem(cols, rows, seed, holes) : basin_dem(cols, rows, seed, holes);
      for (std::optional<double> sea : {std::optional<double>(), std::optional<double>(seed % 2 == 0 ? 2.0 : 17.0)}) {
        const Dem serial = fill_depressions(dem, {FillMethod::priority_flood, sea}, p);
        const Dem slow = slow_fill(dem, sea);
        std::size_t i = 0;
        ASSERT_TRUE(same_bits(serial, slow, &i)) << "seed " << seed << " cell " << i;
        for (int strips : {1, 2, 3, 4, 7, 64}) {
          const Dem strip = fill_depressions_in_strips(dem, sea, strips, p);
          ASSERT_TRUE(same_bits(strip, serial, &i))
              << "seed " << seed << " " << cols << "x" << rows << " strips " << strips << " threads " << threads
              << " sea " << sea.has_value() << " cell " << i << ": " << strip[i] << " != " << serial[i];
        }
      }
    }
  }
}

TEST(Depressions, LargeDemFillIsTheSameWithOneAndTwoThreads) {
  // Above the size where fill_depressions switches to strips when two threads are allowed.
  const Dem dem = basin_dem(1100, 1000, 99, true);
  SilentProgress p;
  for (std::optional<double> sea : {std::optional<double>(), std::optional<double>(18.0)}) {
    Dem one, two;
    {
      tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
      one = fill_depressions(dem, {FillMethod::priority_flood, sea}, p);
    }
    {
      tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 2);
      two = fill_depressions(dem, {FillMethod::priority_flood, sea}, p);
    }
    std::size_t i = 0;
    EXPECT_TRUE(same_bits(one, two, &i)) << "cell " << i;
  }
}
