// Tests of the planar-map basins: tree text, Strahler orders, the facet inequalities and their LP
// on hand-computed cases, planarity and river descent of the built map, determinism.
// SPDX-License-Identifier: MIT
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "core/error.hpp"
#include "generate/planar_basins.hpp"

using namespace terrapolis;
using namespace terrapolis::generate;

TEST(PlanarBasins, ParsesTreesAndOrders) {
  const BinaryTree t = parse_tree("((..).)", "--tree");
  ASSERT_EQ(t.size(), 5);
  const std::vector<int> s = strahler_orders(t);
  EXPECT_EQ(s[0], 2);                            // a confluence of orders 2 and 1
  EXPECT_EQ(s[std::size_t(t.left[0])], 2);       // (..)
  EXPECT_EQ(s[std::size_t(t.right[0])], 1);
  EXPECT_EQ(strahler_orders(parse_tree("((..)(..))", "--tree"))[0], 3);
  EXPECT_THROW(parse_tree("(.)", "--tree"), Error);
  EXPECT_THROW(parse_tree("(...)", "--tree"), Error);
  EXPECT_THROW(parse_tree("((..)", "--tree"), Error);
  EXPECT_THROW(parse_tree("(..)x", "--tree"), Error);
  const BinaryTree r = random_increasing_tree(40, 9);
  EXPECT_EQ(r.size(), 81);
  for (int n = 1; n < r.size(); ++n) EXPECT_LT(r.parent[std::size_t(n)], n);
  const BinaryTree u = random_binary_tree(40, 9);  // Rémy: renumbered so that parents come first
  ASSERT_EQ(u.size(), 81);
  EXPECT_EQ(u.parent[0], -1);
  int leaves = 0;
  for (int n = 0; n < u.size(); ++n) {
    leaves += u.leaf(n) ? 1 : 0;
    if (n > 0) {
      EXPECT_LT(u.parent[std::size_t(n)], n);
    }
    if (!u.leaf(n)) {
      EXPECT_EQ(u.parent[std::size_t(u.left[std::size_t(n)])], n);
    }
  }
  EXPECT_EQ(leaves, 41);
}

TEST(PlanarBasins, FacetInequalitiesByHand) {
  // Type 1: river (0,0) z 0 → (10,0) z 10, ridge vertex at (4,3): the river's line is at 4 m below
  // it and it is 3 m away, so with a bank slope 0.1: z ≥ 4 + 0.3.
  const LinearRow a = type1_row({0, 0}, 0, {10, 0}, 10, 7, {4, 3}, 0.1);
  ASSERT_EQ(a.terms.size(), 1u);
  EXPECT_EQ(a.terms[0].first, 7);
  EXPECT_DOUBLE_EQ(a.terms[0].second, 1.0);
  EXPECT_NEAR(a.rhs, 4.3, 1e-12);
  // Type 2: ridge (0,0)-(10,0), river vertex (2,-5) at z 5: s = 0.2, so 0.8 z1 + 0.2 z2 ≥ 5 + 0.5.
  const LinearRow b = type2_row(1, {0, 0}, 2, {10, 0}, {2, -5}, 5, 0.1);
  EXPECT_NEAR(b.terms[0].second, 0.8, 1e-12);
  EXPECT_NEAR(b.terms[1].second, 0.2, 1e-12);
  EXPECT_NEAR(b.rhs, 5.5, 1e-12);
}

TEST(PlanarBasins, LinearProgramOnTwoRidgeVertices) {
  // min z1 + z2 s.t. 0.8 z1 + 0.2 z2 ≥ 5.5, z1 ≥ 3, z2 ≥ 3. Raising z1 costs 1 per 0.8 of the first
  // row, z2 1 per 0.2: so z2 = 3 and z1 = (5.5 - 0.6) / 0.8 = 6.125.
  std::vector<LinearRow> rows{type2_row(1, {0, 0}, 2, {10, 0}, {2, -5}, 5, 0.1), {{{1, 1.0}}, 3}, {{{2, 1.0}}, 3}};
  const std::vector<double> z = solve_min_sum({1, 2}, rows);
  EXPECT_NEAR(z[0], 6.125, 1e-9);
  EXPECT_NEAR(z[1], 3.0, 1e-9);
  // Three vertices on a line: z3 ≥ z2 + 1 ≥ z1 + 2 and z1 ≥ 1: the least is 1, 2, 3.
  std::vector<LinearRow> chain{{{{1, 1.0}}, 1}, {{{2, 1.0}, {1, -1.0}}, 1}, {{{3, 1.0}, {2, -1.0}}, 1}};
  const std::vector<double> c = solve_min_sum({1, 2, 3}, chain);
  EXPECT_NEAR(c[0], 1, 1e-9);
  EXPECT_NEAR(c[1], 2, 1e-9);
  EXPECT_NEAR(c[2], 3, 1e-9);
  // Unbounded below: refused.
  EXPECT_THROW(solve_min_sum({1, 2}, {{{{1, 1.0}, {2, -1.0}}, 0}}), Error);
}

TEST(PlanarBasins, MapIsPlanarAndRiversDescend) {
  PlanarParams p;
  p.fractalisations = 1;
  const BinaryTree t = random_increasing_tree(60, 4);
  const PlanarMap map = build_planar_map(t, 20000, 12000, p);
  // Every river edge descends; the map has 3 facets per confluence × 2 or 3 after the ridges, × 4.
  for (const auto& e : map.rivers) EXPECT_GT(map.z[std::size_t(e.up)], map.z[std::size_t(e.down)]);
  // Planar: the facets do not overlap, so their areas add up to the area they cover on a fine grid.
  double facet_area = 0;
  for (const auto& f : map.facets) {
    const Point2 a = map.p[std::size_t(f[0])], b = map.p[std::size_t(f[1])], c = map.p[std::size_t(f[2])];
    facet_area += 0.5 * std::abs((b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x));
  }
  Georef g;
  const double cell = 10;
  g.transform = {0, cell, 0, 0, 0, -cell};
  Raster<float> grid(2000, 1200, g, 0.0f);
  rasterise(map, grid);
  std::size_t covered = 0;
  for (std::size_t i = 0; i < grid.size(); ++i) covered += std::isfinite(grid[i]) ? 1 : 0;
  EXPECT_NEAR(covered * cell * cell / facet_area, 1.0, 0.01);
  // Every ridge vertex stands above the ends of the edge it was put on, hence above the mouth.
  for (std::size_t i = 0; i < map.p.size(); ++i) {
    if (map.kind[i] != PlanarMap::Kind::ridge) continue;
    EXPECT_GT(map.z[i], 0);
  }
}

TEST(PlanarBasins, SameSeedSameMap) {
  PlanarParams p;
  p.seed = 8;
  const PlanarMap a = build_planar_map(random_increasing_tree(30, 8), 5000, 4000, p);
  const PlanarMap b = build_planar_map(random_increasing_tree(30, 8), 5000, 4000, p);
  ASSERT_EQ(a.z.size(), b.z.size());
  EXPECT_EQ(std::memcmp(a.z.data(), b.z.data(), a.z.size() * sizeof(double)), 0);
}
