// Ground surface, water depth and land components of a DEM for the road search.
// SPDX-License-Identifier: MIT
#include "roads/terrain_field.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/error.hpp"
#include "core/neighbours.hpp"

namespace terrapolis::roads {

void WaterCount::add(const Dem& window, double sea_level_m) {
  for (std::size_t i = 0; i < window.size(); ++i) {
    if (window.is_nodata(i) || !(window[i] <= sea_level_m)) continue;
    ++water;
    if (window[i] < sea_level_m - 1) ++deep;
  }
}

TerrainField::TerrainField(const Dem& dem, double sea_level_m, double unknown_depth_m, double road_radius_m,
                           const Raster<std::uint8_t>* inland_water)
    : cols_(dem.cols()), rows_(dem.rows()), col_end_(dem.cols()), row_end_(dem.rows()), grid_cols_(dem.cols()), grid_rows_(dem.rows()),
      georef_(dem.georef()), metrics_(cell_metrics(dem.georef(), dem.cols(), dem.rows())), sea_level_(sea_level_m) {
  WaterCount count;
  count.add(dem, sea_level_m);
  bathymetry_ = count.bathymetry();
  build(dem, unknown_depth_m, road_radius_m, inland_water);
}

TerrainField::TerrainField(const Dem& window, int col0, int row0, const TerrainGrid& grid, double sea_level_m, double unknown_depth_m,
                           double road_radius_m, const Raster<std::uint8_t>* inland_water)
    : cols_(window.cols()), rows_(window.rows()), col0_(col0), row0_(row0), col_end_(col0 + window.cols()), row_end_(row0 + window.rows()),
      grid_cols_(grid.cols), grid_rows_(grid.rows), origin_(std::size_t(row0) * std::size_t(window.cols()) + std::size_t(col0)),
      georef_(grid.georef), metrics_(cell_metrics(grid.georef, grid.cols, grid.rows)), sea_level_(sea_level_m), bathymetry_(grid.bathymetry) {
  if (col0 < 0 || row0 < 0 || col_end_ > grid.cols || row_end_ > grid.rows) throw processing_error("terrain: a window outside its grid");
  if (inland_water && (inland_water->cols() != cols_ || inland_water->rows() != rows_))
    throw processing_error("terrain: the inland water window is not the DEM's");
  build(window, unknown_depth_m, road_radius_m, inland_water);
}

TerrainField TerrainField::frame(const TerrainGrid& grid) {
  TerrainField t;
  t.cols_ = t.col_end_ = t.grid_cols_ = grid.cols;
  t.rows_ = t.row_end_ = t.grid_rows_ = grid.rows;
  t.georef_ = grid.georef;
  t.metrics_ = cell_metrics(grid.georef, grid.cols, grid.rows);
  t.bathymetry_ = grid.bathymetry;
  t.frame_ = true;
  t.in_c1_ = grid.cols, t.in_r1_ = grid.rows;
  t.set_cell_sizes();
  return t;
}

void TerrainField::set_cell_sizes() {
  // The grid's cell sizes, whatever part of it is held, so that a window prices as the grid does.
  double lo = 1e300;
  for (int r = 0; r < grid_rows_; ++r) lo = std::min({lo, metrics_.width_m[r], metrics_.height_m[r]});
  min_cell_m_ = lo;
  typical_cell_m_ = 0.5 * (metrics_.width_m[grid_rows_ / 2] + metrics_.height_m[grid_rows_ / 2]);
}

void TerrainField::build(const Dem& dem, double unknown_depth_m, double road_radius_m, const Raster<std::uint8_t>* inland_water) {
  in_c0_ = col0_, in_r0_ = row0_, in_c1_ = col_end_, in_r1_ = row_end_;
  const double sea_level_m = sea_level_;
  const std::size_t n = dem.size();
  surface_.resize(n);
  ground_.resize(n);
  depth_.assign(n, 0.f);
  water_.assign(n, 0);
  std::vector<float> raw_depth(n, 0.f);
  for (std::size_t i = 0; i < n; ++i) {
    const bool nodata = dem.is_nodata(i);
    if (nodata || dem[i] <= sea_level_m) {
      water_[i] = 1;
      const double d = (!nodata && bathymetry_) ? sea_level_m - dem[i] : std::max(unknown_depth_m, nodata ? 0.0 : sea_level_m - dem[i]);
      raw_depth[i] = float(d);
      surface_[i] = float(sea_level_m);
      ground_[i] = float(sea_level_m - d);
    } else if (inland_water && (*inland_water)[i]) {
      // A lake the DEM shows as its level: the surface is the water level, its depth unknown.
      water_[i] = 1;
      raw_depth[i] = float(unknown_depth_m);
      surface_[i] = dem[i];
      ground_[i] = float(dem[i] - unknown_depth_m);
    } else {
      surface_[i] = dem[i];
      ground_[i] = dem[i];
    }
  }
  set_cell_sizes();
  // Water within the road's radius (Peytavie §4.2.1: maximum depth over the disc Omega(p, r)).
  const int rad = int(std::floor(road_radius_m / min_cell_m_));
  if (rad <= 0) {
    depth_ = raw_depth;
  } else {
    for (int r = row0_; r < row_end_; ++r)
      for (int c = col0_; c < col_end_; ++c) {
        float m = 0;
        for (int dr = -rad; dr <= rad; ++dr)
          for (int dc = -rad; dc <= rad; ++dc) {
            if (!inside(c + dc, r + dr)) continue;
            if (std::hypot(dc * metrics_.width_m[r], dr * metrics_.height_m[r]) > road_radius_m) continue;
            m = std::max(m, raw_depth[index(c + dc, r + dr)]);
          }
        depth_[index(c, r)] = m;
      }
  }
  // 8-connected land components, labelled in scan order (deterministic).
  land_.assign(n, -1);
  std::int32_t next = 0;
  std::vector<std::size_t> stack;
  for (std::size_t s = 0; s < n; ++s) {
    if (water_[s] || land_[s] >= 0) continue;
    land_[s] = next;
    stack.push_back(s);
    while (!stack.empty()) {
      const std::size_t i = stack.back();
      stack.pop_back();
      const int c = col_of(i), r = row_of(i);
      for (int k = 0; k < 8; ++k) {
        const int cc = c + dcol[k], rr = r + drow[k];
        if (!inside(cc, rr)) continue;
        const std::size_t j = index(cc, rr);
        if (water_[j] || land_[j] >= 0) continue;
        land_[j] = next;
        stack.push_back(j);
      }
    }
    ++next;
  }
}

namespace {
/// Bilinear at (col, row) of the window whose first cell is (col0, row0), clamped to it.
template <class V>
double bilinear(const V& v, int cols, int rows, int col0, int row0, double col, double row) {
  col = std::clamp(col - col0, 0.0, double(cols - 1));
  row = std::clamp(row - row0, 0.0, double(rows - 1));
  const int c0 = std::min(int(col), cols - 2 < 0 ? 0 : cols - 2), r0 = std::min(int(row), rows - 2 < 0 ? 0 : rows - 2);
  const double fc = col - c0, fr = row - r0;
  const std::size_t i = std::size_t(r0) * std::size_t(cols) + std::size_t(c0);
  const double a = v[i], b = v[i + 1], c = v[i + cols], d = v[i + cols + 1];
  return (a * (1 - fc) + b * fc) * (1 - fr) + (c * (1 - fc) + d * fc) * fr;
}
}  // namespace

double TerrainField::surface_at(double col, double row) const { return bilinear(surface_, cols_, rows_, col0_, row0_, col, row); }
double TerrainField::ground_at(double col, double row) const { return bilinear(ground_, cols_, rows_, col0_, row0_, col, row); }

void TerrainField::set_vegetation(const Raster<float>& density) {
  if (density.cols() != cols_ || density.rows() != rows_) throw bad_input("vegetation layer: not on the DEM's grid");
  vegetation_.resize(density.size());
  for (std::size_t i = 0; i < density.size(); ++i) vegetation_[i] = std::isnan(density[i]) ? 0.f : density[i];
}

void TerrainField::add_cost_layer(const std::string& name, const Raster<float>& kappa, const std::array<TransferFunction, 3>& transfer,
                                  const std::array<bool, 3>& priced) {
  if (kappa.cols() != cols_ || kappa.rows() != rows_) throw bad_input(name + ": cost layer not on the DEM's grid");
  for (int s = 0; s < 3; ++s) {
    if (!priced[std::size_t(s)]) continue;
    auto& v = extra_[std::size_t(s)];
    if (v.empty()) v.assign(size(), 0.f);
    const TransferFunction& mu = transfer[std::size_t(s)];
    for (std::size_t i = 0; i < v.size(); ++i) {
      const float k = kappa[i];
      if (std::isnan(k)) continue;
      v[i] = std::isinf(k) && k > 0 ? std::numeric_limits<float>::infinity() : float(double(v[i]) + mu(k));
    }
  }
}

float TerrainField::vegetation_at(double col, double row) const {
  if (vegetation_.empty()) return 0.f;
  return vegetation_[nearest_index(col, row)];
}

double TerrainField::metres_x(double row) const {
  const int r = std::clamp(nearest_cell(row), 0, grid_rows_ - 1);
  return metrics_.width_m[r];
}

double TerrainField::metres_y(double row) const {
  // height_m[r] spans rows r-1..r; take the boundary nearest to the position.
  const int r = std::clamp(nearest_cell(row + 0.5), 0, grid_rows_);
  return metrics_.height_m[r];
}

double TerrainField::length_m(GridPoint a, GridPoint b) const {
  const double mid = 0.5 * (a.row + b.row);
  return std::hypot((b.col - a.col) * metres_x(mid), (b.row - a.row) * metres_y(mid));
}

}  // namespace terrapolis::roads
