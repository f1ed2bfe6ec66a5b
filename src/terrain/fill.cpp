// Void detection and windowed void filling; whole-grid reconstruction from sparse heights.
// SPDX-License-Identifier: MIT
#include "terrain/fill.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <optional>
#include <cmath>

#include "core/error.hpp"
#include "core/geodesy.hpp"
#include "core/neighbours.hpp"

namespace terrapolis::terrain {

FillMethod parse_fill_method(const std::string& option, const std::string& text) {
  if (text == "dmmc") return FillMethod::dmmc;
  if (text == "harmonic") return FillMethod::harmonic;
  if (text == "thin-plate") return FillMethod::thin_plate;
  throw bad_input(option + ": unknown method '" + text + "' (expected dmmc, harmonic or thin-plate)");
}

const char* to_string(FillMethod method) {
  switch (method) {
    case FillMethod::dmmc: return "dmmc";
    case FillMethod::harmonic: return "harmonic";
    case FillMethod::thin_plate: return "thin-plate";
  }
  return "?";
}

void reconstruct(Raster<float>& raster, const FillParams& params, Progress* progress) {
  if (params.method == FillMethod::dmmc) {
    dmmc(raster, params.dmmc, progress);
    return;
  }
  SplineParams spline = params.spline;
  // Rectangular cells (geographic grids): weigh the curvature along each axis by its true spacing.
  const CellMetrics metrics = cell_metrics(raster.georef(), raster.cols(), raster.rows());
  const int centre = raster.rows() / 2;
  if (metrics.height_m[std::size_t(centre) + 1] > 0) spline.cell_aspect = metrics.width_m[std::size_t(centre)] / metrics.height_m[std::size_t(centre) + 1];
  spline.smoothness = params.method == FillMethod::harmonic ? Smoothness::harmonic : Smoothness::thin_plate;
  spline_fill(raster, spline, progress);
}

std::vector<std::uint8_t> find_voids(const Dem& dem, const VoidOptions& options, VoidReport* report) {
  const int cols = dem.cols(), rows = dem.rows();
  const std::size_t n = dem.size();
  // 0: data, 1: nodata (candidate void), 2: outside (sea or border nodata).
  std::vector<std::uint8_t> kind(n, 0);
  for (std::size_t i = 0; i < n; ++i) kind[i] = dem.is_nodata(i) ? 1 : 0;
  auto is_sea = [&](std::size_t i) { return options.sea_level_m && !dem.is_nodata(i) && dem[i] <= *options.sea_level_m; };
  // Flood from the border through nodata (unless fill_border) and through sea cells.
  std::vector<std::uint32_t> stack;
  std::vector<std::uint8_t> seen(n, 0);
  auto passable = [&](std::size_t i) { return (kind[i] == 1 && !options.fill_border) || is_sea(i); };
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) {
      if (r != 0 && r != rows - 1 && c != 0 && c != cols - 1) continue;
      const std::size_t i = dem.index(c, r);
      if (!seen[i] && passable(i)) { seen[i] = 1; stack.push_back(std::uint32_t(i)); }
    }
  while (!stack.empty()) {
    const std::size_t i = stack.back();
    stack.pop_back();
    if (kind[i] == 1) kind[i] = 2;
    const int c = int(i % std::size_t(cols)), r = int(i / std::size_t(cols));
    for (int k = 0; k < 8; ++k) {
      const int x = c + dcol[std::size_t(k)], y = r + drow[std::size_t(k)];
      if (!dem.inside(x, y)) continue;
      const std::size_t j = dem.index(x, y);
      // Nodata touching the sea is sea even when border nodata is filled.
      if (seen[j] || !(passable(j) || (kind[j] == 1 && is_sea(i)))) continue;
      seen[j] = 1;
      stack.push_back(std::uint32_t(j));
    }
  }
  // Connected components of the remaining nodata, measured in geodesic km2.
  const CellMetrics metrics = cell_metrics(dem.georef(), cols, rows);
  std::vector<std::uint8_t> voids(n, 0);
  VoidReport rep;
  std::vector<std::uint32_t> component;
  for (std::size_t start = 0; start < n; ++start) {
    if (kind[start] != 1 || seen[start]) continue;
    component.clear();
    seen[start] = 1;
    stack.push_back(std::uint32_t(start));
    double area = 0;
    while (!stack.empty()) {
      const std::size_t i = stack.back();
      stack.pop_back();
      component.push_back(std::uint32_t(i));
      const int c = int(i % std::size_t(cols)), r = int(i / std::size_t(cols));
      area += metrics.area_m2[std::size_t(r)];
      for (int k = 0; k < 8; ++k) {
        const int x = c + dcol[std::size_t(k)], y = r + drow[std::size_t(k)];
        if (!dem.inside(x, y)) continue;
        const std::size_t j = dem.index(x, y);
        if (kind[j] != 1 || seen[j]) continue;
        seen[j] = 1;
        stack.push_back(std::uint32_t(j));
      }
    }
    ++rep.voids;
    rep.largest_km2 = std::max(rep.largest_km2, area / 1e6);
    if (options.max_area_km2 && area / 1e6 > *options.max_area_km2) { ++rep.too_large; continue; }
    ++rep.voids_filled;
    rep.cells_filled += component.size();
    for (const std::uint32_t i : component) voids[i] = 1;
  }
  if (report) *report = rep;
  return voids;
}

namespace {
struct Window {
  int c0, r0, c1, r1;  // inclusive bounds of the void
  std::vector<std::uint32_t> cells;
};
}  // namespace

void fill_voids(Dem& dem, const std::vector<std::uint8_t>& voids, const FillParams& params, Progress* progress) {
  const int cols = dem.cols(), rows = dem.rows();
  // Components of the void mask (8-neighbours), in row-major order of their first cell.
  std::vector<Window> windows;
  std::vector<std::uint8_t> seen(dem.size(), 0);
  std::vector<std::uint32_t> stack;
  for (std::size_t start = 0; start < dem.size(); ++start) {
    if (!voids[start] || seen[start]) continue;
    Window w{cols, rows, -1, -1, {}};
    seen[start] = 1;
    stack.push_back(std::uint32_t(start));
    while (!stack.empty()) {
      const std::size_t i = stack.back();
      stack.pop_back();
      w.cells.push_back(std::uint32_t(i));
      const int c = int(i % std::size_t(cols)), r = int(i / std::size_t(cols));
      w.c0 = std::min(w.c0, c); w.c1 = std::max(w.c1, c);
      w.r0 = std::min(w.r0, r); w.r1 = std::max(w.r1, r);
      for (int k = 0; k < 8; ++k) {
        const int x = c + dcol[std::size_t(k)], y = r + drow[std::size_t(k)];
        if (!dem.inside(x, y)) continue;
        const std::size_t j = dem.index(x, y);
        if (!voids[j] || seen[j]) continue;
        seen[j] = 1;
        stack.push_back(std::uint32_t(j));
      }
    }
    windows.push_back(std::move(w));
  }
  std::optional<ProgressStep> step;
  if (progress) step.emplace(*progress, "filling voids");
  const Dem source = dem;  // windows read the input and write only their own void: no race
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, windows.size(), 1), [&](const tbb::blocked_range<std::size_t>& range) {
    for (std::size_t k = range.begin(); k != range.end(); ++k) {
      const Window& w = windows[k];
      // Splines need only the two known rings their 13-point stencil reaches; DMMC's subdivision
      // tree benefits from more known context around the void.
      const int extent = std::max(w.c1 - w.c0, w.r1 - w.r0) + 1;
      const int margin = params.method == FillMethod::dmmc ? std::max(4, extent / 2) : 2;
      const int c0 = std::max(0, w.c0 - margin), r0 = std::max(0, w.r0 - margin);
      const int c1 = std::min(cols - 1, w.c1 + margin), r1 = std::min(rows - 1, w.r1 + margin);
      Georef georef = source.georef();
      auto& gt = georef.transform;
      gt[0] += c0 * gt[1] + r0 * gt[2];
      gt[3] += c0 * gt[4] + r0 * gt[5];
      Raster<float> window(c1 - c0 + 1, r1 - r0 + 1, georef);
      for (int r = r0; r <= r1; ++r)
        for (int c = c0; c <= c1; ++c) window(c - c0, r - r0) = source(c, r);
      // A void's window is small and its interior far from the samples: relaxing it longer is cheap.
      FillParams local = params;
      local.spline.max_sweeps = std::max(params.spline.max_sweeps, 300);
      reconstruct(window, local, nullptr);
      for (const std::uint32_t i : w.cells) {
        const int c = int(i % std::uint32_t(cols)), r = int(i / std::uint32_t(cols));
        dem[i] = window(c - c0, r - r0);
      }
    }
  });
  if (step) step->update(1.0);
}

}  // namespace terrapolis::terrain
