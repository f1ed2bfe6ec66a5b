// Belhadj's test sketch and the measure of its tears, shared by the subdivision and generator tests.
// SPDX-License-Identifier: MIT
#pragma once
#include <algorithm>
#include <cmath>
#include <limits>

#include "core/raster.hpp"
#include "terrain/subdivision.hpp"

namespace terrapolis::test {

/// Belhadj fig. 1.2 / 3.3: two crossed diagonals at `ridge_m`, the counter-diagonal shifted one
/// cell right; `zero_borders` (fig. 2.3, 3.3) fixes the borders at 0, else only the corners (fig.
/// 1.2: "les coins du MNT initial étant à une altitude nulle").
inline Raster<float> cross_skeleton(const Georef& georef, int n, float ridge_m, bool zero_borders = true) {
  Raster<float> r(n, n, georef, std::numeric_limits<float>::quiet_NaN());
  for (int i = 0; i < n; ++i) {
    r(i, i) = ridge_m;
    if (i > 0) r(n - i, i) = ridge_m;
  }
  if (zero_borders)
    for (int i = 0; i < n; ++i) r(i, 0) = r(i, n - 1) = r(0, i) = r(n - 1, i) = 0.0f;
  else
    r(0, 0) = r(n - 1, 0) = r(0, n - 1) = r(n - 1, n - 1) = 0.0f;
  return r;
}

/// Largest height difference between a constrained cell and an 8-neighbour that was computed, away
/// from the borders (where a ridge meets the zero border any neighbour jumps by half the ridge).
inline double largest_jump_at_constraints(const Raster<float>& constraints, const Raster<float>& result) {
  double worst = 0;
  const int margin = result.cols() / 8;
  for (int y = margin; y < result.rows() - margin; ++y)
    for (int x = margin; x < result.cols() - margin; ++x) {
      if (std::isnan(constraints(x, y))) continue;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          if (!result.inside(x + dx, y + dy) || !std::isnan(constraints(x + dx, y + dy))) continue;
          worst = std::max(worst, std::abs(double(result(x + dx, y + dy)) - result(x, y)));
        }
    }
  return worst;
}

/// The sketch filled by plain (top-down) midpoint displacement: what the thesis's tears are measured against.
inline Raster<float> plain_subdivision(const Raster<float>& sketch, const terrain::MidpointParams& params) {
  terrain::SubdivisionGrid grid = terrain::SubdivisionGrid::from_raster(sketch);
  terrain::midpoint_displacement(grid, params);
  Raster<float> out = sketch;
  out.values() = std::move(grid.z);
  return out;
}

}  // namespace terrapolis::test
