// Small synthetic DEMs on a projected 10 m grid for the road tests.
// SPDX-License-Identifier: MIT
#pragma once
#include <functional>

#include "core/raster.hpp"

namespace terrapolis::roads::test {

/// A cols x rows DEM with `cell` metre cells on a projected CRS; z(col, row) in metres.
inline Dem make_dem(int cols, int rows, double cell, const std::function<double(int, int)>& z) {
  Georef g;
  g.transform = {500000.0, cell, 0.0, 5000000.0, 0.0, -cell};
  g.crs.wkt = "LOCAL_CS[\"test\"]";
  g.crs.name = "test metres";
  g.crs.geographic = false;
  g.crs.linear_unit_m = 1.0;
  Dem dem(cols, rows, g);
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) dem(c, r) = float(z(c, r));
  return dem;
}

}  // namespace terrapolis::roads::test
