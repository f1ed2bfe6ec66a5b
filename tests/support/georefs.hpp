// Georeferencing of synthetic test grids: a projected grid in metres, a geographic one in degrees.
// SPDX-License-Identifier: MIT
#pragma once
#include "core/raster.hpp"

namespace terrapolis::test {

/// North-up projected grid at (500000, 4000000), cells `cell_w` x `cell_h` metres.
inline Georef projected(double cell_w, double cell_h) {
  Georef g;
  g.transform = {500000, cell_w, 0, 4000000, 0, -cell_h};
  g.crs.wkt = "projected";
  return g;
}
inline Georef projected(double cell) { return projected(cell, cell); }

/// Geographic grid (WGS 84 metrics) from longitude 9 east and latitude `lat_north`, square cells of `cell_deg`.
inline Georef geographic(double lat_north, double cell_deg) {
  Georef g;
  g.transform = {9.0, cell_deg, 0, lat_north, 0, -cell_deg};
  g.crs.wkt = "geographic";
  g.crs.geographic = true;
  return g;
}

}  // namespace terrapolis::test
