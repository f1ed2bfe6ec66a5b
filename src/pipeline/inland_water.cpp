// Inland water and the roads' terrain, built once for `path`, `roads`, `access` and `terrapolis run`.
// SPDX-License-Identifier: MIT
#include "pipeline/inland_water.hpp"

#include <algorithm>
#include <optional>

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
    out.reservoirs.push_back(reservoir_figures(l, pointer, log));
  }
  return out;
}

nlohmann::ordered_json reservoir_figures(const lake::Lake& l, const std::string& pointer, const Log& log) {
  if (l.spills) log.warn(pointer + ": the water reaches the DEM's edge or nodata");
  const auto round_to = [](double v, double step) { return std::round(v / step) * step; };
  return {{"level_m", round_to(l.level_m, 0.01)}, {"area_km2", round_to(l.area_km2, 1e-4)}, {"volume_m3", std::round(l.volume_m3)},
          {"max_depth_m", round_to(l.max_depth_m, 0.01)}};
}

Raster<std::uint8_t> saved_water_mask(const Raster<float>& saved) {
  Raster<std::uint8_t> mask(saved.cols(), saved.rows(), saved.georef());
  for (std::size_t i = 0; i < mask.size(); ++i) mask[i] = saved[i] == 1;
  return mask;
}

roads::TerrainField road_terrain(const Dem& dem, const Scenario& scenario, const roads::CostModel& model,
                                 const Raster<std::uint8_t>& water) {
  return roads::TerrainField(dem, scenario.resolved["water"]["sea_level_m"].get<double>(), model.unknown_water_depth_m,
                             model.road_radius_m, &water);
}

RoadWindows road_windows(const DemWindowReader& dem, const DemWindowReader& lakes, const Georef& georef, const Scenario& scenario,
                         const roads::CostModel& model, double reach_m, double budget_mb, const std::string& vegetation) {
  const RasterHeader& h = dem.header();
  if (!(budget_mb > 0)) throw bad_input("the memory limit leaves nothing for the roads' windows once the process is counted");
  const double sea_level = scenario.resolved["water"]["sea_level_m"].get<double>();
  const double budget = std::max(0.0, budget_mb) * 1e6;
  RoadWindows out;
  out.grid = {georef, h.cols, h.rows, false};
  roads::WaterCount count;  // by bands of an eighth of the budget, at 4 bytes a cell
  const int band = int(std::clamp(budget / 8 / (4.0 * h.cols), 1.0, double(h.rows)));
  for (int r = 0; r < h.rows; r += band) count.add(dem.read(0, r, h.cols, std::min(band, h.rows - r)), sea_level);
  out.grid.bathymetry = count.bathymetry();
  // The vegetation layer: 4 bytes a cell held, 4 more while it is warped.
  out.window.max_cells = std::size_t(0.5 * budget / (roads::kWindowBytesPerCell + (vegetation.empty() ? 0 : 8)));
  out.max_nodes = std::size_t(0.5 * budget / roads::kSearchBytesPerNode);
  // The road radius in the grid's smallest cells, as a TerrainField of the grid counts it.
  out.window.margin_cells = roads::window_margin_cells(model.road_radius_m, reach_m, roads::TerrainField::frame(out.grid).min_cell_m());
  std::optional<WarpScale> scale;  // the whole grid's (add_road_layers): each window's warp is the grid's
  if (!vegetation.empty()) scale = warp_scale(vegetation, georef, h.cols, h.rows);
  out.read = [&dem, &lakes, grid = out.grid, sea_level, model, vegetation, scale](int c0, int r0, int cols, int rows) {
    const Dem window = dem.read(c0, r0, cols, rows);
    const Raster<std::uint8_t> mask = saved_water_mask(lakes.read(c0, r0, cols, rows));
    roads::TerrainField t(window, c0, r0, grid, sea_level, model.unknown_water_depth_m, model.road_radius_m, &mask);
    if (scale) t.set_vegetation(read_resampled(vegetation, window.georef(), cols, rows, Resampling::bilinear, 1, &*scale));
    return t;
  };
  return out;
}

void add_road_layers(roads::TerrainField& terrain, const RoadsSettings& settings, const plugin::PluginSet& plugins, const Dem& dem,
                     Progress& progress, const Log& log) {
  if (!settings.vegetation.empty()) {
    // One kernel over the grid (warp_scale), as on the windows of a run by tiles (road_windows).
    const WarpScale scale = warp_scale(settings.vegetation, dem.georef(), dem.cols(), dem.rows());
    terrain.set_vegetation(read_resampled(settings.vegetation, dem.georef(), dem.cols(), dem.rows(), Resampling::bilinear, 1, &scale));
  }
  plugin::add_to_terrain(plugin::road_terms(plugins, dem, progress, log), terrain);
}

}  // namespace terrapolis::pipeline
