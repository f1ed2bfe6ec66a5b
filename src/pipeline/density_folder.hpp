// The density stage's saved outputs, read back the same way by the `sites` command and a resumed run.
// SPDX-License-Identifier: MIT
#pragma once
#include <cstdint>
#include <string>

#include "core/raster.hpp"
#include "io/raster_io.hpp"

namespace terrapolis::pipeline {

/// density.tif ([0,1], NaN where the DEM has no data) and buildable.tif (1 habitable, 0 not,
/// 255 no data, as the density stage makes it) on one grid.
struct DensityFolder {
  Raster<float> density;
  Raster<std::uint8_t> buildable;
};

/// DIR/NAME.tif, or DIR/NAME.vrt (the mosaic a tiled density writes) when there is no .tif;
/// throws bad_input naming them when the folder or both files are missing.
std::string density_folder_file(const std::string& dir, const std::string& name);

/// Reads density and buildable (density_folder_file) from `dir` whole. Throws bad_input naming the
/// file when the folder or a file is missing, a density lies outside [0,1], or the two are not on one grid.
DensityFolder read_density_folder(const std::string& dir);

/// Throws bad_input naming `path` at a density value outside [0,1] (NaN is nodata).
void check_density_values(const std::string& path, const float* values, std::size_t count);
/// Throws bad_input naming `buildable_path` unless it lies on `density`'s grid (size, geotransform).
void check_same_grid(const RasterHeader& density, const std::string& buildable_path, const RasterHeader& buildable);

}  // namespace terrapolis::pipeline
