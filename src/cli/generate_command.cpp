// `terrapolis generate OUT.tif --size WxH --cell M`: fractal terrain by DMMC, optionally constrained by a sketch.
// SPDX-License-Identifier: MIT
#include <CLI/CLI.hpp>

#include <cmath>

#include "cli/command.hpp"
#include "cli/commands_list.hpp"
#include "cli/terrain_options.hpp"
#include "cli/schema_options.hpp"
#include "core/error.hpp"
#include "io/output_set.hpp"
#include "io/raster_io.hpp"
#include "terrain/subdivision.hpp"

namespace terrapolis::cli {
namespace {

class GenerateCommand final : public Command {
 public:
  std::string name() const override { return "generate"; }
  std::string summary() const override { return "Generate fractal terrain (Belhadj's DMMC), optionally constrained by a sketch raster"; }

  void setup(CLI::App& app) override {
    file_kind(app.add_option("OUT", output_, "Output GeoTIFF (float32 heights in metres)")->required(), FileKind::raster_out);
    grid_.add(app, true);
    file_kind(app.add_option("--constraints", sketch_, "Sketch raster: cells with a value are fixed heights (m), nodata cells are generated. "
                                             "Warped onto the grid if it has a CRS, else it must have the grid's size"), FileKind::raster_in);
    options_.add(app, false, 1000.0);
    app.add_flag("--overwrite", overwrite_, "Replace OUT if it exists");
  }

  void run(Context& context) override {
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

  std::string output_, sketch_;
  GridOptions grid_;
  TerrainOptions options_;
  bool overwrite_ = false;
};

}  // namespace

std::unique_ptr<Command> make_generate_command() { return std::make_unique<GenerateCommand>(); }

}  // namespace terrapolis::cli
