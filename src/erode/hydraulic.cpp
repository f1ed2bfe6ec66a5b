// Hydraulic erosion by virtual pipes between the 4 neighbours of a cell (Mei, Decaudin & Hu 2007,
// "Fast hydraulic erosion simulation and visualization on GPU", Pacific Graphics, §3).
// SPDX-License-Identifier: MIT
#include <algorithm>
#include <cmath>

#include "erode/domain.hpp"

namespace terrapolis::erode {
namespace {

constexpr double g = 9.81;              // m/s²
constexpr int pipe_k[4] = {0, 2, 4, 6};  // pipes east, south, west, north as neighbours.hpp's k
constexpr int opposite_pipe(int p) { return (p + 2) & 3; }
constexpr double dry_m = 1e-6;           // shallower water has no speed (its velocity is 0/0)

/// North-south size of a cell of row r: the mean of the steps to its two neighbouring rows.
double ns_size(const CellMetrics& m, int r) { return 0.5 * (m.height_m[std::size_t(r)] + m.height_m[std::size_t(r) + 1]); }

}  // namespace

Hydraulic::Hydraulic(Domain& domain, const HydraulicOptions& options)
    : d_(domain), o_(options), water_(domain.height.size(), 0.0), rained_(water_), sediment_(water_),
      sediment_next_(water_), sin_slope_(water_), flux_(water_.size(), {0, 0, 0, 0}), water_out_row_(std::size_t(domain.rows), 0.0) {}

// Sediment volume (m³) a cell sends through pipe p: its suspended volume times the share of its
// water that leaves by that pipe. Moving sediment with the water's own fluxes, rather than by a
// semi-Lagrangian back-trace, keeps its mass exact; both ends evaluate this same expression.
static double sent(const std::vector<double>& sediment, const std::vector<double>& rained,
                   const std::vector<std::array<double, 4>>& flux, std::size_t i, int p, double area, double dt) {
  if (rained[i] <= 0) return 0;
  return sediment[i] * area * (flux[i][std::size_t(p)] * dt / (rained[i] * area));
}

double Hydraulic::fluxes(int r) {
  const CellMetrics& m = *d_.metrics;
  const double area = m.area_m2[std::size_t(r)], ns = ns_size(m, r), dt = o_.dt_s;
  double sediment_out = 0, water_out = 0;
  for (int c = 0; c < d_.cols; ++c) {
    const std::size_t i = d_.index(c, r);
    if (!d_.in[i]) continue;
    const double b = d_.height[i], d1 = water_[i] + o_.rain_m;
    rained_[i] = d1;
    std::array<double, 4> f{};
    double total = 0;
    for (int p = 0; p < 4; ++p) {
      const int k = pipe_k[p];
      const double cross = (p & 1) ? m.width_m[std::size_t(r)] : ns;
      double dh = d1;  // outside the domain: an outlet, the water falls over the edge
      if (d_.inside(c, r, k)) {
        const std::size_t j = d_.index(c + dcol[k], r + drow[k]);
        dh = b + water_[i] - d_.height[j] - water_[j];  // the rain is the same on both sides
      }
      // Mei et al. eq. 2: f += dt A g dh / l, with A = cross x l (the cell face a cell long).
      f[std::size_t(p)] = std::max(0.0, flux_[i][std::size_t(p)] + dt * cross * g * dh);
      total += f[std::size_t(p)];
    }
    // Mei et al. eq. 3: scaled so that no more water leaves than the cell holds.
    if (total * dt > d1 * area) for (double& x : f) x *= d1 * area / (total * dt);
    flux_[i] = f;
    for (int p = 0; p < 4; ++p)
      if (!d_.inside(c, r, pipe_k[p])) {
        water_out += f[std::size_t(p)] * dt;
        sediment_out += sent(sediment_, rained_, flux_, i, p, area, dt);
      }
    // The local tilt by central differences in metres (one-sided at the domain's edge).
    auto side = [&](int k) { return d_.inside(c, r, k) ? d_.height[d_.index(c + dcol[k], r + drow[k])] : b; };
    auto span = [&](int k) { return d_.inside(c, r, k) ? m.step_m(r, k) : 0.0; };
    const double wx = span(0) + span(4), wy = span(2) + span(6);
    const double gx = wx > 0 ? (side(0) - side(4)) / wx : 0, gy = wy > 0 ? (side(2) - side(6)) / wy : 0;
    const double tan_slope = std::hypot(gx, gy);
    sin_slope_[i] = tan_slope / std::sqrt(1 + tan_slope * tan_slope);
  }
  water_out_row_[std::size_t(r)] = water_out;
  return sediment_out;
}

double Hydraulic::sediment_in(int c, int r) const {
  double in = 0;
  for (int p = 0; p < 4; ++p) {
    const int k = pipe_k[p];
    if (!d_.inside(c, r, k)) continue;
    const int rr = r + drow[k];
    in += sent(sediment_, rained_, flux_, d_.index(c + dcol[k], rr), opposite_pipe(p), d_.metrics->area_m2[std::size_t(rr)], o_.dt_s);
  }
  return in;
}

void Hydraulic::transport(int r) {
  const CellMetrics& m = *d_.metrics;
  const double area = m.area_m2[std::size_t(r)], ns = ns_size(m, r), dt = o_.dt_s;
  for (int c = 0; c < d_.cols; ++c) {
    const std::size_t i = d_.index(c, r);
    if (!d_.in[i]) continue;
    const auto& f = flux_[i];
    std::array<double, 4> in{};  // inflow from the neighbour beyond each pipe, m³/s
    for (int p = 0; p < 4; ++p)
      if (d_.inside(c, r, pipe_k[p])) in[std::size_t(p)] = flux_[d_.index(c + dcol[pipe_k[p]], r + drow[pipe_k[p]])][std::size_t(opposite_pipe(p))];
    const double out_total = f[0] + f[1] + f[2] + f[3], in_total = in[0] + in[1] + in[2] + in[3];
    const double d1 = rained_[i], d2 = std::max(0.0, d1 + dt * (in_total - out_total) / area);  // eq. 6-7
    // Mei et al. eq. 8-9: the water passing through the cell per axis over the mean depth's section.
    const double pass_x = 0.5 * (in[2] - f[2] + f[0] - in[0]), pass_y = 0.5 * (in[3] - f[3] + f[1] - in[1]);
    const double depth = 0.5 * (d1 + d2);
    const double speed = depth > dry_m ? std::hypot(pass_x / (ns * depth), pass_y / (m.width_m[std::size_t(r)] * depth)) : 0.0;
    double volume = sediment_[i] * area;
    for (int p = 0; p < 4; ++p) volume -= sent(sediment_, rained_, flux_, i, p, area, dt);
    double s = (volume + sediment_in(c, r)) / area;
    // Mei et al. eq. 10-12: capacity, then dissolution below it and deposition above it.
    const double capacity = o_.capacity_s * std::max(sin_slope_[i], o_.min_slope) * speed;
    const double change = s < capacity ? o_.dissolve * (capacity - s) : -o_.deposit * (s - capacity);
    d_.height[i] -= change;
    s += change;
    sediment_next_[i] = s;
    water_[i] = d2 * (1 - o_.evaporation);  // eq. 14
  }
}

void Hydraulic::step() {
  sediment_out_m3 += rows_sum(d_.rows, [&](int r) { return fluxes(r); });
  water_out_m3 += std::accumulate(water_out_row_.begin(), water_out_row_.end(), 0.0);
  for_rows(d_.rows, [&](int r) { transport(r); });
  sediment_.swap(sediment_next_);
}

void Hydraulic::settle() {
  for (std::size_t i = 0; i < sediment_.size(); ++i)
    if (d_.in[i]) d_.height[i] += sediment_[i];
  std::fill(sediment_.begin(), sediment_.end(), 0.0);
}

}  // namespace terrapolis::erode
