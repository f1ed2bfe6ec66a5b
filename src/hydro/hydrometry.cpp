// Hydrometry by method: Belhadj's diffusion, or log-rescaled D8 upstream area.
// SPDX-License-Identifier: MIT
#include "hydro/hydrometry.hpp"

#include <algorithm>
#include <cmath>

#include "core/geodesy.hpp"
#include "hydro/accumulation.hpp"
#include "hydro/depressions.hpp"
#include "hydro/flow_directions.hpp"

namespace terrapolis::hydro {

Raster<float> hydrometry_from_accumulation(Raster<double> area, const Dem& dem, const std::optional<double>& sea_level) {
  if (sea_level)
    for (std::size_t i = 0; i < area.size(); ++i)
      if (is_sea(dem[i], sea_level)) area[i] = 0;
  double lo = INFINITY, hi = -INFINITY;
  for (double a : area.values())
    if (a > 0) {
      lo = std::min(lo, std::log(a));
      hi = std::max(hi, std::log(a));
    }
  Raster<float> out = area.like<float>(NAN);
  const double span = hi > lo ? hi - lo : 1.0;
  for (std::size_t i = 0; i < area.size(); ++i) {
    if (std::isnan(area[i])) continue;
    out[i] = area[i] > 0 ? float(std::clamp((std::log(area[i]) - lo) / span, 0.0, 1.0)) : 0.0f;
  }
  return out;
}

BelhadjOptions belhadj_options(const HydrometryOptions& options) {
  BelhadjOptions b;
  b.max_iterations = options.max_iterations;
  b.threshold = options.threshold;
  b.vertical = options.vertical;
  b.sea_level = options.sea_level;
  b.share = options.share;
  return b;
}

Raster<float> compute_hydrometry(const Dem& dem, const HydrometryOptions& options, Progress& progress) {
  const CellMetrics metrics = cell_metrics(dem.georef(), dem.cols(), dem.rows());
  if (options.method == HydrometryMethod::belhadj)
    return belhadj_hydrometry(dem, metrics, belhadj_options(options), progress).hydrometry;
  const Dem filled = fill_depressions(dem, {FillMethod::priority_flood, options.sea_level}, progress);
  const auto d8 = d8_directions(filled, metrics, options.sea_level, progress);
  const FlowRouter router(filled, d8, metrics, FlowMethod::d8);
  return hydrometry_from_accumulation(accumulate(filled, router, metrics, {}, progress), dem, options.sea_level);
}

}  // namespace terrapolis::hydro
