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
#include "pipeline/by_tiles.hpp"
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
    if (!plugins_.specs.empty()) throw bad_input("--plugin: plugins are not run on tiles yet");
    if (rivers_used(options))
      throw bad_input("river_near: this command does not find the rivers on tiles (terrapolis run does): give it weight 0, and no boosted model");
    const bool hydrometry = hydrometry_used(options), compute_hydrometry = hydrometry && hydrometry_path_.empty();
    const hydro::HydroOptions hydro = pipeline::hydro_options(scenario);
    if (compute_hydrometry && hydro.hydrometry.method != hydro::HydrometryMethod::belhadj)
      throw bad_input("/hydro/hydrometry: the accumulation hydrometry is not computed on tiles yet (Belhadj's is); give --hydrometry FILE");
    const DemWindowReader reader(dem_.path, dem_.options());
    const RasterHeader& h = reader.header();
    // What the whole-grid command computes on the whole DEM (pipeline::hydro_for_density), computed
    // by tiles into the staging folder first, then read by windows: the inland water, Belhadj's hydrometry.
    std::optional<ScratchFolder> computed(std::in_place, (dir / ".computed").string());  // gone before the outputs are committed
    const MosaicFiles belhadj{computed->path(), "hydrometry"};
    const std::string water =
        pipeline::inland_water_mosaic(reader, pipeline::inland_water_settings(scenario), tiles, computed->path(), context.progress, context.log);
    std::optional<DemWindowReader> hydrometry_tiles;
    if (compute_hydrometry) {
      belhadj.create();
      const hydro::tiled::TiledBelhadjReport b = pipeline::hydrometry_by_tiles(
          reader, hydro, tiles, reserve_reader_memory(tiles.limit_mb()), computed->path() + "/scratch",
          [&](int t, int across, const Raster<float>& tile) { write_raster(belhadj.tile(t, across), tile, WriteOptions{}); }, context.progress);
      belhadj.finish(b.tiles, b.across);
      hydrometry_tiles.emplace(belhadj.vrt(), ReadOptions{});
      context.log.detail(pipeline::describe(b));
    }
    pipeline::ReadHydrometry read_hydro;
    if (hydrometry_tiles)
      read_hydro = [&](const Dem& window, int c0, int r0) { return hydrometry_tiles->read(c0, r0, window.cols(), window.rows()); };
    else if (hydrometry)
      read_hydro = [&](const Dem& window, int, int) { return read_hydrometry(hydrometry_path_, window.georef(), window.cols(), window.rows()); };
    const density::ReadWindowInputs read = pipeline::density_windows(reader, scenario, options, water, read_hydro);
    const double reserved_mb = reserve_reader_memory(tiles.limit_mb());
    const char* layers[] = {"coast", "plateau", "plain", "hydrometry", "buildable", "density"};
    for (const char* l : layers)
      if (hydrometry || std::string(l) != "hydrometry") fs::create_directory(dir / l);
    const density::TiledDensityReport report = density::run_tiled_density(
        h.cols, h.rows, h.georef, read, options, tiles.tile_size, tiles.limit_mb(), computed->path(),
        [&](int t, int across, const density::DensityResult& tile) {
          write_rasters(tile, options, terms(scenario), [&](const std::string& n) { return MosaicFiles{dir.string(), n}.tile(t, across); });
        },
        context.progress, reserved_mb, pipeline::density_file_bytes_per_cell(scenario));
    for (const char* l : layers)
      if (hydrometry || std::string(l) != "hydrometry") MosaicFiles{dir.string(), l}.finish(report.tiles, report.across);
    hydrometry_tiles.reset();
    computed.reset();
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
