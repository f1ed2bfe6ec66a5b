// SPDX-License-Identifier: MIT
#include "generate/river_ridge_plan.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace terrapolis::generate {

void assign_strahler(RiverRidgePlan& plan) {
  auto& rivers = plan.rivers;
  const int n = int(rivers.size());
  std::vector<int> pending(std::size_t(n), 0);  // inflows not yet ordered
  for (const auto& r : rivers) {
    if (r.downstream < -1 || r.downstream >= n) throw std::logic_error("assign_strahler: downstream index out of range");
    if (r.downstream >= 0) ++pending[std::size_t(r.downstream)];
  }
  std::vector<int> top(std::size_t(n), 0), top_count(std::size_t(n), 0), ready;
  for (int i = 0; i < n; ++i)
    if (pending[std::size_t(i)] == 0) ready.push_back(i);
  int done = 0;
  while (!ready.empty()) {  // sources first, then each reach once all its inflows are ordered
    const int i = ready.back();
    ready.pop_back();
    ++done;
    auto& r = rivers[std::size_t(i)];
    r.strahler = top[std::size_t(i)] == 0 ? 1 : top[std::size_t(i)] + (top_count[std::size_t(i)] >= 2 ? 1 : 0);
    if (r.downstream < 0) continue;
    const auto d = std::size_t(r.downstream);
    if (r.strahler > top[d]) top[d] = r.strahler, top_count[d] = 1;
    else if (r.strahler == top[d]) ++top_count[d];
    if (--pending[d] == 0) ready.push_back(r.downstream);
  }
  if (done != n) throw std::logic_error("assign_strahler: the river reaches form a cycle");
}

std::vector<RiverReach> reaches_from_paths(const std::vector<RiverPath>& paths) {
  const std::size_t n = paths.size();
  std::vector<std::vector<std::size_t>> cuts(n);  // per path: indices where a reach starts
  auto join_index = [&](const RiverPath& p) {  // a join at the very end is a join into the last segment
    const auto& into = paths[std::size_t(p.into)].line;
    return std::min(p.at, into.size() >= 2 ? into.size() - 2 : 0);
  };
  for (std::size_t i = 0; i < n; ++i) {
    cuts[i].push_back(0);
    if (paths[i].into >= 0) {
      if (std::size_t(paths[i].into) >= n) throw std::logic_error("reaches_from_paths: `into` out of range");
      cuts[std::size_t(paths[i].into)].push_back(join_index(paths[i]));
    }
  }
  std::vector<std::size_t> first(n + 1, 0);  // index of each path's first reach
  for (std::size_t i = 0; i < n; ++i) {
    std::sort(cuts[i].begin(), cuts[i].end());
    cuts[i].erase(std::unique(cuts[i].begin(), cuts[i].end()), cuts[i].end());
    first[i + 1] = first[i] + cuts[i].size();
  }
  std::vector<RiverReach> reaches(first[n]);
  for (std::size_t i = 0; i < n; ++i) {
    const auto& p = paths[i];
    for (std::size_t k = 0; k < cuts[i].size(); ++k) {
      const std::size_t from = cuts[i][k], to = k + 1 < cuts[i].size() ? cuts[i][k + 1] : p.line.size() - 1;
      RiverReach& r = reaches[first[i] + k];
      r.line.assign(p.line.begin() + std::ptrdiff_t(from), p.line.begin() + std::ptrdiff_t(to) + 1);
      if (!p.width_m.empty()) r.width_m = p.width_m[to];
      if (k + 1 < cuts[i].size()) {
        r.downstream = int(first[i] + k + 1);
      } else if (p.into >= 0) {
        const auto& c = cuts[std::size_t(p.into)];
        r.downstream = int(first[std::size_t(p.into)] + std::size_t(std::lower_bound(c.begin(), c.end(), join_index(p)) - c.begin()));
      }
    }
  }
  RiverRidgePlan s;
  s.rivers = std::move(reaches);
  assign_strahler(s);
  return std::move(s.rivers);
}

double line_length_m(const std::vector<GridPoint>& line, double cell_m) {
  double length = 0;
  for (std::size_t i = 1; i < line.size(); ++i)
    length += std::hypot(line[i][0] - line[i - 1][0], line[i][1] - line[i - 1][1]);
  return length * cell_m;
}

VectorLayer river_ridge_layer(const RiverRidgePlan& plan, const Georef& georef, double cell_m) {
  VectorLayer layer;
  layer.name = "skeleton";
  layer.geometry = GeometryType::line_string;
  layer.crs = georef.crs;
  layer.fields = {{"kind", FieldType::string},   {"id", FieldType::integer},
                  {"strahler", FieldType::integer}, {"width_m", FieldType::real},
                  {"downstream_id", FieldType::integer}, {"length_m", FieldType::real}};
  auto to_crs = [&](const std::vector<GridPoint>& line) {
    std::vector<std::array<double, 2>> out;
    out.reserve(line.size());
    for (const auto& p : line) out.push_back(georef.cell_centre(p[0], p[1]));
    return out;
  };
  for (std::size_t i = 0; i < plan.rivers.size(); ++i) {
    const auto& r = plan.rivers[i];
    if (r.line.size() < 2) continue;
    layer.features.push_back({{to_crs(r.line)},
                              {std::string("river"), std::int64_t(i + 1), std::int64_t(r.strahler), r.width_m,
                               std::int64_t(r.downstream + 1), line_length_m(r.line, cell_m)}});
  }
  for (std::size_t i = 0; i < plan.ridges.size(); ++i) {
    const auto& r = plan.ridges[i];
    if (r.line.size() < 2) continue;
    layer.features.push_back({{to_crs(r.line)},
                              {std::string("ridge"), std::int64_t(i + 1), std::monostate{}, std::monostate{},
                               std::int64_t(0), line_length_m(r.line, cell_m)}});
  }
  return layer;
}

}  // namespace terrapolis::generate
