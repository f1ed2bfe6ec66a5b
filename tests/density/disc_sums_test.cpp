// Disc and ring sums: summed-area tables and band plans against brute force, projected and geographic.
// SPDX-License-Identifier: MIT
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "core/geodesy.hpp"
#include "density/disc_sums.hpp"
#include "support/georefs.hpp"

namespace terrapolis::density {
namespace {

using test::geographic;
using test::projected;

std::vector<double> random_values(int cols, int rows, std::uint64_t seed, bool binary) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<double> v(std::size_t(cols) * std::size_t(rows));
  for (double& x : v) x = binary ? double(u(rng) < 0.3) : std::floor(u(rng) * 100);
  return v;
}

/// Disc sums of every cell through a SummedArea<double> and a DiscPlan.
std::vector<double> fast_disc_sums(const std::vector<double>& v, const CellMetrics& m, int cols, int rows, double radius,
                                   int bands) {
  const SummedArea<double> table(cols, rows, [&](std::size_t i) { return v[i]; });
  const DiscPlan plan(m, rows, radius, bands);
  std::vector<double> out(v.size(), 0.0);
  for (int r = 0; r < rows; ++r) add_disc_row(table, plan, r, +1, out.data() + std::size_t(r) * std::size_t(cols), 0, cols);
  return out;
}

TEST(SummedArea, RectangleSumsAreExactInModularArithmetic) {
  const int cols = 37, rows = 23;
  std::vector<std::uint32_t> v(std::size_t(cols * rows));
  std::mt19937_64 rng(7);
  for (auto& x : v) x = std::uint32_t(rng() % 2);
  const SummedArea<std::uint32_t> t(cols, rows, [&](std::size_t i) { return v[i]; });
  for (int y0 = 0; y0 < rows; y0 += 3)
    for (int y1 = y0 + 1; y1 <= rows; y1 += 4)
      for (int x0 = 0; x0 < cols; x0 += 5)
        for (int x1 = x0 + 1; x1 <= cols; x1 += 6) {
          std::uint32_t expect = 0;
          for (int y = y0; y < y1; ++y)
            for (int x = x0; x < x1; ++x) expect += v[std::size_t(y * cols + x)];
          const std::uint32_t got = (t.at(y1, x1) - t.at(y1, x0)) - (t.at(y0, x1) - t.at(y0, x0));
          ASSERT_EQ(got, expect);
        }
}

TEST(DiscPlan, ExactPlansEqualBruteForceProjected) {
  const int cols = 41, rows = 33;
  const Georef g = projected(30.0, 45.0);  // non-square cells: the disc is wider in columns
  const CellMetrics m = cell_metrics(g, cols, rows);
  const auto v = random_values(cols, rows, 11, false);
  for (double radius : {40.0, 100.0, 333.3, 700.0, 5000.0}) {
    const auto slow = brute_force_disc_sums(v, m, cols, rows, radius);
    const auto fast = fast_disc_sums(v, m, cols, rows, radius, 1000);
    for (std::size_t i = 0; i < v.size(); ++i) ASSERT_EQ(fast[i], slow[i]) << "radius " << radius << " cell " << i;
  }
}

TEST(DiscPlan, ExactPlansEqualBruteForceGeographic) {
  const int cols = 45, rows = 40;
  const Georef g = geographic(61.0, 0.002);  // at 61 N a cell is about 108 m east-west by 222 m north-south
  const CellMetrics m = cell_metrics(g, cols, rows);
  const auto v = random_values(cols, rows, 12, true);
  for (double radius : {250.0, 900.0, 2500.0}) {
    const auto slow = brute_force_disc_sums(v, m, cols, rows, radius);
    const auto fast = fast_disc_sums(v, m, cols, rows, radius, 1000);
    for (std::size_t i = 0; i < v.size(); ++i) ASSERT_EQ(fast[i], slow[i]) << "radius " << radius << " cell " << i;
  }
}

TEST(DiscPlan, GeographicDiscIsWiderInColumnsAndWidensPoleward) {
  const int rows = 600;
  const Georef g = geographic(70.0, 0.05);  // 70 N down to 40 N
  const CellMetrics m = cell_metrics(g, 10, rows);
  const double radius = 20000.0;
  const int north_row = 10, south_row = rows - 10;
  const int w_north = DiscPlan::exact_half_cols(m, rows, radius, north_row, 0);
  const int w_south = DiscPlan::exact_half_cols(m, rows, radius, south_row, 0);
  int h = 0;
  while (DiscPlan::exact_half_cols(m, rows, radius, south_row, h + 1) >= 0) ++h;
  EXPECT_GT(w_south, h);      // wider in columns than in rows (cos 40 < 1)
  EXPECT_GT(w_north, w_south);  // wider still nearer the pole
  // Half-widths agree with geodesic distances to within one cell.
  const auto west = geodesic_destination(g.crs.ellipsoid, 9.0, 69.5 - 0.025, 90.0, radius);
  EXPECT_NEAR(w_north, (west[0] - 9.0) / 0.05, 1.0);
}

TEST(DiscPlan, PlanarShapeMatchesGeodesicCircle) {
  // The local planar rule misclassifies only cells right on the rim of a true geodesic circle.
  const int cols = 81, rows = 81;
  const double cell = 0.001;
  const Georef g = geographic(45.04, cell);
  const CellMetrics m = cell_metrics(g, cols, rows);
  const double radius = 3000.0;
  const int rc = 40, cc = 40;
  const auto centre = g.cell_centre(cc, rc);
  int disagree = 0, inside = 0;
  for (int r = 0; r < rows; ++r) {
    const int h = DiscPlan::exact_half_cols(m, rows, radius, rc, r - rc);
    for (int c = 0; c < cols; ++c) {
      const auto p = g.cell_centre(c, r);
      const bool geo = geodesic_distance_m(g.crs.ellipsoid, centre[0], centre[1], p[0], p[1]) <= radius;
      const bool planar = h >= 0 && std::abs(c - cc) <= h;
      inside += geo;
      disagree += geo != planar;
    }
  }
  EXPECT_GT(inside, 1000);
  EXPECT_LE(disagree, inside / 200);  // under 0.5 %
}

/// Ring share of a random binary grid: approximated band plans against brute force.
void check_ring_error(const Georef& g, int cols, int rows, double r_in, double r_out, int bands, double max_disc_error,
                      double max_share_error) {
  const CellMetrics m = cell_metrics(g, cols, rows);
  const auto v = random_values(cols, rows, 21, true);
  const std::vector<double> ones(v.size(), 1.0);
  const auto slow_in = brute_force_disc_sums(v, m, cols, rows, r_in), slow_out = brute_force_disc_sums(v, m, cols, rows, r_out);
  const auto slow_n_in = brute_force_disc_sums(ones, m, cols, rows, r_in), slow_n_out = brute_force_disc_sums(ones, m, cols, rows, r_out);
  const auto fast_in = fast_disc_sums(v, m, cols, rows, r_in, bands), fast_out = fast_disc_sums(v, m, cols, rows, r_out, bands);
  const auto fast_n_in = fast_disc_sums(ones, m, cols, rows, r_in, bands), fast_n_out = fast_disc_sums(ones, m, cols, rows, r_out, bands);
  const DiscPlan plan(m, rows, r_out, bands);
  ASSERT_FALSE(plan.exact());
  double worst_disc = 0, worst_share = 0;
  for (std::size_t i = 0; i < v.size(); ++i) {
    // Disc error relative to the unclipped disc around the grid's central cells only.
    const int r = int(i) / cols, c = int(i) % cols;
    if (r < rows / 3 || r > 2 * rows / 3 || c < cols / 3 || c > 2 * cols / 3) continue;
    worst_disc = std::max(worst_disc, std::abs(fast_n_out[i] - slow_n_out[i]) / slow_n_out[i]);
    const double slow_share = (slow_out[i] - slow_in[i]) / (slow_n_out[i] - slow_n_in[i]);
    const double fast_share = (fast_out[i] - fast_in[i]) / (fast_n_out[i] - fast_n_in[i]);
    worst_share = std::max(worst_share, std::abs(fast_share - slow_share));
  }
  EXPECT_LE(worst_disc, max_disc_error);
  EXPECT_LE(worst_share, max_share_error);
  std::printf("worst disc error %.4f, worst ring share error %.4f\n", worst_disc, worst_share);
}

TEST(DiscPlan, BandApproximationErrorIsBoundedProjected) {
  check_ring_error(projected(30.0, 30.0), 121, 121, 300.0, 1500.0, 16, 0.02, 0.01);
}

TEST(DiscPlan, BandApproximationErrorIsBoundedGeographic) {
  check_ring_error(geographic(46.0, 1.0 / 3600.0 * 3), 131, 131, 400.0, 1700.0, 16, 0.02, 0.01);
}

TEST(DiscPlan, BandCountDoesNotGrowWithRadius) {
  const Georef g = projected(30.0, 30.0);
  const CellMetrics m = cell_metrics(g, 10, 3000);
  for (double radius : {500.0, 2000.0, 10000.0, 40000.0}) {
    const DiscPlan plan(m, 3000, radius, 16);
    EXPECT_LE(plan.band_count(), 16) << radius;
  }
}

}  // namespace
}  // namespace terrapolis::density
