// Delaunay union and detour simplification of the agglomeration network (Belhadj 2007, §4.3.2).
// SPDX-License-Identifier: MIT
#include "network/network.hpp"

#include <CGAL/Delaunay_triangulation_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>
#include <string>
#include <tuple>

#include "core/error.hpp"
#include "core/geodesy.hpp"

namespace terrapolis::network {
namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = K::Point_2;
using Vb = CGAL::Triangulation_vertex_base_with_info_2<int, K>;
using Tds = CGAL::Triangulation_data_structure_2<Vb>;
using Delaunay = CGAL::Delaunay_triangulation_2<K, Tds>;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

int priority(EdgeKind kind) {  // lower wins when triangulations share an edge
  switch (kind) {
    case EdgeKind::parent_child: return 0;
    case EdgeKind::inter_urban: return 1;
    case EdgeKind::all_sites: return 2;
  }
  return 3;
}

struct Candidate {
  std::uint64_t key;  // (min index << 32) | max index
  EdgeKind kind;
};

std::uint64_t pair_key(int a, int b) {
  const auto lo = std::uint64_t(std::min(a, b)), hi = std::uint64_t(std::max(a, b));
  return (lo << 32) | hi;
}

/// Appends the edges of the Delaunay triangulation of `members` (indices into `points`).
/// With co-circular points (common for sites on grid cells) the triangulation depends on the
/// insertion order: CGAL's spatial sort shuffles with a locally default-seeded rand48, so the
/// result depends only on `members`' order.
void delaunay_edges(const std::vector<Point>& points, const std::vector<int>& members, EdgeKind kind,
                    const std::vector<int>& parent, std::vector<Candidate>& out) {
  if (members.size() < 2) return;
  auto add = [&](int a, int b) {
    const bool family = parent[std::size_t(a)] == b || parent[std::size_t(b)] == a;
    out.push_back({pair_key(a, b), family ? EdgeKind::parent_child : kind});
  };
  if (members.size() == 2) {
    add(members[0], members[1]);
    return;
  }
  std::vector<std::pair<Point, int>> located;
  located.reserve(members.size());
  for (int i : members) located.emplace_back(points[std::size_t(i)], i);
  const Delaunay dt(located.begin(), located.end());
  for (auto e = dt.finite_edges_begin(); e != dt.finite_edges_end(); ++e) {
    const auto face = e->first;
    const int i = e->second;
    add(face->vertex(face->cw(i))->info(), face->vertex(face->ccw(i))->info());
  }
}

/// A lower bound, in metres, of the geodesic distance between two sites, cheap enough to
/// evaluate at every node of a search. Projected CRS: the Euclidean distance. Geographic CRS:
/// the great-circle angle between the geodetic positions times a(1 - e^2) = b^2/a, the smallest
/// radius of curvature of the ellipsoid (its meridian radius at the equator): the ellipsoid's
/// metric is at least that sphere's in every direction, so no path can be shorter.
class DistanceBound {
 public:
  DistanceBound(const std::vector<sites::Site>& sites, const Crs& crs) : geographic_(crs.geographic) {
    const double f = crs.ellipsoid.flattening();
    radius_ = crs.ellipsoid.semi_major_m * (1 - f) * (1 - f) * (1 - 1e-9);
    unit_ = crs.linear_unit_m * (1 - 1e-12);
    for (const auto& s : sites) {
      const double lat = s.y * M_PI / 180.0, lon = s.x * M_PI / 180.0;
      nodes_.push_back(geographic_ ? Node{lat, lon, std::cos(lat)} : Node{s.x, s.y, 0});
    }
  }
  double operator()(int u, int v) const {
    const Node &p = nodes_[std::size_t(u)], &q = nodes_[std::size_t(v)];
    if (!geographic_) return std::hypot(p.a - q.a, p.b - q.b) * unit_;
    const double sin_dlat = std::sin(0.5 * (q.a - p.a)), sin_dlon = std::sin(0.5 * (q.b - p.b));
    const double h = sin_dlat * sin_dlat + p.c * q.c * sin_dlon * sin_dlon;
    return 2 * radius_ * std::asin(std::min(1.0, std::sqrt(h)));
  }

 private:
  struct Node {
    double a, b, c;  // lat, lon (radians), cos(lat); or x, y in CRS units
  };
  bool geographic_;
  double radius_ = 0, unit_ = 1;
  std::vector<Node> nodes_;
};

/// Shortest path from `a` to `b` over edges not removed and other than `skip`, cutting every
/// path that cannot stay under `bound` metres: Belhadj's pruned Dijkstra, guided towards `b` by
/// an admissible and consistent lower bound (A*), which prunes the same paths and more, and
/// returns the same length. Returns the length of the shortest path under `bound`, or NaN.
class DetourSearch {
 public:
  DetourSearch(int nodes, const std::vector<std::uint32_t>& offsets, const std::vector<std::pair<int, int>>& adjacency,
               const std::vector<double>& length, const std::vector<char>& removed, const DistanceBound& lower_bound)
      : dist_(std::size_t(nodes), std::numeric_limits<double>::infinity()),
        offsets_(offsets), adjacency_(adjacency), length_(length), removed_(removed), lower_bound_(lower_bound) {}

  double operator()(int a, int b, int skip, double bound) {
    double found = kNaN;
    dist_[std::size_t(a)] = 0;
    touched_.push_back(a);
    heap_.push_back({lower_bound_(a, b), 0.0, a});
    while (!heap_.empty()) {
      std::pop_heap(heap_.begin(), heap_.end(), std::greater<>());
      const auto [f, d, u] = heap_.back();
      heap_.pop_back();
      if (d > dist_[std::size_t(u)]) continue;
      if (u == b) {
        found = d;
        break;
      }
      for (std::uint32_t k = offsets_[std::size_t(u)]; k < offsets_[std::size_t(u) + 1]; ++k) {
        const auto [v, e] = adjacency_[k];
        if (e == skip || removed_[std::size_t(e)]) continue;
        const double nd = d + length_[std::size_t(e)];
        if (nd >= bound || nd >= dist_[std::size_t(v)]) continue;
        const double estimate = nd + lower_bound_(v, b);
        if (estimate >= bound) continue;  // no path through v can stay under the bound
        if (dist_[std::size_t(v)] == std::numeric_limits<double>::infinity()) touched_.push_back(v);
        dist_[std::size_t(v)] = nd;
        heap_.push_back({estimate, nd, v});
        std::push_heap(heap_.begin(), heap_.end(), std::greater<>());
      }
    }
    for (int v : touched_) dist_[std::size_t(v)] = std::numeric_limits<double>::infinity();
    touched_.clear();
    heap_.clear();
    return found;
  }

 private:
  std::vector<double> dist_;
  std::vector<int> touched_;
  std::vector<std::tuple<double, double, int>> heap_;
  const std::vector<std::uint32_t>& offsets_;
  const std::vector<std::pair<int, int>>& adjacency_;
  const std::vector<double>& length_;
  const std::vector<char>& removed_;
  const DistanceBound& lower_bound_;
};

void check_sites(const std::vector<sites::Site>& sites) {
  const int n = int(sites.size());
  for (int i = 0; i < n; ++i) {
    const auto& s = sites[std::size_t(i)];
    if (!std::isfinite(s.x) || !std::isfinite(s.y)) throw bad_input("network: site " + std::to_string(s.id) + " has no valid position");
    if (!(std::isfinite(s.radius_m) && s.radius_m >= 0)) throw bad_input("network: site " + std::to_string(s.id) + " has an invalid radius");
    if (s.parent < -1 || s.parent >= n || s.parent == i)
      throw bad_input("network: site " + std::to_string(s.id) + " has a parent that is not another site");
  }
  // Every chain of parents must reach a root, else it loops: walk each chain once (linear time).
  std::vector<char> state(sites.size(), 0);  // 0 unseen, 1 on the current chain, 2 reaches a root
  for (int i = 0; i < n; ++i) {
    int p = i;
    while (p >= 0 && state[std::size_t(p)] == 0) state[std::size_t(p)] = 1, p = sites[std::size_t(p)].parent;
    if (p >= 0 && state[std::size_t(p)] == 1) throw bad_input("network: the parents of site " + std::to_string(sites[std::size_t(p)].id) + " form a cycle");
    for (p = i; p >= 0 && state[std::size_t(p)] == 1; p = sites[std::size_t(p)].parent) state[std::size_t(p)] = 2;
  }
  std::vector<int> order(sites.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](int a, int b) {
    return std::tie(sites[std::size_t(a)].x, sites[std::size_t(a)].y) < std::tie(sites[std::size_t(b)].x, sites[std::size_t(b)].y);
  });
  for (std::size_t k = 1; k < order.size(); ++k) {
    const auto &a = sites[std::size_t(order[k - 1])], &b = sites[std::size_t(order[k])];
    if (a.x == b.x && a.y == b.y)
      throw bad_input("network: sites " + std::to_string(a.id) + " and " + std::to_string(b.id) + " are at the same position");
  }
}

/// Plane coordinates for the triangulations: metres on a projected CRS; on a geographic CRS an
/// equirectangular plane around the mean latitude (Delaunay is planar; lengths stay geodesic).
std::vector<Point> plane_points(const std::vector<sites::Site>& sites, const Crs& crs) {
  const int n = int(sites.size());
  std::vector<Point> points(sites.size());
  double lon0 = 0, lat0 = 0;
  for (const auto& s : sites) lon0 += s.x / n, lat0 += s.y / n;
  const double shrink = std::cos(lat0 * M_PI / 180.0);
  for (int i = 0; i < n; ++i) {
    const auto& s = sites[std::size_t(i)];
    if (crs.geographic) {
      const double dlon = std::remainder(s.x - lon0, 360.0);
      points[std::size_t(i)] = Point(dlon * shrink, s.y - lat0);
    } else {
      points[std::size_t(i)] = Point(s.x, s.y);
    }
  }
  return points;
}

/// The union of the triangulations (the roots', each family's, all the sites') and the
/// parent-child links, each pair once with its highest-priority kind.
std::vector<Candidate> candidate_edges(const std::vector<Point>& points, const std::vector<int>& parent, Progress& progress) {
  const int n = int(points.size());
  std::vector<Candidate> candidates;
  {
    ProgressStep step(progress, "network: triangulations");
    std::vector<int> all(points.size()), roots;
    std::iota(all.begin(), all.end(), 0);
    std::vector<std::vector<int>> families(points.size());
    for (int i = 0; i < n; ++i) {
      if (parent[std::size_t(i)] < 0) roots.push_back(i);
      else families[std::size_t(parent[std::size_t(i)])].push_back(i);
    }
    // The parent-child links themselves: a parent's Delaunay may skip a child hidden behind a sibling.
    for (int i = 0; i < n; ++i)
      if (parent[std::size_t(i)] >= 0) candidates.push_back({pair_key(i, parent[std::size_t(i)]), EdgeKind::parent_child});
    delaunay_edges(points, roots, EdgeKind::inter_urban, parent, candidates);
    for (int p = 0; p < n; ++p) {
      auto& family = families[std::size_t(p)];
      if (family.size() < 2) continue;
      family.insert(family.begin(), p);
      delaunay_edges(points, family, EdgeKind::all_sites, parent, candidates);
    }
    step.update(0.5);
    delaunay_edges(points, all, EdgeKind::all_sites, parent, candidates);
    step.update(1.0);
  }
  std::sort(candidates.begin(), candidates.end(), [](const Candidate& a, const Candidate& b) {
    return a.key != b.key ? a.key < b.key : priority(a.kind) < priority(b.kind);
  });
  candidates.erase(std::unique(candidates.begin(), candidates.end(), [](const Candidate& a, const Candidate& b) { return a.key == b.key; }),
                   candidates.end());
  return candidates;
}

/// Every edge not a parent-child link, examined in order, removed when a detour through the
/// kept edges is shorter than k times its length. `length`: the edges' lengths, m.
void simplify(SiteGraph& graph, const std::vector<sites::Site>& sites, const Crs& crs, const std::vector<double>& length,
              const NetworkOptions& options, Progress& progress) {
  const std::size_t count = sites.size(), m = graph.edges.size();
  // Adjacency (CSR) of every candidate edge; removal only flags edges.
  std::vector<std::uint32_t> offsets(count + 1, 0);
  for (const Edge& e : graph.edges) ++offsets[std::size_t(e.from) + 1], ++offsets[std::size_t(e.to) + 1];
  std::partial_sum(offsets.begin(), offsets.end(), offsets.begin());
  std::vector<std::pair<int, int>> adjacency(offsets.back());
  {
    std::vector<std::uint32_t> fill(offsets.begin(), offsets.end() - 1);
    for (std::size_t e = 0; e < m; ++e) {
      adjacency[fill[std::size_t(graph.edges[e].from)]++] = {graph.edges[e].to, int(e)};
      adjacency[fill[std::size_t(graph.edges[e].to)]++] = {graph.edges[e].from, int(e)};
    }
  }

  // Examination order: by decreasing size of the sites (larger radius, then smaller radius),
  // then longest first (a long edge is the one a detour can replace), then by ends.
  std::vector<int> order;
  for (std::size_t e = 0; e < m; ++e)
    if (graph.edges[e].kind != EdgeKind::parent_child) order.push_back(int(e));
  auto size_key = [&](int e) {
    const double ra = sites[std::size_t(graph.edges[std::size_t(e)].from)].radius_m;
    const double rb = sites[std::size_t(graph.edges[std::size_t(e)].to)].radius_m;
    return std::make_tuple(-std::max(ra, rb), -std::min(ra, rb), -length[std::size_t(e)], graph.edges[std::size_t(e)].from,
                           graph.edges[std::size_t(e)].to);
  };
  std::sort(order.begin(), order.end(), [&](int a, int b) { return size_key(a) < size_key(b); });

  ProgressStep step(progress, "network: simplification");
  std::vector<char> removed(m, 0);
  const DistanceBound lower_bound(sites, crs);
  DetourSearch search(int(count), offsets, adjacency, length, removed, lower_bound);
  for (std::size_t k = 0; k < order.size(); ++k) {
    const int e = order[k];
    Edge& edge = graph.edges[std::size_t(e)];
    edge.rank = int(k);
    const double detour = search(edge.from, edge.to, e, options.k * edge.length_m);
    if (!std::isnan(detour)) {
      removed[std::size_t(e)] = 1;
      edge.kept = false;
      edge.detour_ratio = edge.length_m > 0 ? detour / edge.length_m : kNaN;
    }
    if ((k & 4095) == 0) step.update(double(k) / double(order.size()));
  }
  step.update(1.0);
}

/// Removing an edge only when another path joins its ends keeps the union connected; check it.
void check_connected(const SiteGraph& graph, int n) {
  std::vector<int> root(static_cast<std::size_t>(n));
  std::iota(root.begin(), root.end(), 0);
  auto find = [&](int v) {
    while (root[std::size_t(v)] != v) v = root[std::size_t(v)] = root[std::size_t(root[std::size_t(v)])];
    return v;
  };
  int components = n;
  for (const Edge& e : graph.edges)
    if (e.kept) {
      const int a = find(e.from), b = find(e.to);
      if (a != b) root[std::size_t(a)] = b, --components;
    }
  if (components != 1) throw processing_error("network: the simplified network is not connected (" + std::to_string(components) + " parts)");
}

}  // namespace

const char* to_string(EdgeKind kind) {
  switch (kind) {
    case EdgeKind::inter_urban: return "inter_urban";
    case EdgeKind::parent_child: return "parent_child";
    case EdgeKind::all_sites: return "all_sites";
  }
  return "?";
}

SiteGraph build_network(const std::vector<sites::Site>& sites, const Crs& crs, const NetworkOptions& options,
                        Progress& progress) {
  if (!(std::isfinite(options.k) && options.k > 1)) throw bad_input("network: k must be a number greater than 1");
  check_sites(sites);
  const int n = int(sites.size());
  SiteGraph graph;
  if (n < 2) return graph;

  std::vector<int> parent(sites.size());
  for (int i = 0; i < n; ++i) parent[std::size_t(i)] = sites[std::size_t(i)].parent;
  const std::vector<Candidate> candidates = candidate_edges(plane_points(sites, crs), parent, progress);

  const std::size_t m = candidates.size();
  graph.edges.resize(m);
  std::vector<double> length(m);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, m, 1024), [&](const tbb::blocked_range<std::size_t>& range) {
    for (std::size_t e = range.begin(); e < range.end(); ++e) {
      Edge& edge = graph.edges[e];
      int a = int(candidates[e].key >> 32), b = int(candidates[e].key & 0xffffffffu);
      if (candidates[e].kind == EdgeKind::parent_child && parent[std::size_t(a)] == b) std::swap(a, b);  // parent first
      edge.from = a;
      edge.to = b;
      edge.kind = candidates[e].kind;
      edge.kept = true;
      edge.detour_ratio = kNaN;
      const auto &sa = sites[std::size_t(a)], &sb = sites[std::size_t(b)];
      edge.length_m = length[e] = crs_distance_m(crs, sa.x, sa.y, sb.x, sb.y);
    }
  });
  simplify(graph, sites, crs, length, options, progress);
  check_connected(graph, n);
  return graph;
}

}  // namespace terrapolis::network
