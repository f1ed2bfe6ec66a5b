// Priority-Flood filling, breaching and flat resolution: golden cases, invariants, differential tests.
// SPDX-License-Identifier: MIT
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

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
