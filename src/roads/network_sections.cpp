// Shared sections and junctions of a road network.
// SPDX-License-Identifier: MIT
#include "roads/network_sections.hpp"

#include <algorithm>
#include <cmath>
#include <tuple>

namespace terrapolis::roads {

CellChain cell_chain(const TerrainField& t, const std::vector<Cell>& path, const std::vector<Structure>& structures) {
  CellChain chain;
  if (path.empty()) return chain;
  chain.cells.push_back(std::uint32_t(t.index(path[0].col, path[0].row)));
  for (std::size_t i = 1; i < path.size(); ++i) {
    const Cell p = path[i - 1];
    const int dc = path[i].col - p.col, dr = path[i].row - p.row;
    const int steps = std::max(std::abs(dc), std::abs(dr));
    const Structure s = i - 1 < structures.size() ? structures[i - 1] : Structure::road;
    // The arc drawn with one cell per step along its major axis: consecutive cells are 8-neighbours.
    for (int k = 1; k <= steps; ++k) {
      const int col = p.col + int(std::floor(double(dc) * k / steps + 0.5)), row = p.row + int(std::floor(double(dr) * k / steps + 0.5));
      chain.cells.push_back(std::uint32_t(t.index(col, row)));
      chain.structures.push_back(s);
    }
  }
  return chain;
}

namespace {

struct Edge {
  std::uint32_t a = 0, b = 0;  ///< a < b
  Structure structure = Structure::road;
  std::vector<std::size_t> roads;
  bool existing = false;
  auto key() const { return std::make_tuple(a, b, int(structure)); }
};

GridPoint point_of(const TerrainField& t, std::uint32_t cell) {
  return {double(t.col_of(cell)), double(t.row_of(cell))};
}

/// Douglas-Peucker in grid units: the staircase of a chain drawn as straight runs, ends kept.
void simplify(const std::vector<GridPoint>& pts, std::size_t i, std::size_t j, double tolerance, std::vector<GridPoint>& out) {
  double worst = 0;
  std::size_t at = i;
  const double dx = pts[j].col - pts[i].col, dy = pts[j].row - pts[i].row, len = std::hypot(dx, dy);
  for (std::size_t k = i + 1; k < j; ++k) {
    const double ex = pts[k].col - pts[i].col, ey = pts[k].row - pts[i].row;
    const double d = len > 0 ? std::fabs(dx * ey - dy * ex) / len : std::hypot(ex, ey);
    if (d > worst) worst = d, at = k;
  }
  if (worst > tolerance) {
    simplify(pts, i, at, tolerance, out);
    simplify(pts, at, j, tolerance, out);
  } else {
    out.push_back(pts[j]);
  }
}

}  // namespace

GivenCells::GivenCells(const std::vector<CellChain>& chains)
    : GivenCells([&] {
        std::vector<std::uint32_t> all;
        for (const CellChain& chain : chains) all.insert(all.end(), chain.cells.begin(), chain.cells.end());
        return all;
      }()) {}

bool on_existing(const TerrainField& t, const GivenCells& existing, std::uint32_t a, std::uint32_t b) {
  if (existing.empty()) return false;
  const bool on_a = existing.holds(a), on_b = existing.holds(b);
  if (!on_a && !on_b) return false;
  auto near = [&](std::uint32_t cell, bool on) {
    if (on) return true;
    const int col = t.col_of(cell), row = t.row_of(cell);
    for (int dr = -1; dr <= 1; ++dr)
      for (int dc = -1; dc <= 1; ++dc)
        if (t.inside(col + dc, row + dr) && existing.holds(std::uint32_t(t.index(col + dc, row + dr)))) return true;
    return false;
  };
  return near(a, on_a) && near(b, on_b);
}

std::vector<std::array<double, 2>> chain_line(const TerrainField& t, const std::vector<std::uint32_t>& cells) {
  std::vector<GridPoint> pts, kept;
  for (std::uint32_t c : cells) pts.push_back(point_of(t, c));
  kept.push_back(pts.front());
  if (pts.size() > 1) simplify(pts, 0, pts.size() - 1, 0.5, kept);
  std::vector<std::array<double, 2>> out;
  for (const GridPoint& p : kept) out.push_back(t.georef().cell_centre(p.col, p.row));
  return out;
}

RoadNetworkLayout network_layout(const TerrainField& t, const std::vector<CellChain>& chains, const std::vector<RoadClass>& classes,
                                 const GivenCells& existing) {
  // Every step of every chain, as an undirected edge with the roads using it.
  std::vector<Edge> steps;
  for (std::size_t r = 0; r < chains.size(); ++r)
    for (std::size_t i = 0; i < chains[r].structures.size(); ++i) {
      const std::uint32_t u = chains[r].cells[i], v = chains[r].cells[i + 1];
      if (u != v) steps.push_back({std::min(u, v), std::max(u, v), chains[r].structures[i], {r}, on_existing(t, existing, u, v)});
    }
  std::sort(steps.begin(), steps.end(), [](const Edge& x, const Edge& y) { return std::tie(x.a, x.b, x.structure, x.roads[0]) < std::tie(y.a, y.b, y.structure, y.roads[0]); });
  std::vector<Edge> edges;
  for (Edge& s : steps) {
    if (!edges.empty() && edges.back().key() == s.key()) {
      if (edges.back().roads.back() != s.roads[0]) edges.back().roads.push_back(s.roads[0]);
    } else {
      edges.push_back(std::move(s));
    }
  }
  auto edge_of = [&](std::uint32_t u, std::uint32_t v, Structure s) {
    const auto key = std::make_tuple(std::min(u, v), std::max(u, v), int(s));
    return std::size_t(std::lower_bound(edges.begin(), edges.end(), key, [](const Edge& e, const auto& k) { return e.key() < k; }) - edges.begin());
  };
  // Incidence lists (CSR over the nodes, in node order).
  std::vector<std::pair<std::uint32_t, std::size_t>> incidence;
  for (std::size_t e = 0; e < edges.size(); ++e) incidence.push_back({edges[e].a, e}), incidence.push_back({edges[e].b, e});
  std::sort(incidence.begin(), incidence.end());
  auto incident = [&](std::uint32_t node) {
    const auto lo = std::lower_bound(incidence.begin(), incidence.end(), std::make_pair(node, std::size_t(0)));
    auto hi = lo;
    while (hi != incidence.end() && hi->first == node) ++hi;
    return std::make_pair(lo, hi);
  };
  // A breakpoint ends sections: not exactly two edges, or two that differ in roads or structure.
  auto breakpoint = [&](std::uint32_t node) {
    const auto [lo, hi] = incident(node);
    if (hi - lo != 2) return true;
    const Edge &x = edges[lo->second], &y = edges[(lo + 1)->second];
    return x.structure != y.structure || x.roads != y.roads || x.existing != y.existing;
  };
  auto other_end = [&](std::size_t e, std::uint32_t node) { return edges[e].a == node ? edges[e].b : edges[e].a; };
  auto next_edge = [&](std::uint32_t node, std::size_t e) {  // at a non-breakpoint: the other edge
    const auto [lo, hi] = incident(node);
    return lo->second == e ? (lo + 1)->second : lo->second;
  };

  RoadNetworkLayout layout;
  layout.with_existing = !existing.empty();
  std::vector<std::size_t> section_of(edges.size(), SIZE_MAX);
  for (std::size_t e0 = 0; e0 < edges.size(); ++e0) {
    if (section_of[e0] != SIZE_MAX) continue;
    // Back to the section's start, then forward to its end (a loop with no breakpoint stops where it began).
    std::uint32_t node = edges[e0].a;
    std::size_t e = e0;
    while (!breakpoint(node)) {
      const std::size_t prev = next_edge(node, e);
      if (prev == e0) break;
      e = prev;
      node = other_end(e, node);
    }
    NetworkSection s;
    s.roads = edges[e].roads;
    s.structure = edges[e].structure;
    s.existing = edges[e].existing;
    s.cells.push_back(node);
    const std::size_t id = layout.sections.size();
    while (true) {
      section_of[e] = id;
      const std::uint32_t next = other_end(e, node);
      s.length_m += t.length_m(point_of(t, node), point_of(t, next));
      s.cells.push_back(next);
      node = next;
      if (breakpoint(node)) break;
      e = next_edge(node, e);
      if (section_of[e] != SIZE_MAX) break;
    }
    s.road_class = RoadClass::maritime;
    for (std::size_t r : s.roads) s.road_class = std::min(s.road_class, classes[r]);
    layout.sections.push_back(std::move(s));
  }
  layout.road_sections.resize(chains.size());
  for (std::size_t r = 0; r < chains.size(); ++r)
    for (std::size_t i = 0; i < chains[r].structures.size(); ++i) {
      if (chains[r].cells[i] == chains[r].cells[i + 1]) continue;
      const std::size_t id = section_of[edge_of(chains[r].cells[i], chains[r].cells[i + 1], chains[r].structures[i])];
      auto& list = layout.road_sections[r];
      if (list.empty() || list.back() != id) list.push_back(id);
    }
  for (std::size_t k = 0; k < incidence.size();) {
    std::size_t end = k;
    while (end < incidence.size() && incidence[end].first == incidence[k].first) ++end;
    if (end - k >= 3) {
      Junction j;
      j.cell = incidence[k].first;
      j.degree = int(end - k);
      std::vector<std::size_t> roads;
      for (std::size_t i = k; i < end; ++i) {
        const NetworkSection& s = layout.sections[section_of[incidence[i].second]];
        j.classes.push_back(s.road_class);
        roads.insert(roads.end(), s.roads.begin(), s.roads.end());
      }
      std::sort(j.classes.begin(), j.classes.end());
      j.classes.erase(std::unique(j.classes.begin(), j.classes.end()), j.classes.end());
      std::sort(roads.begin(), roads.end());
      j.roads = std::size_t(std::unique(roads.begin(), roads.end()) - roads.begin());
      layout.junctions.push_back(std::move(j));
    }
    k = end;
  }
  return layout;
}

std::string id_list(const std::vector<std::size_t>& ids) {
  std::string out;
  for (std::size_t id : ids) {
    if (!out.empty()) out += ',';
    out += std::to_string(id);
  }
  return out;
}

VectorLayer network_sections_layer(const TerrainField& t, const RoadNetworkLayout& layout) {
  VectorLayer layer;
  layer.name = "sections";
  layer.geometry = GeometryType::line_string;
  layer.crs = t.georef().crs;
  layer.fields = {{"id", FieldType::integer},     {"roads", FieldType::string},     {"count", FieldType::integer},
                  {"class", FieldType::string},   {"structure", FieldType::string}, {"length_m", FieldType::real}};
  if (layout.with_existing) layer.fields.push_back({"existing", FieldType::integer});
  for (std::size_t i = 0; i < layout.sections.size(); ++i) {
    const NetworkSection& s = layout.sections[i];
    Feature f;
    f.parts.push_back(chain_line(t, s.cells));
    f.values = {std::int64_t(i), id_list(s.roads), std::int64_t(s.roads.size()), std::string(name_of(s.road_class)),
                std::string(structure_name(s.structure)), std::round(s.length_m * 100) / 100};
    if (layout.with_existing) f.values.push_back(std::int64_t(s.existing ? 1 : 0));
    layer.features.push_back(std::move(f));
  }
  return layer;
}

VectorLayer junctions_layer(const TerrainField& t, const RoadNetworkLayout& layout) {
  VectorLayer layer;
  layer.name = "junctions";
  layer.geometry = GeometryType::point;
  layer.crs = t.georef().crs;
  layer.fields = {{"degree", FieldType::integer}, {"classes", FieldType::string}, {"roads", FieldType::integer}};
  for (const Junction& j : layout.junctions) {
    std::string classes;
    for (RoadClass c : j.classes) {
      if (!classes.empty()) classes += ',';
      classes += name_of(c);
    }
    const GridPoint p = point_of(t, j.cell);
    layer.features.push_back({{{t.georef().cell_centre(p.col, p.row)}}, {std::int64_t(j.degree), classes, std::int64_t(j.roads)}});
  }
  return layer;
}

}  // namespace terrapolis::roads
