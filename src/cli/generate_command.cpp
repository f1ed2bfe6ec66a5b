// `terrapolis generate OUT.tif --size WxH --cell M [--method M]`: synthetic terrain. dmmc: fractal terrain
// constrained by a sketch; the other methods build a skeleton (rivers, ridges) first, each in its own
// source file (generate/generate_*.cpp), and write it beside the DEM with the checks of its rivers.
// SPDX-License-Identifier: MIT
#include <CLI/CLI.hpp>

#include <chrono>
#include <cmath>

#include "cli/command.hpp"
#include "cli/commands_list.hpp"
#include "cli/generate_methods.hpp"
#include "cli/generate_report.hpp"
#include "cli/terrain_options.hpp"
#include "cli/schema_options.hpp"
#include "core/error.hpp"
#include "core/geodesy.hpp"
#include "erode/erosion.hpp"
#include "io/output_set.hpp"
#include "io/raster_io.hpp"
#include "io/text_io.hpp"
#include "io/vector_io.hpp"
#include "generate/generators.hpp"
#include "pipeline/stage_options.hpp"
#include "terrain/subdivision.hpp"

namespace terrapolis::cli {
namespace {

generate::GeneratedTerrain generate_dmmc(const generate::GenerateRequest& request) {
  generate::GeneratedTerrain out;
  out.dem = request.grid;
  const auto t0 = std::chrono::steady_clock::now();
  terrain::dmmc(out.dem, request.dmmc, request.progress, request.labels);
  out.timings.emplace_back("dmmc", std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  return out;
}

/// The generators, by --method name.
struct Method {
  const char* name;
  generate::GeneratedTerrain (*generate)(const generate::GenerateRequest&);
};
constexpr Method kMethods[] = {
    {"dmmc", generate_dmmc},
    {"flow", generate::generate_flow},
    {"tectonic", generate::generate_tectonic},
    {"coast", generate::generate_coast},
    {"planar", generate::generate_planar},
    {"window", generate::generate_window},
    {"river", generate::generate_river},
};

std::string method_names() {
  std::string names;
  for (const auto& m : kMethods) names += (names.empty() ? "" : " | ") + std::string(m.name);
  return names;
}

/// `path` without its extension, for the files written beside it.
std::string stem_of(const std::string& path) {
  const auto dot = path.find_last_of('.'), slash = path.find_last_of('/');
  return dot != std::string::npos && (slash == std::string::npos || dot > slash) ? path.substr(0, dot) : path;
}

/// A vector file's coordinates in the cell coordinates of `grid` (centre of cell (c,r) at (c,r)).
generate::GridPoint to_cell(const Georef& g, const std::array<double, 2>& p) {
  const auto& t = g.transform;
  return {(p[0] - t[0]) / t[1] - 0.5, (p[1] - t[3]) / t[5] - 0.5};
}

class GenerateCommand final : public Command {
 public:
  std::string name() const override { return "generate"; }
  std::string summary() const override {
    return "Generate a synthetic region: fractal terrain (DMMC, optionally from a sketch) or a terrain built from rivers and ridges";
  }

  void setup(CLI::App& app) override {
    app_ = &app;
    file_kind(app.add_option("OUT", output_, "Output GeoTIFF (float32 heights in metres)")->required(), FileKind::raster_out);
    grid_.add(app, true, "dmmc, window: an unreferenced grid with its corner at 0,0; the other methods: ETRS89-LAEA Europe, "
                         "EPSG:3035, the grid centred on 52N 10E");
    app.add_option("--method", method_, "Generator: " + method_names() + " (see docs/terrain.md; river defaults to the thesis's "
                                         "--hurst 0.4565 and --roughness equal to --relief)")->capture_default_str();
    app.add_option("--relief", relief_m_, "flow, tectonic, river: height (m) of the highest crest above the outlets (river: the north-west corner)")
        ->capture_default_str()->check(CLI::PositiveNumber);
    file_kind(app.add_option("--ridges", lines_path_, "flow: ridge lines (any OGR vector file of lines; default: random ridges from --seed)"), FileKind::vector_in);
    file_kind(app.add_option("--mountains", points_path_, "tectonic: mountain points, one plate each (any OGR vector file of points; default: random)"), FileKind::vector_in);
    file_kind(app.add_option("--constraints", sketch_, "dmmc, window: sketch raster: cells with a value are fixed heights (m), nodata cells are generated. "
                                             "Warped onto the grid if it has a CRS, else it must have the grid's size"), FileKind::raster_in);
    file_kind(app.add_option("--labels", labels_path_, "dmmc: which way each sketch cell extrapolates in the bottom-up pass (Belhadj §5.1.1): "
                                                     "1 river (up, I_-1 = -|shape-up|), 2 ridge (down, +|shape-up|), 0 or nodata --shape-up as given. "
                                                     "Same grid rules as --constraints"), FileKind::raster_in);
    options_.add(app, false, 1000.0);
    skeleton_options_.add(app);
    erode_schema_.setup(app, name());  // --erode-iterations, --erode-process (the erode section)
    add_overwrite_flag(app, overwrite_);
  }

  void run(Context& context) override {
    const Method* method = nullptr;
    for (const auto& m : kMethods)
      if (method_ == m.name) method = &m;
    if (!method) throw bad_input("--method: unknown generator '" + method_ + "' (expected " + method_names() + ")");
    const pipeline::Scenario erode_scenario = erode_schema_.scenario();
    const erode::ErodeOptions erode_options = erode_schema_.settings([&] { return pipeline::erode_options(erode_scenario); });
    // dmmc and window fill a sketch; the others build a skeleton and write it with its report.
    const bool skeleton_method = method_ != "dmmc" && method_ != "window";
    if (skeleton_method && !sketch_.empty()) throw bad_input("--constraints: only --method dmmc and window take a sketch");
    if (method_ == "window") check_window_options();
    if (!lines_path_.empty() && method_ != "flow") throw bad_input("--ridges: only --method flow takes ridge lines");
    if (!points_path_.empty() && method_ != "tectonic") throw bad_input("--mountains: only --method tectonic takes mountain points");
    if (skeleton_method && grid_.crs.empty()) default_local_grid();
    // Between a skeleton's cells the noise must stay below the relief it carves, or it makes pits.
    if (skeleton_method && app_->get_option("--roughness")->count() == 0) options_.roughness_m = 0.05 * relief_m_;
    if (method_ == "river") {  // Belhadj §1.2.3.2: H = 0.4565 and s = 1, S = dim(T.a) s the whole altitude range
      if (app_->get_option("--hurst")->count() == 0) options_.hurst = 0.4565;
      if (app_->get_option("--roughness")->count() == 0) options_.roughness_m = relief_m_;
    }
    terrain::FillParams params = options_.params();
    Raster<float> grid = grid_.make();
    check_labels_options();
    OutputSet outputs("generate", {sketch_, labels_path_, lines_path_, points_path_, skeleton_options_.coast_path}, overwrite_);
    const std::string out = outputs.file(output_);
    const std::string skeleton_out = skeleton_method ? outputs.file(stem_of(output_) + ".skeleton.geojson") : "";
    const std::string report_out = skeleton_method ? outputs.file(stem_of(output_) + ".report.json") : "";
    std::vector<terrain::ExtrapolationLabel> labels;
    if (!labels_path_.empty()) labels = read_labels(grid);
    if (!sketch_.empty()) {
      grid.values() = read_on_grid(sketch_, grid).values();
      std::size_t fixed = 0;
      for (std::size_t i = 0; i < grid.size(); ++i) fixed += std::isfinite(grid[i]) ? 1 : 0;
      context.log.info("generate: " + std::to_string(fixed) + " cells fixed by the sketch");
      if (fixed == 0 && method_ == "window") throw bad_input(sketch_ + ": has no cell with a value (--method window grows from them)");
    }
    params.dmmc.low_pass = false;  // generation wants the fractal detail, not the smoothest surface
    generate::GenerateRequest request;
    request.cell_m = grid_.cell_m;
    request.seed = options_.seed;
    request.relief_m = relief_m_;
    request.dmmc = params.dmmc;
    request.labels = std::move(labels);
    request.progress = &context.progress;
    if (!lines_path_.empty()) request.lines = read_lines(lines_path_, grid.georef());
    if (!points_path_.empty()) request.points = read_points(points_path_, grid.georef());
    if (!skeleton_options_.coast_path.empty()) request.polygons = read_rings(skeleton_options_.coast_path, grid.georef());
    skeleton_options_.apply(request);
    request.grid = std::move(grid);
    generate::GeneratedTerrain terrain = method->generate(request);
    for (const auto& [phase, seconds] : terrain.timings)
      context.log.detail("generate: " + phase + " in " + std::to_string(seconds) + " s");
    if (erode_options.iterations > 0) {  // an older landscape; the report then measures the eroded DEM's rivers
      erode::ErodeReport report;
      const CellMetrics metrics = cell_metrics(terrain.dem.georef(), terrain.dem.cols(), terrain.dem.rows());
      terrain.dem = erode::erode(terrain.dem, metrics, erode_options, nullptr, context.progress, &report);
      context.log.info("generate: eroded " + std::to_string(report.iterations) + " iterations, " + std::to_string(std::llround(report.eroded_m3)) +
                       " m3 moved, largest lowering " + std::to_string(report.max_lowering_m) + " m");
    }

    WriteOptions write;
    write.description = "generated elevation (m)";
    write.metadata = options_.metadata(false);
    write.metadata.emplace_back("TERRAPOLIS_GENERATOR", method_);
    if (!request.labels.empty()) write.metadata.emplace_back("TERRAPOLIS_LABELS", labels_summary(request.labels));
    if (skeleton_method) write.metadata.emplace_back("TERRAPOLIS_RELIEF_M", std::to_string(relief_m_));
    if (erode_options.iterations > 0) write.metadata.emplace_back("TERRAPOLIS_ERODE", erode_scenario.resolved["erode"].dump());
    if (method_ == "river") {
      write.metadata.emplace_back("TERRAPOLIS_RIVER_CONVERGENCE", std::to_string(request.river.convergence));
      write.metadata.emplace_back("TERRAPOLIS_RIVER_POWER", std::to_string(request.river.power));
      write.metadata.emplace_back("TERRAPOLIS_RIVER_DROP_M", std::to_string(request.river.bed_drop_m));
    }
    write_raster(out, terrain.dem, write);
    if (skeleton_method) {
      write_vector(skeleton_out, generate::river_ridge_layer(terrain.plan, terrain.dem.georef(), grid_.cell_m));
      write_text_file(report_out, skeleton_report(terrain, grid_.cell_m, method_, context.log, context.progress), false);
    }
    outputs.commit();
  }

 private:
  /// Alg. 1 is plain midpoint displacement from a sketch: no shaping, no bottom-up pass.
  void check_window_options() const {
    if (sketch_.empty()) throw bad_input("--method window: needs --constraints SKETCH.tif (the growing window grows from its cells)");
    for (const char* name : {"--shape", "--shape-up", "--bottom-up"})
      if (app_->get_option(name)->count() > 0) throw bad_input(std::string(name) + ": not used by --method window (Belhadj Alg. 1 has no shaping or bottom-up pass)");
  }
  /// §5.1.1's labels shape the weighted extrapolation of a sketch by |I_-1|: they need all three.
  void check_labels_options() const {
    if (labels_path_.empty()) return;
    if (method_ != "dmmc") throw bad_input("--labels: only --method dmmc takes labels (its bottom-up pass uses them)");
    if (sketch_.empty()) throw bad_input("--labels: needs --constraints SKETCH.tif (the labels are of its cells)");
    if (options_.bottom_up != "weighted") throw bad_input("--labels: needs --bottom-up weighted (Belhadj Alg. 10 has no extrapolation shaping)");
    if (options_.shape_up == 0.0) throw bad_input("--labels: needs --shape-up I (labelled cells extrapolate with |I|, up or down)");
  }
  /// The labels raster on the grid: 0 or nodata global, 1 river, 2 ridge; any other value is refused.
  std::vector<terrain::ExtrapolationLabel> read_labels(const Raster<float>& grid) const {
    const Raster<float> values = read_on_grid(labels_path_, grid);
    std::vector<terrain::ExtrapolationLabel> labels(values.size(), terrain::ExtrapolationLabel::global);
    for (std::size_t i = 0; i < values.size(); ++i) {
      const float v = values[i];
      if (!std::isfinite(v) || v == 0.0f) continue;
      if (v != 1.0f && v != 2.0f)
        throw bad_input(labels_path_ + ": cell " + std::to_string(i % std::size_t(values.cols())) + "," + std::to_string(i / std::size_t(values.cols())) +
                        " holds " + std::to_string(v) + "; expected 0, 1 (river) or 2 (ridge)");
      labels[i] = v == 1.0f ? terrain::ExtrapolationLabel::river : terrain::ExtrapolationLabel::ridge;
    }
    return labels;
  }
  static std::string labels_summary(const std::vector<terrain::ExtrapolationLabel>& labels) {
    std::size_t river = 0, ridge = 0;
    for (const auto l : labels) {
      river += l == terrain::ExtrapolationLabel::river ? 1 : 0;
      ridge += l == terrain::ExtrapolationLabel::ridge ? 1 : 0;
    }
    return std::to_string(river) + " river cells, " + std::to_string(ridge) + " ridge cells";
  }
  /// A raster given for the grid: warped (nearest) if both have a CRS, else read as is, and then
  /// it must have the grid's size.
  Raster<float> read_on_grid(const std::string& path, const Raster<float>& grid) const {
    const RasterHeader header = read_header(path, ReadOptions{std::nullopt, std::string("EPSG:4326")});
    if (!grid.georef().crs.empty() && !has_no_crs(path)) return read_resampled(path, grid.georef(), grid.cols(), grid.rows(), Resampling::nearest);
    if (header.cols != grid.cols() || header.rows != grid.rows())
      throw bad_input(path + ": is " + std::to_string(header.cols) + "x" + std::to_string(header.rows) +
                      " cells but the grid is " + grid_.size + " and one of them has no CRS to warp it");
    return read_pixels(path);
  }
  static bool has_no_crs(const std::string& path) {
    try {
      (void)read_header(path);
      return false;
    } catch (const Error&) {
      return true;  // read_header refuses a file without a CRS; the assumed-CRS read above proved it is readable
    }
  }
  static Raster<float> read_pixels(const std::string& path) {
    ReadOptions read;
    read.assume_crs = "EPSG:4326";  // only the pixel values are used
    try {
      return read_dem(path, read);
    } catch (const Error& e) {
      // A sketch may hold nothing but nodata; everything is then generated.
      const RasterHeader header = read_header(path, read);
      Raster<float> empty(header.cols, header.rows, header.georef, std::numeric_limits<float>::quiet_NaN());
      if (std::string(e.what()).find("no data") != std::string::npos) return empty;
      throw;
    }
  }

  /// Without --crs: ETRS89-LAEA Europe (EPSG:3035), the grid centred on the projection's centre
  /// (52N 10E), so a generated region has real metres and opens in QGIS; --crs/--origin override it.
  void default_local_grid() {
    grid_.crs = "EPSG:3035";
    if (!grid_.origin.empty()) return;
    grid_.default_crs = true;
    const auto x = grid_.size.find_first_of("xX");
    if (x == std::string::npos) return;  // make() reports the bad size
    double cols = 0, rows = 0;
    try {
      cols = std::stod(grid_.size.substr(0, x));
      rows = std::stod(grid_.size.substr(x + 1));
    } catch (const std::exception&) {
      return;
    }
    grid_.origin = std::to_string(4321000.0 - cols * grid_.cell_m / 2) + "," + std::to_string(3210000.0 + rows * grid_.cell_m / 2);
  }
  static std::vector<std::vector<generate::GridPoint>> read_lines(const std::string& path, const Georef& georef) {
    const VectorLayer layer = read_vector(path, georef.crs);
    std::vector<std::vector<generate::GridPoint>> lines;
    for (const auto& f : layer.features) {
      if (layer.geometry != GeometryType::line_string || f.parts.empty() || f.parts[0].size() < 2)
        throw bad_input(path + ": expected lines of at least 2 points");
      std::vector<generate::GridPoint> line;
      for (const auto& p : f.parts[0]) line.push_back(to_cell(georef, p));
      lines.push_back(std::move(line));
    }
    if (lines.empty()) throw bad_input(path + ": holds no line");
    return lines;
  }
  static std::vector<std::vector<generate::GridPoint>> read_rings(const std::string& path, const Georef& georef) {
    const VectorLayer layer = read_vector(path, georef.crs);
    if (layer.geometry != GeometryType::polygon) throw bad_input(path + ": expected polygons (the land)");
    std::vector<std::vector<generate::GridPoint>> rings;
    for (const auto& f : layer.features)
      for (const auto& part : f.parts) {
        std::vector<generate::GridPoint> ring;
        for (const auto& p : part) ring.push_back(to_cell(georef, p));
        if (ring.size() > 1 && ring.front() == ring.back()) ring.pop_back();
        if (ring.size() >= 3) rings.push_back(std::move(ring));
      }
    if (rings.empty()) throw bad_input(path + ": holds no polygon");
    return rings;
  }
  static std::vector<generate::GridPoint> read_points(const std::string& path, const Georef& georef) {
    const VectorLayer layer = read_vector(path, georef.crs);
    std::vector<generate::GridPoint> points;
    for (const auto& f : layer.features) {
      if (layer.geometry != GeometryType::point || f.parts.empty() || f.parts[0].empty()) throw bad_input(path + ": expected points");
      points.push_back(to_cell(georef, f.parts[0][0]));
    }
    if (points.size() < 2) throw bad_input(path + ": needs at least 2 points (one plate each)");
    return points;
  }

  std::string output_, sketch_, labels_path_, lines_path_, points_path_, method_ = "dmmc";
  double relief_m_ = 1500;
  CLI::App* app_ = nullptr;
  GridOptions grid_;
  TerrainOptions options_;
  CoastPlanarOptions skeleton_options_;
  bool overwrite_ = false;
  SchemaOptions erode_schema_;
};

}  // namespace

std::unique_ptr<Command> make_generate_command() { return std::make_unique<GenerateCommand>(); }

}  // namespace terrapolis::cli
