// The hydrometry raster in [0,1] that the density stage uses: Belhadj's diffusion or accumulation.
// SPDX-License-Identifier: MIT
#pragma once
#include <optional>

#include "core/progress.hpp"
#include "core/raster.hpp"
#include "hydro/belhadj_hydrometry.hpp"

namespace terrapolis::hydro {

enum class HydrometryMethod {
  belhadj,       ///< Belhadj 2007 §4.2.2 Algorithm 12 (belhadj_hydrometry.hpp)
  accumulation,  ///< D8 upstream area (Priority-Flood fill), log-rescaled to [0,1]
};

struct HydrometryOptions {
  HydrometryMethod method = HydrometryMethod::belhadj;
  int max_iterations = 0;            ///< belhadj: 0 until convergence (safety cap 160)
  double threshold = 1.0 / 1048576;  ///< belhadj: mean quantity below which it stops (2^-20)
  VerticalScale vertical = VerticalScale::metres;
  std::optional<double> sea_level;   ///< cells at or below are outlets (coastal DEMs), metres
  BelhadjShare share = BelhadjShare::all_neighbours;  ///< belhadj: what Σn sums over
};

/// Hydrometry in [0,1] on the DEM's grid (NaN where the DEM is nodata; 0 on sea cells when
/// `sea_level` is set). Throws bad_input for invalid options or a DEM without land.
Raster<float> compute_hydrometry(const Dem& dem, const HydrometryOptions& options, Progress& progress);

/// The Belhadj part of `options`.
BelhadjOptions belhadj_options(const HydrometryOptions& options);

/// Log rescale of a D8 upstream area (m², > 0 on valid cells) to [0,1]:
/// (ln a - ln min) / (ln max - ln min) over valid cells; NaN stays NaN; cells of `dem` at or below
/// `sea_level` (when set) drain nothing and get 0. The one home of the "accumulation" method.
Raster<float> hydrometry_from_accumulation(Raster<double> area_m2, const Dem& dem, const std::optional<double>& sea_level);

}  // namespace terrapolis::hydro
