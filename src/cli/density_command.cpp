// `terrapolis density DEM OUTDIR`: the population density model (Belhadj 2007, §4.2) and its rasters.
// SPDX-License-Identifier: MIT
#include <CLI/CLI.hpp>

#include <chrono>
#include <cmath>
#include <ctime>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <optional>
#include <sstream>

#include "cli/command.hpp"
#include "cli/commands_list.hpp"
#include "cli/dem_input.hpp"
#include "cli/hydro_tiles.hpp"
#include "core/memory.hpp"
#include "cli/plugin_options.hpp"
#include "cli/schema_options.hpp"
#include "core/error.hpp"
#include "core/text.hpp"
#include "density/density.hpp"
#include "density/tiled_density.hpp"
#include "hydro/hydro.hpp"
#include "hydro/tiled/tiled_belhadj.hpp"
#include "hydro/tiled/tiled_flat_water.hpp"
#include "pipeline/descriptions.hpp"
#include "pipeline/stages.hpp"
#include "io/output_set.hpp"
#include "io/mask_io.hpp"
#include "io/raster_io.hpp"
#include "pipeline/stage_options.hpp"
#include "terrapolis/version.hpp"

namespace terrapolis::cli {
namespace {

namespace fs = std::filesystem;


/// The hydrometry the density model uses, on the DEM's grid, and whether it is worth writing.
/// This is the ONE place that decides where hydrometry comes from: a file given with --hydrometry
/// (resampled bilinearly to the DEM's grid), nothing when neither its weight nor a river-bed cap
/// needs it (all zeros, not written), otherwise the hydro stage's, computed from the DEM.
struct Hydrometry {
  Raster<float> values;
  bool used = false;
};

bool hydrometry_used(const density::DensityOptions& options) {
  return options.weights[1] != 0 || options.river_bed_cap.has_value() || options.model;  // boosted trees may read it
}

/// A --hydrometry file on a grid (the DEM's or a window of it), checked to lie in [0,1].
Raster<float> read_hydrometry(const std::string& path, const Georef& grid, int cols, int rows) {
  Raster<float> values = read_resampled(path, grid, cols, rows, Resampling::bilinear);
  for (std::size_t i = 0; i < values.size(); ++i) {
    const float v = values[i];
    if (!std::isnan(v) && (v < -1e-6f || v > 1 + 1e-6f))
      throw bad_input("--hydrometry " + path + ": values must lie in [0,1] (found " + std::to_string(v) + ")");
  }
  return values;
}

bool rivers_used(const density::DensityOptions& options) {
  return options.terrain_weights[std::size_t(density::TerrainTerm::river_near)] != 0 || options.model;
}

/// What the run's hydro stage gives its density stage (pipeline::hydro_for_density, with the
/// scenario's water and hydro sections): the inland water as the water mask, the rivers when
/// river_near is read, and the hydrometry unless --hydrometry gives it or nothing uses it.
Hydrometry hydro_inputs(const Dem& dem, const pipeline::Scenario& scenario, density::DensityOptions& options, const std::string& path,
                        Progress& progress, const Log& log) {
  Hydrometry h;
  h.used = hydrometry_used(options);
  const bool compute = h.used && path.empty();
  pipeline::HydroForDensity hydro = pipeline::hydro_for_density(scenario, dem, pipeline::inland_water_settings(scenario), pipeline::hydro_options(scenario),
                                                                compute, rivers_used(options), progress, log);
  options.water_mask = std::move(hydro.water);
  if (hydro.rivers) options.rivers = std::move(*hydro.rivers);
  h.values = compute ? std::move(hydro.hydrometry) : path.empty() ? dem.like<float>(0.0f) : read_hydrometry(path, dem.georef(), dem.cols(), dem.rows());
  return h;
}

class DensityCommand final : public Command {
 public:
  std::string name() const override { return "density"; }
  std::string summary() const override {
    return "Population density model from terrain: coast, hydrometry, plateau, plain, user layers (Belhadj 2007, 4.2)";
  }

  void setup(CLI::App& app) override {
    dem_.add_to(app);
    file_kind(app.add_option("OUTDIR", out_dir_, "Folder for coast.tif, plateau.tif, plain.tif, hydrometry.tif, buildable.tif, density.tif")
                  ->required(),
              FileKind::folder_out);
    app.add_option("--weights", weights_, "Weights of coast,hydrometry,plateau,plain; negative repulsive, 0 neutral (default: the --preset's; belhadj2007 1,1,1.5,0)");
    file_kind(app.add_option("--layer", layers_, "User raster and its weight, FILE:WEIGHT (repeatable); values in [0,1] or rescaled from their range"),
              FileKind::raster_in);
    file_kind(app.add_option("--exclude", exclusions_, "Exclusion raster: non-zero cells are uninhabitable (repeatable)"), FileKind::raster_in);
    file_kind(app.add_option("--hydrometry", hydrometry_path_, "Hydrometry raster in [0,1], resampled to the DEM grid"), FileKind::raster_in);
    schema_.setup(app, name());
    schema_.name_as("/density/weights", "--weights");
    schema_.name_as("/density/layers", "--layer");
    schema_.name_as("/density/exclusions", "--exclude");
    plugins_.setup(app, "adds its density factor, combined like a --layer of that weight, and its exclusions");
    app.add_flag("--report", report_, "Print the buildable share and the density histogram");
    app.add_flag("--cog", cog_, "Write Cloud Optimized GeoTIFFs");
    add_overwrite_flag(app, overwrite_);
  }

  void run(Context& context) override {
    const pipeline::Scenario scenario = schema_.scenario(table_options());
    density::DensityOptions options = schema_.settings([&] { return pipeline::density_options(scenario); });
    // Outputs refused before any work; hydrometry.tif is written only when used.
    std::vector<std::string> inputs = pipeline::density_files(scenario);
    inputs.push_back(dem_.path);
    inputs.push_back(hydrometry_path_);
    OutputSet outputs("density", inputs, overwrite_);
    const fs::path dir = outputs.folder(out_dir_);
    const pipeline::TileSettings tiles = schema_.settings([&] { return pipeline::tile_settings(scenario); });
    if (tiles.tiled(dem_.path)) return run_tiled(context, scenario, options, tiles, dir, outputs);

    using clock = std::chrono::steady_clock;
    const auto seconds = [](clock::time_point a, clock::time_point b) { return format(std::chrono::duration<double>(b - a).count(), 3); };
    const auto t0 = clock::now();
    const plugin::PluginSet plugins = plugins_.load(context.log);
    const Dem dem = dem_.read();
    pipeline::read_density_files(scenario, dem, "", options);
    const Hydrometry hydrometry = hydro_inputs(dem, scenario, options, hydrometry_path_, context.progress, context.log);
    plugin::add_to_density(plugin::density_factors(plugins, dem, context.progress, context.log), options);
    const auto t1 = clock::now();
    const std::clock_t cpu1 = std::clock();  // processor time of all threads
    const density::DensityResult result = density::compute_density(dem, hydrometry.values, options, context.progress);
    const std::clock_t cpu2 = std::clock();
    const auto t2 = clock::now();

    write_rasters(result, options, terms(scenario), [&](const std::string& n) { return (dir / (n + ".tif")).string(); });
    outputs.commit();
    const auto t3 = clock::now();
    context.log.detail("density: read " + seconds(t0, t1) + " s, model " + seconds(t1, t2) + " s (cpu " +
                       format(double(cpu2 - cpu1) / CLOCKS_PER_SEC, 3) + " s), write " + seconds(t2, t3) + " s");
    finish(context, result.stats);
  }

 private:
  /// What the descriptions say of the hydrometry: the hydro section's method, or the file it was read from.
  pipeline::DescriptionTerms terms(const pipeline::Scenario& scenario) const {
    pipeline::DescriptionTerms t = pipeline::description_terms(scenario);
    if (!hydrometry_path_.empty()) t.hydrometry = "read from " + fs::path(hydrometry_path_).filename().string();
    return t;
  }
  /// The rasters of `result` (the whole grid's or a tile's), each to path(name), concurrently.
  void write_rasters(const density::DensityResult& result, const density::DensityOptions& options,
                     const pipeline::DescriptionTerms& terms, const std::function<std::string(const std::string&)>& path) const {
    const auto metadata = provenance(options);
    std::vector<std::function<void()>> writes;
    auto write = [&](const std::string& n, const auto& raster) {
      writes.emplace_back([&, n] {
        WriteOptions w;
        w.cog = cog_;
        w.description = pipeline::describe_output(n + ".tif", terms);
        w.metadata = metadata;
        write_raster(path(n), raster, w);
      });
    };
    write("coast", result.coast);
    write("plateau", result.plateau);
    write("plain", result.plain);
    if (hydrometry_used(options)) write("hydrometry", result.hydrometry);
    write("buildable", result.buildable);
    write("density", result.density);
    write_concurrently(writes);
  }

  void finish(Context& context, const density::DensityStats& s) const {
    const double land = double(s.known_cells - s.water_cells);
    context.log.info("density: " + std::to_string(s.buildable_cells) + " buildable cells (" +
                     format(land > 0 ? 100.0 * double(s.buildable_cells) / land : 0.0) + " % of land), mean density " +
                     format(s.mean_density, 3) + ", written to " + out_dir_);
    if (report_) print_report(s);
  }

  /// The model tile by tile (docs/scale.md): the DEM read by windows (a huge GeoTIFF, a VRT, a
  /// folder of tiles), one GeoTIFF a tile and a VRT per output, the whole grid's cells.
  void run_tiled(Context& context, const pipeline::Scenario& scenario, density::DensityOptions options,
                 const pipeline::TileSettings& tiles, const fs::path& dir, OutputSet& outputs) {
    if (!options.factors.empty() || !scenario.resolved["density"]["layers"].empty())
      throw bad_input("--layer: user layers are rescaled by their range over the grid, not computed on tiles yet");
    if (!plugins_.specs.empty()) throw bad_input("--plugin: plugins are not run on tiles yet");
    const bool hydrometry = hydrometry_used(options);
    const hydro::HydrometryOptions belhadj = hydro::hydrometry_options(pipeline::hydro_options(scenario));
    if (hydrometry && hydrometry_path_.empty() && belhadj.method != hydro::HydrometryMethod::belhadj)
      throw bad_input("density on tiles: the accumulation hydrometry (hydro.hydrometry) is not computed on tiles yet, Belhadj's is; "
                      "give --hydrometry FILE (a raster or VRT in [0,1]) or a hydrometry weight of 0 (--weights C,0,P,L)");
    const pipeline::InlandWaterSettings water = pipeline::inland_water_settings(scenario);
    if (!water.reservoirs.empty()) throw bad_input("/water/reservoirs: not flooded on tiles yet");
    const double reserved_mb = reserve_reader_memory(tiles.limit_mb());
    const DemWindowReader reader(dem_.path, dem_.options());
    const RasterHeader& h = reader.header();
    const auto read_dem = [&](int c0, int r0, int cols, int rows) { return reader.read(c0, r0, cols, rows); };
    // What the whole-grid command computes on the whole DEM, computed by tiles into the staging
    // folder first, then read by windows as given files are: the lakes the DEM flattens, Belhadj's hydrometry.
    const fs::path computed = dir / ".computed";
    std::string flat_water;
    if (water.flat_water.min_area_km2 > 0) {
      const int side = tiles.tile_size > 0 ? tiles.tile_size : hydro::tiled::flat_water_tile_size_for(h.cols, h.rows, tiles.limit_mb(), reserved_mb);
      fs::create_directories(computed / "flat_water");
      const hydro::tiled::TiledFlatWaterReport f = hydro::tiled::run_tiled_flat_water(
          h.cols, h.rows, h.georef, read_dem, water.flat_water, side,
          [&](int t, int across, const Raster<std::uint8_t>& tile) {
            write_raster(tile_file(computed.string(), "flat_water", t, across), tile, WriteOptions{});
          },
          context.progress);
      std::vector<std::string> files;
      for (int t = 0; t < f.tiles; ++t) files.push_back(tile_file(computed.string(), "flat_water", t, f.across));
      flat_water = (computed / "flat_water.vrt").string();
      write_vrt(flat_water, files, false);
      context.log.detail("flat water tiles: " + std::to_string(f.tiles) + " of " + std::to_string(side) + " cells a side, " +
                         std::to_string(f.lakes) + " lakes the DEM flattens, " + format(f.area_km2, 2) + " km2 (" +
                         std::to_string(f.surfaces) + " level surfaces on tile edges or large enough, joined across tiles)");
    }
    // The inland water of a window: the flattened lakes and --water-mask, as pipeline::inland_water.
    auto read_water = [&](density::DensityOptions& o, const Georef& grid, int cols, int rows) {
      if (!water.water_mask.empty()) o.water_mask = read_mask(water.water_mask, grid, cols, rows);
      if (flat_water.empty()) return;
      Raster<std::uint8_t> lakes = read_mask(flat_water, grid, cols, rows);
      if (o.water_mask.size() > 0)
        for (std::size_t i = 0; i < lakes.size(); ++i)
          if (o.water_mask[i]) lakes[i] = 1;
      o.water_mask = std::move(lakes);
    };
    std::optional<DemWindowReader> hydrometry_reader;
    if (hydrometry && hydrometry_path_.empty()) {
      fs::create_directories(computed / "tiles");
      const hydro::tiled::TiledBelhadjReport b = hydro::tiled::run_tiled_belhadj(
          h.cols, h.rows, h.georef, read_dem,
          hydro::belhadj_options(belhadj), tiles.tile_size, tiles.limit_mb(), (computed / "scratch").string(),
          [&](int t, int across, const Raster<float>& tile) { write_raster(tile_file(computed.string(), "tiles", t, across), tile, WriteOptions{}); },
          context.progress, reserved_mb);
      std::vector<std::string> files;
      for (int t = 0; t < b.tiles; ++t) files.push_back(tile_file(computed.string(), "tiles", t, b.across));
      write_vrt((computed / "hydrometry.vrt").string(), files, false);
      hydrometry_reader.emplace((computed / "hydrometry.vrt").string(), ReadOptions{});
      char line[300];
      std::snprintf(line, sizeof line,
                    "hydrometry tiles: %d of %d cells a side, %d Belhadj iterations (mean %.3g) found in %d pass%s, halo %d cells; "
                    "state %.1f MB a window",
                    b.tiles, b.tile_size, b.iterations, b.final_mean, b.searches, b.searches > 1 ? "es" : "", b.halo, b.window_bytes / 1e6);
      context.log.detail(line);
    }
    auto read = [&](int c0, int r0, int cols, int rows, bool dem_only) {
      density::WindowInputs in;
      in.dem = reader.read(c0, r0, cols, rows);
      in.options = options;
      const Georef& grid = in.dem.georef();
      read_water(in.options, grid, cols, rows);
      if (dem_only) return in;
      pipeline::read_density_files(scenario, grid, cols, rows, "", in.options);
      in.hydrometry = !hydrometry            ? in.dem.like<float>(0.0f)
                      : hydrometry_reader ? hydrometry_reader->read(c0, r0, cols, rows)
                                          : read_hydrometry(hydrometry_path_, grid, cols, rows);
      return in;
    };
    const char* layers[] = {"coast", "plateau", "plain", "hydrometry", "buildable", "density"};
    for (const char* l : layers)
      if (hydrometry || std::string(l) != "hydrometry") fs::create_directory(dir / l);
    const density::TiledDensityReport report = density::run_tiled_density(
        h.cols, h.rows, h.georef, read, options, tiles.tile_size, tiles.limit_mb(),
        [&](int t, int across, const density::DensityResult& tile) {
          write_rasters(tile, options, terms(scenario), [&](const std::string& n) { return tile_file(dir.string(), n, t, across); });
        },
        context.progress, reserved_mb);
    for (const char* l : layers)
      if (hydrometry || std::string(l) != "hydrometry") {
        std::vector<std::string> files;
        for (int t = 0; t < report.tiles; ++t) files.push_back(tile_file(dir.string(), l, t, report.across));
        write_vrt((dir / (std::string(l) + ".vrt")).string(), files, false);
      }
    hydrometry_reader.reset();
    fs::remove_all(computed);
    outputs.commit();
    char line[360];
    std::snprintf(line, sizeof line,
                  "density tiles: %d of %d cells a side, halo %d x %d cells (r_max + r_min); state %.1f MB a window + %.1f MB global + "
                  "%.0f MB reader and process; peak resident %.0f MB",
                  report.tiles, report.tile_size, report.halo_cols, report.halo_rows, report.window_bytes / 1e6,
                  report.global_bytes / 1e6, reserved_mb, peak_resident_mb());
    context.log.detail(line);
    finish(context, report.stats);
  }

  static std::string format(double v, int digits = 1) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.*f", digits, v);
    return buf;
  }

  /// The command's own options as scenario fields: --weights (over the --preset's), --layer, --exclude.
  std::vector<std::string> table_options() const {
    std::vector<std::string> sets;
    if (!weights_.empty()) {
      std::stringstream ss(weights_);
      std::string part;
      std::vector<double> w;
      while (std::getline(ss, part, ',')) w.push_back(parse_number_option("--weights", part));
      if (w.size() != 4) throw bad_input("--weights: expected 4 numbers C,H,P,L but got '" + weights_ + "'");
      const char* terms[4] = {"coast", "hydrometry", "plateau", "plain"};
      for (int i = 0; i < 4; ++i) sets.push_back(std::string("density.weights.") + terms[i] + "=" + nlohmann::json(w[std::size_t(i)]).dump());
    }
    nlohmann::json layers = nlohmann::json::array();
    for (const std::string& l : layers_) {
      const auto colon = l.rfind(':');
      if (colon == std::string::npos || colon == 0) throw bad_input("--layer: expected FILE:WEIGHT but got '" + l + "'");
      layers.push_back({{"file", l.substr(0, colon)}, {"weight", parse_number_option("--layer " + l.substr(0, colon), l.substr(colon + 1))}});
    }
    sets.push_back("density.layers=" + layers.dump());
    sets.push_back("density.exclusions=" + nlohmann::json(exclusions_).dump());
    return sets;
  }

  std::vector<std::pair<std::string, std::string>> provenance(const density::DensityOptions& o) const {
    std::ostringstream w;
    w << o.weights[0] << ',' << o.weights[1] << ',' << o.weights[2] << ',' << o.weights[3];
    for (const auto& f : o.factors) w << ';' << f.name << ':' << f.weight;
    std::vector<std::pair<std::string, std::string>> m = {
        {"TERRAPOLIS_VERSION", terrapolis::version},
        {"TERRAPOLIS_STAGE", "density"},
        {"DEM", fs::path(dem_.path).filename().string()},
        {"WEIGHTS_COAST_HYDROMETRY_PLATEAU_PLAIN", w.str()},
        {"R_MIN_M", format(o.r_min_m, 3)},
        {"R_MAX_M", format(o.r_max_m, 3)},
        {"SEA_LEVEL_M", format(o.sea_level_m, 3)},
        {"NODATA_IS_SEA", o.nodata_is_sea ? "yes" : "no"},
        {"MAX_ALTITUDE_M", format(o.max_altitude_m, 3)},
        {"PLATEAU_M", format(o.plateau_min_m, 1) + ".." + format(o.plateau_max_m, 1)},
        {"PLAIN_MAX_VARIATION_M", format(o.plain_max_variation_m, 3)},
    };
    if (o.max_slope_deg) m.emplace_back("MAX_SLOPE_DEG", format(*o.max_slope_deg, 3));
    if (o.river_bed_cap) m.emplace_back("RIVER_BED_CAP", format(*o.river_bed_cap, 4));
    return m;
  }

  void print_report(const density::DensityStats& s) const {
    const double land = double(s.known_cells - s.water_cells);
    std::printf("Density report: %s\n", dem_.path.c_str());
    std::printf("  cells:      %zu (%zu with data or water, %zu water)\n", s.cells, s.known_cells, s.water_cells);
    std::printf("  buildable:  %zu cells, %.2f %% of land, %.2f %% of the grid\n", s.buildable_cells,
                land > 0 ? 100.0 * double(s.buildable_cells) / land : 0.0, 100.0 * double(s.buildable_cells) / double(s.cells));
    std::printf("  radii:      r_min %.1f m, r_max %.1f m (%s, up to %d bands per disc)\n", s.r_min_m, s.r_max_m,
                s.ring_exact ? "exact discs" : "banded discs", s.ring_bands);
    std::printf("  density:    mean %.3f over buildable cells\n", s.mean_density);
    std::printf("  histogram of density over buildable cells:\n");
    for (int k = 0; k < 10; ++k) {
      const double share = s.buildable_cells ? 100.0 * double(s.histogram[std::size_t(k)]) / double(s.buildable_cells) : 0.0;
      std::printf("    [%.1f, %.1f%c %6.2f %%  %s\n", k / 10.0, (k + 1) / 10.0, k == 9 ? ']' : ')', share,
                  std::string(std::size_t(std::lround(share / 2)), '#').c_str());
    }
  }

  DemInput dem_;
  PluginOptions plugins_;
  std::string out_dir_, weights_, hydrometry_path_;
  std::vector<std::string> layers_, exclusions_;
  SchemaOptions schema_;
  bool report_ = false, cog_ = false, overwrite_ = false;
};

}  // namespace

std::unique_ptr<Command> make_density_command() { return std::make_unique<DensityCommand>(); }

}  // namespace terrapolis::cli
