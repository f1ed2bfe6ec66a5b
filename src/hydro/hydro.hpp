// The whole hydrology stage in one call: conditioning, directions, accumulation, hydrometry, streams.
// SPDX-License-Identifier: MIT
#pragma once
#include <cstdint>
#include <optional>

#include "core/progress.hpp"
#include "core/raster.hpp"
#include "hydro/accumulation.hpp"
#include "hydro/depressions.hpp"
#include "hydro/flow_directions.hpp"
#include "hydro/hydrometry.hpp"
#include "hydro/streams.hpp"
#include "io/vector_io.hpp"

namespace terrapolis::hydro {

struct HydroOptions {
  FillMethod fill = FillMethod::priority_flood;
  FlowMethod flow = FlowMethod::d8;       ///< routing used for `accumulation`
  double mfd_exponent = 1.1;              ///< MFD: share ∝ tan(slope)^p, p > 0
  AccumulationUnit unit = AccumulationUnit::area_m2;
  std::optional<Raster<float>> weights;   ///< optional per-cell weights on the DEM's grid
  /// Cells at or below this elevation (m) are outlets for every step (overrides hydrometry.sea_level).
  std::optional<double> sea_level;
  HydrometryOptions hydrometry;
  bool with_hydrometry = true;
  StreamOptions streams;
  bool with_streams = true;
};

struct HydroResult {
  Dem filled;                         ///< conditioned DEM, metres
  Raster<std::uint8_t> d8;            ///< D8 receivers (flow_directions.hpp codes; encode_d8 for files)
  Raster<double> accumulation;        ///< in options.unit (x weights), with options.flow routing
  Raster<float> hydrometry;           ///< [0,1], empty when !with_hydrometry
  VectorLayer streams;                ///< D8 streams (streams.hpp fields), empty when !with_streams
  int hydrometry_iterations = 0;      ///< Belhadj iterations done (0 for the accumulation method)
  double hydrometry_seconds = 0;      ///< wall time of the Belhadj diffusion (for logs, never written to files)
};

/// Runs the stage on `dem` (metres, NaN nodata). Throws bad_input on invalid options.
HydroResult run_hydro(const Dem& dem, const HydroOptions& options, Progress& progress);

/// The hydrometry's options as run_hydro uses them: the stage's sea level (when set) for theirs.
inline HydrometryOptions hydrometry_options(const HydroOptions& options) {
  HydrometryOptions h = options.hydrometry;
  if (options.sea_level) h.sea_level = options.sea_level;
  return h;
}

}  // namespace terrapolis::hydro
