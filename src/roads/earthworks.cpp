// Cut-and-fill of the terrain along the surface sections of roads.
// SPDX-License-Identifier: MIT
#include "roads/earthworks.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/error.hpp"

namespace terrapolis::roads {

Dem earthworks(const Dem& dem, const TerrainField& terrain, const std::vector<const RoadGeometry*>& roads,
               const EarthworkOptions& o) {
  if (!(o.half_width_m > 0) || !(o.side_slope > 0) || !(o.max_height_m >= 0)) throw bad_input("earthworks: widths and slopes must be > 0");
  const std::size_t n = dem.size();
  std::vector<double> best_d(n, std::numeric_limits<double>::infinity()), deck(n, 0.0);
  double gentlest = o.side_slope;
  if (o.side_slopes)
    for (std::size_t k = 0; k < n; ++k) gentlest = std::max(gentlest, o.slope_at(k));
  const double reach_m = o.half_width_m + gentlest * o.max_height_m;
  for (const RoadGeometry* road : roads) {
    for (std::size_t i = 0; i + 1 < road->points.size(); ++i) {
      if (road->segments[i] != Structure::road) continue;
      const GridPoint a = road->points[i], b = road->points[i + 1];
      const double za = road->z[i], zb = road->z[i + 1];
      // A local metric plane at the segment's middle row (as the search prices arcs).
      const double mx = terrain.metres_x(0.5 * (a.row + b.row)), my = terrain.metres_y(0.5 * (a.row + b.row));
      const double ex = (b.col - a.col) * mx, ey = (b.row - a.row) * my, l2 = ex * ex + ey * ey;
      const int c0 = std::max(0, int(std::floor(std::min(a.col, b.col) - reach_m / mx)));
      const int c1 = std::min(dem.cols() - 1, int(std::ceil(std::max(a.col, b.col) + reach_m / mx)));
      const int r0 = std::max(0, int(std::floor(std::min(a.row, b.row) - reach_m / my)));
      const int r1 = std::min(dem.rows() - 1, int(std::ceil(std::max(a.row, b.row) + reach_m / my)));
      for (int r = r0; r <= r1; ++r)
        for (int c = c0; c <= c1; ++c) {
          const double px = (c - a.col) * mx, py = (r - a.row) * my;
          const double t = l2 > 0 ? std::clamp((px * ex + py * ey) / l2, 0.0, 1.0) : 0.0;
          const double d = std::hypot(px - t * ex, py - t * ey);
          if (d > reach_m) continue;
          const double z = za + t * (zb - za);
          const std::size_t k = dem.index(c, r);
          if (d < best_d[k] || (d == best_d[k] && z < deck[k])) {
            best_d[k] = d;
            deck[k] = z;
          }
        }
    }
  }
  Dem out = dem;
  for (std::size_t k = 0; k < n; ++k) {
    if (best_d[k] == std::numeric_limits<double>::infinity() || dem.is_nodata(k)) continue;
    const int c = int(k % std::size_t(dem.cols())), r = int(k / std::size_t(dem.cols()));
    if (terrain.water(c, r)) continue;
    const double slope = o.slope_at(k);
    if (best_d[k] > o.half_width_m + slope * o.max_height_m) continue;  // beyond this cell's own reach
    const double allowed = std::max(0.0, best_d[k] - o.half_width_m) / slope;
    out[k] = float(std::clamp(double(dem[k]), deck[k] - allowed, deck[k] + allowed));
  }
  return out;
}

}  // namespace terrapolis::roads
