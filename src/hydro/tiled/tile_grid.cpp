// The mosaic cut into tiles, tile sizes from a memory limit, the threads a run may use.
// SPDX-License-Identifier: MIT
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "core/error.hpp"
#include "hydro/tiled/tiled_hydro.hpp"

namespace terrapolis::hydro::tiled {
namespace {

std::vector<int> bounds(int n, int tile_size) {
  const int parts = std::max(1, (n + tile_size - 1) / tile_size);
  std::vector<int> b(std::size_t(parts) + 1);
  for (int i = 0; i <= parts; ++i) b[std::size_t(i)] = int(std::int64_t(n) * i / parts);
  return b;
}

}  // namespace

Georef shifted(const Georef& g, int col0, int row0) {
  Georef out = g;
  const GeoTransform& t = g.transform;
  out.transform[0] = t[0] + col0 * t[1] + row0 * t[2];
  out.transform[3] = t[3] + col0 * t[4] + row0 * t[5];
  return out;
}

TileGrid::TileGrid(int cols, int rows, int tile_size)
    : col_bounds_(bounds(cols, std::max(tile_size, 8))), row_bounds_(bounds(rows, std::max(tile_size, 8))) {}

TileRect TileGrid::rect(int tile) const {
  const int i = tile % across(), j = tile / across();
  return {col_bounds_[std::size_t(i)], row_bounds_[std::size_t(j)], col_bounds_[std::size_t(i) + 1] - col_bounds_[std::size_t(i)],
          row_bounds_[std::size_t(j) + 1] - row_bounds_[std::size_t(j)]};
}

TileRect TileGrid::grown(int tile, int halo_cols, int halo_rows) const {
  const TileRect r = rect(tile);
  const int c0 = std::max(0, r.col0 - halo_cols), r0 = std::max(0, r.row0 - halo_rows);
  return {c0, r0, std::min(cols(), r.col0 + r.cols + halo_cols) - c0, std::min(rows(), r.row0 + r.rows + halo_rows) - r0};
}

int TileGrid::tile_of(int col, int row) const {
  const int i = int(std::upper_bound(col_bounds_.begin(), col_bounds_.end(), col) - col_bounds_.begin()) - 1;
  const int j = int(std::upper_bound(row_bounds_.begin(), row_bounds_.end(), row) - row_bounds_.begin()) - 1;
  return j * across() + i;
}

namespace {
/// Global state per tile and cell of its side, at worst (every edge cell its own label): frames
/// (two rings: float + label, 64), exits of the edge cells (32), labels (4 a side, 12 bytes each:
/// 48) and their spill edges (about 4 a label, 28 bytes each in list and adjacency: 448).
constexpr double kGlobalBytesPerTileSide = 600;
}  // namespace

int allowed_threads() {
  return int(tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism));
}

std::string too_little(double memory_limit_mb, double reserved_mb) {
  std::string held;
  if (reserved_mb > 0) held = " (" + std::to_string(int(std::ceil(reserved_mb))) + " MB of it held by the process and the mosaic's reader)";
  return "/input/memory_limit_mb: " + std::to_string(int(memory_limit_mb)) + " MB" + held + " is too little";
}

int largest_tile_side(const std::function<double(int side)>& bytes, double memory_limit_mb, double reserved_mb, const std::string& what) {
  const double limit = (memory_limit_mb - reserved_mb) * 1e6;
  for (int side = 1 << 15; side >= 64; side = side * 7 / 8)
    if (bytes(side) <= limit) return side;
  throw bad_input(too_little(memory_limit_mb, reserved_mb) + " for " + what);
}

int tile_size_for(int cols, int rows, double memory_limit_mb, int concurrent, double reserved_mb) {
  return largest_tile_side(
      [&](int side) {
        const TileGrid grid(cols, rows, side);
        const double tile = kTileBytesPerCell * double(side + 4) * double(side + 4) * concurrent;
        return tile + kGlobalBytesPerTileSide * double(grid.count()) * double(side) + 40.0 * rows;
      },
      memory_limit_mb, reserved_mb, "tiles of 64 x 64 cells on a " + std::to_string(cols) + " x " + std::to_string(rows) + " mosaic");
}

}  // namespace terrapolis::hydro::tiled
