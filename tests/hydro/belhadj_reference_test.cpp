// Belhadj hydrometry: the banded gather kernel against a plain per-cell Algorithm 12, bit for bit.
// SPDX-License-Identifier: MIT
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>
#include <random>

#include "core/geodesy.hpp"
#include "core/neighbours.hpp"
#include "hydro/belhadj_hydrometry.hpp"
#include "hydro/test_grids.hpp"

using namespace terrapolis;
using namespace terrapolis::hydro;

namespace {

/// Algorithm 12 written the obvious way: one sender at a time, water and flow pushed to its
/// fed inside neighbours. Each receiver's inputs are summed in its own neighbour order (k = 0..7,
/// the direction of the sender seen from the receiver), the order the kernel documents.
struct Reference {
  int cols, rows;
  std::vector<double> z, fx, fy, fz, q, acc;
  std::vector<char> valid;
  double z_out;
  const BelhadjModel& geometry;  // only for the V_i steps and the outside altitude
  bool all;

  Reference(const Dem& dem, const BelhadjModel& model, VerticalScale vertical, std::optional<double> sea, bool all_)
      : cols(dem.cols()), rows(dem.rows()), z_out(model.outside_altitude()), geometry(model), all(all_) {
    const std::size_t n = dem.size();
    z.assign(n, 0);
    valid.assign(n, 0);
    fx.assign(n, 0);
    fy.assign(n, 0);
    fz.assign(n, 0);
    q.assign(n, 0);
    acc.assign(n, 0);
    for (std::size_t i = 0; i < n; ++i) {
      const float v = dem[i];
      if (std::isnan(v) || (sea && v <= *sea)) continue;
      valid[i] = 1;
      z[i] = vertical == VerticalScale::normalised16 ? double(v) / 65535.0 : double(v);
      fz[i] = -1;
      q[i] = 1;
    }
  }
  bool inside(int c, int r) const { return c >= 0 && r >= 0 && c < cols && r < rows && valid[std::size_t(r * cols + c)]; }
  double alt(int c, int r) const { return inside(c, r) ? z[std::size_t(r * cols + c)] : z_out; }

  double step() {
    const std::size_t n = z.size();
    // in[i][k]: what cell i receives from its neighbour k (R and the water), when fed.
    struct In {
      bool fed = false;
      double rx = 0, ry = 0, rz = 0, w = 0;
    };
    std::vector<std::array<In, 8>> in(n);
    double total = 0;
    int count = 0;
    for (int r = 0; r < rows; ++r)
      for (int c = 0; c < cols; ++c) {
        const std::size_t i = std::size_t(r * cols + c);
        if (!valid[i]) continue;
        total += q[i];
        ++count;
        acc[i] += q[i];
        double rx[8], ry[8], rz[8], norm[8], s[8], sn = 0;
        for (int k = 0; k < 8; ++k) {
          const auto h = geometry.step_vector(r, k);
          const double dz = alt(c + dcol[k], r + drow[k]) - z[i];
          rx[k] = fx[i] + h[0];
          ry[k] = fy[i] + h[1];
          rz[k] = fz[i] + dz;
          s[k] = rx[k] * h[0] + ry[k] * h[1] + rz[k] * dz;
          norm[k] = std::sqrt(rx[k] * rx[k] + ry[k] * ry[k] + rz[k] * rz[k]);
          if (s[k] > 0 || all) sn += norm[k];
        }
        for (int k = 0; k < 8; ++k) {
          if (!(s[k] > 0) || !inside(c + dcol[k], r + drow[k])) continue;
          In& to = in[std::size_t((r + drow[k]) * cols + c + dcol[k])][std::size_t(opposite(k))];
          to = {true, rx[k], ry[k], rz[k], sn > 0 ? norm[k] * (q[i] / sn) : 0.0};
        }
      }
    for (std::size_t i = 0; i < n; ++i) {
      fx[i] = fy[i] = fz[i] = q[i] = 0;
      for (int k = 0; k < 8; ++k) {
        const In& from = in[i][std::size_t(k)];
        if (!from.fed) continue;
        fx[i] += from.rx;
        fy[i] += from.ry;
        fz[i] += from.rz;
        q[i] += from.w;
      }
    }
    return total / count;
  }
};

void expect_same(const Dem& dem, VerticalScale vertical, std::optional<double> sea, BelhadjShare share, int threads) {
  const CellMetrics m = cell_metrics(dem.georef(), dem.cols(), dem.rows());
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, std::size_t(threads));
  BelhadjModel model(dem, m, vertical, sea, share);
  Reference ref(dem, model, vertical, sea, share == BelhadjShare::all_neighbours);
  for (int it = 0; it < 6; ++it) {
    const double mean = model.step(), ref_mean = ref.step();
    EXPECT_NEAR(mean, ref_mean, 1e-12 * std::max(1.0, ref_mean));  // row sums: a different order
    for (int r = 0; r < dem.rows(); ++r)
      for (int c = 0; c < dem.cols(); ++c) {
        const std::size_t i = std::size_t(r * dem.cols() + c);
        const auto f = model.flow(c, r);
        // Bit for bit: the same operations in the same order (EXPECT_EQ on doubles is exact).
        ASSERT_EQ(model.q(c, r), ref.q[i]) << "cell " << c << "," << r << " iteration " << it;
        ASSERT_EQ(model.acc(c, r), ref.acc[i]);
        ASSERT_EQ(f[0], ref.fx[i]);
        ASSERT_EQ(f[1], ref.fy[i]);
        ASSERT_EQ(f[2], ref.fz[i]);
      }
  }
}

}  // namespace

TEST(BelhadjKernel, MatchesPlainAlgorithm12BitForBit) {
  for (std::uint64_t seed = 1; seed <= 4; ++seed) {
    const bool holes = seed % 2 == 0;
    const Dem dem = test::random_dem(37 + int(seed), 29 + 3 * int(seed), seed, holes);
    for (auto share : {BelhadjShare::all_neighbours, BelhadjShare::fed_neighbours})
      for (int threads : {1, 2, 3}) {
        expect_same(dem, VerticalScale::metres, std::nullopt, share, threads);
        expect_same(dem, VerticalScale::normalised16, std::optional<double>(2.0), share, threads);
      }
  }
}

TEST(BelhadjKernel, GeographicGridAndTinyShapes) {
  // Geographic rows (metres vary with latitude) and grids smaller than a band.
  for (auto [cols, rows] : {std::pair{2, 2}, std::pair{1, 5}, std::pair{7, 1}, std::pair{40, 70}}) {
    Dem dem = test::random_dem(cols, rows, 99, false);
    Georef g;
    g.transform = {9.0, 1.0 / 1200, 0, 47.5, 0, -1.0 / 1200};
    g.crs.wkt = "GEOGCS[\"WGS 84\"]";
    g.crs.geographic = true;
    dem = Dem(cols, rows, g, 0.0f);
    std::mt19937_64 rng(7);
    for (auto& v : dem.values()) v = float(rng() % 500);
    expect_same(dem, VerticalScale::metres, std::nullopt, BelhadjShare::all_neighbours, 2);
  }
}
