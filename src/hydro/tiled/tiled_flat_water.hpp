// The lakes a DEM flattens (hydro::detect_flat_water) tile by tile: the whole grid's mask, cell for
// cell, holding one tile, the frames of the tiles and the surfaces that reach them (docs/scale.md).
// SPDX-License-Identifier: MIT
#pragma once
#include <cstdint>
#include <functional>

#include "core/progress.hpp"
#include "core/raster.hpp"
#include "hydro/flat_water.hpp"
#include "hydro/tiled/tiled_hydro.hpp"

namespace terrapolis::hydro::tiled {

/// Receives each tile's mask (1 on detected lakes, on the tile's grid); tiles are numbered row-major, `across` a row of tiles.
using WriteMaskTile = std::function<void(int tile, int across, const Raster<std::uint8_t>& mask)>;

struct TiledFlatWaterReport {
  int tile_size = 0, tiles = 0, across = 0;
  std::size_t lakes = 0;         ///< surfaces kept, as FlatWater::lakes
  double area_km2 = 0;           ///< their area (summed tile by tile)
  std::size_t surfaces = 0;      ///< level surfaces that reach a tile's frame or are large enough, given a mosaic-wide id
};

/// detect_flat_water of a cols x rows mosaic on tiles of `tile_size` (>= 8), three passes reading
/// each tile with a one-cell halo: the level surfaces of each tile, joined across tile edges
/// (union-find over the surfaces that reach a tile's two-cell frame); the cells around each large
/// one and how many lie below it (each tile counts its own cells, seeing its neighbours' frames);
/// the mask. The mask is the whole grid's cell for cell; a surface's area is summed in another order,
/// which matters only for an area within rounding of flat_water_min_km2.
TiledFlatWaterReport run_tiled_flat_water(int cols, int rows, const Georef& georef, const ReadWindow& read, const FlatWaterOptions& options,
                                          int tile_size, const WriteMaskTile& write, Progress& progress);

/// State per cell of a tile (its window, seeds, labels, the ids around it, the mask) and per cell
/// of a tile's edge (its two-cell frame of ids).
inline constexpr double kFlatWaterBytesPerCell = 32, kFlatWaterBytesPerEdgeCell = 2 * 8;

/// The largest tile side (at least 64) whose state fits `memory_limit_mb` less `reserved_mb`;
/// throws bad_input when none does.
int flat_water_tile_size_for(int cols, int rows, double memory_limit_mb, double reserved_mb = 0);

}  // namespace terrapolis::hydro::tiled
