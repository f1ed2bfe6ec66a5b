// Belhadj's hydrometry (thesis 2007, §4.2.2, Algorithm 12) tile by tile: the whole grid's cells
// bit for bit, in memory bounded by one tile and its halo (docs/scale.md).
// SPDX-License-Identifier: MIT
#pragma once
#include <functional>
#include <string>

#include "core/progress.hpp"
#include "core/raster.hpp"
#include "hydro/belhadj_hydrometry.hpp"
#include "hydro/tiled/tiled_hydro.hpp"

namespace terrapolis::hydro::tiled {

/// Receives each tile's hydrometry (on the tile's grid); tiles are numbered row-major, `across` a row of tiles.
using WriteHydrometryTile = std::function<void(int tile, int across, const Raster<float>& hydrometry)>;

struct TiledBelhadjReport {
  int tile_size = 0, tiles = 0, across = 0;
  int iterations = 0;     ///< the whole grid's iterations
  double final_mean = 0;  ///< the mean quantity that stopped it
  int searches = 0;       ///< passes that looked for the stop (their halo doubling)
  int halo = 0;           ///< the last pass's halo, cells
  double window_bytes = 0;
};

/// State per cell of a window: the model's ten padded doubles, the DEM, the tile's Acc.
inline constexpr double kBelhadjBytesPerCell = 96;

/// belhadj_hydrometry of a cols x rows mosaic, tile by tile (tiles of `tile_size`, 0: sized to
/// `memory_limit_mb` less `reserved_mb`). A cell's state after t steps depends on the cells within
/// t + 2 of it only (its neighbours' previous state, their neighbours' altitudes), so a tile computed
/// with a halo of t + 2 cells is exact. The stop is global (the mean quantity over the whole grid):
/// passes of 32, 64, 128... steps (each tile with a halo of the steps + 2) sum each tile's quantities
/// until one step's mean falls under the threshold; the last pass runs that many steps and keeps each
/// tile's Acc in `scratch_dir` (8 bytes a cell, removed on return; on an error, with the caller's
/// scratch folder), then rescales them by the whole grid's range. The stop test
/// sums the quantities tile by tile, the whole grid row by row: the two means may differ in their
/// last bit, which changes the iterations only when a mean lies that close to the threshold.
TiledBelhadjReport run_tiled_belhadj(int cols, int rows, const Georef& georef, const ReadWindow& read, const BelhadjOptions& options,
                                     int tile_size, double memory_limit_mb, const std::string& scratch_dir,
                                     const WriteHydrometryTile& write, Progress& progress, double reserved_mb = 0);

}  // namespace terrapolis::hydro::tiled
