// The agglomeration network: which pairs of sites get a direct link (Belhadj §4.3.2).
// SPDX-License-Identifier: MIT
#pragma once
#include <vector>

#include "core/progress.hpp"
#include "core/raster.hpp"
#include "sites/sites.hpp"

namespace terrapolis::network {

struct NetworkOptions {
  /// Detour factor k > 1: an edge of length D_d is removed when another path shorter than
  /// k x D_d joins its ends (Belhadj §4.3.2 takes 1.8: "a detour under 80 % extra"; 1.5 joins
  /// city pairs at the circuity of real networks, docs/sites.md).
  double k = 1.5;
};

/// Where an edge comes from, in priority order when several triangulations give it.
enum class EdgeKind {
  inter_urban,   ///< Delaunay triangulation of the roots of the hierarchy
  parent_child,  ///< a site and its direct parent (never removed: a city's main axes)
  all_sites,     ///< Delaunay of all sites, or child-child edges of a parent's family triangulation
};

/// "inter_urban", "parent_child" or "all_sites".
const char* to_string(EdgeKind kind);

struct Edge {
  int from = 0, to = 0;  ///< indices into the site list (parent first for parent_child, else from < to)
  EdgeKind kind = EdgeKind::all_sites;
  bool kept = true;
  double length_m = 0;   ///< geodesic length, metres
  /// Shortest other path found / length_m, when one under k x length_m was found (the edge
  /// was then removed); NaN when none was found or the edge was not examined.
  double detour_ratio = 0;
  /// Position of the edge in the examination order (0 first), -1 for parent_child edges.
  int rank = -1;
};

/// The candidate edges (union of the triangulations, without duplicates) with their fate.
struct SiteGraph {
  std::vector<Edge> edges;  ///< sorted by (from, to) of the unordered pair
};

/// Builds the network of `sites` (positions x,y in `crs`, radius_m, parent = index of the
/// parent in `sites` or -1): union of the Delaunay triangulations of the roots, of each parent
/// with its children, of all sites, and of the parent-child links; then, by decreasing size of
/// their sites (larger radius, then smaller radius, then length, decreasing), each edge that is
/// not parent_child is removed when a path shorter than k x its length joins its ends in the
/// current graph (Dijkstra pruned at that bound). The kept edges form a connected graph.
/// Throws bad_input for k <= 1, two sites at the same position, or a parent that is not a
/// site or makes a cycle.
SiteGraph build_network(const std::vector<sites::Site>& sites, const Crs& crs, const NetworkOptions& options,
                        Progress& progress);

}  // namespace terrapolis::network
