// SHA-256 of files, for the provenance of runs.
// SPDX-License-Identifier: MIT
#pragma once
#include <cstdint>
#include <map>
#include <string>

namespace terrapolis {

/// Hex SHA-256 of a file's bytes. Throws bad_input if it cannot be read.
std::string file_sha256(const std::string& path);

/// The same for a run's DEM, which may be a folder of GeoTIFF tiles: then the SHA-256 of each tile's
/// name and bytes in name order, so that changing, adding or renaming a tile changes it.
std::string input_sha256(const std::string& path);
/// Bytes of a file, or of a folder DEM's GeoTIFF tiles.
std::uintmax_t input_bytes(const std::string& path);

/// Versions of the libraries behind the io layer (GDAL, PROJ, GeographicLib, oneTBB).
std::map<std::string, std::string> io_library_versions();

}  // namespace terrapolis
