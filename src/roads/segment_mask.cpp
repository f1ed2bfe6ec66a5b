// Segment masks M_k and the annulus masks of bridges and tunnels.
// SPDX-License-Identifier: MIT
#include "roads/segment_mask.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>
#include <string>

#include "core/error.hpp"

namespace terrapolis::roads {
namespace {

double grid_angle(int dcol, int drow) {
  double a = std::atan2(-double(drow), double(dcol));
  if (a < 0) a += 2 * std::numbers::pi;
  return a;
}

}  // namespace

std::vector<MaskArc> segment_mask(int k) {
  if (k < 1 || k > 16) throw bad_input("/roads/k: mask size must be in 1..16, got " + std::to_string(k));
  std::vector<MaskArc> arcs;
  for (int j = -k; j <= k; ++j)
    for (int i = -k; i <= k; ++i)
      if ((i != 0 || j != 0) && std::gcd(std::abs(i), std::abs(j)) == 1) arcs.push_back({i, j, grid_angle(i, j)});
  std::sort(arcs.begin(), arcs.end(), [](const MaskArc& a, const MaskArc& b) { return a.angle_rad < b.angle_rad; });
  return arcs;
}

std::vector<MaskArc> annulus_mask(double r_min_cells, double r_max_cells) {
  std::vector<MaskArc> arcs;
  const int r = int(std::ceil(r_max_cells));
  for (int j = -r; j <= r; ++j)
    for (int i = -r; i <= r; ++i) {
      const double d = std::hypot(double(i), double(j));
      if (d >= std::max(1.0, r_min_cells) && d <= r_max_cells) arcs.push_back({i, j, grid_angle(i, j)});
    }
  return arcs;
}

}  // namespace terrapolis::roads
