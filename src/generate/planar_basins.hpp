// Binary-tree river basins on planar maps (the planar-maps chapter, seeds/003 §6.2-6.3): a binary
// river tree, its embedding as a quasi-triangular planar map having the tree as spanning tree,
// ridge vertices on the non-river edges, altitudes from the river law by Strahler order and the
// facet inequalities solved by linear programming, global fractalisations, rasterised facets.
// SPDX-License-Identifier: MIT
#pragma once
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "core/progress.hpp"
#include "core/raster.hpp"
#include "generate/plan_geometry.hpp"

namespace terrapolis::generate {

/// A binary tree: node 0 is the root (the first confluence above the mouth); -1: no child.
struct BinaryTree {
  std::vector<int> left, right, parent;
  int size() const { return int(left.size()); }
  bool leaf(int n) const { return left[std::size_t(n)] < 0; }
};

/// A random increasing binary tree of `internal` internal nodes: `internal` times, a uniformly
/// drawn leaf gets two children (the chapter's §6.4.1 "arbre binaire aléatoire croissant").
BinaryTree random_increasing_tree(int internal, std::uint64_t seed);
/// A uniformly random binary tree of `internal` internal nodes (Rémy 1985), numbered parents first:
/// the chapter's "arbre binaire aléatoire" (§6.4.1), Shreve's topologically random network.
BinaryTree random_binary_tree(int internal, std::uint64_t seed);
/// A tree written as nested pairs: "." is a leaf, "(LR)" an internal node with left L and right R,
/// e.g. "((..).)". Throws bad_input naming `option` on a malformed text.
BinaryTree parse_tree(const std::string& text, const std::string& option);
/// Strahler order of every node (leaves 1).
std::vector<int> strahler_orders(const BinaryTree& tree);

struct PlanarParams {
  std::string tree;           ///< the river tree as parse_tree text; empty: random_binary_tree(nodes)
  int nodes = 150;            ///< confluences of the random tree
  bool uniform_tree = false;  ///< random tree law: uniform (Rémy) rather than increasing
  double drop_m = 30;         ///< CRIV of DALT(n) = CRIV / Strahler(n)^a (§6.3.4.1), metres
  double drop_exponent = 1;   ///< a
  double bank_slope = 0.08;   ///< least slope (m/m) of a facet towards its river or away from its ridge
  int fractalisations = 2;    ///< global fractalisations (§6.2.5), each ×4 facets
  double meander = 0.5;       ///< C_PONDERAL (§6.3.2.2): pull of a new river vertex towards a facet centre
  double roughness = 0.04;    ///< upward displacement of a new non-river vertex, share of its edge length
  std::uint64_t seed = 1;
};

/// The planar map: vertices in plan metres with altitudes, triangular facets, river edges.
struct PlanarMap {
  enum class Kind : std::uint8_t { river, ridge, other };
  std::vector<Point2> p;
  std::vector<double> z;
  std::vector<Kind> kind;
  std::vector<std::array<int, 3>> facets;
  struct RiverEdge {
    int up, down, strahler;
  };
  std::vector<RiverEdge> rivers;                ///< upstream and downstream vertex of each river edge
  std::vector<std::pair<int, int>> ridges;      ///< ridge edges (both ends ridge vertices)
  int mouth = -1;                               ///< the extra vertex below the root
  std::size_t lp_variables = 0, lp_constraints = 0, lp_problems = 0;
};

/// Facet inequalities (§6.3.4.2.1) as rows a·z >= c over the ridge vertices of one facet.
/// Type 1 (river edge r1-r2, ridge vertex p): z_p >= z(r1r2 at p's projection) + ε dist(p, r1r2).
/// Type 2 (ridge edge p1-p2, river vertex r): (1-s) z_p1 + s z_p2 >= z_r + ε dist(r, p1p2), s the
/// projection parameter of r on p1→p2.
struct LinearRow {
  std::vector<std::pair<int, double>> terms;  ///< (vertex, coefficient)
  double rhs = 0;
};
LinearRow type1_row(Point2 r1, double z1, Point2 r2, double z2, int p, Point2 pp, double bank_slope);
LinearRow type2_row(int p1, Point2 a, int p2, Point2 b, Point2 r, double zr, double bank_slope);

/// Minimises Σ z over `variables` subject to `rows` (CGAL's exact LP solver, planar_lp.cpp).
/// Returns the altitudes in the order of `variables`; throws Error(processing) if infeasible.
std::vector<double> solve_min_sum(const std::vector<int>& variables, const std::vector<LinearRow>& rows);

/// The map of `tree` drawn on a `width_m` × `height_m` plan (root near the south edge, the fan
/// northwards), ridge altitudes solved, fractalised.
PlanarMap build_planar_map(const BinaryTree& tree, double width_m, double height_m, const PlanarParams& params);

/// Rasterises the facets onto `grid` (cell centres inside a facet take its plane; NaN outside the map).
void rasterise(const PlanarMap& map, Raster<float>& grid, Progress* progress = nullptr);

}  // namespace terrapolis::generate
