// The one georeferenced grid type: values, geotransform, CRS and nodata, row 0 at the north.
// SPDX-License-Identifier: MIT
#pragma once
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace terrapolis {

/// GDAL's affine geotransform: x = gt[0] + col*gt[1] + row*gt[2], y = gt[3] + col*gt[4] + row*gt[5],
/// where (col,row) is a pixel *corner* position (pixels are areas; the centre of cell (c,r) is c+0.5, r+0.5).
using GeoTransform = std::array<double, 6>;

/// The ellipsoid a CRS is built on, in metres.
struct Ellipsoid {
  double semi_major_m = 6378137.0;
  double inverse_flattening = 298.257223563;  ///< 0 for a sphere
  double flattening() const { return inverse_flattening == 0 ? 0.0 : 1.0 / inverse_flattening; }
};

/// A coordinate reference system as GDAL knows it, reduced to what the algorithms need.
struct Crs {
  std::string wkt;                   ///< WKT2 (empty only for an explicitly unreferenced grid)
  std::optional<int> epsg;           ///< EPSG code when the CRS carries one
  std::string name;                  ///< human-readable name, e.g. "WGS 84"
  bool geographic = false;           ///< axes are longitude/latitude in degrees
  double linear_unit_m = 1.0;        ///< projected CRSs: metres per CRS unit
  Ellipsoid ellipsoid;               ///< the datum's ellipsoid
  bool empty() const { return wkt.empty(); }
};

/// Where a grid sits on the Earth.
struct Georef {
  GeoTransform transform{0, 1, 0, 0, 0, -1};
  Crs crs;
  /// CRS coordinates of the centre of cell (col,row).
  std::array<double, 2> cell_centre(double col, double row) const {
    const double c = col + 0.5, r = row + 0.5;
    return {transform[0] + c * transform[1] + r * transform[2], transform[3] + c * transform[4] + r * transform[5]};
  }
  /// The georeferencing of a window of the grid whose first cell is (col0, row0).
  Georef window(int col0, int row0) const {
    Georef g = *this;
    g.transform[0] = transform[0] + col0 * transform[1] + row0 * transform[2];
    g.transform[3] = transform[3] + col0 * transform[4] + row0 * transform[5];
    return g;
  }
};

/// A 2-D grid of values with its georeferencing. Float rasters hold nodata as NaN in memory;
/// other types carry an explicit `nodata` value (or none).
template <class T>
class Raster {
 public:
  Raster() = default;
  Raster(int cols, int rows, Georef georef, T fill = T{})
      : cols_(cols), rows_(rows), georef_(std::move(georef)), values_(std::size_t(cols) * std::size_t(rows), fill) {}

  /// A new raster on the same grid and georeferencing, filled with `fill`.
  template <class U>
  Raster<U> like(U fill = U{}) const { return Raster<U>(cols_, rows_, georef_, fill); }

  int cols() const { return cols_; }
  int rows() const { return rows_; }
  std::size_t size() const { return values_.size(); }
  std::size_t index(int col, int row) const { return std::size_t(row) * std::size_t(cols_) + std::size_t(col); }
  bool inside(int col, int row) const { return col >= 0 && row >= 0 && col < cols_ && row < rows_; }

  T& operator()(int col, int row) { return values_[index(col, row)]; }
  const T& operator()(int col, int row) const { return values_[index(col, row)]; }
  T& operator[](std::size_t i) { return values_[i]; }
  const T& operator[](std::size_t i) const { return values_[i]; }
  T* data() { return values_.data(); }
  const T* data() const { return values_.data(); }
  std::vector<T>& values() { return values_; }
  const std::vector<T>& values() const { return values_; }

  const Georef& georef() const { return georef_; }
  Georef& georef() { return georef_; }

  /// Nodata value written to files for non-float types (floats use NaN).
  std::optional<double> nodata;

  bool is_nodata(std::size_t i) const {
    if constexpr (std::is_floating_point_v<T>) {
      return std::isnan(values_[i]);
    } else {
      return nodata && double(values_[i]) == *nodata;
    }
  }

 private:
  int cols_ = 0, rows_ = 0;
  Georef georef_;
  std::vector<T> values_;
};

/// An elevation model: metres above the vertical datum, NaN where there is no data.
using Dem = Raster<float>;

}  // namespace terrapolis
