// `terrapolis info DEM`: what a DEM is, where it is, and how big its cells are in metres.
// SPDX-License-Identifier: MIT
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "cli/command.hpp"
#include "cli/commands_list.hpp"
#include "cli/dem_input.hpp"
#include "core/geodesy.hpp"
#include "io/crs.hpp"
#include "io/raster_io.hpp"

namespace terrapolis::cli {
namespace {

class InfoCommand final : public Command {
 public:
  std::string name() const override { return "info"; }
  std::string summary() const override { return "Describe a DEM: size, CRS, cell size in metres, extent in lon/lat, elevations"; }

  void setup(CLI::App& app) override {
    input_.add_to(app);
    app.add_flag("--json", json_, "Machine-readable output");
  }

  void run(Context&) override {
    const RasterHeader header = read_header(input_.path, input_.options());
    const Dem dem = input_.read();
    const std::string& path_ = input_.path;

    double lo = std::numeric_limits<double>::infinity(), hi = -lo, sum = 0;
    std::size_t valid = 0;
    for (std::size_t i = 0; i < dem.size(); ++i) {
      if (dem.is_nodata(i)) continue;
      lo = std::min(lo, double(dem[i]));
      hi = std::max(hi, double(dem[i]));
      sum += dem[i];
      ++valid;
    }
    const int centre_row = dem.rows() / 2;
    const CellMetrics metrics = cell_metrics(dem.georef(), dem.cols(), dem.rows());
    const GridLocator locator(dem.georef());
    // Extent in lon/lat from points along the border (a projected grid's edges are curves in lon/lat).
    double lon0 = 1e300, lon1 = -1e300, lat0 = 1e300, lat1 = -1e300;
    const int samples = 32;
    for (int i = 0; i <= samples; ++i) {
      const double f = double(i) / samples;
      const double pts[4][2] = {{f * dem.cols(), 0}, {f * dem.cols(), double(dem.rows())}, {0, f * dem.rows()}, {double(dem.cols()), f * dem.rows()}};
      for (const auto& p : pts) {
        const auto xy = locator.pixel_to_crs(p[0], p[1]);
        const auto ll = locator.crs_to_lonlat(xy[0], xy[1]);
        if (std::isnan(ll[0])) continue;
        lon0 = std::min(lon0, ll[0]); lon1 = std::max(lon1, ll[0]);
        lat0 = std::min(lat0, ll[1]); lat1 = std::max(lat1, ll[1]);
      }
    }
    const Crs& crs = dem.georef().crs;
    const double nodata_share = 1.0 - double(valid) / double(dem.size());
    const double width = metrics.width_m[centre_row];
    const double height = metrics.height_m[centre_row];
    const double area_km2 = metrics.total_area_m2(dem.cols()) / 1e6;

    if (json_) {
      nlohmann::ordered_json j;
      j["file"] = path_;
      j["driver"] = header.driver;
      j["data_type"] = header.data_type;
      j["cols"] = dem.cols();
      j["rows"] = dem.rows();
      j["bands"] = header.bands;
      j["crs"] = {{"name", crs.name}, {"epsg", crs.epsg ? nlohmann::json(*crs.epsg) : nlohmann::json(nullptr)}, {"geographic", crs.geographic}};
      j["geotransform"] = dem.georef().transform;
      j["cell_size_m"] = {{"east_west", width}, {"north_south", height}, {"at_row", centre_row}};
      j["area_km2"] = area_km2;
      j["extent_lonlat"] = {{"west", lon0}, {"south", lat0}, {"east", lon1}, {"north", lat1}};
      j["elevation_m"] = {{"min", lo}, {"max", hi}, {"mean", sum / double(valid)}};
      j["nodata"] = {{"value", header.nodata ? nlohmann::json(*header.nodata) : nlohmann::json(nullptr)}, {"share", nodata_share}};
      std::printf("%s\n", j.dump(2).c_str());
      return;
    }
    std::printf("File:       %s (%s, %s)\n", path_.c_str(), header.driver.c_str(), header.data_type.c_str());
    std::printf("Size:       %d x %d cells, %d band%s\n", dem.cols(), dem.rows(), header.bands, header.bands > 1 ? "s" : "");
    std::printf("CRS:        %s%s, %s\n", crs.name.c_str(), crs.epsg ? (" (EPSG:" + std::to_string(*crs.epsg) + ")").c_str() : " (no EPSG code)",
                crs.geographic ? "geographic" : "projected");
    std::printf("Cell size:  %.2f m east-west x %.2f m north-south at the centre row\n", width, height);
    std::printf("Area:       %.2f km2\n", area_km2);
    std::printf("Extent:     lon %.6f .. %.6f, lat %.6f .. %.6f (WGS 84)\n", lon0, lon1, lat0, lat1);
    std::printf("Elevation:  %.2f .. %.2f m, mean %.2f m\n", lo, hi, sum / double(valid));
    if (header.nodata) std::printf("Nodata:     %.2f %% of cells (value %g)\n", 100.0 * nodata_share, *header.nodata);
    else std::printf("Nodata:     %.2f %% of cells (no nodata value)\n", 100.0 * nodata_share);
  }

 private:
  DemInput input_;
  bool json_ = false;
};

}  // namespace

std::unique_ptr<Command> make_info_command() { return std::make_unique<InfoCommand>(); }

}  // namespace terrapolis::cli
