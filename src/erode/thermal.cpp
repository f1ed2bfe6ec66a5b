// Thermal erosion to the angle of repose: Musgrave, Kolb & Mace 1989 ("The synthesis and rendering
// of eroded fractal terrains", SIGGRAPH, §4) with Peytavie's stabilisation (Peytavie 2010, thesis
// §2.3.4): material above the angle of repose slides to the lower neighbours; on a layered ground
// only the loose layer does (Peytavie §2.1.1.1: "le moteur physique opère sur l'ensemble des
// matériaux sauf la roche").
// SPDX-License-Identifier: MIT
#include <algorithm>
#include <cmath>
#include <numbers>

#include "core/error.hpp"
#include "erode/domain.hpp"

namespace terrapolis::erode {

Thermal::Thermal(Domain& domain, const ThermalOptions& options)
    : d_(domain), rate_(options.rate), tan_(domain.height.size(), 0.0), next_(domain.height), next_loose_(domain.loose),
      out_(domain.height.size(), {0, 0, 0, 0, 0, 0, 0, 0}) {
  const double deg = std::numbers::pi / 180;
  for (std::size_t i = 0; i < tan_.size(); ++i) {
    double angle = options.angle_deg;
    if (options.angles_deg && d_.in[i] && std::isfinite((*options.angles_deg)[i])) {
      angle = (*options.angles_deg)[i];
      if (!(angle > 0 && angle < 90))
        throw bad_input("/erode/angles: angle of repose " + std::to_string(angle) + " degrees out of (0, 90)");
    }
    tan_[i] = std::tan(angle * deg);
  }
}

double Thermal::outflows(int r) {
  const CellMetrics& m = *d_.metrics;
  const double area = m.area_m2[std::size_t(r)];
  double moved = 0;
  for (int c = 0; c < d_.cols; ++c) {
    const std::size_t i = d_.index(c, r);
    if (!d_.in[i]) continue;
    std::array<double, 8> excess{};
    double largest = 0, total = 0;
    for (int k = 0; k < 8; ++k) {
      if (!d_.inside(c, r, k)) continue;  // nodata, the mask and the border hold no material
      const double drop = d_.height[i] - d_.height[d_.index(c + dcol[k], r + drow[k])];
      const double e = drop - m.step_m(r, k) * tan_[i];  // Peytavie: dh_i - s tan(alpha)
      if (e > stable_m) {
        excess[std::size_t(k)] = e;
        largest = std::max(largest, e);
        total += e;
      }
    }
    // Musgrave et al.: move c (d_max - T), shared in proportion to each neighbour's excess
    // (Peytavie's dz_i = a dh_i / sum dh_i); as a volume, so unequal cells conserve mass.
    double volume = total > 0 ? rate_ * largest * area : 0.0;
    // Layered: no more than the loose material on the cell; steep bare rock stays (a film thinner
    // than stable_m counts as bare, so that the last of a layer does not trickle for ever).
    if (!d_.loose.empty()) volume = std::min(volume, d_.loose[i] > stable_m ? d_.loose[i] * area : 0.0);
    for (int k = 0; k < 8; ++k) out_[i][std::size_t(k)] = volume > 0 ? volume * excess[std::size_t(k)] / total : 0.0;
    moved += volume;
  }
  return moved;
}

void Thermal::gather(int r) {
  const double area = d_.metrics->area_m2[std::size_t(r)];
  for (int c = 0; c < d_.cols; ++c) {
    const std::size_t i = d_.index(c, r);
    if (!d_.in[i]) continue;
    double change = 0;
    for (int k = 0; k < 8; ++k) {
      change -= out_[i][std::size_t(k)];
      if (d_.inside(c, r, k)) change += out_[d_.index(c + dcol[k], r + drow[k])][std::size_t(opposite(k))];
    }
    next_[i] = d_.height[i] + change / area;
    if (!d_.loose.empty()) next_loose_[i] = d_.loose[i] + change / area;  // only loose material moved
  }
}

double Thermal::step() {
  const double moved = rows_sum(d_.rows, [&](int r) { return outflows(r); });
  if (moved == 0) return 0;
  for_rows(d_.rows, [&](int r) { gather(r); });
  d_.height.swap(next_);
  d_.loose.swap(next_loose_);
  return moved;
}

}  // namespace terrapolis::erode
