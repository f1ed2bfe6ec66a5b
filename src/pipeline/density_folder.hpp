// The density stage's saved outputs, read back the same way by the `sites` command and a resumed run.
// SPDX-License-Identifier: MIT
#pragma once
#include <cstdint>
#include <string>

#include "core/raster.hpp"

namespace terrapolis::pipeline {

/// density.tif ([0,1], NaN where the DEM has no data) and buildable.tif (1 habitable, 0 not,
/// 255 no data, as the density stage makes it) on one grid.
struct DensityFolder {
  Raster<float> density;
  Raster<std::uint8_t> buildable;
};

/// Reads density.tif and buildable.tif from `dir`. Throws bad_input naming the file when the
/// folder or a file is missing, a density lies outside [0,1], or the two are not on one grid.
DensityFolder read_density_folder(const std::string& dir);

}  // namespace terrapolis::pipeline
