// `terrapolis density DEM OUTDIR`: the population density model (Belhadj 2007, §4.2) and its rasters.
// SPDX-License-Identifier: MIT
#include <CLI/CLI.hpp>

#include <chrono>
#include <cmath>
#include <ctime>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <sstream>

#include "cli/command.hpp"
#include "cli/commands_list.hpp"
#include "cli/dem_input.hpp"
#include "cli/plugin_options.hpp"
#include "cli/schema_options.hpp"
#include "core/error.hpp"
#include "core/text.hpp"
#include "density/density.hpp"
#include "hydro/hydrometry.hpp"
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
/// needs it (all zeros, not written), otherwise Belhadj's hydrometry computed from the DEM.
struct Hydrometry {
  Raster<float> values;
  bool used = false;
};

Hydrometry obtain_hydrometry(const Dem& dem, const density::DensityOptions& options, const std::string& path, Progress& progress) {
  Hydrometry h;
  h.used = options.weights[1] != 0 || options.river_bed_cap.has_value();
  if (!path.empty()) {
    h.values = read_resampled(path, dem.georef(), dem.cols(), dem.rows(), Resampling::bilinear);
    for (std::size_t i = 0; i < h.values.size(); ++i) {
      const float v = h.values[i];
      if (!std::isnan(v) && (v < -1e-6f || v > 1 + 1e-6f))
        throw bad_input("--hydrometry " + path + ": values must lie in [0,1] (found " + std::to_string(v) + ")");
    }
    return h;
  }
  if (!h.used) {
    h.values = dem.like<float>(0.0f);
    return h;
  }
  // Belhadj's hydrometry (thesis Alg. 12) with the sea as outlet, as `terrapolis hydro --sea-level` does.
  hydro::HydrometryOptions hydrometry;
  hydrometry.sea_level = options.sea_level_m;
  h.values = hydro::compute_hydrometry(dem, hydrometry, progress);
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
    app.add_option("--weights", weights_, "Weights of coast,hydrometry,plateau,plain; negative repulsive, 0 neutral (default 1,1,1.5,0)");
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
    app.add_flag("--overwrite", overwrite_, "Replace existing outputs");
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
    const bool write_hydro = options.weights[1] != 0 || options.river_bed_cap.has_value();

    using clock = std::chrono::steady_clock;
    const auto seconds = [](clock::time_point a, clock::time_point b) { return format(std::chrono::duration<double>(b - a).count(), 3); };
    const auto t0 = clock::now();
    const plugin::PluginSet plugins = plugins_.load(context.log);
    const Dem dem = dem_.read();
    pipeline::read_density_files(scenario, dem, scenario.path("/water/water_mask"), options);
    const Hydrometry hydrometry = obtain_hydrometry(dem, options, hydrometry_path_, context.progress);
    plugin::add_to_density(plugin::density_factors(plugins, dem, context.progress, context.log), options);
    const auto t1 = clock::now();
    const std::clock_t cpu1 = std::clock();  // processor time of all threads
    const density::DensityResult result = density::compute_density(dem, hydrometry.values, options, context.progress);
    const std::clock_t cpu2 = std::clock();
    const auto t2 = clock::now();

    const auto metadata = provenance(options);
    std::vector<std::function<void()>> writes;
    auto write = [&](const std::string& n, const auto& raster) {
      writes.emplace_back([&, n] {
        WriteOptions w;
        w.cog = cog_;
        w.description = density::describe_output(n);
        w.metadata = metadata;
        write_raster((dir / (n + ".tif")).string(), raster, w);
      });
    };
    write("coast", result.coast);
    write("plateau", result.plateau);
    write("plain", result.plain);
    if (write_hydro) write("hydrometry", result.hydrometry);
    write("buildable", result.buildable);
    write("density", result.density);
    write_concurrently(writes);
    outputs.commit();
    const auto t3 = clock::now();
    context.log.detail("density: read " + seconds(t0, t1) + " s, model " + seconds(t1, t2) + " s (cpu " +
                       format(double(cpu2 - cpu1) / CLOCKS_PER_SEC, 3) + " s), write " + seconds(t2, t3) + " s");

    const auto& s = result.stats;
    const double land = double(s.known_cells - s.water_cells);
    context.log.info("density: " + std::to_string(s.buildable_cells) + " buildable cells (" +
                     format(land > 0 ? 100.0 * double(s.buildable_cells) / land : 0.0) + " % of land), mean density " +
                     format(s.mean_density, 3) + ", written to " + out_dir_);
    if (report_) print_report(result);
  }

 private:
  static std::string format(double v, int digits = 1) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.*f", digits, v);
    return buf;
  }

  /// The command's own options as scenario fields: the thesis's weights unless --weights, --layer, --exclude.
  std::vector<std::string> table_options() const {
    std::vector<std::string> sets = {"density.preset=\"belhadj2007\""};
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

  void print_report(const density::DensityResult& r) const {
    const auto& s = r.stats;
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
