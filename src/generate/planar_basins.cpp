// Binary-tree basins on planar maps (seeds/003 §6.2-6.3). See planar_basins.hpp.
// SPDX-License-Identifier: MIT
#include "generate/planar_basins.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>
#include <numeric>

#include "core/error.hpp"
#include "generate/generators.hpp"

namespace terrapolis::generate {
namespace {

constexpr double kPi = std::numbers::pi;
std::uint64_t edge_key(int a, int b) { return std::uint64_t(std::uint32_t(std::min(a, b))) << 32 | std::uint32_t(std::max(a, b)); }

/// Union-find over vertex ids (ridge lines as connected components).
struct Components {
  std::vector<int> up;
  explicit Components(std::size_t n) : up(n) { std::iota(up.begin(), up.end(), 0); }
  int find(int x) {
    while (up[std::size_t(x)] != x) x = up[std::size_t(x)] = up[std::size_t(up[std::size_t(x)])];
    return x;
  }
  void join(int a, int b) {
    a = find(a), b = find(b);
    if (a != b) up[std::size_t(std::max(a, b))] = std::min(a, b);
  }
};

}  // namespace

BinaryTree random_increasing_tree(int internal, std::uint64_t seed) {
  if (internal < 1) throw bad_input("--nodes: give at least 1 internal node");
  BinaryTree t;
  t.left = {-1};
  t.right = {-1};
  t.parent = {-1};
  std::vector<int> leaves{0};
  Rng draw(seed);
  for (int k = 0; k < internal; ++k) {
    const std::size_t pick = std::size_t(integer(draw, 0, int(leaves.size()) - 1));
    const int n = leaves[pick];
    const int l = t.size(), r = l + 1;
    t.left[std::size_t(n)] = l;
    t.right[std::size_t(n)] = r;
    for (int k = 0; k < 2; ++k) {
      t.left.push_back(-1);
      t.right.push_back(-1);
      t.parent.push_back(n);
    }
    leaves[pick] = l;
    leaves.push_back(r);
  }
  return t;
}

BinaryTree random_binary_tree(int internal, std::uint64_t seed) {
  if (internal < 1) throw bad_input("--nodes: give at least 1 internal node");
  // Rémy's algorithm (1985): a uniformly drawn node gets a new parent whose other child is a new
  // leaf, on a side drawn at random; every binary tree of `internal` internal nodes is equally likely.
  std::vector<int> left{-1}, right{-1}, parent{-1};
  int root = 0;
  Rng draw(seed);
  for (int k = 0; k < internal; ++k) {
    const int x = integer(draw, 0, int(left.size()) - 1);
    const int node = int(left.size()), leaf = node + 1;
    const bool leaf_left = draw.uniform() < 0.5;
    left.push_back(leaf_left ? leaf : x);
    right.push_back(leaf_left ? x : leaf);
    parent.push_back(parent[std::size_t(x)]);
    left.push_back(-1);
    right.push_back(-1);
    parent.push_back(node);
    const int up = parent[std::size_t(x)];
    if (up < 0) root = node;
    else (left[std::size_t(up)] == x ? left : right)[std::size_t(up)] = node;
    parent[std::size_t(x)] = node;
  }
  // Renumbered breadth-first so that parents precede children.
  BinaryTree t;
  std::vector<int> order{root}, id(left.size(), -1);
  for (std::size_t h = 0; h < order.size(); ++h)
    if (left[std::size_t(order[h])] >= 0) order.push_back(left[std::size_t(order[h])]), order.push_back(right[std::size_t(order[h])]);
  for (std::size_t i = 0; i < order.size(); ++i) id[std::size_t(order[i])] = int(i);
  for (int old : order) {
    t.left.push_back(left[std::size_t(old)] < 0 ? -1 : id[std::size_t(left[std::size_t(old)])]);
    t.right.push_back(right[std::size_t(old)] < 0 ? -1 : id[std::size_t(right[std::size_t(old)])]);
    t.parent.push_back(parent[std::size_t(old)] < 0 ? -1 : id[std::size_t(parent[std::size_t(old)])]);
  }
  return t;
}

BinaryTree parse_tree(const std::string& text, const std::string& option) {
  BinaryTree t;
  std::size_t pos = 0;
  const auto fail = [&](const std::string& why) {
    return bad_input(option + ": " + why + " at character " + std::to_string(pos + 1) + " (expected '.' or '(LR)', e.g. \"((..).)\")");
  };
  // Iterative parse: each '(' opens a node whose left then right child follow.
  std::vector<std::pair<int, int>> open;  // (node, children seen)
  const auto add = [&](int parent) {
    t.left.push_back(-1);
    t.right.push_back(-1);
    t.parent.push_back(parent);
    return t.size() - 1;
  };
  const auto attach = [&](int child) {
    if (open.empty()) return;
    auto& [node, seen] = open.back();
    (seen == 0 ? t.left : t.right)[std::size_t(node)] = child;
    t.parent[std::size_t(child)] = node;
    ++seen;
  };
  bool done = false;
  for (; pos < text.size(); ++pos) {
    const char ch = text[pos];
    if (ch == ' ') continue;
    if (done) throw fail("text after the root");
    if (ch == '.') {
      if (open.empty() && t.size() > 0) throw fail("text after the root");
      const int leaf = add(-1);
      attach(leaf);
      if (open.empty()) done = true;
    } else if (ch == '(') {
      if (!open.empty() && open.back().second >= 2) throw fail("a node has more than two children");
      const int node = add(-1);
      attach(node);
      open.emplace_back(node, 0);
    } else if (ch == ')') {
      if (open.empty() || open.back().second != 2) throw fail("a node needs exactly two children");
      open.pop_back();
      if (open.empty()) done = true;
    } else {
      throw fail(std::string("unexpected '") + ch + "'");
    }
    if (!open.empty() && open.back().second > 2) throw fail("a node has more than two children");
  }
  if (!done || t.size() < 3) throw fail(t.size() < 3 && done ? "the tree needs at least one confluence" : "unfinished tree");
  return t;
}

std::vector<int> strahler_orders(const BinaryTree& tree) {
  std::vector<int> s(std::size_t(tree.size()), 1);
  for (int n = tree.size() - 1; n >= 0; --n) {  // children are numbered after their parent
    if (tree.leaf(n)) continue;
    const int a = s[std::size_t(tree.left[std::size_t(n)])], b = s[std::size_t(tree.right[std::size_t(n)])];
    s[std::size_t(n)] = a == b ? a + 1 : std::max(a, b);
  }
  return s;
}

LinearRow type1_row(Point2 r1, double z1, Point2 r2, double z2, int p, Point2 pp, double bank_slope) {
  // Limit case of Fig. 6Q: the horizontal through p is perpendicular to the river, i.e. z_p equals the
  // river's altitude at p's projection on its line; above it the steepest descent points to the river.
  const Point2 d = r2 - r1;
  const double l2 = dot(d, d), t = dot(pp - r1, d) / l2;
  const double distance = std::abs(d.x * (pp.y - r1.y) - d.y * (pp.x - r1.x)) / std::sqrt(l2);
  return {{{p, 1.0}}, z1 + t * (z2 - z1) + bank_slope * distance};
}

LinearRow type2_row(int p1, Point2 a, int p2, Point2 b, Point2 r, double zr, double bank_slope) {
  // Fig. 6R: the ridge line's altitude at the projection of the river vertex r must exceed z_r; the
  // coefficients 1-s and s carry the signs of the cosines at p1 and p2, and sum to 1 (> 0).
  const Point2 d = b - a;
  const double l2 = dot(d, d), s = dot(r - a, d) / l2;
  const double distance = std::abs(d.x * (r.y - a.y) - d.y * (r.x - a.x)) / std::sqrt(l2);
  return {{{p1, 1 - s}, {p2, s}}, zr + bank_slope * distance};
}

namespace {

/// §6.3.1: level k on the half circle of radius r_k around the root; sectors split by the
/// barycentric rule a_n = θ_i + Δ O_d/(O_d+O_g) with Strahler orders; the right child's sector is
/// the one of smaller angles. The child of a node at level k stays within acos(r_k/r_k+1) of its
/// parent's angle, so that the angle at the parent between its partition ray and the edge is < 90°.
/// r_k linear in k, as the chapter suggests (a concave law, tried to fill more of the grid with the
/// deep random trees, made narrower facets and fewer D8-consistent rivers). The extra vertex (the
/// mouth) goes below the root on the root's partition ray.
void place_tree(const BinaryTree& tree, const std::vector<int>& order, double width_m, double height_m, PlanarMap& map) {
  const int n_tree = tree.size();
  std::vector<int> depth(std::size_t(n_tree), 0);
  int max_depth = 0;
  for (int n = 1; n < n_tree; ++n) max_depth = std::max(max_depth, depth[std::size_t(n)] = depth[std::size_t(tree.parent[std::size_t(n)])] + 1);
  const double margin = 0.04 * std::min(width_m, height_m);
  const double reach_m = std::min(width_m / 2 - margin, height_m - 2 * margin);
  const auto radius_of = [&](int k) { return reach_m * double(k) / (max_depth + 1.0); };
  const double r0 = radius_of(1);
  const Point2 root{width_m / 2, height_m - margin - r0};
  const std::size_t count = std::size_t(n_tree);
  std::vector<double> angle(count), lo(count), hi(count);
  lo[0] = 0;
  hi[0] = kPi;
  const auto split = [&](int n) {
    const int l = tree.left[std::size_t(n)], r = tree.right[std::size_t(n)];
    const double od = order[std::size_t(r)], og = order[std::size_t(l)];
    return lo[std::size_t(n)] + (hi[std::size_t(n)] - lo[std::size_t(n)]) * od / (od + og);
  };
  map.p.resize(std::size_t(n_tree) + 1);
  for (int n = 0; n < n_tree; ++n) {
    const std::size_t i = std::size_t(n);
    if (n > 0) {
      const int parent = tree.parent[i];
      double a = tree.leaf(n) ? 0.5 * (lo[i] + hi[i]) : split(n);
      if (parent > 0) {
        const int k = depth[std::size_t(parent)];
        const double reach = 0.9 * std::acos(radius_of(k) / radius_of(k + 1));
        a = std::clamp(a, angle[std::size_t(parent)] - reach, angle[std::size_t(parent)] + reach);
        a = std::clamp(a, lo[i], hi[i]);
      }
      angle[i] = a;
      const double radius = radius_of(depth[i]);
      map.p[i] = {root.x + radius * std::cos(a), root.y - radius * std::sin(a)};
    } else {
      angle[0] = split(0);
      map.p[0] = root;
    }
    if (!tree.leaf(n)) {
      const int l = tree.left[i], r = tree.right[i];
      lo[std::size_t(r)] = lo[i];
      hi[std::size_t(r)] = angle[i];
      lo[std::size_t(l)] = angle[i];
      hi[std::size_t(l)] = hi[i];
    }
  }
  map.mouth = n_tree;
  map.p[std::size_t(n_tree)] = {root.x - r0 * std::cos(angle[0]), root.y + r0 * std::sin(angle[0])};
}

/// §6.2.2: breadth-first, right to left, each internal node n on the outer boundary gets its
/// children n1 (right) and n2 (left) and five edges: n-n1, n-n2, n1-n2, n1-nd, n2-ng. The
/// triangles, the mouth (vertex tree.size()) closing the boundary.
std::vector<std::array<int, 3>> coarse_facets(const BinaryTree& tree) {
  const int n_tree = tree.size();
  std::vector<int> next(std::size_t(n_tree) + 1, -1), prev(std::size_t(n_tree) + 1, -1);  // boundary, right to left
  const int x = n_tree;
  next[std::size_t(x)] = 0;
  prev[std::size_t(x)] = 0;
  next[0] = x;
  prev[0] = x;
  std::vector<std::array<int, 3>> coarse;
  std::vector<int> queue{0};
  for (std::size_t head = 0; head < queue.size(); ++head) {
    const int n = queue[head];
    if (tree.leaf(n)) continue;
    const int n1 = tree.right[std::size_t(n)], n2 = tree.left[std::size_t(n)];
    const int nd = prev[std::size_t(n)], ng = next[std::size_t(n)];
    coarse.push_back({n, n1, n2});
    coarse.push_back({n, nd, n1});
    coarse.push_back({n, n2, ng});
    prev[std::size_t(n1)] = nd;
    next[std::size_t(n1)] = n2;
    prev[std::size_t(n2)] = n1;
    next[std::size_t(n2)] = ng;
    next[std::size_t(nd)] = n1;
    prev[std::size_t(ng)] = n2;
    queue.push_back(n1);
    queue.push_back(n2);
  }
  return coarse;
}

/// §6.2.4: a ridge vertex in the middle of every non-river edge (§6.3.2.2), the facets
/// retriangulated, and the linear constraints on the ridge vertices' altitudes.
class RidgeFacets {
 public:
  RidgeFacets(PlanarMap& map, const std::map<std::uint64_t, PlanarMap::RiverEdge>& river, double bank_slope)
      : map_(map), river_(river), bank_slope_(bank_slope) {}

  void split(const std::vector<std::array<int, 3>>& coarse, Rng& draw) {
    for (const auto& f : coarse) {
      int river_sides = 0;
      for (int k = 0; k < 3; ++k) river_sides += is_river(f[std::size_t(k)], f[std::size_t((k + 1) % 3)]) ? 1 : 0;
      // Rotate so that f = (a, b, c) with a-b a river edge (and, for two, a-c the other).
      std::array<int, 3> t = f;
      for (int k = 0; k < 3 && !(is_river(t[0], t[1]) && (river_sides == 1 || is_river(t[0], t[2]))); ++k) t = {t[1], t[2], t[0]};
      const int a = t[0], b = t[1], c = t[2];
      if (river_sides == 2) {  // a junction: one ridge vertex on b-c, where the ridge between the two branches starts
        const int p = ridge_on(b, c);
        type1(a, b, p);
        type1(a, c, p);
      } else if (river_sides == 1) {  // one river edge a-b: ridge vertices on b-c and c-a, joined by a ridge edge
        const int p = ridge_on(b, c), q = ridge_on(c, a);
        type2(c, p, q);
        if (draw.uniform() < 0.5) {
          type1(a, b, p);
          type2(a, p, q);
        } else {
          type1(a, b, q);
          type2(b, p, q);
        }
      } else {
        throw Error(ErrorKind::processing, "planar map: a facet without a river edge (the construction of §6.2.2 never makes one)");
      }
    }
    // A ridge vertex stands above both ends of its edge (our bound; it keeps each LP bounded).
    for (const auto& [key, p] : ridge_vertex_) {
      const int a = int(key >> 32), b = int(key & 0xffffffffu);
      const double half = 0.5 * norm(map_.p[std::size_t(a)] - map_.p[std::size_t(b)]);
      rows_.push_back({{{p, 1.0}}, std::max(map_.z[std::size_t(a)], map_.z[std::size_t(b)]) + bank_slope_ * half});
    }
  }

  /// §6.3.4.2.2: one LP per ridge line (connected ridge vertices), minimising the sum of altitudes.
  void solve_altitudes() {
    Components comp(map_.p.size());
    for (auto [p, q] : ridge_edges_) comp.join(p, q);
    std::map<int, std::vector<int>> variables;
    std::map<int, std::vector<LinearRow>> problems;
    for (const auto& [key, p] : ridge_vertex_) variables[comp.find(p)].push_back(p);
    for (const LinearRow& row : rows_) problems[comp.find(row.terms[0].first)].push_back(row);
    for (auto& [root_id, vars] : variables) {
      std::sort(vars.begin(), vars.end());
      const std::vector<double> z = solve_min_sum(vars, problems[root_id]);
      for (std::size_t i = 0; i < vars.size(); ++i) map_.z[std::size_t(vars[i])] = z[i];
      map_.lp_variables += vars.size();
      map_.lp_constraints += problems[root_id].size();
      ++map_.lp_problems;
    }
  }

  const std::vector<std::pair<int, int>>& ridge_edges() const { return ridge_edges_; }

 private:
  bool is_river(int a, int b) const { return river_.count(edge_key(a, b)) > 0; }
  int ridge_on(int a, int b) {
    auto [it, fresh] = ridge_vertex_.emplace(edge_key(a, b), int(map_.p.size()));
    if (fresh) {
      map_.p.push_back(0.5 * (map_.p[std::size_t(a)] + map_.p[std::size_t(b)]));
      map_.z.push_back(0);
      map_.kind.push_back(PlanarMap::Kind::ridge);
    }
    return it->second;
  }
  void type1(int r1, int r2, int p) {
    map_.facets.push_back({r1, r2, p});
    rows_.push_back(type1_row(map_.p[std::size_t(r1)], map_.z[std::size_t(r1)], map_.p[std::size_t(r2)], map_.z[std::size_t(r2)], p,
                              map_.p[std::size_t(p)], bank_slope_));
  }
  void type2(int r, int p1, int p2) {
    map_.facets.push_back({r, p1, p2});
    rows_.push_back(type2_row(p1, map_.p[std::size_t(p1)], p2, map_.p[std::size_t(p2)], map_.p[std::size_t(r)], map_.z[std::size_t(r)],
                              bank_slope_));
    ridge_edges_.emplace_back(p1, p2);
  }

  PlanarMap& map_;
  const std::map<std::uint64_t, PlanarMap::RiverEdge>& river_;
  const double bank_slope_;
  std::map<std::uint64_t, int> ridge_vertex_;
  std::vector<LinearRow> rows_;
  std::vector<std::pair<int, int>> ridge_edges_;
};

/// §6.2.5 global fractalisations: every facet into four; a new river vertex is pulled towards the
/// centre of one adjacent facet (weight C_PONDERAL against 1 and 1 for the edge ends, §6.3.2.2),
/// which keeps it inside that facet and below its midline, so the map stays planar; its altitude is
/// the mean of the ends (the river still descends). Other new vertices rise by up to roughness × length.
void fractalise(PlanarMap& map, const PlanarParams& params, Rng& draw) {
  std::map<std::uint64_t, std::vector<int>> faces_of;
  for (std::size_t f = 0; f < map.facets.size(); ++f)
    for (int k = 0; k < 3; ++k) faces_of[edge_key(map.facets[f][std::size_t(k)], map.facets[f][std::size_t((k + 1) % 3)])].push_back(int(f));
  std::map<std::uint64_t, PlanarMap::RiverEdge> river_now;
  for (const auto& e : map.rivers) river_now[edge_key(e.up, e.down)] = e;
  std::map<std::uint64_t, int> middle;
  std::vector<PlanarMap::RiverEdge> rivers;
  std::vector<std::pair<int, int>> ridges;
  std::map<std::uint64_t, bool> ridge_now;
  for (auto [a, b] : map.ridges) ridge_now[edge_key(a, b)] = true;
  for (const auto& [key, faces] : faces_of) {
    const int a = int(key >> 32), b = int(key & 0xffffffffu);
    const Point2 pa = map.p[std::size_t(a)], pb = map.p[std::size_t(b)];
    Point2 m = 0.5 * (pa + pb);
    double z = 0.5 * (map.z[std::size_t(a)] + map.z[std::size_t(b)]);
    PlanarMap::Kind kind = PlanarMap::Kind::other;
    const auto r = river_now.find(key);
    if (r != river_now.end()) {
      const auto& f = map.facets[std::size_t(faces[std::size_t(integer(draw, 0, int(faces.size()) - 1))])];
      const Point2 g = (1.0 / 3) * (map.p[std::size_t(f[0])] + map.p[std::size_t(f[1])] + map.p[std::size_t(f[2])]);
      m = (1.0 / (2 + params.meander)) * (pa + pb + params.meander * g);
      kind = PlanarMap::Kind::river;
    } else {
      z += params.roughness * norm(pb - pa) * draw.uniform();
      if (ridge_now.count(key)) kind = PlanarMap::Kind::ridge;
    }
    middle[key] = int(map.p.size());
    map.p.push_back(m);
    map.z.push_back(z);
    map.kind.push_back(kind);
    if (r != river_now.end()) {
      rivers.push_back({r->second.up, int(map.p.size() - 1), r->second.strahler});
      rivers.push_back({int(map.p.size() - 1), r->second.down, r->second.strahler});
    } else if (kind == PlanarMap::Kind::ridge) {
      ridges.emplace_back(a, int(map.p.size() - 1));
      ridges.emplace_back(int(map.p.size() - 1), b);
    }
  }
  std::vector<std::array<int, 3>> facets;
  facets.reserve(map.facets.size() * 4);
  for (const auto& f : map.facets) {
    const int ab = middle[edge_key(f[0], f[1])], bc = middle[edge_key(f[1], f[2])], ca = middle[edge_key(f[2], f[0])];
    facets.push_back({f[0], ab, ca});
    facets.push_back({ab, f[1], bc});
    facets.push_back({ca, bc, f[2]});
    facets.push_back({ab, bc, ca});
  }
  map.facets = std::move(facets);
  map.rivers = std::move(rivers);
  map.ridges = std::move(ridges);
}

}  // namespace

PlanarMap build_planar_map(const BinaryTree& tree, double width_m, double height_m, const PlanarParams& params) {
  const int n_tree = tree.size();
  const std::vector<int> order = strahler_orders(tree);
  for (int n = 0; n < n_tree; ++n)
    if (tree.parent[std::size_t(n)] >= 0 && tree.parent[std::size_t(n)] > n) throw Error(ErrorKind::processing, "tree: a child precedes its parent");
  PlanarMap map;
  place_tree(tree, order, width_m, height_m, map);
  map.kind.assign(std::size_t(n_tree) + 1, PlanarMap::Kind::river);

  // §6.3.4.1: DALT(n) = CRIV / Strahler(n)^a above the parent; the mouth at 0.
  map.z.assign(std::size_t(n_tree) + 1, 0);
  for (int n = 0; n < n_tree; ++n) {
    const double base = n == 0 ? 0.0 : map.z[std::size_t(tree.parent[std::size_t(n)])];
    map.z[std::size_t(n)] = base + params.drop_m / std::pow(order[std::size_t(n)], params.drop_exponent);
  }

  const std::vector<std::array<int, 3>> coarse = coarse_facets(tree);
  // River edges: the tree's and the root edge (to the mouth).
  std::map<std::uint64_t, PlanarMap::RiverEdge> river;
  for (int n = 0; n < n_tree; ++n)
    river[edge_key(n, n == 0 ? n_tree : tree.parent[std::size_t(n)])] = {n, n == 0 ? n_tree : tree.parent[std::size_t(n)], order[std::size_t(n)]};

  Rng draw(params.seed);
  RidgeFacets ridges(map, river, params.bank_slope);
  ridges.split(coarse, draw);
  ridges.solve_altitudes();
  for (auto [key, e] : river) map.rivers.push_back(e);
  map.ridges = ridges.ridge_edges();
  for (int pass = 0; pass < params.fractalisations; ++pass) fractalise(map, params, draw);
  return map;
}

void rasterise(const PlanarMap& map, Raster<float>& grid, Progress* progress) {
  const double cell = std::abs(grid.georef().transform[1]) * (grid.georef().crs.linear_unit_m > 0 ? grid.georef().crs.linear_unit_m : 1.0);
  std::fill(grid.values().begin(), grid.values().end(), std::numeric_limits<float>::quiet_NaN());
  if (progress) progress->begin("generate: facets");
  for (std::size_t f = 0; f < map.facets.size(); ++f) {
    const Point2 a = map.p[std::size_t(map.facets[f][0])], b = map.p[std::size_t(map.facets[f][1])], c = map.p[std::size_t(map.facets[f][2])];
    const double za = map.z[std::size_t(map.facets[f][0])], zb = map.z[std::size_t(map.facets[f][1])], zc = map.z[std::size_t(map.facets[f][2])];
    const double area = (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
    if (area == 0) continue;
    const int c0 = std::max(0, int(std::floor(std::min({a.x, b.x, c.x}) / cell - 0.5)));
    const int c1 = std::min(grid.cols() - 1, int(std::ceil(std::max({a.x, b.x, c.x}) / cell)));
    const int r0 = std::max(0, int(std::floor(std::min({a.y, b.y, c.y}) / cell - 0.5)));
    const int r1 = std::min(grid.rows() - 1, int(std::ceil(std::max({a.y, b.y, c.y}) / cell)));
    for (int r = r0; r <= r1; ++r)
      for (int col = c0; col <= c1; ++col) {
        const Point2 p{(col + 0.5) * cell, (r + 0.5) * cell};
        // Barycentric weights; a cell centre on a shared edge takes the facet drawn first.
        const double wa = ((b.x - p.x) * (c.y - p.y) - (b.y - p.y) * (c.x - p.x)) / area;
        const double wb = ((c.x - p.x) * (a.y - p.y) - (c.y - p.y) * (a.x - p.x)) / area;
        const double wc = 1 - wa - wb;
        if (wa < 0 || wb < 0 || wc < 0) continue;
        float& v = grid(col, r);
        if (std::isnan(v)) v = float(wa * za + wb * zb + wc * zc);
      }
    if (progress && f % 4096 == 0 && !progress->update(double(f) / map.facets.size()))
      throw Error(ErrorKind::cancelled, "generate: interrupted");
  }
  if (progress) progress->end();
}

GeneratedTerrain generate_planar(const GenerateRequest& request) {
  PlanarParams params = request.planar;
  params.seed = request.seed;
  const BinaryTree tree = !params.tree.empty()     ? parse_tree(params.tree, "--tree")
                           : params.uniform_tree ? random_binary_tree(params.nodes, request.seed)
                                                 : random_increasing_tree(params.nodes, request.seed);
  const double cell = request.cell_m;
  const PlanarMap map = build_planar_map(tree, request.grid.cols() * cell, request.grid.rows() * cell, params);
  GeneratedTerrain out;
  out.dem = request.grid;
  rasterise(map, out.dem, request.progress);
  const auto grid_point = [&](int v) { return GridPoint{map.p[std::size_t(v)].x / cell - 0.5, map.p[std::size_t(v)].y / cell - 0.5}; };
  // One reach per river edge; it flows into the edge leaving its downstream vertex (none at the mouth).
  std::map<int, int> leaving;
  for (std::size_t i = 0; i < map.rivers.size(); ++i) leaving[map.rivers[i].up] = int(i);
  for (const auto& e : map.rivers) {
    RiverReach reach;
    reach.line = {grid_point(e.up), grid_point(e.down)};
    const auto next = leaving.find(e.down);
    reach.downstream = next == leaving.end() ? -1 : next->second;
    out.plan.rivers.push_back(reach);
  }
  assign_strahler(out.plan);
  for (auto [a, b] : map.ridges)
    out.plan.ridges.push_back({{grid_point(a), grid_point(b)}, {float(map.z[std::size_t(a)]), float(map.z[std::size_t(b)])}});
  out.figures = {{"tree_nodes", double(tree.size())},
                 {"map_vertices", double(map.p.size())},
                 {"facets", double(map.facets.size())},
                 {"linear_programs", double(map.lp_problems)},
                 {"lp_unknowns", double(map.lp_variables)},
                 {"lp_inequalities", double(map.lp_constraints)}};
  return out;
}

}  // namespace terrapolis::generate
