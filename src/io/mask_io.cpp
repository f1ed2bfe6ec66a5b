// Mask rasters (water, exclusions) read onto a DEM's grid.
// SPDX-License-Identifier: MIT
#include "io/mask_io.hpp"

#include <cmath>

#include "io/raster_io.hpp"

namespace terrapolis {

Raster<std::uint8_t> read_mask(const std::string& path, const Georef& like, int cols, int rows) {
  const Raster<float> values = read_resampled(path, like, cols, rows, Resampling::nearest);
  Raster<std::uint8_t> mask(cols, rows, like, 0);
  for (std::size_t i = 0; i < values.size(); ++i) mask[i] = !std::isnan(values[i]) && values[i] != 0;
  return mask;
}

}  // namespace terrapolis
