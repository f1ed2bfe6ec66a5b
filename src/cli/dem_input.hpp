// The DEM argument every command shares: path, --band and --assume-crs.
// SPDX-License-Identifier: MIT
#pragma once
#include <string>

#include "core/raster.hpp"
#include "io/raster_io.hpp"

namespace CLI { class App; }

namespace terrapolis::cli {

struct DemInput {
  std::string path;
  int band = 0;
  std::string assume_crs;

  /// Declares the positional DEM argument and the --band / --assume-crs options.
  void add_to(CLI::App& app, const std::string& name = "DEM");
  ReadOptions options() const;
  Dem read() const { return read_dem(path, options()); }
};

}  // namespace terrapolis::cli
