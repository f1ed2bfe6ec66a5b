// Private helpers shared by the io sources (the only files that see GDAL headers).
// SPDX-License-Identifier: MIT
#pragma once
#include <cpl_error.h>
#include <ogr_spatialref.h>

#include <string>

#include "core/error.hpp"
#include "core/raster.hpp"

namespace terrapolis::detail {

/// Silences GDAL's stderr output for a scope and clears the last error; errors are read with
/// CPLGetLastErrorMsg (last_gdal_error). The one GDAL error guard of the io sources.
struct QuietGdal {
  QuietGdal() {
    CPLPushErrorHandler(CPLQuietErrorHandler);
    CPLErrorReset();
  }
  ~QuietGdal() { CPLPopErrorHandler(); }
  QuietGdal(const QuietGdal&) = delete;
  QuietGdal& operator=(const QuietGdal&) = delete;
};

/// Describes an OGR spatial reference as a Crs.
Crs describe(const OGRSpatialReference& srs);

/// The OGR spatial reference of a Crs, with longitude-first axis order.
OGRSpatialReference to_ogr(const Crs& crs);

/// Last GDAL error message, or `fallback`.
std::string last_gdal_error(const std::string& fallback);

/// Writes to "<path>.tmp-<pid>" then renames over `path`, removing the temporary on failure.
std::string temporary_name(const std::string& path);
void commit_file(const std::string& temporary, const std::string& path);
void discard_file(const std::string& temporary);

/// Writes `size` bytes to a new file `path`, checking every write, the last flush and the close.
/// Returns 0, or the errno of the first failure (ENOSPC on a full disk).
int write_bytes(const std::string& path, const void* data, std::size_t size);

/// The error of a failed write of `path` (exit 1): "no space left on the device" when `error_number`
/// is ENOSPC or GDAL's message says so, else `message` (GDAL's) or the system's text for the number.
Error write_failure(const std::string& path, int error_number, const std::string& message);

/// Refuses an existing output unless `overwrite`, and an output whose folder does not exist or is not writable.
void check_output(const std::string& path, bool overwrite);

}  // namespace terrapolis::detail
