// Inland water and the roads' terrain, built once for `path`, `roads`, `access` and `terrapolis run`.
// SPDX-License-Identifier: MIT
#pragma once
#include <cstdint>
#include <nlohmann/json.hpp>

#include "core/progress.hpp"
#include "core/raster.hpp"
#include "pipeline/stage_options.hpp"
#include "plugin/plugin.hpp"
#include "roads/cost_model.hpp"
#include "roads/terrain_field.hpp"

namespace terrapolis::pipeline {

/// Water no sea level sees (docs/lakes.md, docs/roads.md): 1 water, 0 not.
struct InlandWater {
  Raster<std::uint8_t> mask;
  std::size_t flat_lakes = 0;   ///< lakes the DEM flattens (hydro::detect_flat_water)
  double flat_lake_km2 = 0;
  nlohmann::ordered_json reservoirs = nlohmann::ordered_json::array();  ///< per reservoir: level_m, area_km2, volume_m3, max_depth_m
};

/// The lakes the DEM flattens, the user's water mask and the reservoirs flooded to their level
/// (Peytavie 2010 §2.4.1), as one mask that the density (uninhabitable, lakeshores as coast), the
/// roads (bridged or avoided) and the access (impassable) read alike.
InlandWater inland_water(const Dem& dem, const InlandWaterSettings& settings, Progress& progress, const Log& log);

/// The roads' terrain: the DEM, the sea (below water.sea_level_m, and nodata) and the inland water.
roads::TerrainField road_terrain(const Dem& dem, const Scenario& scenario, const roads::CostModel& model,
                                 const Raster<std::uint8_t>& water);

/// Adds the road layers to the roads' terrain: roads.vegetation read onto the DEM's grid (when
/// given) and the plugins' road cost terms.
void add_road_layers(roads::TerrainField& terrain, const RoadsSettings& settings, const plugin::PluginSet& plugins, const Dem& dem,
                     Progress& progress, const Log& log);

}  // namespace terrapolis::pipeline
