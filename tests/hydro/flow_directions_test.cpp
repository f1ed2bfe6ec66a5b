// D8, D-infinity and MFD on hand-computed grids.
// SPDX-License-Identifier: MIT
#include <gtest/gtest.h>

#include <cmath>

#include "core/geodesy.hpp"
#include "hydro/depressions.hpp"
#include "hydro/flow_directions.hpp"
#include "hydro/test_grids.hpp"

using namespace terrapolis;
using namespace terrapolis::hydro;
using terrapolis::hydro::test::grid;

namespace {
Raster<std::uint8_t> d8_of(const Dem& dem) {
  SilentProgress p;
  const CellMetrics m = cell_metrics(dem.georef(), dem.cols(), dem.rows());
  return d8_directions(dem, m, std::nullopt, p);
}

/// 3 x 3 plane z = -(2c + r) on 1 m cells, falling east and, less, south.
Dem tilted_plane() {
  std::vector<float> v;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) v.push_back(float(-(2 * c + r)));
  return grid(3, 3, v);
}
}  // namespace

TEST(FlowDirections, RampFlowsEast) {
  Dem dem = grid(4, 3, {4, 3, 2, 1, 4, 3, 2, 1, 4, 3, 2, 1});
  const auto d8 = d8_of(dem);
  for (std::size_t i = 0; i < d8.size(); ++i) EXPECT_EQ(d8[i], 0) << i;  // E; the east column flows out east
  EXPECT_EQ(encode_d8(d8, D8Codes::esri)[0], 1);
  EXPECT_EQ(encode_d8(d8, D8Codes::grass)[0], 8);
  EXPECT_EQ(encode_d8(d8, D8Codes::taudem)[0], 1);
}

TEST(FlowDirections, CodeConventions) {
  // k: E SE S SW W NW N NE
  const int esri[8] = {1, 2, 4, 8, 16, 32, 64, 128};
  const int grass[8] = {8, 7, 6, 5, 4, 3, 2, 1};
  const int taudem[8] = {1, 8, 7, 6, 5, 4, 3, 2};
  Raster<std::uint8_t> d8(10, 1, {}, 0);
  for (int k = 0; k < 8; ++k) d8[std::size_t(k)] = std::uint8_t(k);
  d8[8] = kTerminal;
  d8[9] = kNoData;
  const auto e = encode_d8(d8, D8Codes::esri), g = encode_d8(d8, D8Codes::grass), t = encode_d8(d8, D8Codes::taudem);
  for (int k = 0; k < 8; ++k) {
    EXPECT_EQ(e[std::size_t(k)], esri[k]);
    EXPECT_EQ(g[std::size_t(k)], grass[k]);
    EXPECT_EQ(t[std::size_t(k)], taudem[k]);
  }
  EXPECT_EQ(e[8], 0);
  EXPECT_EQ(e[9], 255);
  for (D8Codes c : {D8Codes::esri, D8Codes::grass, D8Codes::taudem}) EXPECT_EQ(decode_d8(encode_d8(d8, c), c).values(), d8.values());
}

TEST(FlowDirections, VValleyAndCone) {
  // V valley draining south: z = 10|c-2| + (4-r).
  std::vector<float> v;
  for (int r = 0; r < 5; ++r)
    for (int c = 0; c < 5; ++c) v.push_back(float(10 * std::abs(c - 2) + (4 - r)));
  const auto d8 = d8_of(grid(5, 5, v));
  for (int r = 0; r < 5; ++r) {
    EXPECT_EQ(d8(0, r), 0);
    EXPECT_EQ(d8(1, r), 0);
    EXPECT_EQ(d8(3, r), 4);
    EXPECT_EQ(d8(4, r), 4);
    if (r < 4) {
      EXPECT_EQ(d8(2, r), 2);
    }
  }
  EXPECT_EQ(d8(2, 4), 1);  // bottom of the valley: flows out (first outside neighbour, south-east)
  // Cone: peak in the middle of a 3x3, ring lower: the peak goes to the steepest, cardinal (tie -> lowest k = E).
  const auto cone = d8_of(grid(3, 3, {1, 1, 1, 1, 3, 1, 1, 1, 1}));
  EXPECT_EQ(cone(1, 1), 0);
  // Diagonal steeper than cardinal when its drop is more than sqrt(2) times larger.
  const auto diag = d8_of(grid(3, 3, {5, 5, 5, 5, 5, 4, 5, 4, 2}));
  EXPECT_EQ(diag(1, 1), 1);  // drop 3 over 1.414 m beats drop 1 over 1 m
}

TEST(FlowDirections, NodataHoleIsAnOutletOnlyWithoutLowerNeighbour) {
  Dem dem = grid(5, 5, {5, 4, 3, 2, 1, 5, 4, 3, 2, 1, 5, 4, NAN, 2, 1, 5, 4, 3, 2, 1, 5, 4, 3, 2, 1});
  const auto d8 = d8_of(dem);
  EXPECT_EQ(d8(2, 2), kNoData);
  EXPECT_EQ(d8(1, 2), 1);  // east is nodata; SE and NE tie, lowest k wins
  Dem pit = grid(3, 3, {5, 5, 5, 5, 5, 5, 5, 5, 5});
  pit(1, 1) = NAN;
  const auto p8 = d8_of(pit);
  // A flat around a hole: no lower neighbour, so each cell flows out through its first outside
  // neighbour (grid border or the hole), in neighbour order.
  EXPECT_EQ(p8(0, 0), 1);  // E is inside, SE is the hole
  EXPECT_EQ(p8(1, 0), 2);  // E and SE inside, S is the hole
  EXPECT_EQ(p8(2, 2), 0);  // E is off the grid
}

TEST(FlowDirections, DinfSplitsOnTheSteepestFacet) {
  // Plane z = -(2c + r) on 1 m cells: facet E/SE, angle atan(1/2) out of 45 degrees.
  const Dem dem = tilted_plane();
  const auto d8 = d8_of(dem);
  const CellMetrics m = cell_metrics(dem.georef(), 3, 3);
  const FlowRouter dinf(dem, d8, m, FlowMethod::dinf);
  FlowSplit s;
  dinf.split(1, 1, s);
  ASSERT_EQ(s.count, 2);
  EXPECT_EQ(s.k[0], 0);
  EXPECT_EQ(s.k[1], 1);
  const double p2 = std::atan(0.5) / std::atan(1.0);
  EXPECT_NEAR(s.fraction[1], p2, 1e-12);
  EXPECT_NEAR(s.fraction[0], 1 - p2, 1e-12);
  // Pure east ramp: everything east.
  const Dem ramp = grid(3, 3, {3, 2, 1, 3, 2, 1, 3, 2, 1});
  const auto r8 = d8_of(ramp);
  const FlowRouter rd(ramp, r8, m, FlowMethod::dinf);
  rd.split(1, 1, s);
  ASSERT_EQ(s.count, 1);
  EXPECT_EQ(s.k[0], 0);
  EXPECT_EQ(s.fraction[0], 1.0);
}

TEST(FlowDirections, MfdSharesFollowSlopePower) {
  const Dem dem = tilted_plane();
  const auto d8 = d8_of(dem);
  const CellMetrics m = cell_metrics(dem.georef(), 3, 3);
  const double diag = std::hypot(1.0, 1.0);
  // Downslope neighbours of the centre: E drop 2, SE drop 3 (diagonal), S drop 1, NE drop 1 (diagonal).
  for (double p : {1.0, 1.1, 4.0}) {
    const FlowRouter mfd(dem, d8, m, FlowMethod::mfd, p);
    FlowSplit s;
    mfd.split(1, 1, s);
    ASSERT_EQ(s.count, 4);
    const double w[4] = {std::pow(2.0, p), std::pow(3.0 / diag, p), std::pow(1.0, p), std::pow(1.0 / diag, p)};
    const int k[4] = {0, 1, 2, 7};
    const double total = w[0] + w[1] + w[2] + w[3];
    for (int j = 0; j < 4; ++j) {
      EXPECT_EQ(s.k[std::size_t(j)], k[j]);
      EXPECT_NEAR(s.fraction[std::size_t(j)], w[j] / total, 1e-12);
    }
  }
}

TEST(FlowDirections, InnerReceiversAreTheValidReceiversOfSplit) {
  // inner_receivers has a fast path for MFD (no weights): it must name exactly split()'s receivers
  // that lie inside the grid on valid data, for every method.
  SilentProgress p;
  for (std::uint64_t seed = 1; seed <= 4; ++seed) {
    const Dem dem = test::random_dem(23, 17, seed, seed % 2 == 0);
    const Dem filled = fill_depressions(dem, {}, p);
    const CellMetrics m = cell_metrics(dem.georef(), dem.cols(), dem.rows());
    const auto d8 = d8_directions(filled, m, std::nullopt, p);
    for (FlowMethod method : {FlowMethod::d8, FlowMethod::dinf, FlowMethod::mfd}) {
      const FlowRouter router(filled, d8, m, method);
      FlowSplit s;
      for (int r = 0; r < dem.rows(); ++r)
        for (int c = 0; c < dem.cols(); ++c) {
          router.split(c, r, s);
          std::uint8_t bits = 0;
          for (int j = 0; j < s.count; ++j) {
            const int k = s.k[std::size_t(j)], nc = c + dcol[k], nr = r + drow[k];
            if (filled.inside(nc, nr) && !std::isnan(filled(nc, nr))) bits = std::uint8_t(bits | (1u << k));
          }
          ASSERT_EQ(router.inner_receivers(c, r), bits) << c << "," << r;
        }
    }
  }
}
