// `terrapolis hydro DEM OUTDIR`: conditioned DEM, D8 directions, accumulation, hydrometry, streams.
// SPDX-License-Identifier: MIT
#include <CLI/CLI.hpp>

#include <array>
#include <cmath>
#include <filesystem>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "cli/command.hpp"
#include "cli/commands_list.hpp"
#include "cli/dem_input.hpp"
#include "cli/hydro_tiles.hpp"
#include "pipeline/by_tiles.hpp"
#include "cli/schema_options.hpp"
#include "core/error.hpp"
#include "hydro/catchment.hpp"
#include "hydro/hydro.hpp"
#include "hydro/river_types.hpp"
#include "io/output_set.hpp"
#include "io/raster_io.hpp"
#include "io/text_io.hpp"
#include "io/vector_io.hpp"
#include "pipeline/descriptions.hpp"
#include "pipeline/stage_options.hpp"
#include "terrapolis/version.hpp"

namespace terrapolis::cli {
namespace {

namespace fs = std::filesystem;
using namespace terrapolis::hydro;

std::string number(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

class HydroCommand final : public Command {
 public:
  std::string name() const override { return "hydro"; }
  std::string summary() const override {
    return "Hydrology of a DEM: filled DEM, D8 directions, flow accumulation, hydrometry, streams";
  }

  void setup(CLI::App& app) override {
    dem_.add_to(app);
    file_kind(app.add_option("OUTDIR", out_dir_, "Output folder (its parent must exist)")->required(), FileKind::folder_out);
    schema_.setup(app, name());
    app.add_option("--area-units", units_, "Unit of accumulation.tif: m2, km2 or cells")
        ->check(CLI::IsMember({"m2", "km2", "cells"}))->capture_default_str();
    file_kind(app.add_option("--weights", weights_, "Raster of per-cell weights (resampled bilinearly onto the DEM)"), FileKind::raster_in);
    app.add_option("--outputs", outputs_, "Outputs to write, comma-separated: filled,flowdir,accumulation,hydrometry,streams,basins")
        ->capture_default_str();
    app.add_flag("--cog", cog_, "Write Cloud Optimized GeoTIFFs");
    add_overwrite_flag(app, overwrite_);
  }

  void run(Context& context) override {
    const pipeline::Scenario scenario = schema_.scenario();
    const nlohmann::ordered_json& h = scenario.resolved["hydro"];
    HydroOptions o = pipeline::hydro_options(scenario);
    if (!schema_.given("/water/sea_level_m")) o.sea_level.reset();  // this command has no sea unless told
    const D8Codes codes = pipeline::d8_codes(scenario);
    const std::optional<RiverTypeOptions> types = pipeline::river_type_options(scenario);
    const bool classify = types.has_value();
    const std::string fill = h["fill"], flow = h["flow"], hydrometry = h["hydrometry"];
    o.unit = units_ == "cells" ? AccumulationUnit::cells : AccumulationUnit::area_m2;

    const std::array<bool, 6> wanted = wanted_outputs();
    o.with_hydrometry = wanted[3];
    o.with_streams = wanted[4];
    if (classify && !wanted[4]) throw bad_input("--classify: needs the streams output (--outputs ... ,streams)");
    OutputSet outputs("hydro", {dem_.path, weights_}, overwrite_);  // refused before any work
    const fs::path dir = outputs.folder(out_dir_);

    std::vector<std::pair<std::string, std::string>> provenance = {
        {"TERRAPOLIS_VERSION", version}, {"TERRAPOLIS_COMMAND", "hydro"}, {"SOURCE_DEM", fs::path(dem_.path).filename().string()},
        {"FILL", fill}, {"FLOW", flow}, {"MFD_EXPONENT", number(o.mfd_exponent)}, {"HYDROMETRY", hydrometry},
        {"ITERATIONS", std::to_string(o.hydrometry.max_iterations)}, {"THRESHOLD", number(o.hydrometry.threshold)},
        {"VERTICAL", h["vertical"].get<std::string>()}, {"BELHADJ_SHARE", h["belhadj_share"].get<std::string>()},
        {"SEA_LEVEL", o.sea_level ? number(*o.sea_level) : "off"}};
    auto opts = [&](const std::string& description, std::vector<std::pair<std::string, std::string>> extra = {}) {
      WriteOptions w;
      w.cog = cog_;
      w.description = description;
      w.deflate_level = 1;  // 13 M-cell float rasters: a third of the compression time, files ~4 % larger
      w.metadata = provenance;
      w.metadata.insert(w.metadata.end(), extra.begin(), extra.end());
      return w;
    };
    const ReadOptions read = dem_.options();
    pipeline::DescriptionTerms terms = pipeline::description_terms(scenario);
    terms.accumulation_unit = units_;
    terms.weighted = !weights_.empty();
    const std::string flowdir_description = pipeline::describe_output("flowdir.tif", terms);
    const std::vector<std::pair<std::string, std::string>> flowdir_metadata = {{"D8_CODES", h["d8_codes"].get<std::string>()}, {"D8_CODES_DESCRIPTION", describe(codes)}};
    const std::string basins_description = pipeline::describe_output("basins.tif", terms);
    const std::string acc_unit = units_ == "cells" ? "cells" : units_;
    const std::string acc_description = pipeline::describe_output("accumulation.tif", terms);
    const pipeline::TileSettings tiles = schema_.settings([&] { return pipeline::tile_settings(scenario); });
    if (tiles.tiled(dem_.path)) {
      // The tile engine: fill, D8 and accumulation, tile by tile (docs/scale.md).
      check_tiled(o, wanted, classify);
      TiledHydroRequest q;
      q.dem_path = dem_.path;
      q.out_dir = dir.string();
      q.out_name = out_dir_;
      q.read = read;
      q.tile_size = tiles.tile_size;
      q.memory_limit_mb = tiles.limit_mb();
      q.sea_level = o.sea_level;
      q.unit = o.unit;
      q.accumulation_scale = units_ == "km2" ? 1e-6 : 1.0;
      q.codes = codes;
      q.filled = wanted[0];
      q.flowdir = wanted[1];
      q.accumulation = wanted[2];
      q.basins = wanted[5];
      q.streams = wanted[4] && o.unit != AccumulationUnit::cells;
      q.streams_threshold_km2 = o.streams.threshold_km2;
      q.river_types = types;
      q.filled_file = opts(pipeline::describe_output("filled.tif", terms));
      q.flowdir_file = opts(flowdir_description, flowdir_metadata);
      q.accumulation_file = opts(acc_description, {{"UNIT", acc_unit}});
      q.basins_file = opts(basins_description);
      const std::string done = run_tiled_hydro_command(q, context);
      if (wanted[3]) tiled_hydrometry(context, o, tiles, dir, opts(pipeline::describe_output("hydrometry.tif", terms)));
      outputs.commit();
      context.log.info(done);
      return;
    }
    const Dem dem = dem_.read();
    if (!weights_.empty()) o.weights = read_resampled(weights_, dem.georef(), dem.cols(), dem.rows(), Resampling::bilinear);

    HydroResult result = run_hydro(dem, o, context.progress);
    if (classify) classify_streams(result.streams, result.filled, o.sea_level, *types);
    if (result.hydrometry_iterations > 0) {
      char line[160];
      std::snprintf(line, sizeof line, "belhadj: %d iterations in %.2f ms, %.1f M cell-iterations/s", result.hydrometry_iterations,
                    result.hydrometry_seconds * 1e3,
                    double(dem.size()) * result.hydrometry_iterations / result.hydrometry_seconds / 1e6);
      context.log.detail(line);
    }

    Raster<float> acc;
    if (wanted[2]) {
      acc = result.filled.like<float>(NAN);
      const double scale = units_ == "km2" ? 1e-6 : 1.0;
      for (std::size_t i = 0; i < acc.size(); ++i) acc[i] = float(result.accumulation[i] * scale);
      result.accumulation = Raster<double>();  // release before writing
    }
    auto path = [&](int i) { return (dir / kNames[std::size_t(i)]).string(); };
    std::vector<std::function<void()>> writes;
    if (wanted[0])
      writes.push_back([&, p = path(0)] {
        write_raster(p, result.filled, opts(pipeline::describe_output("filled.tif", terms)));
      });
    if (wanted[1])
      writes.push_back([&, p = path(1)] { write_raster(p, encode_d8(result.d8, codes), opts(flowdir_description, flowdir_metadata)); });
    if (wanted[2]) writes.push_back([&, p = path(2)] { write_raster(p, acc, opts(acc_description, {{"UNIT", acc_unit}})); });
    if (wanted[3])
      writes.push_back([&, p = path(3)] { write_raster(p, result.hydrometry, opts(pipeline::describe_output("hydrometry.tif", terms))); });
    if (wanted[4]) writes.push_back([&, p = path(4)] { write_vector(p, result.streams); });
    if (wanted[5]) writes.push_back([&, p = path(5)] { write_raster(p, drainage_basins(result.d8), opts(basins_description)); });
    if (classify) writes.push_back([&] { write_text_file((dir / "streams.qml").string(), river_types_qml(), false); });
    write_concurrently(writes);
    outputs.commit();
    context.log.info("hydro: wrote " + out_dir_ + (wanted[4] ? " (" + std::to_string(result.streams.features.size()) + " stream reaches)" : ""));
  }

 private:
  static constexpr std::array<const char*, 6> kNames = {"filled.tif", "flowdir.tif", "accumulation.tif", "hydrometry.tif", "streams.geojson",
                                                        "basins.tif"};

  /// The outputs --outputs names, in the order of kNames.
  std::array<bool, 6> wanted_outputs() const {
    std::array<bool, 6> wanted{};
    for (std::size_t start = 0; start <= outputs_.size();) {
      const std::size_t comma = std::min(outputs_.find(',', start), outputs_.size());
      const std::string item = outputs_.substr(start, comma - start);
      bool known = false;
      for (std::size_t i = 0; i < kNames.size(); ++i)
        if (item + (i == 4 ? ".geojson" : ".tif") == kNames[i]) wanted[i] = known = true;
      if (!known) throw bad_input("--outputs: unknown output '" + item + "'");
      start = comma + 1;
    }
    return wanted;
  }

  /// Belhadj's hydrometry by tiles into DIR/hydrometry.vrt, after the engine (it has the memory to itself).
  void tiled_hydrometry(Context& context, const HydroOptions& o, const pipeline::TileSettings& tiles, const fs::path& dir,
                        const WriteOptions& file) const {
    if (o.hydrometry.method != HydrometryMethod::belhadj)
      return context.log.detail("hydrometry.tif left out: the accumulation hydrometry is not computed on tiles yet (Belhadj's is)");
    const double reserved_mb = reserve_reader_memory(tiles.limit_mb());
    const DemWindowReader reader(dem_.path, dem_.options());
    const MosaicFiles m{dir.string(), "hydrometry"};
    m.create();
    const ScratchFolder scratch((dir / ".scratch-hydrometry").string());
    const hydro::tiled::TiledBelhadjReport b = pipeline::hydrometry_by_tiles(
        reader, o, tiles, reserved_mb, scratch.path(),
        [&](int t, int across, const Raster<float>& tile) { write_raster(m.tile(t, across), tile, file); }, context.progress);
    m.finish(b.tiles, b.across);
    context.log.detail(pipeline::describe(b));
  }

  /// What the tile engine does not compute (yet), refused by name.
  void check_tiled(const HydroOptions& o, const std::array<bool, 6>& wanted, bool classify) const {
    if (o.fill != FillMethod::priority_flood || o.flow != FlowMethod::d8 || !weights_.empty())
      throw bad_input("tiled hydro (--tile-size, --memory-limit, a folder of tiles): only --fill priority-flood, --flow d8, no --weights");
    // The default outputs on tiles: the hydrometry when it is Belhadj's, and the streams when the accumulation is an area.
    const bool explicit_outputs = outputs_ != kDefaultOutputs;
    if (explicit_outputs && wanted[3] && o.hydrometry.method != HydrometryMethod::belhadj)
      throw bad_input("--outputs: the accumulation hydrometry is not computed on tiles yet (Belhadj's is)");
    if (explicit_outputs && wanted[4] && o.unit == AccumulationUnit::cells)
      throw bad_input("--outputs: streams on tiles need --area-units m2 or km2");
    if (classify && !wanted[0]) throw bad_input("--classify: on tiles the river types read the filled tiles (--outputs ... ,filled)");
  }

  DemInput dem_;
  std::string out_dir_;
  static constexpr const char* kDefaultOutputs = "filled,flowdir,accumulation,hydrometry,streams";
  std::string outputs_ = kDefaultOutputs;
  std::string units_ = "m2", weights_;
  bool cog_ = false, overwrite_ = false;
  SchemaOptions schema_;
};

}  // namespace

std::unique_ptr<Command> make_hydro_command() { return std::make_unique<HydroCommand>(); }

}  // namespace terrapolis::cli
