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
#include "io/raster_io.hpp"
#include "roads/terrain_field.hpp"
#include "roads/windowed_route.hpp"

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

/// A reservoir's figures in the run's summary (hydro.reservoirs: level_m, area_km2, volume_m3,
/// max_depth_m); warns, naming `pointer`, when its water reaches the DEM's edge or nodata.
nlohmann::ordered_json reservoir_figures(const lake::Lake& lake, const std::string& pointer, const Log& log);

/// The water cells of a saved inland water raster read back as floats (inland_water.tif or .vrt):
/// 1 where it holds 1, else 0.
Raster<std::uint8_t> saved_water_mask(const Raster<float>& saved);

/// The roads' terrain: the DEM, the sea (below water.sea_level_m, and nodata) and the inland water.
roads::TerrainField road_terrain(const Dem& dem, const Scenario& scenario, const roads::CostModel& model,
                                 const Raster<std::uint8_t>& water);

/// The roads' terrain by windows of a mosaic (roads::route_by_windows, on a grid larger than memory):
/// what road_terrain builds on the whole grid, from windows of `dem` and of `lakes` (the inland
/// water's mosaic: 1 water). Holds references to both readers.
struct RoadWindows {
  roads::TerrainGrid grid;          ///< with the bathymetry rule counted over bands of the DEM's rows
  roads::ReadTerrainWindow read;
  roads::WindowOptions window;      ///< the windows' limit and margin
  std::size_t max_nodes = 0;        ///< the search's nodes within the limit
};
/// `budget_mb`: what the windows and searches may take together (half each: windows at
/// roads::kWindowBytesPerCell, nodes at 48 bytes with their long-arc cache); the links searched
/// at once share it (roads::NetworkWindows).
/// `reach_m`: how far from the road its corridor reads (0 without corridors). `vegetation`: the
/// roads.vegetation raster, warped onto each window with the whole grid's kernel (warp_scale, as
/// add_road_layers), or "".
RoadWindows road_windows(const DemWindowReader& dem, const DemWindowReader& lakes, const Georef& georef, const Scenario& scenario,
                         const roads::CostModel& model, double reach_m, double budget_mb, const std::string& vegetation = {});

/// Adds the road layers to the roads' terrain: roads.vegetation read onto the DEM's grid (when
/// given) and the plugins' road cost terms.
void add_road_layers(roads::TerrainField& terrain, const RoadsSettings& settings, const plugin::PluginSet& plugins, const Dem& dem,
                     Progress& progress, const Log& log);

}  // namespace terrapolis::pipeline
