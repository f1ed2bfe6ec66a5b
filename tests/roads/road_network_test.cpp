// Network routing: deterministic whatever the threads, maritime links, classes; Bézier router.
// SPDX-License-Identifier: MIT
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <utility>

#include "roads/road_network.hpp"
#include "roads_fixtures.hpp"

using namespace terrapolis;
using namespace terrapolis::roads;

namespace {

/// Two hilly islands in a sea 30 m deep.
Dem islands() {
  return test::make_dem(60, 40, 10.0, [](int c, int r) {
    const double a = 60 - 0.6 * ((c - 14) * (c - 14) + (r - 20) * (r - 20));
    const double b = 40 - 0.8 * ((c - 47) * (c - 47) + (r - 20) * (r - 20));
    return std::max({a, b, -30.0});
  });
}

std::vector<Link> network(const Dem& dem, const std::vector<std::array<int, 4>>& edges) {
  std::vector<Link> links;
  for (const auto& e : edges) {
    const std::int64_t id = std::int64_t(links.size());
    links.push_back({id, id + 1, dem.georef().cell_centre(e[0], e[1]), dem.georef().cell_centre(e[2], e[3]), RoadClass::departmental});
  }
  return links;
}

/// The default cost model without bridges and tunnels: roads on the surface only.
CostModel surface_model() {
  CostModel model = default_cost_model();
  model.bridge.enabled = model.tunnel.enabled = false;
  return model;
}

/// What the network tests route on: a DEM, its terrain (sea at 0 m) and road graph, and routing
/// options on that graph; each test states its DEM, graph, links and the options that differ.
struct RoutingScene {
  RoutingScene(Dem d, const GraphOptions& graph_options, const CostModel& model = surface_model())
      : dem(std::move(d)), terrain(dem, 0.0, 10.0, 0.0), graph(terrain, model, graph_options) {
    options.graph = graph_options;
  }
  RoutingScene(const RoutingScene&) = delete;  // the graph refers to this scene's terrain
  RoutingScene& operator=(const RoutingScene&) = delete;
  NetworkResult route(const std::vector<Link>& links) { return route_network(terrain, graph, links, options, silent); }

  Dem dem;
  TerrainField terrain;
  RoadGraph graph;
  RoutingOptions options;
  SilentProgress silent;
};

std::string dump(const VectorLayer& l) {
  std::string s;
  char buf[64];
  for (const auto& f : l.features) {
    for (const auto& p : f.parts[0]) {
      std::snprintf(buf, sizeof buf, "%.9f %.9f;", p[0], p[1]);
      s += buf;
    }
    for (const auto& v : f.values) {
      if (const auto* i = std::get_if<std::int64_t>(&v)) s += std::to_string(*i);
      if (const auto* d = std::get_if<double>(&v)) s += std::to_string(*d);
      if (const auto* t = std::get_if<std::string>(&v)) s += *t;
      s += "|";
    }
    s += "\n";
  }
  return s;
}

}  // namespace

TEST(RoadNetwork, SameOutputWithOneAndTwoThreadsAndFerriesBetweenIslands) {
  CostModel model = default_cost_model();
  model.bridge.max_length_cells = model.tunnel.max_length_cells = 8;
  model.bridge.samples = model.tunnel.samples = 20;
  RoutingScene s(islands(), {4, 8, 9}, model);
  const std::vector<Link> net = network(s.dem, {{6, 20, 22, 20}, {14, 12, 14, 28}, {10, 17, 47, 20}, {42, 20, 52, 20}});
  s.options.max_grade_pct = {27, 27, 27, 27};  // the islands are steep: the default threshold's grade
  std::string outputs[2];
  for (int threads : {1, 2}) {
    for (Router router : {Router::galin, Router::bezier}) {
      tbb::global_control limit(tbb::global_control::max_allowed_parallelism, std::size_t(threads));
      s.options.router = router;
      const NetworkResult r = s.route(net);
      ASSERT_EQ(r.roads.size(), 4u);
      EXPECT_TRUE(r.roads[2].ferry);  // the two islands
      EXPECT_EQ(r.roads[2].router, "ferry");
      EXPECT_FALSE(r.roads[0].ferry);
      EXPECT_EQ(r.roads[0].router, router == Router::galin ? "galin" : "bezier");
      outputs[threads - 1] += dump(roads_layer(s.terrain, r.roads, &r.layout)) + dump(sections_layer(s.terrain, r.roads)) +
                              dump(network_sections_layer(s.terrain, r.layout)) + dump(junctions_layer(s.terrain, r.layout));
    }
  }
  EXPECT_EQ(outputs[0], outputs[1]);
}

TEST(RoadNetwork, ClassFromTheSmallerEndsSizeClassByQuarters) {
  // 8 size classes: classes 0-1 are the top quarter, 2-3 the second, 4-5 the third, 6-7 the last.
  EXPECT_EQ(link_class(0, 1, 8), RoadClass::motorway);
  EXPECT_EQ(link_class(0, 2, 8), RoadClass::national);      // the smaller end decides
  EXPECT_EQ(link_class(5, 1, 8), RoadClass::departmental);
  EXPECT_EQ(link_class(7, 0, 8), RoadClass::local);
  EXPECT_EQ(link_class(0, 0, 1), RoadClass::motorway);       // one class: every town is a top town
  EXPECT_EQ(link_class(-1, 0, 8), RoadClass::departmental);  // an unknown city
  EXPECT_EQ(link_class(9, 9, 8), RoadClass::local);          // past the last class
  for (const RoadClassStyle& s : kRoadClasses) {
    EXPECT_EQ(road_class_named(s.name), s.road_class);
    EXPECT_EQ(s.colour.size(), 7u);
  }
  EXPECT_FALSE(road_class_named("highway"));
}

TEST(RoadNetwork, LinksKeepTheirClassAndFerriesAreMaritime) {
  RoutingScene s(islands(), {3, 1, 1});
  std::vector<Link> net = network(s.dem, {{6, 20, 22, 20}, {10, 17, 47, 20}});
  net[0].road_class = RoadClass::national;
  net[1].road_class = RoadClass::motorway;
  s.options.max_grade_pct = {27, 27, 27, 27};  // the islands are steep: the default threshold's grade
  const NetworkResult r = s.route(net);
  ASSERT_EQ(r.roads.size(), 2u);
  EXPECT_EQ(r.roads[0].road_class, RoadClass::national);
  EXPECT_EQ(r.roads[1].road_class, RoadClass::maritime);  // the two islands
}

TEST(BezierRouter, RefinementLeavesCellsACostLayerForbids) {
  // A flat plain with a forbidden block (a protected area, kappa = +infinity) across the straight
  // line: every straight position in it costs 10; refined, the curve leaves the block.
  const Dem dem = test::make_dem(50, 50, 30.0, [](int, int) { return 100.0; });
  TerrainField terrain(dem, 0.0, 10.0, 0.0);
  Raster<float> kappa = dem.like<float>(0.0f);
  for (int r = 20; r <= 30; ++r)
    for (int c = 22; c <= 28; ++c) kappa(c, r) = std::numeric_limits<float>::infinity();
  terrain.add_cost_layer("reserve", kappa, {TransferFunction{}, TransferFunction{}, TransferFunction{}}, {true, false, false});
  auto inside = [&](const BezierResult& b) {
    int n = 0;
    for (const GridPoint& p : b.polyline) n += std::isinf(kappa(int(p.col), int(p.row)));
    return n;
  };
  BezierOptions o;
  o.seed = 3;
  o.max_evaluations = 1;
  const BezierResult straight = bezier_route(terrain, {5, 25}, {45, 25}, o);
  EXPECT_EQ(inside(straight), 7);
  EXPECT_DOUBLE_EQ(straight.worst, 10.0);
  o.max_evaluations = 1000;
  const BezierResult refined = bezier_route(terrain, {5, 25}, {45, 25}, o);
  EXPECT_EQ(inside(refined), 0);
  EXPECT_LE(refined.worst, 1.0);
}

TEST(BezierRouter, DeterministicAndNeverWorseThanTheStraightCurve) {
  const Dem dem = test::make_dem(50, 50, 30.0, [](int c, int r) {
    return 100 + 400 * std::exp(-((c - 25) * (c - 25) + (r - 25) * (r - 25)) / 60.0);  // a hill on the way
  });
  const TerrainField terrain(dem, 0.0, 10.0, 0.0);
  BezierOptions o;
  o.seed = 5;
  o.max_evaluations = 300;
  const BezierResult a = bezier_route(terrain, {5, 25}, {45, 25}, o);
  const BezierResult b = bezier_route(terrain, {5, 25}, {45, 25}, o);
  o.max_evaluations = 1;
  const BezierResult straight = bezier_route(terrain, {5, 25}, {45, 25}, o);
  ASSERT_EQ(a.polyline.size(), b.polyline.size());
  for (std::size_t i = 0; i < a.polyline.size(); ++i) {
    EXPECT_EQ(a.polyline[i].col, b.polyline[i].col);
    EXPECT_EQ(a.polyline[i].row, b.polyline[i].row);
  }
  EXPECT_LT(a.cost, straight.cost);
  EXPECT_GT(a.control.size(), 2u);
  EXPECT_EQ(a.polyline.front().col, 5);
  EXPECT_EQ(a.polyline.back().col, 45);
}

TEST(RoadNetwork, ABudgetMarksLinksNotRoutedAndKeepsTheOthers) {
  RoutingScene s(islands(), {3, 8, 1});
  const std::vector<Link> net = network(s.dem, {{6, 20, 22, 20}, {14, 12, 14, 28}, {10, 17, 47, 20}});
  s.options.max_grade_pct = {27, 27, 27, 27};  // the islands are steep: the default threshold's grade
  s.options.max_seconds = 1e-9;  // every search runs out at its first check
  const NetworkResult r = s.route(net);
  EXPECT_EQ(r.over_budget.size(), 2u);  // the two land links
  ASSERT_EQ(r.roads.size(), 1u);        // the maritime link needs no search
  EXPECT_TRUE(r.roads[0].ferry);
  EXPECT_TRUE(r.failed.empty());
  s.options.max_seconds = 3600;
  EXPECT_TRUE(s.route(net).over_budget.empty());
}

namespace {

/// A flat valley floor `cols` x 40 cells of 10 m between steep sides (rows < 6 and > 34).
Dem valley(int cols = 100) {
  return test::make_dem(cols, 40, 10.0, [](int, int r) { return r < 6 ? 100.0 + 30 * (6 - r) : r > 34 ? 100.0 + 30 * (r - 34) : 100.0; });
}

/// Share of a road's chain cells lying on `row`.
double share_on_row(const TerrainField& t, const Road& r, int row) {
  std::size_t n = 0;
  for (std::uint32_t c : r.chain.cells) n += c / std::uint32_t(t.cols()) == std::uint32_t(row);
  return double(n) / double(r.chain.cells.size());
}

}  // namespace

TEST(RoadNetwork, ASecondRoadJoinsTheFirstAlongTheValley) {
  // A motorway along row 20, then a local road parallel to it 4 cells away (rows 24, 10 -> 90).
  // On its own the local road runs straight along row 24 (80 cells). With a 50 % discount on the
  // motorway's cells, going over to it (about 4 cells each way) and along it (72 cells at half
  // price, 36) costs about 45: the local road joins the motorway and leaves it near its end.
  RoutingScene s(valley(), {4, 8, 1});
  std::vector<Link> net = network(s.dem, {{10, 24, 90, 24}, {5, 20, 95, 20}});
  net[0].road_class = RoadClass::local;
  net[1].road_class = RoadClass::motorway;  // routed first although listed second
  s.options.reuse_discount = {0, 0, 0, 0};  // on its own: the roads ignore each other
  const NetworkResult apart = s.route(net);
  ASSERT_EQ(apart.roads.size(), 2u);
  EXPECT_GT(share_on_row(s.terrain, apart.roads[0], 24), 0.9);
  EXPECT_EQ(share_on_row(s.terrain, apart.roads[0], 20), 0.0);
  EXPECT_TRUE(apart.layout.junctions.empty());
  EXPECT_EQ(apart.layout.sections.size(), 2u);

  s.options.reuse_discount = {0.5, 0.5, 0.5, 0.5};  // half price on the motorway
  const NetworkResult joined = s.route(net);
  ASSERT_EQ(joined.roads.size(), 2u);  // not redundant: its ends were not on the network
  EXPECT_TRUE(joined.redundant.empty());
  EXPECT_GT(share_on_row(s.terrain, joined.roads[0], 20), 0.75);
  EXPECT_LT(*joined.roads[0].cost, 0.7 * *apart.roads[0].cost);
  // Trunk: west part, shared part, east part; two spurs; two junctions where the spurs meet it.
  const RoadNetworkLayout& l = joined.layout;
  ASSERT_EQ(l.junctions.size(), 2u);
  for (const Junction& j : l.junctions) {
    EXPECT_EQ(j.degree, 3);
    EXPECT_EQ(j.roads, 2u);
    EXPECT_EQ(j.classes, (std::vector<RoadClass>{RoadClass::motorway, RoadClass::local}));
    EXPECT_EQ(j.cell / std::uint32_t(s.terrain.cols()), 20u);
  }
  ASSERT_EQ(l.sections.size(), 5u);
  std::size_t shared = 0;
  for (const NetworkSection& s : l.sections) {
    if (s.roads.size() != 2) continue;
    ++shared;
    EXPECT_EQ(s.road_class, RoadClass::motorway);  // the highest class of its roads
    EXPECT_GT(s.length_m, 600.0);
  }
  EXPECT_EQ(shared, 1u);
  EXPECT_EQ(l.road_sections[0].size(), 3u);  // spur, shared trunk, spur
  EXPECT_EQ(l.road_sections[1].size(), 3u);  // west, shared, east
}

TEST(RoadNetwork, ALinkRunningOnEarlierRoadsBetweenJoinedEndsIsDropped) {
  // A motorway A-B along row 20, a town C two cells off it. A-C joins the motorway and branches to
  // C (its end C is new: kept); C-B then runs on A-C's spur and the motorway only, between ends
  // the network already joins: redundant.
  RoutingScene s(valley(), {4, 8, 1});
  std::vector<Link> net = network(s.dem, {{10, 20, 90, 20}, {10, 20, 52, 22}, {52, 22, 90, 20}});
  net[0].road_class = RoadClass::motorway;
  net[1].road_class = net[2].road_class = RoadClass::local;
  net[2].from = 7;
  const NetworkResult r = s.route(net);
  EXPECT_EQ(r.roads.size(), 2u);
  ASSERT_EQ(r.redundant.size(), 1u);
  EXPECT_EQ(r.redundant[0], "7-3");
  s.options.redundant_share = 1.01;  // keeps every link
  EXPECT_EQ(s.route(net).roads.size(), 3u);
}

TEST(RoadNetwork, GradesNeverExceedTheClassLimitOnACone) {
  // A cone of 20 degree flanks (36 %) on a plain: every class climbs to a town half-way up within
  // its design grade (slanting across the flank), its surface never steeper; tighter classes climb longer.
  const Dem cone = test::make_dem(80, 80, 10.0, [](int c, int r) {
    const double d = std::hypot(c - 39.5, r - 39.5) * 10.0;
    return 20.0 + std::max(0.0, 120.0 - d * std::tan(20.0 * std::numbers::pi / 180));
  });
  RoutingScene s(cone, {5, 16, 3});
  s.options.reuse_discount = {0, 0, 0, 0};
  s.options.max_grade_pct = {8, 10, 12, 16};
  double previous = 0;
  for (RoadClass c : {RoadClass::local, RoadClass::departmental, RoadClass::national, RoadClass::motorway}) {
    std::vector<Link> net = network(s.dem, {{2, 40, 24, 40}});  // 60 m up at 16 cells from the top
    net[0].road_class = c;
    const NetworkResult r = s.route(net);
    ASSERT_EQ(r.roads.size(), 1u) << name_of(c);
    const RoadStats& stats = r.roads[0].stats;
    const double limit = s.options.max_grade_pct[std::size_t(c)];
    EXPECT_NEAR(stats.grade_limit_pct, limit, 1e-9);
    EXPECT_LE(stats.max_grade_pct, limit * (1 + 1e-6)) << name_of(c);
    EXPECT_EQ(stats.over_limit_m, 0.0) << name_of(c);
    EXPECT_EQ(stats.longest_over_limit_m, 0.0) << name_of(c);
    EXPECT_EQ(stats.water_m, 0.0);
    EXPECT_GT(stats.length_m, previous) << name_of(c);  // a gentler grade is a longer road
    previous = stats.length_m;
  }
}

namespace {

/// Random hills (a few Gaussian bumps above a plain at 50 m) on n x n cells of 10 m, with towns at
/// random cells each linked to its two nearest neighbours, in random classes.
struct RandomNetwork {
  Dem dem;
  std::vector<Link> links;
};
RandomNetwork random_network(std::mt19937_64& rng, int n, int towns) {
  std::uniform_real_distribution<double> u(0, 1);
  struct Bump { double c, r, h, s; };
  std::vector<Bump> bumps;
  for (int i = 0; i < 8; ++i) bumps.push_back({u(rng) * n, u(rng) * n, 10 + 40 * u(rng), 3 + 6 * u(rng)});
  RandomNetwork net{test::make_dem(n, n, 10.0, [&](int c, int r) {
    double z = 50;
    for (const auto& b : bumps) z += b.h * std::exp(-((c - b.c) * (c - b.c) + (r - b.r) * (r - b.r)) / (2 * b.s * b.s));
    return z;
  }), {}};
  std::vector<std::array<int, 2>> at;
  for (int i = 0; i < towns; ++i) at.push_back({2 + int(u(rng) * (n - 4)), 2 + int(u(rng) * (n - 4))});
  for (int i = 0; i < towns; ++i) {
    std::vector<int> near;
    for (int j = 0; j < towns; ++j)
      if (j != i) near.push_back(j);
    auto d2 = [&](int j) { return std::hypot(at[j][0] - at[i][0], at[j][1] - at[i][1]); };
    std::sort(near.begin(), near.end(), [&](int x, int y) { return d2(x) < d2(y); });
    for (int k = 0; k < 2; ++k) {
      const int j = near[std::size_t(k)];
      if (j < i) continue;  // each pair once
      net.links.push_back({i, j, net.dem.georef().cell_centre(at[i][0], at[i][1]), net.dem.georef().cell_centre(at[j][0], at[j][1]),
                           RoadClass(int(u(rng) * 4))});
    }
  }
  return net;
}

}  // namespace

TEST(RoadNetwork, RoutingAheadGivesTheRoadsOfOneLinkAfterTheOther) {
  // Differential: links routed ahead in parallel (kept only when the roads added meanwhile change
  // nothing they read) against one link after the other, on random networks that reuse each
  // other's roads; the same layers byte for byte whatever the look-ahead and the threads.
  std::mt19937_64 rng(2026);
  std::size_t rerouted = 0;
  for (int trial = 0; trial < 4; ++trial) {
    const RandomNetwork net = random_network(rng, 48, 9);
    RoutingScene s(net.dem, {4, 8, 1});
    s.options.max_grade_pct = {30, 30, 30, 30};
    auto layers = [&](const NetworkResult& r) {
      return dump(roads_layer(s.terrain, r.roads, &r.layout)) + dump(network_sections_layer(s.terrain, r.layout)) +
             dump(junctions_layer(s.terrain, r.layout));
    };
    s.options.lookahead = 1;  // one link after the other: each routed once
    NetworkResult sequential;
    {
      tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
      sequential = s.route(net.links);
    }
    EXPECT_EQ(sequential.searches, net.links.size());
    ASSERT_GE(sequential.roads.size(), 3u);
    EXPECT_FALSE(sequential.layout.junctions.empty()) << "the roads should share cells, trial " << trial;
    const std::string expected = layers(sequential);
    for (std::size_t lookahead : {2, 3, 16})
      for (int threads : {1, 2}) {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, std::size_t(threads));
        s.options.lookahead = lookahead;
        const NetworkResult r = s.route(net.links);
        EXPECT_EQ(layers(r), expected) << "trial " << trial << ", look-ahead " << lookahead << ", " << threads << " threads";
        EXPECT_EQ(r.redundant, sequential.redundant);
        EXPECT_GE(r.searches, net.links.size());
        rerouted += r.searches - net.links.size();
      }
  }
  EXPECT_GT(rerouted, 0u);  // some attempts were stale and routed again
}

TEST(RoadNetwork, ALinkRoutedAheadFarFromTheRoadsBeforeItIsKept) {
  // The first road changes the smallest factor, so the link routed ahead of it is routed again
  // (searches 1 and 2, then 2 again). The third link, at the other end of a long valley, is routed
  // ahead of the second: its search never reads a cell of the second road, so it is kept (4
  // searches); crossing the second road instead, it is routed again (5).
  RoutingScene s(valley(220), {4, 8, 1});
  s.options.lookahead = 2;
  const NetworkResult apart = s.route(network(s.dem, {{5, 20, 100, 20}, {10, 28, 90, 30}, {150, 20, 210, 22}}));
  EXPECT_EQ(apart.roads.size() + apart.redundant.size(), 3u);
  EXPECT_EQ(apart.searches, 4u);
  const NetworkResult crossing = s.route(network(s.dem, {{5, 20, 100, 20}, {10, 28, 90, 30}, {60, 30, 130, 10}}));
  EXPECT_EQ(crossing.roads.size() + crossing.redundant.size(), 3u);
  EXPECT_EQ(crossing.searches, 5u);
}
