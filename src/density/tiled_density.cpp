// The density model tile by tile: three passes over the mosaic, one tile and its halo at a time.
// SPDX-License-Identifier: MIT
#include "density/tiled_density.hpp"

#include <algorithm>
#include <functional>
#include <memory>
#include <cmath>
#include <string>

#include "core/error.hpp"
#include "hydro/tiled/tiled_hydro.hpp"

namespace terrapolis::density {
namespace {

using hydro::tiled::TileGrid;
using hydro::tiled::TileRect;

/// Reach of the discs of `plan` around the cells of rows [row0, row0 + rows): rows and columns.
/// On a geographic grid the columns follow the latitude (a disc is wider in columns poleward).
std::array<int, 2> reach_of_rows(const DiscPlan& plan, int row0, int rows) {
  std::array<int, 2> reach{0, 0};
  for (int r = row0; r < row0 + rows; ++r)
    for (const Band& b : plan.bands(r)) reach = {std::max({reach[0], -b.row_lo, b.row_hi}), std::max(reach[1], b.half_cols)};
  return reach;
}

/// Adds a tile's figures to the mosaic's (counts exactly; areas and the density sum in tile order).
void add_stats(DensityStats& total, const DensityStats& tile) {
  total.cells += tile.cells;
  total.known_cells += tile.known_cells;
  total.water_cells += tile.water_cells;
  total.buildable_cells += tile.buildable_cells;
  for (std::size_t k = 0; k < total.histogram.size(); ++k) total.histogram[k] += tile.histogram[k];
  total.land_area_km2 += tile.land_area_km2;
  total.density_sum += tile.density_sum;
}

double plan_bytes(const DiscPlan& plan, int rows) {
  double bytes = 0;
  for (int r = 0; r < rows; ++r) bytes += double(sizeof(std::vector<Band>)) + double(plan.bands(r).size() * sizeof(Band));
  return bytes;
}

/// The distances to the water (feature 0) and the rivers (1, none when not given), by bands of
/// full rows (DistanceStrips); `also` sees each band read.
std::unique_ptr<DistanceStrips> whole_grid_distances(const CellMetrics& metrics, int cols, int rows, const ReadWindowInputs& read,
                                                     const std::function<void(const WindowInputs&)>& also, const std::string& scratch_dir,
                                                     double budget_bytes, Progress& progress) {
  return std::make_unique<DistanceStrips>(
      metrics, cols, rows, 2, scratch_dir, budget_bytes,
      [&](int r0, int n) {
        const WindowInputs in = read(0, r0, cols, n, true);
        also(in);
        const bool rivers = in.options.rivers.size() == in.dem.size();
        return std::vector<std::vector<std::uint8_t>>{water_cells(in.dem, in.options),
                                                       rivers ? river_mask(in.options.rivers) : std::vector<std::uint8_t>(in.dem.size(), 0)};
      },
      progress);
}

}  // namespace

int density_tile_size_for(int cols, int rows, int halo_rows, int halo_cols, double global_bytes, double memory_limit_mb, double reserved_mb,
                          double cell_bytes) {
  return hydro::tiled::largest_tile_side(
      [&](int side) {
        return cell_bytes * double(std::min(side, rows) + 2 * halo_rows) * double(std::min(side, cols) + 2 * halo_cols) + global_bytes;
      },
      memory_limit_mb, reserved_mb,
      "density tiles of 64 x 64 cells with a halo of " + std::to_string(halo_cols) + " x " + std::to_string(halo_rows) + " cells (the discs' reach)");
}

TiledDensityReport run_tiled_density(int cols, int rows, const Georef& georef, const ReadWindowInputs& read,
                                     const DensityOptions& options, int tile_size, double memory_limit_mb, const std::string& scratch_dir,
                                     const WriteDensityTile& write, Progress& progress, double reserved_mb,
                                     double input_bytes_per_cell) {
  TiledDensityReport report;
  const CellMetrics metrics = cell_metrics(georef, cols, rows);
  const double r_min = raised_r_min(metrics, options);
  // The discs are planned once on the whole grid: a plan depends on the northings summed from the
  // grid's first row, which a window would sum from its own.
  const DiscPlan inner(metrics, rows, r_min, options.ring_bands), outer(metrics, rows, options.r_max_m, options.ring_bands);
  report.global_bytes = plan_bytes(inner, rows) + plan_bytes(outer, rows) + 4.0 * sizeof(double) * rows;
  // The terrain terms' discs, and their ranks counted over the whole grid.
  const bool terms = needs_terrain_terms(options);
  const std::array<DiscPlan, 2> positions = terms ? position_discs(metrics, rows, options.ring_bands) : std::array<DiscPlan, 2>{};
  if (terms) report.global_bytes += plan_bytes(positions[0], rows) + plan_bytes(positions[1], rows) + double(kRankedTerms.size()) * LandRanks::kBytes;
  // A ring cell's plain needs the r_min disc around it: the halo is the two reaches (or the
  // positions' wider disc).
  auto halo_of = [&](int row0, int n) {
    const std::array<int, 2> ring = reach_of_rows(outer, row0, n);
    std::array<int, 2> halo{ring[0] + inner.reach_rows(), ring[1] + inner.reach_cols()};
    if (terms) {
      const std::array<int, 2> far = reach_of_rows(positions[1], row0, n);
      halo = {std::max(halo[0], far[0]), std::max(halo[1], far[1])};
    }
    return halo;
  };
  std::array<int, 2> widest = {outer.reach_rows() + inner.reach_rows(), outer.reach_cols() + inner.reach_cols()};
  if (terms) widest = {std::max(widest[0], positions[1].reach_rows()), std::max(widest[1], positions[1].reach_cols())};
  const double cell_bytes =
      kDensityBytesPerCell + (terms ? kTerrainBytesPerCell : 0) + (options.model ? kBoostedBytesPerCell : 0) + input_bytes_per_cell;
  report.tile_size = tile_size > 0 ? std::max(tile_size, 8)
                                   : density_tile_size_for(cols, rows, widest[0], widest[1], report.global_bytes, memory_limit_mb, reserved_mb, cell_bytes);
  const TileGrid grid(cols, rows, report.tile_size);
  report.tiles = grid.count();
  report.across = grid.across();
  SilentProgress quiet;  // per-tile steps would flood the console: one step per pass instead

  // 1. The land's altitude range (the plain's sums are taken relative to its middle): by tiles, or,
  // with the terrain terms, on the bands the distances to water and rivers read over the whole
  // grid (in a budget of a tile's window when no limit is given).
  std::array<float, 2> range{std::numeric_limits<float>::infinity(), -std::numeric_limits<float>::infinity()};
  const auto add_range = [&](const WindowInputs& in) {
    const std::array<float, 2> part = land_range(in.dem, in.options);
    range = {std::min(range[0], part[0]), std::max(range[1], part[1])};
  };
  std::unique_ptr<DistanceStrips> distances;
  std::optional<std::array<LandRanks, kRankedTerms.size()>> ranks;  // 4 MB each: only with the terms
  if (terms) {
    ranks.emplace();
    const double side = report.tile_size + 2.0 * std::max(widest[0], widest[1]);
    const double budget = memory_limit_mb > 0 ? (memory_limit_mb - reserved_mb) * 1e6 - report.global_bytes : cell_bytes * side * side;
    distances = whole_grid_distances(metrics, cols, rows, read, add_range, scratch_dir, budget, progress);
  } else {
    ProgressStep step(progress, "density by tiles: altitudes");
    for (int t = 0; t < grid.count(); ++t) {
      const TileRect r = grid.rect(t);
      add_range(read(r.col0, r.row0, r.cols, r.rows, true));
      step.update(double(t + 1) / grid.count());
    }
  }
  // 2. The coast and plateau maxima over habitable land (and the land ranks' counts), then 3. each
  // tile divided by them.
  auto pass = [&](const char* what, const std::optional<std::array<float, 2>>& maxima, auto&& use) {
    ProgressStep step(progress, what);
    for (int t = 0; t < grid.count(); ++t) {
      const TileRect r = grid.rect(t);
      const std::array<int, 2> halo = halo_of(r.row0, r.rows);
      const TileRect w = grid.grown(t, halo[1], halo[0]);
      const int c0 = w.col0, r0 = w.row0, c1 = w.col0 + w.cols, r1 = w.row0 + w.rows;
      report.halo_rows = std::max(report.halo_rows, halo[0]);
      report.halo_cols = std::max(report.halo_cols, halo[1]);
      report.window_bytes = std::max(report.window_bytes, cell_bytes * double(c1 - c0) * double(r1 - r0));
      WindowInputs in = read(c0, r0, c1 - c0, r1 - r0, false);
      WholeGridFigures whole{metric_rows(metrics, r0, r1 - r0), range, r_min, inner.from_row(r0), outer.from_row(r0),
                             Window{r.col0 - c0, r.row0 - r0, r.cols, r.rows}, maxima, std::nullopt};
      if (terms) {
        WholeTerrainFigures& t = whole.terrain.emplace();
        t.near = positions[0].from_row(r0), t.far = positions[1].from_row(r0);
        if (distances->any(0)) t.to_water = distances->window(0, c0, r0, c1 - c0, r1 - r0);
        if (distances->any(1)) t.to_river = distances->window(1, c0, r0, c1 - c0, r1 - r0);
        if (maxima) t.ranks = &*ranks;
      }
      use(t, compute_density_window(in.dem, in.hydrometry, in.options, whole, quiet), whole.core);
      step.update(double(t + 1) / grid.count());
    }
  };
  std::array<float, 2> maxima{0, 0};
  pass("density by tiles: coast and plateau maxima", std::nullopt, [&](int, const DensityResult& d, const Window&) {
    maxima = {std::max(maxima[0], d.stats.coast_max), std::max(maxima[1], d.stats.plateau_max)};
    if (terms)
      for (std::size_t k = 0; k < kRankedTerms.size(); ++k) {
        const Raster<float>& values = d.term(kRankedTerms[k]);
        (*ranks)[k].add(values.data(), values.size());  // NaN off the core's land
      }
  });
  if (terms)
    for (LandRanks& r : *ranks) r.finish();
  DensityStats& stats = report.stats;
  pass("density by tiles", maxima, [&](int t, const DensityResult& d, const Window& core) {
    DensityResult tile;
    tile.coast = hydro::tiled::crop(d.coast, core.x0, core.y0, core.cols, core.rows);
    tile.plateau = hydro::tiled::crop(d.plateau, core.x0, core.y0, core.cols, core.rows);
    tile.plain = hydro::tiled::crop(d.plain, core.x0, core.y0, core.cols, core.rows);
    tile.hydrometry = hydro::tiled::crop(d.hydrometry, core.x0, core.y0, core.cols, core.rows);
    tile.density = hydro::tiled::crop(d.density, core.x0, core.y0, core.cols, core.rows);
    tile.buildable = hydro::tiled::crop(d.buildable, core.x0, core.y0, core.cols, core.rows);
    for (std::size_t k = 0; k < kTerrainCount; ++k)
      if (d.terrain[k].size()) tile.terrain[k] = hydro::tiled::crop(d.terrain[k], core.x0, core.y0, core.cols, core.rows);
    tile.stats = d.stats;
    add_stats(stats, d.stats);
    write(t, grid.across(), tile);
  });
  stats.mean_density = stats.buildable_cells ? stats.density_sum / double(stats.buildable_cells) : 0.0;
  stats.r_min_m = r_min;
  stats.r_max_m = options.r_max_m;
  stats.ring_bands = std::max(inner.band_count(), outer.band_count());
  stats.ring_exact = inner.exact() && outer.exact();
  stats.coast_max = maxima[0];
  stats.plateau_max = maxima[1];
  return report;
}

}  // namespace terrapolis::density
