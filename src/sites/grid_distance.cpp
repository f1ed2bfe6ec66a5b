// Metres between cell centres of a grid, geodesic to sub-millimetre over city-sized distances.
// SPDX-License-Identifier: MIT
#include "sites/sites.hpp"

#include <algorithm>
#include <cmath>

namespace terrapolis::sites {

GridDistance::GridDistance(const Georef& georef, int cols, int rows)
    : metrics_(cell_metrics(georef, cols, rows)), y_(std::size_t(rows) + 2), rows_(rows) {
  // y_[r + 1] is the northing of row r's centre; height_m[r] joins rows r-1 and r, for r in 0..rows.
  y_[0] = -metrics_.height_m[0];
  for (int r = 0; r <= rows; ++r) y_[std::size_t(r + 1)] = y_[std::size_t(r)] + metrics_.height_m[std::size_t(r)];
}

double GridDistance::width_between(int r0, int r1) const {
  // Width of one column at the mid-latitude of the two rows (mid-latitude formula); rows
  // outside the grid take the width of the nearest row.
  const auto width = [&](int r) { return metrics_.width_m[std::size_t(std::clamp(r, 0, rows_ - 1))]; };
  const int s = r0 + r1;
  if (s % 2 == 0) return width(s / 2);
  const int lo = int(std::floor(s / 2.0));
  return 0.5 * (width(lo) + width(lo + 1));
}

double GridDistance::operator()(int c0, int r0, int c1, int r1) const {
  const double dx = double(c1 - c0) * width_between(r0, r1);
  const double dy = northing(r1) - northing(r0);
  return std::sqrt(dx * dx + dy * dy);
}

}  // namespace terrapolis::sites
