// Priority-Flood of the spillover graph (Barnes 2016), shared by the strip fill and the tile engine.
// SPDX-License-Identifier: MIT
#include "hydro/spill_graph.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <queue>
#include <utility>

namespace terrapolis::hydro {

std::vector<float> spill_levels(std::uint32_t nodes, std::vector<SpillEdge>& edges) {
  // Adjacency in compressed rows, then the graph's Priority-Flood from label 0.
  std::vector<std::uint32_t> start(std::size_t(nodes) + 1, 0);
  for (const SpillEdge& e : edges) {
    ++start[e.a + 1];
    ++start[e.b + 1];
  }
  for (std::size_t v = 0; v < nodes; ++v) start[v + 1] += start[v];
  std::vector<std::pair<std::uint32_t, float>> adjacent(start[nodes]);
  {
    std::vector<std::uint32_t> fill_at(start.begin(), start.end() - 1);
    for (const SpillEdge& e : edges) {
      adjacent[fill_at[e.a]++] = {e.b, e.spill};
      adjacent[fill_at[e.b]++] = {e.a, e.spill};
    }
  }
  edges = {};
  std::vector<float> level(nodes, INFINITY);
  std::vector<std::uint8_t> settled(nodes, 0);
  std::priority_queue<std::pair<float, std::uint32_t>, std::vector<std::pair<float, std::uint32_t>>, std::greater<>> queue;
  level[0] = -INFINITY;
  queue.push({-INFINITY, 0});
  while (!queue.empty()) {
    const auto [w, v] = queue.top();
    queue.pop();
    if (settled[v]) continue;
    settled[v] = 1;
    for (std::uint32_t e = start[v]; e < start[v + 1]; ++e) {
      const auto [u, spill] = adjacent[e];
      const float l = std::max(w, spill);
      if (l < level[u]) {
        level[u] = l;
        queue.push({l, u});
      }
    }
  }
  return level;
}

void keep_lowest_edges(std::vector<SpillEdge>& edges) {
  for (SpillEdge& e : edges)
    if (e.a > e.b) std::swap(e.a, e.b);
  std::sort(edges.begin(), edges.end(), [](const SpillEdge& x, const SpillEdge& y) {
    return x.a != y.a ? x.a < y.a : x.b != y.b ? x.b < y.b : x.spill < y.spill;
  });
  edges.erase(std::unique(edges.begin(), edges.end(), [](const SpillEdge& x, const SpillEdge& y) { return x.a == y.a && x.b == y.b; }),
              edges.end());
}

}  // namespace terrapolis::hydro
