// Each stage's options from a resolved scenario.
// SPDX-License-Identifier: MIT
#include "pipeline/stage_options.hpp"

#include <algorithm>
#include <filesystem>
#include <functional>
#include <iterator>
#include <map>

#include "core/error.hpp"
#include "density/boosted.hpp"
#include "hydro/option_names.hpp"
#include "io/mask_io.hpp"
#include "io/raster_io.hpp"

namespace terrapolis::pipeline {
namespace {

using json = nlohmann::ordered_json;

/// The schema's enum already restricted the value: an unknown one is a programming error.
template <class E>
E choice(const json& value, const std::map<std::string, E>& choices) {
  return choices.at(value.get<std::string>());
}

}  // namespace

hydro::HydroOptions hydro_options(const Scenario& scenario) {
  using namespace hydro;
  const json& h = scenario.resolved["hydro"];
  HydroOptions o;
  o.fill = choice(h["fill"], kFillMethods);
  o.flow = choice(h["flow"], kFlowMethods);
  o.mfd_exponent = h["mfd_exponent"].get<double>();
  o.hydrometry.method = choice(h["hydrometry"], kHydrometryMethods);
  o.hydrometry.max_iterations = h["iterations"].get<int>();
  o.hydrometry.threshold = h["threshold"].get<double>();
  o.hydrometry.vertical = choice(h["vertical"], kVerticalScales);
  o.hydrometry.share = choice(h["belhadj_share"], kBelhadjShares);
  o.streams.threshold_km2 = h["streams_threshold_km2"].get<double>();
  // The sea drains the land: its cells are outlets for every step (density treats them as water).
  o.sea_level = scenario.resolved["water"]["sea_level_m"].get<double>();
  return o;
}

std::optional<hydro::RiverTypeOptions> river_type_options(const Scenario& scenario) {
  const json& h = scenario.resolved["hydro"];
  if (!h["classify"].get<bool>()) return std::nullopt;
  hydro::RiverTypeOptions o;
  o.braided_discharge_m3s = h["braided_discharge_m3s"].get<double>();
  o.delta_discharge_m3s = h["delta_discharge_m3s"].get<double>();
  o.coast_distance_km = h["coast_distance_km"].get<double>();
  return o;
}

lake::LakeSpec reservoir_spec(const json& r) {
  lake::LakeSpec spec;
  spec.lon = r["at"][0].get<double>();
  spec.lat = r["at"][1].get<double>();
  if (r.contains("level_m")) spec.level_m = r["level_m"].get<double>();
  if (r.contains("depth_m")) spec.depth_m = r["depth_m"].get<double>();
  if (r.contains("crest_m")) spec.crest_m = r["crest_m"].get<double>();
  if (r.contains("dam"))
    for (const json& p : r["dam"]) spec.dam_lonlat.push_back({p[0].get<double>(), p[1].get<double>()});
  return spec;
}

std::vector<lake::LakeSpec> reservoir_specs(const Scenario& scenario) {
  std::vector<lake::LakeSpec> out;
  for (const json& r : scenario.resolved["water"]["reservoirs"]) {
    const lake::LakeSpec spec = reservoir_spec(r);
    try {
      lake::check_spec(spec);
    } catch (const Error& e) {
      throw Error(e.kind(), "/water/reservoirs/" + std::to_string(out.size()) + e.what());
    }
    out.push_back(std::move(spec));
  }
  return out;
}

InlandWaterSettings inland_water_settings(const Scenario& scenario) {
  return {flat_water_options(scenario), scenario.path("/water/water_mask"), reservoir_specs(scenario)};
}

bool TileSettings::tiled(const std::string& dem_path) const {
  return tile_size > 0 || memory_limit_mb > 0 || std::filesystem::is_directory(dem_path);
}

TileSettings tile_settings(const Scenario& scenario) {
  const json& in = scenario.resolved["input"];
  TileSettings t{in["tile_size"].get<int>(), in["memory_limit_mb"].get<double>()};
  if (t.tile_size != 0 && t.tile_size < 8) throw bad_input("/input/tile_size: must be at least 8 cells");
  return t;
}

hydro::D8Codes d8_codes(const Scenario& scenario) {
  return choice(scenario.resolved["hydro"]["d8_codes"], hydro::kD8Codes);
}

density::DensityOptions density_options(const Scenario& scenario) {
  const json& w = scenario.resolved["water"];
  const json& d = scenario.resolved["density"];
  density::DensityOptions o;
  o.sea_level_m = w["sea_level_m"].get<double>();
  o.nodata_is_sea = w["nodata_is_sea"].get<bool>();
  o.max_altitude_m = d["max_altitude_m"].get<double>();
  // 90 degrees and a cap of 1 exclude nothing: the schema's "off" values.
  if (const double slope = d["max_slope_deg"].get<double>(); slope < 90) o.max_slope_deg = slope;
  if (const double cap = d["river_bed_cap"].get<double>(); cap < 1) o.river_bed_cap = cap;
  o.r_min_m = d["r_min_m"].get<double>();
  o.r_max_m = d["r_max_m"].get<double>();
  o.plateau_min_m = d["plateau_min_m"].get<double>();
  o.plateau_max_m = d["plateau_max_m"].get<double>();
  o.plain_max_variation_m = d["plain_max_variation_m"].get<double>();
  const json& weights = d["weights"];
  o.weights = {weights["coast"].get<double>(), weights["hydrometry"].get<double>(), weights["plateau"].get<double>(),
               weights["plain"].get<double>()};
  for (std::size_t k = 0; k < density::kTerrainTerms.size(); ++k) o.terrain_weights[k] = weights[density::kTerrainTerms[k]].get<double>();
  std::vector<double> layer_weights;
  for (const auto& layer : d["layers"]) layer_weights.push_back(layer["weight"].get<double>());
  if (const std::string model = scenario.path("/density/model"); !model.empty()) {
    try {  // read and checked now: a run refuses a bad model file before any stage
      o.model = std::make_shared<const density::BoostedModel>(density::BoostedModel::load(model));
    } catch (const Error& e) {
      throw Error(e.kind(), std::string("/density/model: ") + e.what());
    }
  }
  density::check_settings(o, layer_weights);
  return o;
}

namespace {
/// read_density_files on `grid`, the whole grid (`whole` null) or a window of the grid `whole` describes.
void read_density_files(const Scenario& scenario, const Georef& grid, int cols, int rows, const std::vector<LayerOnGrid>* whole,
                        const std::string& water_mask, density::DensityOptions& o) {
  const json& d = scenario.resolved["density"];
  std::vector<density::DensityOptions::Factor> layers;
  for (std::size_t k = 0; k < d["layers"].size(); ++k) {
    const json& layer = d["layers"][k];
    const std::string file = scenario.file(layer["file"].get<std::string>());
    const WarpScale scale = whole ? (*whole)[k].scale : warp_scale(file, grid, cols, rows);
    Raster<float> values = read_resampled(file, grid, cols, rows, Resampling::bilinear, 1, &scale);
    if (whole) density::to_unit_range(values, (*whole)[k].range);
    else density::to_unit_range(values);
    layers.push_back({std::filesystem::path(file).filename().string(), std::move(values), layer["weight"].get<double>()});
  }
  o.factors.insert(o.factors.begin(), std::make_move_iterator(layers.begin()), std::make_move_iterator(layers.end()));
  for (const auto& file : d["exclusions"])
    o.exclusion_masks.push_back(read_mask(scenario.file(file.get<std::string>()), grid, cols, rows));
  if (!water_mask.empty()) o.water_mask = read_mask(water_mask, grid, cols, rows);
}
}  // namespace

void read_density_files(const Scenario& scenario, const Dem& dem, const std::string& water_mask, density::DensityOptions& o) {
  read_density_files(scenario, dem.georef(), dem.cols(), dem.rows(), nullptr, water_mask, o);
}

void read_density_files(const Scenario& scenario, const Georef& window, int cols, int rows, const std::vector<LayerOnGrid>& layers,
                        const std::string& water_mask, density::DensityOptions& o) {
  read_density_files(scenario, window, cols, rows, &layers, water_mask, o);
}

std::vector<LayerOnGrid> layers_on_grid(const Scenario& scenario, const Georef& grid, int cols, int rows) {
  std::vector<LayerOnGrid> out;
  for (const auto& layer : scenario.resolved["density"]["layers"]) {
    const std::string file = scenario.file(layer["file"].get<std::string>());
    LayerOnGrid& l = out.emplace_back();
    l.scale = warp_scale(file, grid, cols, rows);
    read_resampled_by_bands(file, grid, cols, rows, Resampling::bilinear, &l.scale, [&](const Raster<float>& band, int) { l.range.add(band); });
  }
  return out;
}

double least_side_angle(const std::string& map, const RasterHeader& grid) {
  float least = 90;
  read_resampled_by_bands(map, grid.georef, grid.cols, grid.rows, Resampling::nearest, nullptr, [&](const Raster<float>& angles, int) {
    for (const float a : angles.values())
      if (a > 0 && a < 90) least = std::min(least, a);
  });
  return least < 90 ? least : 0.0;
}

std::vector<std::string> density_files(const Scenario& scenario) {
  const json& d = scenario.resolved["density"];
  std::vector<std::string> files = {scenario.path("/water/water_mask"), scenario.path("/density/model")};
  for (const auto& layer : d["layers"]) files.push_back(scenario.file(layer["file"].get<std::string>()));
  for (const auto& file : d["exclusions"]) files.push_back(scenario.file(file.get<std::string>()));
  return files;
}

sites::SitesOptions sites_options(const Scenario& scenario) {
  const json& s = scenario.resolved["sites"];
  sites::SitesOptions o;
  o.seed = scenario.resolved["seed"].get<std::uint64_t>();
  o.mode = s["mode"] == "manhattan" ? sites::SitesOptions::Mode::manhattan : sites::SitesOptions::Mode::paris;
  o.disc_test = s["disc_test"] == "perimeter" ? sites::SitesOptions::DiscTest::perimeter : sites::SitesOptions::DiscTest::exact;
  o.candidates = s["candidates"].get<int>();
  o.r_min_m = s["r_min_m"].get<double>();
  o.r_max_m = s["r_max_m"].get<double>();
  o.dr_min_m = s["dr_min_m"].get<double>();
  o.u_min = s["u_min"].get<double>();
  o.u_max = s["u_max"].get<double>();
  o.x_max = s["x_max"].get<double>();
  o.p = s["p"].get<double>();
  o.people_per_m = s["people_per_m"].get<double>();
  o.quota_scale = s["quota_scale"].get<double>();
  o.refill_rounds = s["refill_rounds"].get<int>();
  o.quotas = s["quotas"] == "belhadj2007" ? sites::SitesOptions::Quotas::belhadj2007 : sites::SitesOptions::Quotas::rank_size;
  o.population = s["population"].get<double>();
  o.people_per_km2 = s["people_per_km2"].get<double>();
  o.urban_share = s["urban_share"].get<double>();
  o.sizes = s["sizes"] == "rank_size" ? sites::SitesOptions::Sizes::rank_size : sites::SitesOptions::Sizes::catchment;
  o.zipf_exponent = s["zipf_exponent"].get<double>();
  o.min_population = s["min_population"].get<double>();
  o.spacing_km = s["spacing_km"].get<double>();
  o.min_distance_share = s["min_distance_share"].get<double>();
  o.area_exponent = s["area_exponent"].get<double>();
  o.town_density_per_km2 = s["town_density_per_km2"].get<double>();
  o.influence_factor = s["influence_factor"].get<double>();
  o.growth = s["growth"].get<double>();
  o.growth_new_share = s["growth_new_share"].get<double>();
  sites::check_settings(o);
  if (o.growth > 0 && s["existing"].get<std::string>().empty()) throw bad_input("/sites/growth: needs /sites/existing, the places that grow");
  if (!s["existing"].get<std::string>().empty() && o.quotas == sites::SitesOptions::Quotas::belhadj2007)
    throw bad_input("/sites/existing: needs /sites/quotas rank_size (the census table of belhadj2007 has no room for given places)");
  return o;
}

Raster<std::uint8_t> river_cells(const Raster<float>& accumulation_km2, const Scenario& scenario) {
  const double threshold_m2 = scenario.resolved["hydro"]["streams_threshold_km2"].get<double>() * 1e6;
  Raster<std::uint8_t> rivers = accumulation_km2.like<std::uint8_t>(0);
  for (std::size_t i = 0; i < rivers.size(); ++i) rivers[i] = double(accumulation_km2[i]) * 1e6 >= threshold_m2 ? 1 : 0;  // NaN: not a river
  return rivers;
}

erode::ErodeOptions erode_options(const Scenario& scenario) {
  const json& e = scenario.resolved["erode"];
  erode::ErodeOptions o;
  const std::string process = e["process"].get<std::string>();
  o.process = process == "hydraulic" ? erode::Process::hydraulic
              : process == "thermal"  ? erode::Process::thermal
              : process == "layered"  ? erode::Process::layered
                                      : erode::Process::both;
  o.iterations = e["iterations"].get<int>();
  o.hydraulic.rain_m = e["rain_m"].get<double>();
  o.hydraulic.capacity_s = e["capacity_s"].get<double>();
  o.hydraulic.dissolve = e["dissolve"].get<double>();
  o.hydraulic.deposit = e["deposit"].get<double>();
  o.hydraulic.evaporation = e["evaporation"].get<double>();
  o.hydraulic.dt_s = e["dt_s"].get<double>();
  const double angle = e["angle_deg"].get<double>();
  o.thermal.angle_deg = angle > 0 ? angle : erode::material_angle_deg(e["material"].get<std::string>());
  o.layered.erodibility = e["erodibility"].get<double>();
  o.layered.voxel_m = e["voxel_m"].get<double>();
  o.layered.radius_m = e["radius_m"].get<double>();
  o.layered.strata_m = e["strata_m"].get<double>();
  o.layered.hard_ratio = e["hard_ratio"].get<double>();
  erode::check_settings(o);
  return o;
}

skeleton::SkeletonOptions skeleton_options(const Scenario& scenario) {
  const json& k = scenario.resolved["skeleton"];
  skeleton::SkeletonOptions o;
  const std::string lines = k["lines"].get<std::string>();
  o.lines = lines == "ridges" ? skeleton::Lines::ridges : lines == "valleys" ? skeleton::Lines::valleys : skeleton::Lines::both;
  o.tolerance = k["tolerance"].get<double>();
  o.seed_share = k["seed_share"].get<double>();
  o.min_cells = k["min_cells"].get<int>();
  o.lattice = k["lattice"].get<int>();
  o.line_step = k["line_step"].get<int>();
  return o;
}

network::NetworkOptions network_options(const Scenario& scenario) {
  network::NetworkOptions o;
  o.k = scenario.resolved["network"]["k"].get<double>();
  return o;
}

RoadsSettings roads_settings(const Scenario& scenario) {
  const json& r = scenario.resolved["roads"];
  RoadsSettings s;
  const std::string costs = scenario.path("/roads/costs");
  try {
    s.model = costs.empty() ? roads::default_cost_model() : roads::load_cost_model(costs);
  } catch (const Error& e) {  // the file's errors name it and the key; the scenario's reader needs the setting
    throw Error(e.kind(), "/roads/costs: " + std::string(e.what()));
  }
  if (!r["bridges"].get<bool>()) s.model.bridge.enabled = false;
  if (!r["tunnels"].get<bool>()) s.model.tunnel.enabled = false;
  const std::uint64_t seed = scenario.resolved["seed"].get<std::uint64_t>();
  s.routing.router = r["router"] == "bezier" ? roads::Router::bezier : roads::Router::galin;
  s.routing.graph = {r["k"].get<int>(), r["angles"].get<int>(), seed};
  s.routing.bezier.seed = seed;
  s.routing.bezier.max_evaluations = r["bezier_evaluations"].get<int>();
  s.routing.bezier.threshold = r["bezier_threshold"].get<double>();
  s.routing.bezier.tries = r["bezier_tries"].get<int>();
  s.vegetation = scenario.path("/roads/vegetation");
  s.existing = scenario.path("/roads/existing");
  s.routing.max_seconds = r["max_seconds"].get<double>();
  for (std::size_t c = 0; c < s.routing.reuse_discount.size(); ++c) {
    const std::string name(roads::name_of(roads::RoadClass(c)));
    s.routing.reuse_discount[c] = r["reuse_discount"][name].get<double>();
    s.routing.max_grade_pct[c] = r["max_grade_pct"][name].get<double>();
    s.routing.min_radius_m[c] = r["min_radius_m"][name].get<double>();
  }
  s.routing.redundant_share = r["redundant_share"].get<double>();
  return s;
}

CorridorSettings corridor_settings(const Scenario& scenario) {
  const json& c = scenario.resolved["roads"]["corridor"];
  CorridorSettings s;
  s.options.half_width_m = c["half_width_m"].get<double>();
  for (std::size_t k = 0; k < s.options.widths.size(); ++k) {
    const std::string name(roads::name_of(roads::RoadClass(k)));
    s.options.widths[k] = {c["carriageway_m"][name].get<double>(), c["platform_m"][name].get<double>()};
    if (s.options.widths[k].platform_m < s.options.widths[k].carriageway_m)
      throw bad_input("/roads/corridor/platform_m/" + name + ": narrower than /roads/corridor/carriageway_m/" + name);
  }
  s.enabled = c["enabled"].get<bool>();
  const double angle = c["side_angle_deg"].get<double>();
  s.options.side_angle_deg = angle > 0 ? angle : roads::repose_angle_deg(c["material"].get<std::string>());
  s.options.max_height_m = c["max_height_m"].get<double>();
  s.side_angles = scenario.path("/roads/corridor/side_angles");
  return s;
}

hydro::FlatWaterOptions flat_water_options(const Scenario& scenario) {
  const json& w = scenario.resolved["water"];
  hydro::FlatWaterOptions o;
  o.min_area_km2 = w["flat_water_min_km2"].get<double>();
  o.tolerance_m = w["flat_water_tolerance_m"].get<double>();
  o.sea_level_m = w["sea_level_m"].get<double>();
  return o;
}

void check_file(const std::string& pointer, const std::string& path) {
  std::error_code ec;
  if (path.empty() || path.starts_with("/vsi") || std::filesystem::is_regular_file(path, ec)) return;
  throw bad_input(pointer + ": " + path + ": no such file");
}

AccessSettings access_settings(const Scenario& scenario) {
  const json& a = scenario.resolved["access"];
  AccessSettings s;
  s.enabled = a["enabled"].get<bool>();
  s.options.walk_factor = a["walk_factor"].get<double>();
  s.options.knight_moves = a["knight_moves"].get<bool>();
  for (std::size_t k = 0; k < roads::kRoadClasses.size(); ++k)
    s.options.road_kmh[k] = a["road_kmh"][std::string(roads::kRoadClasses[k].name)].get<double>();
  s.thresholds_minutes = a["thresholds_minutes"].get<std::vector<double>>();
  s.levels_population = a["levels_population"].get<std::vector<double>>();
  std::sort(s.thresholds_minutes.begin(), s.thresholds_minutes.end());
  std::sort(s.levels_population.begin(), s.levels_population.end());
  if (std::adjacent_find(s.thresholds_minutes.begin(), s.thresholds_minutes.end()) != s.thresholds_minutes.end())
    throw bad_input("/access/thresholds_minutes: a threshold is given twice");
  if (std::adjacent_find(s.levels_population.begin(), s.levels_population.end()) != s.levels_population.end())
    throw bad_input("/access/levels_population: a level is given twice");
  return s;
}


}  // namespace terrapolis::pipeline
