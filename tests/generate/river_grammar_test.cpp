// Tests of the coast method (Génévaux et al.): grammar rules, selection, validity tests, ridge
// heights, determinism and the paper's Tab. 2 figures on a region of its smallest size.
// SPDX-License-Identifier: MIT
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "generate/river_grammar.hpp"

using namespace terrapolis;
using namespace terrapolis::generate;

namespace {

Raster<float> grid_of(int cols, int rows, double cell) {
  Georef g;
  g.transform = {0, cell, 0, 0, 0, -cell};
  return Raster<float>(cols, rows, g, 0.0f);
}

std::vector<std::vector<Point2>> square(double side) { return {{{0, 0}, {side, 0}, {side, side}, {0, side}}}; }

}  // namespace

TEST(RiverGrammar, RulesFollowTheProbabilities) {
  const CoastParams p;  // (P_c, P_s, P_a) = (0.2, 0.7, 0.1); rules tried in the order P_c, P_a, P_s
  EXPECT_EQ(choose_rule(0, 0.05, p), GrammarRule::fill);  // priority 0 always fills (rule 1)
  EXPECT_EQ(choose_rule(3, 0.05, p), GrammarRule::continuation);
  EXPECT_EQ(choose_rule(3, 0.199, p), GrammarRule::continuation);
  EXPECT_EQ(choose_rule(3, 0.25, p), GrammarRule::asymmetric);
  EXPECT_EQ(choose_rule(3, 0.31, p), GrammarRule::symmetric);
  EXPECT_EQ(choose_rule(1, 0.99, p), GrammarRule::symmetric);
}

TEST(RiverGrammar, MixedSelectionOfFigure5) {
  const std::vector<double> z{10, 12, 30};
  const std::vector<int> s{0, 3, 5};
  EXPECT_EQ(select_candidate(z, s, 0), 0u);    // ζ = 0: the lowest
  EXPECT_EQ(select_candidate(z, s, 5), 1u);    // 12 - 10 < 5: the higher priority of the two
  EXPECT_EQ(select_candidate(z, s, 100), 2u);  // ζ → ∞: the highest priority
  EXPECT_EQ(select_candidate({5, 3}, {2, 2}, 10), 1u);  // equal priorities: the lower
}

TEST(RiverGrammar, RidgeHeightFormula) {
  // q_z = max(10, 20, 15) + 0.1 × 500 = 70.
  EXPECT_DOUBLE_EQ(ridge_height(10, 20, 15, 0.1, 500), 70.0);
  EXPECT_DOUBLE_EQ(ridge_height(3, 1, 2, 0, 1e6), 3.0);
}

TEST(RiverGrammar, ValidityTests) {
  CoastParams p;  // e = 1000, σ = 800, δ = 300, κ = 0.3
  RiverGraph g(10000, 10000, square(10000), p);
  const int m = g.add_mouth({5000, 0}, 2);
  EXPECT_TRUE(g.valid(m, {5000, 1000}, 4));
  EXPECT_FALSE(g.valid(m, {5000, -1000}, 4));  // outside Ω
  EXPECT_FALSE(g.valid(m, {5000, 200}, 4));    // 200 m from Γ < δ
  const int a = g.add(m, {5000, 1000}, 4, 2);
  const int m2 = g.add_mouth({5500, 0}, 1);
  EXPECT_FALSE(g.valid(m2, {5500, 1000}, 4));  // 500 m from the edge m-a < σ
  const int m3 = g.add_mouth({7000, 0}, 1);
  EXPECT_TRUE(g.valid(m3, {7000, 1000}, 4));
  // Not along the coast either: an edge from a to (5000+..., 1000) ending 250 m from Γ... a side edge
  EXPECT_FALSE(g.valid(a, {5000, 2000}, 4 + 0.5 * 1000));  // slope 0.5 to a > κ
  EXPECT_TRUE(g.valid(a, {5000, 2000}, 4 + 0.1 * 1000));
  EXPECT_FALSE(g.valid(a, {9900, 1000}, 5));               // the edge ends 100 m from the east coast
}

TEST(RiverGrammar, SameSeedSameTerrain) {
  CoastParams p;
  Raster<float> a = grid_of(120, 100, 100), b = grid_of(120, 100, 100), c = grid_of(120, 100, 100);
  const auto coast = synthetic_coast(12000, 10000, 3);
  p.seed = 3;
  const CoastTerrain ta = generate_coast_terrain(a, coast, p);
  const CoastTerrain tb = generate_coast_terrain(b, coast, p);
  p.seed = 4;
  generate_coast_terrain(c, coast, p);
  ASSERT_EQ(a.size(), b.size());
  EXPECT_EQ(std::memcmp(a.values().data(), b.values().data(), a.size() * sizeof(float)), 0);
  EXPECT_NE(std::memcmp(a.values().data(), c.values().data(), a.size() * sizeof(float)), 0);
  EXPECT_EQ(ta.nodes.size(), tb.nodes.size());
}

TEST(RiverGrammar, VoronoiRidgesOfDegenerateNodeSets) {
  const auto lambda = [](Point2) { return 0.1; };
  // Two nodes (a region holding one river reach, as `generate --method coast --size 193x161
  // --cell 30 --seed 11` made) and three collinear ones: no triangle, so no ridge (it crashed).
  EXPECT_TRUE(voronoi_ridges({{0, 0}, {100, 0}}, {0, 5}, {{1, 0}}, lambda).empty());
  EXPECT_TRUE(voronoi_ridges({{0, 0}, {100, 0}, {200, 0}}, {0, 5, 9}, {{1, 0}, {2, 1}}, lambda).empty());
  EXPECT_TRUE(voronoi_ridges({}, {}, {}, lambda).empty());
  // A square of four nodes with one river edge: two triangles share one inner Delaunay edge (the
  // diagonal), which is not a river edge, so one ridge joins the two circumcentres. Both are the
  // square's centre here (cocircular points), at q_z = max(p_z) + λ d with d = 50√2.
  const auto square_ridges = voronoi_ridges({{0, 0}, {100, 0}, {100, 100}, {0, 100}}, {0, 1, 2, 3}, {{1, 0}}, lambda);
  ASSERT_EQ(square_ridges.size(), 1u);
  EXPECT_NEAR(square_ridges[0].a.x, 50, 1e-9);
  EXPECT_NEAR(square_ridges[0].a.y, 50, 1e-9);
  EXPECT_NEAR(std::max(square_ridges[0].za, square_ridges[0].zb), 3 + 0.1 * 50 * std::sqrt(2.0), 1e-9);  // node 3 is in one triangle
}

TEST(RiverGrammar, NetworkInvariants) {
  CoastParams p;
  p.seed = 5;
  Raster<float> g = grid_of(160, 160, 100);
  const auto coast = synthetic_coast(16000, 16000, 5);
  const CoastTerrain t = generate_coast_terrain(g, coast, p);
  ASSERT_GT(t.nodes.size(), 20u);
  RiverGraph domain(16000, 16000, coast, p);
  for (std::size_t i = 0; i < t.nodes.size(); ++i) {
    const RiverNode& n = t.nodes[i];
    if (n.parent < 0) continue;
    ASSERT_LT(n.parent, int(i));                                   // parents first
    EXPECT_GT(n.z, t.nodes[std::size_t(n.parent)].z);              // altitudes grow upstream
    EXPECT_TRUE(domain.inside(n.p));
    EXPECT_GT(domain.coast_distance(n.p), p.delta_m);
    EXPECT_GE(t.nodes[std::size_t(n.parent)].strahler, n.strahler);
    EXPECT_GE(t.nodes[std::size_t(n.parent)].area_km2, n.area_km2);
    EXPECT_NEAR(n.discharge_m3s, 0.42 * std::pow(n.area_km2, 0.69), 1e-9 * (1 + n.discharge_m3s));
  }
  // Ridges stand above the rivers they separate: every ridge vertex is at least the lowest node.
  for (const RidgeSegment& s : t.ridges) EXPECT_GE(std::min(s.za, s.zb), 0.0);
}

TEST(RiverGrammar, PaperTable2FiguresOnAMiniSizedIsland) {
  // Tab. 2's "Mini" is 969 km² with 404 km of river (0.42 km/km²) and 9,697 terrain primitives
  // (10 per km²). An island of about the same land area on a 100 m grid, default parameters.
  CoastParams p;
  p.seed = 1;
  Raster<float> g = grid_of(400, 400, 100);
  const CoastTerrain t = generate_coast_terrain(g, synthetic_coast(40000, 40000, 1), p);
  ASSERT_GT(t.land_km2, 500);
  const double density = t.river_km / t.land_km2, primitives = t.terrain_primitives / t.land_km2;
  EXPECT_GT(density, 0.36);
  EXPECT_LT(density, 0.52);
  EXPECT_GT(primitives, 9);
  EXPECT_LT(primitives, 11);
  std::size_t low = 0, streams = 0;
  for (const RiverNode& n : t.nodes)
    if (n.parent >= 0) {
      ++streams;
      low += n.priority <= 1 ? 1 : 0;
    }
  EXPECT_GT(double(low) / streams, 0.75);  // §4.3: > 75 % low-priority streams with (0.2, 0.7, 0.1)
}
