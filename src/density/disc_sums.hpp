// Sums over geodesic discs and rings around every cell at a cost independent of the radius.
// SPDX-License-Identifier: MIT
#pragma once
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "core/geodesy.hpp"

namespace terrapolis::density {

/// A rectangle of a grid: columns [x0, x0 + cols), rows [y0, y0 + rows).
struct Window {
  int x0 = 0, y0 = 0, cols = 0, rows = 0;
};

/// Summed-area table (Crow 1984, "Summed-area tables for texture mapping") of a window of a grid:
/// at(y, x) is the sum of the window's cells of rows < y and columns < x (window coordinates), for y
/// in 0..rows, x in 0..cols. With T = uint32_t the arithmetic is modular and a rectangle sum is exact
/// whenever the true sum fits in 32 bits (counts of cells); with T = double it is exact for integer
/// data up to 2^53. Built in a fixed order, so the table does not depend on the thread count.
template <class T>
class SummedArea {
 public:
  SummedArea() = default;
  /// `value(i)` gives the value of cell i (row-major index in the whole grid of `grid_cols`
  /// columns); called once per cell of the window, possibly in parallel.
  template <class F>
  SummedArea(const Window& window, int grid_cols, F value);
  /// A table of a whole cols x rows grid.
  template <class F>
  SummedArea(int cols, int rows, F value) : SummedArea(Window{0, 0, cols, rows}, cols, value) {}
  int cols() const { return window_.cols; }
  int rows() const { return window_.rows; }
  const Window& window() const { return window_; }
  const T* row(int y) const { return table_.data() + std::size_t(y) * stride(); }
  T at(int y, int x) const { return row(y)[x]; }

 private:
  std::size_t stride() const { return std::size_t(window_.cols) + 1; }
  Window window_;
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
  const std::vector<Band>& bands(int row) const { return (*per_row_)[std::size_t(row + first_row_)]; }
  /// The same plan for a window of the grid whose row 0 is the grid's row `row0` (a tile with its
  /// halo): the window's rows get the grid's discs, planned from the grid's metrics. Shares the rows.
  DiscPlan from_row(int row0) const {
    DiscPlan p = *this;
    p.first_row_ += row0;
    return p;
  }
  /// Exact half-width in columns of the disc of a centre in row `row` at relative row `dr`, or -1
  /// when that row is outside the disc (the reference shape; used by tests and band planning).
  static int exact_half_cols(const CellMetrics& metrics, int rows, double radius_m, int row, int dr);
  /// True when every band is a single row (sums are exact).
  bool exact() const { return exact_; }
  /// Largest number of bands of any row.
  int band_count() const { return band_count_; }
  /// Largest number of cells of any row's (unclipped) disc.
  double max_cells() const { return max_cells_; }
  /// Largest reach of the disc, in rows (north or south) and in columns.
  int reach_rows() const { return reach_rows_; }
  int reach_cols() const { return reach_cols_; }

 private:
  std::shared_ptr<std::vector<std::vector<Band>>> per_row_;
  int first_row_ = 0;
  bool exact_ = true;
  int band_count_ = 0;
  double max_cells_ = 0;
  int reach_rows_ = 0, reach_cols_ = 0;
};

/// Adds (sign = +1) or subtracts (sign = -1) to acc[c], for every column c in [c_begin, c_end) of
/// centre row `row` (grid coordinates), the sum of the table's cells in the disc of `plan`, clipped
/// to the table's window (which must hold every grid cell of those discs for an unclipped sum).
/// O((c_end - c_begin) x bands), whatever the radius.
template <class T>
void add_disc_row(const SummedArea<T>& table, const DiscPlan& plan, int row, int sign, T* acc, int c_begin, int c_end);

/// Adds to acc[c], c in [c_begin, c_end), the number of grid cells in the disc of `plan` around
/// (c, row) (the disc clipped to a grid of `cols` x `rows`), by arithmetic alone.
void add_disc_count_row(const DiscPlan& plan, int cols, int rows, int row, int sign, std::uint32_t* acc, int c_begin,
                        int c_end);

/// Sums of `values` (row-major, cols x rows) over the disc of every cell; the slow obvious
/// reference (O(cells x disc cells)) for tests, using DiscPlan::exact_half_cols.
std::vector<double> brute_force_disc_sums(const std::vector<double>& values, const CellMetrics& metrics, int cols,
                                          int rows, double radius_m);

// ---- implementation of the template constructor --------------------------------------------------

template <class T>
template <class F>
SummedArea<T>::SummedArea(const Window& window, int grid_cols, F value)
    : window_(window), table_((std::size_t(window.cols) + 1) * (std::size_t(window.rows) + 1), T{}) {
  const std::size_t s = stride();
  T* t = table_.data();
  const int cols = window.cols;
  // Row prefix sums (rows independent), then running sums down the columns (column blocks
  // independent): every entry is computed in one fixed order whatever the threads.
  tbb::parallel_for(tbb::blocked_range<int>(0, window.rows, 16), [&](const tbb::blocked_range<int>& range) {
    for (int y = range.begin(); y < range.end(); ++y) {
      T run{};
      T* out = t + std::size_t(y + 1) * s;
      const std::size_t base = std::size_t(y + window.y0) * std::size_t(grid_cols) + std::size_t(window.x0);
      for (int x = 0; x < cols; ++x) {
        run += T(value(base + std::size_t(x)));
        out[x + 1] = run;
      }
    }
  });
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, s, 512), [&](const tbb::blocked_range<std::size_t>& range) {
    for (int y = 1; y <= window.rows; ++y) {
      T* cur = t + std::size_t(y) * s;
      const T* prev = cur - s;
      for (std::size_t x = range.begin(); x < range.end(); ++x) cur[x] += prev[x];
    }
  });
}

}  // namespace terrapolis::density
