// Stream network: reaches between confluences as line strings, with Strahler order.
// SPDX-License-Identifier: MIT
#pragma once
#include <cstdint>
#include <vector>

#include "core/geodesy.hpp"
#include "core/progress.hpp"
#include "core/raster.hpp"
#include "io/vector_io.hpp"

namespace terrapolis::hydro {

struct StreamOptions {
  double threshold_km2 = 10.0;  ///< a cell is on a stream when its D8 upstream area is at least this (km², > 0)
};

/// Streams of a D8 network: cells with upstream area >= threshold, one LineString per reach,
/// through cell centres (DEM CRS), from a source or a confluence down to the next confluence
/// (which ends the reach, so reaches connect) or to an outlet. Fields:
/// `id` (1..), `strahler` (Strahler 1952: 1 at sources, +1 where two reaches of the same
/// highest order meet), `upstream_km2` (area at the reach's last own cell), `length_m` (geodesic
/// length of the line), `downstream_id` (the reach it flows into, 0 at outlets).
/// Reaches of a single cell (a source that is also an outlet) are left out. Deterministic.
VectorLayer extract_streams(const Raster<std::uint8_t>& d8, const Raster<double>& area_m2, const CellMetrics& metrics,
                            const StreamOptions& options, Progress& progress);

/// The cells of a stream network (upstream area at least the threshold) of a `cols` x `rows` grid,
/// in row-major order: what the tile engine gathers from its tiles (a few % of the cells).
struct StreamCells {
  int cols = 0, rows = 0;
  std::vector<std::int64_t> index;  ///< row * cols + col, increasing
  std::vector<std::uint8_t> code;   ///< D8 code (flow_directions.hpp)
  std::vector<double> area_m2;      ///< D8 upstream area
};

/// extract_streams on the stream cells alone, on the grid of `georef` (the same layer).
VectorLayer streams_of_cells(const StreamCells& cells, const Georef& georef, const CellMetrics& metrics, Progress& progress);

}  // namespace terrapolis::hydro
