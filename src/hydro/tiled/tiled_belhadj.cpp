// Belhadj's hydrometry tile by tile (see tiled_belhadj.hpp): the land range, the search for the
// stop, the tiles' Acc, their rescale.
// SPDX-License-Identifier: MIT
#include "hydro/tiled/tiled_belhadj.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <vector>

#include "core/error.hpp"
#include "core/geodesy.hpp"
#include "hydro/tiled/tiled_hydro.hpp"

namespace terrapolis::hydro::tiled {
namespace {

/// Acc kept between the last two passes (>= 0); NaN on nodata, this on the sea.
constexpr double kSea = -1;

/// The first pass's halo; each further search for the stop doubles it.
constexpr int kFirstSteps = 32;

/// The state a cell of a tile depends on after `steps` steps lies within steps + 2 cells.
int halo_for(int steps) { return steps + 2; }

std::string acc_file(const std::string& dir, int tile) { return dir + "/belhadj_acc_" + std::to_string(tile) + ".bin"; }

int belhadj_tile_size_for(int cols, int rows, int halo, double memory_limit_mb, double reserved_mb) {
  return largest_tile_side(
      [&](int side) {  // a window and the whole grid's metrics
        return kBelhadjBytesPerCell * double(std::min(side, cols) + 2 * halo) * double(std::min(side, rows) + 2 * halo) + 64.0 * rows;
      },
      memory_limit_mb, reserved_mb, "hydrometry tiles of 64 x 64 cells with a halo of " + std::to_string(halo) + " cells (Belhadj's iterations)");
}

}  // namespace

TiledBelhadjReport run_tiled_belhadj(int cols, int rows, const Georef& georef, const ReadWindow& read, const BelhadjOptions& options,
                                     int tile_size, double memory_limit_mb, const std::string& scratch_dir,
                                     const WriteHydrometryTile& write, Progress& progress, double reserved_mb) {
  if (options.max_iterations < 0) throw bad_input("/hydro/iterations: must be 0 (until convergence) or positive");
  if (!(options.threshold > 0)) throw bad_input("/hydro/threshold: must be a positive number");
  TiledBelhadjReport report;
  const int limit = belhadj_iteration_limit(options);
  report.tile_size = tile_size > 0 ? std::max(tile_size, 8) : belhadj_tile_size_for(cols, rows, halo_for(limit), memory_limit_mb, reserved_mb);
  const TileGrid grid(cols, rows, report.tile_size);
  report.tiles = grid.count();
  report.across = grid.across();
  // Cell steps and areas from the whole grid's rows: a window's own metrics may differ in the last bit.
  const CellMetrics metrics = cell_metrics(georef, cols, rows);

  // 1. The land's altitude range, which places the outside cells below every cell.
  std::array<double, 2> range{INFINITY, -INFINITY};
  {
    ProgressStep step(progress, "hydrometry by tiles: altitudes");
    for (int t = 0; t < grid.count(); ++t) {
      const TileRect r = grid.rect(t);
      const std::array<double, 2> tile = belhadj_land_range(read(r.col0, r.row0, r.cols, r.rows), options.sea_level);
      range = {std::min(range[0], tile[0]), std::max(range[1], tile[1])};
      step.update(double(t + 1) / grid.count());
    }
  }
  if (!(range[0] <= range[1])) throw bad_input("hydrometry: the DEM has no land cell (all nodata or below sea level)");

  // Runs `steps` steps on tile t and its halo, calling each(model, window, core, step) before every
  // step (the quantities the step starts from) and after the last.
  auto on_tile = [&](int t, int steps, auto&& each) {
    const TileRect r = grid.rect(t), w = grid.grown(t, halo_for(steps), halo_for(steps));
    report.window_bytes = std::max(report.window_bytes, kBelhadjBytesPerCell * double(w.cols) * double(w.rows));
    const Dem window = read(w.col0, w.row0, w.cols, w.rows);
    BelhadjModel model(window, metric_rows(metrics, w.row0, w.rows), options.vertical, options.sea_level, options.share, range);
    const TileRect core{r.col0 - w.col0, r.row0 - w.row0, r.cols, r.rows};
    for (int k = 0; k < steps; ++k) {
      each(model, window, core, k);
      model.step();
    }
    each(model, window, core, steps);
  };

  // 2. The stop: each tile's quantities at the start of each step, summed over the whole grid.
  std::size_t valid = 0;
  for (int steps = std::min(limit, kFirstSteps);; steps = std::min(limit, 2 * steps)) {
    ++report.searches;
    std::vector<double> sums(std::size_t(steps), 0.0);
    valid = 0;
    ProgressStep step(progress, "hydrometry by tiles: iterations (up to " + std::to_string(steps) + ")");
    for (int t = 0; t < grid.count(); ++t) {
      on_tile(t, steps, [&](const BelhadjModel& model, const Dem&, const TileRect& core, int k) {
        if (k == steps) return;
        double sum = 0;
        for (int y = core.row0; y < core.row0 + core.rows; ++y)
          for (int x = core.col0; x < core.col0 + core.cols; ++x)
            if (model.valid(x, y)) {
              sum += model.q(x, y);
              valid += k == 0;
            }
        sums[std::size_t(k)] += sum;
      });
      step.update(double(t + 1) / grid.count());
    }
    for (int k = 0; k < steps && report.iterations == 0; ++k)
      if (const double mean = sums[std::size_t(k)] / double(valid); belhadj_stops(options, k + 1, mean)) {
        report.iterations = k + 1;
        report.final_mean = mean;
      }
    if (report.iterations > 0) break;
  }
  report.halo = halo_for(report.iterations);

  // 3. Each tile's Acc after the whole grid's iterations, kept on disk, and the range of Acc.
  std::filesystem::create_directories(scratch_dir);
  double lo = INFINITY, hi = -INFINITY;
  {
    ProgressStep step(progress, "hydrometry by tiles");
    for (int t = 0; t < grid.count(); ++t) {
      std::vector<double> acc;
      on_tile(t, report.iterations, [&](const BelhadjModel& model, const Dem& window, const TileRect& core, int k) {
        if (k < report.iterations) return;
        acc.reserve(std::size_t(core.cols) * std::size_t(core.rows));
        for (int y = core.row0; y < core.row0 + core.rows; ++y)
          for (int x = core.col0; x < core.col0 + core.cols; ++x) {
            if (model.valid(x, y)) {
              lo = std::min(lo, model.acc(x, y));
              hi = std::max(hi, model.acc(x, y));
              acc.push_back(model.acc(x, y));
            } else {
              acc.push_back(std::isnan(window(x, y)) ? NAN : kSea);
            }
          }
      });
      std::ofstream out(acc_file(scratch_dir, t), std::ios::binary);
      out.write(reinterpret_cast<const char*>(acc.data()), std::streamsize(acc.size() * sizeof(double)));
      if (!out.flush()) throw processing_error(scratch_dir + ": cannot keep the hydrometry's tiles (disk full?)");
      step.update(double(t + 1) / grid.count());
    }
  }

  // 4. Rescaled by the whole grid's range: NaN on nodata, 0 on the sea, as the whole grid.
  for (int t = 0; t < grid.count(); ++t) {
    const TileRect r = grid.rect(t);
    std::vector<double> acc(std::size_t(r.cols) * std::size_t(r.rows));
    {
      std::ifstream in(acc_file(scratch_dir, t), std::ios::binary);
      if (!in.read(reinterpret_cast<char*>(acc.data()), std::streamsize(acc.size() * sizeof(double))))
        throw processing_error(scratch_dir + ": the hydrometry's tile " + std::to_string(t) + " was not read back");
    }
    std::filesystem::remove(acc_file(scratch_dir, t));
    Raster<float> out(r.cols, r.rows, shifted(georef, r.col0, r.row0));
    for (std::size_t i = 0; i < acc.size(); ++i) out[i] = std::isnan(acc[i]) ? NAN : acc[i] < 0 ? 0.0f : belhadj_rescale(acc[i], lo, hi);
    write(t, grid.across(), out);
  }
  return report;
}

}  // namespace terrapolis::hydro::tiled
