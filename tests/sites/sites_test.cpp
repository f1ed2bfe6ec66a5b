// City sites: quota table (Algorithm 13), placement invariants (Algorithm 14), hierarchy (Algorithm 15).
// SPDX-License-Identifier: MIT
#include <gtest/gtest.h>

#include <cmath>

#include "core/error.hpp"
#include "core/geodesy.hpp"
#include "sites/fixtures.hpp"
#include "sites/sites.hpp"

using namespace terrapolis;
using namespace terrapolis::sites;

namespace {

// The thesis's Corsica example: a cell every 500 m, so dr = 500; radii 500 .. 2500 m.
// f(400 r) = 4 + 1068 ((10^6 - 400 r) / 10^6)^4, by hand:
//   r = 2500: 4 + 1068 * 0       = 4
//   r = 2000: 4 + 1068 * 0.0016  = 5.7088   -> 5
//   r = 1500: 4 + 1068 * 0.0256  = 31.3408  -> 31
//   r = 1000: 4 + 1068 * 0.1296  = 142.4128 -> 142
//   r =  500: 4 + 1068 * 0.4096  = 441.4528 -> 441
TEST(Quotas, ThesisCorsicaTable) {
  SitesOptions o = fixtures::thesis_options();
  o.r_min_m = 500;
  o.r_max_m = 3000;
  const QuotaTable t = compute_quotas(500.0, o);
  EXPECT_EQ(t.dr_m, 500.0);
  ASSERT_EQ(t.classes.size(), 5u);
  const double radii[5] = {2500, 2000, 1500, 1000, 500};
  const int quotas[5] = {4, 5, 31, 142, 441};
  for (int k = 0; k < 5; ++k) {
    EXPECT_EQ(t.classes[std::size_t(k)].radius_m, radii[k]) << k;
    EXPECT_EQ(t.classes[std::size_t(k)].quota, quotas[k]) << k;
  }
  EXPECT_EQ(t.total(), 623);
}

// The same table scaled to Corsica (8680 km2 of the 543940 km2 the census fit describes):
//   scale 0.015958 x (4, 5.7088, 31.3408, 142.4128, 441.4528) = (0.064, 0.091, 0.500, 2.273, 7.045)
TEST(Quotas, ScaledToARegion) {
  SitesOptions o = fixtures::thesis_options();
  o.r_min_m = 500;
  o.r_max_m = 3000;
  o.quota_scale = 8680.0 / 543940.0;
  const QuotaTable t = compute_quotas(500.0, o);
  const int quotas[5] = {0, 0, 0, 2, 7};
  for (int k = 0; k < 5; ++k) EXPECT_EQ(t.classes[std::size_t(k)].quota, quotas[k]) << k;
  o.quota_scale = 0;
  EXPECT_THROW(compute_quotas(500.0, o), Error);
}

TEST(Quotas, StepAndAutomaticRange) {
  SitesOptions o = fixtures::thesis_options();
  EXPECT_EQ(class_step_m(30.85, o), 50.0);    // dr_min wins on fine grids
  EXPECT_EQ(class_step_m(463.7, o), 463.0);   // floor(1/e) on coarse ones
  const QuotaTable t = compute_quotas(30.0, o);
  EXPECT_EQ(t.r_min_m, 50.0);
  EXPECT_EQ(t.r_max_m, 2550.0);  // x_max / 400 + dr: the largest class is the million-people one
  ASSERT_EQ(t.classes.size(), 50u);
  EXPECT_EQ(t.classes.front().radius_m, 2500.0);
  EXPECT_EQ(t.classes.front().quota, 4);
  // r = 50: 4 + 1068 * 0.98^4 = 989.06...
  EXPECT_EQ(t.classes.back().quota, 989);
}

TEST(Quotas, PastXmaxStaysAtUmin) {
  SitesOptions o = fixtures::thesis_options();
  EXPECT_EQ(units_for_people(2e6, o), 4.0);
  EXPECT_EQ(units_for_people(0, o), 1072.0);
}

TEST(Quotas, EmptyRangeIsBadInput) {
  SitesOptions o = fixtures::thesis_options();
  o.r_min_m = 1000;
  o.r_max_m = 1020;
  try {
    compute_quotas(30.0, o);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::bad_input);
    EXPECT_NE(std::string(e.what()).find("r_max"), std::string::npos);
  }
}

// Every invariant of a placement, checked independently of the implementation's metric.
void check_invariants(const fixtures::SitesScenario& s, const SitesResult& r, const SitesOptions& o, bool exact) {
  const Crs& crs = s.density.georef().crs;
  // Quotas never exceeded, and the counts add up.
  std::vector<int> per_class(r.quotas.size(), 0);
  for (const Site& site : r.sites) ++per_class[std::size_t(site.radius_class)];
  for (std::size_t k = 0; k < r.quotas.size(); ++k) {
    EXPECT_LE(r.quotas[k].kept, r.quotas[k].quota) << "class " << k;
    if (o.refill_rounds == 0) {
      EXPECT_LE(r.quotas[k].placed, r.quotas[k].quota) << "class " << k;
    }
    EXPECT_LE(r.quotas[k].kept, r.quotas[k].placed);
    EXPECT_EQ(r.quotas[k].kept, per_class[k]);
  }
  for (std::size_t i = 0; i < r.sites.size(); ++i) {
    const Site& t = r.sites[i];
    EXPECT_EQ(t.id, int(i));
    EXPECT_EQ(t.radius_m, r.quotas[std::size_t(t.radius_class)].radius_m);
    EXPECT_EQ(s.buildable(t.col, t.row), 1);
    if (i > 0) {
      EXPECT_GE(r.sites[i - 1].radius_m, t.radius_m);
    }
    // No disc touches an uninhabitable cell (or leaves the grid): brute force with GeographicLib.
    if (exact) {
      const CellMetrics m = cell_metrics(s.density.georef(), s.density.cols(), s.density.rows());
      const int reach_c = int(std::ceil(t.radius_m / m.width_m[std::size_t(t.row)])) + 2;
      const int reach_r = int(std::ceil(t.radius_m / m.height_m[std::size_t(t.row)])) + 2;
      for (int rr = t.row - reach_r; rr <= t.row + reach_r; ++rr)
        for (int cc = t.col - reach_c; cc <= t.col + reach_c; ++cc) {
          const bool inside = cc >= 0 && rr >= 0 && cc < s.density.cols() && rr < s.density.rows();
          if (inside && s.buildable(cc, rr) == 1 && std::isfinite(s.density(cc, rr))) continue;
          if (!inside && (cc < -1 || rr < -1 || cc > s.density.cols() || rr > s.density.rows())) continue;
          const auto p = s.density.georef().cell_centre(cc, rr);
          const double d = crs_distance_m(crs, t.x, t.y, p[0], p[1]);
          ASSERT_GT(d, t.radius_m - 1e-3) << "site " << i << " touches cell " << cc << "," << rr;
        }
    }
    // Inclusion rules against every larger (earlier) site.
    for (std::size_t j = 0; j < i; ++j) {
      const Site& S = r.sites[j];
      const double d = crs_distance_m(crs, S.x, S.y, t.x, t.y);
      if (d >= S.radius_m - 1e-6) continue;
      ASSERT_EQ(o.mode, SitesOptions::Mode::paris) << "manhattan keeps a centre inside site " << j;
      EXPECT_GT(d + t.radius_m, S.radius_m + 1e-6) << i << " wholly inside " << j;
      EXPECT_LE(2 * t.radius_m, S.radius_m) << i << " same rank inside " << j;
      EXPECT_GE(t.parent, 0) << i << " inside " << j << " but a root";
    }
    // The hierarchy: a parent contains the child's centre and is at least twice as large.
    if (t.parent >= 0) {
      ASSERT_LT(t.parent, int(i));
      const Site& p = r.sites[std::size_t(t.parent)];
      EXPECT_LT(crs_distance_m(crs, p.x, p.y, t.x, t.y), p.radius_m + 1e-6);
      EXPECT_LE(2 * t.radius_m, p.radius_m);
      EXPECT_EQ(t.depth, p.depth + 1);
    } else {
      EXPECT_EQ(t.depth, 0);
    }
  }
}

/// The sites of `s` placed with `o`, checked: more than `more_than` of them, every invariant.
SitesResult checked_placement(const fixtures::SitesScenario& s, const SitesOptions& o, std::size_t more_than, bool exact) {
  const SitesResult r = fixtures::place(s, o);
  EXPECT_GT(r.sites.size(), more_than);
  check_invariants(s, r, o, exact);
  return r;
}

bool same_sites(const std::vector<Site>& a, const std::vector<Site>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (a[i].col != b[i].col || a[i].row != b[i].row || a[i].radius_m != b[i].radius_m || a[i].parent != b[i].parent) return false;
  return true;
}

}  // namespace

TEST(Placement, CorsicaGeographicInvariants) {
  const auto s = fixtures::scenario_from_sample("gebco2022_15s_north_corsica_capcorse.asc");
  for (auto [mode, refill] : {std::pair{SitesOptions::Mode::paris, 8}, {SitesOptions::Mode::manhattan, 8}, {SitesOptions::Mode::paris, 0}}) {
    SitesOptions o = fixtures::thesis_options();
    o.seed = 7;
    o.mode = mode;
    o.refill_rounds = refill;
    const SitesResult r = checked_placement(s, o, 20u, true);
    EXPECT_EQ(r.dr_m, 462.0);  // 15" GEBCO at 43 N: cells 462.9 m north-south
    if (refill == 0) {
      const auto with_refill = [&] { SitesOptions f = o; f.refill_rounds = 8; return fixtures::place(s, f); }();
      EXPECT_GT(with_refill.sites.size(), r.sites.size()) << "refill adds sites";
    }
    if (mode == SitesOptions::Mode::paris) {
      int children = 0;
      for (const Site& t : r.sites) children += t.parent >= 0;
      EXPECT_GT(children, 0) << "no suburb at all";
    }
  }
}

TEST(Placement, VermontProjectedInvariants) {
  const auto s = fixtures::scenario_from_sample("whiteboxR_DEM_vermont.tif");
  SitesOptions o = fixtures::thesis_options();
  o.seed = 3;
  o.r_max_m = 800;
  checked_placement(s, o, 10u, true);
}

TEST(Placement, PerimeterModeKeepsQuotas) {
  const auto s = fixtures::scenario_from_sample("gebco2022_15s_north_corsica_capcorse.asc");
  SitesOptions o = fixtures::thesis_options();
  o.disc_test = SitesOptions::DiscTest::perimeter;
  checked_placement(s, o, 20u, false);
}

TEST(Placement, SameSeedSameSitesOtherSeedOtherSites) {
  const auto s = fixtures::scenario_from_sample("gebco2022_15s_north_corsica_capcorse.asc");
  SitesOptions o = fixtures::thesis_options();
  o.seed = 11;
  const SitesResult a = fixtures::place(s, o);
  const SitesResult b = fixtures::place(s, o);
  EXPECT_TRUE(same_sites(a.sites, b.sites));
  o.seed = 12;
  const SitesResult c = fixtures::place(s, o);
  EXPECT_FALSE(same_sites(a.sites, c.sites));
}

// A flat 41 x 41 grid of 100 m cells, buildable everywhere but one cell 223.6 m from the
// centre (2 cells east, 1 north). Classes 100, 400, 700 m (dr = 300). The centre has the
// highest density, so it grows first. Exact: 400 m would cover the hole, so 100 m. Perimeter:
// the circles of 100 m and 400 m pass on either side of the hole, so the site reaches 700 m.
TEST(Placement, ExactDiscSeesTheHolePerimeterMissesIt) {
  for (auto test : {SitesOptions::DiscTest::exact, SitesOptions::DiscTest::perimeter}) {
    auto s = fixtures::flat_scenario(41, 41, 100.0);
    s.density(20, 20) = 1.0f;
    s.buildable(22, 19) = 0;
    SitesOptions o = fixtures::thesis_options();
    o.r_min_m = 100;
    o.r_max_m = 1000;
    o.dr_min_m = 300;
    o.candidates = 41 * 41;  // every buildable cell
    o.disc_test = test;
    const SitesResult r = fixtures::place(s, o);
    ASSERT_EQ(r.quotas.size(), 3u);
    bool found = false;
    for (const Site& t : r.sites)
      if (t.col == 20 && t.row == 20) {
        found = true;
        EXPECT_EQ(t.radius_m, test == SitesOptions::DiscTest::exact ? 100.0 : 700.0);
        EXPECT_EQ(t.population, test == SitesOptions::DiscTest::exact ? 40000 : 280000);
      }
    EXPECT_TRUE(found);
  }
}

// Hand-made inclusions on a 100 m grid: S (r 1000) at (50,50); A (r 400) 700 m east: partial,
// half size -> suburb; B (r 300) 500 m north: wholly inside -> removed; C (r 600) 800 m west:
// partial but same rank -> removed; D (r 200) 1200 m south: outside -> root; E (r 100) partly in
// A only (360.6 m from A, 1019.8 m from S) -> child of A, depth 2; Manhattan keeps S, D and E.
TEST(Hierarchy, HandMadeInclusions) {
  auto s = fixtures::flat_scenario(101, 101, 100.0);
  const GridDistance distance(s.density.georef(), 101, 101);
  auto site = [](int col, int row, double r) {
    Site t;
    t.col = col, t.row = row, t.radius_m = r;
    return t;
  };
  const std::vector<Site> in = {site(50, 50, 1000), site(42, 50, 600), site(57, 50, 400), site(50, 45, 300), site(50, 62, 200),
                                site(60, 48, 100)};
  const auto paris = resolve_inclusions(in, SitesOptions::Mode::paris, distance, 101, 101);
  ASSERT_EQ(paris.size(), 4u);
  EXPECT_EQ(paris[0].col, 50);
  EXPECT_EQ(paris[1].col, 57);   // A
  EXPECT_EQ(paris[1].parent, 0);
  EXPECT_EQ(paris[2].row, 62);   // D
  EXPECT_EQ(paris[2].parent, -1);
  EXPECT_EQ(paris[3].col, 60);   // E
  EXPECT_EQ(paris[3].parent, 1);
  EXPECT_EQ(paris[3].depth, 2);
  const auto manhattan = resolve_inclusions(in, SitesOptions::Mode::manhattan, distance, 101, 101);
  ASSERT_EQ(manhattan.size(), 3u);  // S, D and E (A, which held E, is gone)
  EXPECT_EQ(manhattan[1].row, 62);
  EXPECT_EQ(manhattan[2].col, 60);
  for (const Site& t : manhattan) EXPECT_EQ(t.parent, -1);
}

TEST(GridDistance, MatchesGeodesicsOnGeographicGrid) {
  const auto s = fixtures::scenario_from_sample("gebco2022_15s_north_corsica_capcorse.asc");
  const auto& g = s.density.georef();
  const GridDistance distance(g, s.density.cols(), s.density.rows());
  for (auto [c0, r0, c1, r1] : {std::array<int, 4>{10, 10, 17, 3}, {100, 150, 92, 158}, {50, 0, 50, 7}, {3, 60, 12, 60}}) {
    const auto a = g.cell_centre(c0, r0), b = g.cell_centre(c1, r1);
    EXPECT_NEAR(distance(c0, r0, c1, r1), crs_distance_m(g.crs, a[0], a[1], b[0], b[1]), 1e-3);
  }
}
