// Agglomeration network: Delaunay union, protected parent-child links, replay of the detour simplification.
// SPDX-License-Identifier: MIT
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <queue>
#include <random>
#include <set>

#include "core/error.hpp"
#include "core/geodesy.hpp"
#include "network/layers.hpp"
#include "network/network.hpp"
#include "sites/fixtures.hpp"

using namespace terrapolis;
using namespace terrapolis::network;
using sites::Site;

namespace {

Crs metres_crs() {
  Crs crs;
  crs.wkt = "LOCAL_CS[\"metres\"]";
  crs.geographic = false;
  return crs;
}

Site site(double x, double y, double r, int parent = -1) {
  static_assert(sizeof(Site) > 0);
  Site s;
  s.x = x, s.y = y, s.radius_m = r, s.parent = parent;
  return s;
}

std::vector<Site> numbered(std::vector<Site> v) {
  for (std::size_t i = 0; i < v.size(); ++i) v[i].id = int(i);
  return v;
}

// Plain Dijkstra over every edge flagged in `present`, except `skip`; no pruning.
double shortest_other_path(int n, const std::vector<Edge>& edges, const std::vector<char>& present, int skip, int a, int b) {
  std::vector<std::vector<std::pair<int, double>>> adj(static_cast<std::size_t>(n));
  for (std::size_t e = 0; e < edges.size(); ++e)
    if (present[e] && int(e) != skip) {
      adj[std::size_t(edges[e].from)].push_back({edges[e].to, edges[e].length_m});
      adj[std::size_t(edges[e].to)].push_back({edges[e].from, edges[e].length_m});
    }
  std::vector<double> dist(static_cast<std::size_t>(n), std::numeric_limits<double>::infinity());
  std::priority_queue<std::pair<double, int>, std::vector<std::pair<double, int>>, std::greater<>> q;
  dist[std::size_t(a)] = 0;
  q.push({0, a});
  while (!q.empty()) {
    auto [d, u] = q.top();
    q.pop();
    if (d > dist[std::size_t(u)]) continue;
    if (u == b) return d;
    for (auto [v, w] : adj[std::size_t(u)])
      if (d + w < dist[std::size_t(v)]) dist[std::size_t(v)] = d + w, q.push({d + w, v});
  }
  return std::numeric_limits<double>::infinity();
}

bool connected(int n, const std::vector<Edge>& edges) {
  std::vector<char> present(edges.size());
  for (std::size_t e = 0; e < edges.size(); ++e) present[e] = edges[e].kept;
  for (int v = 1; v < n; ++v)
    if (!std::isfinite(shortest_other_path(n, edges, present, -1, 0, v))) return false;
  return true;
}

// Every invariant of a simplified network, with the simplification replayed edge by edge.
void check_network(const std::vector<Site>& s, const Crs& crs, const SiteGraph& g, double k) {
  const int n = int(s.size());
  std::set<std::pair<int, int>> pairs;
  for (const Edge& e : g.edges) {
    EXPECT_TRUE(pairs.insert({std::min(e.from, e.to), std::max(e.from, e.to)}).second) << "duplicate " << e.from << "-" << e.to;
    EXPECT_NEAR(e.length_m, crs_distance_m(crs, s[std::size_t(e.from)].x, s[std::size_t(e.from)].y, s[std::size_t(e.to)].x,
                                           s[std::size_t(e.to)].y), 1e-6);
    const bool family = s[std::size_t(e.to)].parent == e.from || s[std::size_t(e.from)].parent == e.to;
    EXPECT_EQ(e.kind == EdgeKind::parent_child, family);
    if (e.kind == EdgeKind::parent_child) {
      EXPECT_TRUE(e.kept);
      EXPECT_EQ(s[std::size_t(e.to)].parent, e.from) << "parent first";
    }
  }
  for (int i = 0; i < n; ++i)
    if (s[std::size_t(i)].parent >= 0) {
      EXPECT_TRUE(pairs.count({std::min(i, s[std::size_t(i)].parent), std::max(i, s[std::size_t(i)].parent)}));
    }
  EXPECT_TRUE(connected(n, g.edges));

  // Replay: in examination order, the graph holds every edge not removed before.
  std::vector<int> order(g.edges.size(), -1);
  int examined = 0;
  for (std::size_t e = 0; e < g.edges.size(); ++e)
    if (g.edges[e].rank >= 0) order[std::size_t(g.edges[e].rank)] = int(e), ++examined;
  std::vector<char> present(g.edges.size(), 1);
  for (int r = 0; r < examined; ++r) {
    const int e = order[std::size_t(r)];
    ASSERT_GE(e, 0);
    const Edge& edge = g.edges[std::size_t(e)];
    const double other = shortest_other_path(n, g.edges, present, e, edge.from, edge.to);
    if (edge.kept) {
      EXPECT_GE(other, k * edge.length_m * (1 - 1e-12)) << "kept edge " << e << " had a detour";
      EXPECT_TRUE(std::isnan(edge.detour_ratio));
    } else {
      EXPECT_LT(other, k * edge.length_m) << "removed edge " << e << " had no detour";
      EXPECT_NEAR(edge.detour_ratio, other / edge.length_m, 1e-9);
      present[std::size_t(e)] = 0;
    }
  }
  // The examination goes by decreasing size of the sites.
  for (int r = 1; r < examined; ++r) {
    const Edge& a = g.edges[std::size_t(order[std::size_t(r - 1)])];
    const Edge& b = g.edges[std::size_t(order[std::size_t(r)])];
    const double ra = std::max(s[std::size_t(a.from)].radius_m, s[std::size_t(a.to)].radius_m);
    const double rb = std::max(s[std::size_t(b.from)].radius_m, s[std::size_t(b.to)].radius_m);
    EXPECT_GE(ra, rb);
  }
}

}  // namespace

// A(0,0) B(1000,0) C(500,100): AB (1000 m) is examined first (longest) and A-C-B, 1019.8 m,
// is under k x 1000 (the default 1.5): AB goes. AC and BC then have no other path and stay.
TEST(Network, GoldenTriangle) {
  const auto s = numbered({site(0, 0, 100), site(1000, 0, 100), site(500, 100, 100)});
  SilentProgress progress;
  const SiteGraph g = build_network(s, metres_crs(), {}, progress);
  ASSERT_EQ(g.edges.size(), 3u);
  const Edge& ab = g.edges[0];
  EXPECT_EQ(ab.from, 0);
  EXPECT_EQ(ab.to, 1);
  EXPECT_EQ(ab.kind, EdgeKind::inter_urban);
  EXPECT_FALSE(ab.kept);
  EXPECT_EQ(ab.rank, 0);
  EXPECT_NEAR(ab.detour_ratio, 2 * std::hypot(500.0, 100.0) / 1000.0, 1e-12);
  EXPECT_TRUE(g.edges[1].kept);
  EXPECT_TRUE(g.edges[2].kept);
  EXPECT_TRUE(std::isnan(g.edges[1].detour_ratio));
  // With k = 1.01 the detour (ratio 1.0198) is not good enough: everything stays.
  NetworkOptions tight;
  tight.k = 1.01;
  for (const Edge& e : build_network(s, metres_crs(), tight, progress).edges) EXPECT_TRUE(e.kept);
}

// P (r 1000) with children C1 (500,0) and C2 (250,10): P-C1 has a detour through C2 but is a
// parent-child link, so it stays; C1-C2 comes from the family triangulation.
TEST(Network, ParentChildNeverRemoved) {
  const auto s = numbered({site(0, 0, 1000), site(500, 0, 400, 0), site(250, 10, 300, 0), site(5000, 0, 1000)});
  SilentProgress progress;
  const SiteGraph g = build_network(s, metres_crs(), {}, progress);
  check_network(s, metres_crs(), g, NetworkOptions{}.k);
  int family = 0;
  for (const Edge& e : g.edges) {
    if (e.kind == EdgeKind::parent_child) {
      ++family;
      EXPECT_EQ(e.rank, -1);
    }
    if (std::min(e.from, e.to) == 1 && std::max(e.from, e.to) == 2) {
      EXPECT_EQ(e.kind, EdgeKind::all_sites);
    }
    if (std::min(e.from, e.to) == 0 && std::max(e.from, e.to) == 3) {
      EXPECT_EQ(e.kind, EdgeKind::inter_urban);
    }
  }
  EXPECT_EQ(family, 2);
}

// Differential: every edge of the Delaunay triangulation of all sites (found by brute force:
// a triangle whose circumcircle holds no other site) is in the union.
TEST(Network, ContainsEveryDelaunayEdgeOfAllSites) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(0, 10000);
  std::vector<Site> s;
  for (int i = 0; i < 40; ++i) s.push_back(site(u(rng), u(rng), 100 + 10 * (i % 7), i >= 10 ? i % 10 : -1));
  s = numbered(s);
  SilentProgress progress;
  const SiteGraph g = build_network(s, metres_crs(), {}, progress);
  std::set<std::pair<int, int>> pairs;
  for (const Edge& e : g.edges) pairs.insert({std::min(e.from, e.to), std::max(e.from, e.to)});
  const int n = int(s.size());
  for (int i = 0; i < n; ++i)
    for (int j = i + 1; j < n; ++j)
      for (int k = j + 1; k < n; ++k) {
        const double ax = s[std::size_t(i)].x, ay = s[std::size_t(i)].y, bx = s[std::size_t(j)].x, by = s[std::size_t(j)].y;
        const double cx = s[std::size_t(k)].x, cy = s[std::size_t(k)].y;
        const double d = 2 * (ax * (by - cy) + bx * (cy - ay) + cx * (ay - by));
        const double ux = ((ax * ax + ay * ay) * (by - cy) + (bx * bx + by * by) * (cy - ay) + (cx * cx + cy * cy) * (ay - by)) / d;
        const double uy = ((ax * ax + ay * ay) * (cx - bx) + (bx * bx + by * by) * (ax - cx) + (cx * cx + cy * cy) * (bx - ax)) / d;
        const double r2 = (ax - ux) * (ax - ux) + (ay - uy) * (ay - uy);
        bool empty = true;
        for (int q = 0; q < n && empty; ++q)
          if (q != i && q != j && q != k)
            empty = (s[std::size_t(q)].x - ux) * (s[std::size_t(q)].x - ux) + (s[std::size_t(q)].y - uy) * (s[std::size_t(q)].y - uy) > r2;
        if (!empty) continue;
        EXPECT_TRUE(pairs.count({i, j}) && pairs.count({i, k}) && pairs.count({j, k})) << i << " " << j << " " << k;
      }
  check_network(s, metres_crs(), g, NetworkOptions{}.k);
}

TEST(Network, CorsicaSitesReplay) {
  const auto sc = fixtures::scenario_from_sample("gebco2022_15s_north_corsica_capcorse.asc");
  SilentProgress progress;
  sites::SitesOptions o;
  o.seed = 4;
  const auto placed = sites::place_sites(sc.density, sc.buildable, o, progress);
  const Crs& crs = sc.density.georef().crs;
  ASSERT_TRUE(crs.geographic);
  const SiteGraph g = build_network(placed.sites, crs, {}, progress);
  check_network(placed.sites, crs, g, NetworkOptions{}.k);
  int removed = 0, inter = 0;
  for (const Edge& e : g.edges) removed += !e.kept, inter += e.kind == EdgeKind::inter_urban;
  EXPECT_GT(removed, 0);
  EXPECT_GT(inter, 0);
  // Deterministic.
  const SiteGraph again = build_network(placed.sites, crs, {}, progress);
  ASSERT_EQ(again.edges.size(), g.edges.size());
  for (std::size_t e = 0; e < g.edges.size(); ++e) {
    EXPECT_EQ(again.edges[e].from, g.edges[e].from);
    EXPECT_EQ(again.edges[e].to, g.edges[e].to);
    EXPECT_EQ(again.edges[e].kept, g.edges[e].kept);
  }
}

// Sites on a regular grid are co-circular by fours: the triangulation must still be a
// function of the input only, and the network connected.
TEST(Network, CocircularGridIsDeterministic) {
  std::vector<Site> s;
  for (int y = 0; y < 12; ++y)
    for (int x = 0; x < 12; ++x) s.push_back(site(x * 100.0, y * 100.0, 50));
  s = numbered(s);
  SilentProgress progress;
  const SiteGraph a = build_network(s, metres_crs(), {}, progress);
  const SiteGraph b = build_network(s, metres_crs(), {}, progress);
  ASSERT_EQ(a.edges.size(), b.edges.size());
  for (std::size_t e = 0; e < a.edges.size(); ++e) EXPECT_TRUE(a.edges[e].from == b.edges[e].from && a.edges[e].to == b.edges[e].to);
  check_network(s, metres_crs(), a, NetworkOptions{}.k);
}

TEST(Network, BadInputs) {
  SilentProgress progress;
  auto expect_bad = [&](const std::vector<Site>& s, double k, const char* word) {
    NetworkOptions o;
    o.k = k;
    try {
      build_network(s, metres_crs(), o, progress);
      ADD_FAILURE() << "no error for " << word;
    } catch (const Error& e) {
      EXPECT_EQ(e.kind(), ErrorKind::bad_input);
      EXPECT_NE(std::string(e.what()).find(word), std::string::npos) << e.what();
    }
  };
  expect_bad(numbered({site(0, 0, 1), site(1, 0, 1)}), 1.0, "k must");
  expect_bad(numbered({site(0, 0, 1), site(0, 0, 1)}), 1.8, "same position");
  expect_bad(numbered({site(0, 0, 1, 1), site(1, 0, 1, 0)}), 1.8, "cycle");
  expect_bad(numbered({site(0, 0, 1, 5), site(1, 0, 1)}), 1.8, "parent");
  // Degenerate but valid: no site, one site, collinear sites.
  EXPECT_TRUE(build_network({}, metres_crs(), {}, progress).edges.empty());
  EXPECT_TRUE(build_network(numbered({site(0, 0, 1)}), metres_crs(), {}, progress).edges.empty());
  const auto line = numbered({site(0, 0, 1), site(100, 0, 1), site(300, 0, 1), site(200, 0, 1)});
  const SiteGraph g = build_network(line, metres_crs(), {}, progress);
  EXPECT_EQ(g.edges.size(), 3u);
  check_network(line, metres_crs(), g, NetworkOptions{}.k);
}

// Geographic CRS far north, where the plane of the triangulations is most distorted and the
// A* lower bound (great circle on the b^2/a sphere) is tightest: decisions equal an unpruned
// Dijkstra's on geodesic lengths.
TEST(Network, HighLatitudeGeographicReplay) {
  Crs crs;
  crs.wkt = "GEOGCS[\"WGS 84\"]";
  crs.geographic = true;
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> lon(20, 23), lat(69, 70), r(100, 3000);
  std::vector<Site> s;
  for (int i = 0; i < 300; ++i) s.push_back(site(lon(rng), lat(rng), r(rng), i >= 200 ? i % 50 : -1));
  s = numbered(s);
  SilentProgress progress;
  const SiteGraph g = build_network(s, crs, {}, progress);
  check_network(s, crs, g, NetworkOptions{}.k);
  NetworkOptions loose;
  loose.k = 3.0;
  check_network(s, crs, build_network(s, crs, loose, progress), 3.0);
}

TEST(Network, RoadLinksReadTheKeptEdgesAndClassThemByTheCitiesRanks) {
  // 41 cities, city i of population 200,000 - 1000 i (rank i; all large enough for any level):
  // ranks 0-3 are level 0, 4-12 level 1, 13-39 level 2, 40 level 3. Kept links 0-1 (motorway), 1-13
  // (departmental: the smaller end decides) and 5-40 (local); the removed candidate 0-2 is no link.
  VectorLayer net;
  net.name = "network.geojson";
  net.geometry = GeometryType::line_string;
  net.fields = {{"from", FieldType::integer}, {"to", FieldType::integer}, {"kept", FieldType::integer}};
  net.features = {{{{{0, 0}, {1, 0}}}, {std::int64_t(0), std::int64_t(1), std::int64_t(1)}},
                  {{{{1, 0}, {2, 1}}}, {std::int64_t(1), std::int64_t(13), std::int64_t(1)}},
                  {{{{0, 0}, {2, 1}}}, {std::int64_t(0), std::int64_t(2), std::int64_t(0)}},
                  {{{{3, 0}, {4, 1}}}, {std::int64_t(5), std::int64_t(40), std::int64_t(1)}}};
  VectorLayer cities;
  cities.name = "cities.geojson";
  cities.fields = {{"id", FieldType::integer}, {"class", FieldType::integer}, {"population", FieldType::integer}};
  for (int id = 40; id >= 0; --id) cities.features.push_back({{}, {std::int64_t(id), std::int64_t(3), std::int64_t(200000 - 1000 * id)}});
  const auto links = network::road_links(net, &cities);
  ASSERT_EQ(links.size(), 3u);
  EXPECT_EQ(links[0].road_class, roads::RoadClass::motorway);
  EXPECT_EQ(links[1].road_class, roads::RoadClass::departmental);
  EXPECT_EQ(links[2].road_class, roads::RoadClass::local);
  EXPECT_EQ(links[1].from, 1);
  EXPECT_EQ(links[1].to, 13);
  EXPECT_EQ(links[1].b[0], 2.0);
  EXPECT_EQ(network::road_links(net, nullptr)[0].road_class, roads::RoadClass::departmental);  // no cities: departmental
  // The same ranks in a rural region: towns of 9,000 to 40,000 people. A motorway needs two cities of
  // 100,000, a national road two of 10,000: 0-1 (40,000 and 39,000) is national; 5-40 stays local.
  for (int id = 0; id <= 40; ++id) cities.features[std::size_t(40 - id)].values[2] = std::int64_t(id == 0 ? 40000 : id == 1 ? 39000 : 9000 - id);
  const auto rural = network::road_links(net, &cities);
  EXPECT_EQ(rural[0].road_class, roads::RoadClass::national);
  EXPECT_EQ(rural[1].road_class, roads::RoadClass::departmental);
  EXPECT_EQ(rural[2].road_class, roads::RoadClass::local);
  cities.fields[1].name = "rank";
  EXPECT_THROW(network::road_links(net, &cities), Error);
}
