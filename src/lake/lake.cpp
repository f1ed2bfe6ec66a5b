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

Lake flood(const Dem& dem, const CellMetrics& metrics, int seed_col, int seed_row, double level_m, const Dam* dam, Progress& progress) {
  if (!std::isfinite(level_m)) throw bad_input("/level_m: must be a finite elevation in metres");
  if (!dem.inside(seed_col, seed_row)) throw bad_input("/at: the point lies outside the DEM");
  const int cols = dem.cols(), rows = dem.rows();
  Lake lake;
  lake.level_m = level_m;
  lake.seed_col = seed_col;
  lake.seed_row = seed_row;
  lake.mask = dem.like<std::uint8_t>(0);
  lake.mask.nodata = 255;
  for (std::size_t i = 0; i < dem.size(); ++i)
    if (dem.is_nodata(i)) lake.mask[i] = 255;
  // The dam raises its cells to the crest (never lowers them).
  std::vector<std::uint8_t> is_dam;
  if (dam) {
    if (!std::isfinite(dam->crest_m)) throw bad_input("/crest_m: must be a finite elevation in metres");
    is_dam.assign(dem.size(), 0);
    for (std::size_t i : line_cells(dem.georef(), cols, rows, dam->line)) is_dam[i] = 1, ++lake.dam_cells;
    if (lake.dam_cells == 0) throw bad_input("/dam: the line does not cross the DEM");
  }
  auto ground = [&](std::size_t i) { return is_dam.empty() || !is_dam[i] ? double(dem[i]) : std::max(double(dem[i]), dam->crest_m); };
  const std::size_t seed = dem.index(seed_col, seed_row);
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
  check_spec(spec);
  const GridLocator locator(dem.georef());
  auto to_cell = [&](double lon, double lat, const char* pointer) {
    const auto xy = locator.lonlat_to_crs(lon, lat);
    if (!std::isfinite(xy[0]) || !std::isfinite(xy[1])) throw bad_input(std::string(pointer) + ": cannot be transformed to the DEM's CRS");
    return xy;
  };
  const auto seed_xy = to_cell(spec.lon, spec.lat, "/at");
  const auto p = to_pixel(dem.georef().transform, seed_xy[0], seed_xy[1]);
  const int col = int(std::floor(p[0])), row = int(std::floor(p[1]));
  if (!dem.inside(col, row)) throw bad_input("/at: the point lies outside the DEM");
  Dam dam;
  const bool with_dam = !spec.dam_lonlat.empty();
  if (with_dam) {
    for (const auto& q : spec.dam_lonlat) dam.line.push_back(to_cell(q[0], q[1], "/dam"));
    dam.crest_m = *spec.crest_m;
  }
  double level = dam.crest_m;
  if (spec.level_m) level = *spec.level_m;
  else if (spec.depth_m) level = double(dem(col, row)) + *spec.depth_m;  // NaN on nodata: refused below
  if (spec.depth_m && dem.is_nodata(dem.index(col, row))) throw bad_input("/at: the point lies on the DEM's nodata");
  return flood(dem, metrics, col, row, level, with_dam ? &dam : nullptr, progress);
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
