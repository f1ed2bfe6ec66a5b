// Inland water that a DEM flattens: SRTM, NASADEM and most DEMs built from radar or photogrammetry
// store a lake as one flat connected surface (the water level, edited in), which no sea level sees.
// SPDX-License-Identifier: MIT
#pragma once
#include <cstddef>
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

/// Flat water: 8-connected components of land cells above the sea level whose elevation differs
/// from a neighbour's by at most `tolerance_m`, seeded only by cells all of whose 8 neighbours are on
/// the same level (so a lone flat pair in noisy terrain never grows), kept when their geodesic area
/// reaches `min_area_km2` and at most a quarter of the cells around it lie below its level (water sits
/// in a basin; a dead-level valley floor falls away downstream). Real terrain of SRTM's 1 m resolution varies by metres between 30-90 m
/// cells; a water level is one value over square kilometres.
FlatWater detect_flat_water(const Dem& dem, const FlatWaterOptions& options);

}  // namespace terrapolis::hydro
