// `terrapolis skeleton DEM OUTDIR`: ridge and valley lines and the sparse raster of their cells (Belhadj 2007, §5.2.2).
// SPDX-License-Identifier: MIT
#include <CLI/CLI.hpp>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "cli/command.hpp"
#include "cli/commands_list.hpp"
#include "cli/dem_input.hpp"
#include "cli/schema_options.hpp"
#include "core/error.hpp"
#include "io/output_set.hpp"
#include "io/raster_io.hpp"
#include "io/text_io.hpp"
#include "io/vector_io.hpp"
#include "pipeline/stage_options.hpp"
#include "skeleton/ridges_valleys.hpp"
#include "terrapolis/version.hpp"

namespace terrapolis::cli {
namespace {

namespace fs = std::filesystem;

class SkeletonCommand final : public Command {
 public:
  std::string name() const override { return "skeleton"; }
  std::string summary() const override { return "Ridge and valley lines (form index, path following) and the sparse raster of their cells"; }

  void setup(CLI::App& app) override {
    dem_.add_to(app);
    file_kind(app.add_option("OUTDIR", out_dir_, "Output folder: ridges.geojson, valleys.geojson (+ QGIS .qml styles), skeleton.tif (the kept cells), form_index.tif, skeleton.json (its parent must exist)")
                  ->required(),
              FileKind::folder_out);
    schema_.setup(app, name());
    app.add_flag("--cog", cog_, "Write Cloud Optimized GeoTIFFs");
    add_overwrite_flag(app, overwrite_);
  }

  void run(Context& context) override {
    const pipeline::Scenario scenario = schema_.scenario();
    const skeleton::SkeletonOptions options = schema_.settings([&] { return pipeline::skeleton_options(scenario); });
    OutputSet outputs("skeleton", {dem_.path}, overwrite_);  // refused before any work
    const fs::path dir = outputs.folder(out_dir_);
    const Dem dem = dem_.read();
    const auto start = std::chrono::steady_clock::now();
    const CellMetrics metrics = cell_metrics(dem.georef(), dem.cols(), dem.rows());
    const skeleton::Skeleton s = skeleton::extract_skeleton(dem, metrics, options, context.progress);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (s.valid_cells == 0) throw bad_input(dem_.path + ": holds no valid cell");

    const std::string source = fs::path(dem_.path).filename().string();
    const double share = double(s.kept_cells) / double(s.valid_cells);
    auto write = [&](const std::string& file, const Raster<float>& raster, const std::string& description, const std::string& unit) {
      WriteOptions w;
      w.cog = cog_;
      w.description = description;
      w.metadata = {{"TERRAPOLIS_VERSION", version}, {"TERRAPOLIS_COMMAND", "skeleton"}, {"SOURCE_DEM", source},
                    {"TERRAPOLIS_SKELETON", scenario.resolved["skeleton"].dump()}, {"UNIT", unit}};
      write_raster((dir / file).string(), raster, w);
    };
    write("skeleton.tif", s.kept, "Elevation (m) on the ridge and valley cells, nodata elsewhere", "m");
    write("form_index.tif", s.index, "Form index (Belhadj 2007 §5.2.2): > 0 ridges, < 0 valleys", "1");
    for (const auto kind : {skeleton::Kind::ridge, skeleton::Kind::valley}) {
      const std::string layer = kind == skeleton::Kind::ridge ? "ridges" : "valleys";
      write_vector((dir / (layer + ".geojson")).string(), skeleton::lines_layer(s, kind));
      write_text_file((dir / (layer + ".qml")).string(), skeleton::lines_qml(kind), false);
    }
    double ridge_km = 0, valley_km = 0;
    for (const auto& line : s.lines) (line.kind == skeleton::Kind::ridge ? ridge_km : valley_km) += line.length_m / 1000;
    const nlohmann::ordered_json report = {
        {"terrapolis_version", version}, {"dem", source}, {"options", scenario.resolved["skeleton"]},
        {"valid_cells", s.valid_cells}, {"kept_cells", s.kept_cells}, {"kept_share", share},
        {"line_cells", s.line_cells}, {"lattice_cells", s.lattice_cells},
        {"ridges", s.ridges}, {"valleys", s.valleys}, {"ridge_km", ridge_km}, {"valley_km", valley_km}, {"seconds", seconds}};
    write_text_file((dir / "skeleton.json").string(), report.dump(2) + "\n", false);
    outputs.commit();
    char line[320];
    std::snprintf(line, sizeof line,
                  "skeleton: %zu ridges (%.1f km), %zu valleys (%.1f km), %.1f %% of the cells kept (%.1f %% on the lines, %.1f %% on the lattice), %.2f s; wrote ",
                  s.ridges, ridge_km, s.valleys, valley_km, 100 * share, 100.0 * double(s.line_cells) / double(s.valid_cells),
                  100.0 * double(s.lattice_cells) / double(s.valid_cells), seconds);
    context.log.info(line + out_dir_);
  }

 private:
  DemInput dem_;
  SchemaOptions schema_;
  std::string out_dir_;
  bool cog_ = false, overwrite_ = false;
};

}  // namespace

std::unique_ptr<Command> make_skeleton_command() { return std::make_unique<SkeletonCommand>(); }

}  // namespace terrapolis::cli
