// Accumulation: golden counts, mass conservation for every method, geodesic areas, thread independence.
// SPDX-License-Identifier: MIT
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>
#include <cstring>
#include <numeric>

#include "core/geodesy.hpp"
#include "hydro/accumulation.hpp"
#include "hydro/depressions.hpp"
#include "hydro/flow_directions.hpp"
#include "hydro/hydro.hpp"
#include "hydro/test_grids.hpp"
#include "io/crs.hpp"

using namespace terrapolis;
using namespace terrapolis::hydro;
using terrapolis::hydro::test::grid;
using terrapolis::hydro::test::random_dem;

namespace {
Raster<double> acc_of(const Dem& dem, FlowMethod method, AccumulationUnit unit = AccumulationUnit::cells) {
  SilentProgress p;
  const CellMetrics m = cell_metrics(dem.georef(), dem.cols(), dem.rows());
  const Dem filled = fill_depressions(dem, {}, p);
  const auto d8 = d8_directions(filled, m, std::nullopt, p);
  const FlowRouter router(filled, d8, m, method);
  return accumulate(filled, router, m, {unit, nullptr}, p);
}
}  // namespace

TEST(Accumulation, GoldenRampAndValley) {
  const auto ramp = acc_of(grid(4, 2, {4, 3, 2, 1, 4, 3, 2, 1}), FlowMethod::d8);
  const double expected[8] = {1, 2, 3, 4, 1, 2, 3, 4};
  for (std::size_t i = 0; i < 8; ++i) EXPECT_EQ(ramp[i], expected[i]);
  std::vector<float> v;
  for (int r = 0; r < 5; ++r)
    for (int c = 0; c < 5; ++c) v.push_back(float(10 * std::abs(c - 2) + (4 - r)));
  const auto valley = acc_of(grid(5, 5, v), FlowMethod::d8);
  for (int r = 0; r < 5; ++r) {
    EXPECT_EQ(valley(0, r), 1);
    EXPECT_EQ(valley(1, r), 2);
    EXPECT_EQ(valley(2, r), 5 * (r + 1));
  }
  // D-infinity and MFD on the same valley: the bottom cell still collects all 25 cells.
  EXPECT_NEAR(acc_of(grid(5, 5, v), FlowMethod::dinf)(2, 4), 25.0, 1e-12);
  EXPECT_NEAR(acc_of(grid(5, 5, v), FlowMethod::mfd)(2, 4), 25.0, 1e-12);
  // Pit: the filled pit and its ring drain over the border; everything ends at the outlets.
  const auto pit = acc_of(grid(3, 3, {5, 5, 5, 5, 1, 5, 5, 5, 5}), FlowMethod::d8);
  EXPECT_EQ(pit(1, 1), 1);
  EXPECT_EQ(pit(1, 0) + pit(0, 0) + pit(2, 0) + pit(0, 1) + pit(2, 1) + pit(0, 2) + pit(1, 2) + pit(2, 2), 9);
}

TEST(Accumulation, MassIsConservedForEveryMethod) {
  SilentProgress p;
  for (std::uint64_t seed = 1; seed <= 6; ++seed) {
    const Dem dem = random_dem(40, 30, seed, seed % 2 == 1);
    const CellMetrics m = cell_metrics(dem.georef(), dem.cols(), dem.rows());
    for (FillMethod fill : {FillMethod::priority_flood, FillMethod::none})
      for (FlowMethod method : {FlowMethod::d8, FlowMethod::dinf, FlowMethod::mfd}) {
        const Dem filled = fill_depressions(dem, {fill, {}}, p);
        const auto d8 = d8_directions(filled, m, std::nullopt, p);
        const FlowRouter router(filled, d8, m, method, 1.1);
        const auto acc = accumulate(filled, router, m, {AccumulationUnit::area_m2, nullptr}, p);
        const auto out = outflow(filled, router, acc);
        double input = 0, leaving = 0;
        for (int r = 0; r < dem.rows(); ++r)
          for (int c = 0; c < dem.cols(); ++c)
            if (!std::isnan(dem(c, r))) input += m.area_m2[std::size_t(r)];
        for (double o : out.values()) leaving += o;
        EXPECT_LT(std::abs(leaving - input) / input, 1e-9) << "seed " << seed << " method " << int(method);
      }
  }
}

TEST(Accumulation, GeodesicAreaOnAGeographicDem) {
  // 30x20 cells of 30 arc-seconds near 60 N: the outlets' upstream areas sum to the geodesic area.
  Georef g;
  g.transform = {10.0, 1.0 / 120, 0, 60.5, 0, -1.0 / 120};
  g.crs = wgs84();
  const Dem base = random_dem(30, 20, 7, false);
  Dem dem(30, 20, g);
  dem.values() = base.values();
  SilentProgress p;
  const CellMetrics m = cell_metrics(g, 30, 20);
  const Dem filled = fill_depressions(dem, {}, p);
  const auto d8 = d8_directions(filled, m, std::nullopt, p);
  for (FlowMethod method : {FlowMethod::d8, FlowMethod::mfd}) {
    const FlowRouter router(filled, d8, m, method);
    const auto acc = accumulate(filled, router, m, {}, p);
    const auto out = outflow(filled, router, acc);
    const double total = std::accumulate(out.values().begin(), out.values().end(), 0.0);
    EXPECT_NEAR(total / m.total_area_m2(30), 1.0, 1e-12);
  }
  // A cell at 60 N is about half as wide as at the equator: the area is not cellsize^2.
  EXPECT_LT(m.area_m2[0], 0.52 * 926.6 * 926.6);
}

TEST(Accumulation, WeightsScaleContributions) {
  const Dem dem = grid(4, 1, {4, 3, 2, 1});
  SilentProgress p;
  const CellMetrics m = cell_metrics(dem.georef(), 4, 1);
  const auto d8 = d8_directions(dem, m, std::nullopt, p);
  const FlowRouter router(dem, d8, m, FlowMethod::d8);
  Raster<float> w = dem.like<float>(2.0f);
  w[1] = NAN;
  const auto acc = accumulate(dem, router, m, {AccumulationUnit::cells, &w}, p);
  EXPECT_EQ(acc[3], 6.0);
}

TEST(Accumulation, SameBitsWithOneAndTwoThreads) {
  const Dem dem = random_dem(120, 90, 3, true);
  HydroOptions o;
  o.flow = FlowMethod::mfd;
  o.hydrometry.max_iterations = 15;
  o.streams.threshold_km2 = 0.05;
  SilentProgress p;
  HydroResult one, two;
  {
    tbb::global_control c(tbb::global_control::max_allowed_parallelism, 1);
    one = run_hydro(dem, o, p);
  }
  {
    tbb::global_control c(tbb::global_control::max_allowed_parallelism, 2);
    two = run_hydro(dem, o, p);
  }
  auto same = [](const auto& a, const auto& b) {
    return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(*a.data())) == 0;
  };
  EXPECT_TRUE(same(one.filled, two.filled));
  EXPECT_TRUE(same(one.d8, two.d8));
  EXPECT_TRUE(same(one.accumulation, two.accumulation));
  EXPECT_TRUE(same(one.hydrometry, two.hydrometry));
  EXPECT_EQ(one.streams.features.size(), two.streams.features.size());
  EXPECT_GT(one.streams.features.size(), 0u);
}
