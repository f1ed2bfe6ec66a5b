// SPDX-License-Identifier: MIT
#include "generate/distance_field.hpp"

#include <cmath>
#include <functional>
#include <queue>
#include <utility>

#include "core/neighbours.hpp"

namespace terrapolis::generate {

void distance_to(const std::vector<char>& source, int cols, int rows, std::vector<double>& dist, std::vector<std::size_t>& nearest) {
  const std::size_t n = std::size_t(cols) * rows;
  dist.assign(n, 1e30);
  nearest.assign(n, 0);
  using Item = std::pair<double, std::size_t>;
  std::priority_queue<Item, std::vector<Item>, std::greater<>> queue;
  for (std::size_t i = 0; i < n; ++i)
    if (source[i]) dist[i] = 0, nearest[i] = i, queue.push({0.0, i});
  while (!queue.empty()) {
    const auto [d, i] = queue.top();
    queue.pop();
    if (d > dist[i]) continue;
    const int c = int(i % std::size_t(cols)), r = int(i / std::size_t(cols));
    for (int k = 0; k < 8; ++k) {
      const int nc = c + dcol[std::size_t(k)], nr = r + drow[std::size_t(k)];
      if (nc < 0 || nr < 0 || nc >= cols || nr >= rows) continue;
      const std::size_t j = std::size_t(nr) * std::size_t(cols) + std::size_t(nc);
      const double nd = d + (is_diagonal(k) ? std::sqrt(2.0) : 1.0);
      if (nd < dist[j]) dist[j] = nd, nearest[j] = nearest[i], queue.push({nd, j});
    }
  }
}

}  // namespace terrapolis::generate
