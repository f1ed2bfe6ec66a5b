// Hillshade for display (QGIS background and preview.png).
// SPDX-License-Identifier: MIT
#pragma once
#include <cstdint>

#include "core/geodesy.hpp"
#include "core/raster.hpp"

namespace terrapolis::pipeline {

/// Horn's (1981) hillshade with geodesic cell sizes, light from `azimuth_deg` (clockwise from north)
/// at `altitude_deg` above the horizon; 1..255, 0 where the DEM is nodata (the nodata value).
Raster<std::uint8_t> hillshade(const Dem& dem, double azimuth_deg = 315.0, double altitude_deg = 45.0, double z_factor = 1.0);
/// The same with the cell sizes given: a window of a larger grid shades its cells as the whole grid
/// does with the whole grid's metrics of its rows (metric_rows).
Raster<std::uint8_t> hillshade(const Dem& dem, const CellMetrics& metrics, double azimuth_deg = 315.0, double altitude_deg = 45.0,
                               double z_factor = 1.0);

}  // namespace terrapolis::pipeline
