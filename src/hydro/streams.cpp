// Stream extraction by upstream-area threshold, Strahler ordering, reach vectorisation.
// SPDX-License-Identifier: MIT
#include "hydro/streams.hpp"

#include <cmath>
#include <vector>

#include "core/error.hpp"
#include "hydro/grid.hpp"

namespace terrapolis::hydro {

VectorLayer extract_streams(const Raster<std::uint8_t>& d8, const Raster<double>& area, const CellMetrics& metrics,
                            const StreamOptions& options, Progress& progress) {
  if (!(options.threshold_km2 > 0) || !std::isfinite(options.threshold_km2))
    throw bad_input("--streams-threshold: must be a positive number of km2");
  ProgressStep step(progress, "streams");
  const int cols = d8.cols();
  const double threshold = options.threshold_km2 * 1e6;
  const std::size_t n_cells = d8.size();
  auto on_stream = [&](std::size_t i) { return d8[i] != kNoData && area[i] >= threshold; };
  // Receiver on the stream network, or -1 (outlet).
  auto receiver = [&](std::size_t i) -> std::ptrdiff_t {
    const int k = d8[i];
    if (k >= 8) return -1;
    const int c = int(i % std::size_t(cols)) + dcol[k], r = int(i / std::size_t(cols)) + drow[k];
    if (!d8.inside(c, r)) return -1;
    const std::size_t n = d8.index(c, r);
    return on_stream(n) ? std::ptrdiff_t(n) : -1;
  };
  std::vector<std::uint8_t> inflow(n_cells, 0), order(n_cells, 0), top(n_cells, 0), top_count(n_cells, 0);
  for (std::size_t i = 0; i < n_cells; ++i)
    if (on_stream(i))
      if (auto n = receiver(i); n >= 0) ++inflow[std::size_t(n)];
  step.update(0.3);
  // Strahler in topological order from the sources.
  std::vector<std::uint8_t> pending(inflow);
  for (std::size_t s = 0; s < n_cells; ++s) {
    if (!on_stream(s) || inflow[s] != 0) continue;
    std::size_t i = s;
    for (;;) {
      order[i] = inflow[i] == 0 ? 1 : std::uint8_t(top[i] + (top_count[i] >= 2 ? 1 : 0));
      const auto n = receiver(i);
      if (n < 0) break;
      const std::size_t m = std::size_t(n);
      if (order[i] > top[m]) {
        top[m] = order[i];
        top_count[m] = 1;
      } else if (order[i] == top[m]) {
        ++top_count[m];
      }
      if (--pending[m] != 0) break;
      i = m;
    }
  }
  step.update(0.6);
  VectorLayer layer;
  layer.name = "streams";
  layer.geometry = GeometryType::line_string;
  layer.crs = d8.georef().crs;
  layer.fields = {{"id", FieldType::integer},
                  {"strahler", FieldType::integer},
                  {"upstream_km2", FieldType::real},
                  {"length_m", FieldType::real},
                  {"downstream_id", FieldType::integer}};
  // Reach ids by start cell (sources and confluences), in row-major order.
  std::vector<std::int64_t> reach_id(n_cells, 0);
  std::int64_t next = 1;
  std::vector<std::size_t> starts;
  for (std::size_t i = 0; i < n_cells; ++i)
    if (on_stream(i) && inflow[i] != 1) {
      starts.push_back(i);
      reach_id[i] = -1;  // provisional: single-cell reaches get no id
    }
  std::vector<std::vector<std::size_t>> paths;
  for (std::size_t s : starts) {
    std::vector<std::size_t> path{s};
    std::ptrdiff_t n = receiver(s);
    while (n >= 0) {
      path.push_back(std::size_t(n));
      if (inflow[std::size_t(n)] >= 2) break;
      n = receiver(std::size_t(n));
    }
    if (path.size() >= 2) reach_id[s] = next++;
    paths.push_back(std::move(path));
  }
  for (std::size_t p = 0; p < paths.size(); ++p) {
    const auto& path = paths[p];
    if (path.size() < 2) continue;
    const std::size_t s = path.front(), last = path.back();
    const bool ends_at_confluence = inflow[last] >= 2 && last != s;
    const std::size_t end_own = ends_at_confluence ? path[path.size() - 2] : last;
    Feature f;
    f.parts.emplace_back();
    double length = 0;
    for (std::size_t j = 0; j < path.size(); ++j) {
      const int c = int(path[j] % std::size_t(cols)), r = int(path[j] / std::size_t(cols));
      f.parts[0].push_back(d8.georef().cell_centre(c, r));
      if (j > 0) length += metrics.step_m(int(path[j - 1] / std::size_t(cols)), d8[path[j - 1]]);
    }
    const std::int64_t down = ends_at_confluence ? std::max<std::int64_t>(reach_id[last], 0) : 0;
    f.values = {reach_id[s], std::int64_t(order[s]), area[end_own] / 1e6, length, down};
    layer.features.push_back(std::move(f));
  }
  return layer;
}

}  // namespace terrapolis::hydro
