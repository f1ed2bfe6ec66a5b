// Fuzz harness: bytes as a GeoJSON layer (a network, cities, or a plugin's features) read through
// OGR and transformed to a projected DEM CRS (UTM 32N), as `roads` and `network` read them.
// SPDX-License-Identifier: MIT
#include <cpl_vsi.h>

#include <cstddef>
#include <cstdint>

#include "core/error.hpp"
#include "io/crs.hpp"
#include "io/raster_io.hpp"
#include "io/vector_io.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  terrapolis::init_gdal();
  static const terrapolis::Crs utm = terrapolis::crs_from_user("EPSG:32632");
  const char* name = "/vsimem/fuzz.geojson";
  VSILFILE* f = VSIFileFromMemBuffer(name, const_cast<GByte*>(data), vsi_l_offset(size), FALSE);
  if (!f) return 0;
  VSIFCloseL(f);
  try {
    const terrapolis::VectorLayer layer = terrapolis::read_vector(name, utm);
    for (const auto& feature : layer.features) (void)feature.parts.size();
  } catch (const terrapolis::Error&) {
  }
  VSIUnlink(name);
  return 0;
}
