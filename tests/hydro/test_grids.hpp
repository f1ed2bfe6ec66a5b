// Small DEM builders shared by the hydrology tests.
// SPDX-License-Identifier: MIT
#pragma once
#include <cmath>
#include <random>
#include <vector>

#include "core/raster.hpp"
#include "support/local_grid.hpp"

namespace terrapolis::hydro::test {

/// A projected grid of square `cell` metre cells, values given row by row (row 0 north).
inline Dem grid(int cols, int rows, std::vector<float> values, double cell = 1.0) {
  Dem d(cols, rows, support::local_metres(cell), 0.0f);
  d.values() = std::move(values);
  return d;
}

/// A random rough DEM with some pits and flats and optional nodata holes, seeded.
inline Dem random_dem(int cols, int rows, std::uint64_t seed, bool holes) {
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<int> level(0, 12);  // integers: many ties and flats
  std::vector<float> v(std::size_t(cols) * std::size_t(rows));
  for (auto& x : v) x = float(level(rng));
  if (holes) {
    std::uniform_int_distribution<int> pick(0, int(v.size()) - 1);
    for (int h = 0; h < int(v.size()) / 15; ++h) v[std::size_t(pick(rng))] = NAN;
  }
  return grid(cols, rows, std::move(v), 30.0);
}

}  // namespace terrapolis::hydro::test
