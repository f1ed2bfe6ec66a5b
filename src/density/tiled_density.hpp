// The density model tile by tile: each tile computed on a window grown by the discs' reach, so
// that its cells are the whole grid's (docs/scale.md, issue 17).
// SPDX-License-Identifier: MIT
#pragma once
#include <array>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "density/density.hpp"
#include "density/disc_sums.hpp"

namespace terrapolis::density {

/// What a window's terrain terms take from the whole grid.
struct WholeTerrainFigures {
  DiscPlan near, far;                    ///< the topographic positions' discs (position_discs), from the window's first row
  /// The distances of the window's cells, metres; empty when the whole grid has no water, no river
  /// (the term is then 0).
  std::vector<float> to_water, to_river;
  /// The ranks of altitude, slope and the two positions among the whole grid's land; null: the
  /// first pass, which leaves those terms unranked so that the tiles can count them.
  const std::array<LandRanks, kRankedTerms.size()>* ranks = nullptr;
};

/// What the density of a window of a larger grid (a tile and its halo) takes from the whole grid,
/// so that the tile's cells are those compute_density gives on the whole grid.
struct WholeGridFigures {
  CellMetrics metrics;                   ///< the whole grid's metrics of the window's rows (height_m, diagonal_m: one more)
  std::array<float, 2> land_range{};     ///< lowest and highest land altitude of the whole grid (land_range)
  double r_min_m = 0;                    ///< r_min as raised on the whole grid (raised_r_min)
  DiscPlan inner, outer;                 ///< the whole grid's discs of r_min and r_max, DiscPlan::from_row the window's first row
  Window core;                           ///< the tile in the window; the rest is halo, read but not computed
  /// The whole grid's habitable maxima of the coast and plateau shares (DensityStats::coast_max,
  /// plateau_max); unset: the core's own (a first pass, which learns them).
  std::optional<std::array<float, 2>> maxima;
  /// When the terrain terms are computed.
  std::optional<WholeTerrainFigures> terrain;
};

/// The density model on the core of `window`: the rasters are on the window's grid, right on the
/// core only (NaN elsewhere), the stats the core's. The core's cells equal compute_density's on the
/// whole grid bit for bit when the halo holds the discs' reach (the two disc sums in a row: r_max,
/// then r_min around each cell of that ring) and `whole` is the whole grid's, altitudes being
/// integers or other values whose squares sum exactly in double (SRTM, GEBCO, any int16 DEM).
/// The terrain terms need `whole.terrain`.
DensityResult compute_density_window(const Dem& window, const Raster<float>& hydrometry, const DensityOptions& options,
                                     const WholeGridFigures& whole, Progress& progress);

/// r_min raised to the largest cell step of a grid with these metrics (the plain disc must hold
/// the 4-neighbours); throws bad_input when r_max is not larger.
double raised_r_min(const CellMetrics& metrics, const DensityOptions& options);

/// The discs of the topographic positions (1 and 5 km, at least two cells) on a grid of these metrics.
std::array<DiscPlan, 2> position_discs(const CellMetrics& metrics, int rows, int max_bands);

/// Lowest and highest altitude of the land cells (not water, with data) of `dem` (+inf, -inf: none).
std::array<float, 2> land_range(const Dem& dem, const DensityOptions& options);

/// A window's inputs read from the mosaic: the DEM (cells outside the mosaic are never asked for)
/// and `options`' rasters on its grid (hydrometry, water mask, exclusions; empty when unused).
struct WindowInputs {
  Dem dem;
  Raster<float> hydrometry;
  DensityOptions options;
};

/// Reads the window [col0, col0 + cols) x [row0, row0 + rows); `dem_only`: the DEM, the water mask
/// and the rivers alone (the first pass, the distances' bands). Called once per tile and pass, one tile at a time.
using ReadWindowInputs = std::function<WindowInputs(int col0, int row0, int cols, int rows, bool dem_only)>;

/// Receives each tile's rasters (on the tile's grid) and its stats; tiles are numbered row-major,
/// `across` a row of tiles.
using WriteDensityTile = std::function<void(int tile, int across, const DensityResult& result)>;

struct TiledDensityReport {
  int tile_size = 0, tiles = 0, across = 0;
  int halo_rows = 0, halo_cols = 0;  ///< largest halo of a tile, cells
  double window_bytes = 0;           ///< state of the largest window (a tile and its halo)
  double global_bytes = 0;           ///< the whole grid's metrics and disc plans
  DensityStats stats;                ///< the whole grid's (sums added tile by tile)
};

/// Bytes of state per cell of a window (DEM, masks, summed-area tables, the six output rasters),
/// used to size tiles from a memory limit.
inline constexpr double kDensityBytesPerCell = 64;
/// Bytes per cell of a window more with the terrain terms (six rasters, the positions' sums, the
/// distances read back), and more again with boosted trees (their table of the ten terms, its
/// copy in XGBoost, the margins).
inline constexpr double kTerrainBytesPerCell = 56, kBoostedBytesPerCell = 100;

/// The largest tile side (at least 64) whose window fits `memory_limit_mb` with the global state;
/// throws bad_input when none does.
int density_tile_size_for(int cols, int rows, int halo_rows, int halo_cols, double global_bytes, double memory_limit_mb,
                          double reserved_mb = 0, double cell_bytes = kDensityBytesPerCell);

/// compute_density of a cols x rows mosaic georeferenced by `georef`, tile by tile on tiles of
/// `tile_size` (0: from `memory_limit_mb` less `reserved_mb`), one tile at a time (each computed in parallel):
/// three reads of each tile (altitude range, coast and plateau maxima, then the tile), two
/// computations. `options` carries no raster (read gives each window's). With the terrain terms,
/// the first pass reads bands of full rows instead, for the altitude range and the distances to
/// water and rivers (DistanceStrips, in `scratch_dir`), and the second pass counts the land ranks.
/// `input_bytes_per_cell`: what `read` holds a window's cell more than the DEM and the water (user
/// layers, exclusions), counted in the tile size.
TiledDensityReport run_tiled_density(int cols, int rows, const Georef& georef, const ReadWindowInputs& read,
                                     const DensityOptions& options, int tile_size, double memory_limit_mb, const std::string& scratch_dir,
                                     const WriteDensityTile& write, Progress& progress, double reserved_mb = 0,
                                     double input_bytes_per_cell = 0);

}  // namespace terrapolis::density
