// run_hydro: the stage's steps in order, sharing the cell metrics and the conditioned DEM.
// SPDX-License-Identifier: MIT
#include "hydro/hydro.hpp"

#include <chrono>

#include "core/geodesy.hpp"

namespace terrapolis::hydro {

HydroResult run_hydro(const Dem& dem, const HydroOptions& options, Progress& progress) {
  const CellMetrics metrics = cell_metrics(dem.georef(), dem.cols(), dem.rows());
  HydroResult out;
  out.filled = fill_depressions(dem, {options.fill, options.sea_level}, progress);
  out.d8 = d8_directions(out.filled, metrics, options.sea_level, progress);
  const FlowRouter router(out.filled, out.d8, metrics, options.flow, options.mfd_exponent);
  AccumulationOptions acc;
  acc.unit = options.unit;
  if (options.weights) acc.weights = &*options.weights;
  out.accumulation = accumulate(out.filled, router, metrics, acc, progress);
  // Streams and the accumulation hydrometry need the plain D8 upstream area.
  const bool plain_area = options.flow == FlowMethod::d8 && options.unit == AccumulationUnit::area_m2 && !options.weights;
  Raster<double> area;
  const bool need_area =
      options.with_streams || (options.with_hydrometry && options.hydrometry.method == HydrometryMethod::accumulation);
  if (need_area && !plain_area) {
    const FlowRouter d8_router(out.filled, out.d8, metrics, FlowMethod::d8);
    area = accumulate(out.filled, d8_router, metrics, {}, progress);
  }
  const Raster<double>& d8_area = plain_area ? out.accumulation : area;
  if (options.with_hydrometry) {
    const HydrometryOptions h = hydrometry_options(options);
    if (h.method == HydrometryMethod::accumulation) {
      out.hydrometry = hydrometry_from_accumulation(d8_area, dem, h.sea_level);
    } else {
      const auto t0 = std::chrono::steady_clock::now();
      BelhadjRun run = belhadj_hydrometry(dem, metrics, belhadj_options(h), progress);
      out.hydrometry_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      out.hydrometry_iterations = run.iterations;
      out.hydrometry = std::move(run.hydrometry);
    }
  }
  if (options.with_streams) out.streams = extract_streams(out.d8, d8_area, metrics, options.streams, progress);
  return out;
}

}  // namespace terrapolis::hydro
