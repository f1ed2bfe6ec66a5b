// The lakes a DEM flattens, tile by tile (see tiled_flat_water.hpp): each tile's level surfaces,
// joined across tile edges, the cells around the large ones counted by the tiles that hold them.
// SPDX-License-Identifier: MIT
#include "hydro/tiled/tiled_flat_water.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "core/geodesy.hpp"
#include "hydro/tiled/tiled_run.hpp"

namespace terrapolis::hydro::tiled {
namespace {

constexpr std::int64_t kNone = -1;

/// One tile's level surfaces (8-connected seeds of its own cells), read with a one-cell halo.
struct TileSurfaces {
  TileRect core;                      ///< in the mosaic
  Dem window;                         ///< the core and its halo
  int ox = 0, oy = 0;                 ///< the core's first cell in the window
  std::vector<std::int32_t> label;    ///< per core cell: its surface, -1 not a seed
  std::vector<double> area_m2;        ///< per surface
  std::vector<std::int64_t> first;    ///< per surface: its first cell in the mosaic's row-major order
  std::vector<std::uint8_t> framed;   ///< per surface: a cell within two of the tile's edges
  std::uint8_t seed(int x, int y) const { return label[std::size_t(y) * std::size_t(core.cols) + std::size_t(x)] >= 0; }
};

TileSurfaces surfaces_of(const TileGrid& grid, int t, const ReadWindow& read, const CellMetrics& metrics, const FlatWaterOptions& options) {
  TileSurfaces s;
  s.core = grid.rect(t);
  const TileRect& r = s.core;
  const TileRect w = grid.grown(t, 1, 1);
  s.window = read(w.col0, w.row0, w.cols, w.rows);
  s.ox = r.col0 - w.col0;
  s.oy = r.row0 - w.row0;
  const std::size_t n = std::size_t(r.cols) * std::size_t(r.rows);
  std::vector<std::uint8_t> seed(n);
  for (int y = 0; y < r.rows; ++y)
    for (int x = 0; x < r.cols; ++x) seed[std::size_t(y) * std::size_t(r.cols) + std::size_t(x)] = flat_water_seed(s.window, s.ox + x, s.oy + y, options);
  s.label.assign(n, -1);
  const Border frame(TileRect{0, 0, r.cols, r.rows}, 2);
  std::vector<std::size_t> stack;
  for (std::size_t start = 0; start < n; ++start) {
    if (!seed[start] || s.label[start] >= 0) continue;
    const std::int32_t id = std::int32_t(s.area_m2.size());
    const int sx = int(start % std::size_t(r.cols)), sy = int(start / std::size_t(r.cols));
    s.area_m2.push_back(0);
    s.first.push_back(std::int64_t(r.row0 + sy) * grid.cols() + r.col0 + sx);
    s.framed.push_back(0);
    s.label[start] = id;
    stack.assign(1, start);
    while (!stack.empty()) {
      const std::size_t i = stack.back();
      stack.pop_back();
      const int x = int(i % std::size_t(r.cols)), y = int(i / std::size_t(r.cols));
      s.area_m2.back() += metrics.area_m2[std::size_t(r.row0 + y)];
      if (frame.contains(x, y)) s.framed.back() = 1;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          if (x + dx < 0 || y + dy < 0 || x + dx >= r.cols || y + dy >= r.rows) continue;
          const std::size_t j = std::size_t(y + dy) * std::size_t(r.cols) + std::size_t(x + dx);
          if (seed[j] && s.label[j] < 0) {
            s.label[j] = id;
            stack.push_back(j);
          }
        }
    }
  }
  return s;
}

/// The surfaces of the mosaic that matter beyond their tile: those reaching a tile's frame (they
/// may continue in the next tile, and the next tile's cells may lie around them) and those large
/// enough to be lakes. Ids are given tile by tile in each tile's scan order.
class MosaicSurfaces {
 public:
  MosaicSurfaces(const TileGrid& grid, double min_area_m2) : grid_(grid), min_area_m2_(min_area_m2), base_(std::size_t(grid.count())), frames_(std::size_t(grid.count())) {}

  /// Pass 1: the tile's surfaces get ids and its frame their ids.
  void add(int t, const TileSurfaces& s) {
    base_[std::size_t(t)] = std::int64_t(area_.size());
    const std::vector<std::int64_t> ids = ids_of(t, s);
    for (std::size_t k = 0; k < ids.size(); ++k)
      if (ids[k] != kNone) {
        area_.push_back(s.area_m2[k]);
        first_.push_back(s.first[k]);
        level_.push_back(s.window(s.ox + int(s.first[k] % grid_.cols()) - s.core.col0, s.oy + int(s.first[k] / grid_.cols()) - s.core.row0));
      }
    const Border frame(TileRect{0, 0, s.core.cols, s.core.rows}, 2);
    std::vector<std::int64_t>& f = frames_[std::size_t(t)];
    f.assign(frame.size(), kNone);
    for (int y = 0; y < s.core.rows; ++y)
      for (int x = 0; x < s.core.cols; ++x)
        if (frame.contains(x, y) && s.seed(x, y)) f[frame.index(x, y)] = ids[std::size_t(s.label[std::size_t(y) * std::size_t(s.core.cols) + std::size_t(x)])];
  }

  /// After pass 1: surfaces that touch across tile edges are one; each gets its area, first cell
  /// and level (its first cell's, as the whole grid's scan finds it).
  void join() {
    parent_.resize(area_.size());
    for (std::size_t g = 0; g < parent_.size(); ++g) parent_[g] = std::int64_t(g);
    for (int t = 0; t < grid_.count(); ++t) {
      const TileRect r = grid_.rect(t);
      const Border ring(TileRect{0, 0, r.cols, r.rows}, 1), frame(TileRect{0, 0, r.cols, r.rows}, 2);
      for (int y = 0; y < r.rows; ++y)
        for (int x = 0; x < r.cols; ++x) {
          if (!ring.contains(x, y)) continue;
          const std::int64_t a = frames_[std::size_t(t)][frame.index(x, y)];
          if (a == kNone) continue;
          for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
              const int c = r.col0 + x + dx, w = r.row0 + y + dy;
              if (c < 0 || w < 0 || c >= grid_.cols() || w >= grid_.rows() || (x + dx >= 0 && y + dy >= 0 && x + dx < r.cols && y + dy < r.rows))
                continue;
              if (const std::int64_t b = at(c, w); b != kNone) unite(a, b);
            }
        }
    }
    root_area_.assign(area_.size(), 0);
    for (std::size_t g = 0; g < area_.size(); ++g) {
      const std::int64_t root = find(std::int64_t(g));
      root_area_[std::size_t(root)] += area_[g];
      if (first_[g] < first_[std::size_t(root)]) first_[std::size_t(root)] = first_[g], level_[std::size_t(root)] = level_[g];
    }
    outside_.assign(area_.size(), 0);
    lower_.assign(area_.size(), 0);
  }

  /// The large surface (by area) a core cell of tile t belongs to, or kNone.
  std::vector<std::int64_t> ids_of(int t, const TileSurfaces& s) const {
    std::vector<std::int64_t> ids(s.area_m2.size(), kNone);
    std::int64_t next = base_[std::size_t(t)];
    for (std::size_t k = 0; k < ids.size(); ++k)
      if (s.framed[k] || s.area_m2[k] >= min_area_m2_) ids[k] = next++;
    return ids;
  }
  /// The id of a cell on some tile's frame (kNone: no surface that matters there).
  std::int64_t at(int c, int r) const {
    const int u = grid_.tile_of(c, r);
    const TileRect ru = grid_.rect(u);
    const Border frame(TileRect{0, 0, ru.cols, ru.rows}, 2);
    return frames_[std::size_t(u)][frame.index(c - ru.col0, r - ru.row0)];
  }
  /// The root of a surface when the joined surface is large enough to be a lake, else kNone.
  std::int64_t large(std::int64_t id) {
    if (id == kNone) return kNone;
    const std::int64_t root = find(id);
    return root_area_[std::size_t(root)] >= min_area_m2_ ? root : kNone;
  }
  std::int64_t find(std::int64_t g) {
    while (parent_[std::size_t(g)] != g) g = parent_[std::size_t(g)] = parent_[std::size_t(parent_[std::size_t(g)])];
    return g;
  }
  std::size_t surfaces() const { return area_.size(); }
  float level(std::int64_t root) const { return level_[std::size_t(root)]; }
  std::vector<std::size_t> outside_, lower_;  ///< per root: cells two from the surface, and those below it

 private:
  void unite(std::int64_t a, std::int64_t b) {
    a = find(a);
    b = find(b);
    if (a != b) parent_[std::size_t(std::max(a, b))] = std::min(a, b);
  }
  const TileGrid& grid_;
  double min_area_m2_;
  std::vector<std::int64_t> base_;
  std::vector<std::vector<std::int64_t>> frames_;
  std::vector<double> area_, root_area_;
  std::vector<std::int64_t> first_, parent_;
  std::vector<float> level_;
};

/// Up to a few distinct ids (a cell lies near one surface, rarely two or three).
struct IdSet {
  std::vector<std::int64_t> ids;
  void add(std::int64_t id) {
    if (id != kNone && std::find(ids.begin(), ids.end(), id) == ids.end()) ids.push_back(id);
  }
  bool has(std::int64_t id) const { return std::find(ids.begin(), ids.end(), id) != ids.end(); }
};

}  // namespace

int flat_water_tile_size_for(int cols, int rows, double memory_limit_mb, double reserved_mb) {
  return largest_tile_side(
      [&](int side) {  // a tile and its halo, the frames of all tiles
        const double tile = kFlatWaterBytesPerCell * double(std::min(side, cols) + 4) * double(std::min(side, rows) + 4);
        return tile + kFlatWaterBytesPerEdgeCell * 4.0 * double(side) * double(TileGrid(cols, rows, side).count());
      },
      memory_limit_mb, reserved_mb, "flat water tiles of 64 x 64 cells on a " + std::to_string(cols) + " x " + std::to_string(rows) + " mosaic");
}

TiledFlatWaterReport run_tiled_flat_water(int cols, int rows, const Georef& georef, const ReadWindow& read, const FlatWaterOptions& options,
                                          int tile_size, const WriteMaskTile& write, Progress& progress) {
  const TileGrid grid(cols, rows, std::max(tile_size, 8));
  TiledFlatWaterReport report;
  report.tile_size = std::max(tile_size, 8);
  report.tiles = grid.count();
  report.across = grid.across();
  const CellMetrics metrics = cell_metrics(georef, cols, rows);
  const bool off = options.min_area_km2 <= 0 || cols < 3 || rows < 3;  // as detect_flat_water
  MosaicSurfaces mosaic(grid, options.min_area_km2 * 1e6);
  if (!off) {
    ProgressStep step(progress, "flat water by tiles: level surfaces");
    for (int t = 0; t < grid.count(); ++t) {
      mosaic.add(t, surfaces_of(grid, t, read, metrics, options));
      step.update(double(t + 1) / grid.count());
    }
    mosaic.join();
  }
  report.surfaces = mosaic.surfaces();

  // For each cell of tile t: the large surfaces within one cell of it (it lies on their shore or
  // inside) and within two (the ring around them where the whole grid looks for lower land).
  auto each_cell = [&](int t, auto&& use) {
    const TileSurfaces s = surfaces_of(grid, t, read, metrics, options);
    const std::vector<std::int64_t> ids = mosaic.ids_of(t, s);
    const TileRect& r = s.core;
    const TileRect around = grid.grown(t, 2, 2);
    const int e0 = around.col0, f0 = around.row0, e1 = e0 + around.cols, f1 = f0 + around.rows, w = around.cols;
    std::vector<std::int64_t> near(std::size_t(w) * std::size_t(f1 - f0), kNone);
    for (int y = f0; y < f1; ++y)
      for (int x = e0; x < e1; ++x) {
        const bool own = x >= r.col0 && y >= r.row0 && x < r.col0 + r.cols && y < r.row0 + r.rows;
        std::int64_t id = kNone;
        if (own) {
          const std::int32_t l = s.label[std::size_t(y - r.row0) * std::size_t(r.cols) + std::size_t(x - r.col0)];
          if (l >= 0) id = ids[std::size_t(l)];
        } else {
          id = mosaic.at(x, y);
        }
        near[std::size_t(y - f0) * std::size_t(w) + std::size_t(x - e0)] = mosaic.large(id);
      }
    IdSet within1, within2;
    for (int y = r.row0; y < r.row0 + r.rows; ++y)
      for (int x = r.col0; x < r.col0 + r.cols; ++x) {
        within1.ids.clear();
        within2.ids.clear();
        for (int dy = -2; dy <= 2; ++dy)
          for (int dx = -2; dx <= 2; ++dx) {
            const int c = x + dx, v = y + dy;
            if (c < e0 || v < f0 || c >= e1 || v >= f1) continue;
            const std::int64_t id = near[std::size_t(v - f0) * std::size_t(w) + std::size_t(c - e0)];
            if (id == kNone) continue;
            if (std::abs(dx) <= 1 && std::abs(dy) <= 1) within1.add(id);
            within2.add(id);
          }
        if (!within2.ids.empty()) use(s, x - r.col0, y - r.row0, within1, within2);
      }
  };

  if (!off) {
    ProgressStep step(progress, "flat water by tiles: their shores");
    for (int t = 0; t < grid.count(); ++t) {
      each_cell(t, [&](const TileSurfaces& s, int x, int y, const IdSet& within1, const IdSet& within2) {
        const std::size_t i = s.window.index(s.ox + x, s.oy + y);
        for (const std::int64_t root : within2.ids) {
          if (within1.has(root)) continue;
          ++mosaic.outside_[std::size_t(root)];
          if (s.window.is_nodata(i) || double(s.window[i]) < double(mosaic.level(root)) - options.tolerance_m) ++mosaic.lower_[std::size_t(root)];
        }
      });
      step.update(double(t + 1) / grid.count());
    }
  }
  auto kept = [&](std::int64_t root) { return flat_water_in_basin(mosaic.lower_[std::size_t(root)], mosaic.outside_[std::size_t(root)]); };
  for (std::size_t g = 0; g < mosaic.surfaces(); ++g)
    if (const std::int64_t root = mosaic.large(std::int64_t(g)); root == std::int64_t(g) && kept(root)) ++report.lakes;

  ProgressStep step(progress, "flat water by tiles");
  for (int t = 0; t < grid.count(); ++t) {
    const TileRect r = grid.rect(t);
    Raster<std::uint8_t> mask(r.cols, r.rows, shifted(georef, r.col0, r.row0));
    std::fill(mask.values().begin(), mask.values().end(), std::uint8_t(0));
    if (!off)
      each_cell(t, [&](const TileSurfaces&, int x, int y, const IdSet& within1, const IdSet&) {
        for (const std::int64_t root : within1.ids)
          if (kept(root)) mask(x, y) = 1;
      });
    for (int y = 0; y < r.rows; ++y)
      for (int x = 0; x < r.cols; ++x)
        if (mask(x, y)) report.area_km2 += metrics.area_m2[std::size_t(r.row0 + y)] / 1e6;
    write(t, grid.across(), mask);
    step.update(double(t + 1) / grid.count());
  }
  return report;
}

}  // namespace terrapolis::hydro::tiled
