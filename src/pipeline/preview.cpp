// A software renderer for preview.png (OpenImageIO writes the file and draws the legend's text).
// SPDX-License-Identifier: MIT
#include "pipeline/preview.hpp"

#include <dlfcn.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <limits>
#include <memory>
#include <vector>

#include "core/error.hpp"
#include "core/geodesy.hpp"
#include "io/crs.hpp"
#include "pipeline/hillshade.hpp"
#include "pipeline/png/png_writer.h"
#include "roads/road_class.hpp"

namespace terrapolis::pipeline {
namespace {

using Rgb = std::array<float, 3>;

Rgb hex(unsigned v) { return {((v >> 16) & 255) / 255.0f, ((v >> 8) & 255) / 255.0f, (v & 255) / 255.0f}; }

class Canvas {
 public:
  Canvas(int w, int h) : w_(w), h_(h), px_(std::size_t(w) * h * 3, 1.0f) {}
  int width() const { return w_; }
  int height() const { return h_; }
  void blend(int x, int y, const Rgb& c, float alpha) {
    if (x < 0 || y < 0 || x >= w_ || y >= h_) return;
    float* p = &px_[(std::size_t(y) * w_ + x) * 3];
    for (int i = 0; i < 3; ++i) p[i] = p[i] * (1 - alpha) + c[i] * alpha;
  }
  void disc(double cx, double cy, double r, const Rgb& c, float alpha = 1.0f) {
    for (int y = int(std::floor(cy - r)); y <= int(std::ceil(cy + r)); ++y)
      for (int x = int(std::floor(cx - r)); x <= int(std::ceil(cx + r)); ++x)
        if ((x + 0.5 - cx) * (x + 0.5 - cx) + (y + 0.5 - cy) * (y + 0.5 - cy) <= r * r) blend(x, y, c, alpha);
  }
  void segment(double x0, double y0, double x1, double y1, double width, const Rgb& c, bool dashed = false) {
    const double len = std::hypot(x1 - x0, y1 - y0);
    const int steps = std::max(1, int(len * 2));
    for (int i = 0; i <= steps; ++i) {
      if (dashed && (i / 8) % 2) continue;
      const double t = double(i) / steps;
      disc(x0 + t * (x1 - x0), y0 + t * (y1 - y0), width / 2, c);
    }
  }
  void rect(int x0, int y0, int x1, int y1, const Rgb& c, float alpha = 1.0f) {
    for (int y = y0; y < y1; ++y)
      for (int x = x0; x < x1; ++x) blend(x, y, c, alpha);
  }
  const float* data() const { return px_.data(); }

 private:
  int w_, h_;
  std::vector<float> px_;
};

Rgb density_color(float v) {
  static const Rgb ramp[5] = {hex(0xffffb2), hex(0xfecc5c), hex(0xfd8d3c), hex(0xf03b20), hex(0xbd0026)};
  const float t = std::clamp(v, 0.0f, 1.0f) * 4;
  const int i = std::min(3, int(t));
  const float f = t - i;
  return {ramp[i][0] * (1 - f) + ramp[i + 1][0] * f, ramp[i][1] * (1 - f) + ramp[i + 1][1] * f, ramp[i][2] * (1 - f) + ramp[i + 1][2] * f};
}

struct LegendEntry {
  Rgb color;
  std::string label;
  bool line;
};

/// The rows of the terrain the preview samples: the DEM, its hillshade and the density (when the run
/// made one), from memory, or for a run by tiles read a row at a time from its VRTs (the same cells).
class TerrainRows {
 public:
  explicit TerrainRows(const RunState& state) : state_(state), cols_(state.grid.cols) {
    if (!state.by_tiles) {
      shade_ = hillshade(state.dem);
      return;
    }
    const auto reader = [&](const char* name) { return std::make_unique<DemWindowReader>((state.folder / name).string()); };
    elevation_ = reader("elevation.vrt");
    shaded_ = reader("hillshade.vrt");
    if (std::filesystem::exists(state.folder / "density.vrt")) density_ = reader("density.vrt");
  }
  bool has_density() const { return state_.by_tiles ? bool(density_) : bool(state_.density); }
  /// Row r of the three (density NaN without one).
  void read(int r, std::vector<float>& z, std::vector<float>& shade, std::vector<float>& density) const {
    z.resize(std::size_t(cols_));
    shade.resize(std::size_t(cols_));
    density.assign(std::size_t(cols_), std::numeric_limits<float>::quiet_NaN());
    if (!state_.by_tiles) {
      for (int c = 0; c < cols_; ++c) {
        z[std::size_t(c)] = state_.dem(c, r);
        shade[std::size_t(c)] = float(shade_(c, r));
        if (state_.density) density[std::size_t(c)] = (*state_.density)(c, r);
      }
      return;
    }
    const auto row = [&](const DemWindowReader& reader, std::vector<float>& out) {
      const Dem values = reader.read(0, r, cols_, 1);
      std::copy_n(values.data(), cols_, out.data());
    };
    row(*elevation_, z);
    row(*shaded_, shade);
    for (float& s : shade)
      if (std::isnan(s)) s = 0;  // the hillshade's nodata value is 0
    if (density_) row(*density_, density);
  }

 private:
  const RunState& state_;
  int cols_;
  Raster<std::uint8_t> shade_;
  std::unique_ptr<DemWindowReader> elevation_, shaded_, density_;
};

/// Terrain: hillshade tinted by land / sea, then the density where it exists.
void draw_terrain(Canvas& canvas, const TerrainRows& terrain, int cols, int rows, double sx, double sy) {
  const int width = canvas.width(), height = canvas.height();
  std::vector<float> z, shade, density;
  int loaded = -1;
  for (int y = 0; y < height; ++y) {
    const int r = std::min(rows - 1, int((y + 0.5) * sy));
    if (r != loaded) terrain.read(loaded = r, z, shade, density);
    for (int x = 0; x < width; ++x) {
      const int c = std::min(cols - 1, int((x + 0.5) * sx));
      if (std::isnan(z[std::size_t(c)])) {
        canvas.blend(x, y, hex(0xdddddd), 1);
      } else {
        const float s = shade[std::size_t(c)] / 255.0f;
        const Rgb base = z[std::size_t(c)] <= 0 ? hex(0x9ecae1) : hex(0xe8e4d0);
        canvas.blend(x, y, {base[0] * (0.45f + 0.55f * s), base[1] * (0.45f + 0.55f * s), base[2] * (0.45f + 0.55f * s)}, 1);
      }
      const float d = density[std::size_t(c)];
      if (!std::isnan(d) && d > 0) canvas.blend(x, y, density_color(d), 0.55f);
    }
  }
}

/// The legend's swatches drawn on the canvas, and its labels for the PNG writer (which draws text).
std::vector<TerrapolisPngText> draw_legend(Canvas& canvas, const std::vector<LegendEntry>& legend, double unit) {
  // Legend box, bottom left, scaled down to fit the image (in units: 126 wide with its margins,
  // 14 per entry plus 24 high); left out when its text would be under 7 px (a thumbnail).
  std::vector<TerrapolisPngText> texts;
  const int width = canvas.width(), height = canvas.height();
  const double lu = std::min({unit, width / 126.0, height / (14.0 * double(legend.size()) + 24.0)});
  if (11 * lu >= 7) {
    const int row_h = int(14 * lu), box_w = int(110 * lu), box_h = row_h * int(legend.size()) + int(8 * lu);
    const int bx = int(8 * lu), by = height - box_h - int(8 * lu);
    canvas.rect(bx, by, bx + box_w, by + box_h, hex(0xffffff), 0.8f);
    const float black[3] = {0.1f, 0.1f, 0.1f};
    for (std::size_t i = 0; i < legend.size(); ++i) {
      const int y = by + int(4 * lu) + int(i) * row_h;
      const int sw = int(18 * lu), sh = legend[i].line ? std::max(2, int(3 * lu)) : int(9 * lu);
      const int sx0 = bx + int(5 * lu), sy0 = y + (row_h - sh) / 2;
      canvas.rect(sx0, sy0, sx0 + sw, sy0 + sh, legend[i].color);
      texts.push_back({bx + int(28 * lu), y + row_h - int(3 * lu), int(11 * lu), {black[0], black[1], black[2]}, legend[i].label.c_str()});
    }
  }
  return texts;
}

}  // namespace

/// The PNG writer module: beside the executable (installed or built), else where the build put it.
static TerrapolisWritePng png_writer() {
  static TerrapolisWritePng writer = [] {
    std::vector<std::string> candidates;
    char exe[4096] = {};
    if (const ssize_t n = ::readlink("/proc/self/exe", exe, sizeof(exe) - 1); n > 0) {
      const std::filesystem::path dir = std::filesystem::path(std::string(exe, std::size_t(n))).parent_path();
      candidates.push_back((dir / "terrapolis_png.so").string());
      candidates.push_back((dir / ".." / "lib" / "terrapolis" / "terrapolis_png.so").string());
    }
    candidates.push_back(TERRAPOLIS_PNG_MODULE);
    std::string tried;
    for (const auto& file : candidates) {
      if (void* handle = ::dlopen(file.c_str(), RTLD_NOW | RTLD_LOCAL))
        if (void* symbol = ::dlsym(handle, TERRAPOLIS_WRITE_PNG_SYMBOL)) return reinterpret_cast<TerrapolisWritePng>(symbol);
      tried += (tried.empty() ? "" : ", ") + file;
    }
    throw processing_error("preview.png: cannot load the PNG writer module (tried " + tried + ")");
  }();
  return writer;
}

void write_preview(const RunState& state, const std::string& path, int width) {
  const int cols = state.grid.cols, rows = state.grid.rows;
  const Georef& georef = state.grid.georef;
  const CellMetrics m = cell_metrics(georef, cols, rows);
  const double mean_w = m.width_m[std::size_t(rows / 2)], mean_h = m.height_m[std::size_t(rows / 2)];
  const int height = std::max(16, int(std::lround(width * (rows * mean_h) / (cols * mean_w))));
  Canvas canvas(width, height);
  const double sx = double(cols) / width, sy = double(rows) / height;

  const TerrainRows terrain(state);
  draw_terrain(canvas, terrain, cols, rows, sx, sy);

  // Vectors, in the DEM's CRS (layers written in another CRS are transformed).
  const GridLocator locator(georef);
  std::vector<LegendEntry> legend;
  auto to_px = [&](const VectorLayer& layer, std::vector<std::array<double, 2>> pts) {
    std::optional<CrsTransform> t;
    if (layer.crs.wkt != georef.crs.wkt) t.emplace(layer.crs, georef.crs);
    for (auto& p : pts) {
      if (t) p = (*t)(p[0], p[1]);
      const auto q = locator.crs_to_pixel(p[0], p[1]);
      p = {q[0] / sx, q[1] / sy};
    }
    return pts;
  };
  auto field = [](const VectorLayer& layer, const Feature& f, const std::string& name) -> std::string {
    const int i = layer.field_index(name);
    if (i < 0) return "";
    const auto& v = f.values[std::size_t(i)];
    if (std::holds_alternative<std::int64_t>(v)) return std::to_string(std::get<std::int64_t>(v));
    if (std::holds_alternative<std::string>(v)) return std::get<std::string>(v);
    if (std::holds_alternative<double>(v)) return std::to_string(std::get<double>(v));
    return "";
  };
  const double unit = std::max(1.0, width / 600.0);  // line widths grow with the image
  // The network's sections draw each shared stretch once, in its highest class: when present they
  // replace the per-link roads, which overlap along trunks.
  bool has_sections = false;
  for (const auto& v : state.vectors) has_sections = has_sections || v.first == Style::sections;
  for (Style pass : {Style::city_extents, Style::streams, Style::network, Style::existing_roads, Style::road_sections, Style::roads, Style::sections,
                     Style::junctions, Style::cities}) {
    if (pass == Style::roads && has_sections) continue;
    for (const auto& [style, layer] : state.vectors) {
      if (style != pass) continue;
      for (const auto& f : layer.features) {
        if (f.parts.empty()) continue;
        if (style == Style::cities) {
          const auto p = to_px(layer, {f.parts[0][0]})[0];
          const int cls = std::atoi(field(layer, f, "class").c_str());
          canvas.disc(p[0], p[1], unit * std::max(1.5, 5.0 - cls), hex(0x252525));
          canvas.disc(p[0], p[1], unit * std::max(1.0, 4.0 - cls), hex(0xcb181d));
          continue;
        }
        if (style == Style::junctions) {
          const auto p = to_px(layer, {f.parts[0][0]})[0];
          canvas.disc(p[0], p[1], unit * 1.6, hex(0x252525));
          continue;
        }
        Rgb color = hex(0x2171b5);
        double w = unit;
        bool dashed = false;
        if (style == Style::streams) { w = unit * (0.5 + 0.3 * std::atoi(field(layer, f, "strahler").c_str())); }
        else if (style == Style::network) { if (field(layer, f, "kept") != "1") continue; color = hex(0x636363); w = unit * 0.6; dashed = true; }
        else if (style == Style::existing_roads) {
          const auto& s = roads::style_of(roads::road_class_named(field(layer, f, "class")).value_or(roads::RoadClass::local));
          color = hex(0x525252);
          w = unit * (0.6 + 1.3 * s.width_mm);
        } else if (style == Style::roads || style == Style::sections) {
          if (style == Style::sections && field(layer, f, "existing") == "1") continue;  // drawn as the existing road under it
          const auto& s = roads::style_of(roads::road_class_named(field(layer, f, "class")).value_or(roads::RoadClass::departmental));
          color = hex(unsigned(std::stoul(std::string(s.colour.substr(1)), nullptr, 16)));
          w = unit * (0.6 + 1.3 * s.width_mm);  // the QGIS widths, scaled to the image
          dashed = s.dashed;
        } else if (style == Style::road_sections) {
          const std::string s = field(layer, f, "structure");
          if (s == "bridge") { color = hex(0x08519c); w = unit * 3; }
          else if (s == "tunnel") { color = hex(0x8c510a); w = unit * 2.5; dashed = true; }
          else continue;
        } else if (style == Style::city_extents) { color = hex(0xa50f15); w = unit * 0.5; }
        for (const auto& part : f.parts) {
          const auto px = to_px(layer, part);
          for (std::size_t i = 1; i < px.size(); ++i) canvas.segment(px[i - 1][0], px[i - 1][1], px[i][0], px[i][1], w, color, dashed);
        }
      }
      if (pass == Style::streams) legend.push_back({hex(0x2171b5), "streams", true});
      if (pass == Style::network) legend.push_back({hex(0x636363), "network", true});
      if (pass == Style::roads || pass == Style::sections) legend.push_back({hex(0xe31a1c), "roads", true});
      if (pass == Style::existing_roads) legend.push_back({hex(0x525252), "existing roads", true});
      if (pass == Style::junctions) legend.push_back({hex(0x252525), "junctions", false});
      if (pass == Style::road_sections) legend.push_back({hex(0x08519c), "bridges", true});
      if (pass == Style::cities) legend.push_back({hex(0xcb181d), "cities", false});
    }
  }
  if (terrain.has_density()) legend.insert(legend.begin(), {hex(0xf03b20), "density", false});
  legend.insert(legend.begin(), {hex(0x9ecae1), "sea", false});

  const std::vector<TerrapolisPngText> texts = draw_legend(canvas, legend, unit);
  const std::string tmp = path + ".tmp.png";
  char error[512] = {};
  if (png_writer()(canvas.data(), width, height, texts.data(), int(texts.size()), "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf",
                   tmp.c_str(), error, int(sizeof(error))) != 0)
    throw processing_error(path + ": cannot write preview (" + error + ")");
  std::filesystem::rename(tmp, path);
}

}  // namespace terrapolis::pipeline
