// `terrapolis generate OUT.tif --size WxH --cell M`: fractal terrain by DMMC, optionally constrained by a sketch,
// or a region grown from its river skeleton (--method coast | planar, generate_methods.hpp).
// SPDX-License-Identifier: MIT
#include <CLI/CLI.hpp>

#include <cmath>

#include "cli/command.hpp"
#include "cli/commands_list.hpp"
#include "cli/generate_methods.hpp"
#include "cli/terrain_options.hpp"
#include "core/error.hpp"
#include "io/output_set.hpp"
#include "io/raster_io.hpp"
#include "io/vector_io.hpp"
#include "terrain/subdivision.hpp"

namespace terrapolis::cli {
namespace {

class GenerateCommand final : public Command {
 public:
  std::string name() const override { return "generate"; }
  std::string summary() const override {
    return "Generate terrain: fractal (Belhadj's DMMC, optionally constrained by a sketch) or from a river skeleton (coast, planar)";
  }

  void setup(CLI::App& app) override {
    app.add_option("OUT", output_, "Output GeoTIFF (float32 heights in metres)")->required();
    grid_.add(app, true);
    app.add_option("--constraints", sketch_, "Sketch raster: cells with a value are fixed heights (m), nodata cells are generated. "
                                             "Warped onto the grid if it has a CRS, else it must have the grid's size");
    options_.add(app, false, 1000.0);
    app.add_option("--method", method_, "dmmc | coast (Génévaux et al.: rivers grown from a coastline) | planar (binary-tree basin on a planar map)")
        ->capture_default_str();
    app.add_option("--skeleton", skeleton_, "coast, planar: GeoJSON of the rivers and ridges the terrain was built from (default: OUT's name + _skeleton.geojson)");
    coast_.add(app);
    planar_.add(app);
    app.add_flag("--overwrite", overwrite_, "Replace OUT if it exists");
  }

  void run(Context& context) override {
    if (method_ == "coast" || method_ == "planar") return run_skeleton(context);
    if (method_ != "dmmc") throw bad_input("--method: unknown method '" + method_ + "' (expected dmmc, coast or planar)");
    terrain::FillParams params = options_.params();
    Raster<float> grid = grid_.make();
    OutputSet outputs("generate", {sketch_}, overwrite_);
    const std::string out = outputs.file(output_);
    if (!sketch_.empty()) {
      const RasterHeader header = read_header(sketch_, ReadOptions{std::nullopt, std::string("EPSG:4326")});
      Raster<float> sketch;
      const bool sketch_has_crs = !read_header_has_no_crs();
      if (!grid.georef().crs.empty() && sketch_has_crs) {
        sketch = read_resampled(sketch_, grid.georef(), grid.cols(), grid.rows(), Resampling::nearest);
      } else {
        if (header.cols != grid.cols() || header.rows != grid.rows())
          throw bad_input(sketch_ + ": is " + std::to_string(header.cols) + "x" + std::to_string(header.rows) +
                          " cells but the grid is " + grid_.size + " and one of them has no CRS to warp it");
        sketch = read_sketch_pixels();
      }
      grid.values() = sketch.values();
      std::size_t fixed = 0;
      for (std::size_t i = 0; i < grid.size(); ++i) fixed += std::isfinite(grid[i]) ? 1 : 0;
      context.log.info("generate: " + std::to_string(fixed) + " cells fixed by the sketch");
    }
    params.dmmc.low_pass = false;  // generation wants the fractal detail, not the smoothest surface
    terrain::dmmc(grid, params.dmmc, &context.progress);
    WriteOptions write;
    write.description = "generated elevation (m)";
    write.metadata = options_.metadata(false);
    write_raster(out, grid, write);
    outputs.commit();
  }

 private:
  /// The skeleton generators: a georeferenced DEM (default: a local azimuthal equidistant grid
  /// centred on the origin, so that QGIS and `terrapolis run` place it) and its skeleton.
  void run_skeleton(Context& context) {
    if (!sketch_.empty()) throw bad_input("--constraints: only --method dmmc takes a sketch");
    GridOptions grid_options = grid_;
    if (grid_options.crs.empty()) grid_options.crs = "+proj=aeqd +lat_0=0 +lon_0=0 +x_0=0 +y_0=0 +datum=WGS84 +units=m +no_defs";
    Raster<float> grid = grid_options.make();
    if (grid_.crs.empty() && grid_.origin.empty()) {  // centre the local grid on the projection's origin
      auto t = grid.georef().transform;
      t[0] = -0.5 * grid.cols() * t[1];
      t[3] = -0.5 * grid.rows() * t[5];
      Georef georef = grid.georef();
      georef.transform = t;
      grid = Raster<float>(grid.cols(), grid.rows(), georef, std::numeric_limits<float>::quiet_NaN());
    }
    std::vector<std::string> inputs;
    if (!coast_.coast.empty()) inputs.push_back(coast_.coast);
    OutputSet outputs("generate", inputs, overwrite_);
    const std::string out = outputs.file(output_);
    std::string skeleton_path = skeleton_;
    if (skeleton_path.empty()) {
      const auto dot = output_.find_last_of('.');
      skeleton_path = (dot == std::string::npos || output_.find('/', dot) != std::string::npos ? output_ : output_.substr(0, dot)) + "_skeleton.geojson";
    }
    const std::string skeleton = outputs.file(skeleton_path);
    const GeneratedRegion region = method_ == "coast" ? coast_.run(grid, options_.seed, context) : planar_.run(grid, options_.seed, context);
    WriteOptions write;
    write.description = "generated elevation (m)";
    write.metadata = region.metadata;
    write.metadata.emplace_back("TERRAPOLIS_METHOD", method_);
    write_concurrently({[&] { write_raster(out, grid, write); }, [&] { write_vector(skeleton, region.skeleton, true); }});
    outputs.commit();
  }

  bool read_header_has_no_crs() const {
    try {
      (void)read_header(sketch_);
      return false;
    } catch (const Error&) {
      return true;  // read_header refuses a file without a CRS; the assumed-CRS read above proved it is readable
    }
  }
  Raster<float> read_sketch_pixels() const {
    ReadOptions read;
    read.assume_crs = "EPSG:4326";  // only the pixel values are used
    try {
      return read_dem(sketch_, read);
    } catch (const Error& e) {
      // A sketch may hold nothing but nodata; everything is then generated.
      const RasterHeader header = read_header(sketch_, read);
      Raster<float> empty(header.cols, header.rows, header.georef, std::numeric_limits<float>::quiet_NaN());
      if (std::string(e.what()).find("no data") != std::string::npos) return empty;
      throw;
    }
  }

  std::string output_, sketch_, method_ = "dmmc", skeleton_;
  GridOptions grid_;
  CoastOptions coast_;
  PlanarOptions planar_;
  TerrainOptions options_;
  bool overwrite_ = false;
};

}  // namespace

std::unique_ptr<Command> make_generate_command() { return std::make_unique<GenerateCommand>(); }

}  // namespace terrapolis::cli
