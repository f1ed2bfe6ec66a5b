// Test grids and runs shared by the erosion tests: hills with noise, ramps, the float precision of a balance.
// SPDX-License-Identifier: MIT
#pragma once
#include <cmath>
#include <cstring>
#include <random>

#include "erode/erosion.hpp"
#include "support/georefs.hpp"

namespace terrapolis::erode::test_grids {

using terrapolis::test::geographic;
using terrapolis::test::projected;

/// Rolling hills with noise, 300-700 m, on 1/1200 degree cells at 45 N (about 65 x 93 m).
inline Dem random_dem(int cols, int rows, unsigned seed, double noise_m) {
  Dem dem(cols, rows, geographic(45.0, 1.0 / 1200));
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c)
      dem(c, r) = float(500 + 150 * std::sin(c * 0.3) * std::cos(r * 0.2) + 3 * c + noise_m * u(rng));
  return dem;
}

/// A plane falling eastwards by `slope` (m/m) on 10 m cells.
inline Dem ramp(int cols, int rows, double slope) {
  Dem dem(cols, rows, projected(10));
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) dem(c, r) = float(100 + slope * 10 * (cols - 1 - c));
  return dem;
}

inline ErodeOptions with(Process process, int iterations) {
  ErodeOptions o;
  o.process = process;
  o.iterations = iterations;
  return o;
}

inline Dem run(const Dem& dem, const ErodeOptions& options, ErodeReport* report = nullptr, const Raster<std::uint8_t>* mask = nullptr,
               Raster<float>* loose = nullptr) {
  SilentProgress progress;
  return erode(dem, cell_metrics(dem.georef(), dem.cols(), dem.rows()), options, mask, progress, report, loose);
}

inline bool same_bytes(const Dem& a, const Dem& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0;
}

/// The float rounding of the heights written, summed over the grid: the precision of the balance.
inline double float_tolerance_m3(const Dem& dem) {
  const CellMetrics m = cell_metrics(dem.georef(), dem.cols(), dem.rows());
  double tolerance = 0;
  for (int r = 0; r < dem.rows(); ++r)
    for (int c = 0; c < dem.cols(); ++c)
      if (!std::isnan(dem(c, r))) tolerance += m.area_m2[std::size_t(r)] * std::abs(dem(c, r)) * 0x1p-23;
  return tolerance;
}

}  // namespace terrapolis::erode::test_grids
