// Mask rasters (water, exclusions) read onto a DEM's grid.
// SPDX-License-Identifier: MIT
#pragma once
#include <cstdint>
#include <string>

#include "core/raster.hpp"

namespace terrapolis {

/// A mask raster read onto the grid of `like` by nearest resampling (read_resampled): 1 where
/// the source has data and is not 0, else 0.
Raster<std::uint8_t> read_mask(const std::string& path, const Georef& like, int cols, int rows);

}  // namespace terrapolis
