// SPDX-License-Identifier: MIT
#include "generate/river_checks.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>

#include "core/neighbours.hpp"

namespace terrapolis::generate {
namespace {

/// Antilog of the least-squares slope of log10(y) over x = 1, 2, ...
double log_slope_ratio(const std::vector<double>& y) {
  const double n = double(y.size());
  double mx = 0, my = 0;
  for (std::size_t i = 0; i < y.size(); ++i) mx += double(i + 1) / n, my += std::log10(y[i]) / n;
  double sxy = 0, sxx = 0;
  for (std::size_t i = 0; i < y.size(); ++i) {
    const double dx = double(i + 1) - mx;
    sxy += dx * (std::log10(y[i]) - my);
    sxx += dx * dx;
  }
  return std::pow(10.0, sxy / sxx);
}

int nearest(double v) { return int(std::lround(v)); }

}  // namespace

HortonRatios horton_ratios(const RiverRidgePlan& plan, double cell_m) {
  const auto& rivers = plan.rivers;
  std::vector<char> continues(rivers.size(), 0);  // an inflow of the same order continues into it
  int top = 0;
  for (const auto& r : rivers) {
    top = std::max(top, r.strahler);
    if (r.downstream >= 0 && rivers[std::size_t(r.downstream)].strahler == r.strahler) continues[std::size_t(r.downstream)] = 1;
  }
  HortonRatios h;
  h.streams.assign(std::size_t(top), 0);
  std::vector<double> total(std::size_t(top), 0.0);
  for (std::size_t i = 0; i < rivers.size(); ++i) {
    if (continues[i]) continue;  // not the start of a stream
    const int order = rivers[i].strahler;
    double length = 0;
    for (int j = int(i); j >= 0 && rivers[std::size_t(j)].strahler == order; j = rivers[std::size_t(j)].downstream)
      length += line_length_m(rivers[std::size_t(j)].line, cell_m);
    ++h.streams[std::size_t(order - 1)];
    total[std::size_t(order - 1)] += length;
  }
  for (std::size_t w = 0; w < total.size(); ++w) h.mean_length_m.push_back(h.streams[w] ? total[w] / h.streams[w] : 0.0);
  const bool complete = top >= 2 && std::all_of(h.streams.begin(), h.streams.end(), [](int n) { return n > 0; });
  if (complete) {
    h.bifurcation = 1.0 / log_slope_ratio(std::vector<double>(h.streams.begin(), h.streams.end()));
    h.length = log_slope_ratio(h.mean_length_m);
  }
  return h;
}

D8Consistency d8_consistency(const RiverRidgePlan& plan, const Raster<std::uint8_t>& stream_order, const Raster<float>& dem,
                             double cell_m, double radius_cells, std::optional<double> sea_level_m) {
  std::vector<std::array<int, 2>> disc;
  const int reach = int(std::ceil(radius_cells));
  for (int dr = -reach; dr <= reach; ++dr)
    for (int dc = -reach; dc <= reach; ++dc)
      if (dc * dc + dr * dr <= radius_cells * radius_cells + 1e-9) disc.push_back({dc, dr});
  auto matches = [&](double x, double y, int order) {
    const int c = nearest(x), r = nearest(y);
    for (const auto& d : disc) {
      if (!stream_order.inside(c + d[0], r + d[1])) continue;
      const int o = stream_order(c + d[0], r + d[1]);
      if (o > 0 && std::abs(o - order) <= 1) return true;
    }
    return false;
  };
  auto is_outlet_side = [&](int c, int r) {  // a neighbour (or the cell) off the grid, nodata or sea
    for (int k = -1; k < 8; ++k) {
      const int nc = c + (k < 0 ? 0 : dcol[std::size_t(k)]), nr = r + (k < 0 ? 0 : drow[std::size_t(k)]);
      if (!dem.inside(nc, nr)) return true;
      const float z = dem(nc, nr);
      if (!std::isfinite(z) || (sea_level_m && z <= *sea_level_m)) return true;
    }
    return false;
  };
  D8Consistency out;
  for (const auto& river : plan.rivers) {
    for (std::size_t i = 1; i < river.line.size(); ++i) {
      const auto& a = river.line[i - 1];
      const auto& b = river.line[i];
      const double cells = std::hypot(b[0] - a[0], b[1] - a[1]);
      const int steps = std::max(1, int(std::ceil(cells * 2)));  // samples at most half a cell apart
      for (int s = 0; s < steps; ++s) {
        const double t = (s + 0.5) / steps;
        const double m = cells / steps * cell_m;
        out.river_length_m += m;
        if (matches(a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]), river.strahler)) out.matched_length_m += m;
      }
    }
    if (river.downstream < 0 && !river.line.empty()) {
      ++out.mouths;
      if (!is_outlet_side(nearest(river.line.back()[0]), nearest(river.line.back()[1]))) ++out.ending_in_pit;
    }
  }
  return out;
}

Raster<std::uint8_t> stream_order_raster(const VectorLayer& streams, const Georef& georef, int cols, int rows) {
  Raster<std::uint8_t> order(cols, rows, georef, 0);
  const int field = streams.field_index("strahler");
  if (field < 0) return order;
  const auto& gt = georef.transform;
  for (const auto& f : streams.features) {
    const auto* o = std::get_if<std::int64_t>(&f.values[std::size_t(field)]);
    if (!o || f.parts.empty()) continue;
    for (const auto& p : f.parts[0]) {
      const int c = nearest((p[0] - gt[0]) / gt[1] - 0.5), r = nearest((p[1] - gt[3]) / gt[5] - 0.5);
      if (order.inside(c, r)) order(c, r) = std::max<std::uint8_t>(order(c, r), std::uint8_t(std::min<std::int64_t>(*o, 255)));
    }
  }
  return order;
}

double channel_head_threshold_m2(const RiverRidgePlan& plan, const Raster<double>& area_m2) {
  std::vector<char> fed(plan.rivers.size(), 0);
  for (const auto& r : plan.rivers)
    if (r.downstream >= 0) fed[std::size_t(r.downstream)] = 1;
  std::vector<double> heads;
  for (std::size_t i = 0; i < plan.rivers.size(); ++i) {
    if (fed[i] || plan.rivers[i].line.empty()) continue;
    const int c = nearest(plan.rivers[i].line.front()[0]), r = nearest(plan.rivers[i].line.front()[1]);
    if (area_m2.inside(c, r) && std::isfinite(area_m2(c, r))) heads.push_back(area_m2(c, r));
  }
  if (heads.empty()) return 1.0;
  std::nth_element(heads.begin(), heads.begin() + std::ptrdiff_t(heads.size() / 2), heads.end());
  return std::max(1.0, heads[heads.size() / 2]);
}

double drainage_density(const RiverRidgePlan& plan, const Raster<float>& dem, double cell_m, std::optional<double> sea_level_m) {
  double length_m = 0;
  for (const auto& r : plan.rivers) length_m += line_length_m(r.line, cell_m);
  std::size_t land = 0;
  for (std::size_t i = 0; i < dem.size(); ++i) land += std::isfinite(dem[i]) && !(sea_level_m && dem[i] <= *sea_level_m) ? 1 : 0;
  return land ? (length_m / 1000.0) / (double(land) * cell_m * cell_m / 1e6) : 0.0;
}

}  // namespace terrapolis::generate
