// The population density model: water and buildable masks, coast, plateau, plain, combination.
// SPDX-License-Identifier: MIT
#include "density/density.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <climits>
#include <cstdint>
#include <cmath>
#include <functional>
#include <limits>
#include <numbers>

#include "core/error.hpp"
#include "core/geodesy.hpp"
#include "density/boosted.hpp"
#include "density/calibration.hpp"
#include "density/disc_sums.hpp"
#include "density/global_terms.hpp"
#include "density/tiled_density.hpp"

namespace terrapolis::density {
namespace {

constexpr float nan_f = std::numeric_limits<float>::quiet_NaN();

/// What a cell is for the model.
enum CellKind : std::uint8_t { land = 0, water = 1, unknown = 2 };

/// Runs fn(row) for every row in parallel, in ~32 chunks so the step can report progress and be
/// cancelled between them (ProgressStep is not called from worker threads).
void for_rows(int rows, ProgressStep& step, const std::function<void(int, int)>& fn) {
  const int chunks = std::min(rows, 32);
  for (int k = 0; k < chunks; ++k) {
    const int lo = int(std::int64_t(rows) * k / chunks), hi = int(std::int64_t(rows) * (k + 1) / chunks);
    tbb::parallel_for(tbb::blocked_range<int>(lo, hi, 1), [&](const tbb::blocked_range<int>& r) { fn(r.begin(), r.end()); });
    step.update(double(k + 1) / chunks);
  }
}

/// Largest value of `r` over habitable cells (0 when none), deterministic (max is exact).
float habitable_max(const Raster<float>& r, const Raster<std::uint8_t>& buildable) {
  return tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, r.size(), 1 << 16), 0.0f,
      [&](const tbb::blocked_range<std::size_t>& range, float m) {
        for (std::size_t i = range.begin(); i < range.end(); ++i)
          if (buildable[i] == 1 && r[i] > m) m = r[i];
        return m;
      },
      [](float a, float b) { return std::max(a, b); });
}

/// Rescales a characteristic so its largest value on habitable land is 1 (thesis §4.2.1: "ré-échelonnées
/// dans [0,1]"); uninhabitable land may hold more and is clamped to 1.
void divide_land_by_max(Raster<float>& r, const std::vector<std::uint8_t>& kind, float m) {
  if (m <= 0) return;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, r.size(), 1 << 16), [&](const tbb::blocked_range<std::size_t>& range) {
    for (std::size_t i = range.begin(); i < range.end(); ++i)
      if (kind[i] == land) r[i] = std::min(1.0f, r[i] / m);
  });
}

void check_options(const Dem& dem, const Raster<float>& hydrometry, const DensityOptions& o) {
  std::vector<double> factor_weights;
  for (const auto& f : o.factors) factor_weights.push_back(f.weight);
  check_settings(o, factor_weights);
  if (hydrometry.cols() != dem.cols() || hydrometry.rows() != dem.rows())
    throw bad_input("hydrometry: grid is " + std::to_string(hydrometry.cols()) + "x" + std::to_string(hydrometry.rows()) +
                    ", the DEM's is " + std::to_string(dem.cols()) + "x" + std::to_string(dem.rows()));
  for (const auto& f : o.factors)
    if (f.values.cols() != dem.cols() || f.values.rows() != dem.rows()) throw bad_input(f.name + ": factor is not on the DEM's grid");
  for (const auto& m : o.exclusion_masks)
    if (m.cols() != dem.cols() || m.rows() != dem.rows()) throw bad_input("exclusion mask: not on the DEM's grid");
  if (o.water_mask.size() && (o.water_mask.cols() != dem.cols() || o.water_mask.rows() != dem.rows()))
    throw bad_input("water mask: not on the DEM's grid");
}

/// Slope in degrees from central differences in metres (one-sided at edges and next to nodata).
float slope_deg(const Dem& dem, const CellMetrics& m, int c, int r) {
  auto z = [&](int cc, int rr) { return dem.inside(cc, rr) ? dem(cc, rr) : nan_f; };
  const float z0 = dem(c, r);
  auto derivative = [&](float before, float after, double d_before, double d_after) {
    const bool b = !std::isnan(before), a = !std::isnan(after);
    if (a && b) return (double(after) - double(before)) / (d_before + d_after);
    if (a) return (double(after) - z0) / d_after;
    if (b) return (double(z0) - before) / d_before;
    return 0.0;
  };
  const double dx = derivative(z(c - 1, r), z(c + 1, r), m.width_m[std::size_t(r)], m.width_m[std::size_t(r)]);
  const double dy = derivative(z(c, r - 1), z(c, r + 1), m.height_m[std::size_t(r)], m.height_m[std::size_t(r) + 1]);
  return float(std::atan(std::hypot(dx, dy)) * 180.0 / std::numbers::pi);
}



}  // namespace

void check_settings(const DensityOptions& o, const std::vector<double>& layer_weights) {
  if (!(o.r_min_m > 0) || !std::isfinite(o.r_min_m)) throw bad_input("/density/r_min_m: must be a positive number of metres");
  if (!(o.r_max_m > o.r_min_m) || !std::isfinite(o.r_max_m)) throw bad_input("/density/r_max_m: must be larger than /density/r_min_m (metres)");
  if (!(o.plateau_max_m >= o.plateau_min_m))
    throw bad_input("/density/plateau_max_m: lies below /density/plateau_min_m (" + std::to_string(int(o.plateau_max_m)) + " < " +
                    std::to_string(int(o.plateau_min_m)) + " m)");
  if (!(o.plain_max_variation_m > 0)) throw bad_input("/density/plain_max_variation_m: must be positive (metres)");
  if (std::isnan(o.sea_level_m)) throw bad_input("/water/sea_level_m: not a number");
  if (std::isnan(o.max_altitude_m)) throw bad_input("/density/max_altitude_m: not a number");
  if (o.max_slope_deg && !(*o.max_slope_deg > 0 && *o.max_slope_deg <= 90)) throw bad_input("/density/max_slope_deg: must be in (0, 90] degrees");
  if (o.river_bed_cap && !std::isfinite(*o.river_bed_cap)) throw bad_input("/density/river_bed_cap: not a number");
  if (o.ring_bands < 1) throw bad_input("ring bands: must be at least 1");
  bool any = false;
  for (double w : o.weights) {
    if (!std::isfinite(w)) throw bad_input("/density/weights: weights must be finite numbers");
    any = any || w != 0;
  }
  for (double w : o.terrain_weights) {
    if (!std::isfinite(w)) throw bad_input("/density/weights: weights must be finite numbers");
    any = any || w != 0;
  }
  for (std::size_t i = 0; i < layer_weights.size(); ++i) {
    if (!std::isfinite(layer_weights[i])) throw bad_input("/density/layers/" + std::to_string(i) + "/weight: must be a finite number");
    any = any || layer_weights[i] != 0;
  }
  if (!any && !o.model) throw bad_input("/density/weights: every weight is 0 (and every layer's), the density would be undefined");
}


double combine(const double* weights, const double* values, std::size_t n) {
  double negative = 0, total = 0, sum = 0;
  for (std::size_t i = 0; i < n; ++i) {
    sum += weights[i] * values[i];
    total += std::abs(weights[i]);
    if (weights[i] < 0) negative += weights[i];
  }
  if (total == 0) throw bad_input("/density/weights: every weight is 0, the density would be undefined");
  return std::clamp((sum - negative) / total, 0.0, 1.0);
}

namespace {

/// The grid as the model sees it: what each cell is, each row's span of land (only land needs
/// characteristics: a big saving on coastal tiles that are mostly sea and on nodata borders).
struct Grid {
  int cols = 0, rows = 0;
  CellMetrics metrics;
  std::vector<std::uint8_t> kind;  ///< CellKind per cell
  std::vector<int> span_lo, span_hi;  ///< land columns of each row: [lo, hi)
  float land_min = 0, land_max = 0;  ///< range of the land's altitudes (min > max: no land)
  bool any_unknown = false, any_water = false;
  /// The cells whose characteristics are computed: the whole grid, or a tile of a window whose
  /// other cells are its halo (compute_density_window).
  Window core;
  int core_lo(int r) const { return std::max(span_lo[std::size_t(r)], core.x0); }
  int core_hi(int r) const { return std::min(span_hi[std::size_t(r)], core.x0 + core.cols); }
};

/// Water, land or unknown per cell: water at or below the sea level, on nodata when it is sea,
/// and on the mask of inland water.
std::vector<std::uint8_t> cell_kinds(const Dem& dem, const DensityOptions& options) {
  std::vector<std::uint8_t> kind(dem.size());
  const Raster<std::uint8_t>& mask = options.water_mask;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, dem.size(), 1 << 16), [&](const tbb::blocked_range<std::size_t>& range) {
    for (std::size_t i = range.begin(); i < range.end(); ++i) {
      const float z = dem[i];
      const bool valid = !std::isnan(z);
      const bool is_water = (valid && z <= options.sea_level_m) || (!valid && options.nodata_is_sea) || (mask.size() && mask[i] != 0);
      kind[i] = is_water ? water : valid ? land : unknown;
    }
  });
  return kind;
}

Grid describe_grid(const Dem& dem, const DensityOptions& options, CellMetrics metrics) {
  Grid g;
  g.cols = dem.cols(), g.rows = dem.rows();
  g.core = Window{0, 0, g.cols, g.rows};
  g.metrics = std::move(metrics);
  g.kind = cell_kinds(dem, options);
  const auto nrows = static_cast<std::size_t>(g.rows);
  g.span_lo.assign(nrows, 0), g.span_hi.assign(nrows, 0);
  std::vector<std::uint8_t> row_unknown(nrows, 0), row_water(nrows, 0);
  std::vector<float> row_zmin(nrows), row_zmax(nrows);
  tbb::parallel_for(tbb::blocked_range<int>(0, g.rows, 8), [&](const tbb::blocked_range<int>& range) {
    for (int r = range.begin(); r < range.end(); ++r) {
      int lo = g.cols, hi = 0;
      bool u = false, w = false;
      float zmin = std::numeric_limits<float>::infinity(), zmax = -zmin;
      for (int x = 0; x < g.cols; ++x) {
        const std::size_t i = dem.index(x, r);
        const std::uint8_t k = g.kind[i];
        if (k == land) lo = std::min(lo, x), hi = x + 1, zmin = std::min(zmin, dem[i]), zmax = std::max(zmax, dem[i]);
        u = u || k == unknown;
        w = w || k == water;
      }
      g.span_lo[std::size_t(r)] = lo;
      g.span_hi[std::size_t(r)] = std::max(lo, hi);
      row_unknown[std::size_t(r)] = u, row_water[std::size_t(r)] = w;
      row_zmin[std::size_t(r)] = zmin, row_zmax[std::size_t(r)] = zmax;
    }
  });
  g.any_unknown = std::find(row_unknown.begin(), row_unknown.end(), 1) != row_unknown.end();
  g.any_water = std::find(row_water.begin(), row_water.end(), 1) != row_water.end();
  g.land_min = *std::min_element(row_zmin.begin(), row_zmin.end());
  g.land_max = *std::max_element(row_zmax.begin(), row_zmax.end());
  return g;
}

/// The largest distance between the centres of two 4-neighbours, metres.
double largest_cell_step(const CellMetrics& m) {
  double step = 0;
  for (std::size_t r = 0; r < m.width_m.size(); ++r) step = std::max({step, m.width_m[r], m.height_m[r], m.height_m[r + 1]});
  return step;
}

/// The masks (§4.2.2.2, the thresholds): uninhabitable are water, cells too high, excluded,
/// river beds and cells too steep; the hydrometry clamped to [0,1], 0 on water.
void mark_buildable(const Dem& dem, const Grid& g, const Raster<float>& hydrometry, const DensityOptions& options, DensityResult& result,
                    Progress& progress) {
  ProgressStep step(progress, "density: masks");
  std::vector<std::uint8_t> excluded(dem.size(), 0);
  for (const auto& ex : options.exclusion_masks)
    for (std::size_t i = 0; i < dem.size(); ++i)
      if (ex[i] != 0) excluded[i] = 1;
  step.update(0.5);
  result.hydrometry = dem.like<float>(nan_f);
  result.buildable = dem.like<std::uint8_t>(255);
  result.buildable.nodata = 255;
  tbb::parallel_for(tbb::blocked_range<int>(0, g.rows, 8), [&](const tbb::blocked_range<int>& range) {
    for (int r = range.begin(); r < range.end(); ++r)
      for (int x = 0; x < g.cols; ++x) {
        const std::size_t i = dem.index(x, r);
        if (g.kind[i] == unknown) continue;
        const float hv = std::isnan(hydrometry[i]) ? 0.0f : std::clamp(hydrometry[i], 0.0f, 1.0f);
        result.hydrometry[i] = g.kind[i] == water ? 0.0f : hv;
        bool ok = g.kind[i] == land && dem[i] <= options.max_altitude_m && !excluded[i];
        if (ok && options.river_bed_cap && hv > *options.river_bed_cap) ok = false;
        if (ok && options.max_slope_deg && slope_deg(dem, g.metrics, x, r) > *options.max_slope_deg) ok = false;
        result.buildable[i] = ok ? 1 : 0;
      }
  });
}

/// The summed-area tables cover only the land's bounding box grown by the discs' reach: no cell
/// outside it falls in the disc of a land cell.
Window disc_window(const Grid& g, const DiscPlan& inner, const DiscPlan& outer) {
  Window win;
  int r_lo = g.rows, r_hi = -1, c_lo = g.cols, c_hi = -1;
  for (int r = 0; r < g.rows; ++r)
    if (g.span_lo[std::size_t(r)] < g.span_hi[std::size_t(r)]) {
      r_lo = std::min(r_lo, r), r_hi = r;
      c_lo = std::min(c_lo, g.span_lo[std::size_t(r)]), c_hi = std::max(c_hi, g.span_hi[std::size_t(r)] - 1);
    }
  if (r_hi >= 0) {
    const int ry = std::max(outer.reach_rows(), inner.reach_rows()), rx = std::max(outer.reach_cols(), inner.reach_cols());
    win.y0 = std::max(0, r_lo - ry);
    win.x0 = std::max(0, c_lo - rx);
    win.rows = std::min(g.rows, r_hi + ry + 1) - win.y0;
    win.cols = std::min(g.cols, c_hi + rx + 1) - win.x0;
  }
  return win;
}

/// Plain (§4.2.1, point 4): 1 - the standard deviation of the land's altitudes within r_min over
/// plain_max_variation, clamped to [0,1]; 0 on water.
Raster<float> plain_characteristic(const Dem& dem, const Grid& g, const DiscPlan& inner, const Window& win, double max_variation_m,
                                   Progress& progress) {
  Raster<float> plain = dem.like<float>(nan_f);
  ProgressStep step(progress, "density: plain");
  const std::vector<std::uint8_t>& kind = g.kind;
  // Altitudes are taken relative to the middle of their range to keep the squares small.
  const double mid = g.land_min <= g.land_max ? 0.5 * (double(g.land_min) + double(g.land_max)) : 0.0;
  // When every cell is land, land cells in a disc are counted by arithmetic instead.
  const bool all_land = !g.any_water && !g.any_unknown;
  const SummedArea<std::uint32_t> count = all_land ? SummedArea<std::uint32_t>()
                                                   : SummedArea<std::uint32_t>(win, g.cols, [&](std::size_t i) { return std::uint32_t(kind[i] == land); });
  const SummedArea<double> s1(win, g.cols, [&](std::size_t i) { return kind[i] == land ? double(dem[i]) - mid : 0.0; });
  const SummedArea<double> s2(win, g.cols, [&](std::size_t i) {
    const double d = kind[i] == land ? double(dem[i]) - mid : 0.0;
    return d * d;
  });
  for_rows(g.rows, step, [&](int r0, int r1) {
    std::vector<std::uint32_t> a(std::size_t(g.cols), 0);
    std::vector<double> b(static_cast<std::size_t>(g.cols)), c(static_cast<std::size_t>(g.cols));
    for (int r = r0; r < r1; ++r) {
      for (int x = 0; x < g.cols; ++x)
        if (kind[dem.index(x, r)] == water) plain(x, r) = 0;
      const int x0 = g.span_lo[std::size_t(r)], x1 = g.span_hi[std::size_t(r)];
      if (x0 >= x1) continue;
      std::fill(a.begin() + x0, a.begin() + x1, 0u);
      std::fill(b.begin() + x0, b.begin() + x1, 0.0);
      std::fill(c.begin() + x0, c.begin() + x1, 0.0);
      if (all_land) add_disc_count_row(inner, g.cols, g.rows, r, +1, a.data(), x0, x1);
      else add_disc_row(count, inner, r, +1, a.data(), x0, x1);
      add_disc_row(s1, inner, r, +1, b.data(), x0, x1);
      add_disc_row(s2, inner, r, +1, c.data(), x0, x1);
      for (int x = x0; x < x1; ++x) {
        const std::size_t i = dem.index(x, r);
        if (kind[i] != land) continue;
        const double k = a[std::size_t(x)];
        const double mean = b[std::size_t(x)] / k;
        const double sd = std::sqrt(std::max(0.0, c[std::size_t(x)] / k - mean * mean));
        plain[i] = float(std::clamp(1.0 - sd / max_variation_m, 0.0, 1.0));
      }
    }
  });
  return plain;
}

/// Coast and plateau (§4.2.1, points 1 and 3): the shares of water and of rough plateau ground in
/// the ring r_min..r_max, each divided by its maximum over habitable land; 0 on water.
void ring_shares(const Dem& dem, const Grid& g, const DiscPlan& inner, const DiscPlan& outer, const Window& win, const DensityOptions& options,
                 const std::optional<std::array<float, 2>>& maxima, DensityResult& result, Progress& progress) {
  result.coast = dem.like<float>(nan_f);
  result.plateau = dem.like<float>(nan_f);
  ProgressStep step(progress, "density: coast and plateau");
  const std::vector<std::uint8_t>& kind = g.kind;
  // Plateau ground "opposed to plains" (§4.2.1, point 3): altitude within the plateau range,
  // weighted by how far it is from a plain (cliffs and slopes count, flat tops do not). The
  // weight is quantised to `levels` steps so its sums stay exact integers in 32 bits.
  const double levels = std::min(1024.0, std::floor(double(UINT32_MAX) / std::max(1.0, outer.max_cells())));
  if (levels < 16) throw bad_input("/density/r_max_m: the ring holds too many cells for this grid (" + std::to_string(outer.max_cells()) + ")");
  // An inland grid has no coast: its water sums are all 0 and need no table.
  const SummedArea<std::uint32_t> wet = g.any_water ? SummedArea<std::uint32_t>(win, g.cols, [&](std::size_t i) { return std::uint32_t(kind[i] == water); })
                                                    : SummedArea<std::uint32_t>();
  // Without unknown cells every cell is known: count ring cells by arithmetic instead.
  const SummedArea<std::uint32_t> known = g.any_unknown ? SummedArea<std::uint32_t>(win, g.cols, [&](std::size_t i) { return std::uint32_t(kind[i] != unknown); })
                                                        : SummedArea<std::uint32_t>();
  const SummedArea<std::uint32_t> high(win, g.cols, [&](std::size_t i) {
    const float z = dem[i];
    const bool in_range = kind[i] == land && z >= options.plateau_min_m && z <= options.plateau_max_m;
    return in_range ? std::uint32_t(std::lround((1.0 - double(result.plain[i])) * levels)) : 0u;
  });
  for_rows(g.core.rows, step, [&](int r0, int r1) {
    std::vector<std::uint32_t> w(static_cast<std::size_t>(g.cols)), k(static_cast<std::size_t>(g.cols)), h(static_cast<std::size_t>(g.cols));
    for (int r = r0 + g.core.y0; r < r1 + g.core.y0; ++r) {
      for (int x = g.core.x0; x < g.core.x0 + g.core.cols; ++x)
        if (kind[dem.index(x, r)] == water) result.coast(x, r) = result.plateau(x, r) = 0;
      const int x0 = g.core_lo(r), x1 = g.core_hi(r);
      if (x0 >= x1) continue;
      std::fill(w.begin() + x0, w.begin() + x1, 0u);
      std::fill(k.begin() + x0, k.begin() + x1, 0u);
      std::fill(h.begin() + x0, h.begin() + x1, 0u);
      if (g.any_water) {
        add_disc_row(wet, outer, r, +1, w.data(), x0, x1);
        add_disc_row(wet, inner, r, -1, w.data(), x0, x1);
      }
      if (g.any_unknown) {
        add_disc_row(known, outer, r, +1, k.data(), x0, x1);
        add_disc_row(known, inner, r, -1, k.data(), x0, x1);
      } else {
        add_disc_count_row(outer, g.cols, g.rows, r, +1, k.data(), x0, x1);
        add_disc_count_row(inner, g.cols, g.rows, r, -1, k.data(), x0, x1);
      }
      add_disc_row(high, outer, r, +1, h.data(), x0, x1);
      add_disc_row(high, inner, r, -1, h.data(), x0, x1);
      for (int x = x0; x < x1; ++x) {
        const std::size_t i = dem.index(x, r);
        if (kind[i] != land) continue;
        const double total = k[std::size_t(x)];
        // Band approximations can make a ring cell count slightly off: keep shares in [0,1].
        result.coast[i] = total > 0 ? float(std::clamp(double(w[std::size_t(x)]) / total, 0.0, 1.0)) : 0.0f;
        result.plateau[i] = total > 0 ? float(std::clamp(double(h[std::size_t(x)]) / levels / total, 0.0, 1.0)) : 0.0f;
      }
    }
  });
  // The halo's cells have no share (NaN): the maxima are the core's.
  result.stats.coast_max = habitable_max(result.coast, result.buildable);
  result.stats.plateau_max = habitable_max(result.plateau, result.buildable);
  divide_land_by_max(result.coast, kind, maxima ? (*maxima)[0] : result.stats.coast_max);
  divide_land_by_max(result.plateau, kind, maxima ? (*maxima)[1] : result.stats.plateau_max);
}

bool terrain_used(const DensityOptions& options) {
  return std::any_of(options.terrain_weights.begin(), options.terrain_weights.end(), [](double w) { return w != 0; });
}

/// Topographic position (Weiss 2001; Guisan et al. 1999): each land cell's altitude minus the mean
/// altitude of the land cells within the disc of `plan`, NaN off land and off the core.
Raster<float> topographic_position(const Dem& dem, const Grid& g, const DiscPlan& plan) {
  Raster<float> out = dem.like<float>(nan_f);
  const Window win = disc_window(g, plan, plan);
  const std::vector<std::uint8_t>& kind = g.kind;
  const double mid = g.land_min <= g.land_max ? 0.5 * (double(g.land_min) + double(g.land_max)) : 0.0;
  const SummedArea<std::uint32_t> count(win, g.cols, [&](std::size_t i) { return std::uint32_t(kind[i] == land); });
  const SummedArea<double> sum(win, g.cols, [&](std::size_t i) { return kind[i] == land ? double(dem[i]) - mid : 0.0; });
  tbb::parallel_for(tbb::blocked_range<int>(g.core.y0, g.core.y0 + g.core.rows, 4), [&](const tbb::blocked_range<int>& range) {
    std::vector<std::uint32_t> a(static_cast<std::size_t>(g.cols));
    std::vector<double> b(static_cast<std::size_t>(g.cols));
    for (int r = range.begin(); r < range.end(); ++r) {
      const int x0 = g.core_lo(r), x1 = g.core_hi(r);
      if (x0 >= x1) continue;
      std::fill(a.begin() + x0, a.begin() + x1, 0u);
      std::fill(b.begin() + x0, b.begin() + x1, 0.0);
      add_disc_row(count, plan, r, +1, a.data(), x0, x1);
      add_disc_row(sum, plan, r, +1, b.data(), x0, x1);
      for (int x = x0; x < x1; ++x) {
        const std::size_t i = dem.index(x, r);
        if (kind[i] == land) out[i] = float(double(dem[i]) - mid - b[std::size_t(x)] / std::max(1u, a[std::size_t(x)]));
      }
    }
  });
  return out;
}

/// The terrain terms the thesis does not have (TerrainTerm, fitted by `terrapolis calibrate`), on
/// the core's land. On a window, `whole` gives the whole grid's discs, distances and ranks (no
/// ranks: the terms are left unranked, for the tiles to count them).
void terrain_terms(const Dem& dem, const Grid& g, const DensityOptions& options, const WholeTerrainFigures* whole, DensityResult& result,
                   Progress& progress) {
  ProgressStep step(progress, "density: terrain terms");
  const bool rivers_known = options.rivers.size() == dem.size();
  if (!whole && options.rivers.size() != 0 && !rivers_known) throw bad_input("rivers: not on the DEM's grid");
  // No distance without a feature: its term is then 0, as exp(-infinity) would be.
  std::vector<float> own_water, own_river;  // on the whole grid; a window's come with `whole`
  if (!whole && g.any_water) own_water = distance_to_m(water_cells(dem, options), g.metrics, g.cols, g.rows);
  if (!whole && rivers_known) own_river = distance_to_m(river_mask(options.rivers), g.metrics, g.cols, g.rows);
  const std::vector<float>& to_water = whole ? whole->to_water : own_water;
  const std::vector<float>& to_river = whole ? whole->to_river : own_river;
  step.update(0.3);
  auto term = [&](TerrainTerm t) -> Raster<float>& { return result.terrain[std::size_t(t)]; };
  if (whole) {
    term(TerrainTerm::position_1km) = topographic_position(dem, g, whole->near);
    step.update(0.5);
    term(TerrainTerm::position_5km) = topographic_position(dem, g, whole->far);
  } else {
    const std::array<DiscPlan, 2> plans = position_discs(g.metrics, g.rows, options.ring_bands);
    term(TerrainTerm::position_1km) = topographic_position(dem, g, plans[0]);
    step.update(0.5);
    term(TerrainTerm::position_5km) = topographic_position(dem, g, plans[1]);
  }
  step.update(0.8);
  for (TerrainTerm t : {TerrainTerm::altitude, TerrainTerm::slope, TerrainTerm::coast_near, TerrainTerm::river_near})
    term(t) = dem.like<float>(nan_f);
  tbb::parallel_for(tbb::blocked_range<int>(g.core.y0, g.core.y0 + g.core.rows, 8), [&](const tbb::blocked_range<int>& range) {
    for (int r = range.begin(); r < range.end(); ++r)
      for (int x = g.core.x0; x < g.core.x0 + g.core.cols; ++x) {
        const std::size_t i = dem.index(x, r);
        if (g.kind[i] != land) continue;
        term(TerrainTerm::altitude)[i] = dem[i];
        term(TerrainTerm::slope)[i] = slope_deg(dem, g.metrics, x, r);
        term(TerrainTerm::coast_near)[i] = to_water.empty() ? 0.0f : float(std::exp(-double(to_water[i]) / 10000.0));
        term(TerrainTerm::river_near)[i] = to_river.empty() ? 0.0f : float(std::exp(-double(to_river[i]) / 2000.0));
      }
  });
  if (whole && !whole->ranks) return;
  for (std::size_t k = 0; k < kRankedTerms.size(); ++k) {
    Raster<float>& values = term(kRankedTerms[k]);
    std::optional<LandRanks> own;  // 4 MB: only on the whole grid
    if (!whole) own.emplace().add(values.data(), values.size()), own->finish();
    const LandRanks& ranks = whole ? (*whole->ranks)[k] : *own;
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, values.size(), 1 << 14), [&](const tbb::blocked_range<std::size_t>& range) {
      for (std::size_t i = range.begin(); i < range.end(); ++i) values[i] = ranks.rank(values[i]);
    });
  }
}

/// The boosted trees' density of every habitable cell of the core, in [0,1] (NaN elsewhere).
std::vector<float> boosted_density(const Dem& dem, const Grid& g, const BoostedModel& model, const DensityResult& result) {
  const auto names = term_names();
  std::vector<std::size_t> columns;
  for (const std::string& t : model.terms()) {
    const auto at = std::find_if(names.begin(), names.end(), [&](const char* n) { return t == n; });
    if (at == names.end()) throw bad_input("/density/model: unknown term '" + t + "'");
    columns.push_back(std::size_t(at - names.begin()));
  }
  std::vector<std::size_t> cells;
  for (int r = g.core.y0; r < g.core.y0 + g.core.rows; ++r)
    for (int x = g.core.x0; x < g.core.x0 + g.core.cols; ++x)
      if (const std::size_t i = dem.index(x, r); g.kind[i] != unknown && result.buildable[i] == 1) cells.push_back(i);
  std::vector<float> rows(cells.size() * columns.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, cells.size(), 4096), [&](const tbb::blocked_range<std::size_t>& range) {
    for (std::size_t k = range.begin(); k < range.end(); ++k) {
      const Terms t = terms_at(result, cells[k]);
      for (std::size_t j = 0; j < columns.size(); ++j) rows[k * columns.size() + j] = float(t[columns[j]]);
    }
  });
  const std::vector<float> margins = model.margins(rows);
  std::vector<float> unit(dem.size(), nan_f);
  for (std::size_t k = 0; k < cells.size(); ++k) unit[cells[k]] = float(std::clamp(model.unit(margins[k]), 0.0, 1.0));
  return unit;
}

/// The density (§4.2.1, Fig. 4.3): the weighted combination of the characteristics, the user's
/// factors and the terrain terms on habitable cells, 0 elsewhere on known ground.
void combine_terms(const Dem& dem, const Grid& g, const DensityOptions& options, DensityResult& result, Progress& progress) {
  result.density = dem.like<float>(nan_f);
  ProgressStep step(progress, "density: combine");
  // With boosted trees, their density is the one term before the factors (weight 1).
  const std::vector<float> boosted = options.model ? boosted_density(dem, g, *options.model, result) : std::vector<float>();
  std::vector<double> weights(options.weights.begin(), options.weights.end());
  if (options.model) weights = {1};
  const std::size_t first_factor = weights.size();
  for (const auto& f : options.factors) weights.push_back(f.weight);
  const std::size_t first_terrain = first_factor + options.factors.size();
  // The terrain terms come last, and only when used: the thesis's model sums exactly what it always did.
  const bool with_terrain = terrain_used(options) && !options.model;
  if (with_terrain) weights.insert(weights.end(), options.terrain_weights.begin(), options.terrain_weights.end());
  for_rows(g.core.rows, step, [&](int r0, int r1) {
    std::vector<double> values(weights.size()), cell_weights(weights);
    for (int r = r0 + g.core.y0; r < r1 + g.core.y0; ++r)
      for (int x = g.core.x0; x < g.core.x0 + g.core.cols; ++x) {
        const std::size_t i = dem.index(x, r);
        if (g.kind[i] == unknown) continue;
        if (result.buildable[i] != 1) {
          result.density[i] = 0;
          continue;
        }
        if (options.model) {
          values[0] = boosted[i];
        } else {
          values[0] = result.coast[i];
          values[1] = result.hydrometry[i];
          values[2] = result.plateau[i];
          values[3] = result.plain[i];
        }
        // A factor with no value here (NaN) takes no part in this cell's combination.
        for (std::size_t f = 0; f < options.factors.size(); ++f) {
          const float v = options.factors[f].values[i];
          values[first_factor + f] = std::isnan(v) ? 0.0 : std::clamp(double(v), 0.0, 1.0);
          cell_weights[first_factor + f] = std::isnan(v) ? 0.0 : weights[first_factor + f];
        }
        if (with_terrain)
          for (std::size_t t = 0; t < kTerrainCount; ++t) values[first_terrain + t] = result.terrain[t][i];
        const bool any = std::any_of(cell_weights.begin(), cell_weights.end(), [](double w) { return w != 0; });
        result.density[i] = any ? float(combine(cell_weights.data(), values.data(), cell_weights.size())) : 0.0f;
      }
  });
}

/// Report figures: per-row partial sums added in row order (deterministic).
void gather_stats(const Dem& dem, const Grid& g, DensityResult& result) {
  DensityStats& stats = result.stats;
  const auto nrows = static_cast<std::size_t>(g.rows);
  std::vector<DensityStats> per_row(nrows);
  std::vector<double> row_sum(nrows, 0.0);
  tbb::parallel_for(tbb::blocked_range<int>(g.core.y0, g.core.y0 + g.core.rows, 8), [&](const tbb::blocked_range<int>& range) {
    for (int r = range.begin(); r < range.end(); ++r) {
      DensityStats& t = per_row[std::size_t(r)];
      for (int x = g.core.x0; x < g.core.x0 + g.core.cols; ++x) {
        const std::size_t i = dem.index(x, r);
        if (g.kind[i] != unknown) ++t.known_cells;
        if (g.kind[i] == water) ++t.water_cells;
        if (g.kind[i] == land) t.land_area_km2 += g.metrics.area_m2[std::size_t(r)] * 1e-6;
        if (result.buildable[i] == 1) {
          ++t.buildable_cells;
          row_sum[std::size_t(r)] += result.density[i];
          ++t.histogram[std::size_t(std::min(9, int(result.density[i] * 10)))];
        }
      }
    }
  });
  double sum = 0;
  for (std::size_t r = 0; r < nrows; ++r) {
    const DensityStats& t = per_row[r];
    stats.known_cells += t.known_cells;
    stats.water_cells += t.water_cells;
    stats.buildable_cells += t.buildable_cells;
    stats.land_area_km2 += t.land_area_km2;
    for (std::size_t k = 0; k < 10; ++k) stats.histogram[k] += t.histogram[k];
    sum += row_sum[r];
  }
  stats.density_sum = sum;
  stats.mean_density = stats.buildable_cells ? sum / double(stats.buildable_cells) : 0.0;
}

}  // namespace

namespace {

/// The model on `grid` once its masks are known, with the discs of the whole grid and, on a
/// window, the whole grid's coast and plateau maxima and terrain figures.
void characteristics(const Dem& dem, const Grid& grid, const DiscPlan& inner, const DiscPlan& outer, double r_min,
                     const std::optional<std::array<float, 2>>& maxima, const WholeTerrainFigures* terrain, const DensityOptions& options,
                     DensityResult& result, Progress& progress) {
  result.stats.r_min_m = r_min;
  result.stats.r_max_m = options.r_max_m;
  result.stats.ring_bands = std::max(inner.band_count(), outer.band_count());
  result.stats.ring_exact = inner.exact() && outer.exact();
  const Window win = disc_window(grid, inner, outer);
  result.plain = plain_characteristic(dem, grid, inner, win, options.plain_max_variation_m, progress);
  ring_shares(dem, grid, inner, outer, win, options, maxima, result, progress);
  if (needs_terrain_terms(options)) terrain_terms(dem, grid, options, terrain, result, progress);
  if (terrain && !terrain->ranks) return;  // the tiles' first pass: the terms are not ranked yet, no density
  combine_terms(dem, grid, options, result, progress);
  gather_stats(dem, grid, result);
}

}  // namespace

DensityResult compute_density(const Dem& dem, const Raster<float>& hydrometry, const DensityOptions& options, Progress& progress) {
  check_options(dem, hydrometry, options);
  const Grid grid = describe_grid(dem, options, cell_metrics(dem.georef(), dem.cols(), dem.rows()));
  DensityResult result;
  result.stats.cells = dem.size();
  mark_buildable(dem, grid, hydrometry, options, result, progress);

  // The plain disc must hold at least the 4-neighbours: raise r_min to the largest cell step.
  const double r_min = raised_r_min(grid.metrics, options);
  const DiscPlan inner(grid.metrics, grid.rows, r_min, options.ring_bands);
  const DiscPlan outer(grid.metrics, grid.rows, options.r_max_m, options.ring_bands);
  characteristics(dem, grid, inner, outer, r_min, std::nullopt, nullptr, options, result, progress);
  return result;
}

double raised_r_min(const CellMetrics& metrics, const DensityOptions& options) {
  const double r_min = std::max(options.r_min_m, largest_cell_step(metrics) * (1 + 1e-9));
  if (!(options.r_max_m > r_min))
    throw bad_input("/density/r_max_m: must be larger than r_min (" + std::to_string(r_min) + " m once raised to the cell size)");
  return r_min;
}

std::array<DiscPlan, 2> position_discs(const CellMetrics& metrics, int rows, int max_bands) {
  // Radii of at least two cells, so that the disc holds the neighbours on coarse grids.
  const double largest_step = largest_cell_step(metrics);
  return {DiscPlan(metrics, rows, std::max(1000.0, 2 * largest_step), max_bands), DiscPlan(metrics, rows, std::max(5000.0, 2 * largest_step), max_bands)};
}

bool needs_terrain_terms(const DensityOptions& options) { return terrain_used(options) || options.terrain_terms || options.model; }

std::vector<std::uint8_t> water_cells(const Dem& dem, const DensityOptions& options) {
  std::vector<std::uint8_t> wet = cell_kinds(dem, options);
  for (std::uint8_t& k : wet) k = k == water;
  return wet;
}

std::vector<std::uint8_t> land_cells(const Dem& dem, const DensityOptions& options) {
  std::vector<std::uint8_t> cells = cell_kinds(dem, options);
  for (std::uint8_t& k : cells) k = k == land;
  return cells;
}

std::vector<std::uint8_t> river_mask(const Raster<std::uint8_t>& rivers) {
  std::vector<std::uint8_t> mask(rivers.size());
  for (std::size_t i = 0; i < mask.size(); ++i) mask[i] = rivers[i] != 0 && rivers[i] != rivers.nodata;
  return mask;
}

std::array<float, 2> land_range(const Dem& dem, const DensityOptions& options) {
  const std::vector<std::uint8_t> kind = cell_kinds(dem, options);
  std::array<float, 2> range{std::numeric_limits<float>::infinity(), -std::numeric_limits<float>::infinity()};
  for (std::size_t i = 0; i < kind.size(); ++i)
    if (kind[i] == land) range[0] = std::min(range[0], dem[i]), range[1] = std::max(range[1], dem[i]);
  return range;
}

DensityResult compute_density_window(const Dem& dem, const Raster<float>& hydrometry, const DensityOptions& options,
                                     const WholeGridFigures& whole, Progress& progress) {
  check_options(dem, hydrometry, options);
  if (needs_terrain_terms(options) && !whole.terrain)
    throw processing_error("density: a window's terrain terms need the whole grid's figures");
  Grid grid = describe_grid(dem, options, whole.metrics);
  grid.core = whole.core;
  grid.land_min = whole.land_range[0], grid.land_max = whole.land_range[1];
  DensityResult result;
  result.stats.cells = std::size_t(whole.core.cols) * std::size_t(whole.core.rows);
  mark_buildable(dem, grid, hydrometry, options, result, progress);
  characteristics(dem, grid, whole.inner, whole.outer, whole.r_min_m, whole.maxima, whole.terrain ? &*whole.terrain : nullptr, options, result,
                  progress);
  return result;
}

void ValueRange::add(const Raster<float>& values) {
  for (std::size_t i = 0; i < values.size(); ++i)
    if (!std::isnan(values[i])) lo = std::min(lo, values[i]), hi = std::max(hi, values[i]);
}

void to_unit_range(Raster<float>& layer, const ValueRange& range) {
  const float lo = range.lo, hi = range.hi;
  const bool rescale = lo < 0 || hi > 1;
  for (std::size_t i = 0; i < layer.size(); ++i) {
    float& v = layer[i];
    if (std::isnan(v)) v = 0;
    else if (rescale) v = hi > lo ? (v - lo) / (hi - lo) : 0.0f;
  }
}

void to_unit_range(Raster<float>& layer) {
  ValueRange range;
  range.add(layer);
  to_unit_range(layer, range);
}

}  // namespace terrapolis::density
