// Streams (reaches, Strahler, areas, lengths) and catchments on hand-made networks.
// SPDX-License-Identifier: MIT
#include <gtest/gtest.h>

#include <cmath>

#include "core/error.hpp"
#include "core/geodesy.hpp"
#include "hydro/accumulation.hpp"
#include "hydro/catchment.hpp"
#include "hydro/flow_directions.hpp"
#include "hydro/streams.hpp"
#include "hydro/test_grids.hpp"
#include "io/crs.hpp"

using namespace terrapolis;
using namespace terrapolis::hydro;
using terrapolis::hydro::test::grid;

TEST(Streams, YConfluenceGivesThreeReachesAndOrderTwo) {
  // Two diagonal tributaries meet at (2,2) and leave southwards off the grid at (2,4).
  Dem dem = grid(5, 5, std::vector<float>(25, 1.0f));
  Raster<std::uint8_t> d8 = dem.like<std::uint8_t>(kTerminal);
  Raster<double> area = dem.like<double>(0.0);
  auto set = [&](int c, int r, int k, double a) {
    d8(c, r) = std::uint8_t(k);
    area(c, r) = a;
  };
  set(0, 0, 1, 1);  // SE
  set(1, 1, 1, 2);
  set(4, 0, 3, 1);  // SW
  set(3, 1, 3, 2);
  set(2, 2, 2, 5);  // S
  set(2, 3, 2, 6);
  set(2, 4, 2, 7);  // off the grid
  const CellMetrics m = cell_metrics(dem.georef(), 5, 5);
  SilentProgress p;
  const VectorLayer s = extract_streams(d8, area, m, {1e-6}, p);  // 1 m²: every network cell
  ASSERT_EQ(s.features.size(), 3u);
  const double diag = std::hypot(1.0, 1.0);
  // Row-major start order: (0,0), (4,0), then the confluence (2,2).
  const auto& a = s.features[0];
  const auto& b = s.features[1];
  const auto& c = s.features[2];
  EXPECT_EQ(a.parts[0].size(), 3u);
  EXPECT_EQ(std::get<std::int64_t>(a.values[1]), 1);
  EXPECT_NEAR(std::get<double>(a.values[2]), 2e-6, 1e-15);  // area at its last own cell (1,1)
  EXPECT_NEAR(std::get<double>(a.values[3]), 2 * diag, 1e-9);
  EXPECT_EQ(std::get<std::int64_t>(a.values[4]), std::get<std::int64_t>(c.values[0]));
  EXPECT_EQ(std::get<std::int64_t>(b.values[4]), std::get<std::int64_t>(c.values[0]));
  EXPECT_EQ(std::get<std::int64_t>(c.values[1]), 2);  // two order-1 reaches meet
  EXPECT_NEAR(std::get<double>(c.values[2]), 7e-6, 1e-15);
  EXPECT_NEAR(std::get<double>(c.values[3]), 2.0, 1e-9);
  EXPECT_EQ(std::get<std::int64_t>(c.values[4]), 0);  // flows out of the DEM
  // The confluence is the last vertex of the tributaries and the first of the main reach.
  EXPECT_EQ(a.parts[0].back(), c.parts[0].front());
  EXPECT_EQ(a.parts[0].front(), dem.georef().cell_centre(0, 0));
  EXPECT_THROW(extract_streams(d8, area, m, {0.0}, p), Error);
}

TEST(Catchment, ValleyOutletTakesTheWholeValley) {
  std::vector<float> v;
  for (int r = 0; r < 5; ++r)
    for (int c = 0; c < 5; ++c) v.push_back(float(10 * std::abs(c - 2) + (4 - r)));
  Dem dem = grid(5, 5, v, 30.0);
  dem.georef().crs = crs_from_user("EPSG:32632");
  const CellMetrics m = cell_metrics(dem.georef(), 5, 5);
  SilentProgress p;
  const auto d8 = d8_directions(dem, m, std::nullopt, p);
  const FlowRouter router(dem, d8, m, FlowMethod::d8);
  const auto area = accumulate(dem, router, m, {}, p);
  // A point in cell (1,3), 30 m west of the valley: snapped within 40 m to the valley cell (2,3).
  const auto pt = dem.georef().cell_centre(1, 3);
  const Catchment c = delineate_catchment(d8, area, m, pt[0], pt[1], 40.0, p);
  EXPECT_EQ(c.outlet_col, 2);
  EXPECT_EQ(c.outlet_row, 3);
  EXPECT_EQ(c.cells, 20u);  // rows 0..3 of the valley
  EXPECT_NEAR(c.area_km2, 20 * 900 / 1e6, 1e-12);
  ASSERT_EQ(c.polygon.features.size(), 1u);
  EXPECT_EQ(c.mask(2, 4), 0);
  EXPECT_EQ(c.mask(0, 0), 1);
  // Without snapping it stays in (1,3): that cell and (0,3), which drains into it.
  EXPECT_EQ(delineate_catchment(d8, area, m, pt[0], pt[1], 0.0, p).cells, 2u);
  EXPECT_THROW(delineate_catchment(d8, area, m, pt[0] + 1e6, pt[1], 0.0, p), Error);
}
