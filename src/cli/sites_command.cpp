// `terrapolis sites DENSITY_DIR_OR_DEM OUTDIR`: city sites and their hierarchy from a density model (Belhadj §4.3.1).
// SPDX-License-Identifier: MIT
#include <CLI/CLI.hpp>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <memory>
#include <optional>

#include "cli/command.hpp"
#include "cli/commands_list.hpp"
#include "cli/dem_input.hpp"
#include "cli/schema_options.hpp"
#include "core/error.hpp"
#include "density/density.hpp"
#include "hydro/hydrometry.hpp"
#include "io/output_set.hpp"
#include "io/raster_io.hpp"
#include "pipeline/by_tiles.hpp"
#include "pipeline/density_folder.hpp"
#include "pipeline/places.hpp"
#include "pipeline/stage_options.hpp"
#include "pipeline/stages.hpp"
#include "sites/layers.hpp"
#include "sites/sites.hpp"

namespace terrapolis::cli {
namespace {

class SitesCommand final : public Command {
 public:
  std::string name() const override { return "sites"; }
  std::string summary() const override { return "Place city sites with size quotas and their hierarchy on a density model (Belhadj Alg. 13-15)"; }

  void setup(CLI::App& app) override {
    file_kind(app.add_option("DENSITY_DIR_OR_DEM", dir_,
                   "Folder holding density.tif (float, [0,1]) and buildable.tif (1 = buildable) on the DEM grid (or the .vrt "
                   "mosaics of a tiled density, read by tiles), or a DEM "
                   "(the density is then computed as a run's hydro and density stages do, with the scenario's defaults)")
        ->required(), FileKind::folder_in);
    dem_.add_read_options(app, "of a DEM");
    file_kind(app.add_option("OUTDIR", out_, "Output folder: cities.geojson, city_extents.geojson")->required(), FileKind::folder_out);
    schema_.setup(app, name());
    app.add_flag("--report", report_, "Print the quota table");
    add_overwrite_flag(app, overwrite_);
  }

  void run(Context& context) override {
    const pipeline::Scenario scenario = schema_.scenario();
    sites::SitesOptions options = schema_.settings([&] { return pipeline::sites_options(scenario); });
    const std::string existing_file = scenario.path("/sites/existing");
    OutputSet outputs("sites", {dir_, existing_file}, overwrite_);
    const std::filesystem::path out_dir = outputs.folder(out_);
    const auto t0 = std::chrono::steady_clock::now();
    const bool dem = std::filesystem::is_regular_file(dir_);
    if (!dem && dem_.given()) throw bad_input("--band, --assume-crs: only for a DEM, and " + dir_ + " is a density folder");
    const pipeline::TileSettings tiles = schema_.settings([&] { return pipeline::tile_settings(scenario); });
    if (dem && tiles.given())
      throw bad_input("--tile-size, --memory-limit: for a density folder (a DEM by tiles: terrapolis run --until network)");
    // A density folder written by tiles (density.vrt), or a limit given: the land read by bands and blocks.
    const std::string density = dem ? "" : pipeline::density_folder_file(dir_, "density");
    pipeline::DensityFolder in;
    std::unique_ptr<sites::Land> land;
    if (!dem && (tiles.given() || std::filesystem::path(density).extension() == ".vrt")) {
      const double reserved = reserve_reader_memory(tiles.limit_mb());
      land = std::make_unique<pipeline::LandTiles>(density, pipeline::density_folder_file(dir_, "buildable"), std::nullopt, tiles, reserved);
    } else {
      in = dem ? run_density(scenario, dem_.read(dir_), options, context) : pipeline::read_density_folder(dir_);
      land = std::make_unique<sites::LandRasters>(in.density, in.buildable);
    }
    pipeline::ExistingPlaces existing;
    if (!existing_file.empty()) {
      existing = pipeline::read_existing_places(existing_file, *land);
      options.existing = existing.sites;
      for (const auto& w : pipeline::existing_place_warnings(existing)) context.log.warn(w);
    }
    const auto t1 = std::chrono::steady_clock::now();
    const sites::SitesResult result = sites::place_sites(*land, options, context.progress);
    const auto t2 = std::chrono::steady_clock::now();
    const Crs& crs = land->georef().crs;
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
      std::printf("sites: %.0f people (%s), %.0f in settlements, rank-size exponent %.2f (%s)\n", result.target_population,
                  result.population_assumed ? "assumed: default people/km2 x buildable land" : "given", result.settled_population,
                  result.sizes_exponent, options.sizes == sites::SitesOptions::Sizes::catchment ? "from the catchments" : "zipf_exponent");
    if (result.count_limited)
      std::printf("sites: count held to the %lld settlements the land holds %g km apart (--spacing; closer where denser than an urban centre)\n",
                  static_cast<long long>(result.room), options.spacing_km);
    if (result.crowded > 0)
      std::printf("sites: %lld placed without a disc clear of water and steep land\n", static_cast<long long>(result.crowded));
    if (result.unplaced > 0)
      std::printf("sites: %lld settlements of the law (%lld people) found no place (raise --candidates)\n", static_cast<long long>(result.unplaced),
                  static_cast<long long>(result.unplaced_people));
    if (!existing_file.empty())
      std::printf("sites: %zu existing places (%.0f people; %zu moved to land, %zu outside the DEM left out), %zu generated\n",
                  existing.sites.size(), result.existing_population, existing.moved.size(), existing.outside.size(),
                  result.sites.size() - existing.sites.size());
    if (result.growth_people > 0)
      std::printf("sites: growth +%g%%: %lld new settled people, %lld to the existing places, %lld in new settlements\n",
                  100 * options.growth, static_cast<long long>(result.growth_people), static_cast<long long>(result.growth_to_existing),
                  static_cast<long long>(result.growth_to_new));
    std::printf("sites: %zu cities (%d roots, %zu suburbs) from %d candidates, dr %.0f m, seed %llu\n", result.sites.size(), roots,
                result.sites.size() - std::size_t(roots), result.candidates, result.dr_m, static_cast<unsigned long long>(result.seed));
  }

 private:
  /// A DEM instead of a density folder: the density the run's hydro and density stages compute,
  /// with the scenario's settings, and the land it finds for the default population (as a run).
  pipeline::DensityFolder run_density(const pipeline::Scenario& scenario, const Dem& dem, sites::SitesOptions& options, Context& context) const {
    pipeline::StageSettings settings;
    for (const char* stage : {"hydro", "density"})
      schema_.settings([&] {
        pipeline::stage(stage).prepare(scenario, grid_of(dem), settings);
        return 0;
      });
    density::DensityResult model = pipeline::run_density(scenario, settings, dem, context.progress, context.log);
    options.land_area_km2 = pipeline::land_area_figure(model.stats);
    return {std::move(model.density), std::move(model.buildable)};
  }

  std::string dir_, out_;
  DemInput dem_;  // --band and --assume-crs when DENSITY_DIR_OR_DEM is a DEM
  SchemaOptions schema_;
  bool report_ = false, overwrite_ = false;
};

}  // namespace

std::unique_ptr<Command> make_sites_command() { return std::make_unique<SitesCommand>(); }

}  // namespace terrapolis::cli
