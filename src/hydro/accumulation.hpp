// Flow accumulation in one pass in topological order: upstream cells, area (geodesic m²) or weights.
// SPDX-License-Identifier: MIT
#pragma once
#include "core/geodesy.hpp"
#include "core/progress.hpp"
#include "core/raster.hpp"
#include "hydro/flow_directions.hpp"

namespace terrapolis::hydro {

enum class AccumulationUnit {
  cells,    ///< number of upstream cells, the cell itself included
  area_m2,  ///< upstream area in m², from the geodesic area of each cell (CellMetrics::area_m2)
};

struct AccumulationOptions {
  AccumulationUnit unit = AccumulationUnit::area_m2;
  /// Optional weight per cell (same grid): a cell contributes weight x (1 or its area) instead of
  /// 1 or its area; NaN weights count as 0.
  const Raster<float>* weights = nullptr;
};

/// Accumulates what each cell contributes down the flow graph of `router` (D8, D-infinity or MFD)
/// in one pass in topological order (Kahn's algorithm: a cell is passed on once all its donors
/// are done). The value of a cell includes its own contribution. NaN on nodata.
/// @post mass conservation: the sum over cells of (value x share leaving the grid or kept by a
///   terminal cell) equals the sum of contributions (up to rounding, ~1e-15 relative).
/// Serial and deterministic; 9 bytes/cell (value + in-degree).
Raster<double> accumulate(const Dem& filled, const FlowRouter& router,
                          const CellMetrics& metrics, const AccumulationOptions& options, Progress& progress);

/// The water that leaves the DEM from each cell (through the border, nodata or a terminal cell),
/// same unit as `accumulation`; 0 elsewhere. Used to check mass conservation and to find outlets.
Raster<double> outflow(const Dem& filled, const FlowRouter& router, const Raster<double>& accumulation);

}  // namespace terrapolis::hydro
