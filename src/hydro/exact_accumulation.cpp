// Fixed-point D8 accumulation (order-free sums) shared by the whole-grid and tiled paths.
// SPDX-License-Identifier: MIT
#include "hydro/exact_accumulation.hpp"

#include <cmath>

namespace terrapolis::hydro {

double FixedPointUnits::value(std::int64_t units) const { return std::ldexp(double(units), -shift); }

FixedPointUnits fixed_point_units(const CellMetrics& metrics, int cols, AccumulationUnit unit) {
  FixedPointUnits u;
  const std::size_t rows = metrics.area_m2.size();
  double total = 0;
  for (std::size_t r = 0; r < rows; ++r) total += (unit == AccumulationUnit::area_m2 ? metrics.area_m2[r] : 1.0) * cols;
  int exponent = 0;
  std::frexp(total, &exponent);  // total < 2^exponent
  u.shift = std::min(62 - exponent, 1000);
  u.per_row.resize(rows);
  for (std::size_t r = 0; r < rows; ++r)
    u.per_row[r] = std::llround(std::ldexp(unit == AccumulationUnit::area_m2 ? metrics.area_m2[r] : 1.0, u.shift));
  return u;
}

void accumulate_d8_units(const Raster<std::uint8_t>& d8, std::vector<std::int64_t>& acc) {
  const int cols = d8.cols(), rows = d8.rows();
  auto receiver = [&](std::size_t i) -> std::ptrdiff_t {  // index of the inner valid receiver, or -1
    const std::uint8_t k = d8[i];
    if (k >= 8) return -1;
    const int c = int(i % std::size_t(cols)) + dcol[k], r = int(i / std::size_t(cols)) + drow[k];
    if (c < 0 || r < 0 || c >= cols || r >= rows) return -1;
    const std::size_t n = d8.index(c, r);
    return d8[n] == kNoData ? -1 : std::ptrdiff_t(n);
  };
  BigVector<std::uint8_t> indegree(d8.size(), 0);
  for (std::size_t i = 0; i < d8.size(); ++i)
    if (const std::ptrdiff_t n = receiver(i); n >= 0) ++indegree[std::size_t(n)];
  for (std::size_t start = 0; start < d8.size(); ++start) {
    if (indegree[start] != 0 || d8[start] == kNoData) continue;
    indegree[start] = 0xFF;  // done (a real in-degree never exceeds 8)
    // Follow the path down while each next cell has received from all its donors.
    for (std::size_t i = start;;) {
      const std::ptrdiff_t n = receiver(i);
      if (n < 0) break;
      acc[std::size_t(n)] += acc[i];
      if (--indegree[std::size_t(n)] != 0) break;
      indegree[std::size_t(n)] = 0xFF;
      i = std::size_t(n);
    }
  }
}

}  // namespace terrapolis::hydro
