// SHA-256 of files, for the provenance of runs.
// SPDX-License-Identifier: MIT
#pragma once
#include <map>
#include <string>

namespace terrapolis {

/// Hex SHA-256 of a file's bytes. Throws bad_input if it cannot be read.
std::string file_sha256(const std::string& path);

/// Versions of the libraries behind the io layer (GDAL, PROJ, GeographicLib, oneTBB).
std::map<std::string, std::string> io_library_versions();

}  // namespace terrapolis
