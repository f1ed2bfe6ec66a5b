// Topological-order flow accumulation for D8 (no stack) and for split methods.
// SPDX-License-Identifier: MIT
#include "hydro/accumulation.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <bit>
#include <cmath>
#include <vector>

#include "core/error.hpp"
#include "hydro/exact_accumulation.hpp"
#include "hydro/grid.hpp"

namespace terrapolis::hydro {

Raster<double> accumulate(const Dem& filled, const FlowRouter& router,
                          const CellMetrics& metrics, const AccumulationOptions& options, Progress& progress) {
  ProgressStep step(progress, "accumulation");
  const int cols = filled.cols(), rows = filled.rows();
  if (options.weights && (options.weights->cols() != cols || options.weights->rows() != rows))
    throw bad_input("weights: raster is not on the DEM's grid");
  Raster<double> acc = filled.like<double>(0.0);
  if (router.method() == FlowMethod::d8 && !options.weights) {
    // Fixed-point sums, the same bits as the tile engine's whatever the tiling.
    const FixedPointUnits units = fixed_point_units(metrics, cols, options.unit);
    std::vector<std::int64_t> sum(filled.size(), 0);
    for (int r = 0; r < rows; ++r)
      for (int c = 0; c < cols; ++c)
        if (!std::isnan(filled(c, r))) sum[acc.index(c, r)] = units.per_row[std::size_t(r)];
    accumulate_d8_units(router.d8(), sum);
    for (std::size_t i = 0; i < acc.size(); ++i) acc[i] = std::isnan(filled[i]) ? NAN : units.value(sum[i]);
    return acc;
  }
  // Own contributions; in-degrees of the receivers that lie inside the grid.
  BigVector<std::uint8_t> indegree(filled.size(), 0);
  BigVector<std::uint8_t> receivers(filled.size(), 0);  // bit k: neighbour k receives
  tbb::parallel_for(tbb::blocked_range<int>(0, rows), [&](const tbb::blocked_range<int>& rr) {
    for (int r = rr.begin(); r < rr.end(); ++r) {
      const double own = options.unit == AccumulationUnit::area_m2 ? metrics.area_m2[std::size_t(r)] : 1.0;
      for (int c = 0; c < cols; ++c) {
        const std::size_t i = acc.index(c, r);
        if (std::isnan(filled[i])) {
          acc[i] = NAN;
          continue;
        }
        double w = own;
        if (options.weights) {
          const float wt = (*options.weights)[i];
          w = std::isnan(wt) ? 0.0 : own * double(wt);
        }
        acc[i] = w;
        receivers[i] = router.inner_receivers(c, r);  // D8: one bit, no split computed
      }
    }
  });
  // In-degrees gathered (each cell counts the neighbours that send to it): parallel, no atomics.
  tbb::parallel_for(tbb::blocked_range<int>(0, rows), [&](const tbb::blocked_range<int>& rr) {
    for (int r = rr.begin(); r < rr.end(); ++r)
      for (int c = 0; c < cols; ++c) {
        std::uint8_t n = 0;
        for (int k = 0; k < 8; ++k) {
          const int cn = c + dcol[k], rn = r + drow[k];
          if (cn >= 0 && rn >= 0 && cn < cols && rn < rows && (receivers[acc.index(cn, rn)] & (1u << opposite(k)))) ++n;
        }
        indegree[acc.index(c, r)] = n;
      }
  });
  step.update(0.3);
  std::vector<std::uint32_t> stack;
  FlowSplit split;
  const std::size_t report = std::max<std::size_t>(filled.size() / 20, 1);
  for (std::size_t start = 0; start < filled.size(); ++start) {
    if (start % report == 0) step.update(0.3 + 0.7 * double(start) / double(filled.size()));
    if (indegree[start] != 0 || std::isnan(filled[start])) continue;
    indegree[start] = 0xFF;  // done marker (a real in-degree never exceeds 8)
    stack.push_back(std::uint32_t(start));
    while (!stack.empty()) {
      const std::uint32_t i = stack.back();
      stack.pop_back();
      const std::uint8_t bits = receivers[i];
      if (bits == 0) continue;
      if ((bits & (bits - 1)) == 0) {  // one bit (std::has_single_bit calls libgcc's popcount without -mpopcnt)
        // One inner receiver takes everything: MFD and D-infinity only split between valid
        // cells, so no share of a single-receiver cell leaves the grid. No split to compute.
        const std::size_t n = std::size_t(std::ptrdiff_t(i) + neighbour_offset(cols, std::countr_zero(bits)));
        acc[n] += acc[i];
        if (--indegree[n] == 0) {
          indegree[n] = 0xFF;
          stack.push_back(std::uint32_t(n));
        }
        continue;
      }
      const int c = int(i % std::uint32_t(cols)), r = int(i / std::uint32_t(cols));
      router.split(c, r, split);
      for (int j = 0; j < split.count; ++j) {
        const int k = split.k[std::size_t(j)];
        if (!(bits & (1u << k))) continue;
        const std::size_t n = std::size_t(std::ptrdiff_t(i) + neighbour_offset(cols, k));
        acc[n] += split.fraction[std::size_t(j)] * acc[i];
        if (--indegree[n] == 0) {
          indegree[n] = 0xFF;
          stack.push_back(std::uint32_t(n));
        }
      }
    }
  }
  return acc;
}

Raster<double> outflow(const Dem& filled, const FlowRouter& router, const Raster<double>& accumulation) {
  Raster<double> out = filled.like<double>(0.0);
  FlowSplit split;
  for (int r = 0; r < filled.rows(); ++r)
    for (int c = 0; c < filled.cols(); ++c) {
      const std::size_t i = out.index(c, r);
      if (std::isnan(filled[i])) continue;
      router.split(c, r, split);
      if (split.count == 0) {
        out[i] = accumulation[i];
        continue;
      }
      const std::uint8_t bits = router.inner_receivers(c, r);
      for (int j = 0; j < split.count; ++j)
        if (!(bits & (1u << split.k[std::size_t(j)]))) out[i] += split.fraction[std::size_t(j)] * accumulation[i];
    }
  return out;
}

}  // namespace terrapolis::hydro
