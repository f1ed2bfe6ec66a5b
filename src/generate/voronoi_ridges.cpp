// Voronoi ridges of the river nodes (Génévaux et al. §5.1, Fig. 10-11). The only source of the
// coast method that includes CGAL.
// SPDX-License-Identifier: MIT
#include <CGAL/Delaunay_triangulation_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>

#include <algorithm>
#include <set>
#include <utility>

#include "generate/river_grammar.hpp"

namespace terrapolis::generate {

std::vector<RidgeSegment> voronoi_ridges(const std::vector<Point2>& points, const std::vector<double>& z,
                                         const std::vector<std::pair<int, int>>& river_edges,
                                         const std::function<double(Point2)>& lambda_at) {
  using K = CGAL::Exact_predicates_inexact_constructions_kernel;
  using Vb = CGAL::Triangulation_vertex_base_with_info_2<int, K>;
  using Tds = CGAL::Triangulation_data_structure_2<Vb>;
  using Delaunay = CGAL::Delaunay_triangulation_2<K, Tds>;
  std::vector<std::pair<K::Point_2, int>> input;
  input.reserve(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) input.emplace_back(K::Point_2(points[i].x, points[i].y), int(i));
  Delaunay dt(input.begin(), input.end());  // spatial sort: the triangulation does not depend on input order
  // Fewer than three nodes, or all on one line (a tiny region may hold a single river): no triangle,
  // hence no Voronoi vertex. CGAL's faces are then 1-dimensional and have no circumcentre.
  if (dt.dimension() < 2) return {};
  std::set<std::pair<int, int>> rivers;
  for (auto [a, b] : river_edges) rivers.emplace(std::min(a, b), std::max(a, b));

  // Ridge vertex of a face: its circumcentre q at q_z = max(p_z) + λ(q) d, d the circumradius.
  const auto vertex = [&](Delaunay::Face_handle f, double& qz) {
    const K::Point_2 c = dt.circumcenter(f);
    const Point2 q{c.x(), c.y()};
    double top = -std::numeric_limits<double>::infinity();
    for (int k = 0; k < 3; ++k) top = std::max(top, z[std::size_t(f->vertex(k)->info())]);
    const double d = norm(q - points[std::size_t(f->vertex(0)->info())]);
    qz = ridge_height(top, top, top, lambda_at(q), d);
    return q;
  };
  std::vector<std::pair<std::pair<int, int>, RidgeSegment>> keyed;
  for (auto e = dt.finite_edges_begin(); e != dt.finite_edges_end(); ++e) {
    Delaunay::Face_handle f = e->first, g = f->neighbor(e->second);
    if (dt.is_infinite(f) || dt.is_infinite(g)) continue;  // hull edges: the ridge runs off to infinity
    const int a = f->vertex(f->cw(e->second))->info(), b = f->vertex(f->ccw(e->second))->info();
    // The iterator reports an edge from either of its faces, in an order that follows memory
    // addresses: orient every ridge from the same side of its edge (node a < b) so that the
    // segments, not only their set, are the same from run to run.
    if (a > b) std::swap(f, g);
    const std::pair<int, int> key{std::min(a, b), std::max(a, b)};
    if (rivers.count(key)) continue;  // a river crosses this Voronoi edge: an inlet or the outlet of a block
    RidgeSegment s;
    s.a = vertex(f, s.za);
    s.b = vertex(g, s.zb);
    keyed.emplace_back(key, s);
  }
  std::sort(keyed.begin(), keyed.end(), [](const auto& x, const auto& y) { return x.first < y.first; });
  std::vector<RidgeSegment> out;
  out.reserve(keyed.size());
  for (const auto& [key, s] : keyed) out.push_back(s);
  return out;
}

}  // namespace terrapolis::generate
