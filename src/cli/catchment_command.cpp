// `terrapolis catchment DEM --outlet X,Y OUT.geojson`: the catchment polygon (and mask) of an outlet.
// SPDX-License-Identifier: MIT
#include <CLI/CLI.hpp>

#include <cmath>
#include <cstdio>
#include <filesystem>

#include "cli/command.hpp"
#include "cli/commands_list.hpp"
#include "cli/dem_input.hpp"
#include "cli/schema_options.hpp"
#include "core/error.hpp"
#include "core/geodesy.hpp"
#include "hydro/accumulation.hpp"
#include "hydro/catchment.hpp"
#include "hydro/depressions.hpp"
#include "hydro/flow_directions.hpp"
#include "io/crs.hpp"
#include "io/output_set.hpp"
#include "io/raster_io.hpp"
#include "io/vector_io.hpp"
#include "pipeline/stage_options.hpp"
#include "terrapolis/version.hpp"

namespace terrapolis::cli {
namespace {

using namespace terrapolis::hydro;

class CatchmentCommand final : public Command {
 public:
  std::string name() const override { return "catchment"; }
  std::string summary() const override { return "Catchment of an outlet: polygon (GeoJSON/GeoPackage) and optional mask raster"; }

  void setup(CLI::App& app) override {
    dem_.add_to(app);
    file_kind(app.add_option("OUT", out_path_, "Output polygon: .geojson or .gpkg")->required(), FileKind::vector_out);
    app.add_option("--outlet", outlet_, "Outlet X,Y: lon,lat (default) or DEM CRS coordinates (--outlet-crs dem)")->required();
    app.add_option("--outlet-crs", outlet_crs_, "CRS of --outlet: lonlat or dem")
        ->check(CLI::IsMember({"lonlat", "dem"}))->capture_default_str();
    app.add_option("--snap-radius", snap_m_, "Snap the outlet to the highest accumulation within this radius (m)")->capture_default_str();
    file_kind(app.add_option("--mask", mask_path_, "Also write the catchment mask (GeoTIFF: 1 inside, 0 outside, 255 nodata)"), FileKind::raster_out);
    schema_.setup(app, name());  // --fill, --sea-level (hydro.fill, water.sea_level_m; no sea unless given)
    add_overwrite_flag(app, overwrite_);
  }

  void run(Context& context) override {
    const auto xy = parse_pair("--outlet", outlet_);
    if (!(snap_m_ >= 0) || !std::isfinite(snap_m_)) throw bad_input("--snap-radius: must be >= 0 metres");
    const std::string ext = std::filesystem::path(out_path_).extension().string();
    if (ext != ".geojson" && ext != ".json" && ext != ".gpkg") throw bad_input(out_path_ + ": output must end in .geojson or .gpkg");
    OutputSet outputs("catchment", {dem_.path}, overwrite_);
    const std::string out = outputs.file(out_path_);
    const std::string mask = mask_path_.empty() ? "" : outputs.file(mask_path_);
    const Dem dem = dem_.read();
    double x = xy[0], y = xy[1];
    if (outlet_crs_ == "lonlat") {
      if (std::abs(y) > 90 || std::abs(x) > 360) throw bad_input("--outlet: '" + outlet_ + "' is not a lon,lat pair");
      const GridLocator locator(dem.georef());
      const auto p = locator.lonlat_to_crs(x, y);
      x = p[0];
      y = p[1];
      if (!std::isfinite(x) || !std::isfinite(y)) throw bad_input("--outlet: cannot be transformed to the DEM's CRS");
    }
    HydroOptions o = pipeline::hydro_options(schema_.scenario());
    if (!schema_.given("/water/sea_level_m")) o.sea_level.reset();  // as `terrapolis hydro`: no sea unless told
    const std::optional<double> sea = o.sea_level;
    const FillMethod fill = o.fill;
    const CellMetrics metrics = cell_metrics(dem.georef(), dem.cols(), dem.rows());
    const Dem filled = fill_depressions(dem, {fill, sea}, context.progress);
    const auto d8 = d8_directions(filled, metrics, sea, context.progress);
    const FlowRouter router(filled, d8, metrics, FlowMethod::d8);
    const auto area = accumulate(filled, router, metrics, {}, context.progress);
    const Catchment c = [&] {
      try {
        return delineate_catchment(d8, area, metrics, x, y, snap_m_, context.progress);
      } catch (const Error& e) {  // the module names its inputs; this command knows them by its flags
        std::string m = e.what();
        if (m.starts_with("outlet: ")) m = "--" + m;
        throw Error(e.kind(), m);
      }
    }();
    write_vector(out, c.polygon);
    if (!mask.empty()) {
      WriteOptions w;
      w.description = "Catchment mask: 1 inside, 0 outside";
      w.metadata = {{"TERRAPOLIS_VERSION", version}, {"TERRAPOLIS_COMMAND", "catchment"}, {"OUTLET", outlet_},
                    {"AREA_KM2", std::to_string(c.area_km2)}};
      write_raster(mask, c.mask, w);
    }
    outputs.commit();
    const GridLocator locator(dem.georef());
    const auto ll = locator.crs_to_lonlat(c.outlet_x, c.outlet_y);
    char line[256];
    std::snprintf(line, sizeof line, "catchment: outlet snapped to cell (%d, %d) at lon %.6f lat %.6f, %zu cells, %.3f km2",
                  c.outlet_col, c.outlet_row, ll[0], ll[1], c.cells, c.area_km2);
    context.log.info(line);
  }

 private:
  DemInput dem_;
  SchemaOptions schema_;
  std::string out_path_, outlet_, outlet_crs_ = "lonlat", mask_path_;
  double snap_m_ = 0;
  bool overwrite_ = false;
};

}  // namespace

std::unique_ptr<Command> make_catchment_command() { return std::make_unique<CatchmentCommand>(); }

}  // namespace terrapolis::cli
