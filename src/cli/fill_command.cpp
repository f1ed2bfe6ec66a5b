// `terrapolis fill DEM OUT.tif`: fills the nodata voids of a DEM, keeping its grid and CRS.
// SPDX-License-Identifier: MIT
#include <CLI/CLI.hpp>

#include <optional>

#include "cli/command.hpp"
#include "cli/commands_list.hpp"
#include "cli/dem_input.hpp"
#include "cli/terrain_options.hpp"
#include "cli/schema_options.hpp"
#include "core/error.hpp"
#include "io/output_set.hpp"
#include "io/raster_io.hpp"
#include "terrain/fill.hpp"

namespace terrapolis::cli {
namespace {

class FillCommand final : public Command {
 public:
  std::string name() const override { return "fill"; }
  std::string summary() const override { return "Fill the nodata voids of a DEM (thin-plate spline, harmonic or DMMC)"; }

  void setup(CLI::App& app) override {
    input_.add_to(app);
    file_kind(app.add_option("OUT", output_, "Output GeoTIFF (float32, same grid and CRS)")->required(), FileKind::raster_out);
    options_.add(app, true, 0.0);
    app.add_option("--max-void-km2", max_void_km2_, "Voids larger than this (km2, geodesic) stay nodata")->check(CLI::PositiveNumber);
    schema_.setup(app, name());  // --sea-level (water.sea_level_m): cells at or below it connected to the border are sea, whose voids stay
    app.add_flag("--fill-border-voids", fill_border_, "Also fill nodata connected to the grid border (by default it is outside the DEM)");
    add_overwrite_flag(app, overwrite_);
  }

  void run(Context& context) override {
    const terrain::FillParams params = options_.params();
    OutputSet outputs("fill", {input_.path}, overwrite_);
    const std::string out = outputs.file(output_);
    Dem dem = input_.read();
    terrain::VoidOptions voids_options;
    if (max_void_km2_ > 0) voids_options.max_area_km2 = max_void_km2_;
    if (schema_.given("/water/sea_level_m")) voids_options.sea_level_m = schema_.scenario().resolved["water"]["sea_level_m"].get<double>();
    voids_options.fill_border = fill_border_;
    terrain::VoidReport report;
    const auto voids = terrain::find_voids(dem, voids_options, &report);
    context.log.info("fill: " + std::to_string(report.voids) + " voids, " + std::to_string(report.voids_filled) + " filled (" +
                     std::to_string(report.cells_filled) + " cells), " + std::to_string(report.too_large) + " larger than the limit left as nodata");
    terrain::fill_voids(dem, voids, params, &context.progress);
    WriteOptions write;
    write.description = "elevation with voids filled (m)";
    write.metadata = options_.metadata(true);
    write.metadata.emplace_back("TERRAPOLIS_VOIDS_FILLED", std::to_string(report.voids_filled));
    write_raster(out, dem, write);
    outputs.commit();
  }

 private:
  DemInput input_;
  std::string output_;
  TerrainOptions options_;
  double max_void_km2_ = 0;
  SchemaOptions schema_;
  bool fill_border_ = false, overwrite_ = false;
};

}  // namespace

std::unique_ptr<Command> make_fill_command() { return std::make_unique<FillCommand>(); }

}  // namespace terrapolis::cli
