// `terrapolis convert DEM OUT.tif`: any GDAL DEM to a float32 GeoTIFF in metres (optionally COG).
// SPDX-License-Identifier: MIT
#include <CLI/CLI.hpp>

#include "cli/command.hpp"
#include "cli/commands_list.hpp"
#include "cli/dem_input.hpp"
#include "cli/schema_options.hpp"
#include "io/output_set.hpp"
#include "io/raster_io.hpp"
#include "terrapolis/version.hpp"

namespace terrapolis::cli {
namespace {

class ConvertCommand final : public Command {
 public:
  std::string name() const override { return "convert"; }
  std::string summary() const override {
    return "Copy a DEM as float32 metres GeoTIFF (nodata, scale/offset and feet resolved), tiled or COG";
  }
  void setup(CLI::App& app) override {
    input_.add_to(app);
    file_kind(app.add_option("OUT", out_, "Output GeoTIFF")->required(), FileKind::raster_out);
    app.add_flag("--cog", cog_, "Cloud Optimized GeoTIFF layout");
    add_overwrite_flag(app, overwrite_);
  }
  void run(Context& context) override {
    OutputSet outputs("convert", {input_.path}, overwrite_);
    const std::string out = outputs.file(out_);
    const Dem dem = input_.read();
    WriteOptions options;
    options.cog = cog_;
    options.description = "elevation in metres";
    options.metadata = {{"TERRAPOLIS_VERSION", terrapolis::version}, {"TERRAPOLIS_SOURCE", input_.path}};
    write_raster(out, dem, options);
    outputs.commit();
    context.log.info("wrote " + out_);
  }

 private:
  DemInput input_;
  std::string out_;
  bool cog_ = false, overwrite_ = false;
};

}  // namespace

std::unique_ptr<Command> make_convert_command() { return std::make_unique<ConvertCommand>(); }

}  // namespace terrapolis::cli
