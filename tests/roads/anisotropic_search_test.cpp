// The anisotropic search: A*, bidirectional A* and Dijkstra agree; masks, bridges, tunnels.
// SPDX-License-Identifier: MIT
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "core/error.hpp"
#include "roads/anisotropic_search.hpp"
#include "roads/road_geometry.hpp"
#include "roads_fixtures.hpp"

using namespace terrapolis;
using namespace terrapolis::roads;

namespace {

/// Smooth random hills with a few pits below sea level.
Dem random_dem(std::mt19937_64& rng, int n) {
  std::uniform_real_distribution<double> u(0, 1);
  struct Bump { double c, r, h, s; };
  std::vector<Bump> bumps;
  for (int i = 0; i < 6; ++i) bumps.push_back({u(rng) * n, u(rng) * n, (u(rng) - 0.3) * 25, 1.5 + 3 * u(rng)});
  return test::make_dem(n, n, 10.0, [&](int c, int r) {
    double z = 5;
    for (const auto& b : bumps) z += b.h * std::exp(-((c - b.c) * (c - b.c) + (r - b.r) * (r - b.r)) / (2 * b.s * b.s));
    return z;
  });
}

CostModel random_model(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(0, 1);
  CostModel m = default_cost_model();
  m.road.slope_deg.threshold = 8 + 20 * u(rng);
  m.road.slope_deg.points = {{0, 1}, {5, 1 + 3 * u(rng)}, {20, 5 + 10 * u(rng)}};
  m.bridge.enabled = u(rng) < 0.6;
  m.tunnel.enabled = u(rng) < 0.6;
  for (StructureCosts* s : {&m.bridge, &m.tunnel}) {
    s->min_length_cells = 2;
    s->max_length_cells = 5;
    s->samples = 15;
  }
  m.bridge.height_m = {{{0, 1 + 3 * u(rng)}, {150, 10}}, 150};
  m.tunnel.depth_m = {{{0, 1 + 3 * u(rng)}, {15, 8}}, 1000};
  return m;
}

/// A random problem on a 16 x 16 grid: terrain, cost model and graph, built in place (the graph
/// holds references to the terrain and the model).
struct RandomProblem {
  Dem dem;
  CostModel model;
  TerrainField terrain;
  RoadGraph graph;
  explicit RandomProblem(std::mt19937_64& rng)
      : dem(random_dem(rng, 16)),
        model(random_model(rng)),
        terrain(dem, 0.0, 10.0, 0.0),
        graph(terrain, model, GraphOptions{1 + int(rng() % 3), int(std::vector<int>{1, 3, 8}[rng() % 3]), rng()}) {}
};

}  // namespace

TEST(AnisotropicSearch, AStarBidirectionalAndDijkstraAgreeOnRandomProblems) {
  std::mt19937_64 rng(42);
  int found = 0;
  for (int trial = 0; trial < 80; ++trial) {
    const RandomProblem problem(rng);
    const RoadGraph& graph = problem.graph;
    const Cell a{int(rng() % 16), int(rng() % 16)}, b{int(rng() % 16), int(rng() % 16)};
    const SearchResult d = shortest_path(graph, a, b, SearchMethod::dijkstra);
    const SearchResult s = shortest_path(graph, a, b, SearchMethod::astar);
    const SearchResult bi = shortest_path(graph, a, b, SearchMethod::bidirectional);
    const SearchResult sd = shortest_path(graph, a, b, SearchMethod::astar_distance);
    ASSERT_EQ(d.found, s.found) << trial;
    ASSERT_EQ(d.found, sd.found) << trial;
    ASSERT_EQ(d.found, bi.found) << trial;
    if (!d.found) continue;
    ++found;
    EXPECT_NEAR(s.cost, d.cost, 1e-9 * (1 + d.cost)) << trial;
    EXPECT_NEAR(bi.cost, d.cost, 1e-9 * (1 + d.cost)) << trial;
    EXPECT_NEAR(sd.cost, d.cost, 1e-9 * (1 + d.cost)) << trial;
    EXPECT_LE(s.expanded, d.expanded) << trial;
    EXPECT_LE(sd.expanded, d.expanded) << trial;
    EXPECT_LE(graph.lower_bound(a, b), d.cost * (1 + 1e-12)) << trial;  // the heuristic is admissible
    // The returned paths cost what the searches say (every arc finite, turns included).
    for (const SearchResult* r : {&d, &s, &bi, &sd}) {
      ASSERT_EQ(r->cells.front(), a);
      ASSERT_EQ(r->cells.back(), b);
      ASSERT_EQ(r->structures.size() + 1, r->cells.size());
    }
  }
  EXPECT_GE(found, 40);
}

TEST(AnisotropicSearch, RoadsSharingATargetSearchKeepDijkstrasCosts) {
  // Every heuristic, several sources in turn to one target with one shared TargetSearch (the
  // relaxed reverse search resumed and re-keyed for each source): each cost is Dijkstra's.
  std::mt19937_64 rng(7);
  int found = 0;
  for (int trial = 0; trial < 30; ++trial) {
    const RandomProblem problem(rng);
    const RoadGraph& graph = problem.graph;
    const Cell target{int(rng() % 16), int(rng() % 16)};
    for (SearchMethod method : {SearchMethod::astar, SearchMethod::astar_distance, SearchMethod::bidirectional, SearchMethod::dijkstra}) {
      TargetSearch shared(graph, target);
      for (int road = 0; road < 4; ++road) {
        const Cell source{int(rng() % 16), int(rng() % 16)};
        const SearchResult d = shortest_path(graph, source, target, SearchMethod::dijkstra);
        const SearchResult s = shortest_path(graph, source, target, method, 60'000'000, nullptr, 0, &shared);
        ASSERT_EQ(d.found, s.found) << trial << " road " << road;
        if (!d.found) continue;
        ++found;
        EXPECT_NEAR(s.cost, d.cost, 1e-9 * (1 + d.cost)) << trial << " road " << road;
        ASSERT_EQ(s.cells.front(), source);
        ASSERT_EQ(s.cells.back(), target);
      }
    }
  }
  EXPECT_GE(found, 200);
  const Dem dem = random_dem(rng, 16);
  const TerrainField terrain(dem, 0.0, 10.0, 0.0);
  const RoadGraph graph(terrain, default_cost_model(), GraphOptions{});
  TargetSearch shared(graph, {3, 3});
  EXPECT_THROW(shortest_path(graph, {0, 0}, {4, 4}, SearchMethod::astar, 60'000'000, nullptr, 0, &shared), Error);
}

TEST(AnisotropicSearch, EveryHeuristicKeepsDijkstrasCostWithRoadReuse) {
  // Random roads already built (cells at factor 0.3..1) and a shared target search reused across
  // discounts: every search returns Dijkstra's cost for the discounted costs, never above the
  // undiscounted optimum.
  std::mt19937_64 rng(11);
  int found = 0, cheaper = 0;
  for (int trial = 0; trial < 40; ++trial) {
    const RandomProblem problem(rng);
    const RoadGraph& graph = problem.graph;
    const Cell target{int(rng() % 16), int(rng() % 16)};
    std::vector<float> factor(problem.terrain.size(), 1.0f);
    const int row = int(rng() % 16);
    for (int c = 0; c < 16; ++c) factor[problem.terrain.index(c, row)] = 0.3f + 0.2f * float(rng() % 3);  // a road along a row
    for (int r = 0; r < 16; ++r) factor[problem.terrain.index(int(rng() % 16), r)] = 0.5f;                // and scattered cells
    const ArcDiscount discount{factor, 0.3};
    TargetSearch shared(graph, target);
    for (int road = 0; road < 3; ++road) {
      const Cell source{int(rng() % 16), int(rng() % 16)};
      const SearchResult plain = shortest_path(graph, source, target, SearchMethod::dijkstra);
      const SearchResult d = shortest_path(graph, source, target, SearchMethod::dijkstra, 60'000'000, nullptr, 0, nullptr, &discount);
      ASSERT_EQ(d.found, plain.found) << trial;
      if (!d.found) continue;
      ++found;
      EXPECT_LE(d.cost, plain.cost * (1 + 1e-12)) << trial;
      cheaper += d.cost < 0.999 * plain.cost;
      for (SearchMethod method : {SearchMethod::astar, SearchMethod::astar_distance, SearchMethod::bidirectional}) {
        const SearchResult s = shortest_path(graph, source, target, method, 60'000'000, nullptr, 0,
                                             method == SearchMethod::astar ? &shared : nullptr, &discount);
        ASSERT_TRUE(s.found) << trial;
        EXPECT_NEAR(s.cost, d.cost, 1e-9 * (1 + d.cost)) << trial << " method " << int(method);
      }
    }
  }
  EXPECT_GE(found, 60);
  EXPECT_GE(cheaper, 20);  // the discount does change the costs
}

TEST(AnisotropicSearch, NoSurfaceArcSteeperThanTheThresholdAndNoInfiniteArc) {
  std::mt19937_64 rng(7);
  for (int trial = 0; trial < 10; ++trial) {
    const Dem dem = random_dem(rng, 20);
    CostModel model = random_model(rng);
    const TerrainField terrain(dem, 0.0, 10.0, 0.0);
    const RoadGraph graph(terrain, model, {3, 8, 5});
    const SearchResult r = shortest_path(graph, {0, 0}, {19, 19}, SearchMethod::astar);
    if (!r.found) continue;
    const double step = 5.0;  // half the 10 m cell, the default integration step
    for (std::size_t i = 0; i + 1 < r.cells.size(); ++i) {
      const Cell p = r.cells[i], q = r.cells[i + 1];
      int arc = -1;
      for (std::size_t a = 0; a < graph.arcs().size(); ++a)
        if (graph.arcs()[a].dcol == q.col - p.col && graph.arcs()[a].drow == q.row - p.row && graph.arcs()[a].structure == r.structures[i])
          arc = int(a);
      ASSERT_GE(arc, 0);
      EXPECT_LT(graph.arc_cost(p, arc), kInfinity);
      if (r.structures[i] != Structure::road) continue;
      const double len = terrain.length_m({double(p.col), double(p.row)}, {double(q.col), double(q.row)});
      const int n = int(std::ceil(len / step));
      for (int k = 0; k < n; ++k) {
        const double t0 = double(k) / n, t1 = double(k + 1) / n;
        const double z0 = terrain.surface_at(p.col + t0 * (q.col - p.col), p.row + t0 * (q.row - p.row));
        const double z1 = terrain.surface_at(p.col + t1 * (q.col - p.col), p.row + t1 * (q.row - p.row));
        EXPECT_LE(std::atan(std::fabs(z1 - z0) / (len / n)) * 180 / std::numbers::pi, model.road.slope_deg.threshold + 1e-9);
      }
    }
  }
}

TEST(AnisotropicSearch, LargerMasksNeverCostMore) {
  std::mt19937_64 rng(3);
  for (int trial = 0; trial < 6; ++trial) {
    const Dem dem = random_dem(rng, 18);
    const CostModel model = random_model(rng);
    const TerrainField terrain(dem, 0.0, 10.0, 0.0);
    double previous = kInfinity;
    for (int k = 1; k <= 5; ++k) {
      const RoadGraph graph(terrain, model, {k, 8, 11});
      const SearchResult r = shortest_path(graph, {1, 2}, {16, 15}, SearchMethod::astar);
      const double cost = r.found ? r.cost : kInfinity;
      EXPECT_LE(cost, previous * (1 + 1e-12)) << "trial " << trial << " k " << k;
      previous = cost;
    }
  }
}

namespace {
/// A plateau at 100 m cut by a 80 m wide canyon (floor at 70 m) that stops 10 cells before the
/// south edge: the road goes round it or bridges it.
Dem canyon_dem() {
  return test::make_dem(60, 120, 10.0, [](int c, int r) { return (c >= 26 && c < 34 && r < 110) ? 70.0 : 100.0; });
}
/// The same with a 300 m high wall instead of the canyon.
Dem ridge_dem() {
  return test::make_dem(60, 120, 10.0, [](int c, int r) { return (c >= 27 && c < 33 && r < 110) ? 400.0 : 100.0; });
}
CostModel structures_model(bool bridges, bool tunnels) {
  CostModel m = default_cost_model();
  m.bridge.enabled = bridges;
  m.tunnel.enabled = tunnels;
  for (StructureCosts* s : {&m.bridge, &m.tunnel}) {
    s->max_length_cells = 10;
    s->samples = 1 << 20;  // every long arc: the test does not depend on the sampling
  }
  return m;
}
bool has_section(const TerrainField& t, const CostModel& m, const SearchResult& r, const std::string& kind) {
  for (const auto& s : road_sections(t, build_road_geometry(t, m, r)))
    if (s.structure == kind && s.length_m > 20) return true;
  return false;
}
}  // namespace

TEST(AnisotropicSearch, BridgeOverACanyonLowersTheCost) {
  const Dem dem = canyon_dem();
  const TerrainField terrain(dem, 0.0, 10.0, 0.0);
  const CostModel without = structures_model(false, false), with = structures_model(true, false);
  const RoadGraph g0(terrain, without, {3, 1, 1}), g1(terrain, with, {3, 1, 1});
  const SearchResult r0 = shortest_path(g0, {5, 5}, {54, 5}, SearchMethod::astar);
  const SearchResult r1 = shortest_path(g1, {5, 5}, {54, 5}, SearchMethod::astar);
  ASSERT_TRUE(r0.found);
  ASSERT_TRUE(r1.found);
  EXPECT_LT(r1.cost, 0.9 * r0.cost);
  EXPECT_TRUE(has_section(terrain, with, r1, "bridge"));
  EXPECT_FALSE(has_section(terrain, without, r0, "bridge"));
}

TEST(AnisotropicSearch, BridgeOverALake) {
  // Land at 20 m around a 12 m deep lake (bathymetry) that leaves a long way round by the south.
  const Dem dem = test::make_dem(60, 120, 10.0, [](int c, int r) { return (c >= 26 && c < 34 && r < 110) ? -12.0 : 20.0; });
  const TerrainField terrain(dem, 0.0, 10.0, 0.0);
  ASSERT_TRUE(terrain.has_bathymetry());
  const CostModel without = structures_model(false, false), with = structures_model(true, false);
  const RoadGraph g0(terrain, without, {3, 1, 1}), g1(terrain, with, {3, 1, 1});
  const SearchResult r0 = shortest_path(g0, {5, 5}, {54, 5}, SearchMethod::bidirectional);
  const SearchResult r1 = shortest_path(g1, {5, 5}, {54, 5}, SearchMethod::bidirectional);
  ASSERT_TRUE(r0.found && r1.found);
  EXPECT_LT(r1.cost, r0.cost);
  EXPECT_TRUE(has_section(terrain, with, r1, "bridge"));
}

TEST(AnisotropicSearch, TunnelThroughARidgeWherePays) {
  const Dem dem = ridge_dem();
  const TerrainField terrain(dem, 0.0, 10.0, 0.0);
  const CostModel without = structures_model(false, false);
  CostModel with = structures_model(false, true);
  with.tunnel.depth_m = {{{0, 5}, {15, 10}}, 1000};  // cheap enough to beat a 2 km detour
  const RoadGraph g0(terrain, without, {3, 1, 1}), g1(terrain, with, {3, 1, 1});
  const SearchResult r0 = shortest_path(g0, {5, 5}, {54, 5}, SearchMethod::astar);
  const SearchResult r1 = shortest_path(g1, {5, 5}, {54, 5}, SearchMethod::astar);
  ASSERT_TRUE(r0.found && r1.found);
  EXPECT_LT(r1.cost, r0.cost);
  EXPECT_TRUE(has_section(terrain, with, r1, "tunnel"));
  // Near the gap the detour is short: no tunnel there.
  const SearchResult r2 = shortest_path(g1, {5, 112}, {54, 112}, SearchMethod::astar);
  ASSERT_TRUE(r2.found);
  EXPECT_FALSE(has_section(terrain, with, r2, "tunnel"));
}

TEST(AnisotropicSearch, CurvatureLayersStraightenTheRoad) {
  // On flat ground every path of equal length ties without curvature; with 8 layers the turns
  // are priced, so the road has no sharp turn.
  const Dem dem = test::make_dem(30, 30, 10.0, [](int, int) { return 50.0; });
  const TerrainField terrain(dem, 0.0, 10.0, 0.0);
  CostModel m = default_cost_model();
  m.bridge.enabled = m.tunnel.enabled = false;
  const RoadGraph g(terrain, m, {5, 8, 1});
  const SearchResult r = shortest_path(g, {2, 3}, {27, 20}, SearchMethod::bidirectional);
  ASSERT_TRUE(r.found);
  const double straight = terrain.length_m({2, 3}, {27, 20});
  EXPECT_LT(r.cost, 1.01 * straight);
  for (std::size_t i = 2; i < r.cells.size(); ++i) {
    const double a0 = std::atan2(r.cells[i - 1].row - r.cells[i - 2].row, r.cells[i - 1].col - r.cells[i - 2].col);
    const double a1 = std::atan2(r.cells[i].row - r.cells[i - 1].row, r.cells[i].col - r.cells[i - 1].col);
    double turn = std::fabs(a1 - a0) * 180 / std::numbers::pi;
    if (turn > 180) turn = 360 - turn;
    EXPECT_LT(turn, 30.0);
  }
}

TEST(AnisotropicSearch, DenseVegetationIsWalkedAround) {
  // A forest block (density 1) on the straight line; its transfer function makes it 9 times dearer.
  const Dem dem = test::make_dem(40, 40, 10.0, [](int, int) { return 50.0; });
  TerrainField terrain(dem, 0.0, 10.0, 0.0);
  Raster<float> forest = dem.like<float>(0.f);
  for (int r = 10; r < 30; ++r)
    for (int c = 15; c < 25; ++c) forest(c, r) = 1.f;
  CostModel m = default_cost_model();
  m.bridge.enabled = m.tunnel.enabled = false;
  m.road.vegetation = {{{0, 0}, {1, 8}}, kInfinity};
  const RoadGraph plain(terrain, m, {4, 8, 1});
  const SearchResult r0 = shortest_path(plain, {5, 20}, {35, 20}, SearchMethod::astar);
  terrain.set_vegetation(forest);
  const RoadGraph wooded(terrain, m, {4, 8, 1});
  const SearchResult r1 = shortest_path(wooded, {5, 20}, {35, 20}, SearchMethod::astar);
  const SearchResult r2 = shortest_path(wooded, {5, 20}, {35, 20}, SearchMethod::dijkstra);
  ASSERT_TRUE(r0.found && r1.found && r2.found);
  EXPECT_NEAR(r1.cost, r2.cost, 1e-9 * r2.cost);
  EXPECT_GT(r1.cost, r0.cost);
  for (const Cell& c : r1.cells) EXPECT_FALSE(c.col > 15 && c.col < 24 && c.row > 10 && c.row < 29) << c.col << "," << c.row;
}

TEST(AnisotropicSearch, SampledLongArcsAreSymmetricAndListedBothWays) {
  // The precomputed out- and in-lists hold exactly the sampled arcs, and a pair is sampled (or not)
  // whichever end the search stands on; about s / |annulus| of the pairs are kept.
  const Dem dem = test::make_dem(70, 70, 10.0, [](int c, int r) { return 50.0 + 0.1 * c + 0.05 * r; });
  const TerrainField terrain(dem, 0.0, 10.0, 0.0);
  CostModel m = default_cost_model();
  for (StructureCosts* sc : {&m.bridge, &m.tunnel}) {
    sc->min_length_cells = 2;
    sc->max_length_cells = 6;
    sc->samples = 10;
  }
  const double expected = 10.0 / double(annulus_mask(2, 6).size());
  const RoadGraph g(terrain, m, {3, 8, 99});
  const auto& arcs = g.arcs();
  std::size_t kept = 0, total = 0;
  for (int r = 0; r < 70; r += 2)
    for (int c = 0; c < 70; c += 2)
      for (std::size_t a = g.surface_arcs(); a < arcs.size(); ++a) {
        const Cell from{c, r}, to{c + arcs[a].dcol, r + arcs[a].drow};
        if (!terrain.inside(to.col, to.row)) continue;
        int back = -1;
        for (std::size_t b = g.surface_arcs(); b < arcs.size(); ++b)
          if (arcs[b].dcol == -arcs[a].dcol && arcs[b].drow == -arcs[a].drow && arcs[b].structure == arcs[a].structure) back = int(b);
        ASSERT_GE(back, 0);
        const bool s = g.arc_sampled(from, int(a));
        EXPECT_EQ(s, g.arc_sampled(to, back));
        int ring = -1;
        for (std::size_t i = 0; i < g.rings().size() && ring < 0; ++i)
          for (int x : g.arcs_from(from, g.start_orientation(), int(i) + 1))
            if (x == int(a)) ring = int(i);
        EXPECT_EQ(s, ring >= 0);
        bool into = false;
        for (std::size_t i = 0; i < g.rings().size(); ++i)
          for (int x : g.arcs_into(to, arcs[a].orientation, int(i) + 1)) into = into || x == int(a);
        EXPECT_EQ(s, into);
        kept += s;
        ++total;
      }
  const double rate = double(kept) / double(total);
  EXPECT_GT(rate, 0.7 * expected);
  EXPECT_LT(rate, 1.3 * expected);
}

TEST(AnisotropicSearch, ALongArcCostsTheSameBothWays) {
  // The relaxed reverse search prices the arc w -> v as v -> w (the heuristic stays a lower bound
  // only if the two agree): the same deck over the same samples, bridges and tunnels, over water too.
  std::mt19937_64 rng(11);
  std::size_t finite = 0;
  for (int trial = 0; trial < 20; ++trial) {
    const RandomProblem problem(rng);
    const RoadGraph& g = problem.graph;
    const auto& arcs = g.arcs();
    for (int r = 0; r < 16; ++r)
      for (int c = 0; c < 16; ++c)
        for (std::size_t a = g.surface_arcs(); a < arcs.size(); ++a) {
          const Cell from{c, r}, to{c + arcs[a].dcol, r + arcs[a].drow};
          if (!problem.terrain.inside(to.col, to.row)) continue;
          int back = -1;
          for (std::size_t b = g.surface_arcs(); b < arcs.size() && back < 0; ++b)
            if (arcs[b].dcol == -arcs[a].dcol && arcs[b].drow == -arcs[a].drow && arcs[b].structure == arcs[a].structure) back = int(b);
          ASSERT_GE(back, 0);
          const double there = g.arc_cost(from, int(a)), back_cost = g.arc_cost(to, back);
          if (there == kInfinity) {
            EXPECT_EQ(back_cost, kInfinity) << trial;
            continue;
          }
          EXPECT_NEAR(back_cost, there, 1e-9 * there) << trial;
          ++finite;
        }
  }
  EXPECT_GT(finite, 1000u);
}

// Long arcs scale with the cell (the paper's 50..300 m on a 10 m grid) but never exceed the
// structure's longest_m: 3 km bridges and 5 km tunnels by default.
TEST(AnisotropicSearch, LongArcsStayUnderTheirLongestLength) {
  auto longest = [](double cell, Structure s) {
    const Dem dem = test::make_dem(64, 64, cell, [](int, int) { return 100.0; });
    const TerrainField terrain(dem, 0, 10, 10);
    const RoadGraph graph(terrain, default_cost_model(), {3, 8, 1});
    double metres = 0;
    for (const auto& a : graph.arcs())
      if (a.structure == s) metres = std::max(metres, std::hypot(a.dcol, a.drow) * cell);
    return metres;
  };
  EXPECT_NEAR(longest(10, Structure::bridge), 300, 10);     // 30 cells: the paper's range
  EXPECT_NEAR(longest(90, Structure::bridge), 2700, 90);    // 30 cells of an SRTM 3" grid
  EXPECT_LE(longest(460, Structure::bridge), 3000);         // capped on GEBCO 15"
  EXPECT_GT(longest(460, Structure::bridge), 2000);
  EXPECT_EQ(longest(1000, Structure::bridge), 0);           // 5 cells already exceed 3 km: no bridges
  EXPECT_LE(longest(1000, Structure::tunnel), 5000);
}

TEST(AnisotropicSearch, ABudgetStopsTheSearchAndSaysSo) {
  std::mt19937_64 rng(3);
  const Dem dem = random_dem(rng, 40);
  const TerrainField terrain(dem, -100.0, 10.0, 0.0);
  const RoadGraph graph(terrain, default_cost_model(), {3, 8, 1});
  for (SearchMethod m : {SearchMethod::astar, SearchMethod::bidirectional, SearchMethod::dijkstra}) {
    const SearchResult over = shortest_path(graph, {1, 1}, {38, 37}, m, 60'000'000, nullptr, 1e-9);
    EXPECT_TRUE(over.over_budget);
    EXPECT_FALSE(over.found);
    const SearchResult r = shortest_path(graph, {1, 1}, {38, 37}, m, 60'000'000, nullptr, 3600);
    EXPECT_FALSE(r.over_budget);
    EXPECT_TRUE(r.found);
  }
}
