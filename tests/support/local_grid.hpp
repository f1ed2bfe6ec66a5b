// Georeferencing of the hydrology and road tests' synthetic grids: a named local CRS in metres.
// SPDX-License-Identifier: MIT
#pragma once
#include "core/raster.hpp"

// Not terrapolis::test (support/georefs.hpp): the hydrology and road tests name their own
// terrapolis::hydro::test and terrapolis::roads::test, which a terrapolis::test would make ambiguous.
namespace terrapolis::support {

/// North-up grid at (500000, 5000000) on a local CRS in metres, square cells of `cell` metres.
inline Georef local_metres(double cell) {
  Georef g;
  g.transform = {500000, cell, 0, 5000000, 0, -cell};
  g.crs.wkt = "LOCAL_CS[\"test\"]";
  g.crs.name = "test metres";
  g.crs.geographic = false;
  g.crs.linear_unit_m = 1.0;
  return g;
}

}  // namespace terrapolis::support
