// Tests of constrained midpoint displacement, DMMC, multigrid splines and void detection.
// SPDX-License-Identifier: MIT
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>

#include "core/error.hpp"
#include "terrain/fill.hpp"
#include "terrain/spline.hpp"
#include "terrain/subdivision.hpp"
#include "support/determinism.hpp"
#include "support/georefs.hpp"
#include "support/sketches.hpp"

using namespace terrapolis;
using namespace terrapolis::terrain;

namespace {

constexpr float nan_f = std::numeric_limits<float>::quiet_NaN();

Georef unit_georef() { return test::projected(30); }

/// Random sparse constraints: a share of the cells of `truth`, chosen by a hash.
Raster<float> sample(const Raster<float>& truth, double share, std::uint64_t seed) {
  Raster<float> r = truth;
  for (int y = 0; y < r.rows(); ++y)
    for (int x = 0; x < r.cols(); ++x)
      if ((position_noise(seed, x, y) + 1) / 2 >= share) r(x, y) = nan_f;
  return r;
}

Raster<float> cross_skeleton(int n, float ridge_m) { return test::cross_skeleton(unit_georef(), n, ridge_m); }

using test::largest_jump_at_constraints;

double rmse_hidden(const Raster<float>& truth, const Raster<float>& input, const Raster<float>& result) {
  double s = 0;
  std::size_t n = 0;
  for (std::size_t i = 0; i < truth.size(); ++i)
    if (std::isnan(input[i])) { s += (double(result[i]) - truth[i]) * (double(result[i]) - truth[i]); ++n; }
  return std::sqrt(s / double(n));
}

Raster<float> smooth_surface(int cols, int rows) {
  Raster<float> r(cols, rows, unit_georef());
  for (int y = 0; y < rows; ++y)
    for (int x = 0; x < cols; ++x)
      r(x, y) = float(300 + 120 * std::sin(x * 0.07) * std::cos(y * 0.05) + 40 * std::sin((x + 2 * y) * 0.03));
  return r;
}

}  // namespace

TEST(SubdivisionTree, EveryCellHasLevelAndParentsAtLowerLevels) {
  for (const auto scheme : {Subdivision::triangle_edge, Subdivision::diamond_square})
    for (const auto& [cols, rows] : {std::pair{9, 9}, {13, 7}, {2, 5}, {100, 37}}) {
      const SubdivisionTree tree(cols, rows);
      for (int y = 0; y < rows; ++y)
        for (int x = 0; x < cols; ++x) {
          int pc[4], pr[4];
          double w[4];
          const int n = tree.parents(scheme, x, y, pc, pr, w);
          const bool corner = (x == 0 || x == cols - 1) && (y == 0 || y == rows - 1);
          EXPECT_EQ(n == 0, corner) << x << "," << y;
          double sum = 0;
          for (int k = 0; k < n; ++k) {
            sum += w[k];
            const bool earlier = tree.level(pc[k], pr[k]) < tree.level(x, y);
            // Diamond-Square edge midpoints also read the centres made at the same level.
            const bool same_level_centre = scheme == Subdivision::diamond_square && tree.level(pc[k], pr[k]) == tree.level(x, y) &&
                                           tree.x().depth[std::size_t(pc[k])] == tree.y().depth[std::size_t(pr[k])];
            EXPECT_TRUE(earlier || same_level_centre) << x << "," << y;
          }
          if (n) {
            EXPECT_NEAR(sum, 1.0, 1e-12);
          }
        }
    }
}

TEST(MidpointDisplacement, WithoutNoiseReproducesAPlaneOnAnyGridSize) {
  for (const auto scheme : {Subdivision::triangle_edge, Subdivision::diamond_square})
    for (const auto& [cols, rows] : {std::pair{9, 9}, {13, 7}, {31, 64}}) {
      auto plane = [](int x, int y) { return 10.0 + 2.0 * x - 3.0 * y; };
      Raster<float> r(cols, rows, unit_georef(), nan_f);
      for (const int y : {0, rows - 1})
        for (const int x : {0, cols - 1}) r(x, y) = float(plane(x, y));
      SubdivisionGrid g = SubdivisionGrid::from_raster(r);
      MidpointParams p;
      p.subdivision = scheme;
      midpoint_displacement(g, p);
      for (int y = 0; y < rows; ++y)
        for (int x = 0; x < cols; ++x) EXPECT_NEAR(g.z[std::size_t(y * cols + x)], plane(x, y), 1e-3) << x << "," << y;
    }
}

TEST(MidpointDisplacement, TriangleEdgeIsBilinearBetweenTheCorners) {
  // Hand-computed: corners 0, 8 (east), 16 (south), 0 (south-east) on a 5x5 grid; centre = mean = 6.
  Raster<float> r(5, 5, unit_georef(), nan_f);
  r(0, 0) = 0; r(4, 0) = 8; r(0, 4) = 16; r(4, 4) = 0;
  SubdivisionGrid g = SubdivisionGrid::from_raster(r);
  midpoint_displacement(g, MidpointParams{});
  EXPECT_FLOAT_EQ(g.z[2 * 5 + 2], 6.0f);
  EXPECT_FLOAT_EQ(g.z[0 * 5 + 2], 4.0f);
  EXPECT_FLOAT_EQ(g.z[2 * 5 + 0], 8.0f);
  EXPECT_FLOAT_EQ(g.z[1 * 5 + 1], 0.75f * 0.75f * 0 + 0.25f * 0.75f * 8 + 0.75f * 0.25f * 16);
}

TEST(MidpointDisplacement, ConstraintsAreKeptExactly) {
  const Raster<float> truth = smooth_surface(70, 45);
  const Raster<float> input = sample(truth, 0.05, 7);
  for (const auto scheme : {Subdivision::triangle_edge, Subdivision::diamond_square}) {
    SubdivisionGrid g = SubdivisionGrid::from_raster(input);
    MidpointParams p;
    p.subdivision = scheme;
    p.scale_m = 200;
    midpoint_displacement(g, p);
    Raster<float> d = input;
    DmmcParams dp;
    dp.top_down = p;
    dp.low_pass = true;
    dmmc(d, dp);
    for (std::size_t i = 0; i < input.size(); ++i) {
      EXPECT_TRUE(std::isfinite(g.z[i]));
      EXPECT_TRUE(std::isfinite(d[i]));
      if (std::isnan(input[i])) continue;
      EXPECT_EQ(g.z[i], input[i]);
      EXPECT_EQ(d[i], input[i]);
    }
  }
}

TEST(MidpointDisplacement, SameSeedSameBytesWhateverTheThreads) {
  const Raster<float> input = sample(smooth_surface(200, 130), 0.03, 3);
  auto run = [&](int threads, std::uint64_t seed) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, std::size_t(threads));
    Raster<float> d = input;
    DmmcParams dp;
    dp.top_down.subdivision = Subdivision::diamond_square;
    dp.top_down.scale_m = 50;
    dp.top_down.seed = seed;
    dp.low_pass = true;
    dmmc(d, dp);
    Raster<float> s = input;
    spline_fill(s, SplineParams{});
    d.values().insert(d.values().end(), s.values().begin(), s.values().end());
    return d.values();
  };
  test::expect_same_bytes_at_any_thread_count(run);
}

TEST(Dmmc, BottomUpDownDoesNotTearAlongTheShiftedDiagonal) {
  // Belhadj fig. 1.2 vs fig. 3.3: plain subdivision ignores the shifted counter-diagonal until the
  // last level, so its neighbours sit far below it; bottom-up-down pushes it up the tree first.
  const int n = 65;
  const float ridge = 1000;
  const Raster<float> skeleton = cross_skeleton(n, ridge);
  for (const auto scheme : {Subdivision::triangle_edge, Subdivision::diamond_square}) {
    MidpointParams p;
    p.subdivision = scheme;
    const Raster<float> plain_r = test::plain_subdivision(skeleton, p);
    const double jump_plain = largest_jump_at_constraints(skeleton, plain_r);
    EXPECT_GT(jump_plain, 0.4 * ridge) << int(scheme);
    for (const auto rule : {BottomUpRule::weighted, BottomUpRule::mean}) {
      Raster<float> bud = skeleton;
      DmmcParams dp;
      dp.top_down = p;
      dp.bottom_up.rule = rule;
      dmmc(bud, dp);
      const double jump_bud = largest_jump_at_constraints(skeleton, bud);
      // The smooth slope from ridge to border is ridge / (n/2) per cell; a tear is many times that.
      std::printf("scheme %d, rule %d: largest jump plain %.1f m, bottom-up-down %.1f m\n", int(scheme), int(rule), jump_plain, jump_bud);
      EXPECT_LT(jump_bud, 0.2 * ridge) << int(scheme) << " " << int(rule);
    }
  }
}

namespace {

/// 5x5 Triangle-Edge grid with (1,0) = 10 and (1,1) = 20 fixed, after Alg. 10's bottom-up pass.
/// Round 1: (1,0) feeds its edge ends (0,0), (2,0) at d = 1; (1,1) feeds the 4 corners of its
/// square, (0,0), (2,0), (0,2), (2,2), at d = sqrt 2. Round 2: (2,0) feeds (4,0) at d = 2; (0,2)
/// feeds (0,4) at d = 2; (2,2) feeds (4,0), (0,4), (4,4) at d = 2 sqrt 2.
SubdivisionGrid alg10_grid(double noise_m_per_cell, std::uint64_t seed, std::size_t* set = nullptr) {
  Raster<float> r(5, 5, unit_georef(), nan_f);
  r(1, 0) = 10;
  r(1, 1) = 20;
  SubdivisionGrid g = SubdivisionGrid::from_raster(r);
  BottomUpParams p;
  p.rule = BottomUpRule::mean;
  p.noise_m_per_cell = noise_m_per_cell;
  const std::size_t n = bottom_up(g, Subdivision::triangle_edge, p, seed);
  if (set) *set = n;
  return g;
}

double z_at(const SubdivisionGrid& g, int x, int y) { return g.z[std::size_t(y * g.cols + x)]; }

}  // namespace

TEST(BottomUpMean, ZeroNoiseGivesThePlainMeanOfTheKnownChildren) {
  std::size_t set = 0;
  const SubdivisionGrid g = alg10_grid(0.0, 1, &set);
  EXPECT_EQ(set, 7u);
  EXPECT_EQ(z_at(g, 0, 0), 15.0f);  // (10 + 20) / 2, not Alg. 11's (1 x 10 + sqrt2 x 20) / (1 + sqrt2)
  EXPECT_EQ(z_at(g, 2, 0), 15.0f);
  EXPECT_EQ(z_at(g, 0, 2), 20.0f);
  EXPECT_EQ(z_at(g, 2, 2), 20.0f);
  EXPECT_EQ(z_at(g, 4, 0), 17.5f);  // round 2: (15 + 20) / 2
  EXPECT_EQ(z_at(g, 0, 4), 20.0f);
  EXPECT_EQ(z_at(g, 4, 4), 20.0f);
  EXPECT_EQ(g.state[std::size_t(2 * 5 + 4)], CellState::unknown);  // (4,2): no constraint below it
  // The default rule weights by distance, so the two differ wherever the distances do.
  Raster<float> r(5, 5, unit_georef(), nan_f);
  r(1, 0) = 10;
  r(1, 1) = 20;
  SubdivisionGrid w = SubdivisionGrid::from_raster(r);
  bottom_up(w, Subdivision::triangle_edge, BottomUpParams{});
  EXPECT_FLOAT_EQ(z_at(w, 0, 0), float((10 + 20 * std::sqrt(2.0)) / (1 + std::sqrt(2.0))));
}

TEST(BottomUpMean, NoiseIsTheMeanChildDistanceTimesSTimesX) {
  const double s = 3.0, r2 = std::sqrt(2.0);
  const std::uint64_t seed = 9;
  const SubdivisionGrid g = alg10_grid(s, seed);
  auto x = [&](int col, int row) { return position_noise(seed, col, row); };
  EXPECT_NEAR(z_at(g, 0, 0), 15 + (1 + r2) / 2 * s * x(0, 0), 1e-4);  // Ex.d / Ex.n = (1 + sqrt2) / 2
  EXPECT_NEAR(z_at(g, 2, 0), 15 + (1 + r2) / 2 * s * x(2, 0), 1e-4);
  EXPECT_NEAR(z_at(g, 0, 2), 20 + r2 * s * x(0, 2), 1e-4);            // one child at sqrt 2
  EXPECT_NEAR(z_at(g, 4, 4), z_at(g, 2, 2) + 2 * r2 * s * x(4, 4), 1e-4);  // one child at 2 sqrt 2
  EXPECT_NEAR(z_at(g, 4, 0), (z_at(g, 2, 0) + z_at(g, 2, 2)) / 2 + (2 + 2 * r2) / 2 * s * x(4, 0), 1e-4);
  // Linear in s: twice s, twice the departure from the mean.
  const SubdivisionGrid g2 = alg10_grid(2 * s, seed);
  EXPECT_NEAR(z_at(g2, 0, 0) - 15, 2 * (z_at(g, 0, 0) - 15), 1e-4);
  EXPECT_NE(z_at(g, 0, 0), 15.0f);
  // Fixed cells are never touched.
  EXPECT_EQ(z_at(g, 1, 0), 10.0f);
  EXPECT_EQ(z_at(g, 1, 1), 20.0f);
}

TEST(BottomUpMean, DmmcKeepsConstraintsAndIsThreadIndependent) {
  const Raster<float> input = sample(smooth_surface(200, 130), 0.03, 3);
  auto run = [&](int threads, std::uint64_t seed, Subdivision scheme) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, std::size_t(threads));
    Raster<float> d = input;
    DmmcParams dp;
    dp.top_down.subdivision = scheme;
    dp.top_down.scale_m = 500;
    dp.top_down.seed = seed;
    dp.bottom_up.rule = BottomUpRule::mean;
    dp.bottom_up.noise_m_per_cell = 0.5;
    dmmc(d, dp);
    return d;
  };
  for (const auto scheme : {Subdivision::triangle_edge, Subdivision::diamond_square}) {
    const Raster<float> one = run(1, 5, scheme), two = run(2, 5, scheme), other = run(2, 6, scheme);
    EXPECT_EQ(std::memcmp(one.values().data(), two.values().data(), one.size() * sizeof(float)), 0);
    EXPECT_NE(std::memcmp(one.values().data(), other.values().data(), one.size() * sizeof(float)), 0);
    for (std::size_t i = 0; i < input.size(); ++i) {
      EXPECT_TRUE(std::isfinite(one[i]));
      if (std::isfinite(input[i])) {
        EXPECT_EQ(one[i], input[i]);
      }
    }
  }
}

namespace {

/// Eq. 3.5 written out: f_-1(a, d) = a (1 - sigma(I) (1 - (1 - d / d_max)^|I|)).
double f_minus_1(double a, double d, double d_max, double shape) {
  return a * (1 - (shape >= 0 ? 1 : -1) * (1 - std::pow(1 - d / d_max, std::abs(shape))));
}

/// 5x5 Triangle-Edge grid, (1,0) = 10 and (3,4) = 20 fixed, weighted bottom-up with I_-1 = `shape`.
/// Round 1: (1,0) alone feeds its edge ends (0,0), (2,0) at d = 1; (3,4) alone feeds (2,4), (4,4)
/// at d = 1. Round 2: (2,0) alone feeds (4,0) at d = 2 (its other end is known); (2,4) alone feeds
/// (0,4) at d = 2. Every parent has one child, so Alg. 11's weights cancel: parent = f_-1(child, d).
SubdivisionGrid labelled_grid(double shape, const std::vector<ExtrapolationLabel>& labels) {
  Raster<float> r(5, 5, unit_georef(), nan_f);
  r(1, 0) = 10;
  r(3, 4) = 20;
  SubdivisionGrid g = SubdivisionGrid::from_raster(r);
  g.label = labels;
  BottomUpParams p;
  p.shape = shape;
  bottom_up(g, Subdivision::triangle_edge, p);
  return g;
}

}  // namespace

TEST(BottomUpLabels, RiverCellsExtrapolateUpRidgeCellsDown) {
  const double d_max = std::hypot(5.0, 5.0), shape = 2;
  std::vector<ExtrapolationLabel> labels(25, ExtrapolationLabel::global);
  labels[1] = ExtrapolationLabel::river;       // (1,0)
  labels[4 * 5 + 3] = ExtrapolationLabel::ridge;  // (3,4)
  const SubdivisionGrid g = labelled_grid(shape, labels);
  // By hand: 1 - (1 - 1/sqrt 50)^2 = 0.262843, 1 - (1 - 2/sqrt 50)^2 = 0.485686.
  EXPECT_NEAR(z_at(g, 0, 0), 10 * 1.262843, 1e-4);  // river: above its child
  EXPECT_NEAR(z_at(g, 2, 0), 10 * 1.262843, 1e-4);
  EXPECT_NEAR(z_at(g, 4, 0), 10 * 1.262843 * 1.485686, 1e-3);  // the parent inherits "river" and rises again
  EXPECT_NEAR(z_at(g, 2, 4), 20 * 0.737157, 1e-4);  // ridge: below its child
  EXPECT_NEAR(z_at(g, 4, 4), 20 * 0.737157, 1e-4);
  EXPECT_NEAR(z_at(g, 0, 4), 20 * 0.737157 * 0.514314, 1e-3);
  EXPECT_FLOAT_EQ(z_at(g, 4, 0), float(f_minus_1(f_minus_1(10, 1, d_max, -shape), 2, d_max, -shape)));
  EXPECT_EQ(g.label[4], ExtrapolationLabel::river);           // (4,0)
  EXPECT_EQ(g.label[4 * 5 + 0], ExtrapolationLabel::ridge);   // (0,4)
  // Whatever the sign of --shape-up, the labels set the direction, |I_-1| the amount.
  const SubdivisionGrid negative = labelled_grid(-shape, labels);
  EXPECT_EQ(std::memcmp(negative.z.data(), g.z.data(), g.z.size() * sizeof(float)), 0);
  // Without labels I_-1 = 2 lowers both.
  const SubdivisionGrid plain = labelled_grid(shape, {});
  EXPECT_NEAR(z_at(plain, 0, 0), 10 * 0.737157, 1e-4);
  EXPECT_NEAR(z_at(plain, 2, 4), 20 * 0.737157, 1e-4);
}

TEST(BottomUpLabels, AParentOfARiverAndARidgeFollowsBothAndTakesTheGlobalRule) {
  // (1,0) river = 10 and (3,0) ridge = 20 share the parent (2,0), both at d = 1 (weights equal).
  Raster<float> r(5, 5, unit_georef(), nan_f);
  r(1, 0) = 10;
  r(3, 0) = 20;
  SubdivisionGrid g = SubdivisionGrid::from_raster(r);
  g.label.assign(25, ExtrapolationLabel::global);
  g.label[1] = ExtrapolationLabel::river;
  g.label[3] = ExtrapolationLabel::ridge;
  BottomUpParams p;
  p.shape = 2;
  bottom_up(g, Subdivision::triangle_edge, p);
  EXPECT_NEAR(z_at(g, 2, 0), (10 * 1.262843 + 20 * 0.737157) / 2, 1e-4);
  EXPECT_EQ(g.label[2], ExtrapolationLabel::global);
  EXPECT_EQ(g.label[0], ExtrapolationLabel::river);
  EXPECT_EQ(g.label[4], ExtrapolationLabel::ridge);
}

TEST(BottomUpLabels, AllGlobalLabelsGiveTheBytesOfNoLabelsAtAnyThreadCount) {
  const Raster<float> input = sample(smooth_surface(200, 130), 0.03, 3);
  auto run = [&](int threads, const std::vector<ExtrapolationLabel>& labels) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, std::size_t(threads));
    Raster<float> d = input;
    DmmcParams dp;
    dp.top_down.scale_m = 500;
    dp.bottom_up.shape = 3;
    dmmc(d, dp, nullptr, labels);
    return d;
  };
  std::vector<ExtrapolationLabel> global(input.size(), ExtrapolationLabel::global), mixed = global;
  for (std::size_t i = 0; i < mixed.size(); ++i)
    if (std::isfinite(input[i])) mixed[i] = i % 2 ? ExtrapolationLabel::river : ExtrapolationLabel::ridge;
  const Raster<float> none = run(2, {}), all_global = run(1, global);
  EXPECT_EQ(std::memcmp(none.values().data(), all_global.values().data(), none.size() * sizeof(float)), 0);
  const Raster<float> one = run(1, mixed), two = run(2, mixed);
  EXPECT_EQ(std::memcmp(one.values().data(), two.values().data(), one.size() * sizeof(float)), 0);
  EXPECT_NE(std::memcmp(one.values().data(), none.values().data(), one.size() * sizeof(float)), 0);
  for (std::size_t i = 0; i < input.size(); ++i)
    if (std::isfinite(input[i])) {
      EXPECT_EQ(one[i], input[i]);
    }
  std::vector<ExtrapolationLabel> wrong(3, ExtrapolationLabel::river);
  Raster<float> d = input;
  EXPECT_THROW(dmmc(d, DmmcParams{}, nullptr, wrong), Error);
}

TEST(Reconstruction, ErrorFallsAsSamplesGrowDenser) {
  const Raster<float> truth = smooth_surface(161, 121);
  for (const auto method : {FillMethod::dmmc, FillMethod::harmonic, FillMethod::thin_plate}) {
    double previous = 1e30;
    for (const double share : {0.01, 0.04, 0.16}) {
      const Raster<float> input = sample(truth, share, 11);
      Raster<float> out = input;
      FillParams fp;
      fp.method = method;
      fp.dmmc.top_down.subdivision = Subdivision::diamond_square;
      fp.dmmc.bottom_up.weight_by_distance = false;
      fp.dmmc.low_pass = true;
      reconstruct(out, fp);
      const double e = rmse_hidden(truth, input, out);
      EXPECT_LT(e, previous) << to_string(method) << " " << share;
      previous = e;
    }
    // Relief amplitude is ~300 m; at 16% samples every method is within a few metres.
    EXPECT_LT(previous, method == FillMethod::thin_plate ? 1.0 : 6.0) << to_string(method);
  }
}

TEST(Voids, BorderNodataAndSeaAreNotVoidsAndLargeVoidsStay) {
  // 8x8 grid, 30 m cells: nodata along the west border, a 2-cell hole and a 6-cell hole inside,
  // and a cell at sea level touching the east border next to a 1-cell hole.
  Raster<float> dem(8, 8, unit_georef(), 100.0f);
  for (int y = 0; y < 8; ++y) dem(0, y) = nan_f;
  dem(2, 2) = dem(3, 2) = nan_f;
  for (int y = 4; y <= 5; ++y)
    for (int x = 4; x <= 6; ++x) dem(x, y) = nan_f;
  dem(7, 1) = 0.0f;
  dem(6, 1) = nan_f;
  VoidReport rep;
  auto v = find_voids(dem, VoidOptions{}, &rep);
  EXPECT_EQ(rep.voids, 3u);
  EXPECT_EQ(v[dem.index(0, 3)], 0);
  EXPECT_EQ(v[dem.index(2, 2)], 1);
  EXPECT_EQ(v[dem.index(6, 1)], 1);
  VoidOptions sea;
  sea.sea_level_m = 0.0;
  sea.max_area_km2 = 3 * 900e-6;  // the 6-cell hole (5400 m2) is too large
  v = find_voids(dem, sea, &rep);
  EXPECT_EQ(v[dem.index(6, 1)], 0);
  EXPECT_EQ(v[dem.index(5, 4)], 0);
  EXPECT_EQ(v[dem.index(3, 2)], 1);
  EXPECT_EQ(rep.too_large, 1u);
  VoidOptions all;
  all.fill_border = true;
  v = find_voids(dem, all, &rep);
  EXPECT_EQ(v[dem.index(0, 0)], 1);
  FillParams fp;
  fill_voids(dem, v, fp);
  for (std::size_t i = 0; i < dem.size(); ++i) EXPECT_TRUE(std::isfinite(dem[i]));
  EXPECT_NEAR(dem(2, 2), 100.0f, 0.05);
}
