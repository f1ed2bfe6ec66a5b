// The stages of a run: each one calls its module and writes its files with provenance.
// SPDX-License-Identifier: MIT
#include "pipeline/stages.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <mutex>
#include <optional>

#include "core/error.hpp"
#include "core/geodesy.hpp"
#include "density/tiled_density.hpp"
#include "hydro/catchment.hpp"
#include "hydro/tiled/tiled_hydro.hpp"
#include "pipeline/by_tiles.hpp"
#include "io/mask_io.hpp"
#include "io/raster_io.hpp"
#include "network/layers.hpp"
#include "pipeline/density_folder.hpp"
#include "pipeline/hillshade.hpp"
#include "pipeline/inland_water.hpp"
#include "pipeline/places.hpp"
#include "pipeline/realism.hpp"
#include "pipeline/stage_options.hpp"
#include "roads/existing_roads.hpp"
#include "roads/road_network.hpp"
#include "roads/terrain_field.hpp"
#include "roads/windowed_route.hpp"
#include "sites/layers.hpp"

namespace terrapolis::pipeline {
namespace {

using json = nlohmann::ordered_json;
using Settings = StageSettings;

double round_to(double v, double step) { return std::round(v / step) * step; }

std::string saved(const RunState& s, const std::string& name) { return (s.folder / name).string(); }

/// Runs a check of the file a setting names, its errors prefixed by the setting's pointer (they
/// name the file, which may itself start with '/').
template <class Check>
void named(const std::string& pointer, Check&& check) {
  try {
    check();
  } catch (const Error& e) {
    throw Error(e.kind(), pointer + ": " + e.what());
  }
}

// ---- terrain -------------------------------------------------------------------------------

/// The altitudes' range and cells with data, gathered over the DEM or its tiles.
struct AltitudeRange {
  double lo = 1e300, hi = -1e300;
  std::size_t valid = 0;
  void add(const Dem& dem) {
    for (float v : dem.values()) {
      if (std::isnan(v)) continue;
      lo = std::min(lo, double(v));
      hi = std::max(hi, double(v));
      ++valid;
    }
  }
  json figures(const RasterHeader& g) const {
    return {{"cols", g.cols}, {"rows", g.rows}, {"min_m", lo}, {"max_m", hi}, {"nodata_share", 1.0 - double(valid) / (double(g.cols) * double(g.rows))}};
  }
};

/// The tiles of the terrain stage of a run by tiles: given, or sized to the memory limit as the
/// density's windows are (their state per cell covers the DEM and its hillshade), with a halo of `halo` cells.
hydro::tiled::TileGrid run_tiles(const RunState& s, int halo) {
  const TiledInput& in = *s.by_tiles;
  const int side = in.tiles.tile_size > 0 ? in.tiles.tile_size
                                          : density::density_tile_size_for(s.grid.cols, s.grid.rows, halo, halo, 0, in.tiles.limit_mb(), in.reserved_mb);
  return hydro::tiled::TileGrid(s.grid.cols, s.grid.rows, side);
}

/// The terrain by tiles: each tile read with a one-cell halo for its hillshade.
void terrain_run_tiles(RunState& s, Progress& progress) {
  s.by_tiles->reserve();
  const DemWindowReader reader(s.by_tiles->dem_path, s.by_tiles->read);
  const hydro::tiled::TileGrid grid = run_tiles(s, 1);
  const MosaicFiles elevation = s.mosaic("elevation"), shade = s.mosaic("hillshade");
  elevation.create();
  shade.create();
  AltitudeRange range;
  const CellMetrics metrics = cell_metrics(s.grid.georef, s.grid.cols, s.grid.rows);  // the whole grid's rows: a window's may differ in the last bit
  ProgressStep step(progress, "terrain by tiles");
  for (int t = 0; t < grid.count(); ++t) {
    const hydro::tiled::TileRect r = grid.rect(t), w = grid.grown(t, 1, 1);
    const Dem window = reader.read(w.col0, w.row0, w.cols, w.rows);
    const Dem z = hydro::tiled::crop(window, r.col0 - w.col0, r.row0 - w.row0, r.cols, r.rows);
    s.write_tile("terrain", elevation, t, grid.across(), z);
    const Raster<std::uint8_t> shaded = hillshade(window, metric_rows(metrics, w.row0, w.rows));
    s.write_tile("terrain", shade, t, grid.across(), hydro::tiled::crop(shaded, r.col0 - w.col0, r.row0 - w.row0, r.cols, r.rows));
    range.add(z);
    step.update(double(t + 1) / grid.count());
  }
  s.write_mosaic("terrain", elevation, grid.count(), grid.across(), Style::elevation);
  s.write_mosaic("terrain", shade, grid.count(), grid.across(), Style::hillshade);
  s.summary["terrain"] = range.figures(s.grid);
}

void terrain_run(RunState& s, Progress& progress, const Log&) {
  if (s.by_tiles) return terrain_run_tiles(s, progress);
  s.write("terrain", "elevation.tif", s.dem, Style::elevation);
  s.write("terrain", "hillshade.tif", hillshade(s.dem), Style::hillshade);
  AltitudeRange range;
  range.add(s.dem);
  s.summary["terrain"] = range.figures(s.grid);
}

void terrain_load(RunState&) {}  // the DEM is always read from the input

void terrain_prepare(const Scenario& scenario, const RasterHeader&, Settings&) { tile_settings(scenario); }

void terrain_summary(const json& figures, SummaryText& out) {
  const json& t = figures["terrain"];
  out.line("  terrain  %d x %d cells, %.0f .. %.0f m, %.1f%% nodata\n", t["cols"].get<int>(), t["rows"].get<int>(), t["min_m"].get<double>(),
           t["max_m"].get<double>(), 100 * t["nodata_share"].get<double>());
}

// ---- inland water (docs/lakes.md, docs/roads.md) -----------------------------------------

constexpr const char* kInlandWater = "inland_water.tif";

void inland_water_figures(RunState& s, std::size_t flat_lakes, double flat_lake_km2);

/// The inland water (pipeline::inland_water) as inland_water.tif, which the density, the roads and
/// the access stages read back.
void write_inland_water(RunState& s, Progress& progress, const Log& log) {
  InlandWater water = inland_water(s.dem, s.settings.water, progress, log);
  s.write("hydro", kInlandWater, water.mask, Style::water);
  inland_water_figures(s, water.flat_lakes, water.flat_lake_km2);
  if (!water.reservoirs.empty()) s.summary["hydro"]["reservoirs"] = std::move(water.reservoirs);
}

// ---- hydro (Belhadj 2007 §4.2.2; Barnes et al. 2014; docs/hydro.md) ----------------------

/// The flow directions' metadata: their code convention.
std::vector<std::pair<std::string, std::string>> d8_metadata(const RunState& s) {
  return {{"D8_CODES", s.scenario.resolved["hydro"]["d8_codes"].get<std::string>()}, {"D8_CODES_DESCRIPTION", hydro::describe(s.settings.d8_codes)}};
}

/// The upstream area in km2 as accumulation.tif holds it (from m2), and its largest value.
Raster<float> area_km2(const Raster<double>& accumulation_m2, double& largest_km2) {
  Raster<float> area = accumulation_m2.like<float>(NAN);
  for (std::size_t i = 0; i < area.size(); ++i) {
    area[i] = float(accumulation_m2[i] * 1e-6);
    if (!std::isnan(area[i])) largest_km2 = std::max(largest_km2, double(area[i]));
  }
  return area;
}

json hydro_figures(const VectorLayer& streams, double largest_km2, int belhadj_iterations) {
  const int f_order = streams.field_index("strahler"), f_length = streams.field_index("length_m");
  std::int64_t max_order = 0;
  double length_m = 0;
  for (const auto& f : streams.features) {
    max_order = std::max(max_order, std::get<std::int64_t>(f.values[std::size_t(f_order)]));
    length_m += std::get<double>(f.values[std::size_t(f_length)]);
  }
  return {{"stream_reaches", streams.features.size()},
          {"stream_length_km", round_to(length_m / 1000, 0.01)},
          {"max_strahler", max_order},
          {"largest_catchment_km2", round_to(largest_km2, 0.01)},
          {"belhadj_iterations", belhadj_iterations}};
}

void inland_water_figures(RunState& s, std::size_t flat_lakes, double flat_lake_km2) {
  s.summary["hydro"]["flat_lakes"] = flat_lakes;
  s.summary["hydro"]["flat_lake_km2"] = round_to(flat_lake_km2, 0.01);
}

/// The hydro stage by tiles (docs/scale.md): the tile engine's fill, directions, accumulation and
/// streams, then Belhadj's hydrometry and the inland water by tiles.
void hydro_run_tiles(RunState& s, Progress& progress, const Log& log) {
  s.by_tiles->reserve();
  const TiledInput& in = *s.by_tiles;
  const hydro::HydroOptions& options = s.settings.hydro;
  const DemWindowReader reader(in.dem_path, in.read);
  const RasterHeader& g = s.grid;
  const ScratchFolder scratch((s.folder / ".scratch").string());
  hydro::tiled::TiledOptions o;
  o.memory_limit_mb = in.tiles.limit_mb();
  o.reserved_mb = in.reserved_mb;
  o.sea_level = options.sea_level;
  o.streams_threshold_m2 = options.streams.threshold_km2 * 1e6;
  o.concurrent_tiles = hydro::tiled::allowed_threads();
  o.scratch_dir = scratch.path();
  o.tile_size = in.tiles.tile_size > 0 ? in.tiles.tile_size
                                       : hydro::tiled::tile_size_for(g.cols, g.rows, o.memory_limit_mb, o.concurrent_tiles, in.reserved_mb);
  const int across = hydro::tiled::TileGrid(g.cols, g.rows, o.tile_size).across();
  const MosaicFiles filled = s.mosaic("filled"), flowdir = s.mosaic("flowdir"), accumulation = s.mosaic("accumulation");
  for (const MosaicFiles* m : {&filled, &flowdir, &accumulation}) m->create();
  std::mutex largest_lock;
  double largest_km2 = 0;
  VectorLayer streams;
  hydro::tiled::TileSinks sinks;
  sinks.filled = [&](int t, const Dem& z) { s.write_tile("hydro", filled, t, across, z); };
  sinks.d8 = [&](int t, const Raster<std::uint8_t>& d8) { s.write_tile("hydro", flowdir, t, across, hydro::encode_d8(d8, s.settings.d8_codes), d8_metadata(s)); };
  sinks.accumulation = [&](int t, const Raster<double>& m2) {
    double largest = 0;
    s.write_tile("hydro", accumulation, t, across, area_km2(m2, largest), {{"UNIT", "km2"}});
    const std::lock_guard<std::mutex> lock(largest_lock);
    largest_km2 = std::max(largest_km2, largest);
  };
  sinks.streams = [&](hydro::StreamCells& cells) {
    streams = hydro::streams_of_cells(cells, g.georef, cell_metrics(g.georef, g.cols, g.rows), progress);
    cells = {};
  };
  hydro::tiled::LocalTiles here;
  const hydro::tiled::TiledReport report = hydro::tiled::run_tiled_hydro(
      g.cols, g.rows, g.georef, [&](int c0, int r0, int cols, int rows) { return reader.read(c0, r0, cols, rows); }, o, sinks, progress, here);
  s.write_mosaic("hydro", filled, report.tiles, across, Style::elevation);
  s.write_mosaic("hydro", flowdir, report.tiles, across, Style::flow_direction);
  s.write_mosaic("hydro", accumulation, report.tiles, across, Style::accumulation);
  if (const auto& types = s.settings.river_types) hydro::classify_streams(streams, DemWindowReader(filled.vrt()), g.georef, options.sea_level, *types);
  s.write("hydro", "streams.geojson", streams, Style::streams);
  json figures = hydro_figures(streams, largest_km2, 0);
  streams = {};
  const MosaicFiles hydrometry = s.mosaic("hydrometry");
  hydrometry.create();
  const hydro::tiled::TiledBelhadjReport b = hydrometry_by_tiles(
      reader, options, in.tiles, in.reserved_mb, scratch.path(),
      [&](int t, int n, const Raster<float>& tile) { s.write_tile("hydro", hydrometry, t, n, tile); }, progress);
  s.write_mosaic("hydro", hydrometry, b.tiles, b.across, Style::unit_ramp);
  figures["belhadj_iterations"] = b.iterations;
  s.summary["hydro"] = figures;
  log.detail("hydro tiles: " + std::to_string(report.tiles) + " of " + std::to_string(report.tile_size) + " cells a side; " + describe(b));
  const MosaicFiles water = s.mosaic(std::filesystem::path(kInlandWater).stem().string());
  water.create();
  const WindowReservoirs reservoirs(reader, s.settings.water, in.tiles.limit_mb() - in.reserved_mb, progress, log);
  const hydro::tiled::TiledFlatWaterReport w = inland_water_by_tiles(
      reader, s.settings.water, in.tiles, reservoirs, in.reserved_mb,
      [&](int t, int n, const Raster<std::uint8_t>& tile) { s.write_tile("hydro", water, t, n, tile); }, progress);
  s.write_mosaic("hydro", water, w.tiles, w.across, Style::water);
  inland_water_figures(s, w.lakes, w.area_km2);
  if (!reservoirs.figures().empty()) s.summary["hydro"]["reservoirs"] = reservoirs.figures();
  log.detail(describe(w));
}

void hydro_run(RunState& s, Progress& progress, const Log& log) {
  if (s.by_tiles) return hydro_run_tiles(s, progress, log);
  const hydro::HydroOptions& options = s.settings.hydro;
  hydro::HydroResult r = hydro::run_hydro(s.dem, options, progress);
  if (const auto& types = s.settings.river_types) hydro::classify_streams(r.streams, r.filled, options.sea_level, *types);
  s.write("hydro", "filled.tif", r.filled, Style::elevation);
  s.write("hydro", "flowdir.tif", hydro::encode_d8(r.d8, s.settings.d8_codes), Style::flow_direction, d8_metadata(s));
  double largest_km2 = 0;
  const Raster<float> km2 = area_km2(r.accumulation, largest_km2);
  s.write("hydro", "accumulation.tif", km2, Style::accumulation, {{"UNIT", "km2"}});
  s.write("hydro", "hydrometry.tif", r.hydrometry, Style::unit_ramp);
  s.write("hydro", "streams.geojson", r.streams, Style::streams);
  s.summary["hydro"] = hydro_figures(r.streams, largest_km2, r.hydrometry_iterations);
  if (r.hydrometry_iterations > 0) log.detail("belhadj: " + std::to_string(r.hydrometry_iterations) + " iterations");
  s.hydrometry = std::move(r.hydrometry);
  write_inland_water(s, progress, log);
  s.rivers = river_cells(km2, s.scenario);
}

void hydro_load(RunState& s) {
  if (s.by_tiles) return;  // the density stage reads the hydrometry and the inland water by windows
  s.hydrometry = read_resampled(saved(s, "hydrometry.tif"), s.dem.georef(), s.dem.cols(), s.dem.rows(), Resampling::nearest);
  s.rivers = river_cells(read_resampled(saved(s, "accumulation.tif"), s.dem.georef(), s.dem.cols(), s.dem.rows(), Resampling::nearest), s.scenario);
}

void hydro_prepare(const Scenario& scenario, const RasterHeader&, Settings& s) {
  s.water = inland_water_settings(scenario);
  s.hydro = hydro_options(scenario);
  s.river_types = river_type_options(scenario);
  s.d8_codes = d8_codes(scenario);
  check_file("/water/water_mask", s.water.water_mask);
  if (!tile_settings(scenario).given()) return;
  // What the tile engine computes (docs/scale.md): Priority-Flood, D8, Belhadj's hydrometry, the flattened lakes.
  const json& h = scenario.resolved["hydro"];
  const auto refuse = [](const std::string& what) { throw bad_input(what + ": not computed on tiles yet (input.tile_size, input.memory_limit_mb)"); };
  if (s.hydro.fill != hydro::FillMethod::priority_flood) refuse("/hydro/fill " + h["fill"].get<std::string>());
  if (s.hydro.flow != hydro::FlowMethod::d8) refuse("/hydro/flow " + h["flow"].get<std::string>());
  if (s.hydro.hydrometry.method != hydro::HydrometryMethod::belhadj) refuse("/hydro/hydrometry " + h["hydrometry"].get<std::string>());
}

void hydro_summary(const json& figures, SummaryText& out) {
  const json& h = figures["hydro"];
  out.line("  hydro    %d stream reaches, %.1f km, Strahler up to %d, largest catchment %.1f km2\n", h["stream_reaches"].get<int>(),
           h["stream_length_km"].get<double>(), h["max_strahler"].get<int>(), h["largest_catchment_km2"].get<double>());
}

// ---- density (Belhadj 2007 §4.2; docs/density.md) -----------------------------------------

/// The density model's inputs: the settings, the scenario's layers and exclusions, the hydro
/// stage's inland water (which holds water.water_mask) and its rivers.
density::DensityOptions density_inputs(const Scenario& scenario, const Settings& settings, const Dem& dem, Raster<std::uint8_t> water,
                                       const std::optional<Raster<std::uint8_t>>& rivers) {
  density::DensityOptions options = settings.density;
  read_density_files(scenario, dem, "", options);
  options.water_mask = std::move(water);
  if (rivers) options.rivers = *rivers;
  return options;
}

/// The same in a run, the inland water read back from the hydro stage's inland_water.tif.
density::DensityOptions density_inputs(const RunState& s) {
  return density_inputs(s.scenario, s.settings, s.dem, read_mask(saved(s, kInlandWater), s.dem.georef(), s.dem.cols(), s.dem.rows()), s.rivers);
}

json density_figures(const RunState& s, const density::DensityStats& st) {
  const std::size_t land = st.known_cells - st.water_cells;
  return {{"buildable_land_share", land ? round_to(double(st.buildable_cells) / double(land), 1e-4) : 0.0},
          {"water_share", st.known_cells ? round_to(double(st.water_cells) / double(st.known_cells), 1e-4) : 0.0},
          {"mean_density", round_to(st.mean_density, 1e-4)},
          {"land_area_km2", land_area_figure(st)},
          {"preset", s.scenario.resolved["density"]["preset"]}};
}

/// The density's rasters: the three characteristics, the buildable mask, the density.
constexpr std::pair<const char*, Style> kDensityRasters[] = {
    {"coast", Style::unit_ramp}, {"plateau", Style::unit_ramp}, {"plain", Style::unit_ramp}, {"buildable", Style::mask}, {"density", Style::density}};

/// The density stage by tiles (density::run_tiled_density), reading the hydro stage's hydrometry
/// and inland water by windows.
void density_run_tiles(RunState& s, Progress& progress, const Log& log) {
  s.by_tiles->reserve();
  const TiledInput& in = *s.by_tiles;
  const RunDensityWindows windows(in.dem_path, in.read, s.folder.string(), s.scenario, s.settings.density);
  for (const auto& [name, style] : kDensityRasters) s.mosaic(name).create();
  const ScratchFolder scratch((s.folder / ".scratch").string());
  const density::TiledDensityReport report = density::run_tiled_density(
      s.grid.cols, s.grid.rows, s.grid.georef, windows.read(), windows.options(), in.tiles.tile_size, in.tiles.limit_mb(), scratch.path(),
      [&](int t, int across, const density::DensityResult& d) {
        const Raster<float>* floats[] = {&d.coast, &d.plateau, &d.plain};
        for (int k = 0; k < 3; ++k) s.write_tile("density", s.mosaic(kDensityRasters[k].first), t, across, *floats[k]);
        s.write_tile("density", s.mosaic("buildable"), t, across, d.buildable);
        s.write_tile("density", s.mosaic("density"), t, across, d.density);
      },
      progress, in.reserved_mb, density_file_bytes_per_cell(s.scenario));
  for (const auto& [name, style] : kDensityRasters) s.write_mosaic("density", s.mosaic(name), report.tiles, report.across, style);
  s.summary["density"] = density_figures(s, report.stats);
  log.detail("density tiles: " + std::to_string(report.tiles) + " of " + std::to_string(report.tile_size) + " cells a side, halo " +
             std::to_string(report.halo_cols) + " x " + std::to_string(report.halo_rows) + " cells");
}

void density_run(RunState& s, Progress& progress, const Log& log) {
  if (s.by_tiles) return density_run_tiles(s, progress, log);
  density::DensityOptions options = density_inputs(s);
  plugin::add_to_density(plugin::density_factors(s.plugins, s.dem, progress, log), options);
  density::DensityResult r = density::compute_density(s.dem, *s.hydrometry, options, progress);
  const Raster<float>* floats[] = {&r.coast, &r.plateau, &r.plain};
  for (int k = 0; k < 3; ++k) s.write("density", std::string(kDensityRasters[k].first) + ".tif", *floats[k], kDensityRasters[k].second);
  s.write("density", "buildable.tif", r.buildable, Style::mask);
  s.write("density", "density.tif", r.density, Style::density);
  s.summary["density"] = density_figures(s, r.stats);
  s.density = std::move(r.density);
  s.buildable = std::move(r.buildable);
}

void density_load(RunState& s) {
  if (s.by_tiles) return;  // no later stage runs on tiles yet
  DensityFolder saved_outputs = read_density_folder(s.folder.string());
  if (saved_outputs.density.cols() != s.dem.cols() || saved_outputs.density.rows() != s.dem.rows())
    throw bad_input(saved(s, "density.tif") + ": not on the DEM's grid");
  s.density = std::move(saved_outputs.density);
  s.buildable = std::move(saved_outputs.buildable);
}

void density_prepare(const Scenario& scenario, const RasterHeader& grid, Settings& s) {
  s.density = density_options(scenario);
  const json& density = scenario.resolved["density"];
  for (std::size_t i = 0; i < density["layers"].size(); ++i)
    check_file("/density/layers/" + std::to_string(i) + "/file", scenario.file(density["layers"][i]["file"].get<std::string>()));
  for (std::size_t i = 0; i < density["exclusions"].size(); ++i)
    check_file("/density/exclusions/" + std::to_string(i), scenario.file(density["exclusions"][i].get<std::string>()));
  density::raised_r_min(cell_metrics(grid.georef, grid.cols, grid.rows), s.density);  // r_max against r_min raised to this grid's cells
  if (!tile_settings(scenario).given()) return;
  if (!scenario.resolved["plugins"].empty()) throw bad_input("/plugins: not run on tiles yet");
}

void density_summary(const json& figures, SummaryText& out) {
  const json& d = figures["density"];
  out.line("  density  %.1f%% water, %.1f%% of the land buildable, mean density %.3f\n", 100 * d["water_share"].get<double>(),
           100 * d["buildable_land_share"].get<double>(), d["mean_density"].get<double>());
}

// ---- sites (Belhadj 2007 §4.3.1, Algorithms 13-15; docs/sites.md) --------------------------

/// A growth scenario's figures: the new people and where they went, each existing place's gain
/// (keyed by name, so that `compare` lines two runs up), the largest new settlements and the
/// existing place nearest each.
json growth_figures(const sites::SitesResult& r, const sites::SitesOptions& options, const Crs& crs) {
  std::vector<const sites::Site*> existing, created;
  for (const auto& site : r.sites) (site.existing ? existing : created).push_back(&site);
  const auto by_gain = [](const sites::Site* a, const sites::Site* b) { return a->gained > b->gained; };
  std::stable_sort(existing.begin(), existing.end(), by_gain);
  std::stable_sort(created.begin(), created.end(), by_gain);
  json gained = json::object();
  for (std::size_t k = 0; k < existing.size(); ++k) {
    const std::string base = existing[k]->name.empty() ? "place " + std::to_string(k + 1) : existing[k]->name;
    std::string key = base;
    for (int n = 2; gained.contains(key); ++n) key = base + " (" + std::to_string(n) + ")";
    gained[key] = existing[k]->gained;
  }
  json largest = json::object();
  for (std::size_t k = 0; k < std::min<std::size_t>(5, created.size()); ++k) {
    const sites::Site& c = *created[k];
    const sites::Site* near = nullptr;
    double near_m = INFINITY;
    for (const sites::Site* e : existing)
      if (const double d = crs_distance_m(crs, c.x, c.y, e->x, e->y); d < near_m) near_m = d, near = e;
    json entry = {{"people", c.population}, {"x", c.x}, {"y", c.y}};
    if (near) entry["near"] = near->name, entry["near_km"] = round_to(near_m / 1000, 0.1);
    largest[std::to_string(k + 1)] = entry;
  }
  return {{"share", options.growth},
          {"new_share", options.growth_new_share},
          {"people", r.growth_people},
          {"to_existing", r.growth_to_existing},
          {"new_settlements", created.size()},
          {"to_new_settlements", r.growth_to_new},
          {"gained", gained},
          {"new_largest", largest}};
}

/// The warnings of sites.existing, also in run.json: the places left out or moved (by name), a
/// population given below the places' people, a settled share the places already hold.
std::vector<std::string> existing_warnings(const ExistingPlaces& existing, const sites::SitesOptions& options, const sites::SitesResult& r) {
  std::vector<std::string> out = existing_place_warnings(existing);
  const std::string people = std::to_string(std::llround(r.existing_population));
  if (options.population > 0 && r.existing_population > options.population)
    out.push_back("sites.population (" + std::to_string(std::llround(options.population)) + ") is below the " + people +
                  " people of sites.existing: the region holds at least them");
  if (options.growth == 0 && r.existing_population >= std::round(options.urban_share * r.target_population) && r.settled_population > 0)
    out.push_back("sites.existing: the given places hold " + people + " people, the settled share (" +
                  std::to_string(std::llround(options.urban_share * r.target_population)) + ") or more: no settlement generated");
  return out;
}

void sites_run(RunState& s, Progress& progress, const Log& log) {
  sites::SitesOptions options = s.settings.sites;
  // The land of the density stage (water and nodata excluded), for the default population.
  if (s.summary.contains("density") && s.summary["density"].contains("land_area_km2"))
    options.land_area_km2 = s.summary["density"]["land_area_km2"].get<double>();
  const std::string existing_file = s.scenario.path("/sites/existing");
  // By tiles: the density stage's tiles read by bands and blocks within the memory limit.
  std::unique_ptr<sites::Land> land;
  if (s.by_tiles) {
    s.by_tiles->reserve();
    const TiledInput& in = *s.by_tiles;
    auto tiles = std::make_unique<LandTiles>(saved(s, "density.vrt"), saved(s, "buildable.vrt"), s.grid.georef, in.tiles, in.reserved_mb);
    log.detail("sites by tiles: bands of " + std::to_string(tiles->band_rows()) + " rows, " +
               std::to_string(int(in.tiles.limit_mb() - in.reserved_mb)) + " MB for the land's bands and blocks");
    land = std::move(tiles);
  } else {
    land = std::make_unique<sites::LandRasters>(*s.density, *s.buildable);
  }
  ExistingPlaces existing;
  if (!existing_file.empty()) {
    existing = read_existing_places(existing_file, *land);
    options.existing = existing.sites;
  }
  const sites::SitesResult r = sites::place_sites(*land, options, progress);
  const Crs& crs = s.grid.georef.crs;
  s.cities = sites::cities_layer(r, crs);
  s.write("sites", "cities.geojson", *s.cities, Style::cities);
  s.write("sites", "city_extents.geojson", sites::city_extents_layer(r, crs), Style::city_extents);
  std::map<int, int> per_class;
  std::int64_t population = 0;
  int roots = 0;
  for (const auto& site : r.sites) {
    ++per_class[site.radius_class];
    population += site.population;
    roots += site.parent < 0;
  }
  json classes = json::object();  // keyed by class so `compare` lines them up
  for (std::size_t k = 0; k < r.quotas.size(); ++k)
    if (per_class.count(int(k))) classes[std::to_string(k)] = {{"radius_m", r.quotas[k].radius_m}, {"cities", per_class[int(k)]}};
  s.summary["sites"] = {{"cities", r.sites.size()}, {"roots", roots}, {"suburbs", int(r.sites.size()) - roots},
                        {"population", population}, {"per_class", classes}};
  json& summary = s.summary["sites"];
  if (options.quotas == sites::SitesOptions::Quotas::rank_size) {
    char source[256];
    if (r.population_assumed)
      std::snprintf(source, sizeof source, "assumed: %.0f people/km2 (world average, World Bank 2020) x %.1f km2 of land", options.people_per_km2,
                    r.land_area_km2);
    else
      std::snprintf(source, sizeof source, "given (sites.population)");
    summary["quotas"] = "rank_size";
    summary["target_population"] = r.target_population;
    summary["population_source"] = source;
    summary["urban_share"] = options.urban_share;
    summary["settled_population"] = r.settled_population;  // urban_share x target_population, in the settlements
    // Everyone else lives in hamlets and scattered houses over the land (the density spreads them,
    // as the access stage counts them): settled + scattered = target_population.
    summary["scattered_population"] = r.target_population - r.settled_population;
    summary["sizes"] = options.sizes == sites::SitesOptions::Sizes::catchment ? "catchment" : "rank_size";
    summary["sizes_exponent"] = r.sizes_exponent;  // q of the law that split the settled people
    summary["room"] = r.room;  // settlements the land holds at sites.spacing_km; 0: no limit
    summary["count_limited_by_spacing"] = r.count_limited;
    // Every settled person is in a settlement, or counted here: population + unplaced people = settled.
    summary["crowded"] = r.crowded;
    summary["unplaced"] = {{"settlements", r.unplaced}, {"people", r.unplaced_people}};
    summary["largest"] = r.sites.empty() ? 0 : std::max_element(r.sites.begin(), r.sites.end(), [](const auto& a, const auto& b) {
                                                 return a.population < b.population;
                                               })->population;
  } else {
    summary["quotas"] = "belhadj2007";
  }
  if (!existing_file.empty()) {
    summary["existing"] = {{"places", existing.sites.size()}, {"people", r.existing_population}, {"moved_to_land", existing.moved.size()},
                           {"outside_dem", existing.outside.size()}, {"without_people", existing.without_people},
                           {"generated", r.sites.size() - existing.sites.size()},
                           {"generated_people", population - std::llround(r.existing_population) - r.growth_to_existing}};
  }
  if (options.growth > 0) summary["growth"] = growth_figures(r, options, crs);
  std::vector<std::string> warnings = existing_file.empty() ? std::vector<std::string>() : existing_warnings(existing, options, r);
  for (auto& w : settlement_warnings(s, r)) warnings.push_back(std::move(w));
  const std::string reference = s.scenario.path("/sites/reference");
  const json realism = reference.empty()  ? json()
                       : s.by_tiles ? realism_figures(s, s.settings.density, r, reference, warnings, progress)
                                    : realism_figures(s, density_inputs(s), r, reference, warnings, progress);
  for (const auto& w : warnings) log.warn(w);
  summary["warnings"] = warnings;
  if (!reference.empty()) s.summary["realism"] = realism;  // last: inserting moves the entries `summary` points into
  s.sites = r.sites;
}

void sites_load(RunState& s) {
  s.cities = read_vector(saved(s, "cities.geojson"), s.grid.georef.crs);
  s.sites = sites::sites_from_layer(*s.cities, saved(s, "cities.geojson"));
  sites::snap_to_cells(s.sites, s.grid.georef, s.grid.cols, s.grid.rows);  // the network a full run builds
}

void sites_prepare(const Scenario& scenario, const RasterHeader& grid, Settings& s) {
  s.sites = sites_options(scenario);
  check_file("/sites/reference", scenario.path("/sites/reference"));
  if (const std::string existing = scenario.path("/sites/existing"); !existing.empty()) {
    check_file("/sites/existing", existing);
    // Its format and figures now (whether each place finds land needs the density).
    named("/sites/existing", [&] { check_existing_places(existing, grid.georef.crs); });
  }
}

/// sites.reference: the settlements against the real places (pipeline::realism_figures).
void realism_summary(const json& r, SummaryText& out) {
  out.line("  realism  against %zu real places: %d settlements of min_population or more for %d, %.0f people for %.0f, largest %.0f for %.0f\n",
           r["places"].get<std::size_t>(), r["count"]["generated"].get<int>(), r["count"]["reference"].get<int>(),
           r["total"]["generated"].get<double>(), r["total"]["reference"].get<double>(), r["largest"]["generated"].get<double>(),
           r["largest"]["reference"].get<double>());
  if (r.contains("skill")) {
    const json& k = r["skill"];
    out.line("           density AUC %.3f (population-weighted %.3f); baselines:", k["auc"].get<double>(), k["weighted_auc"].get<double>());
    for (const auto& [name, b] : k["baselines"].items()) out.line(" %s %.3f", name.c_str(), b["auc"].get<double>());
    out.line("\n           ten largest real places with a top-10 settlement within 10 km: %d (random land points: %.1f)\n",
             r["top10"]["within_10km"].get<int>(), r["top10"]["random_within_10km"].get<double>());
  }
}

void sites_summary(const json& figures, SummaryText& out) {
  const json& c = figures["sites"];
  out.line("  sites    %d cities (%d roots, %d suburbs), %.0f people\n", c["cities"].get<int>(), c["roots"].get<int>(),
           c["suburbs"].get<int>(), c["population"].get<double>());
  if (c.contains("population_source"))
    out.line("           %.0f people in the region, %s; largest %.0f\n", c["target_population"].get<double>(),
             c["population_source"].get<std::string>().c_str(), c["largest"].get<double>());
  if (c.contains("growth"))
    out.line("           %.0f of them in the settlements (the existing places grown by %g%%), the new ones split by a rank-size law of exponent %.2f\n",
             c["settled_population"].get<double>(), 100 * c["growth"]["share"].get<double>(), c["sizes_exponent"].get<double>());
  else if (c.contains("existing") && c["population_source"].get<std::string>().rfind("assumed", 0) == 0)
    out.line("           %.0f of them in the given places (sites.existing): without sites.population none is generated beside them\n",
             c["settled_population"].get<double>());
  else if (c.contains("settled_population"))
    out.line("           %.0f of them in the settlements (sites.urban_share %g), split by a rank-size law of exponent %.2f (%s)\n",
             c["settled_population"].get<double>(), c["urban_share"].get<double>(), c["sizes_exponent"].get<double>(),
             c["sizes"] == "catchment" ? "read from the catchments" : "sites.zipf_exponent");
  if (c.contains("scattered_population"))
    out.line("           %.0f scattered over the land (hamlets and houses, spread by the density): %.0f settled + %.0f = %.0f\n",
             c["scattered_population"].get<double>(), c["settled_population"].get<double>(), c["scattered_population"].get<double>(),
             c["target_population"].get<double>());
  if (c.contains("existing")) {
    const json& e = c["existing"];
    out.line("           existing %d places, %.0f people (%d moved to land, %d outside the DEM left out, %d without people); %d generated, %lld people\n",
             e["places"].get<int>(), e["people"].get<double>(), e["moved_to_land"].get<int>(), e["outside_dem"].get<int>(),
             e["without_people"].get<int>(), e["generated"].get<int>(), e["generated_people"].get<long long>());
  }
  if (c.value("count_limited_by_spacing", false))
    out.line("           count held to the %lld settlements the land holds at sites.spacing_km (closer where denser than an urban centre)\n",
             c["room"].get<long long>());
  if (c.value("crowded", 0) > 0)
    out.line("           %d placed without a disc clear of water and steep land (their built-up area reaches over it)\n", c["crowded"].get<int>());
  if (c.contains("growth")) {
    const json& g = c["growth"];
    out.line("           growth +%g%%: %lld new settled people, %lld to the existing places, %lld in %d new settlements\n",
             100 * g["share"].get<double>(), g["people"].get<long long>(), g["to_existing"].get<long long>(),
             g["to_new_settlements"].get<long long>(), g["new_settlements"].get<int>());
    int shown = 0;
    for (const auto& [name, gain] : g["gained"].items())
      if (shown++ < 3) out.line("             %s +%lld\n", name.c_str(), gain.get<long long>());
    for (const auto& [rank, n] : g["new_largest"].items())
      if (n.contains("near"))
        out.line("             new settlement of %lld people %.1f km from %s\n", n["people"].get<long long>(), n["near_km"].get<double>(),
                 n["near"].get<std::string>().c_str());
  }
  for (const auto& [k, v] : c["per_class"].items())
    out.line("           class %s (radius %.0f m): %d\n", k.c_str(), v["radius_m"].get<double>(), v["cities"].get<int>());
  if (c.contains("warnings"))
    for (const auto& w : c["warnings"]) out.line("           warning: %.200s\n", w.get<std::string>().c_str());
  if (figures.contains("realism")) realism_summary(figures["realism"], out);
}

// ---- network (Belhadj 2007 §4.3.2; docs/sites.md) -------------------------------------------

void network_run(RunState& s, Progress& progress, const Log&) {
  const Crs& crs = s.grid.georef.crs;
  const network::SiteGraph graph = network::build_network(s.sites, crs, s.settings.network, progress);
  s.network = network::network_layer(graph, s.sites, crs);
  s.write("network", "network.geojson", *s.network, Style::network);
  std::size_t kept = 0;
  double length_m = 0;
  for (const auto& e : graph.edges)
    if (e.kept) ++kept, length_m += e.length_m;
  s.summary["network"] = {{"candidate_edges", graph.edges.size()}, {"kept_edges", kept},
                          {"kept_length_km", round_to(length_m / 1000, 0.01)}};
}

void network_load(RunState& s) { s.network = read_vector(saved(s, "network.geojson"), s.grid.georef.crs); }

void network_prepare(const Scenario& scenario, const RasterHeader&, Settings& s) { s.network = network_options(scenario); }

void network_summary(const json& figures, SummaryText& out) {
  const json& n = figures["network"];
  out.line("  network  %d of %d candidate links kept, %.1f km\n", n["kept_edges"].get<int>(), n["candidate_edges"].get<int>(),
           n["kept_length_km"].get<double>());
}

// ---- roads (Galin et al. 2010, Peytavie 2010 ch. 4; Belhadj 2007 Alg. 16; docs/roads.md) ----

/// roads.corridor.enabled: corridors.geojson and the land take and volumes for the summary (null
/// when off). `windows`: a run by tiles, `terrain` the grid's frame (roads::CorridorWindows).
json corridor_hook(RunState& s, const roads::TerrainField& terrain, const std::vector<roads::Road>& built, const roads::GivenCells& existing,
                   const roads::CorridorWindows* windows) {
  CorridorSettings c = s.settings.corridor;
  if (!c.enabled) return nullptr;
  if (!c.side_angles.empty() && !windows)  // by windows, each road's window of the map (CorridorWindows::side_angles)
    c.options.side_angles_deg = read_resampled(c.side_angles, s.dem.georef(), s.dem.cols(), s.dem.rows(), Resampling::nearest);
  const roads::Corridors corridors = roads::road_corridors(terrain, built, c.options, existing, windows);  // the new stretches only
  s.write("roads", "corridors.geojson", roads::corridors_layer(terrain, corridors), Style::corridors);
  json out = {{"land_take_ha", round_to(corridors.run.land_take_ha, 0.01)}, {"cut_m3", round_to(corridors.run.cut_m3, 1)},
              {"fill_m3", round_to(corridors.run.fill_m3, 1)}};
  if (corridors.vegetation) out["cleared_ha"] = round_to(corridors.run.cleared_ha, 0.01);
  return out;
}

/// The roads' terrain (pipeline::road_terrain) on the run's inland water (inland_water.tif).
roads::TerrainField road_terrain(const RunState& s) {
  const Raster<float> water = read_resampled(saved(s, kInlandWater), s.dem.georef(), s.dem.cols(), s.dem.rows(), Resampling::nearest);
  return pipeline::road_terrain(s.dem, s.scenario, s.settings.roads.model, saved_water_mask(water));
}

/// roads.existing read onto the grid (nullopt when not given); its errors name the option.
std::optional<roads::ExistingRoads> existing_roads(RunState& s, const roads::TerrainField& terrain, const Log& log) {
  const std::string& path = s.settings.roads.existing;
  if (path.empty()) return std::nullopt;
  roads::ExistingRoads e;
  try {
    e = roads::read_existing_roads(path, terrain);
  } catch (const Error& error) {
    throw Error(error.kind(), "/roads/existing: " + std::string(error.what()));
  }
  if (e.outside > 0) log.warn(std::string("roads.existing: ").append(std::to_string(e.outside)).append(" lines outside the DEM left out"));
  if (e.ferries > 0)
    log.warn(std::string("roads.existing: ").append(std::to_string(e.ferries)).append(" ferry lines left out (no road on the ground)"));
  s.write("roads", "existing_roads.geojson", roads::existing_roads_layer(terrain, e), Style::existing_roads);
  return e;
}

/// What is new, in every run (so that `compare` puts new and existing km side by side): the
/// network's sections off the given roads (all of them when none is given), drawn once, by class.
json new_figures(const roads::NetworkResult& r) {
  std::map<std::string, double> new_km;
  double new_total = 0;
  for (const auto& section : r.layout.sections)
    if (!section.existing) new_km[std::string(roads::name_of(section.road_class))] += section.length_m / 1000, new_total += section.length_m / 1000;
  json built = json::object();
  for (const roads::RoadClassStyle& c : roads::kRoadClasses) built[std::string(c.name)] = round_to(new_km[std::string(c.name)], 0.01);
  return {{"new_km", built}, {"new_network_km", round_to(new_total, 0.01)}};
}

/// The summary's figures of the given roads (roads.existing) and of the new links' sections on them.
json existing_figures(const roads::ExistingRoads& e, const roads::NetworkResult& r) {
  double on_km = 0;
  for (const auto& section : r.layout.sections)
    if (section.existing) on_km += section.length_m / 1000;
  json given = json::object();
  double given_total = 0;
  for (const roads::RoadClassStyle& c : roads::kRoadClasses) {
    if (c.road_class == roads::RoadClass::maritime) continue;
    given[std::string(c.name)] = round_to(e.length_m[std::size_t(c.road_class)] / 1000, 0.01);
    given_total += e.length_m[std::size_t(c.road_class)] / 1000;
  }
  return {{"existing", {{"lines", e.lines}, {"outside_dem", e.outside}, {"ferries_left_out", e.ferries}, {"km", given},
                        {"total_km", round_to(given_total, 0.01)}}},
          {"on_existing_km", round_to(on_km, 0.01)}};
}

/// The roads stage's windows in a run by tiles: the DEM's mosaic and inland_water.vrt read by
/// windows (pipeline::road_windows) within the memory limit, shared by the links routed at once
/// (a link they leave limited is routed again alone: roads::NetworkWindows);
/// their margin holds the corridors' reach when they are drawn. Built in place: `windows` refers
/// to the readers.
struct RunRoadWindows {
  DemWindowReader dem, lakes;
  std::size_t parallel;
  RoadWindows windows;
  roads::TerrainField frame;
  /// `held_mb`: what the roads stage holds beside the windows (the given roads).
  RunRoadWindows(RunState& s, const TiledInput& in, double held_mb)
      : dem(in.dem_path, in.read),
        lakes(saved(s, "inland_water.vrt"), ReadOptions{}),
        parallel(roads::links_at_once(s.settings.roads.routing)),
        windows(road_windows(dem, lakes, s.grid.georef, s.scenario, s.settings.roads.model,
                             s.settings.corridor.enabled ? roads::corridor_reach_m(s.settings.corridor.options) : 0.0,
                             in.tiles.limit_mb() - in.reserved_mb - held_mb, s.settings.roads.vegetation)),
        frame(roads::TerrainField::frame(windows.grid)) {}
  RunRoadWindows(const RunRoadWindows&) = delete;  // `windows` refers to the readers
  RunRoadWindows& operator=(const RunRoadWindows&) = delete;
  /// The network's roads (roads::route_network_by_windows): each link searched on a window of the
  /// DEM and of the inland water around it, on the given roads (drawn on `frame`) and the roads before it.
  roads::NetworkResult route(const RoadsSettings& settings, const std::vector<roads::Link>& links, const roads::ExistingRoads* existing,
                             Progress& progress) const {
    const roads::RoadGraph graph(frame, settings.model, settings.routing.graph);
    return roads::route_network_by_windows(frame, graph, links, settings.routing, progress,
                                           {windows.grid, windows.read, windows.window, windows.max_nodes}, existing);
  }
};

void roads_run(RunState& s, Progress& progress, const Log& log) {
  const RoadsSettings& settings = s.settings.roads;
  const std::vector<roads::Link> links = network::road_links(*s.network, &*s.cities);
  std::optional<RunRoadWindows> by_windows;  // a run by tiles: the layers are drawn on its frame
  std::optional<roads::TerrainField> whole;
  std::optional<roads::ExistingRoads> existing;
  roads::NetworkResult r;
  if (s.by_tiles) {
    s.by_tiles->reserve();
    // The given roads first, on the grid's frame (the bathymetry rule does not change their cells):
    // what they hold comes off the windows' share of the limit.
    existing = existing_roads(s, roads::TerrainField::frame({s.grid.georef, s.grid.cols, s.grid.rows, false}), log);
    std::size_t given_cells = 0;
    if (existing)
      for (const roads::CellChain& chain : existing->chains) given_cells += chain.cells.size();
    by_windows.emplace(s, *s.by_tiles, double(given_cells) * roads::kRoadCellBytes / 1e6);
    log.detail("roads by windows: windows of at most " + std::to_string(by_windows->windows.window.max_cells) + " cells and " +
               std::to_string(by_windows->windows.max_nodes) + " search nodes, shared by " + std::to_string(by_windows->parallel) +
               " roads at once (one left limited is routed again alone)" +
               (existing ? ", " + std::to_string(given_cells) + " cells of given roads" : ""));
    r = by_windows->route(settings, links, existing ? &*existing : nullptr, progress);
  } else {
    whole.emplace(road_terrain(s));
    add_road_layers(*whole, settings, s.plugins, s.dem, progress, log);
    const roads::RoadGraph graph(*whole, settings.model, settings.routing.graph);
    existing = existing_roads(s, *whole, log);
    r = roads::route_network(*whole, graph, links, settings.routing, progress, existing ? &*existing : nullptr);
  }
  const roads::TerrainField* terrain = by_windows ? &by_windows->frame : &*whole;
  // Links routed ahead in parallel are routed again when the roads before them change what they saw.
  log.detail(std::to_string(links.size()) + " links, " + std::to_string(r.searches) + " searches");
  for (const auto& f : r.failed) log.warn("no road: " + f);
  for (const auto& f : r.over_budget) log.warn("not routed: budget (roads.max_seconds): " + f);
  for (const auto& f : r.limited)
    log.warn("roads by windows: " + f + " decided on the largest window the memory limit allows (not proved the whole grid's road)");
  if (!r.redundant.empty()) {  // the summary counts them; the list only when asked (-v)
    std::string list;
    for (const auto& f : r.redundant) list += (list.empty() ? "" : ", ") + f;
    log.detail(std::to_string(r.redundant.size()) + " redundant links dropped (roads.redundant_share): " + list);
  }
  s.write("roads", "roads.geojson", roads::roads_layer(*terrain, r.roads, &r.layout), Style::roads);
  s.write("roads", "sections.geojson", roads::network_sections_layer(*terrain, r.layout), Style::sections);
  // An empty point layer has no geometry type QGIS can style: no junctions, no file.
  if (!r.layout.junctions.empty())
    s.write("roads", "junctions.geojson", roads::junctions_layer(*terrain, r.layout), Style::junctions);
  s.write("roads", "road_sections.geojson", roads::sections_layer(*terrain, r.roads), Style::road_sections);
  std::optional<roads::CorridorWindows> corridor_windows;
  if (by_windows) {
    corridor_windows = roads::CorridorWindows{by_windows->windows.read, by_windows->windows.window.margin_cells, !settings.vegetation.empty(), {}};
    if (const std::string& map = s.settings.corridor.side_angles; !map.empty())  // as corridor_hook reads it on the whole grid
      corridor_windows->side_angles = [map, grid = s.grid.georef](int c0, int r0, int cols, int rows) {
        return read_resampled(map, grid.window(c0, r0), cols, rows, Resampling::nearest);
      };
  }
  const json corridor = corridor_hook(s, *terrain, r.roads, r.existing, corridor_windows ? &*corridor_windows : nullptr);
  std::map<std::string, double> km;
  double bridge_m = 0, tunnel_m = 0, over_limit_m = 0, water_m = 0, network_km = 0;
  for (const auto& road : r.roads) {
    km[std::string(roads::name_of(road.road_class))] += road.stats.length_m / 1000;
    bridge_m += road.stats.bridge_m;
    tunnel_m += road.stats.tunnel_m;
    over_limit_m += road.stats.over_limit_m;
    water_m += road.stats.water_m;
  }
  for (const auto& section : r.layout.sections) network_km += section.length_m / 1000;
  const double land = s.summary["density"]["land_area_km2"].get<double>();  // the land the density stage measured, as sites reads it
  json per_class = json::object();
  for (const roads::RoadClassStyle& c : roads::kRoadClasses) per_class[std::string(c.name)] = round_to(km[std::string(c.name)], 0.01);
  s.summary["roads"] = {{"roads", r.roads.size()}, {"failed", r.failed.size()}, {"not_routed_budget", r.over_budget.size()},
                        {"redundant", r.redundant.size()}, {"sections", r.layout.sections.size()}, {"junctions", r.layout.junctions.size()},
                        {"length_km", per_class},
                        {"bridge_m", round_to(bridge_m, 0.1)}, {"tunnel_m", round_to(tunnel_m, 0.1)},
                        {"network_km", round_to(network_km, 0.01)}, {"land_km2", round_to(land, 0.01)},
                        {"network_km_per_km2", land > 0 ? round_to(network_km / land, 0.001) : 0.0},
                        {"over_grade_limit_m", round_to(over_limit_m, 0.1)},
                        {"on_water_m", round_to(water_m, 0.1)}};
  // By windows: links no window the limit allows proved the grid's (absent when none, as on the whole grid).
  if (!r.limited.empty()) s.summary["roads"]["limited_by_memory"] = r.limited.size();
  if (existing) s.summary["roads"].update(existing_figures(*existing, r));
  s.summary["roads"].update(new_figures(r));
  if (!corridor.is_null()) s.summary["roads"]["corridor"] = corridor;
}

void roads_load(RunState&) {}  // the access stage reads the saved layers

void roads_prepare(const Scenario& scenario, const RasterHeader& grid, Settings& s) {
  s.roads = roads_settings(scenario);
  s.corridor = corridor_settings(scenario);
  check_file("/roads/corridor/side_angles", s.corridor.side_angles);
  if (tile_settings(scenario).given()) {  // by windows (RunRoadWindows): what reads the whole grid is refused
    if (s.roads.routing.router != roads::Router::galin)
      throw bad_input("/roads/router: not computed on tiles yet (input.tile_size, input.memory_limit_mb)");
    if (!s.corridor.side_angles.empty() && s.corridor.enabled)  // the corridors' reach counts the map's shallowest angle
      named("/roads/corridor/side_angles", [&] { s.corridor.options.least_side_angle_deg = least_side_angle(s.corridor.side_angles, grid); });
  }
  check_file("/roads/vegetation", s.roads.vegetation);
  if (const std::string& lines = s.roads.existing; !lines.empty()) {
    check_file("/roads/existing", lines);
    // Its CRS and geometry now (which roads lie on the DEM needs its grid).
    named("/roads/existing", [&] { roads::check_existing_roads(lines, grid.georef.crs); });
  }
}

void roads_summary(const json& figures, SummaryText& out) {
  const json& r = figures["roads"];
  out.line("  roads    %d roads (%d not routable, %d redundant), bridges %.0f m, tunnels %.0f m\n", r["roads"].get<int>(),
           r["failed"].get<int>(), r.value("redundant", 0), r["bridge_m"].get<double>(), r["tunnel_m"].get<double>());
  if (r.contains("network_km"))
    out.line("           network %.1f km drawn once, %d sections, %d junctions\n", r["network_km"].get<double>(), r.value("sections", 0),
             r.value("junctions", 0));
  // Against real networks (Cour des comptes, ccomptes.fr/en/documents/59347: France's 1.1 M km of roads, 380,000 km of them
  // departmental and 1.9 % national, over 552,000 km²): the network joins the settlements only, so
  // its match is the national and departmental roads, not every lane.
  if (r.contains("network_km_per_km2"))
    out.line("           %.3f km of road per km2 of land (%.1f km2); France: 0.73 national and departmental, 2.0 all roads\n",
             r["network_km_per_km2"].get<double>(), r["land_km2"].get<double>());
  if (r.contains("existing")) {
    const json& e = r["existing"];
    out.line("           existing roads %.1f km given (%d lines, %d outside the DEM); the new links run %.1f km on them, %.1f km new\n",
             e["total_km"].get<double>(), e["lines"].get<int>(), e["outside_dem"].get<int>(), r["on_existing_km"].get<double>(),
             r["new_network_km"].get<double>());
    out.line("           %-13s %9s %9s %9s   (links; new, drawn once; existing given)\n", "", "links", "new", "existing");
    for (const auto& [cls, km] : r["length_km"].items())
      out.line("           %-13s %9.1f %9.1f %9.1f km\n", cls.c_str(), km.get<double>(), r["new_km"].value(cls, 0.0), e["km"].value(cls, 0.0));
  } else {
    // By class as drawn once (a section at its highest class), so the classes add up to the
    // network's km; run.json's length_km keeps the km summed per link.
    const json& by_class = r.contains("new_km") ? r["new_km"] : r["length_km"];
    for (const auto& [cls, km] : by_class.items()) out.line("           %-13s %9.1f km\n", cls.c_str(), km.get<double>());
  }
  if (r.contains("corridor")) {  // roads.corridor.enabled: the earthworks, of the new stretches only when roads are given
    const json& c = r["corridor"];
    out.line("           corridors%s: land take %.1f ha, cut %.0f m3, fill %.0f m3", r.contains("existing") ? " of the new roads only" : "",
             c["land_take_ha"].get<double>(), c["cut_m3"].get<double>(), c["fill_m3"].get<double>());
    if (c.contains("cleared_ha")) out.line(", cleared %.1f ha", c["cleared_ha"].get<double>());
    out.line("%s", "\n");
  }
}

// ---- access (Tobler 1993; Weiss et al. 2018; docs/access.md) ---------------------------------

/// The run's road sections with their road's class (roads.geojson) and structure: bridges and
/// ferries cross the water, tunnels are entered at their portals only.
VectorLayer classed_sections(const RunState& s) {
  const Crs& crs = s.grid.georef.crs;
  const VectorLayer roads = read_vector(saved(s, "roads.geojson"), crs);
  VectorLayer sections = read_vector(saved(s, "road_sections.geojson"), crs);
  std::map<std::int64_t, std::string> class_of;
  const int class_field = roads.field_index("class");
  for (std::size_t k = 0; class_field >= 0 && k < roads.features.size(); ++k)  // a section's `road` is its road's index
    if (const auto* c = std::get_if<std::string>(&roads.features[k].values[std::size_t(class_field)])) class_of[std::int64_t(k)] = *c;
  const int road = sections.field_index("road");
  sections.fields.push_back({"class", FieldType::string});
  for (auto& f : sections.features) {
    const auto* k = road >= 0 ? std::get_if<std::int64_t>(&f.values[std::size_t(road)]) : nullptr;
    f.values.push_back(k && class_of.count(*k) ? FieldValue(class_of[*k]) : FieldValue(std::monostate{}));
  }
  return sections;
}

/// The summary's figures of one size level.
json level_figures(const AccessSettings& a, std::size_t destinations, const access::Coverage& c) {
  json within = json::object();
  for (std::size_t k = 0; k < a.thresholds_minutes.size(); ++k) {
    char key[32];
    std::snprintf(key, sizeof key, "%g_min", a.thresholds_minutes[k]);
    within[key] = c.total_people > 0 ? std::round(c.within_people[k] / c.total_people * 1e4) / 1e4 : 0.0;
  }
  return {{"destinations", destinations}, {"share_within", within}, {"mean_minutes", std::round(c.mean_minutes * 10) / 10},
          {"p90_minutes", std::round(c.p90_minutes * 10) / 10}, {"unreachable_people", std::llround(c.unreachable_people)}};
}

/// The people the access stage counts: the sites stage's target population (or its settlements'),
/// spread over the land by the density model (as the sites' catchments count them).
double access_people(const RunState& s) {
  double total = 0;
  for (const auto& site : s.sites) total += double(site.population);
  if (s.summary["sites"].contains("target_population")) total = s.summary["sites"]["target_population"].get<double>();
  return total;
}

const char* const kUnreachableLand = " land cells reach no settlement (islands or enclosed land without a road)";

/// The access stage by tiles (access::travel_time_by_tiles): each tile of the grid read with two
/// cells around it (the DEM, the roads' terrain for the land, the road sections drawn on it); the
/// people, the coverage and the catchments' figures by bands of rows read back from the tiles, in
/// the whole grid's order; the catchments' polygons from access_nearest.vrt by rows.
void access_run_tiles(RunState& s, Progress& progress, const Log& log) {
  const AccessSettings& a = s.settings.access;
  s.by_tiles->reserve();
  const TiledInput& in = *s.by_tiles;
  const double budget_mb = in.tiles.limit_mb() - in.reserved_mb;
  const DemWindowReader dem(in.dem_path, in.read), lakes(saved(s, "inland_water.vrt"), ReadOptions{});
  const DemWindowReader density(saved(s, "density.vrt")), buildable(saved(s, "buildable.vrt"));
  const int cols = s.grid.cols, rows = s.grid.rows;
  // A tile's search holds about 100 bytes a cell (the roads' terrain for the land, the DEM, roads,
  // times, ids, the queue): the tiles take half of what the limit leaves.
  // The tiles' frames (12 bytes a cell of their two outer rows and columns: 96 / side a grid cell)
  // at most a quarter of it.
  const double tile_mb = 0.5 * budget_mb, frames_mb_by_side = 96.0 * double(cols) * double(rows) / 1e6;
  int side = in.tiles.tile_size;
  if (side <= 0) {
    side = std::max(16, std::min(int(std::sqrt(tile_mb * 1e6 / 100)) - 4, std::max(cols, rows)));
    side = std::max(side, int(std::ceil(frames_mb_by_side / (0.25 * budget_mb))));  // larger tiles, fewer frame cells
    if (100.0 * (side + 4.0) * (side + 4.0) / 1e6 > tile_mb)
      throw bad_input("/input/memory_limit_mb: too little for the access stage's tiles and their frames (" +
                      std::to_string(std::llround(frames_mb_by_side / side)) + " MB of frames at tiles of " + std::to_string(side) + " cells)");
  }
  // A band of rows: times, ids (read as floats and as ids), people, density, buildable: 24 bytes a cell.
  const int band = std::clamp(int(0.25 * budget_mb * 1e6 / 24 / cols), 1, rows);
  const RoadWindows terrain = road_windows(dem, lakes, s.grid.georef, s.scenario, s.settings.roads.model, 0, budget_mb);
  const VectorLayer sections = classed_sections(s);
  const access::ReadAccessWindow read = [&](int c0, int r0, int w, int h) {
    access::AccessWindow out;
    out.dem = dem.read(c0, r0, w, h);
    out.passable = out.dem.like<std::uint8_t>(0);
    {
      const roads::TerrainField t = terrain.read(c0, r0, w, h);
      for (int r = 0; r < h; ++r)
        for (int c = 0; c < w; ++c) out.passable(c, r) = !t.water(c0 + c, r0 + r) && !std::isnan(out.dem(c, r));
    }
    out.roads = access::road_cells(sections, out.dem, a.options, s.grid.georef, c0, r0);
    return out;
  };
  // People per cell as sites::people_on_land: the density's mass over the land, in the whole grid's order.
  const double total = access_people(s);
  sites::PeopleOnLand on_land(s.grid.georef, cols, rows, total);
  for (int r0 = 0; r0 < rows; r0 += band) {
    const int h = std::min(band, rows - r0);
    on_land.add(density.read(0, r0, cols, h), buildable.read(0, r0, cols, h), r0);
  }
  const auto people_band = [&](int r0, int h) { return on_land.people(density.read(0, r0, cols, h), buildable.read(0, r0, cols, h), r0); };
  std::vector<access::Settlement> settlements;
  for (const auto& site : s.sites) settlements.push_back({{site.col, site.row, site.id}, double(site.population)});
  log.detail("access by tiles: tiles of " + std::to_string(side) + " cells, bands of " + std::to_string(band) + " rows");
  const int across = (cols + side - 1) / side;
  json levels = json::object();
  for (const double level : a.levels_population) {
    std::vector<access::Destination> to;
    for (const access::Settlement& st : settlements)
      if (st.population >= level) to.push_back(st.at);
    if (to.empty()) continue;
    const bool all = level == 0;
    const std::string key = all ? "all" : std::to_string(std::llround(level));
    const MosaicFiles minutes = s.mosaic(all ? "access_minutes" : "access_minutes_" + key), nearest = s.mosaic("access_nearest");
    minutes.create();
    if (all) nearest.create();
    const access::TiledAccess t = access::travel_time_by_tiles(
        s.grid.georef, cols, rows, side, read, to, a.options,
        [&](int c0, int r0, access::AccessResult&& tile) {
          const int index = (r0 / side) * across + c0 / side;
          s.write_tile("access", minutes, index, across, tile.minutes, {{"UNIT", "min"}});
          if (all) s.write_tile("access", nearest, index, across, tile.nearest);
        },
        progress);
    s.write_mosaic("access", minutes, int(t.tiles), across, Style::access_minutes);
    if (all) s.write_mosaic("access", nearest, int(t.tiles), across, Style::unit_ramp);
    log.detail("access by tiles: " + std::to_string(t.tile_runs) + " searches of " + std::to_string(t.tiles) + " tiles, frames of " +
               std::to_string(std::llround(double(t.frame_bytes) / 1e6)) + " MB");
    // The coverage (two passes for the 90th percentile) and the catchments' sums, by bands.
    const DemWindowReader times(minutes.vrt());
    std::optional<DemWindowReader> ids;
    if (all) ids.emplace(nearest.vrt());
    access::CoverageCount count(a.thresholds_minutes);
    access::CatchmentSums sums;
    for (int pass = 0; pass < 2; ++pass) {
      if (pass == 1 && !count.percentile_pass()) break;
      for (int r0 = 0; r0 < rows; r0 += band) {
        const int h = std::min(band, rows - r0);
        const Dem m = times.read(0, r0, cols, h);
        const Raster<float> people = people_band(r0, h);
        if (pass == 1) {
          count.collect(m.data(), people.data(), m.size());
          continue;
        }
        count.count(m.data(), people.data(), m.size());
        if (!all) continue;
        const Dem idf = ids->read(0, r0, cols, h);  // ids as floats: exact below 2^24 settlements
        Raster<std::int32_t> id = idf.like<std::int32_t>(-1);
        for (std::size_t i = 0; i < id.size(); ++i) id[i] = std::isnan(idf[i]) ? -1 : std::int32_t(idf[i]);
        sums.add(id, m, people, on_land.area_m2(), r0);
      }
    }
    if (all) s.write("access", "access_catchments.geojson",
                     sums.layer(hydro::polygonize_labels(nearest.vrt(), s.grid.georef), "people", settlements, s.grid.georef.crs),
                     Style::access_catchments);
    levels[key] = level_figures(a, to.size(), count.finish());
    if (all && t.unreachable_land > 0) log.warn(std::to_string(t.unreachable_land) + kUnreachableLand);
  }
  s.summary["access"] = {{"people", std::llround(total)}, {"levels", levels}};
}

void access_run(RunState& s, Progress& progress, const Log& log) {
  const AccessSettings& a = s.settings.access;
  if (!a.enabled) return;
  if (s.by_tiles) return access_run_tiles(s, progress, log);
  const roads::TerrainField terrain = road_terrain(s);
  Raster<std::uint8_t> land = s.dem.like<std::uint8_t>(0);
  for (int r = 0; r < s.dem.rows(); ++r)
    for (int c = 0; c < s.dem.cols(); ++c) land(c, r) = !terrain.water(c, r) && !std::isnan(s.dem(c, r));
  const access::RoadCells road_cells = access::road_cells(classed_sections(s), s.dem, a.options);
  const double total = access_people(s);
  const Raster<float> people = sites::people_on_land(*s.density, *s.buildable, total);
  std::vector<access::Settlement> settlements;
  for (const auto& site : s.sites) settlements.push_back({{site.col, site.row, site.id}, double(site.population)});
  json levels = json::object();
  access::for_each_level(s.dem, land, road_cells, settlements, a.levels_population, a.thresholds_minutes, people, a.options, progress,
                         [&](const access::LevelFigures& f) {
    const bool all = f.level == 0;
    s.write("access", all ? "access_minutes.tif" : "access_minutes_" + f.key + ".tif", f.times.minutes, Style::access_minutes, {{"UNIT", "min"}});
    if (all) {
      s.write("access", "access_nearest.tif", f.times.nearest, Style::unit_ramp);
      s.write("access", "access_catchments.geojson", access::catchments_layer(f.times, people, "people", settlements), Style::access_catchments);
    }
    levels[f.key] = level_figures(a, f.destinations, f.coverage);
    if (all && f.times.unreachable_land > 0) log.warn(std::to_string(f.times.unreachable_land) + kUnreachableLand);
  });
  s.summary["access"] = {{"people", std::llround(total)}, {"levels", levels}};
}

void access_load(RunState&) {}  // nothing downstream

void access_prepare(const Scenario& scenario, const RasterHeader&, Settings& s) { s.access = access_settings(scenario); }

void access_summary(const json& figures, SummaryText& out) {
  const json& a = figures["access"];
  out.line("  access   of %.0f people, within reach of\n", a["people"].get<double>());
  for (const auto& [level, v] : a["levels"].items()) {
    const std::string whom = level == "all" ? "any settlement" : "settlements of " + level + "+";
    out.line("           %-22s (%3d)", whom.c_str(), v["destinations"].get<int>());
    for (const auto& [minutes, share] : v["share_within"].items())
      out.line(" %5.1f%% in %s", 100 * share.get<double>(), minutes.substr(0, minutes.find('_')).c_str());
    out.line(" min; mean %.1f min, p90 %.1f min\n", v["mean_minutes"].get<double>(), v["p90_minutes"].get<double>());
  }
}

}  // namespace

double land_area_figure(const density::DensityStats& stats) { return round_to(stats.land_area_km2, 0.01); }

HydroForDensity hydro_for_density(const Scenario& scenario, const Dem& dem, const InlandWaterSettings& water, hydro::HydroOptions hydro,
                                  bool hydrometry, bool rivers, Progress& progress, const Log& log) {
  HydroForDensity out{inland_water(dem, water, progress, log).mask, {}, std::nullopt};
  if (!hydrometry && !rivers) return out;
  hydro.with_streams = false;  // neither the hydrometry nor the upstream areas depend on them
  hydro.with_hydrometry = hydrometry;
  hydro::HydroResult h = hydro::run_hydro(dem, hydro, progress);
  double largest_km2 = 0;
  if (rivers) out.rivers = river_cells(area_km2(h.accumulation, largest_km2), scenario);
  out.hydrometry = std::move(h.hydrometry);
  return out;
}

density::DensityResult run_density(const Scenario& scenario, const StageSettings& settings, const Dem& dem, Progress& progress,
                                   const Log& log) {
  HydroForDensity h = hydro_for_density(scenario, dem, settings.water, settings.hydro, true, true, progress, log);
  const density::DensityOptions options = density_inputs(scenario, settings, dem, std::move(h.water), h.rivers);
  return density::compute_density(dem, h.hydrometry, options, progress);
}

const StageDef& stage(const std::string& name) {
  for (const StageDef& s : stages())
    if (name == s.name) return s;
  throw std::out_of_range("no stage " + name);
}

const std::vector<StageDef>& stages() {
  static const std::vector<StageDef> list = {
      {"terrain", {"dem", "input"}, terrain_prepare, terrain_run, terrain_load, terrain_summary},
      {"hydro", {"water", "hydro"}, hydro_prepare, hydro_run, hydro_load, hydro_summary},
      {"density", {"density", "plugins"}, density_prepare, density_run, density_load, density_summary},
      {"sites", {"sites", "seed"}, sites_prepare, sites_run, sites_load, sites_summary},
      {"network", {"network"}, network_prepare, network_run, network_load, network_summary},
      {"roads", {"roads"}, roads_prepare, roads_run, roads_load, roads_summary},
      {"access", {"access"}, access_prepare, access_run, access_load, access_summary},
  };
  return list;
}

}  // namespace terrapolis::pipeline
