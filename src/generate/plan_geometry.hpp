// Plane geometry of the skeleton generators: points in plan metres, segment distances, a bin index
// for neighbourhood queries, uniform draws.
// SPDX-License-Identifier: MIT
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "core/random.hpp"

namespace terrapolis::generate {

/// Plan coordinates in metres from the grid's north-west corner: x east, y south (as rows grow).
struct Point2 {
  double x = 0, y = 0;
};
inline Point2 operator+(Point2 a, Point2 b) { return {a.x + b.x, a.y + b.y}; }
inline Point2 operator-(Point2 a, Point2 b) { return {a.x - b.x, a.y - b.y}; }
inline Point2 operator*(double s, Point2 a) { return {s * a.x, s * a.y}; }
inline double dot(Point2 a, Point2 b) { return a.x * b.x + a.y * b.y; }
inline double norm(Point2 a) { return std::hypot(a.x, a.y); }

/// Parameter t in [0,1] of the point of segment [a,b] nearest to p.
inline double segment_parameter(Point2 p, Point2 a, Point2 b) {
  const Point2 ab = b - a;
  const double l2 = dot(ab, ab);
  return l2 > 0 ? std::clamp(dot(p - a, ab) / l2, 0.0, 1.0) : 0.0;
}
inline double point_segment_distance(Point2 p, Point2 a, Point2 b) {
  return norm(p - (a + segment_parameter(p, a, b) * (b - a)));
}
/// Distance between segments [a,b] and [c,d] (0 when they cross).
inline double segment_segment_distance(Point2 a, Point2 b, Point2 c, Point2 d) {
  const auto cross = [](Point2 u, Point2 v) { return u.x * v.y - u.y * v.x; };
  const double d1 = cross(b - a, c - a), d2 = cross(b - a, d - a), d3 = cross(d - c, a - c), d4 = cross(d - c, b - c);
  if (((d1 > 0) != (d2 > 0)) && ((d3 > 0) != (d4 > 0)) && d1 != 0 && d2 != 0 && d3 != 0 && d4 != 0) return 0;
  return std::min({point_segment_distance(a, c, d), point_segment_distance(b, c, d), point_segment_distance(c, a, b),
                   point_segment_distance(d, a, b)});
}

/// Square bins of items by bounding box: a query visits every item whose box meets the query box
/// (an item spanning several bins may be visited more than once; callers take minima or "any").
class SpatialBins {
 public:
  SpatialBins(double width, double height, double bin) : bin_(bin) {
    cols_ = std::max(1, int(std::ceil(width / bin)) + 1);
    rows_ = std::max(1, int(std::ceil(height / bin)) + 1);
    bins_.resize(std::size_t(cols_) * rows_);
  }
  void insert(int id, double x0, double y0, double x1, double y1) {
    for_bins(x0, y0, x1, y1, [&](std::vector<int>& b) { b.push_back(id); });
  }
  template <class F>
  void visit(double x0, double y0, double x1, double y1, F&& f) const {
    const_cast<SpatialBins*>(this)->for_bins(x0, y0, x1, y1, [&](const std::vector<int>& b) {
      for (int id : b) f(id);
    });
  }
  double bin() const { return bin_; }

 private:
  template <class F>
  void for_bins(double x0, double y0, double x1, double y1, F&& f) {
    const int c0 = clamp_col(x0), c1 = clamp_col(x1), r0 = clamp_row(y0), r1 = clamp_row(y1);
    for (int r = r0; r <= r1; ++r)
      for (int c = c0; c <= c1; ++c) f(bins_[std::size_t(r) * cols_ + c]);
  }
  int clamp_col(double x) const { return std::clamp(int(std::floor(x / bin_)), 0, cols_ - 1); }
  int clamp_row(double y) const { return std::clamp(int(std::floor(y / bin_)), 0, rows_ - 1); }
  double bin_;
  int cols_ = 1, rows_ = 1;
  std::vector<std::vector<int>> bins_;
};

/// Draws of the generators from the shared portable Rng (random.hpp).
inline double between(Rng& rng, double lo, double hi) { return lo + (hi - lo) * rng.uniform(); }
inline int integer(Rng& rng, int lo, int hi) { return lo + int(rng.uniform() * (hi - lo + 1)); }  ///< [lo,hi]

}  // namespace terrapolis::generate
