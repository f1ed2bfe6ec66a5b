// Small helpers shared by the hydrology kernels: which cells are outlets, neighbour offsets.
// SPDX-License-Identifier: MIT
#pragma once
#include <cmath>
#include <cstdint>
#include <optional>

#include "core/neighbours.hpp"
#include "core/raster.hpp"

namespace terrapolis::hydro {

/// D8 receiver codes used in memory (not in files): 0..7 is the neighbours.hpp index,
/// `kTerminal` a cell that keeps its water (pit left unfilled, sea cell), `kNoData` a nodata cell.
inline constexpr std::uint8_t kTerminal = 8;
inline constexpr std::uint8_t kNoData = 255;

/// True when `z` is a sea cell under `sea_level` (cells at or below it are outlets).
inline bool is_sea(float z, const std::optional<double>& sea_level) { return sea_level && double(z) <= *sea_level; }

/// True when a valid cell touches the outside of the DEM: the grid border or a nodata neighbour.
/// Such cells are outlets: water may leave the grid through them (Barnes et al. 2014).
inline bool touches_outside(const Dem& dem, int col, int row) {
  if (col == 0 || row == 0 || col == dem.cols() - 1 || row == dem.rows() - 1) return true;
  for (int k = 0; k < 8; ++k)
    if (std::isnan(dem(col + dcol[k], row + drow[k]))) return true;
  return false;
}

/// Index offset of neighbour k in a row-major grid of `cols` columns.
inline std::ptrdiff_t neighbour_offset(int cols, int k) { return std::ptrdiff_t(drow[k]) * cols + dcol[k]; }

}  // namespace terrapolis::hydro
