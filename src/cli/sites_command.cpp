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
#include "core/error.hpp"
#include "density/density.hpp"
#include "hydro/hydrometry.hpp"
#include "io/output_set.hpp"
#include "io/raster_io.hpp"
#include "pipeline/density_folder.hpp"
#include "sites/layers.hpp"
#include "sites/sites.hpp"

namespace terrapolis::cli {
namespace {

/// A DEM instead of a density folder: the density model with its defaults (hydrometry by
/// Belhadj's method, the sea at 0 m as outlet and water), as `terrapolis density` writes it.
pipeline::DensityFolder density_from_dem(const std::string& path, Progress& progress) {
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
    app.add_option("DENSITY_DIR_OR_DEM", dir_,
                   "Folder holding density.tif (float, [0,1]) and buildable.tif (1 = buildable) on the DEM grid, or a DEM "
                   "(the density model is then computed with its defaults)")
        ->required();
    app.add_option("OUTDIR", out_, "Output folder: cities.geojson, city_extents.geojson")->required();
    // The seed is recorded as a 64-bit signed integer field: keep it in that range.
    app.add_option("--seed", options_.seed, "Seed of the candidate draw (0 .. 2^63-1); recorded in the outputs")
        ->check(CLI::Range(std::uint64_t(0), std::uint64_t(std::numeric_limits<std::int64_t>::max())))
        ->capture_default_str();
    app.add_option("--mode", mode_, "Inclusions: paris keeps half-size suburbs (radio-concentric), manhattan removes every inclusion")
        ->check(CLI::IsMember({"paris", "manhattan"}))
        ->capture_default_str();
    app.add_option("--disc-test", disc_test_, "exact: whole disc clear of uninhabitable cells; perimeter: only each circle, as the thesis")
        ->check(CLI::IsMember({"exact", "perimeter"}))
        ->capture_default_str();
    app.add_option("--quotas", quotas_, "Sizes: rank_size (the region's population by a rank-size law) or belhadj2007 (the thesis's census table)")
        ->check(CLI::IsMember({"rank_size", "belhadj2007"}))
        ->capture_default_str();
    app.add_option("--population", options_.population, "rank_size: people in the region (0: 60 people/km2 of buildable land, the world average)")
        ->check(CLI::NonNegativeNumber)
        ->capture_default_str();
    app.add_option("--influence-factor", options_.influence_factor,
                   "rank_size: a settlement's influence area holds this many times its people at the region's mean density; "
                   "smaller settlements (at most half) in it are its suburbs (0: none)")
        ->check(CLI::NonNegativeNumber)
        ->capture_default_str();
    app.add_option("--candidates", options_.candidates, "Candidate positions M (0: 20 x the number of sites)")->check(CLI::NonNegativeNumber);
    app.add_option("--r-min", options_.r_min_m, "Smallest radius, metres (0: the class step dr)")->check(CLI::NonNegativeNumber);
    app.add_option("--r-max", options_.r_max_m, "Radii run up to r_max - dr, metres (0: 1e6 people / 400 + dr)")->check(CLI::NonNegativeNumber);
    app.add_option("--dr-min", options_.dr_min_m, "Smallest class step, metres; dr = max(dr_min, cell size)")->capture_default_str();
    app.add_option("--refill", options_.refill_rounds, "Rounds giving the quota of removed sites back to the growth (0: Algorithm 14 as printed)")
        ->check(CLI::NonNegativeNumber)
        ->capture_default_str();
    app.add_option("--quota-scale", options_.quota_scale,
                   "Multiplies every quota (region area / 543940 km2 of the census fit; 1: the thesis)")
        ->check(CLI::PositiveNumber)
        ->capture_default_str();
    app.add_flag("--report", report_, "Print the quota table");
    app.add_flag("--overwrite", overwrite_, "Replace existing outputs");
  }

  void run(Context& context) override {
    options_.mode = mode_ == "manhattan" ? sites::SitesOptions::Mode::manhattan : sites::SitesOptions::Mode::paris;
    options_.quotas = quotas_ == "belhadj2007" ? sites::SitesOptions::Quotas::belhadj2007 : sites::SitesOptions::Quotas::rank_size;
    options_.disc_test = disc_test_ == "perimeter" ? sites::SitesOptions::DiscTest::perimeter : sites::SitesOptions::DiscTest::exact;
    OutputSet outputs("sites", {dir_}, overwrite_);
    const std::filesystem::path out_dir = outputs.folder(out_);
    const auto t0 = std::chrono::steady_clock::now();
    const bool dem = std::filesystem::is_regular_file(dir_);
    const pipeline::DensityFolder in = dem ? density_from_dem(dir_, context.progress) : pipeline::read_density_folder(dir_);
    const auto t1 = std::chrono::steady_clock::now();
    const sites::SitesResult result = sites::place_sites(in.density, in.buildable, options_, context.progress);
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
    if (options_.quotas == sites::SitesOptions::Quotas::rank_size)
      std::printf("sites: %.0f people (%s), rank-size law down to %.0f\n", result.target_population,
                  result.population_assumed ? "assumed: default people/km2 x buildable land" : "given", options_.min_population);
    std::printf("sites: %zu cities (%d roots, %zu suburbs) from %d candidates, dr %.0f m, seed %llu\n", result.sites.size(), roots,
                result.sites.size() - std::size_t(roots), result.candidates, result.dr_m, static_cast<unsigned long long>(result.seed));
  }

 private:
  std::string dir_, out_, mode_ = "paris", disc_test_ = "exact", quotas_ = "rank_size";
  sites::SitesOptions options_;
  bool report_ = false, overwrite_ = false;
};

}  // namespace

std::unique_ptr<Command> make_sites_command() { return std::make_unique<SitesCommand>(); }

}  // namespace terrapolis::cli
