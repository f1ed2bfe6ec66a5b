// The terrain as the road search sees it: ground surface, water depth, metric cell sizes.
// SPDX-License-Identifier: MIT
#pragma once
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "core/geodesy.hpp"
#include "core/raster.hpp"
#include "roads/cost_model.hpp"

namespace terrapolis::roads {

/// std::lround for |x| < 2^31, inlined (x - trunc(x) is exact): the nearest cell to a position.
inline int nearest_cell(double x) {
  const double t = std::trunc(x), f = x - t;
  return int(t) + (f >= 0.5) - (f <= -0.5);
}

/// Positions are in cell units, (col, row) with integers at cell centres (row 0 north).
struct GridPoint {
  double col = 0, row = 0;
};

/// What a window of a grid needs from the whole grid to price its cells as the whole grid does:
/// the grid's georeferencing and size (cell metrics, sampling by position) and whether it carries
/// bathymetry (a rule over all its water cells; WaterCount).
struct TerrainGrid {
  Georef georef;
  int cols = 0, rows = 0;
  bool bathymetry = false;
};

/// The bathymetry rule's counts (TerrainField), summed over a grid's windows in any order.
struct WaterCount {
  std::size_t water = 0, deep = 0;  ///< cells at or below the sea level, and over 1 m below it
  void add(const Dem& window, double sea_level_m);
  bool bathymetry() const { return water > 0 && 2 * deep > water; }
};

class TerrainField;
/// The road terrain of a grid's cells [col0, col0 + cols) x [row0, row0 + rows) (TerrainField's
/// window constructor), with whatever the caller layers on it: how roads and their corridors read
/// a grid larger than memory.
using ReadTerrainWindow = std::function<TerrainField(int col0, int row0, int cols, int rows)>;

/// Ground and water of a DEM for the road search. Water cells are cells at or below the sea level
/// and nodata cells. Their depth is sea_level - elevation when the DEM carries bathymetry (more
/// than half of its water cells lie over 1 m below sea level, as in GEBCO), otherwise
/// `unknown_depth_m` (SRTM stores the sea as 0 m). Nodata cells get `unknown_depth_m`.
class TerrainField {
 public:
  /// `road_radius_m`: water depth is the maximum over the cells within that distance.
  /// `inland_water` (same grid, optional): non-zero cells are lakes above the sea level (a user's
  /// water layer or hydro::detect_flat_water), water `unknown_depth_m` deep under their DEM level.
  TerrainField(const Dem& dem, double sea_level_m, double unknown_depth_m, double road_radius_m,
               const Raster<std::uint8_t>* inland_water = nullptr);
  /// A window of a larger grid: `window` (and `inland_water`) hold its cells [col0, col0 + cols) x
  /// [row0, row0 + rows). Positions, cells and lengths stay the grid's (its georeferencing and cell
  /// metrics), so a road found in the window is the grid's road, bit for bit, wherever the window
  /// holds every cell the road's costs read (roads::route_by_windows). Cells near the window's edge
  /// see a truncated road radius.
  TerrainField(const Dem& window, int col0, int row0, const TerrainGrid& grid, double sea_level_m, double unknown_depth_m,
               double road_radius_m, const Raster<std::uint8_t>* inland_water = nullptr);

  /// The grid's frame alone: its cells, positions and metrics, no values (surface, water... are not
  /// held and must not be asked for). For what is drawn from roads found by windows (layers,
  /// sections, the cells roads share), in the grid's own cell indices.
  static TerrainField frame(const TerrainGrid& grid);
  bool holds_values() const { return !frame_; }

  /// The cells held: the window's size (the grid's for a whole grid) and its first cell.
  int cols() const { return cols_; }
  int rows() const { return rows_; }
  int col0() const { return col0_; }
  int row0() const { return row0_; }
  /// The whole grid's size.
  int grid_cols() const { return grid_cols_; }
  int grid_rows() const { return grid_rows_; }
  std::size_t size() const { return std::size_t(cols_) * std::size_t(rows_); }
  /// Whether the search may use a cell: held, and within the area set by restrict_search.
  bool inside(int col, int row) const { return col >= in_c0_ && row >= in_r0_ && col < in_c1_ && row < in_r1_; }
  /// Limits inside() to the cells [col0, col_end) x [row0, row_end) of those held: a window's
  /// margin then only feeds the costs (water depth within the road radius, bilinear heights) of
  /// the cells within, which the search uses alone, so every cost it reads is the grid's.
  void restrict_search(int col0, int row0, int col_end, int row_end) {
    in_c0_ = std::max(col0, col0_), in_r0_ = std::max(row0, row0_), in_c1_ = std::min(col_end, col_end_), in_r1_ = std::min(row_end, row_end_);
  }
  /// Index of a held cell (row-major over the window: the order of the grid's own indices).
  std::size_t index(int col, int row) const { return std::size_t(row) * std::size_t(cols_) + std::size_t(col) - origin_; }
  int col_of(std::size_t index) const { return col0_ + int(index % std::size_t(cols_)); }
  int row_of(std::size_t index) const { return row0_ + int(index / std::size_t(cols_)); }
  int clamp_col(int col) const { return std::clamp(col, col0_, col_end_ - 1); }
  int clamp_row(int row) const { return std::clamp(row, row0_, row_end_ - 1); }
  /// Index of the cell nearest to a position, clamped to the cells held.
  std::size_t nearest_index(double col, double row) const { return index(clamp_col(nearest_cell(col)), clamp_row(nearest_cell(row))); }

  /// Ground or water surface height (m) at a cell: max(elevation, sea level); sea level on nodata.
  float surface(int col, int row) const { return surface_[index(col, row)]; }
  /// Terrain height (m) at a cell, the sea floor under water (for tunnels); sea level - depth on nodata.
  float ground(int col, int row) const { return ground_[index(col, row)]; }
  /// Bilinear surface height (m) at a fractional position, clamped to the cells held.
  double surface_at(double col, double row) const;
  /// Bilinear terrain height (m) (sea floor under water).
  double ground_at(double col, double row) const;
  /// Water depth (m) at the nearest cell, the maximum within the road radius; 0 on land.
  float depth_at(double col, double row) const {
    return depth_[nearest_index(col, row)];
  }
  /// Sets the vegetation / land-cover density layer (the cells held; NaN counts as 0).
  void set_vegetation(const Raster<float>& density);
  /// Vegetation density at the nearest cell (0 without a layer).
  float vegetation_at(double col, double row) const;
  bool has_vegetation() const { return !vegetation_.empty(); }
  /// Adds a per-metre cost term (e.g. from a plugin): a characteristic kappa per cell (same grid
  /// as the DEM) priced by one transfer function per structure (road, bridge, tunnel). The terms'
  /// costs are summed per cell once here. NaN kappa costs nothing; +infinity kappa forbids the
  /// cell to every structure whose function is given (`priced[s]`); unpriced structures pay nothing.
  void add_cost_layer(const std::string& name, const Raster<float>& kappa, const std::array<TransferFunction, 3>& transfer,
                      const std::array<bool, 3>& priced);
  /// Sum of the added terms' costs per metre (>= 0, +infinity where forbidden) at the nearest cell
  /// for structure `s`; 0 without terms.
  float extra_cost_at(Structure s, double col, double row) const {
    const auto& v = extra_[int(s)];
    if (v.empty()) return 0.f;
    return v[nearest_index(col, row)];
  }
  bool water(int col, int row) const { return water_[index(col, row)] != 0; }
  bool has_bathymetry() const { return bathymetry_; }
  double sea_level() const { return sea_level_; }

  /// Metres per cell east-west and north-south at a (fractional) row (CellMetrics, geodesic on
  /// geographic CRSs); arcs use them as a local plane, exact on projected grids and within
  /// (length / Earth radius)^2 on geographic ones.
  double metres_x(double row) const;
  double metres_y(double row) const;
  /// Length in metres of the straight segment a -> b.
  double length_m(GridPoint a, GridPoint b) const;
  /// Smallest cell side over the grid (m).
  double min_cell_m() const { return min_cell_m_; }
  /// Cell side at the centre row (m), the scale of "cells" in the cost model.
  double typical_cell_m() const { return typical_cell_m_; }

  /// Land component label (8-connected land cells held), or -1 on water. Two points on different
  /// labels cannot be joined by a road on the ground (maritime links) within the cells held.
  const std::vector<std::int32_t>& land_components() const { return land_; }

  const Georef& georef() const { return georef_; }
  const CellMetrics& metrics() const { return metrics_; }

 private:
  TerrainField() = default;
  void build(const Dem& dem, double unknown_depth_m, double road_radius_m, const Raster<std::uint8_t>* inland_water);
  void set_cell_sizes();
  bool frame_ = false;
  int cols_ = 0, rows_ = 0, col0_ = 0, row0_ = 0, col_end_ = 0, row_end_ = 0, grid_cols_ = 0, grid_rows_ = 0;
  int in_c0_ = 0, in_r0_ = 0, in_c1_ = 0, in_r1_ = 0;  ///< where inside() holds (restrict_search; the cells held by default)
  std::size_t origin_ = 0;  ///< index(col0, row0) before the window's offset: row0 * cols + col0
  Georef georef_;
  CellMetrics metrics_;
  double sea_level_ = 0;
  bool bathymetry_ = false;
  double min_cell_m_ = 1, typical_cell_m_ = 1;
  std::vector<float> surface_, ground_, depth_, vegetation_;
  std::array<std::vector<float>, 3> extra_;  // summed cost layers per structure (empty: none)
  std::vector<std::uint8_t> water_;
  std::vector<std::int32_t> land_;
};

}  // namespace terrapolis::roads
