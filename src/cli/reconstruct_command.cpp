// `terrapolis reconstruct SAMPLES OUT.tif`: a full DEM from sparse heights (points or a sparse raster).
// SPDX-License-Identifier: MIT
#include <CLI/CLI.hpp>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <sstream>

#include "cli/command.hpp"
#include "cli/commands_list.hpp"
#include "cli/dem_input.hpp"
#include "cli/terrain_options.hpp"
#include "cli/schema_options.hpp"
#include "core/error.hpp"
#include "io/crs.hpp"
#include "io/output_set.hpp"
#include "io/raster_io.hpp"
#include "io/vector_io.hpp"
#include "terrain/fill.hpp"

namespace terrapolis::cli {
namespace {

std::string lower_extension(const std::string& path) {
  const auto dot = path.find_last_of('.');
  if (dot == std::string::npos) return "";
  std::string e = path.substr(dot + 1);
  std::transform(e.begin(), e.end(), e.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return e;
}

/// lon, lat, z rows of a CSV file (comma, semicolon, tab or space separated; an optional header line).
std::vector<std::array<double, 3>> read_csv_points(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw bad_input(path + ": cannot open the samples file");
  std::vector<std::array<double, 3>> points;
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    for (char& c : line)
      if (c == ',' || c == ';' || c == '\t' || c == '\r') c = ' ';
    std::istringstream fields(line);
    std::array<double, 3> p{};
    if (!(fields >> p[0] >> p[1] >> p[2])) {
      if (line.find_first_not_of(' ') == std::string::npos) continue;
      if (number == 1) continue;  // header
      throw bad_input(path + ": line " + std::to_string(number) + " is not 'lon,lat,z'");
    }
    if (!std::isfinite(p[2]) || std::abs(p[1]) > 90 || std::abs(p[0]) > 360)
      throw bad_input(path + ": line " + std::to_string(number) + " has an invalid lon/lat/z");
    points.push_back(p);
  }
  return points;
}

class ReconstructCommand final : public Command {
 public:
  std::string name() const override { return "reconstruct"; }
  std::string summary() const override { return "Rebuild a DEM from sparse heights: points (CSV lon,lat,z or GeoJSON) or a sparse raster"; }

  void setup(CLI::App& app) override {
    file_kind(app.add_option("SAMPLES", input_, "Heights: .csv (lon,lat,z), a vector file of points (.geojson, .gpkg) or a raster with nodata")->required(), FileKind::file_in);
    file_kind(app.add_option("OUT", output_, "Output GeoTIFF (float32, metres)")->required(), FileKind::raster_out);
    file_kind(app.add_option("--like", like_, "DEM whose grid and CRS the output takes"), FileKind::raster_in);
    dem_.add_read_options(app, "of the --like DEM, or of a raster of SAMPLES without --like");
    grid_.add(app, false);
    app.add_option("--z-field", z_field_, "Vector samples: the field holding the height in metres")->capture_default_str();
    options_.add(app, true, 0.0);
    add_overwrite_flag(app, overwrite_);
  }

  void run(Context& context) override {
    const terrain::FillParams params = options_.params();
    if (!like_.empty() && grid_.given()) throw bad_input("--like and --size: give one grid, not both");
    OutputSet outputs("reconstruct", {input_, like_}, overwrite_);
    const std::string out = outputs.file(output_);
    const std::string ext = lower_extension(input_);
    const bool points = ext == "csv" || ext == "txt" || ext == "geojson" || ext == "json" || ext == "gpkg" || ext == "shp";
    Raster<float> grid;
    if (!like_.empty()) {
      const RasterHeader header = dem_.header(like_);
      grid = Raster<float>(header.cols, header.rows, header.georef, std::numeric_limits<float>::quiet_NaN());
    } else if (grid_.given()) {
      grid = grid_.make();
    } else if (!points) {
      grid = dem_.read(input_);  // a sparse raster on its own grid
    } else {
      throw bad_input(input_ + ": points need a grid; give --like DEM or --size WxH --cell M --crs EPSG:n");
    }
    if (points) add_points(grid, ext, context);
    else if (!like_.empty() || grid_.given()) {
      if (grid.georef().crs.empty()) throw bad_input("--crs: a raster of samples can only be placed on a georeferenced grid");
      grid.values() = read_resampled(input_, grid.georef(), grid.cols(), grid.rows(), Resampling::nearest).values();
    }
    std::size_t known = 0;
    for (std::size_t i = 0; i < grid.size(); ++i) known += std::isfinite(grid[i]) ? 1 : 0;
    if (known == 0) throw bad_input(input_ + ": no sample falls on the grid");
    context.log.info("reconstruct: " + std::to_string(known) + " known cells of " + std::to_string(grid.size()) + " (" +
                     std::to_string(100.0 * double(known) / double(grid.size())).substr(0, 5) + " %), method " + options_.method);
    terrain::reconstruct(grid, params, &context.progress);
    WriteOptions write;
    write.description = "elevation reconstructed from samples (m)";
    write.metadata = options_.metadata(true);
    write.metadata.emplace_back("TERRAPOLIS_SAMPLES", std::to_string(known));
    write_raster(out, grid, write);
    outputs.commit();
  }

 private:
  /// Puts the points on the grid; several points in one cell are averaged.
  void add_points(Raster<float>& grid, const std::string& ext, Context& context) const {
    if (grid.georef().crs.empty()) throw bad_input("--crs: lon/lat samples can only be placed on a georeferenced grid");
    const GridLocator locator(grid.georef());
    std::vector<double> sum(grid.size(), 0.0);
    std::vector<int> count(grid.size(), 0);
    std::size_t outside = 0;
    auto put = [&](double x, double y, double z) {
      const auto px = locator.crs_to_pixel(x, y);
      const int c = int(std::floor(px[0])), r = int(std::floor(px[1]));
      if (!std::isfinite(px[0]) || !grid.inside(c, r)) { ++outside; return; }
      sum[grid.index(c, r)] += z;
      ++count[grid.index(c, r)];
    };
    if (ext == "csv" || ext == "txt") {
      for (const auto& p : read_csv_points(input_)) {
        const auto xy = locator.lonlat_to_crs(p[0], p[1]);
        put(xy[0], xy[1], p[2]);
      }
    } else {
      const VectorLayer layer = read_vector(input_, grid.georef().crs);
      if (layer.geometry != GeometryType::point) throw bad_input(input_ + ": expected points");
      const int field = layer.field_index(z_field_);
      if (field < 0) throw bad_input(input_ + ": has no field '" + z_field_ + "' (choose one with --z-field)");
      for (const Feature& f : layer.features) {
        const FieldValue& v = f.values[std::size_t(field)];
        double z = NAN;
        if (const auto* d = std::get_if<double>(&v)) z = *d;
        else if (const auto* i = std::get_if<std::int64_t>(&v)) z = double(*i);
        if (!std::isfinite(z) || f.parts.empty() || f.parts[0].empty()) continue;
        put(f.parts[0][0][0], f.parts[0][0][1], z);
      }
    }
    for (std::size_t i = 0; i < grid.size(); ++i)
      if (count[i]) grid[i] = float(sum[i] / count[i]);
    if (outside) context.log.warn("reconstruct: " + std::to_string(outside) + " samples outside the grid were ignored");
  }

  DemInput dem_;  // --band and --assume-crs of the DEM the grid comes from
  std::string input_, output_, like_, z_field_ = "z";
  GridOptions grid_;
  TerrainOptions options_;
  bool overwrite_ = false;
};

}  // namespace

std::unique_ptr<Command> make_reconstruct_command() { return std::make_unique<ReconstructCommand>(); }

}  // namespace terrapolis::cli
