// The density stage's saved outputs, read back the same way by the `sites` command and a resumed run.
// SPDX-License-Identifier: MIT
#include "pipeline/density_folder.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "core/error.hpp"
#include "io/raster_io.hpp"

namespace terrapolis::pipeline {

void check_density_values(const std::string& path, const float* values, std::size_t count) {
  for (std::size_t i = 0; i < count; ++i) {
    const float v = values[i];
    if (!std::isnan(v) && !(v >= -1e-6f && v <= 1.0f + 1e-6f))
      throw bad_input(path + ": density values must lie in [0,1] (found " + std::to_string(v) + ")");
  }
}

void check_same_grid(const RasterHeader& density, const std::string& buildable_path, const RasterHeader& header) {
  if (header.cols != density.cols || header.rows != density.rows)
    throw bad_input(buildable_path + ": not on the grid of the density (" + std::to_string(header.cols) + "x" + std::to_string(header.rows) +
                    " cells instead of " + std::to_string(density.cols) + "x" + std::to_string(density.rows) + ")");
  for (std::size_t k = 0; k < 6; ++k)
    if (std::abs(header.georef.transform[k] - density.georef.transform[k]) > 1e-9 * std::max(1.0, std::abs(density.georef.transform[k])))
      throw bad_input(buildable_path + ": not on the grid of the density (different geotransform)");
}

std::string density_folder_file(const std::string& dir, const std::string& name) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) throw bad_input(dir + ": no such folder (expected density.tif and buildable.tif in it)");
  for (const char* extension : {".tif", ".vrt"})
    if (const fs::path file = fs::path(dir) / (name + extension); fs::exists(file, ec)) return file.string();
  throw bad_input((fs::path(dir) / (name + ".tif")).string() + ": no such file (nor " + name + ".vrt, a tiled density's)");
}

DensityFolder read_density_folder(const std::string& dir) {
  const std::string density_path = density_folder_file(dir, "density"), buildable_path = density_folder_file(dir, "buildable");
  DensityFolder in;
  in.density = read_dem(density_path);
  check_density_values(density_path, in.density.data(), in.density.size());
  check_same_grid(grid_of(in.density), buildable_path, read_header(buildable_path));
  // Same grid (checked above): the mask as is, nodata (NaN once read) kept as 255.
  const Raster<float> mask = read_dem(buildable_path);
  in.buildable = in.density.like<std::uint8_t>(255);
  in.buildable.nodata = 255;
  for (std::size_t i = 0; i < mask.size(); ++i)
    if (!std::isnan(mask[i])) in.buildable[i] = mask[i] == 1.0f ? 1 : 0;
  return in;
}

}  // namespace terrapolis::pipeline
