// The DEM argument every command shares: path, --band and --assume-crs.
// SPDX-License-Identifier: MIT
#pragma once
#include <string>

#include "core/raster.hpp"
#include "io/raster_io.hpp"

namespace CLI { class App; }

namespace terrapolis::cli {

/// How a command reads its DEM(s): every command that reads one takes --band and --assume-crs
/// and reads through read() or header(), so the georeferencing checks of read_dem apply.
struct DemInput {
  std::string path;
  int band = 0;
  std::string assume_crs;

  /// Declares the positional DEM argument and the --band / --assume-crs options.
  void add_to(CLI::App& app, const std::string& name = "DEM");
  /// Declares --band and --assume-crs only, for a command that declares its DEM argument(s) itself
  /// (several DEMs, a DEM or a folder, a --like DEM); `of` says which file they apply to.
  void add_read_options(CLI::App& app, const std::string& of = "");
  /// True when --band or --assume-crs was given.
  bool given() const { return band > 0 || !assume_crs.empty(); }
  ReadOptions options() const { return read_options(band, assume_crs); }
  Dem read() const { return read(path); }
  Dem read(const std::string& file) const { return read_dem(file, options()); }
  RasterHeader header(const std::string& file) const { return read_header(file, options()); }
};

}  // namespace terrapolis::cli
