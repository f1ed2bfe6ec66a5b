// Inland water and the roads' terrain, built once for `path`, `roads`, `access` and `terrapolis run`.
// SPDX-License-Identifier: MIT
#include "pipeline/inland_water.hpp"

#include <cmath>

#include "core/error.hpp"
#include "core/geodesy.hpp"
#include "io/mask_io.hpp"
#include "io/raster_io.hpp"
#include "pipeline/scenario.hpp"

namespace terrapolis::pipeline {

InlandWater inland_water(const Dem& dem, const InlandWaterSettings& settings, Progress& progress, const Log& log) {
  hydro::FlatWater flat = hydro::detect_flat_water(dem, settings.flat_water);
  InlandWater out{std::move(flat.mask), flat.lakes, flat.area_km2, nlohmann::ordered_json::array()};
  Raster<std::uint8_t>& water = out.mask;
  if (!settings.water_mask.empty()) {
    const Raster<std::uint8_t> m = read_mask(settings.water_mask, dem.georef(), dem.cols(), dem.rows());
    for (std::size_t i = 0; i < m.size(); ++i)
      if (m[i]) water[i] = 1;
  }
  if (settings.reservoirs.empty()) return out;
  const CellMetrics metrics = cell_metrics(dem.georef(), dem.cols(), dem.rows());
  for (std::size_t k = 0; k < settings.reservoirs.size(); ++k) {
    const std::string pointer = "/water/reservoirs/" + std::to_string(k);
    lake::Lake l;
    try {
      l = lake::flood(dem, metrics, settings.reservoirs[k], progress);
    } catch (const Error& e) {
      throw bad_input(pointer + e.what());
    }
    for (std::size_t i = 0; i < l.mask.size(); ++i)
      if (l.mask[i] == 1) water[i] = 1;
    if (l.spills) log.warn(pointer + ": the water reaches the DEM's edge or nodata");
    const auto round_to = [](double v, double step) { return std::round(v / step) * step; };
    out.reservoirs.push_back({{"level_m", round_to(l.level_m, 0.01)}, {"area_km2", round_to(l.area_km2, 1e-4)},
                              {"volume_m3", std::round(l.volume_m3)}, {"max_depth_m", round_to(l.max_depth_m, 0.01)}});
  }
  return out;
}

roads::TerrainField road_terrain(const Dem& dem, const Scenario& scenario, const roads::CostModel& model,
                                 const Raster<std::uint8_t>& water) {
  return roads::TerrainField(dem, scenario.resolved["water"]["sea_level_m"].get<double>(), model.unknown_water_depth_m,
                             model.road_radius_m, &water);
}

void add_road_layers(roads::TerrainField& terrain, const RoadsSettings& settings, const plugin::PluginSet& plugins, const Dem& dem,
                     Progress& progress, const Log& log) {
  if (!settings.vegetation.empty())
    terrain.set_vegetation(read_resampled(settings.vegetation, dem.georef(), dem.cols(), dem.rows(), Resampling::bilinear));
  plugin::add_to_terrain(plugin::road_terms(plugins, dem, progress, log), terrain);
}

}  // namespace terrapolis::pipeline
