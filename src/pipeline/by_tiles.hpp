// What the hydro stage hands the density stage, computed by tiles (the run's stages and the density
// command on a mosaic share it): the inland water and Belhadj's hydrometry, the whole grid's cells.
// SPDX-License-Identifier: MIT
#pragma once
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "core/progress.hpp"
#include "core/raster.hpp"
#include "density/tiled_density.hpp"
#include "hydro/hydro.hpp"
#include "hydro/tiled/tiled_belhadj.hpp"
#include "hydro/tiled/tiled_flat_water.hpp"
#include "io/raster_io.hpp"
#include "pipeline/scenario.hpp"
#include "pipeline/stage_options.hpp"
#include "sites/land.hpp"

namespace terrapolis::pipeline {

template <class T>
using WriteTile = std::function<void(int tile, int across, const Raster<T>& raster)>;

/// The reservoirs (water.reservoirs) of a grid read by windows: each flooded on a window around its
/// seed (lake::flood_by_windows), the whole grid's cells and figures; its water kept as a mask over
/// the lake's bounding box.
class WindowReservoirs {
 public:
  /// Floods each reservoir of `water` on windows of `dem` of at most `budget_mb` while it is flooded.
  WindowReservoirs(const DemWindowReader& dem, const InlandWaterSettings& water, double budget_mb, Progress& progress, const Log& log);
  /// Marks the reservoirs' water (1) in `tile`, whose first cell is (`col0`, `row0`) in the grid.
  void add_to(Raster<std::uint8_t>& tile, int col0, int row0) const;
  /// What the masks hold, MB.
  double held_mb() const;
  /// Per reservoir, as pipeline::inland_water's (reservoir_figures).
  const nlohmann::ordered_json& figures() const { return figures_; }

 private:
  struct Water {
    int col0 = 0, row0 = 0;
    Raster<std::uint8_t> mask;  ///< 1 flooded, over the lake's bounding box
  };
  std::vector<Water> water_;
  nlohmann::ordered_json figures_ = nlohmann::ordered_json::array();
};

/// Bytes a cell of a window while a reservoir is flooded on it: the DEM (4, and GDAL's copy, 4), the
/// mask (1), the depths (4), the dam's cells (1) and the propagation's front (8 at most).
inline constexpr double kFloodBytesPerCell = 22;

/// pipeline::inland_water by tiles: the lakes the DEM flattens (hydro::tiled::run_tiled_flat_water),
/// water.water_mask and `reservoirs` (flooded by windows first), 1 water, 0 not.
hydro::tiled::TiledFlatWaterReport inland_water_by_tiles(const DemWindowReader& dem, const InlandWaterSettings& water, const TileSettings& tiles,
                                                         const WindowReservoirs& reservoirs, double reserved_mb,
                                                         const WriteTile<std::uint8_t>& write, Progress& progress);
/// The log line of inland_water_by_tiles.
std::string describe(const hydro::tiled::TiledFlatWaterReport& report);
/// inland_water_by_tiles written into `dir` (a scratch or staging folder) as inland_water.vrt over
/// one GeoTIFF a tile, its log line given to `log`; returns the VRT's path (the commands on a mosaic).
std::string inland_water_mosaic(const DemWindowReader& dem, const InlandWaterSettings& water, const TileSettings& tiles,
                                const std::string& dir, Progress& progress, const Log& log);

/// The hydrometry of run_hydro by tiles: Belhadj's (the accumulation method is refused, bad_input),
/// keeping its Acc in `scratch_dir` meanwhile.
hydro::tiled::TiledBelhadjReport hydrometry_by_tiles(const DemWindowReader& dem, const hydro::HydroOptions& hydro, const TileSettings& tiles,
                                                     double reserved_mb, const std::string& scratch_dir, const WriteTile<float>& write,
                                                     Progress& progress);
/// The log line of hydrometry_by_tiles.
std::string describe(const hydro::tiled::TiledBelhadjReport& report);

/// The hydrometry of a window of the DEM (its cells [c0, c0 + window.cols()) x ...).
using ReadHydrometry = std::function<Raster<float>(const Dem& window, int c0, int r0)>;
/// The density model's inputs by windows (density::run_tiled_density): the DEM, the inland water
/// (the VRT of inland_water_by_tiles), the scenario's exclusions, `hydrometry`'s (empty: zeros)
/// and, when the terrain terms are computed, the rivers of `accumulation_km2` (empty: none). The
/// user layers are read once over the grid first (layers_on_grid), so a window's are the grid's.
/// Holds references to `dem`, `scenario` and `options`.
/// Bytes a cell of a density window more for the scenario's user layers (a float held, GDAL's
/// warped copy) and exclusions (a byte, its copy), for run_tiled_density's tile size.
double density_file_bytes_per_cell(const Scenario& scenario);
density::ReadWindowInputs density_windows(const DemWindowReader& dem, const Scenario& scenario, const density::DensityOptions& options,
                                          const std::string& inland_water, const ReadHydrometry& hydrometry,
                                          const std::string& accumulation_km2 = "");

/// The density stage's inputs in a run by tiles, by windows (density_windows): the DEM and the
/// hydro stage's hydrometry.vrt, inland_water.vrt and accumulation.vrt in `run_folder`.
class RunDensityWindows {
 public:
  RunDensityWindows(const std::string& dem_path, const ReadOptions& read, const std::string& run_folder, const Scenario& scenario,
                    density::DensityOptions options);
  const density::ReadWindowInputs& read() const { return read_; }
  const density::DensityOptions& options() const { return options_; }

 private:
  density::DensityOptions options_;
  DemWindowReader dem_, hydrometry_;
  density::ReadWindowInputs read_;
};

/// The land of the sites stage read from the density stage's tiles (density.vrt, buildable.vrt):
/// bands of rows and blocks sized to the memory limit, the disc tests' blocks grown by the largest
/// disc.
class LandTiles : public sites::Land {
 public:
  /// Reads the two files (GeoTIFF or VRT) by windows. The bands and blocks hold what `tiles`' limit
  /// leaves once `reserved_mb` is counted (throws bad_input when that is less than a band of two
  /// rows). `grid`: the run's DEM's georeferencing (a VRT's geotransform may differ from it in the
  /// last bit); none: the density file's own.
  LandTiles(const std::string& density, const std::string& buildable, const std::optional<Georef>& grid, const TileSettings& tiles,
            double reserved_mb);
  sites::LandView window(int col0, int row0, int cols, int rows) const override;
  int block_side(int margin_cols, int margin_rows) const override;
  int band_rows() const override { return band_rows_; }

 private:
  LandTiles(std::unique_ptr<DemWindowReader> density, std::unique_ptr<DemWindowReader> buildable, const std::optional<Georef>& grid,
            const TileSettings& tiles, double reserved_mb);
  std::unique_ptr<DemWindowReader> density_, buildable_;
  int tile_size_ = 0, band_rows_ = 0;
  double bytes_ = 0;
};

}  // namespace terrapolis::pipeline
