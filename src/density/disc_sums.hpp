// Sums over geodesic discs and rings around every cell at a cost independent of the radius.
// SPDX-License-Identifier: MIT
#pragma once
#include <cstddef>
#include <cstdint>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "core/geodesy.hpp"

namespace terrapolis::density {

/// Summed-area table (Crow 1984, "Summed-area tables for texture mapping") of a cols x rows grid:
/// at(y, x) is the sum of the cells of rows < y and columns < x, for y in 0..rows, x in 0..cols.
/// With T = uint32_t the arithmetic is modular and a rectangle sum is exact whenever the true sum
/// fits in 32 bits (counts of cells); with T = double it is exact for integer data up to 2^53.
/// Built in a fixed order, so the table does not depend on the thread count.
template <class T>
class SummedArea {
 public:
  SummedArea() = default;
  /// `value(i)` gives the value of cell i (row-major); called once per cell, possibly in parallel.
  template <class F>
  SummedArea(int cols, int rows, F value);
  int cols() const { return cols_; }
  int rows() const { return rows_; }
  const T* row(int y) const { return table_.data() + std::size_t(y) * std::size_t(stride()); }
  T at(int y, int x) const { return row(y)[x]; }

 private:
  std::size_t stride() const { return std::size_t(cols_) + 1; }
  int cols_ = 0, rows_ = 0;
  std::vector<T> table_;
};

/// A horizontal band of a disc: relative rows [row_lo, row_hi] (negative = north of the centre)
/// covered by columns [-half_cols, +half_cols] around the centre column.
struct Band {
  int row_lo = 0, row_hi = 0, half_cols = 0;
};

/// The shape of a disc of radius `radius_m` metres around a cell of each row, as a few bands.
///
/// Exact shape: cell (c+dc, r+dr) belongs to the disc of (c, r) when (dc * width_m[r+dr])² + dy² <=
/// radius², with dy the north-south distance between the two rows (sum of CellMetrics::height_m):
/// the local planar (equirectangular) approximation of the geodesic circle, whose error over a few
/// tens of kilometres is far below a cell. On a geographic grid a disc is thus wider in columns
/// than in rows and widens towards the poles; on a projected grid every row has the same shape.
///
/// When the disc spans at most `max_bands` rows each row is its own band (the shape is exact).
/// Otherwise consecutive rows are grouped into at most `max_bands` bands of equal angle
/// (dy = R sin(theta), theta in equal steps: thin bands where the chord changes fast), each band's
/// half-width being the rounded mean of its rows' exact half-widths (the band keeps the disc's area
/// to half a cell per row). The cells misassigned this way lie along the disc's rim; their number,
/// relative to the disc's cells, falls as 1/max_bands (measured in tests/density: under 2 % of the
/// disc with 16 bands, and the share of a ring made of two such discs errs by under 0.01).
class DiscPlan {
 public:
  DiscPlan() = default;
  DiscPlan(const CellMetrics& metrics, int rows, double radius_m, int max_bands);
  /// Bands of the disc centred on a cell of row `row` (relative rows may reach outside the grid).
  const std::vector<Band>& bands(int row) const { return per_row_[std::size_t(row)]; }
  /// Exact half-width in columns of the disc of a centre in row `row` at relative row `dr`, or -1
  /// when that row is outside the disc (the reference shape; used by tests and band planning).
  static int exact_half_cols(const CellMetrics& metrics, int rows, double radius_m, int row, int dr);
  /// True when every band is a single row (sums are exact).
  bool exact() const { return exact_; }
  /// Largest number of bands of any row.
  int band_count() const { return band_count_; }

 private:
  std::vector<std::vector<Band>> per_row_;
  bool exact_ = true;
  int band_count_ = 0;
};

/// Adds (sign = +1) or subtracts (sign = -1) to acc[c], for every column c of centre row `row`,
/// the sum of the table's cells in the disc of `plan`, clipped to the grid. O(cols x bands).
template <class T>
void add_disc_row(const SummedArea<T>& table, const DiscPlan& plan, int row, int sign, T* acc);

/// Sums of `values` (row-major, cols x rows) over the disc of every cell; the slow obvious
/// reference (O(cells x disc cells)) for tests, using DiscPlan::exact_half_cols.
std::vector<double> brute_force_disc_sums(const std::vector<double>& values, const CellMetrics& metrics, int cols,
                                          int rows, double radius_m);

// ---- implementation of the template constructor --------------------------------------------------

template <class T>
template <class F>
SummedArea<T>::SummedArea(int cols, int rows, F value)
    : cols_(cols), rows_(rows), table_((std::size_t(cols) + 1) * (std::size_t(rows) + 1), T{}) {
  const std::size_t s = stride();
  T* t = table_.data();
  // Row prefix sums (rows independent), then running sums down the columns (column blocks
  // independent): every entry is computed in one fixed order whatever the threads.
  tbb::parallel_for(tbb::blocked_range<int>(0, rows, 16), [&](const tbb::blocked_range<int>& range) {
    for (int y = range.begin(); y < range.end(); ++y) {
      T run{};
      T* out = t + std::size_t(y + 1) * s;
      const std::size_t base = std::size_t(y) * std::size_t(cols);
      for (int x = 0; x < cols; ++x) {
        run += T(value(base + std::size_t(x)));
        out[x + 1] = run;
      }
    }
  });
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, s, 512), [&](const tbb::blocked_range<std::size_t>& range) {
    for (int y = 1; y <= rows; ++y) {
      T* cur = t + std::size_t(y) * s;
      const T* prev = cur - s;
      for (std::size_t x = range.begin(); x < range.end(); ++x) cur[x] += prev[x];
    }
  });
}

}  // namespace terrapolis::density
