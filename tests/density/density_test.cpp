// The density model: thesis synthetic cases (Fig. 4.2), an island, normalisation, invariants.
// SPDX-License-Identifier: MIT
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <cstdio>
#include <cstring>
#include <limits>

#include "core/error.hpp"
#include "density/density.hpp"
#include "density/disc_sums.hpp"
#include "core/geodesy.hpp"
#include "io/raster_io.hpp"
#include "support/georefs.hpp"

namespace terrapolis::density {
namespace {

using test::geographic;
using test::projected;

constexpr float nan_f = std::numeric_limits<float>::quiet_NaN();

struct Feature {
  int col, row;
};

/// Fig. 4.1-4.2: a plain at 100 m with three features of radius 15 cells, 3000 m high,
/// either cylinders or cones (3000 m at the centre down to the plain at the rim).
Dem plain_with(bool cones, const std::vector<Feature>& features) {
  Dem dem(240, 240, projected(50.0), 100.0f);
  for (int r = 0; r < dem.rows(); ++r)
    for (int c = 0; c < dem.cols(); ++c)
      for (const Feature& f : features) {
        const double d = std::hypot(c - f.col, r - f.row);
        if (d > 15) continue;
        dem(c, r) = cones ? float(100 + 2900 * (1 - d / 15)) : 3000.0f;
      }
  return dem;
}

DensityOptions synthetic_options(std::array<double, 4> weights) {
  DensityOptions o;
  o.weights = weights;
  o.r_min_m = 150;
  o.r_max_m = 1500;
  o.max_altitude_m = 2500;  // the features' tops stand for the thesis's "pseudo-infinite" cylinders
  return o;
}

const std::vector<Feature> features = {{60, 60}, {180, 70}, {120, 185}};

/// Mean density over cells at distance [d0, d1) cells from the rim of the feature at (60,60).
double ring_mean(const Raster<float>& density, double d0, double d1) {
  double sum = 0;
  int n = 0;
  for (int r = 0; r < density.rows(); ++r)
    for (int c = 0; c < density.cols(); ++c) {
      const double d = std::hypot(c - 60, r - 60) - 15;
      if (d >= d0 && d < d1) sum += density(c, r), ++n;
    }
  return sum / n;
}

/// Cells near (60,60) whose density exceeds `level`.
int dense_cells_around_first(const Raster<float>& density, float level) {
  int n = 0;
  for (int r = 0; r < 120; ++r)
    for (int c = 0; c < 120; ++c)
      if (std::hypot(c - 60, r - 60) < 55 && density(c, r) > level) ++n;
  return n;
}

TEST(Density, Fig42aPlainsAreDenseAwayFromTheCliffs) {
  SilentProgress p;
  const Dem dem = plain_with(false, features);
  const auto res = compute_density(dem, dem.like<float>(0.0f), synthetic_options({0, 1, -1.5, 0.3}), p);
  const double near = ring_mean(res.density, 1, 10);  // within the ring of the cliff
  const double far = res.density(120, 110);           // plain more than r_max from every cliff
  EXPECT_GT(far, near + 0.2);
  EXPECT_NEAR(far, 1.8 / 2.8, 1e-6);  // flat, no plateau nearby, hydrometry 0: (0 + 1.5 + 0.3) / 2.8
}

TEST(Density, Fig42bDenseHaloAroundCylinders) {
  SilentProgress p;
  const Dem dem = plain_with(false, features);
  const auto res = compute_density(dem, dem.like<float>(0.0f), synthetic_options({0, 1, 1.5, -0.3}), p);
  const double halo = ring_mean(res.density, 1, 10);
  const double far = res.density(120, 110);
  EXPECT_GT(halo, far + 0.2);
  // Tops above the maximum altitude are uninhabitable.
  EXPECT_EQ(res.density(60, 60), 0.0f);
  EXPECT_EQ(res.buildable(60, 60), 0);
}

TEST(Density, Fig42cConesWidenTheHalo) {
  SilentProgress p;
  const auto options = synthetic_options({0, 1, 1.5, -0.3});
  const Dem cylinders = plain_with(false, features);
  const Dem cones = plain_with(true, features);
  const auto a = compute_density(cylinders, cylinders.like<float>(0.0f), options, p);
  const auto b = compute_density(cones, cones.like<float>(0.0f), options, p);
  // The halo (cells above half the densest value around the feature) is wider around a cone ...
  float top_a = 0, top_b = 0;
  for (int r = 0; r < 120; ++r)
    for (int c = 0; c < 120; ++c) top_a = std::max(top_a, a.density(c, r)), top_b = std::max(top_b, b.density(c, r));
  EXPECT_GT(dense_cells_around_first(b.density, 0.5f * top_b), dense_cells_around_first(a.density, 0.5f * top_a) * 3 / 2);
  // ... and denser just outside the feature's base.
  EXPECT_GT(ring_mean(b.density, 0, 10), ring_mean(a.density, 0, 10));
  // The uninhabitable disc of a cone is smaller than the cylinder's.
  int zero_a = 0, zero_b = 0;
  for (int r = 40; r < 80; ++r)
    for (int c = 40; c < 80; ++c) zero_a += a.buildable(c, r) == 0, zero_b += b.buildable(c, r) == 0;
  EXPECT_LT(zero_b, zero_a);
}

TEST(Density, HydrometryIsAttractiveAndRiverBedsUninhabitable) {
  SilentProgress p;
  const Dem dem = plain_with(false, features);
  Raster<float> hydro = dem.like<float>(0.0f);
  for (int r = 0; r < dem.rows(); ++r) hydro(200, r) = 1.0f, hydro(201, r) = 0.6f;
  auto options = synthetic_options({0, 1, -1.5, 0.3});
  options.river_bed_cap = 0.9;
  const auto res = compute_density(dem, hydro, options, p);
  EXPECT_EQ(res.buildable(200, 120), 0);
  EXPECT_EQ(res.density(200, 120), 0.0f);
  EXPECT_GT(res.density(201, 120), res.density(205, 120));
}

/// An island on a geographic grid: land at 200 m in a disc of 40 cells, a 4500 m peak, sea at -50 m.
Dem island(float sea) {
  Dem dem(160, 160, geographic(42.08, 0.001), sea);
  for (int r = 0; r < 160; ++r)
    for (int c = 0; c < 160; ++c) {
      // Cells are ~82 m east-west and ~111 m north-south at 42 N: an ellipse in cells, a disc on the ground.
      const double dx = (c - 80) * 82.7, dy = (r - 80) * 111.1;
      const double d = std::hypot(dx, dy);
      if (d < 4500) dem(c, r) = d < 600 ? float(4500 - d * 5) : 200.0f;
    }
  return dem;
}

TEST(Density, IslandCoastAndThresholds) {
  SilentProgress p;
  DensityOptions o;
  o.r_min_m = 300;
  o.r_max_m = 1500;
  const Dem dem = island(-50.0f);
  const auto res = compute_density(dem, dem.like<float>(0.0f), o, p);
  float best = 0;
  for (std::size_t i = 0; i < dem.size(); ++i) {
    if (dem[i] <= 0) {
      EXPECT_EQ(res.coast[i], 0.0f);
      EXPECT_EQ(res.density[i], 0.0f);
      EXPECT_EQ(res.buildable[i], 0);
    }
    if (dem[i] > 4000) {
      EXPECT_EQ(res.density[i], 0.0f);
    }
    if (dem[i] > 0) best = std::max(best, res.coast[i]);
    EXPECT_GE(res.density[i], 0.0f);
    EXPECT_LE(res.density[i], 1.0f);
  }
  EXPECT_EQ(best, 1.0f);
  // Land just inside the shore (about 200 m from the sea) is coastal; the island's centre, 3 km
  // from the sea, is beyond r_max: 0.
  EXPECT_GT(res.coast(80, 80 - 4500 / 111 + 3), 0.3f);
  EXPECT_EQ(res.coast(80 + 10, 80), 0.0f);
  EXPECT_EQ(res.coast(80 - 15, 80 + 5), 0.0f);
  // Coast falls from the shore inwards along a radius.
  EXPECT_GT(res.coast(80 - 4500 / 83 + 4, 80), res.coast(80 - 4500 / 83 + 14, 80));
  EXPECT_EQ(res.coast.georef().crs.wkt, dem.georef().crs.wkt);
  EXPECT_EQ(res.density.georef().transform, dem.georef().transform);
}

TEST(Density, SeaAtZeroOrNodataGivesTheSameCoast) {
  SilentProgress p;
  DensityOptions o;
  o.r_min_m = 300;
  o.r_max_m = 1500;
  const Dem below = island(-50.0f), zero = island(0.0f), nodata = island(nan_f);
  const auto a = compute_density(below, below.like<float>(0.0f), o, p);
  const auto b = compute_density(zero, zero.like<float>(0.0f), o, p);
  DensityOptions on = o;
  on.nodata_is_sea = true;
  const auto c = compute_density(nodata, nodata.like<float>(0.0f), on, p);
  for (std::size_t i = 0; i < a.coast.size(); ++i) {
    ASSERT_EQ(a.coast[i], b.coast[i]);
    ASSERT_EQ(a.coast[i], c.coast[i]);
    ASSERT_EQ(a.density[i], c.density[i]);
  }
  // Without --nodata-is-sea the nodata is unknown: no coast, density and buildable are nodata there.
  const auto d = compute_density(nodata, nodata.like<float>(0.0f), o, p);
  EXPECT_TRUE(std::isnan(d.density(0, 0)));
  EXPECT_EQ(d.buildable(0, 0), 255);
  for (std::size_t i = 0; i < d.coast.size(); ++i)
    if (!std::isnan(d.coast[i])) {
      ASSERT_EQ(d.coast[i], 0.0f);
    }
}

/// Coast and plain of every land cell against brute-force ring and disc sums, on a grid whose land
/// is a corner (so the tables' window and the land spans are smaller than the grid) with nodata.
void check_against_brute_force(const Georef& g, std::uint64_t seed, bool all_land = false) {
  const int cols = 70, rows = 60;
  Dem dem(cols, rows, g, -5.0f);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) {
      if (all_land) {
        dem(c, r) = float(10 + 80 * u(rng));
        continue;
      }
      if (c > 40 || r > 35) continue;                       // sea outside the north-west corner
      dem(c, r) = float(u(rng) < 0.15 ? -1.0 : 10 + 80 * u(rng));  // land with lagoons
      if (u(rng) < 0.05) dem(c, r) = nan_f;                 // holes of unknown
    }
  SilentProgress p;
  DensityOptions o;
  o.weights = {1, 0, 0, 1};
  const CellMetrics m = cell_metrics(g, cols, rows);
  double step = 0;
  for (int r = 0; r < rows; ++r) step = std::max({step, m.width_m[std::size_t(r)], m.height_m[std::size_t(r)]});
  o.r_min_m = 2.2 * step;
  o.r_max_m = 6.5 * step;
  o.ring_bands = 1000;  // exact discs: the comparison is exact
  const auto res = compute_density(dem, dem.like<float>(0.0f), o, p);
  ASSERT_TRUE(res.stats.ring_exact);
  std::vector<double> wet(dem.size()), known(dem.size()), land(dem.size()), z(dem.size()), z2(dem.size());
  for (std::size_t i = 0; i < dem.size(); ++i) {
    const bool nd = std::isnan(dem[i]);
    wet[i] = !nd && dem[i] <= 0;
    known[i] = !nd;
    land[i] = !nd && dem[i] > 0;
    z[i] = land[i] ? dem[i] : 0.0;
    z2[i] = z[i] * z[i];
  }
  auto disc = [&](const std::vector<double>& v, double radius) { return brute_force_disc_sums(v, m, cols, rows, radius); };
  const auto wet_out = disc(wet, o.r_max_m), wet_in = disc(wet, o.r_min_m);
  const auto known_out = disc(known, o.r_max_m), known_in = disc(known, o.r_min_m);
  const auto n_in = disc(land, o.r_min_m), s1 = disc(z, o.r_min_m), s2 = disc(z2, o.r_min_m);
  std::vector<double> share(dem.size(), 0.0);
  double best = 0;
  for (std::size_t i = 0; i < dem.size(); ++i) {
    if (!land[i]) continue;
    const double k = known_out[i] - known_in[i];
    share[i] = k > 0 ? (wet_out[i] - wet_in[i]) / k : 0.0;
    best = std::max(best, share[i]);
  }
  ASSERT_EQ(best > 0, !all_land);
  if (all_land) best = 1;
  for (std::size_t i = 0; i < dem.size(); ++i) {
    if (!land[i]) {
      if (known[i]) {
        ASSERT_EQ(res.coast[i], 0.0f);
      } else {
        ASSERT_TRUE(std::isnan(res.coast[i]));
      }
      continue;
    }
    ASSERT_NEAR(res.coast[i], share[i] / best, 1e-5) << i;
    const double mean = s1[i] / n_in[i];
    const double sd = std::sqrt(std::max(0.0, s2[i] / n_in[i] - mean * mean));
    ASSERT_NEAR(res.plain[i], std::clamp(1.0 - sd / 50.0, 0.0, 1.0), 1e-4) << i;
  }
}

TEST(Density, CoastAndPlainEqualBruteForceProjected) { check_against_brute_force(projected(100.0), 5); }

TEST(Density, CoastAndPlainEqualBruteForceGeographic) { check_against_brute_force(geographic(62.0, 0.002), 6); }

TEST(Density, PlainEqualsBruteForceOnAllLand) { check_against_brute_force(projected(30.0), 7, true); }

TEST(Density, Normalisation) {
  const double thesis[4] = {1, 1, 1.5, 0};
  const double v[4] = {0.2, 0.4, 0.6, 0.9};
  EXPECT_NEAR(combine(thesis, v, 4), (0.2 + 0.4 + 0.9) / 3.5, 1e-12);  // the thesis's formula when no weight is negative
  const double fig42a[4] = {0, 1, -1.5, 0.3};                         // sums to -0.2
  const double best[4] = {0, 1, 0, 1}, worst[4] = {1, 0, 1, 0}, mid[4] = {0, 0.5, 0.5, 0.5};
  EXPECT_NEAR(combine(fig42a, best, 4), 1.0, 1e-12);
  EXPECT_NEAR(combine(fig42a, worst, 4), 0.0, 1e-12);
  EXPECT_NEAR(combine(fig42a, mid, 4), (0.5 - 0.75 + 0.15 + 1.5) / 2.8, 1e-12);
  const double zero[4] = {0, 0, 0, 0};
  EXPECT_THROW(combine(zero, v, 4), Error);
}

TEST(Density, OutputsInRangeOnARealDemAndDeterministicAcrossThreads) {
  const Dem dem = read_dem(std::string(TERRAPOLIS_SAMPLES) + "/gebco2022_15s_north_corsica_capcorse.asc");
  SilentProgress p;
  DensityOptions o;
  o.weights = {1, 0, 1.5, 0.5};
  o.max_slope_deg = 30;
  DensityResult one, two;
  {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
    one = compute_density(dem, dem.like<float>(0.0f), o, p);
  }
  {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 2);
    two = compute_density(dem, dem.like<float>(0.0f), o, p);
  }
  for (const auto* r : {&one.coast, &one.plateau, &one.plain, &one.density}) {
    EXPECT_EQ(r->cols(), dem.cols());
    EXPECT_EQ(r->georef().crs.wkt, dem.georef().crs.wkt);
    for (std::size_t i = 0; i < r->size(); ++i) {
      ASSERT_FALSE(std::isnan((*r)[i]));  // no nodata in this DEM
      ASSERT_GE((*r)[i], 0.0f);
      ASSERT_LE((*r)[i], 1.0f);
    }
  }
  EXPECT_EQ(0, std::memcmp(one.density.data(), two.density.data(), one.density.size() * sizeof(float)));
  EXPECT_EQ(0, std::memcmp(one.coast.data(), two.coast.data(), one.coast.size() * sizeof(float)));
  EXPECT_EQ(0, std::memcmp(one.plateau.data(), two.plateau.data(), one.plateau.size() * sizeof(float)));
  EXPECT_EQ(one.buildable.values(), two.buildable.values());
  EXPECT_GT(one.stats.buildable_cells, 0u);
  EXPECT_LT(one.stats.buildable_cells, one.stats.known_cells);
}

// A user layer: kept as is within [0,1]; else (v - min) / (max - min); NaN reads as 0.
TEST(Density, UserLayersToTheUnitRange) {
  const Georef g = projected(100.0);
  Raster<float> inside(2, 2, g), outside(2, 2, g);
  const float a[4] = {0.0f, 0.25f, 1.0f, NAN}, b[4] = {-10.0f, 0.0f, 30.0f, NAN};
  for (std::size_t i = 0; i < 4; ++i) inside[i] = a[i], outside[i] = b[i];
  to_unit_range(inside);
  to_unit_range(outside);
  EXPECT_EQ(inside.values(), (std::vector<float>{0.0f, 0.25f, 1.0f, 0.0f}));
  EXPECT_EQ(outside.values(), (std::vector<float>{0.0f, 0.25f, 1.0f, 0.0f}));
}

TEST(Density, RejectsBadOptions) {
  SilentProgress p;
  const Dem dem = plain_with(false, features);
  const Raster<float> h = dem.like<float>(0.0f);
  DensityOptions o;
  o.weights = {0, 0, 0, 0};
  EXPECT_THROW(compute_density(dem, h, o, p), Error);
  o = {};
  o.r_max_m = o.r_min_m;
  EXPECT_THROW(compute_density(dem, h, o, p), Error);
  o = {};
  EXPECT_THROW(compute_density(dem, Raster<float>(10, 10, dem.georef()), o, p), Error);
}

}  // namespace
}  // namespace terrapolis::density
