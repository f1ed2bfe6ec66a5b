// Horn (1981) hillshade, with per-row metric cell sizes.
// SPDX-License-Identifier: MIT
#include "pipeline/hillshade.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "core/geodesy.hpp"

namespace terrapolis::pipeline {

Raster<std::uint8_t> hillshade(const Dem& dem, double azimuth_deg, double altitude_deg, double z_factor) {
  return hillshade(dem, cell_metrics(dem.georef(), dem.cols(), dem.rows()), azimuth_deg, altitude_deg, z_factor);
}

Raster<std::uint8_t> hillshade(const Dem& dem, const CellMetrics& m, double azimuth_deg, double altitude_deg, double z_factor) {
  Raster<std::uint8_t> out = dem.like<std::uint8_t>(0);
  out.nodata = 0;
  const double zenith = (90.0 - altitude_deg) * M_PI / 180.0;
  // Math angle of the light, counter-clockwise from east.
  const double azimuth = std::fmod(360.0 - azimuth_deg + 90.0, 360.0) * M_PI / 180.0;
  const int cols = dem.cols(), rows = dem.rows();
  tbb::parallel_for(tbb::blocked_range<int>(0, rows), [&](const tbb::blocked_range<int>& range) {
    for (int r = range.begin(); r < range.end(); ++r) {
      const double dx = m.width_m[r];
      const double dy = 0.5 * (m.height_m[r] + m.height_m[r + 1]);
      for (int c = 0; c < cols; ++c) {
        const float centre = dem(c, r);
        if (std::isnan(centre)) continue;
        // Missing neighbours (border, nodata) take the centre's value.
        auto z = [&](int dc, int dr) {
          const int cc = c + dc, rr = r + dr;
          if (cc < 0 || rr < 0 || cc >= cols || rr >= rows) return double(centre);
          const float v = dem(cc, rr);
          return std::isnan(v) ? double(centre) : double(v);
        };
        const double dzdx = ((z(1, -1) + 2 * z(1, 0) + z(1, 1)) - (z(-1, -1) + 2 * z(-1, 0) + z(-1, 1))) / (8 * dx) * z_factor;
        const double dzdy = ((z(-1, -1) + 2 * z(0, -1) + z(1, -1)) - (z(-1, 1) + 2 * z(0, 1) + z(1, 1))) / (8 * dy) * z_factor;
        const double slope = std::atan(std::hypot(dzdx, dzdy));
        const double aspect = std::atan2(dzdy, -dzdx);
        const double shade = std::cos(zenith) * std::cos(slope) + std::sin(zenith) * std::sin(slope) * std::cos(azimuth - aspect);
        out(c, r) = std::uint8_t(1 + std::lround(254.0 * std::clamp(shade, 0.0, 1.0)));
      }
    }
  });
  return out;
}

}  // namespace terrapolis::pipeline
