// Flat inland water of a DEM (see flat_water.hpp).
// SPDX-License-Identifier: MIT
#include "hydro/flat_water.hpp"

#include <cmath>
#include <vector>

#include "core/geodesy.hpp"

namespace terrapolis::hydro {

FlatWater detect_flat_water(const Dem& dem, const FlatWaterOptions& options) {
  const int cols = dem.cols(), rows = dem.rows();
  FlatWater out{dem.like<std::uint8_t>(0), 0, 0.0};
  if (options.min_area_km2 <= 0 || cols < 3 || rows < 3) return out;
  const std::size_t n = dem.size();
  // Seeds: land cells level with all their neighbours (grid edges count as level).
  std::vector<std::uint8_t> seed(n, 0);
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) seed[dem.index(c, r)] = flat_water_seed(dem, c, r, options);
  // Components of seeds (8-connected), scan order: deterministic. Kept ones are marked with their
  // one-cell fringe (the shore cells at the water level that seeded them).
  const CellMetrics metrics = cell_metrics(dem.georef(), cols, rows);
  std::vector<std::int32_t> label(n, -1);
  std::vector<std::size_t> stack, members, region;
  std::vector<std::size_t> stamp(n, 0);  // s + 1: in the region of seed s; ~s: counted around it
  for (std::size_t s = 0; s < n; ++s) {
    if (!seed[s] || label[s] >= 0) continue;
    members.clear();
    stack.assign(1, s);
    label[s] = 0;
    double area_m2 = 0;
    while (!stack.empty()) {
      const std::size_t i = stack.back();
      stack.pop_back();
      members.push_back(i);
      const int c = int(i % std::size_t(cols)), r = int(i / std::size_t(cols));
      area_m2 += metrics.area_m2[std::size_t(r)];
      for (int dr = -1; dr <= 1; ++dr)
        for (int dc = -1; dc <= 1; ++dc) {
          if (c + dc < 0 || r + dr < 0 || c + dc >= cols || r + dr >= rows) continue;
          const std::size_t j = dem.index(c + dc, r + dr);
          if (seed[j] && label[j] < 0) {
            label[j] = 0;
            stack.push_back(j);
          }
        }
    }
    if (area_m2 < options.min_area_km2 * 1e6) continue;
    // The surface with its one-cell shore ring, then the cells just outside it: water lies in a
    // basin, so they rise from it but at its outlet; a flat valley floor (a dead-level alluvial
    // plain in SRTM's whole metres) falls away downstream along a whole side.
    region.clear();
    for (const std::size_t i : members) {
      const int c = int(i % std::size_t(cols)), r = int(i / std::size_t(cols));
      for (int dr = -1; dr <= 1; ++dr)
        for (int dc = -1; dc <= 1; ++dc)
          if (c + dc >= 0 && r + dr >= 0 && c + dc < cols && r + dr < rows && stamp[dem.index(c + dc, r + dr)] != s + 1) {
            stamp[dem.index(c + dc, r + dr)] = s + 1;
            region.push_back(dem.index(c + dc, r + dr));
          }
    }
    const double level = double(dem[s]);
    std::size_t outside = 0, lower = 0;
    for (const std::size_t i : region) {
      const int c = int(i % std::size_t(cols)), r = int(i / std::size_t(cols));
      for (int dr = -1; dr <= 1; ++dr)
        for (int dc = -1; dc <= 1; ++dc) {
          if (c + dc < 0 || r + dr < 0 || c + dc >= cols || r + dr >= rows) continue;
          const std::size_t j = dem.index(c + dc, r + dr);
          if (stamp[j] == s + 1 || stamp[j] == ~s) continue;
          stamp[j] = ~s;  // counted once
          ++outside;
          if (dem.is_nodata(j) || double(dem[j]) < level - options.tolerance_m) ++lower;
        }
    }
    if (!flat_water_in_basin(lower, outside)) continue;
    ++out.lakes;
    for (const std::size_t i : region) out.mask[i] = 1;
  }
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c)
      if (out.mask(c, r)) out.area_km2 += metrics.area_m2[std::size_t(r)] / 1e6;
  return out;
}

}  // namespace terrapolis::hydro
