// `terrapolis sites DENSITY_DIR_OR_DEM OUTDIR`: city sites and their hierarchy from a density model (Belhadj §4.3.1).
// SPDX-License-Identifier: MIT
#include <CLI/CLI.hpp>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>

#include "cli/command.hpp"
#include "cli/commands_list.hpp"
#include "cli/schema_options.hpp"
#include "core/error.hpp"
#include "density/density.hpp"
#include "hydro/hydrometry.hpp"
#include "io/output_set.hpp"
#include "io/raster_io.hpp"
#include "pipeline/stage_options.hpp"
#include "sites/layers.hpp"
#include "sites/sites.hpp"

namespace terrapolis::cli {
namespace {

/// density.tif (float, [0,1]) and buildable.tif (1 buildable, anything else not) on one grid.
struct DensityInputs {
  Raster<float> density;
  Raster<std::uint8_t> buildable;
};

DensityInputs read_density_dir(const std::string& dir) {
  std::error_code ec;
  if (!std::filesystem::is_directory(dir, ec)) throw bad_input(dir + ": no such folder (expected density.tif and buildable.tif in it)");
  const std::string density_path = (std::filesystem::path(dir) / "density.tif").string();
  const std::string buildable_path = (std::filesystem::path(dir) / "buildable.tif").string();
  if (!std::filesystem::exists(buildable_path, ec)) throw bad_input(buildable_path + ": no such file");
  DensityInputs in;
  in.density = read_dem(density_path);
  for (std::size_t i = 0; i < in.density.size(); ++i) {
    const float v = in.density[i];
    if (!std::isnan(v) && !(v >= -1e-6f && v <= 1.0f + 1e-6f))
      throw bad_input(density_path + ": density values must lie in [0,1] (found " + std::to_string(v) + ")");
  }
  const RasterHeader header = read_header(buildable_path);
  if (header.cols != in.density.cols() || header.rows != in.density.rows())
    throw bad_input(buildable_path + ": not on the grid of density.tif (" + std::to_string(header.cols) + "x" + std::to_string(header.rows) +
                    " cells instead of " + std::to_string(in.density.cols()) + "x" + std::to_string(in.density.rows()) + ")");
  for (int k = 0; k < 6; ++k)
    if (std::abs(header.georef.transform[std::size_t(k)] - in.density.georef().transform[std::size_t(k)]) >
        1e-9 * std::max(1.0, std::abs(in.density.georef().transform[std::size_t(k)])))
      throw bad_input(buildable_path + ": not on the grid of density.tif (different geotransform)");
  // Same grid (checked above): read the mask as is, nodata as NaN, without warping.
  const Raster<float> mask = read_dem(buildable_path);
  in.buildable = in.density.like<std::uint8_t>(0);
  for (std::size_t i = 0; i < mask.size(); ++i) in.buildable[i] = mask[i] == 1.0f ? 1 : 0;  // nodata (NaN) is not buildable
  return in;
}

/// A DEM instead of a density folder: the density model with its defaults (hydrometry by
/// Belhadj's method, the sea at 0 m as outlet and water), as `terrapolis density` writes it.
DensityInputs density_from_dem(const std::string& path, Progress& progress) {
  const Dem dem = read_dem(path);
  const density::DensityOptions options;
  hydro::HydrometryOptions hydrometry;
  hydrometry.sea_level = options.sea_level_m;
  density::DensityResult model = density::compute_density(dem, hydro::compute_hydrometry(dem, hydrometry, progress), options, progress);
  return {std::move(model.density), std::move(model.buildable)};
}

class SitesCommand final : public Command {
 public:
  std::string name() const override { return "sites"; }
  std::string summary() const override { return "Place city sites with size quotas and their hierarchy on a density model (Belhadj Alg. 13-15)"; }

  void setup(CLI::App& app) override {
    file_kind(app.add_option("DENSITY_DIR_OR_DEM", dir_,
                   "Folder holding density.tif (float, [0,1]) and buildable.tif (1 = buildable) on the DEM grid, or a DEM "
                   "(the density model is then computed with its defaults)")
        ->required(), FileKind::folder_in);
    file_kind(app.add_option("OUTDIR", out_, "Output folder: cities.geojson, city_extents.geojson")->required(), FileKind::folder_out);
    schema_.setup(app, name());
    app.add_flag("--report", report_, "Print the quota table");
    app.add_flag("--overwrite", overwrite_, "Replace existing outputs");
  }

  void run(Context& context) override {
    // The command has always used the allometry's exact 5/6 (the scenario's default is 0.8333).
    const pipeline::Scenario scenario = schema_.scenario({"sites.area_exponent=" + nlohmann::json(5.0 / 6.0).dump()});
    const sites::SitesOptions options = schema_.settings([&] { return pipeline::sites_options(scenario); });
    OutputSet outputs("sites", {dir_}, overwrite_);
    const std::filesystem::path out_dir = outputs.folder(out_);
    const auto t0 = std::chrono::steady_clock::now();
    const bool dem = std::filesystem::is_regular_file(dir_);
    const DensityInputs in = dem ? density_from_dem(dir_, context.progress) : read_density_dir(dir_);
    const auto t1 = std::chrono::steady_clock::now();
    const sites::SitesResult result = sites::place_sites(in.density, in.buildable, options, context.progress);
    const auto t2 = std::chrono::steady_clock::now();
    const Crs& crs = in.density.georef().crs;
    const VectorLayer cities = sites::cities_layer(result, crs);
    const VectorLayer extents = sites::city_extents_layer(result, crs);
    write_vector((out_dir / "cities.geojson").string(), cities);
    write_vector((out_dir / "city_extents.geojson").string(), extents);
    outputs.commit();
    const auto t3 = std::chrono::steady_clock::now();
    const auto seconds = [](auto a, auto b) { return std::to_string(std::chrono::duration<double>(b - a).count()); };
    context.log.detail("sites: read " + seconds(t0, t1) + " s, placement " + seconds(t1, t2) + " s, write " + seconds(t2, t3) + " s");

    int roots = 0, placed = 0, quota = 0;
    for (const auto& s : result.sites) roots += s.parent < 0;
    for (const auto& q : result.quotas) placed += q.placed, quota += q.quota;
    if (report_) {
      std::printf("class  radius_m   quota  placed    kept\n");
      for (std::size_t k = 0; k < result.quotas.size(); ++k) {
        const auto& q = result.quotas[k];
        std::printf("%5zu %9.1f %7d %7d %7d\n", k, q.radius_m, q.quota, q.placed, q.kept);
      }
      std::printf("total %9s %7d %7d %7zu\n", "", quota, placed, result.sites.size());
    }
    if (options.quotas == sites::SitesOptions::Quotas::rank_size)
      std::printf("sites: %.0f people (%s), rank-size law down to %.0f\n", result.target_population,
                  result.population_assumed ? "assumed: default people/km2 x buildable land" : "given", options.min_population);
    std::printf("sites: %zu cities (%d roots, %zu suburbs) from %d candidates, dr %.0f m, seed %llu\n", result.sites.size(), roots,
                result.sites.size() - std::size_t(roots), result.candidates, result.dr_m, static_cast<unsigned long long>(result.seed));
  }

 private:
  std::string dir_, out_;
  SchemaOptions schema_;
  bool report_ = false, overwrite_ = false;
};

}  // namespace

std::unique_ptr<Command> make_sites_command() { return std::make_unique<SitesCommand>(); }

}  // namespace terrapolis::cli
