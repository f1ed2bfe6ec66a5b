// Real places (GeoNames, a census) read onto a DEM's land, for calibration and realism figures.
// SPDX-License-Identifier: MIT
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "core/raster.hpp"
#include "density/calibration.hpp"

namespace terrapolis::pipeline {

/// Places read from `path` (GeoJSON, GPKG or any OGR point layer; CSV with lon/lat or x/y
/// columns in WGS 84) with a numeric `population` (or `pop`) field, kept when they fall on a
/// land cell of `dem` with data, or within two cells of one (a coastal town on a sea cell
/// of a coarse grid is moved to the nearest land cell). `dropped` counts the others.
/// Throws bad_input naming `path` when it cannot be read or has no population field.
std::vector<density::Place> read_places(const std::string& path, const Dem& dem, const std::vector<std::uint8_t>& land, int& dropped);

}  // namespace terrapolis::pipeline
