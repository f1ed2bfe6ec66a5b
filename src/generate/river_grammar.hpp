// River networks grown from a coastline by an open probabilistic grammar, Voronoi blocks and ridges,
// discharge and river types, and a terrain of blended primitives carved by the rivers.
// Génévaux, Galin, Guérin, Peytavie, Beneš, "Génération procédurale de rivières et de terrains"
// (seeds/002): §4 (mouths, grammar, validity), §5 (segmentation, ridges, discharge, types),
// §6-7 (primitives, operators, terrain).
// SPDX-License-Identifier: MIT
#pragma once
#include <cstdint>
#include <functional>
#include <vector>

#include "core/progress.hpp"
#include "core/raster.hpp"
#include "hydro/river_types.hpp"
#include "generate/plan_geometry.hpp"

namespace terrapolis::generate {

/// Parameters of the coast method. Lengths in metres; the paper gives the rules, not the figures:
/// the defaults are ours, chosen so that the drainage density and primitive counts match its Tab. 2.
struct CoastParams {
  double edge_m = 2000;        ///< e: length of a grammar edge (§4)
  double sigma_m = 1500;       ///< σ: least distance between two edges (> e/√2, §4.2.2)
  double delta_m = 300;        ///< δ: least distance from an edge to the coast
  double kappa = 0.3;          ///< κ: greatest slope (m/m) between a new node and the nodes near it
  double zeta_m = 10;          ///< ζ: altitude window of the mixed selection (0: lowest first; large: priority first)
  double p_continue = 0.2;     ///< P_c
  double p_symmetric = 0.7;    ///< P_s
  double p_asymmetric = 0.1;   ///< P_a
  int max_priority = 4;        ///< priority of the most accessible mouth; others get less (§4.1)
  double mouth_spacing_m = 6000;  ///< least distance between two mouths ([DL78]: mouths are far apart)
  double river_grade = 0.004;  ///< rise per metre of a priority-max edge; each lower priority steepens it by √2
  double lambda = 0.1;         ///< λ of q_z = max(p_z) + λd (§5.1), damped within 5 e of the coast
  double primitive_spacing_m = 316;  ///< spacing of the terrain primitives (Tab. 2: about 10 per km²)
  double noise = 0.15;         ///< noise amplitude of a terrain primitive, share of its ridge-to-river relief
  std::uint64_t seed = 1;
};

/// One node of the river forest, N = (p, s, ρ, φ) of §4, with what the analysis adds.
struct RiverNode {
  Point2 p;                 ///< plan metres
  double z = 0;             ///< altitude (m), above its parent's
  int parent = -1;          ///< downstream node; -1 at a mouth
  int priority = 0;         ///< s of the grammar
  int strahler = 1;         ///< Horton-Strahler order in the finished tree
  double area_km2 = 0;      ///< drained area (its Voronoi block and every block upstream)
  double discharge_m3s = 0; ///< φ = 0.42 A^0.69 (§5.1)
  hydro::RiverType type = hydro::RiverType::B;
  std::vector<Point2> course;  ///< refined trajectory from this node down to its parent (empty at a mouth)
  std::vector<double> course_z;
};

/// A ridge: a Voronoi edge between two river nodes that no river crosses (§5.1).
struct RidgeSegment {
  Point2 a, b;
  double za = 0, zb = 0;
};

struct CoastTerrain {
  std::vector<RiverNode> nodes;       ///< parents before children
  std::vector<RidgeSegment> ridges;
  std::size_t mouths = 0, terrain_primitives = 0, river_primitives = 0;
  double land_km2 = 0, river_km = 0;
  double graph_s = 0, analysis_s = 0, terrain_s = 0;  ///< the three phases of the paper's Tab. 1
};

/// The grammar's productions (Fig. 7).
enum class GrammarRule { fill, continuation, asymmetric, symmetric };
/// Rule 1 for priority 0, else rule 2.1/2.2/2.3 by `u` in [0,1) against P_c, then P_a, then P_s.
GrammarRule choose_rule(int priority, double u, const CoastParams& params);

/// The mixed selection of §4.2.1 (Fig. 5): among candidates within ζ of the lowest, the highest
/// priority, ties to the lowest altitude then the first. Returns an index into `z`; `z` non-empty.
std::size_t select_candidate(const std::vector<double>& z, const std::vector<int>& priority, double zeta_m);

/// q_z = max(p_z, p'_z, p''_z) + λ d (§5.1).
double ridge_height(double z0, double z1, double z2, double lambda, double d);

/// The river forest during growth with its validity tests (§4.2.2): inside Ω and farther than δ
/// from Γ, farther than σ from every other edge, slope below κ to the nodes near it.
class RiverGraph {
 public:
  /// `coast`: rings of Γ in plan metres (even-odd: holes are lakes).
  RiverGraph(double width_m, double height_m, std::vector<std::vector<Point2>> coast, const CoastParams& params);
  /// Adds a mouth (no validity test: it lies on Γ).
  int add_mouth(Point2 p, int priority);
  /// Whether a node at (p, z) may hang below node `from` (the three tests of §4.2.2).
  bool valid(int from, Point2 p, double z) const;
  int add(int from, Point2 p, double z, int priority);
  bool inside(Point2 p) const;
  double coast_distance(Point2 p) const;
  const std::vector<RiverNode>& nodes() const { return nodes_; }
  std::vector<RiverNode>& nodes() { return nodes_; }

 private:
  CoastParams params_;
  std::vector<std::vector<Point2>> coast_;
  std::vector<std::pair<Point2, Point2>> coast_segments_;
  SpatialBins coast_bins_, edge_bins_, node_bins_;
  std::vector<RiverNode> nodes_;
  std::vector<int> edge_child_;  ///< edge i joins node edge_child_[i] to its parent
};

/// A default coast for demos: an island with a seeded, wavy outline inscribed in the grid.
std::vector<std::vector<Point2>> synthetic_coast(double width_m, double height_m, std::uint64_t seed);

/// The whole method on `grid` (its size and cell; CRS untouched): mouths, grammar, analysis,
/// primitives, rasterised heights (m) on land, NaN at sea. Deterministic for a seed.
CoastTerrain generate_coast_terrain(Raster<float>& grid, const std::vector<std::vector<Point2>>& coast,
                                    const CoastParams& params, Progress* progress = nullptr);

/// Voronoi ridges of the river nodes (CGAL Delaunay; kept in its own source for build time):
/// every Delaunay edge that is not a river edge gives the ridge joining the circumcentres of its
/// two triangles, each at q_z = max(p_z) + λ(q) d. `river_edges`: (child, parent) pairs.
std::vector<RidgeSegment> voronoi_ridges(const std::vector<Point2>& points, const std::vector<double>& z,
                                         const std::vector<std::pair<int, int>>& river_edges,
                                         const std::function<double(Point2)>& lambda_at);

}  // namespace terrapolis::generate
