// Calibration: AUC by hand, the presence/background fit recovering known weights, the distance transform.
// SPDX-License-Identifier: MIT
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "density/calibration.hpp"
#include "density/density.hpp"

using namespace terrapolis;
using namespace terrapolis::density;

// Presences 1 and 2 against 0, 1, 3: 1 beats 0 and ties 1 -> 1.5 / 3; 2 beats 0 and 1 -> 2 / 3.
TEST(Calibration, AucByHand) {
  EXPECT_NEAR(auc({1, 2}, {}, {0, 1, 3}), (1.5 / 3 + 2.0 / 3) / 2, 1e-12);
  // Weighted: the second presence counts three times.
  EXPECT_NEAR(auc({1, 2}, {1, 3}, {0, 1, 3}), (1.5 / 3 + 3 * 2.0 / 3) / 4, 1e-12);
  EXPECT_NEAR(auc({5}, {}, {1, 2, NAN}), 1.0, 1e-12);
}

// Settlements drawn from a known intensity exp(b.x) over a background of terms: the
// presence/background logistic fit gives back b (its intercept absorbs the sampling rate).
TEST(Calibration, RecoversKnownWeights) {
  const std::vector<double> truth = {2.0, -1.5, 0.0, 1.0};
  std::mt19937_64 g(7);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<std::vector<double>> x;
  std::vector<double> y, w;
  int presences = 0, background = 0;
  while (presences < 4000 || background < 20000) {
    std::vector<double> t(truth.size());
    for (double& v : t) v = u(g);
    double eta = 0;
    for (std::size_t j = 0; j < t.size(); ++j) eta += truth[j] * t[j];
    if (background < 20000) x.push_back(t), y.push_back(0), ++background;
    // Thinning: a cell holds a settlement with probability exp(eta - max eta) (max eta = 3).
    if (presences < 4000 && u(g) < std::exp(eta - 3.0)) x.push_back(t), y.push_back(1), ++presences;
  }
  for (double v : y) w.push_back(v == 1 ? 1.0 / presences : 1.0 / background);
  const std::vector<double> b = fit_logistic(x, y, w, 0.0);
  ASSERT_EQ(b.size(), truth.size() + 1);
  for (std::size_t j = 0; j < truth.size(); ++j) EXPECT_NEAR(b[j + 1], truth[j], 0.15) << j;
}

TEST(Calibration, DistanceTransformIsEuclidean) {
  Georef g;
  g.transform = {500000.0, 100.0, 0.0, 5000000.0, 0.0, -100.0};
  g.crs.geographic = false;
  const int cols = 12, rows = 10;
  const CellMetrics m = cell_metrics(g, cols, rows);
  std::vector<std::uint8_t> f(std::size_t(cols * rows), 0);
  f[std::size_t(3 * cols + 2)] = 1;   // (col 2, row 3)
  f[std::size_t(9 * cols + 11)] = 1;  // (col 11, row 9)
  const std::vector<float> d = distance_to_m(f, m, cols, rows);
  // Brute force over the two features.
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) {
      const double a = std::hypot(100.0 * (c - 2), 100.0 * (r - 3)), b = std::hypot(100.0 * (c - 11), 100.0 * (r - 9));
      EXPECT_NEAR(d[std::size_t(r * cols + c)], std::min(a, b), 1e-3) << c << "," << r;
    }
  EXPECT_NEAR(d[std::size_t(7 * cols + 5)], 500.0, 1e-3);  // 300 m east, 400 m south of (2,3)
  const std::vector<float> none = distance_to_m(std::vector<std::uint8_t>(f.size(), 0), m, cols, rows);
  EXPECT_TRUE(std::isinf(none[0]));
}
