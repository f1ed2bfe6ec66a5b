// Small synthetic DEMs on a projected 10 m grid for the road tests.
// SPDX-License-Identifier: MIT
#pragma once
#include <functional>

#include "core/raster.hpp"
#include "support/local_grid.hpp"

namespace terrapolis::roads::test {

/// A cols x rows DEM with `cell` metre cells on a projected CRS; z(col, row) in metres.
inline Dem make_dem(int cols, int rows, double cell, const std::function<double(int, int)>& z) {
  Dem dem(cols, rows, support::local_metres(cell));
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) dem(c, r) = float(z(c, r));
  return dem;
}

}  // namespace terrapolis::roads::test
