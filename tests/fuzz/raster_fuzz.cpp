// Fuzz harness: bytes as a raster file in GDAL's memory file system -> header and DEM reading,
// then the cell metrics every stage derives from the georeferencing.
// SPDX-License-Identifier: MIT
#include <cpl_vsi.h>

#include <cstddef>
#include <cstdint>
#include <string>

#include "core/error.hpp"
#include "core/geodesy.hpp"
#include "io/raster_io.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  terrapolis::init_gdal();
  // The first byte picks the name's extension: some drivers (ESRI ASCII, VRT) are found by it.
  static const char* const names[] = {"/vsimem/fuzz.tif", "/vsimem/fuzz.asc", "/vsimem/fuzz.vrt", "/vsimem/fuzz.bin"};
  const std::string name = size ? names[data[0] % 4] : names[0];
  VSILFILE* f = VSIFileFromMemBuffer(name.c_str(), const_cast<GByte*>(data), vsi_l_offset(size), FALSE);
  if (!f) return 0;
  VSIFCloseL(f);
  try {
    terrapolis::ReadOptions options;
    options.assume_crs = "EPSG:4326";
    const auto header = terrapolis::read_header(name, options);
    // Large headers are refused by the reader on memory grounds; the harness stays small.
    if (double(header.cols) * header.rows <= 4e6) {
      const terrapolis::Dem dem = terrapolis::read_dem(name, options);
      (void)terrapolis::cell_metrics(dem.georef(), dem.cols(), dem.rows());
    }
  } catch (const terrapolis::Error&) {
  }
  VSIUnlink(name.c_str());
  return 0;
}
