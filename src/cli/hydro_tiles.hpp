// `terrapolis hydro` on a mosaic, tile by tile (--tile-size / --memory-limit).
// SPDX-License-Identifier: MIT
#pragma once
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "cli/command.hpp"
#include "hydro/accumulation.hpp"
#include "hydro/tiled/tiled_hydro.hpp"
#include "hydro/flow_directions.hpp"
#include "hydro/river_types.hpp"
#include "io/raster_io.hpp"

namespace terrapolis::cli {

struct TiledHydroRequest {
  std::string dem_path, out_dir;  ///< out_dir: the (staging) folder to write into
  std::string out_name;           ///< the output folder as the user named it
  ReadOptions read;
  int tile_size = 0;             ///< 0: from memory_limit_mb
  double memory_limit_mb = 1024;
  std::optional<double> sea_level;
  hydro::AccumulationUnit unit = hydro::AccumulationUnit::area_m2;
  double accumulation_scale = 1;  ///< file value = accumulation x scale (km2: 1e-6)
  hydro::D8Codes codes = hydro::D8Codes::esri;
  bool filled = true, flowdir = true, accumulation = true;
  bool basins = false;                ///< drainage basins, labels stitched across tiles
  bool streams = false;               ///< streams.geojson, reaches stitched across tiles (unit area_m2)
  double streams_threshold_km2 = 10;
  /// The streams' river types (--classify), each reach's ends read from the filled tiles (which
  /// must be written); rank 0's alone (it writes the streams).
  std::optional<hydro::RiverTypeOptions> river_types;
  WriteOptions filled_file, flowdir_file, accumulation_file, basins_file;  ///< description, metadata, COG, overwrite
};



/// Writes OUTDIR/filled.vrt, flowdir.vrt, accumulation.vrt (basins.vrt) over one GeoTIFF a tile in
/// OUTDIR/filled/, flowdir/, accumulation/ (tile_RRRR_CCCC.tif); the same cells as the whole-grid
/// command. Returns the log line. Under terrapolis-mpi, the request goes to every rank first.
std::string run_tiled_hydro_command(const TiledHydroRequest& request, Context& context);

/// Where tiled requests run besides this process: installed by terrapolis-mpi (mpi_main.cpp).
class TileDistribution {
 public:
  virtual ~TileDistribution() = default;
  /// On the process that parsed the command line: hands `request` to the other processes, which
  /// then call run_tiled_hydro_tiles with it.
  virtual void start(const TiledHydroRequest& request, const Context& context) = 0;
  virtual hydro::tiled::TileDriver& driver() = 0;
};
void set_tile_distribution(TileDistribution* distribution);

/// One process's part of a tiled request: its tiles (the driver deals them); rank 0 also writes the
/// VRTs and returns the log line. Collective over the driver's processes, errors included.
std::string run_tiled_hydro_tiles(const TiledHydroRequest& request, Context& context, hydro::tiled::TileDriver& driver);

}  // namespace terrapolis::cli
