// D8 with flat resolution, D-infinity facets and MFD splits, all with geodesic distances.
// SPDX-License-Identifier: MIT
#include "hydro/flow_directions.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cmath>

#include "core/error.hpp"
#include "hydro/depressions.hpp"

namespace terrapolis::hydro {
namespace {

bool valid(const Dem& z, int c, int r) { return z.inside(c, r) && !std::isnan(z(c, r)); }

/// First pass: steepest strictly-lower neighbour, outflow for outlets, kNoFlow otherwise.
std::uint8_t steepest(const Dem& z, const double* step, const std::optional<double>& sea_level, int c, int r) {
  const float zc = z(c, r);
  if (std::isnan(zc)) return kNoData;
  if (is_sea(zc, sea_level)) return kTerminal;
  int best = -1, outside = -1;
  double best_slope = 0;
  for (int k = 0; k < 8; ++k) {
    const int nc = c + dcol[k], nr = r + drow[k];
    if (!valid(z, nc, nr)) {
      if (outside < 0) outside = k;
      continue;
    }
    const double drop = double(zc) - double(z(nc, nr));
    if (drop <= 0) continue;
    const double slope = drop / step[k];
    if (slope > best_slope) {
      best_slope = slope;
      best = k;
    }
  }
  if (best >= 0) return std::uint8_t(best);
  if (outside >= 0) return std::uint8_t(outside);
  return kNoFlow;
}

}  // namespace

std::uint8_t d8_first_pass(const Dem& filled, const double* step, const std::optional<double>& sea_level, int col, int row) {
  return steepest(filled, step, sea_level, col, row);
}

Raster<std::uint8_t> d8_directions(const Dem& filled, const CellMetrics& metrics, const std::optional<double>& sea_level,
                                   Progress& progress) {
  ProgressStep step(progress, "flow directions");
  Raster<std::uint8_t> d8 = filled.like<std::uint8_t>(kNoData);
  d8.nodata = kNoData;
  bool any_flat = false;
  tbb::parallel_for(tbb::blocked_range<int>(0, filled.rows()), [&](const tbb::blocked_range<int>& rows) {
    for (int r = rows.begin(); r < rows.end(); ++r) {
      double step[8];
      for (int k = 0; k < 8; ++k) step[k] = metrics.step_m(r, k);
      for (int c = 0; c < filled.cols(); ++c) d8(c, r) = steepest(filled, step, sea_level, c, r);
    }
  });
  for (auto v : d8.values())
    if (v == kNoFlow) {
      any_flat = true;
      break;
    }
  step.update(0.5);
  if (!any_flat) return d8;
  drain_flats(filled, d8);  // Barnes et al. 2014b
  return d8;
}

std::uint8_t d8_code(int k, D8Codes convention) {
  switch (convention) {
    case D8Codes::esri: return std::uint8_t(1u << k);
    case D8Codes::grass: return std::uint8_t(8 - k);  // k=0 (E) -> 8
    case D8Codes::taudem: return std::uint8_t((8 - k) % 8 + 1);
  }
  return 0;
}

Raster<std::uint8_t> encode_d8(const Raster<std::uint8_t>& d8, D8Codes convention) {
  Raster<std::uint8_t> out = d8.like<std::uint8_t>(255);
  out.nodata = 255;
  for (std::size_t i = 0; i < d8.size(); ++i) {
    const int k = d8[i];
    if (k == kNoData) continue;
    if (k == kTerminal) {
      out[i] = 0;
      continue;
    }
    out[i] = d8_code(k, convention);
  }
  return out;
}

Raster<std::uint8_t> decode_d8(const Raster<std::uint8_t>& codes, D8Codes convention) {
  Raster<std::uint8_t> out = codes.like<std::uint8_t>(kNoData);
  out.nodata = kNoData;
  std::array<int, 256> back;
  back.fill(-1);
  back[0] = kTerminal;
  for (int k = 0; k < 8; ++k) {
    Raster<std::uint8_t> one(1, 1, {}, std::uint8_t(k));
    back[encode_d8(one, convention)[0]] = k;
  }
  for (std::size_t i = 0; i < codes.size(); ++i) {
    if (codes.is_nodata(i)) continue;
    if (back[codes[i]] < 0) throw bad_input("flow directions: code " + std::to_string(codes[i]) + " is not a D8 code");
    out[i] = std::uint8_t(back[codes[i]]);
  }
  return out;
}

std::string describe(D8Codes convention) {
  switch (convention) {
    case D8Codes::esri: return "esri: E=1 SE=2 S=4 SW=8 W=16 NW=32 N=64 NE=128, 0=no outflow, 255=nodata";
    case D8Codes::grass: return "grass: NE=1 N=2 NW=3 W=4 SW=5 S=6 SE=7 E=8, 0=no outflow, 255=nodata";
    case D8Codes::taudem: return "taudem: E=1 NE=2 N=3 NW=4 W=5 SW=6 S=7 SE=8, 0=no outflow, 255=nodata";
  }
  return {};
}

FlowRouter::FlowRouter(const Dem& filled, const Raster<std::uint8_t>& d8, const CellMetrics& metrics, FlowMethod method,
                       double mfd_exponent)
    : z_(filled), d8_(d8), metrics_(metrics), method_(method), exponent_(mfd_exponent) {
  if (!(mfd_exponent > 0) || !std::isfinite(mfd_exponent)) throw bad_input("/hydro/mfd_exponent: must be a positive number");
}

void FlowRouter::split(int c, int r, FlowSplit& out) const {
  out.count = 0;
  const std::uint8_t d = d8_(c, r);
  if (d == kNoData || d == kTerminal) return;
  const double zc = z_(c, r);
  if (method_ == FlowMethod::mfd) {
    double total = 0;
    for (int k = 0; k < 8; ++k) {
      const int nc = c + dcol[k], nr = r + drow[k];
      if (!valid(z_, nc, nr)) continue;
      const double drop = zc - double(z_(nc, nr));
      if (drop <= 0) continue;
      const double w = std::pow(drop / metrics_.step_m(r, k), exponent_);
      out.k[std::size_t(out.count)] = std::uint8_t(k);
      out.fraction[std::size_t(out.count)] = w;
      ++out.count;
      total += w;
    }
    if (out.count > 0) {
      for (int j = 0; j < out.count; ++j) out.fraction[std::size_t(j)] /= total;
      return;
    }
  } else if (method_ == FlowMethod::dinf) {
    // Tarboton 1997: 8 triangular facets (cardinal e1, diagonal e2); on each the steepest
    // downhill direction is clipped to the facet, then split between e1 and e2 by angle.
    // Distances are geodesic, so the facet's right angle spans atan(d12/d1), not always 45°.
    static constexpr int facets[8][2] = {{0, 1}, {2, 1}, {2, 3}, {4, 3}, {4, 5}, {6, 5}, {6, 7}, {0, 7}};
    double best_s = 0, best_p2 = 0;
    int best_f = -1;
    for (int f = 0; f < 8; ++f) {
      const int k1 = facets[f][0], k2 = facets[f][1];
      const int c1 = c + dcol[k1], r1 = r + drow[k1], c2 = c + dcol[k2], r2 = r + drow[k2];
      if (!valid(z_, c1, r1) || !valid(z_, c2, r2)) continue;
      const double z1 = z_(c1, r1), z2 = z_(c2, r2);
      const double d1 = metrics_.step_m(r, k1);
      // From e1 to e2: the step perpendicular to e1 (a north-south step for E/W, east-west for N/S).
      int k12 = 0;
      for (int k = 0; k < 8; ++k)
        if (dcol[k] == dcol[k2] - dcol[k1] && drow[k] == drow[k2] - drow[k1]) k12 = k;
      const double d12 = metrics_.step_m(r1, k12);
      const double s1 = (zc - z1) / d1, s2 = (z1 - z2) / d12;
      const double rmax = std::atan2(d12, d1);
      double angle = std::atan2(s2, s1), s = std::hypot(s1, s2);
      if (angle < 0) {
        angle = 0;
        s = s1;
      } else if (angle > rmax) {
        angle = rmax;
        s = (zc - z2) / metrics_.step_m(r, k2);
      }
      if (s > best_s) {
        best_s = s;
        best_f = f;
        best_p2 = angle / rmax;
      }
    }
    if (best_f >= 0) {
      const int k1 = facets[best_f][0], k2 = facets[best_f][1];
      if (best_p2 < 1) {
        out.k[0] = std::uint8_t(k1);
        out.fraction[0] = 1 - best_p2;
        out.count = 1;
      }
      if (best_p2 > 0) {
        out.k[std::size_t(out.count)] = std::uint8_t(k2);
        out.fraction[std::size_t(out.count)] = best_p2;
        ++out.count;
      }
      return;
    }
  }
  out.k[0] = d;
  out.fraction[0] = 1;
  out.count = 1;
}

std::uint8_t FlowRouter::inner_receivers(int c, int r) const {
  if (method_ == FlowMethod::d8) {
    const int k = d8_(c, r);
    if (k >= 8 || !valid(z_, c + dcol[k], r + drow[k])) return 0;
    return std::uint8_t(1u << k);
  }
  if (method_ == FlowMethod::mfd) {
    // The receivers of split() without its weights (no pow): every valid strictly lower neighbour
    // (all of them inside the grid), else the D8 receiver.
    const std::uint8_t d = d8_(c, r);
    if (d == kNoData || d == kTerminal) return 0;
    const float zc = z_(c, r);
    std::uint8_t bits = 0;
    for (int k = 0; k < 8; ++k) {
      const int nc = c + dcol[k], nr = r + drow[k];
      if (valid(z_, nc, nr) && double(zc) - double(z_(nc, nr)) > 0) bits = std::uint8_t(bits | (1u << k));
    }
    if (bits != 0) return bits;
    return valid(z_, c + dcol[d], r + drow[d]) ? std::uint8_t(1u << d) : 0;
  }
  FlowSplit s;
  split(c, r, s);
  std::uint8_t bits = 0;
  for (int j = 0; j < s.count; ++j) {
    const int k = s.k[std::size_t(j)];
    if (valid(z_, c + dcol[k], r + drow[k])) bits = std::uint8_t(bits | (1u << k));
  }
  return bits;
}

}  // namespace terrapolis::hydro
