// River trees of a generator's plan, Strahler orders, Horton ratios and the D8 consistency check on hand-made cases.
// SPDX-License-Identifier: MIT
#include <gtest/gtest.h>

#include <cmath>

#include "generate/river_ridge_plan.hpp"
#include "generate/river_checks.hpp"

namespace terrapolis::generate {
namespace {

std::vector<GridPoint> row_line(double row, double from, double to) { return {{from, row}, {to, row}}; }

// A complete binary tree: four order-1 reaches of 10 cells, two order-2 of 20, one order-3 of 40.
RiverRidgePlan binary_tree() {
  RiverRidgePlan s;
  for (int i = 0; i < 4; ++i) s.rivers.push_back({row_line(i, 0, 10), 4 + i / 2, 1, 0});
  for (int i = 0; i < 2; ++i) s.rivers.push_back({row_line(10 + i, 0, 20), 6, 1, 0});
  s.rivers.push_back({row_line(20, 0, 40), -1, 1, 0});
  assign_strahler(s);
  return s;
}

TEST(RiverRidgePlan, StrahlerOfABinaryTree) {
  const RiverRidgePlan s = binary_tree();
  const int expected[] = {1, 1, 1, 1, 2, 2, 3};
  for (std::size_t i = 0; i < 7; ++i) EXPECT_EQ(s.rivers[i].strahler, expected[i]) << i;
}

TEST(RiverRidgePlan, HortonRatiosOfABinaryTree) {
  // N = 4, 2, 1 and mean L = 100, 200, 400 m (10 m cells): log N and log L are exactly linear in
  // the order, so Rb = 2 and Rl = 2.
  const HortonRatios h = horton_ratios(binary_tree(), 10.0);
  ASSERT_EQ(h.streams, (std::vector<int>{4, 2, 1}));
  EXPECT_DOUBLE_EQ(h.mean_length_m[0], 100);
  EXPECT_DOUBLE_EQ(h.mean_length_m[2], 400);
  ASSERT_TRUE(h.bifurcation && h.length);
  EXPECT_NEAR(*h.bifurcation, 2.0, 1e-12);
  EXPECT_NEAR(*h.length, 2.0, 1e-12);
}

TEST(RiverRidgePlan, PathsSplitAtConfluencesAndStreamsChainThroughThem) {
  // Main river 0 (x 0..20 on row 0, points every cell) takes river 1 at x=5 and river 2 at x=10;
  // river 3 joins river 1 at its point 3. Orders: river 1 becomes 2 below river 3, the main river
  // becomes 2 below river 1 and stays 2 past river 2: one order-2 stream, four order-1 streams.
  std::vector<RiverPath> paths(4);
  for (int x = 0; x <= 20; ++x) paths[0].line.push_back({double(x), 0});
  for (int y = 8; y >= 0; --y) paths[1].line.push_back({5, double(y)});
  paths[1].into = 0, paths[1].at = 5;
  paths[2].line = {{10, 5}, {10, 0}}, paths[2].into = 0, paths[2].at = 10;
  paths[3].line = {{0, 5}, {5, 5}}, paths[3].into = 1, paths[3].at = 3;
  const std::vector<RiverReach> reaches = reaches_from_paths(paths);
  ASSERT_EQ(reaches.size(), 7u);  // main: 3 reaches, river 1: 2, rivers 2 and 3: 1 each
  EXPECT_EQ(reaches[0].strahler, 1);
  EXPECT_EQ(reaches[1].strahler, 2);
  EXPECT_EQ(reaches[2].strahler, 2);
  EXPECT_EQ(reaches[2].downstream, -1);
  EXPECT_EQ(reaches[0].downstream, 1);
  EXPECT_EQ(reaches[4].downstream, 1);  // river 1's lower reach joins the main river's second reach
  EXPECT_EQ(reaches[4].strahler, 2);
  EXPECT_EQ(reaches[5].downstream, 2);  // river 2 joins the third
  EXPECT_EQ(reaches[6].downstream, 4);  // river 3 joins river 1's lower reach
  RiverRidgePlan s;
  s.rivers = reaches;
  const HortonRatios h = horton_ratios(s, 1.0);
  EXPECT_EQ(h.streams, (std::vector<int>{4, 1}));
  EXPECT_NEAR(*h.bifurcation, 4.0, 1e-12);
  // The order-2 stream: river 1 below point 3 (5 cells) + the main river from x=5 (15 cells).
  EXPECT_DOUBLE_EQ(h.mean_length_m[1], 20.0);
}

TEST(RiverRidgePlan, CycleIsRefused) {
  RiverRidgePlan s;
  s.rivers.push_back({row_line(0, 0, 1), 1, 1, 0});
  s.rivers.push_back({row_line(1, 0, 1), 0, 1, 0});
  EXPECT_THROW(assign_strahler(s), std::logic_error);
}

TEST(RiverChecks, ConsistencyOnATinyRaster) {
  // An order-2 D8 stream along row 5 of a 12x12 grid.
  Raster<std::uint8_t> order(12, 12, Georef{}, 0);
  for (int c = 0; c < 12; ++c) order(c, 5) = 2;
  Raster<float> dem(12, 12, Georef{}, 100.0f);
  RiverRidgePlan s;
  s.rivers.push_back({row_line(7, 0, 11), -1, 1, 0});  // 2 cells away, order 1: matched, ends on the border
  s.rivers.push_back({row_line(8, 0, 6), -1, 1, 0});   // 3 cells away: not matched, ends inland
  s.rivers.push_back({row_line(5, 0, 5), -1, 4, 0});   // on it but order 4: not matched, ends inland
  const D8Consistency c = d8_consistency(s, order, dem, 10.0);
  EXPECT_NEAR(c.river_length_m, (11 + 6 + 5) * 10.0, 1e-9);
  EXPECT_NEAR(c.matched_length_m, 110.0, 1e-9);
  EXPECT_EQ(c.mouths, 3);
  EXPECT_EQ(c.ending_in_pit, 2);
  // A sea cell beside the inland end of the second river makes it an outlet.
  dem(7, 8) = -5;
  EXPECT_EQ(d8_consistency(s, order, dem, 10.0, 2.0, 0.0).ending_in_pit, 1);
}

TEST(RiverChecks, DrainageDensityAndChannelHeadThreshold) {
  RiverRidgePlan s;
  s.rivers.push_back({row_line(0, 0, 10), -1, 1, 0});  // 10 cells of 100 m: 1 km
  Raster<float> dem(10, 10, Georef{}, 1.0f);            // 1 km2
  dem(0, 0) = std::numeric_limits<float>::quiet_NaN();
  EXPECT_NEAR(drainage_density(s, dem, 100.0), 1.0 / 0.99, 1e-12);
  // Channel heads: the sources of a binary tree sit on rows 0-3 at x = 0; their areas are 5, 40,
  // 10, 20 m2: the median (upper of the two middle values) is 20.
  Raster<double> area(41, 21, Georef{}, 1e6);
  area(0, 0) = 5, area(0, 1) = 40, area(0, 2) = 10, area(0, 3) = 20;
  EXPECT_EQ(channel_head_threshold_m2(binary_tree(), area), 20.0);
}

TEST(RiverChecks, StreamOrderRasterFromLines) {
  Georef g;
  g.transform = {1000, 10, 0, 2000, 0, -10};
  VectorLayer streams;
  streams.geometry = GeometryType::line_string;
  streams.fields = {{"strahler", FieldType::integer}};
  streams.features.push_back({{{g.cell_centre(1, 1), g.cell_centre(2, 2)}}, {std::int64_t(3)}});
  const auto order = stream_order_raster(streams, g, 4, 4);
  EXPECT_EQ(order(1, 1), 3);
  EXPECT_EQ(order(2, 2), 3);
  EXPECT_EQ(order(2, 1), 0);
}

}  // namespace
}  // namespace terrapolis::generate
