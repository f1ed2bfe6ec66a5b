// Disc shapes in geodesic metres as bands of rows, and their sums through summed-area tables.
// SPDX-License-Identifier: MIT
#include "density/disc_sums.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace terrapolis::density {
namespace {

/// North-south position (metres, growing southwards) and cell width of rows, extended past the grid
/// edges with the edge rows' metrics so that discs near an edge keep their shape (cells there are
/// clipped anyway).
class RowGeometry {
 public:
  RowGeometry(const CellMetrics& m, int rows, int margin) : rows_(rows), margin_(margin), y_(std::size_t(rows + 2 * margin)) {
    // y_[i] is row t = i - margin; height_m[b] is the distance between rows b-1 and b (b in 0..rows).
    auto height = [&](int b) { return m.height_m[std::size_t(std::clamp(b, 0, rows))]; };
    const int origin = margin;
    y_[std::size_t(origin)] = 0.0;
    for (int t = 1; t < rows + margin; ++t) y_[std::size_t(origin + t)] = y_[std::size_t(origin + t - 1)] + height(t);
    for (int t = -1; t >= -margin; --t) y_[std::size_t(origin + t)] = y_[std::size_t(origin + t + 1)] - height(t + 1);
    width_ = &m.width_m;
  }
  double y(int t) const { return y_[std::size_t(t + margin_)]; }
  double width(int t) const { return (*width_)[std::size_t(std::clamp(t, 0, rows_ - 1))]; }
  bool covers(int t) const { return t >= -margin_ && t < rows_ + margin_; }

 private:
  int rows_, margin_;
  std::vector<double> y_;
  const std::vector<double>* width_ = nullptr;
};

/// Rows a disc of radius_m can reach on either side, at most.
int max_reach_rows(const CellMetrics& m, double radius_m) {
  const double min_height = *std::min_element(m.height_m.begin(), m.height_m.end());
  return int(std::ceil(radius_m / min_height)) + 1;
}

/// Half-width in columns of the disc row at relative row dr, -1 outside the disc.
int half_cols(const RowGeometry& g, double radius_m, int row, int dr) {
  const double dy = g.y(row + dr) - g.y(row);
  const double rest = radius_m * radius_m - dy * dy;
  if (rest < 0) return -1;
  return int(std::floor(std::sqrt(rest) / g.width(row + dr)));
}

}  // namespace

int DiscPlan::exact_half_cols(const CellMetrics& metrics, int rows, double radius_m, int row, int dr) {
  const RowGeometry g(metrics, rows, std::abs(dr) + 1);
  return half_cols(g, radius_m, row, dr);
}

DiscPlan::DiscPlan(const CellMetrics& metrics, int rows, double radius_m, int max_bands) {
  const int reach = max_reach_rows(metrics, radius_m);
  const RowGeometry g(metrics, rows, reach + 1);
  const int bands_wanted = std::max(1, max_bands);
  // A projected grid has the same metrics on every row: plan once.
  const bool uniform = std::all_of(metrics.width_m.begin(), metrics.width_m.end(), [&](double w) { return w == metrics.width_m[0]; }) &&
                       std::all_of(metrics.height_m.begin(), metrics.height_m.end(), [&](double h) { return h == metrics.height_m[0]; });
  per_row_ = std::make_shared<std::vector<std::vector<Band>>>(std::size_t(rows));
  std::vector<std::vector<Band>>& per_row = *per_row_;
  auto plan_row = [&](int row) {
    int north = 0, south = 0;
    while (north < reach && half_cols(g, radius_m, row, -(north + 1)) >= 0) ++north;
    while (south < reach && half_cols(g, radius_m, row, south + 1) >= 0) ++south;
    const int count = north + south + 1;
    std::vector<int> widths(static_cast<std::size_t>(count));
    for (int dr = -north; dr <= south; ++dr) widths[std::size_t(dr + north)] = half_cols(g, radius_m, row, dr);
    std::vector<Band>& bands = per_row[std::size_t(row)];
    if (count <= bands_wanted) {
      for (int dr = -north; dr <= south; ++dr) bands.push_back({dr, dr, widths[std::size_t(dr + north)]});
      return;
    }
    // Equal-angle bands: theta = asin(dy / R) cut into bands_wanted equal steps over [-pi/2, pi/2].
    auto band_of = [&](int dr) {
      const double s = std::clamp((g.y(row + dr) - g.y(row)) / radius_m, -1.0, 1.0);
      const double theta = std::asin(s) + std::numbers::pi / 2;
      return std::min(bands_wanted - 1, int(theta / std::numbers::pi * bands_wanted));
    };
    int start = -north;
    while (start <= south) {
      const int id = band_of(start);
      int end = start;
      double sum = 0;
      while (end <= south && band_of(end) == id) sum += widths[std::size_t(end + north)], ++end;
      bands.push_back({start, end - 1, int(std::lround(sum / double(end - start)))});
      start = end;
    }
  };
  if (uniform) {
    if (rows > 0) plan_row(0);
    for (int row = 1; row < rows; ++row) per_row[std::size_t(row)] = per_row[0];
  } else {
    // Rows are planned independently (geographic grids: one plan per latitude).
    tbb::parallel_for(tbb::blocked_range<int>(0, rows, 16), [&](const tbb::blocked_range<int>& range) {
      for (int row = range.begin(); row < range.end(); ++row) plan_row(row);
    });
  }
  for (const std::vector<Band>& bands : per_row) {
    double cells = 0;
    bool single_rows = true;
    for (const Band& b : bands) {
      cells += double(b.row_hi - b.row_lo + 1) * double(2 * b.half_cols + 1);
      reach_rows_ = std::max({reach_rows_, -b.row_lo, b.row_hi});
      reach_cols_ = std::max(reach_cols_, b.half_cols);
      single_rows = single_rows && b.row_lo == b.row_hi;
    }
    exact_ = exact_ && single_rows;
    band_count_ = std::max(band_count_, int(bands.size()));
    max_cells_ = std::max(max_cells_, cells);
  }
}

namespace {

template <class T, bool Add>
void disc_row(const SummedArea<T>& table, const DiscPlan& plan, int row, T* acc, int c_begin, int c_end) {
  const Window& win = table.window();
  const int cols = table.cols(), rows = table.rows();
  for (const Band& b : plan.bands(row)) {
    const int y0 = std::clamp(row - win.y0 + b.row_lo, 0, rows), y1 = std::clamp(row - win.y0 + b.row_hi + 1, 0, rows);
    if (y1 <= y0) continue;
    const T* a0 = table.row(y0);
    const T* a1 = table.row(y1);
    const int w = b.half_cols;
    auto rect = [&](int x0, int x1) { return T((a1[x1] - a1[x0]) - (a0[x1] - a0[x0])); };
    // Work in window columns: acc is shifted so that acc_w[cw] is acc[cw + win.x0].
    T* acc_w = acc + win.x0;
    auto put = [&](int c, T v) {
      if constexpr (Add) acc_w[c] += v;
      else acc_w[c] -= v;
    };
    const int cb = c_begin - win.x0, ce = c_end - win.x0;
    // Columns whose window [c-w, c+w] lies inside the table run without clamping (vectorised).
    const int left = std::clamp(w, cb, ce);
    const int right = std::clamp(cols - w, left, ce);
    for (int c = cb; c < left; ++c) put(c, rect(std::clamp(c - w, 0, cols), std::clamp(c + w + 1, 0, cols)));
    for (int c = left; c < right; ++c) put(c, T((a1[c + w + 1] - a1[c - w]) - (a0[c + w + 1] - a0[c - w])));
    for (int c = right; c < ce; ++c) put(c, rect(std::clamp(c - w, 0, cols), std::clamp(c + w + 1, 0, cols)));
  }
}

}  // namespace

template <class T>
void add_disc_row(const SummedArea<T>& table, const DiscPlan& plan, int row, int sign, T* acc, int c_begin, int c_end) {
  if (sign >= 0) disc_row<T, true>(table, plan, row, acc, c_begin, c_end);
  else disc_row<T, false>(table, plan, row, acc, c_begin, c_end);
}

template void add_disc_row<std::uint32_t>(const SummedArea<std::uint32_t>&, const DiscPlan&, int, int, std::uint32_t*, int, int);
template void add_disc_row<double>(const SummedArea<double>&, const DiscPlan&, int, int, double*, int, int);

void add_disc_count_row(const DiscPlan& plan, int cols, int rows, int row, int sign, std::uint32_t* acc, int c_begin,
                        int c_end) {
  for (const Band& b : plan.bands(row)) {
    const int y0 = std::clamp(row + b.row_lo, 0, rows), y1 = std::clamp(row + b.row_hi + 1, 0, rows);
    if (y1 <= y0) continue;
    const auto h = std::uint32_t(y1 - y0);
    const int w = b.half_cols;
    for (int c = c_begin; c < c_end; ++c) {
      const auto n = h * std::uint32_t(std::min(c + w + 1, cols) - std::max(c - w, 0));
      acc[c] += sign >= 0 ? n : std::uint32_t(0) - n;
    }
  }
}

std::vector<double> brute_force_disc_sums(const std::vector<double>& values, const CellMetrics& metrics, int cols,
                                          int rows, double radius_m) {
  const RowGeometry g(metrics, rows, 1);
  std::vector<double> out(values.size(), 0.0);
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) {
      double sum = 0;
      for (int t = 0; t < rows; ++t) {
        const double dy = g.y(t) - g.y(r);
        for (int x = 0; x < cols; ++x) {
          const double dx = double(x - c) * g.width(t);
          if (dx * dx + dy * dy <= radius_m * radius_m) sum += values[std::size_t(t) * std::size_t(cols) + std::size_t(x)];
        }
      }
      out[std::size_t(r) * std::size_t(cols) + std::size_t(c)] = sum;
    }
  return out;
}

}  // namespace terrapolis::density
