// Inclusion removal and the site hierarchy in one pass (Belhadj 2007, §4.3.1.2 and §4.3.2, Algorithms 14 and 15).
// SPDX-License-Identifier: MIT
#include <algorithm>
#include <cmath>

#include "sites/sites.hpp"

namespace terrapolis::sites {

std::vector<Site> resolve_inclusions(const std::vector<Site>& sites, SitesOptions::Mode mode, const GridDistance& distance,
                                     int cols, int rows) {
  const std::size_t count = sites.size();
  if (count == 0) return {};
  // Buckets of cells at least as wide as the largest radius: a site's centre can only lie in a
  // disc of a site from the 3 x 3 buckets around it.
  double largest = 0;
  for (const Site& s : sites) largest = std::max(largest, s.radius_m);
  const CellMetrics& m = distance.metrics();
  const double min_width = *std::min_element(m.width_m.begin(), m.width_m.end());
  const double min_height = *std::min_element(m.height_m.begin(), m.height_m.end());
  const int bucket_cols = std::clamp(int(std::ceil(largest / min_width)), 1, cols);
  const int bucket_rows = std::clamp(int(std::ceil(largest / min_height)), 1, rows);
  const int bx = cols / bucket_cols + 1, by = rows / bucket_rows + 1;
  std::vector<std::vector<int>> buckets(std::size_t(bx) * std::size_t(by));
  for (std::size_t i = 0; i < count; ++i)
    buckets[std::size_t(sites[i].row / bucket_rows) * std::size_t(bx) + std::size_t(sites[i].col / bucket_cols)].push_back(int(i));

  std::vector<char> removed(count, 0);
  std::vector<int> parent(count, -1);
  for (std::size_t s = 0; s < count; ++s) {
    if (removed[s]) continue;
    const Site& S = sites[s];
    const int sx = S.col / bucket_cols, sy = S.row / bucket_rows;
    for (int y = std::max(0, sy - 1); y <= std::min(by - 1, sy + 1); ++y)
      for (int x = std::max(0, sx - 1); x <= std::min(bx - 1, sx + 1); ++x)
        for (int t : buckets[std::size_t(y) * std::size_t(bx) + std::size_t(x)]) {
          if (std::size_t(t) <= s || removed[std::size_t(t)]) continue;
          const Site& T = sites[std::size_t(t)];
          const double d = distance(S.col, S.row, T.col, T.row);
          if (!(d < S.radius_m)) continue;  // T's centre is outside S: not an inclusion
          const bool whole = d + T.radius_m <= S.radius_m;
          const bool same_rank = 2 * T.radius_m > S.radius_m;
          if (mode == SitesOptions::Mode::manhattan || whole || same_rank) removed[std::size_t(t)] = 1;
          else if (parent[std::size_t(t)] < 0) parent[std::size_t(t)] = int(s);  // a suburb of the first container
        }
  }

  std::vector<int> new_index(count, -1);
  std::vector<Site> kept;
  for (std::size_t i = 0; i < count; ++i) {
    if (removed[i]) continue;
    new_index[i] = int(kept.size());
    Site s = sites[i];
    s.id = int(kept.size());
    s.parent = parent[i] < 0 ? -1 : new_index[std::size_t(parent[i])];  // parents come first
    s.depth = s.parent < 0 ? 0 : kept[std::size_t(s.parent)].depth + 1;
    kept.push_back(s);
  }
  return kept;
}

double influence_radius_m(double people, double factor, double people_per_km2) {
  if (!(people_per_km2 > 0) || !(factor > 0)) return 0;
  return std::sqrt(factor * people / people_per_km2 * 1e6 / M_PI);
}

void attach_suburbs(std::vector<Site>& sites, const std::vector<double>& influence_m, const GridDistance& distance) {
  const CellMetrics& m = distance.metrics();
  const double min_width = *std::min_element(m.width_m.begin(), m.width_m.end());
  const double min_height = *std::min_element(m.height_m.begin(), m.height_m.end());
  for (std::size_t t = 0; t < sites.size(); ++t) {
    Site& T = sites[t];
    if (T.parent >= 0) continue;
    double best_pull = 0;
    for (std::size_t s = 0; s < t; ++s) {
      const Site& S = sites[s];
      const double reach = influence_m[s];
      if (S.population < 2 * T.population || !(reach > 0)) continue;
      // Cheap rejection by cells before the geodesic distance.
      if (std::abs(S.col - T.col) * min_width > reach || std::abs(S.row - T.row) * min_height > reach) continue;
      const double d = distance(S.col, S.row, T.col, T.row);
      if (!(d < reach)) continue;
      const double pull = double(S.population) / std::max(d * d, 1.0);
      if (pull > best_pull) best_pull = pull, T.parent = int(s);
    }
  }
  for (Site& s : sites) s.depth = s.parent < 0 ? 0 : sites[std::size_t(s.parent)].depth + 1;
}

}  // namespace terrapolis::sites
