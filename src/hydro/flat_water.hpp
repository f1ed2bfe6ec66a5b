// Inland water that a DEM flattens: SRTM, NASADEM and most DEMs built from radar or photogrammetry
// store a lake as one flat connected surface (the water level, edited in), which no sea level sees.
// SPDX-License-Identifier: MIT
#pragma once
#include <cstddef>
#include <cmath>
#include <cstdint>

#include "core/raster.hpp"

namespace terrapolis::hydro {

struct FlatWaterOptions {
  double min_area_km2 = 1.0;  ///< smallest flat surface kept as water (0 = detection off)
  double tolerance_m = 0.0;   ///< neighbours within this height of each other belong to one surface
  double sea_level_m = 0.0;   ///< cells at or below it are the sea, left out
};

struct FlatWater {
  Raster<std::uint8_t> mask;  ///< 1 on detected lakes, 0 elsewhere (the DEM's grid)
  std::size_t lakes = 0;      ///< connected surfaces kept
  double area_km2 = 0;        ///< their total area (geodesic)
};

/// A cell of the land flat water may cover: data, above the sea level.
inline bool flat_water_land(const Dem& dem, std::size_t i, const FlatWaterOptions& options) {
  return !dem.is_nodata(i) && double(dem[i]) > options.sea_level_m;
}

/// Whether cell (c, r) seeds a flat surface: land level with all its neighbours (the grid's edges
/// count as level; on a window of a mosaic, the window holds the mosaic's neighbours of the cell).
inline bool flat_water_seed(const Dem& dem, int c, int r, const FlatWaterOptions& options) {
  const std::size_t i = dem.index(c, r);
  if (!flat_water_land(dem, i, options)) return false;
  for (int dr = -1; dr <= 1; ++dr)
    for (int dc = -1; dc <= 1; ++dc) {
      if ((dr == 0 && dc == 0) || c + dc < 0 || r + dr < 0 || c + dc >= dem.cols() || r + dr >= dem.rows()) continue;
      const std::size_t j = dem.index(c + dc, r + dr);
      if (!flat_water_land(dem, j, options) || std::fabs(double(dem[j]) - double(dem[i])) > options.tolerance_m) return false;
    }
  return true;
}

/// Largest share of the cells around a flat surface that may lie below it (its outlet, noise on the
/// shore). On N47E009, 0.1 lost the eastern Obersee of Lake Constance, 0.4 kept a 12 km² stretch of
/// the Alpine Rhine valley floor.
inline bool flat_water_in_basin(std::size_t lower, std::size_t outside) { return !(double(lower) > 0.25 * double(outside)); }

/// Flat water: 8-connected components of land cells above the sea level whose elevation differs
/// from a neighbour's by at most `tolerance_m`, seeded only by cells all of whose 8 neighbours are on
/// the same level (so a lone flat pair in noisy terrain never grows), kept when their geodesic area
/// reaches `min_area_km2` and at most a quarter of the cells around it lie below its level (water sits
/// in a basin; a dead-level valley floor falls away downstream). Real terrain of SRTM's 1 m resolution varies by metres between 30-90 m
/// cells; a water level is one value over square kilometres.
FlatWater detect_flat_water(const Dem& dem, const FlatWaterOptions& options);

}  // namespace terrapolis::hydro
