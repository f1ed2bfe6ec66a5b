// The DEM argument every command shares.
// SPDX-License-Identifier: MIT
#include "cli/dem_input.hpp"

#include <CLI/CLI.hpp>

#include "cli/schema_options.hpp"

namespace terrapolis::cli {

void DemInput::add_to(CLI::App& app, const std::string& name) {
  file_kind(app.add_option(name, path, "Elevation model (any GDAL raster: GeoTIFF, SRTM .hgt, ESRI ASCII grid, VRT...)")->required(),
            FileKind::raster_in);
  add_read_options(app);
}

void DemInput::add_read_options(CLI::App& app, const std::string& of) {
  const std::string suffix = of.empty() ? "" : " (" + of + ")";
  app.add_option("--band", band, "Band to read (required for multi-band files)" + suffix)->check(CLI::PositiveNumber);
  app.add_option("--assume-crs", assume_crs, "CRS for a file that carries none, e.g. EPSG:32611" + suffix);
}

}  // namespace terrapolis::cli
