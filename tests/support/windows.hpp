// A window of a test grid as a grid of its own: how the tests read "by windows" from memory.
// SPDX-License-Identifier: MIT
#pragma once
#include "core/raster.hpp"

namespace terrapolis::test {

/// The cells [col0, col0 + cols) x [row0, row0 + rows) of `grid`, a copy georeferenced in place.
template <class T>
Raster<T> window_of(const Raster<T>& grid, int col0, int row0, int cols, int rows) {
  Raster<T> w(cols, rows, grid.georef().window(col0, row0));
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) w(c, r) = grid(col0 + c, row0 + r);
  return w;
}

}  // namespace terrapolis::test
