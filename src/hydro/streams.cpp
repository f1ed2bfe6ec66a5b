// Stream extraction by upstream-area threshold, Strahler ordering, reach vectorisation.
// SPDX-License-Identifier: MIT
#include "hydro/streams.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/error.hpp"
#include "hydro/grid.hpp"

namespace terrapolis::hydro {

VectorLayer extract_streams(const Raster<std::uint8_t>& d8, const Raster<double>& area, const CellMetrics& metrics,
                            const StreamOptions& options, Progress& progress) {
  if (!(options.threshold_km2 > 0) || !std::isfinite(options.threshold_km2))
    throw bad_input("/hydro/streams_threshold_km2: must be a positive number of km2");
  const double threshold = options.threshold_km2 * 1e6;
  StreamCells cells{d8.cols(), d8.rows(), {}, {}, {}};
  for (std::size_t i = 0; i < d8.size(); ++i)
    if (d8[i] != kNoData && area[i] >= threshold) {
      cells.index.push_back(std::int64_t(i));
      cells.code.push_back(d8[i]);
      cells.area_m2.push_back(area[i]);
    }
  return streams_of_cells(cells, d8.georef(), metrics, progress);
}

VectorLayer streams_of_cells(const StreamCells& cells, const Georef& georef, const CellMetrics& metrics, Progress& progress) {
  ProgressStep step(progress, "streams");
  const int cols = cells.cols;
  const std::size_t n_cells = cells.index.size();  // cells of the network, numbered in row-major order
  // Receiver on the stream network, or -1 (outlet).
  auto receiver = [&](std::size_t i) -> std::ptrdiff_t {
    const int k = cells.code[i];
    if (k >= 8) return -1;
    const int c = int(cells.index[i] % cols) + dcol[k], r = int(cells.index[i] / cols) + drow[k];
    if (c < 0 || r < 0 || c >= cols || r >= cells.rows) return -1;
    const std::int64_t g = std::int64_t(r) * cols + c;
    const auto it = std::lower_bound(cells.index.begin(), cells.index.end(), g);
    return it != cells.index.end() && *it == g ? it - cells.index.begin() : -1;
  };
  auto col_row = [&](std::size_t i) { return std::pair{int(cells.index[i] % cols), int(cells.index[i] / cols)}; };
  std::vector<std::uint8_t> inflow(n_cells, 0), order(n_cells, 0), top(n_cells, 0), top_count(n_cells, 0);
  for (std::size_t i = 0; i < n_cells; ++i)
    if (auto n = receiver(i); n >= 0) ++inflow[std::size_t(n)];
  step.update(0.3);
  // Strahler in topological order from the sources.
  std::vector<std::uint8_t> pending(inflow);
  for (std::size_t s = 0; s < n_cells; ++s) {
    if (inflow[s] != 0) continue;
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
  layer.crs = georef.crs;
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
    if (inflow[i] != 1) {
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
      const auto [c, r] = col_row(path[j]);
      f.parts[0].push_back(georef.cell_centre(c, r));
      if (j > 0) length += metrics.step_m(col_row(path[j - 1]).second, cells.code[path[j - 1]]);
    }
    const std::int64_t down = ends_at_confluence ? std::max<std::int64_t>(reach_id[last], 0) : 0;
    f.values = {reach_id[s], std::int64_t(order[s]), cells.area_m2[end_own] / 1e6, length, down};
    layer.features.push_back(std::move(f));
  }
  return layer;
}

}  // namespace terrapolis::hydro
