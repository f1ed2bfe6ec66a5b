// Calibration: AUC by hand, the presence/background fit recovering known weights, the distance transform.
// SPDX-License-Identifier: MIT
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "density/calibration.hpp"
#include "density/density.hpp"
#include "support/georefs.hpp"

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

// The terrain terms on a tiny valley (450 m cells, z = 100 + 50 |c - 2| + 10 r, one water cell at
// (2,1)): the 1 km disc is the 13 cells with dc² + dr² <= 4 (1000 / 450 = 2.22 cells), land only;
// the 5 km disc covers the grid. Ranks are the share of land cells lower, ties half.
TEST(Calibration, TerrainTermsByHand) {
  const int n = 5;
  Dem dem(n, n, test::projected(450.0), 0.0f);
  for (int r = 0; r < n; ++r)
    for (int c = 0; c < n; ++c) dem(c, r) = float(100 + 50 * std::abs(c - 2) + 10 * r);
  dem(2, 1) = 0;  // water (sea level 0)
  DensityOptions o;
  o.terrain_terms = true;
  SilentProgress progress;
  const DensityResult m = compute_density(dem, dem.like<float>(0.0f), o, progress);
  // Topographic position within 1 km, by hand. (2,2): the disc's land cells are rows 0..4 of the
  // cross, less the water: 100 + (160 + 160) + (220 + 170 + 120 + 170 + 220) + (180 + 130 + 180) +
  // 140 = 1950 over 12 cells, so 120 - 162.5 = -42.5. (0,0), clipped by the grid: 200, 150, 100,
  // 210, 160, 220, mean 173.33, so +26.67. Brute force gives every cell; the term is its rank.
  std::vector<double> tpi;
  for (int r = 0; r < n; ++r)
    for (int c = 0; c < n; ++c) {
      if (c == 2 && r == 1) continue;
      double sum = 0, count = 0;
      for (int rr = 0; rr < n; ++rr)
        for (int cc = 0; cc < n; ++cc)
          if ((cc - c) * (cc - c) + (rr - r) * (rr - r) <= 4 && !(cc == 2 && rr == 1)) sum += dem(cc, rr), ++count;
      tpi.push_back(dem(c, r) - sum / count);
    }
  EXPECT_NEAR(tpi[std::size_t(2 * n + 2 - 1)], -42.5, 1e-9);  // (2,2), after the skipped water cell
  EXPECT_NEAR(tpi[0], 200 - 1040.0 / 6, 1e-9);
  auto rank = [](const std::vector<double>& v, double x) {
    double lower = 0, ties = 0;
    for (double y : v) lower += y < x - 1e-6, ties += std::abs(y - x) <= 1e-6;
    return (lower + 0.5 * ties) / double(v.size());
  };
  const Raster<float>& position = m.term(TerrainTerm::position_1km);
  std::size_t k = 0;
  for (int r = 0; r < n; ++r)
    for (int c = 0; c < n; ++c) {
      if (c == 2 && r == 1) {
        EXPECT_TRUE(std::isnan(position(c, r)));
        continue;
      }
      EXPECT_NEAR(position(c, r), rank(tpi, tpi[k++]), 1e-6) << c << "," << r;
    }
  // Within 5 km every land cell is in the disc: the position is z minus the land's mean, so its
  // rank is the altitude's.
  for (int r = 0; r < n; ++r)
    for (int c = 0; c < n; ++c)
      if (!(c == 2 && r == 1)) {
        EXPECT_FLOAT_EQ(m.term(TerrainTerm::position_5km)(c, r), m.term(TerrainTerm::altitude)(c, r));
      }
  // Altitude rank: (2,0) at 100 m is the lowest of 24 land cells; (0,4)/(4,4) at 240 m tie highest.
  EXPECT_FLOAT_EQ(m.term(TerrainTerm::altitude)(2, 0), 0.5f / 24);
  EXPECT_FLOAT_EQ(m.term(TerrainTerm::altitude)(4, 4), (22 + 0.5f * 2) / 24);
  // Slope rank: the valley floor's cells are the flattest across the valley, but every cell has
  // 10 m per 450 m along it; the steepest are the sides' cells (50 m per 450 m across).
  EXPECT_LT(m.term(TerrainTerm::slope)(2, 3), m.term(TerrainTerm::slope)(1, 3));
  // Without water the nearness to the coast is 0; without rivers, the nearness to rivers.
  EXPECT_EQ(m.term(TerrainTerm::river_near)(0, 0), 0.0f);
}

// Settlements drawn from a known intensity over the terrain terms of a model (a rolling 32 km
// terrain, rivers on one column): the fit on those terms, taken with terms_at, gives the weights
// back, the zero weight of the slope included.
TEST(Calibration, RecoversKnownWeightsOfTerrainTerms) {
  const int n = 160;
  Dem dem(n, n, test::projected(200.0), 0.0f);
  for (int r = 0; r < n; ++r)
    for (int c = 0; c < n; ++c) dem(c, r) = float(300 + 200 * std::sin(c / 9.0) * std::cos(r / 13.0) + 80 * std::sin((c + 2 * r) / 5.0) + 3 * r);
  DensityOptions o;
  o.terrain_terms = true;
  o.rivers = dem.like<std::uint8_t>(0);
  for (int r = 0; r < n; ++r) o.rivers(40, r) = 1;
  std::mt19937_64 g(11);
  std::uniform_real_distribution<double> u(0, 1);
  SilentProgress progress;
  const DensityResult m = compute_density(dem, dem.like<float>(0.0f), o, progress);
  const std::vector<TerrainTerm> fitted = {TerrainTerm::altitude, TerrainTerm::slope, TerrainTerm::position_1km, TerrainTerm::position_5km,
                                           TerrainTerm::river_near};
  const std::vector<double> truth = {-2.0, 0.0, -1.5, 1.0, 1.5};
  std::vector<std::vector<double>> x;
  std::vector<double> y, w;
  int presences = 0, background = 0;
  for (std::size_t i = 0; i < dem.size(); ++i) {
    const Terms t = terms_at(m, i);
    std::vector<double> v;
    double eta = 0;
    for (std::size_t j = 0; j < fitted.size(); ++j) v.push_back(t[4 + std::size_t(fitted[j])]), eta += truth[j] * v.back();
    x.push_back(v), y.push_back(0), ++background;
    // Eight independent thinned draws per cell (max eta = 2.5).
    for (int k = 0; k < 8; ++k)
      if (u(g) < std::exp(eta - 2.5)) x.push_back(v), y.push_back(1), ++presences;
  }
  ASSERT_GT(presences, 3000);
  for (double v : y) w.push_back(v == 1 ? 1.0 / presences : 1.0 / background);
  const std::vector<double> b = fit_logistic(x, y, w, 0.0);
  for (std::size_t j = 0; j < truth.size(); ++j) EXPECT_NEAR(b[j + 1], truth[j], 0.3) << kTerrainTerms[std::size_t(fitted[j])];
}
