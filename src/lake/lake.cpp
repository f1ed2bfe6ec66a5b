// Flood fill to a level (Peytavie 2010 §2.4.1), dams, shoreline, and what the water covers.
// SPDX-License-Identifier: MIT
#include "lake/lake.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/error.hpp"
#include "core/neighbours.hpp"
#include "hydro/catchment.hpp"
#include "io/crs.hpp"

namespace terrapolis::lake {
namespace {

/// Fractional pixel position (corners at integers) of CRS coordinates.
std::array<double, 2> to_pixel(const GeoTransform& t, double x, double y) {
  const double det = t[1] * t[5] - t[2] * t[4];
  if (det == 0) throw bad_input("DEM: singular geotransform");
  const double dx = x - t[0], dy = y - t[3];
  return {(t[5] * dx - t[2] * dy) / det, (t[1] * dy - t[4] * dx) / det};
}

}  // namespace

std::vector<std::size_t> line_cells(const Georef& georef, int cols, int rows, const std::vector<std::array<double, 2>>& line) {
  std::vector<std::size_t> out;
  auto add = [&](int c, int r) {
    if (c < 0 || r < 0 || c >= cols || r >= rows) return;
    const std::size_t i = std::size_t(r) * std::size_t(cols) + std::size_t(c);
    if (out.empty() || out.back() != i) out.push_back(i);
  };
  for (std::size_t s = 0; s + 1 < line.size(); ++s) {
    // Amanatides and Woo's grid traversal: one axis step at a time, so the chain is 4-connected.
    const auto a = to_pixel(georef.transform, line[s][0], line[s][1]);
    const auto b = to_pixel(georef.transform, line[s + 1][0], line[s + 1][1]);
    int c = int(std::floor(a[0])), r = int(std::floor(a[1]));
    const int c1 = int(std::floor(b[0])), r1 = int(std::floor(b[1]));
    const double dx = b[0] - a[0], dy = b[1] - a[1];
    const int sc = dx > 0 ? 1 : -1, sr = dy > 0 ? 1 : -1;
    const double tdx = dx != 0 ? std::abs(1 / dx) : INFINITY, tdy = dy != 0 ? std::abs(1 / dy) : INFINITY;
    double tx = dx != 0 ? (sc > 0 ? std::floor(a[0]) + 1 - a[0] : a[0] - std::floor(a[0])) * tdx : INFINITY;
    double ty = dy != 0 ? (sr > 0 ? std::floor(a[1]) + 1 - a[1] : a[1] - std::floor(a[1])) * tdy : INFINITY;
    add(c, r);
    for (long steps = std::abs(c1 - c) + std::abs(r1 - r); steps > 0; --steps) {
      if (tx < ty) {
        c += sc;
        tx += tdx;
      } else {
        r += sr;
        ty += tdy;
      }
      add(c, r);
    }
  }
  return out;
}

namespace {

/// Which sides of a raster (west, north, east, south) are the grid's edges, where the water spills.
using GridSides = std::array<bool, 4>;
constexpr GridSides kWholeGrid = {true, true, true, true};

/// Peytavie's propagation from `seed` on `dem` (the whole grid or a window of it), `is_dam` (empty:
/// no dam) marking the cells raised to `crest_m`. Returns false as soon as the water reaches a side
/// of `dem` that is not the grid's (the window is too small: `lake` is then incomplete).
bool spread(const Dem& dem, const CellMetrics& metrics, std::size_t seed, double level_m, const std::vector<std::uint8_t>& is_dam, double crest_m,
            const GridSides& grid_sides, Lake& lake, Progress& progress) {
  const int cols = dem.cols();
  lake.mask = dem.like<std::uint8_t>(0);
  lake.mask.nodata = 255;
  for (std::size_t i = 0; i < dem.size(); ++i)
    if (dem.is_nodata(i)) lake.mask[i] = 255;
  auto ground = [&](std::size_t i) { return is_dam.empty() || !is_dam[i] ? double(dem[i]) : std::max(double(dem[i]), crest_m); };
  if (dem.is_nodata(seed)) throw bad_input("/at: the point lies on the DEM's nodata");
  if (!(ground(seed) < level_m)) {
    char msg[160];
    std::snprintf(msg, sizeof msg, "/at: the ground there (%.2f m) is not below the water level (%.2f m)", ground(seed), level_m);
    throw bad_input(msg);
  }
  ProgressStep step(progress, "lake");
  lake.depth = dem.like<float>(NAN);
  std::vector<std::size_t> front{seed};
  lake.mask[seed] = 1;
  while (!front.empty()) {
    const std::size_t i = front.back();
    front.pop_back();
    const int c = int(i % std::size_t(cols)), r = int(i / std::size_t(cols));
    const double a = metrics.area_m2[std::size_t(r)], d = level_m - ground(i);
    lake.depth[i] = float(d);
    ++lake.cells;
    lake.area_km2 += a * 1e-6;
    lake.volume_m3 += a * d;
    lake.max_depth_m = std::max(lake.max_depth_m, d);
    for (int k = 0; k < 8; ++k) {
      const int nc = c + dcol[k], nr = r + drow[k];
      if (!dem.inside(nc, nr)) {
        const bool off_grid = (nc < 0 && grid_sides[0]) || (nr < 0 && grid_sides[1]) || (nc >= cols && grid_sides[2]) ||
                              (nr >= dem.rows() && grid_sides[3]);
        if (!off_grid) return false;  // a cell of the grid past the window
        lake.spills = true;
        continue;
      }
      const std::size_t n = dem.index(nc, nr);
      if (lake.mask[n] == 255) lake.spills = true;
      if (lake.mask[n] != 0 || !(ground(n) < level_m)) continue;
      lake.mask[n] = 1;
      front.push_back(n);
    }
    if ((lake.cells & 0xfffff) == 0) step.update(std::min(0.99, double(lake.cells) / double(dem.size())));
  }
  return true;
}

/// A spec placed on a grid: its seed cell, its dam in the grid's CRS (empty: none) and its level
/// (level_of reads a depth above the seed's ground).
struct Placed {
  int col = 0, row = 0;
  Dam dam;
  double level_m = NAN;
};

Placed place(const Georef& georef, int cols, int rows, const LakeSpec& spec) {
  check_spec(spec);
  const GridLocator locator(georef);
  auto to_crs = [&](double lon, double lat, const char* pointer) {
    const auto xy = locator.lonlat_to_crs(lon, lat);
    if (!std::isfinite(xy[0]) || !std::isfinite(xy[1])) throw bad_input(std::string(pointer) + ": cannot be transformed to the DEM's CRS");
    return xy;
  };
  const auto seed_xy = to_crs(spec.lon, spec.lat, "/at");
  const auto p = to_pixel(georef.transform, seed_xy[0], seed_xy[1]);
  Placed out;
  out.col = int(std::floor(p[0])), out.row = int(std::floor(p[1]));
  if (out.col < 0 || out.row < 0 || out.col >= cols || out.row >= rows) throw bad_input("/at: the point lies outside the DEM");
  if (!spec.dam_lonlat.empty()) {
    for (const auto& q : spec.dam_lonlat) out.dam.line.push_back(to_crs(q[0], q[1], "/dam"));
    out.dam.crest_m = *spec.crest_m;
    out.level_m = out.dam.crest_m;
  }
  if (spec.level_m) out.level_m = *spec.level_m;
  return out;
}

/// The level of `spec` placed as `p`, `seed_ground` the DEM at its seed (NaN: nodata).
double level_of(const LakeSpec& spec, const Placed& p, double seed_ground) {
  if (!spec.depth_m) return p.level_m;
  if (std::isnan(seed_ground)) throw bad_input("/at: the point lies on the DEM's nodata");
  return seed_ground + *spec.depth_m;
}

}  // namespace

Lake flood(const Dem& dem, const CellMetrics& metrics, int seed_col, int seed_row, double level_m, const Dam* dam, Progress& progress) {
  if (!std::isfinite(level_m)) throw bad_input("/level_m: must be a finite elevation in metres");
  if (!dem.inside(seed_col, seed_row)) throw bad_input("/at: the point lies outside the DEM");
  Lake lake;
  lake.level_m = level_m;
  lake.seed_col = seed_col;
  lake.seed_row = seed_row;
  // The dam raises its cells to the crest (never lowers them).
  std::vector<std::uint8_t> is_dam;
  if (dam) {
    if (!std::isfinite(dam->crest_m)) throw bad_input("/crest_m: must be a finite elevation in metres");
    is_dam.assign(dem.size(), 0);
    for (std::size_t i : line_cells(dem.georef(), dem.cols(), dem.rows(), dam->line)) is_dam[i] = 1, ++lake.dam_cells;
    if (lake.dam_cells == 0) throw bad_input("/dam: the line does not cross the DEM");
  }
  spread(dem, metrics, dem.index(seed_col, seed_row), level_m, is_dam, dam ? dam->crest_m : 0.0, kWholeGrid, lake, progress);
  return lake;
}

void check_spec(const LakeSpec& spec) {
  if (!(std::abs(spec.lat) <= 90) || !(std::abs(spec.lon) <= 360)) throw bad_input("/at: not a lon,lat pair in degrees");
  for (const auto& q : spec.dam_lonlat)
    if (!(std::abs(q[1]) <= 90) || !(std::abs(q[0]) <= 360)) throw bad_input("/dam: not lon,lat pairs in degrees");
  if (!spec.dam_lonlat.empty()) {
    if (spec.dam_lonlat.size() < 2) throw bad_input("/dam: a line needs at least two points");
    if (!spec.crest_m) throw bad_input("/dam: needs /crest_m (the crest elevation, m)");
  } else if (spec.crest_m) {
    throw bad_input("/crest_m: only with /dam");
  }
  if (spec.crest_m && !std::isfinite(*spec.crest_m)) throw bad_input("/crest_m: must be a finite elevation in metres");
  if (spec.level_m && spec.depth_m) throw bad_input("/level_m, /depth_m: give one, not both");
  if (spec.level_m && !std::isfinite(*spec.level_m)) throw bad_input("/level_m: must be a finite elevation in metres");
  if (spec.depth_m && !(*spec.depth_m > 0 && std::isfinite(*spec.depth_m))) throw bad_input("/depth_m: must be a positive number of metres");
  if (!spec.level_m && !spec.depth_m && spec.dam_lonlat.empty())
    throw bad_input("/level_m or /depth_m: the water level is required (or /dam with /crest_m)");
}

Lake flood(const Dem& dem, const CellMetrics& metrics, const LakeSpec& spec, Progress& progress) {
  const Placed p = place(dem.georef(), dem.cols(), dem.rows(), spec);
  const std::size_t seed = dem.index(p.col, p.row);
  const double level = level_of(spec, p, dem.is_nodata(seed) ? NAN : double(dem[seed]));
  return flood(dem, metrics, p.col, p.row, level, p.dam.line.empty() ? nullptr : &p.dam, progress);
}

WindowLake flood_by_windows(const Georef& grid, int cols, int rows, const ReadWindow& read, const LakeSpec& spec, std::size_t max_cells,
                            Progress& progress) {
  const Placed p = place(grid, cols, rows, spec);
  std::vector<std::size_t> dam_cells;  // on the grid, so that every window raises the grid's cells
  if (!p.dam.line.empty()) {
    dam_cells = line_cells(grid, cols, rows, p.dam.line);
    if (dam_cells.empty()) throw bad_input("/dam: the line does not cross the DEM");
  }
  const CellMetrics metrics = cell_metrics(grid, cols, rows);
  double level = NAN;
  int windows = 0;
  // A square around the seed, grown twice as wide each time the water reaches its side, until the
  // lake and the cells around it lie inside (the propagation then visits the whole grid's cells in
  // the whole grid's order: the same figures, bit for bit).
  const auto too_large = [&] {
    return bad_input("/at: the water spreads over more cells than the memory limit holds (" + std::to_string(max_cells) +
                     " cells a window); give more memory or a lower level");
  };
  for (long half = 128;; half *= 2) {
    const int c0 = int(std::max<long>(0, p.col - half)), r0 = int(std::max<long>(0, p.row - half));
    const int c1 = int(std::min<long>(cols, p.col + half + 1)), r1 = int(std::min<long>(rows, p.row + half + 1));
    if (std::size_t(c1 - c0) * std::size_t(r1 - r0) > max_cells) throw too_large();
    const Dem dem = read(c0, r0, c1 - c0, r1 - r0);
    const std::size_t seed = dem.index(p.col - c0, p.row - r0);
    if (std::isnan(level)) level = level_of(spec, p, dem.is_nodata(seed) ? NAN : double(dem[seed]));  // finite: check_spec
    std::vector<std::uint8_t> is_dam;
    if (!dam_cells.empty()) {
      is_dam.assign(dem.size(), 0);
      for (std::size_t i : dam_cells)
        if (const int c = int(i % std::size_t(cols)) - c0, r = int(i / std::size_t(cols)) - r0; dem.inside(c, r)) is_dam[dem.index(c, r)] = 1;
    }
    WindowLake out{Lake{}, c0, r0, ++windows};
    Lake& lake = out.lake;
    lake.level_m = level, lake.seed_col = p.col, lake.seed_row = p.row, lake.dam_cells = dam_cells.size();
    const GridSides sides = {c0 == 0, r0 == 0, c1 == cols, r1 == rows};
    if (spread(dem, metric_rows(metrics, r0, r1 - r0), seed, level, is_dam, p.dam.crest_m, sides, lake, progress)) return out;
  }
}

VectorLayer shoreline_layer(const Lake& lake) {
  VectorLayer layer;
  layer.name = "shoreline";
  layer.geometry = GeometryType::polygon;
  layer.crs = lake.mask.georef().crs;
  layer.fields = {{"level_m", FieldType::real}, {"area_km2", FieldType::real}, {"volume_m3", FieldType::real}};
  for (auto& f : hydro::polygonize(lake.mask)) {
    f.values = {lake.level_m, lake.area_km2, lake.volume_m3};
    layer.features.push_back(std::move(f));
  }
  return layer;
}

double flooded_length_m(const Lake& lake, const VectorLayer& roads) {
  const Georef& g = lake.mask.georef();
  double total = 0;
  for (const auto& f : roads.features)
    for (const auto& part : f.parts)
      for (std::size_t s = 0; s + 1 < part.size(); ++s) {
        const auto a = to_pixel(g.transform, part[s][0], part[s][1]), b = to_pixel(g.transform, part[s + 1][0], part[s + 1][1]);
        const int n = std::max(1, int(std::ceil(10 * std::hypot(b[0] - a[0], b[1] - a[1]))));
        const double piece = crs_distance_m(g.crs, part[s][0], part[s][1], part[s + 1][0], part[s + 1][1]) / n;
        for (int j = 0; j < n; ++j) {
          const double t = (j + 0.5) / n;
          const int c = int(std::floor(a[0] + t * (b[0] - a[0]))), r = int(std::floor(a[1] + t * (b[1] - a[1])));
          if (lake.mask.inside(c, r) && lake.mask(c, r) == 1) total += piece;
        }
      }
  return total;
}

std::vector<std::int64_t> cities_touched(const Lake& lake, const CellMetrics& metrics, const VectorLayer& cities) {
  const int f_id = cities.field_index("id"), f_radius = cities.field_index("radius_m");
  if (f_id < 0 || f_radius < 0) throw bad_input(cities.name + ": the cities need fields 'id' and 'radius_m'");
  const Georef& g = lake.mask.georef();
  const double min_height = *std::min_element(metrics.height_m.begin(), metrics.height_m.end());
  std::vector<std::int64_t> out;
  for (const auto& f : cities.features) {
    const auto* id = std::get_if<std::int64_t>(&f.values[std::size_t(f_id)]);
    const auto* radius = std::get_if<double>(&f.values[std::size_t(f_radius)]);
    if (!id || !radius || f.parts.empty() || f.parts[0].empty()) continue;
    const auto centre = f.parts[0][0];
    const auto p = to_pixel(g.transform, centre[0], centre[1]);
    const int pc = int(std::floor(p[0])), pr = int(std::floor(p[1]));
    const int dr = int(std::ceil(*radius / min_height)) + 1;
    bool touched = false;
    for (int r = std::max(0, pr - dr); r <= std::min(lake.mask.rows() - 1, pr + dr) && !touched; ++r) {
      const int dc = int(std::ceil(*radius / metrics.width_m[std::size_t(r)])) + 1;
      for (int c = std::max(0, pc - dc); c <= std::min(lake.mask.cols() - 1, pc + dc) && !touched; ++c) {
        if (lake.mask(c, r) != 1) continue;
        const auto q = g.cell_centre(c, r);
        touched = crs_distance_m(g.crs, centre[0], centre[1], q[0], q[1]) <= *radius;
      }
    }
    if (touched) out.push_back(*id);
  }
  return out;
}

}  // namespace terrapolis::lake
