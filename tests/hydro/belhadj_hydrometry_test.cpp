// Belhadj hydrometry: a hand-computed single iteration, the thesis's cylinder terrain, options.
// SPDX-License-Identifier: MIT
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "core/error.hpp"
#include "core/geodesy.hpp"
#include "hydro/hydrometry.hpp"
#include "hydro/test_grids.hpp"

using namespace terrapolis;
using namespace terrapolis::hydro;
using terrapolis::hydro::test::grid;

TEST(Belhadj, OneIterationOnAFlat3x3ByHand) {
  // Thesis units: z / (2^16-1) (a flat at 0), dx, dy in cells, outside cells at -1.
  const Dem dem = grid(3, 3, std::vector<float>(9, 0.0f));
  const CellMetrics m = cell_metrics(dem.georef(), 3, 3);
  BelhadjModel model(dem, m, VerticalScale::normalised16, std::nullopt);
  EXPECT_EQ(model.outside_altitude(), -1.0);
  // F = (0,0,-1) everywhere. R_i = F + V_i; |R_i| = sqrt(|h|^2 + (dz - 1)^2):
  // inside cardinal sqrt(2), inside diagonal sqrt(3), outside cardinal sqrt(5) (dz = -1), outside diagonal sqrt(6).
  const double s2 = std::sqrt(2.0), s3 = std::sqrt(3.0), s5 = std::sqrt(5.0), s6 = std::sqrt(6.0);
  const double sn_centre = 4 * s2 + 4 * s3;
  const double sn_edge = 3 * s2 + 2 * s3 + s5 + 2 * s6;    // e.g. (1,0): E, W, S, SE, SW inside
  const double sn_corner = 2 * s2 + s3 + 2 * s5 + 3 * s6;  // e.g. (0,0): E, S, SE inside
  // Every S_i = R_i . V_i = |h|^2 > 0 inside, so each inside neighbour gets N_i Q / Σn.
  EXPECT_EQ(model.step(), 1.0);  // mean Q of the iteration
  EXPECT_NEAR(model.q(1, 1), 4 * s2 / sn_edge + 4 * s3 / sn_corner, 1e-14);
  EXPECT_NEAR(model.q(0, 0), 2 * s2 / sn_edge + s3 / sn_centre, 1e-14);
  EXPECT_NEAR(model.q(1, 0), s2 / sn_corner * 2 + s2 / sn_centre + 2 * s3 / sn_edge, 1e-14);
  // F' is the sum of the incoming R: at the centre the horizontal parts cancel.
  const auto fc = model.flow(1, 1);
  EXPECT_NEAR(fc[0], 0.0, 1e-15);
  EXPECT_NEAR(fc[1], 0.0, 1e-15);
  EXPECT_NEAR(fc[2], -8.0, 1e-15);
  // At (0,0): from E (-1,0,-1), from S (0,-1,-1), from SE (-1,-1,-1).
  const auto f0 = model.flow(0, 0);
  EXPECT_NEAR(f0[0], -2.0, 1e-15);
  EXPECT_NEAR(f0[1], -2.0, 1e-15);
  EXPECT_NEAR(f0[2], -3.0, 1e-15);
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) EXPECT_EQ(model.acc(c, r), 1.0);
  // Water is lost through the border (and kept nowhere else): the mean after one step is < 1.
  double total = 0;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) total += model.q(c, r);
  EXPECT_LT(total, 9.0);
  EXPECT_NEAR(model.step(), total / 9, 1e-15);
}

namespace {
/// The thesis's binary terrain (Fig. 4.1): a plain at mid altitude with "infinitely" high cylinders.
Dem cylinders(int size, std::vector<std::array<int, 3>> discs) {
  std::vector<float> v(std::size_t(size * size), 32767.0f);
  for (int r = 0; r < size; ++r)
    for (int c = 0; c < size; ++c)
      for (const auto& d : discs)
        if ((c - d[0]) * (c - d[0]) + (r - d[1]) * (r - d[1]) <= d[2] * d[2]) v[std::size_t(r * size + c)] = 65535.0f;
  return grid(size, size, v);
}
}  // namespace

struct Zones {
  double top = 0, ring = 0, plain = 0, gap = 0;
};

/// Mean hydrometry on the cylinders, within 2 cells of them, elsewhere on the plain, and in the
/// 3-cell gap between the two close cylinders (border band left out).
Zones zones(const Dem& dem, const Raster<float>& h) {
  Zones z;
  int n_top = 0, n_ring = 0, n_plain = 0, n_gap = 0;
  const int n = dem.cols();
  for (int r = 4; r < n - 4; ++r)
    for (int c = 4; c < n - 4; ++c) {
      const bool on = dem(c, r) > 40000;
      bool near = false;
      for (int dr = -2; dr <= 2; ++dr)
        for (int dc = -2; dc <= 2; ++dc) near = near || dem(c + dc, r + dr) > 40000;
      const double v = h(c, r);
      if (on) z.top += v, ++n_top;
      else if (near) z.ring += v, ++n_ring;
      else z.plain += v, ++n_plain;
      if (!on && r >= 18 && r <= 22 && c >= 27 && c <= 28) z.gap += v, ++n_gap;
    }
  z.top /= n_top;
  z.ring /= n_ring;
  z.plain /= n_plain;
  z.gap /= n_gap;
  return z;
}

TEST(Belhadj, CylinderTerrainBehavesAsFigure41) {
  // Two cylinders with a 3-cell gap and one alone, on a 64x64 plain at mid altitude (32767)
  // with tops at 65535: "infinitely" high in metres against 1 m cells.
  const Dem dem = cylinders(64, {{20, 20, 6}, {35, 20, 6}, {40, 45, 7}});
  const CellMetrics m = cell_metrics(dem.georef(), 64, 64);
  SilentProgress p;
  BelhadjOptions o;
  o.vertical = VerticalScale::metres;
  o.share = BelhadjShare::fed_neighbours;
  const BelhadjRun fed = belhadj_hydrometry(dem, m, o, p);
  const Zones f = zones(dem, fed.hydrometry);
  EXPECT_LT(f.top, 0.01);         // none on the cylinders
  EXPECT_GT(f.ring, 2 * f.plain);  // water collects around them
  EXPECT_GT(f.gap, 2 * f.ring);   // and most of all between two of them
  EXPECT_LT(fed.final_mean, o.threshold);
  // Algorithm 12 as printed loses the share of unfed neighbours, so cells next to a wall lose
  // water each iteration: the tops still get the least and the gap more than the rest of the ring,
  // but the open plain far from any wall ends up the wettest (documented in docs/hydro.md).
  o.share = BelhadjShare::all_neighbours;
  for (VerticalScale v : {VerticalScale::metres, VerticalScale::normalised16}) {
    o.vertical = v;
    const BelhadjRun lit = belhadj_hydrometry(dem, m, o, p);
    const Zones l = zones(dem, lit.hydrometry);
    EXPECT_LT(l.top, l.plain);
    if (v == VerticalScale::normalised16) {
      EXPECT_LT(l.top, l.ring);
      EXPECT_GT(l.gap, l.ring);
    }
    EXPECT_GT(l.plain, l.ring);
    EXPECT_LT(lit.iterations, 60);  // geometric convergence, as the thesis's 20 to 51 iterations
  }
}

TEST(Belhadj, OptionsAndEdgeCases) {
  const Dem dem = grid(4, 4, {1, 2, 3, 4, 2, 3, 4, 5, 3, 4, NAN, 6, 4, 5, 6, 7});
  SilentProgress p;
  HydrometryOptions o;
  o.max_iterations = 3;
  const Raster<float> h = compute_hydrometry(dem, o, p);
  EXPECT_TRUE(std::isnan(h(2, 2)));
  float lo = 1, hi = 0;
  for (std::size_t i = 0; i < h.size(); ++i)
    if (!std::isnan(h[i])) lo = std::min(lo, h[i]), hi = std::max(hi, h[i]);
  EXPECT_EQ(lo, 0.0f);
  EXPECT_EQ(hi, 1.0f);
  o.max_iterations = -1;
  EXPECT_THROW(compute_hydrometry(dem, o, p), Error);
  o.max_iterations = 0;
  o.threshold = 0;
  EXPECT_THROW(compute_hydrometry(dem, o, p), Error);
  // Sea cells are outlets: 0, not NaN; a DEM all under the sea is refused.
  o.threshold = 1.0 / 1048576;
  o.sea_level = 2.5;
  const Raster<float> s = compute_hydrometry(dem, o, p);
  EXPECT_EQ(s(0, 0), 0.0f);
  o.sea_level = 100;
  EXPECT_THROW(compute_hydrometry(dem, o, p), Error);
  // The accumulation method is a log rescale of D8 upstream area.
  o.sea_level.reset();
  o.method = HydrometryMethod::accumulation;
  const Raster<float> a = compute_hydrometry(dem, o, p);
  EXPECT_EQ(a(3, 3), 0.0f);  // the top corner: only itself upstream
  EXPECT_EQ(a(0, 0), 1.0f);  // the lowest corner collects the most
}
