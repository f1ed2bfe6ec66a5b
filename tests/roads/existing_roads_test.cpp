// Existing roads (roads.existing): drawn onto the grid, reused at their class's discount, never
// built again; the layers tell the new roads from them.
// SPDX-License-Identifier: MIT
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>
#include <random>

#include "roads/existing_roads.hpp"
#include "roads/road_network.hpp"
#include "roads_fixtures.hpp"

using namespace terrapolis;
using namespace terrapolis::roads;

namespace {

/// A flat valley floor (rows 6-34) between steep sides, 100 x 40 cells of 10 m.
Dem valley() {
  return test::make_dem(100, 40, 10.0, [](int, int r) { return r < 6 ? 100.0 + 30 * (6 - r) : r > 34 ? 100.0 + 30 * (r - 34) : 100.0; });
}

/// A line layer in the DEM's CRS through the given cell centres, with a `class` field.
VectorLayer lines(const Dem& dem, const std::vector<std::vector<std::array<double, 2>>>& paths, const std::vector<std::string>& classes) {
  VectorLayer l;
  l.geometry = GeometryType::line_string;
  l.crs = dem.georef().crs;
  l.fields = {{"class", FieldType::string}};
  for (std::size_t k = 0; k < paths.size(); ++k) {
    Feature f;
    f.parts.emplace_back();
    for (const auto& p : paths[k]) f.parts[0].push_back(dem.georef().cell_centre(p[0], p[1]));
    f.values = {classes[k]};
    l.features.push_back(std::move(f));
  }
  return l;
}

Link link(const Dem& dem, std::int64_t from, std::int64_t to, std::array<int, 4> e, RoadClass c) {
  return {from, to, dem.georef().cell_centre(e[0], e[1]), dem.georef().cell_centre(e[2], e[3]), c};
}

struct Valley {
  Dem dem = valley();
  TerrainField terrain{dem, 0.0, 10.0, 0.0};
  CostModel model = [] {
    CostModel m = default_cost_model();
    m.bridge.enabled = m.tunnel.enabled = false;
    return m;
  }();
  RoadGraph graph{terrain, model, {4, 8, 1}};
  RoutingOptions options = [] {
    RoutingOptions o;
    o.graph = {4, 8, 1};
    return o;
  }();
  SilentProgress silent;
};

double new_km(const NetworkResult& r) {
  double km = 0;
  for (const NetworkSection& s : r.layout.sections) km += s.existing ? 0 : s.length_m / 1000;
  return km;
}

}  // namespace

TEST(ExistingRoads, ClassesFromOurNamesOpenStreetMapAndNationalTags) {
  EXPECT_EQ(existing_road_class("motorway"), RoadClass::motorway);
  EXPECT_EQ(existing_road_class("trunk_link"), RoadClass::motorway);
  EXPECT_EQ(existing_road_class("primary"), RoadClass::national);
  EXPECT_EQ(existing_road_class("national"), RoadClass::national);
  EXPECT_EQ(existing_road_class("secondary"), RoadClass::departmental);
  EXPECT_EQ(existing_road_class("Tertiary"), RoadClass::departmental);
  EXPECT_EQ(existing_road_class("D\xc3\xa9partementale"), RoadClass::departmental);
  EXPECT_EQ(existing_road_class("residential"), RoadClass::local);
  EXPECT_EQ(existing_road_class(""), RoadClass::local);
  EXPECT_EQ(existing_road_class("maritime"), std::nullopt);
}

TEST(ExistingRoads, LinesAreDrawnCellByCellAndCutAtTheGridsEdge) {
  const Valley v;
  // A diagonal that leaves the grid at the top and comes back: two chains.
  const ExistingRoads e = rasterise_roads(v.terrain, lines(v.dem, {{{10, 20}, {30, -5}, {50, 20}}, {{-20, -20}, {-5, -3}}}, {"primary", ""}));
  EXPECT_EQ(e.lines, 2u);
  EXPECT_EQ(e.outside, 1u);  // the second line never enters the grid
  ASSERT_EQ(e.chains.size(), 2u);
  for (const CellChain& c : e.chains) {
    ASSERT_EQ(c.structures.size() + 1, c.cells.size());
    for (std::size_t i = 0; i + 1 < c.cells.size(); ++i) {
      const int dc = int(c.cells[i + 1] % 100) - int(c.cells[i] % 100), dr = int(c.cells[i + 1] / 100) - int(c.cells[i] / 100);
      EXPECT_LE(std::max(std::abs(dc), std::abs(dr)), 1);
      EXPECT_NE(c.cells[i], c.cells[i + 1]);
    }
  }
  EXPECT_EQ(e.classes, (std::vector<RoadClass>{RoadClass::national, RoadClass::national}));
  EXPECT_EQ(e.chains[0].cells.front(), 20u * 100 + 10);
  EXPECT_EQ(e.chains[1].cells.back(), 20u * 100 + 50);
  EXPECT_GT(e.length_m[1], 2 * 200.0);  // two runs of about 20 rows each
  EXPECT_EQ(existing_roads_layer(v.terrain, e).features.size(), 2u);
}

TEST(ExistingRoads, ALinkAlongAnExistingRoadAddsNoNewKm) {
  // An existing road along row 20; the link between two of its cells runs on it from end to end,
  // between ends it joins: dropped as redundant, nothing built.
  Valley v;
  const std::vector<Link> net = {link(v.dem, 0, 1, {10, 20, 90, 20}, RoadClass::local)};
  const NetworkResult alone = route_network(v.terrain, v.graph, net, v.options, v.silent);
  ASSERT_EQ(alone.roads.size(), 1u);
  EXPECT_GT(new_km(alone), 0.75);
  const ExistingRoads e = rasterise_roads(v.terrain, lines(v.dem, {{{5, 20}, {95, 20}}}, {"departmental"}));
  const NetworkResult r = route_network(v.terrain, v.graph, net, v.options, v.silent, &e);
  EXPECT_TRUE(r.roads.empty());
  EXPECT_EQ(r.redundant, (std::vector<std::string>{"0-1"}));
  EXPECT_EQ(new_km(r), 0.0);
  // Kept (redundant_share above 1), it lies on the existing road from end to end: no new metre.
  v.options.redundant_share = 1.01;
  const NetworkResult kept = route_network(v.terrain, v.graph, net, v.options, v.silent, &e);
  ASSERT_EQ(kept.roads.size(), 1u);
  EXPECT_DOUBLE_EQ(kept.roads[0].existing_share, 1.0);
  EXPECT_EQ(new_km(kept), 0.0);
  const VectorLayer layer = roads_layer(v.terrain, kept.roads, &kept.layout);
  const int new_m = layer.field_index("new_m"), existing_m = layer.field_index("existing_m");
  ASSERT_GE(new_m, 0);
  EXPECT_EQ(std::get<double>(layer.features[0].values[std::size_t(new_m)]), 0.0);
  EXPECT_GT(std::get<double>(layer.features[0].values[std::size_t(existing_m)]), 750.0);
}

TEST(ExistingRoads, AnExistingMotorwayMakesAParallelLinkCheaperAndMostlyNotNew) {
  // A local link four rows off an existing motorway goes over to it, follows it and leaves it: its
  // cost falls, most of it lies on the motorway, and only the two spurs are new.
  Valley v;
  const std::vector<Link> net = {link(v.dem, 0, 1, {10, 24, 90, 24}, RoadClass::local)};
  const NetworkResult alone = route_network(v.terrain, v.graph, net, v.options, v.silent);
  ASSERT_EQ(alone.roads.size(), 1u);
  const ExistingRoads e = rasterise_roads(v.terrain, lines(v.dem, {{{2, 20}, {98, 20}}}, {"motorway"}));
  const NetworkResult r = route_network(v.terrain, v.graph, net, v.options, v.silent, &e);
  ASSERT_EQ(r.roads.size(), 1u);  // its ends are not on the motorway: kept
  EXPECT_LT(*r.roads[0].cost, 0.7 * *alone.roads[0].cost);
  EXPECT_GT(r.roads[0].existing_share, 0.75);
  EXPECT_LT(new_km(r), 0.3 * new_km(alone));
  std::size_t existing_sections = 0;
  for (const NetworkSection& s : r.layout.sections) existing_sections += s.existing;
  EXPECT_EQ(existing_sections, 1u);
  EXPECT_EQ(r.layout.sections.size(), 3u);  // spur, on the motorway, spur
  // A motorway's discount (0.6) draws the link harder than a local road's (0.3).
  const ExistingRoads local = rasterise_roads(v.terrain, lines(v.dem, {{{2, 20}, {98, 20}}}, {"residential"}));
  const NetworkResult weak = route_network(v.terrain, v.graph, net, v.options, v.silent, &local);
  ASSERT_EQ(weak.roads.size(), 1u);
  EXPECT_LT(*r.roads[0].cost, *weak.roads[0].cost);
}

TEST(ExistingRoads, RoutingAheadStillGivesTheRoadsOfOneLinkAfterTheOther) {
  // Links in a grid of towns across an existing road: the same layers whatever the look-ahead and threads.
  Valley v;
  std::vector<Link> net;
  std::mt19937_64 rng(7);
  std::uniform_int_distribution<int> col(8, 92), row(8, 32);
  for (std::int64_t k = 0; k < 10; ++k) net.push_back(link(v.dem, k, k + 1, {col(rng), row(rng), col(rng), row(rng)}, RoadClass(k % 4)));
  const ExistingRoads e = rasterise_roads(v.terrain, lines(v.dem, {{{2, 12}, {50, 26}, {98, 14}}, {{40, 8}, {44, 33}}}, {"primary", "tertiary"}));
  auto layers = [&](const NetworkResult& r) {
    std::string s;
    for (const auto& f : network_sections_layer(v.terrain, r.layout).features)
      for (const auto& p : f.parts[0]) s += std::to_string(p[0]) + " " + std::to_string(p[1]) + ";";
    for (const Road& road : r.roads) s += std::to_string(road.existing_share) + "|" + std::to_string(*road.cost) + "\n";
    return s;
  };
  v.options.lookahead = 1;
  std::string expected;
  {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
    expected = layers(route_network(v.terrain, v.graph, net, v.options, v.silent, &e));
  }
  for (std::size_t lookahead : {3, 16}) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 2);
    v.options.lookahead = lookahead;
    EXPECT_EQ(layers(route_network(v.terrain, v.graph, net, v.options, v.silent, &e)), expected) << "look-ahead " << lookahead;
  }
}
