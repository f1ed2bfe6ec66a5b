// Settlement sizes from a population: the rank-size law, the urban-area allometry, and counts that
// follow the population rather than the grid.
// SPDX-License-Identifier: MIT
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <numeric>

#include "core/error.hpp"
#include "sites/fixtures.hpp"
#include "sites/sites.hpp"

using namespace terrapolis;
using namespace terrapolis::sites;

namespace {
/// The rank-size law with its fixed exponent, every person in a settlement.
SitesOptions fixed_law() {
  SitesOptions o;
  o.sizes = SitesOptions::Sizes::rank_size;
  o.urban_share = 1;
  return o;
}
}  // namespace

// 3000 people, q = 1, at least 1000 each: N = 2 gives 3000 x (1/2) / (1 + 1/2) = 1000 >= 1000;
// N = 3 gives 3000 x (1/3) / (11/6) = 545 < 1000. So two settlements, 2000 and 1000.
TEST(RankSize, HandComputedSplit) {
  EXPECT_EQ(rank_size_populations(3000, 1.0, 1000), (std::vector<std::int64_t>{2000, 1000}));
  EXPECT_TRUE(rank_size_populations(999, 1.0, 1000).empty());
  EXPECT_EQ(rank_size_populations(1000, 1.0, 1000), (std::vector<std::int64_t>{1000}));
  EXPECT_THROW(rank_size_populations(1000, 0.0, 1000), Error);
}

TEST(RankSize, TotalsSumToTheTarget) {
  for (double total : {1500.0, 43093.0, 94321.4, 1.6e6, 2.5e7})
    for (double q : {0.7, 1.0, 1.35}) {
      const auto sizes = rank_size_populations(total, q, 1000);
      ASSERT_FALSE(sizes.empty()) << total << " " << q;
      EXPECT_EQ(std::accumulate(sizes.begin(), sizes.end(), std::int64_t(0)), std::llround(total)) << total << " " << q;
      for (std::size_t k = 1; k < sizes.size(); ++k) ASSERT_LE(sizes[k], sizes[k - 1]);
      EXPECT_GE(sizes.back(), 999) << total << " " << q;  // the law's last rank, up to rounding
      // The next rank would fall below the minimum: N is the largest count the law allows.
      double h = 0;
      for (std::size_t k = 1; k <= sizes.size() + 1; ++k) h += std::pow(double(k), -q);
      EXPECT_LT(total * std::pow(double(sizes.size() + 1), -q) / h, 1000.0);
    }
}

// 100,000 people at most 5 settlements (the law alone gives 25: 100000 / (25 H_25) = 1048): P_k = 100000 / (k H_5),
// H_5 = 137/60: 43795.62, 21897.81, 14598.54, 10948.91, 8759.12; the floors add up to 99,997 and
// the three largest fractions (.91, .81, .62) get one person each.
TEST(RankSize, CountLimitedBySpacing) {
  EXPECT_EQ(rank_size_populations(100000, 1.0, 1000).size(), 25u);
  EXPECT_EQ(rank_size_populations(100000, 1.0, 1000, 5), (std::vector<std::int64_t>{43796, 21898, 14598, 10949, 8759}));
  EXPECT_EQ(rank_size_populations(100000, 1.0, 1000, 30).size(), 25u);  // a limit above the law's count changes nothing
  // Hexagons of sqrt(3)/2 x 7^2 = 42.435 km2: 1000 km2 hold 23 of them (23.57); with a floor of
  // 4000 people, 4 x 42.435 km2 each: 5 (5.89); at least one; spacing 0: no limit.
  SitesOptions o;
  EXPECT_EQ(settleable_count(1000, o), 23u);
  EXPECT_EQ(settleable_count(10, o), 1u);
  o.min_population = 4000;
  EXPECT_EQ(settleable_count(1000, o), 5u);
  o.spacing_km = 0;
  EXPECT_EQ(settleable_count(1000, o), std::numeric_limits<std::size_t>::max());
  o.spacing_km = -1;
  EXPECT_THROW(settleable_count(1000, o), Error);
}

TEST(RankSize, ExponentOfAPerfectLaw) {
  std::vector<double> sizes;
  for (int k = 1; k <= 300; ++k) sizes.push_back(1e6 * std::pow(k, -1.2));
  EXPECT_NEAR(rank_size_exponent(sizes), 1.2, 0.08);
  EXPECT_TRUE(std::isnan(rank_size_exponent({5000, 2000})));
}

// A = (1000 / 1500) km2 x (P / 1000)^(5/6): 1000 people, 0.6667 km2, r = sqrt(666 667 / pi) = 460.66 m;
// 100 000 people: 0.6667 x 100^(5/6) = 30.94 km2, r = 3138 m.
TEST(RankSize, UrbanRadius) {
  SitesOptions o;
  EXPECT_NEAR(urban_radius_m(1000, o), 460.66, 0.01);
  EXPECT_NEAR(urban_radius_m(1e5, o), std::sqrt(1000.0 / 1500 * std::pow(100.0, 5.0 / 6) * 1e6 / M_PI), 1e-6);
  EXPECT_NEAR(urban_radius_m(1e5, o), 3138.3, 0.5);
}

TEST(RankSize, ClassesCoverTheRadii) {
  SitesOptions o;
  const std::vector<std::int64_t> sizes = {100000, 20000, 1000};
  const QuotaTable t = rank_size_quotas(463.7, sizes, o);
  EXPECT_EQ(t.dr_m, 463.0);
  // 3138 m -> 7 steps of 463 m (3241 m); 1000 people (461 m) -> the first class, 463 m.
  ASSERT_EQ(t.classes.size(), 7u);
  EXPECT_EQ(t.classes.front().radius_m, 7 * 463.0);
  EXPECT_EQ(t.classes.front().quota, 1);
  EXPECT_EQ(t.classes.back().radius_m, 463.0);
  EXPECT_EQ(t.populations.back(), (std::vector<std::int64_t>{1000}));
  EXPECT_EQ(t.total(), 3);
}

// Same land (400 km2), cells of 100 m or 50 m: the same settlements. Ten times the people: more of
// them (the law alone: no spacing limit, which would hold 400 km2 to 9).
TEST(RankSize, CountsFollowThePopulationNotTheGrid) {
  SilentProgress progress;
  SitesOptions o = fixed_law();
  o.population = 200000;
  o.spacing_km = 0;
  const auto coarse = fixtures::flat_scenario(200, 200, 100.0), fine = fixtures::flat_scenario(400, 400, 50.0);
  const SitesResult a = place_sites(coarse.density, coarse.buildable, o, progress);
  const SitesResult b = place_sites(fine.density, fine.buildable, o, progress);
  const auto count = [](const SitesResult& r) {
    int n = 0;
    for (const auto& q : r.quotas) n += q.quota;
    return n;
  };
  EXPECT_EQ(count(a), count(b));
  EXPECT_EQ(count(a), int(rank_size_populations(200000, 1, 1000).size()));
  std::int64_t people = 0;
  for (const auto& s : a.sites) people += s.population;
  EXPECT_EQ(std::size_t(count(a)), a.sites.size());  // a flat, open region holds every settlement
  EXPECT_EQ(people, 200000);
  o.population = 2000000;
  const SitesResult c = place_sites(coarse.density, coarse.buildable, o, progress);
  EXPECT_GT(count(c), 5 * count(a));
  // No population given: the default density over the land (buildable cells, 400 km2).
  o.population = 0;
  const SitesResult d = place_sites(coarse.density, coarse.buildable, o, progress);
  EXPECT_TRUE(d.population_assumed);
  EXPECT_NEAR(d.land_area_km2, 400.0, 1e-6);
  EXPECT_EQ(d.target_population, 24000.0);
}

// The default spacing (7 km): 400 km2 hold 9 settlements (400 / 42.435 = 9.43) at 500 people/km2,
// on either grid; at 5,000/km2, denser than an urban centre, 10/3 times more (31); the sizes still
// add up to the population. 24,000 people: the law's own count, 8 (24000 / (8 H_8) = 1104 >= 1000 >
// 24000 / (9 H_9) = 943), is below the limit and stays.
TEST(RankSize, SpacingLimitsTheCountOnCrowdedLand) {
  SilentProgress progress;
  SitesOptions o = fixed_law();
  const auto coarse = fixtures::flat_scenario(200, 200, 100.0), fine = fixtures::flat_scenario(400, 400, 50.0);
  for (const auto& [people, room] : {std::pair{200000.0, 9}, std::pair{2000000.0, 31}})
    for (const auto* g : {&coarse, &fine}) {
      o.population = people;
      const SitesResult r = place_sites(g->density, g->buildable, o, progress);
      int quota = 0;
      for (const auto& q : r.quotas) quota += q.quota;
      EXPECT_EQ(quota, room) << people;
      EXPECT_EQ(r.room, room);
      EXPECT_TRUE(r.count_limited);
      EXPECT_EQ(r.unplaced, 0);
      ASSERT_EQ(r.sites.size(), std::size_t(room));
      std::int64_t sum = 0;
      for (const auto& s : r.sites) sum += s.population;
      EXPECT_EQ(sum, std::int64_t(people));
    }
  o.population = 24000;
  const SitesResult few = place_sites(coarse.density, coarse.buildable, o, progress);
  EXPECT_EQ(few.sites.size(), 8u);
  EXPECT_FALSE(few.count_limited);
  o.spacing_km = 0;
  EXPECT_EQ(place_sites(coarse.density, coarse.buildable, o, progress).room, 0);  // no limit
}

// 1000 people at 100 per km2, factor 1: 10 km2, a disc of sqrt(10e6 / pi) = 1784.12 m.
TEST(Suburbs, InfluenceRadiusByHand) {
  EXPECT_NEAR(influence_radius_m(1000, 1, 100), 1784.124, 1e-3);
  EXPECT_NEAR(influence_radius_m(4000, 1, 100), 2 * 1784.124, 1e-3);  // reach grows as the square root
  EXPECT_EQ(influence_radius_m(1000, 0, 100), 0.0);
}

// On a 100 m grid: S (20000 people, reach 3 km) at (50,50); D (12000) 1 km south: more than half
// of S, stays a root; M (8000, reach 1 km) 2 km east: in S's reach -> suburb of S; C (4000) 2.5 km
// west -> S; A (3000) 800 m east of M, 2.8 km from S: M pulls 8000 / 0.8^2 = 12500, S 20000 / 2.8^2
// = 2551 -> M, depth 2; B (1000) 1.5 km north -> S; E (1000) 4 km west: out of every reach.
TEST(Suburbs, StrongestPullAmongLargerSettlementsInReach) {
  auto g = fixtures::flat_scenario(101, 101, 100.0);
  const GridDistance distance(g.density.georef(), 101, 101);
  auto site = [](int col, int row, std::int64_t people) {
    Site t;
    t.col = col, t.row = row, t.population = people;
    return t;
  };
  std::vector<Site> s = {site(50, 50, 20000), site(50, 60, 12000), site(70, 50, 8000), site(25, 50, 4000),
                         site(78, 50, 3000),  site(50, 35, 1000),  site(10, 50, 1000)};
  const std::vector<double> reach = {3000, 1100, 1000, 500, 400, 300, 300};
  attach_suburbs(s, reach, distance);
  const std::vector<int> parents = {-1, -1, 0, 0, 2, 0, -1}, depths = {0, 0, 1, 1, 2, 1, 0};
  for (std::size_t k = 0; k < s.size(); ++k) {
    EXPECT_EQ(s[k].parent, parents[k]) << "site " << k;
    EXPECT_EQ(s[k].depth, depths[k]) << "site " << k;
  }
}

// The default run's hierarchy on a flat region: suburbs appear, none is larger than half its
// parent; with influence_factor 0 only Algorithm 15's partial inclusions remain, far fewer.
TEST(Suburbs, PlacementLinksSmallerSettlements) {
  SilentProgress progress;
  SitesOptions o = fixed_law();
  o.population = 200000;
  o.spacing_km = 0;  // the law's 45 settlements on 400 km2
  const auto flat = fixtures::flat_scenario(200, 200, 100.0);
  const auto suburbs = [&](const SitesResult& r) {
    int n = 0;
    for (const Site& t : r.sites)
      if (t.parent >= 0) {
        ++n;
        EXPECT_LE(2 * t.population, r.sites[std::size_t(t.parent)].population);
      }
    return n;
  };
  const int with = suburbs(place_sites(flat.density, flat.buildable, o, progress));
  o.influence_factor = 0;
  const int without = suburbs(place_sites(flat.density, flat.buildable, o, progress));
  EXPECT_GT(with, 2 * without + 5);
}

// Largest remainders by hand: 7 over three equal sizes is 2.33 each, floors 6, the one left to the
// first; exact shares stay exact; nothing to share of nothing.
TEST(Growth, ProportionalSplitByHand) {
  EXPECT_EQ(proportional_split(7, {1, 1, 1}), (std::vector<std::int64_t>{3, 2, 2}));
  EXPECT_EQ(proportional_split(10, {5, 3, 2}), (std::vector<std::int64_t>{5, 3, 2}));
  EXPECT_EQ(proportional_split(100, {0, 4}), (std::vector<std::int64_t>{0, 100}));
  EXPECT_EQ(proportional_split(0, {0, 0}), (std::vector<std::int64_t>{0, 0}));
  EXPECT_THROW(proportional_split(5, {0, 0}), Error);
  EXPECT_THROW(proportional_split(5, {3, -1}), Error);
}

// Random sizes and totals: the shares add up to the total, each within one person of its exact share.
TEST(Growth, ProportionalSplitAddsUp) {
  std::uint64_t state = 42;
  const auto next = [&] { return (state = state * 6364136223846793005ULL + 1442695040888963407ULL) >> 33; };
  for (int trial = 0; trial < 200; ++trial) {
    std::vector<std::int64_t> sizes(1 + next() % 40);
    for (auto& s : sizes) s = std::int64_t(1 + next() % 100000);
    const std::int64_t total = std::int64_t(next() % 1000000);
    const auto shares = proportional_split(total, sizes);
    const double sum = std::accumulate(sizes.begin(), sizes.end(), 0.0);
    EXPECT_EQ(std::accumulate(shares.begin(), shares.end(), std::int64_t(0)), total);
    for (std::size_t k = 0; k < sizes.size(); ++k) EXPECT_LT(std::abs(double(shares[k]) - double(total) * double(sizes[k]) / sum), 1.0);
  }
}

namespace {
/// Three existing places on the flat 20 km x 20 km region, far apart.
std::vector<Site> three_places(const Raster<float>& density) {
  std::vector<Site> places;
  const int cells[3][2] = {{30, 30}, {170, 40}, {100, 160}};
  const std::int64_t people[3] = {20000, 8000, 3000};
  for (int k = 0; k < 3; ++k) {
    Site s;
    s.col = cells[k][0], s.row = cells[k][1];
    const auto xy = density.georef().cell_centre(s.col, s.row);
    s.x = xy[0], s.y = xy[1];
    s.population = people[k];
    s.existing = true;
    s.name = "P";
    s.name.append(std::to_string(k));
    places.push_back(s);
  }
  return places;
}

/// The fixed law over 40,000 people with the three places given (31,000 of them).
SitesOptions with_three_places(const Raster<float>& density) {
  SitesOptions o = fixed_law();
  o.population = 40000;
  o.existing = three_places(density);
  return o;
}
}  // namespace

// +25 % of 31,000 settled people is 7,750 new ones. All to the existing places (new share 0): each
// grows by a quarter (5000, 2000, 750), nothing new is placed. Half to new settlements: the rank-size
// law's new places hold 3,875, the places the rest; the sums add up; positions never move.
TEST(Growth, SplitsAddUpAndPlacesKeepTheirCells) {
  SilentProgress progress;
  const auto flat = fixtures::flat_scenario(200, 200, 100.0);
  SitesOptions o = with_three_places(flat.density);
  o.growth = 0.25;
  const SitesResult gibrat = place_sites(flat.density, flat.buildable, o, progress);
  EXPECT_EQ(gibrat.growth_people, 7750);
  EXPECT_EQ(gibrat.growth_to_existing, 7750);
  EXPECT_EQ(gibrat.growth_to_new, 0);
  ASSERT_EQ(gibrat.sites.size(), 3u);
  EXPECT_EQ(gibrat.target_population, 50000);
  const std::int64_t grown[3] = {25000, 10000, 3750};
  for (int k = 0; k < 3; ++k) {
    const Site& s = gibrat.sites[std::size_t(k)];
    EXPECT_EQ(s.population, grown[k]);
    EXPECT_EQ(s.gained, grown[k] / 5);
    EXPECT_EQ(s.col, o.existing[std::size_t(k)].col);
    EXPECT_EQ(s.row, o.existing[std::size_t(k)].row);
  }
  o.growth_new_share = 0.5;
  const SitesResult mixed = place_sites(flat.density, flat.buildable, o, progress);
  EXPECT_EQ(mixed.growth_to_new, 3875);
  EXPECT_EQ(mixed.growth_to_existing, 3875);
  std::int64_t total = 0, created = 0, gained = 0;
  for (const Site& s : mixed.sites) {
    total += s.population;
    gained += s.gained;
    if (s.existing) continue;
    created += s.population;
    EXPECT_EQ(s.gained, s.population);
  }
  EXPECT_GT(mixed.sites.size(), 3u);
  EXPECT_EQ(created, 3875);
  EXPECT_EQ(gained, 7750);
  EXPECT_EQ(total, 31000 + 7750);
  // Growth 0 with every settled person in the places (urban share 1, population = their sum): nothing new.
  o.growth = 0;
  o.population = 31000;
  EXPECT_EQ(place_sites(flat.density, flat.buildable, o, progress).sites.size(), 3u);
  // No places, no growth scenario.
  o.growth = 0.1;
  o.existing.clear();
  EXPECT_THROW(place_sites(flat.density, flat.buildable, o, progress), Error);
}

// Land cut by a water channel every 2 km (a delta, a city of canals): no disc wider than 1 km is
// clear, so no settlement above about 6,400 people has a clear site. They are crowded in on the
// densest free candidates, and every settled person is in a settlement; the list stays in size
// order with parents first.
TEST(RankSize, EveryPersonPlacedOnLandCutByWater) {
  SilentProgress progress;
  auto land = fixtures::flat_scenario(200, 200, 100.0);
  for (int r = 0; r < 200; ++r)
    for (int c = 0; c < 200; c += 20) land.buildable(c, r) = 0;
  for (int r = 0; r < 200; ++r)  // density rising to the east: the order of the candidates is known
    for (int c = 0; c < 200; ++c) land.density(c, r) = land.buildable(c, r) ? float(0.2 + 0.7 * c / 200.0) : 0.0f;
  SitesOptions o = fixed_law();
  o.population = 500000;
  o.spacing_km = 0;
  const SitesResult r = place_sites(land.density, land.buildable, o, progress);
  std::int64_t people = 0;
  for (std::size_t k = 0; k < r.sites.size(); ++k) {
    const Site& s = r.sites[k];
    people += s.population;
    EXPECT_EQ(s.id, int(k));
    EXPECT_EQ(land.buildable(s.col, s.row), 1);
    if (s.parent >= 0) {
      EXPECT_LT(s.parent, s.id);
    }
    if (k > 0) {
      EXPECT_LE(s.radius_m, r.sites[k - 1].radius_m);
    }
  }
  EXPECT_EQ(r.unplaced, 0);
  EXPECT_GT(r.crowded, 0);
  EXPECT_EQ(people, 500000);
  EXPECT_EQ(r.sites.size(), rank_size_populations(500000, 1, 1000).size());
}

// Christaller's lattice holds a rural land; a region denser than an urban centre (1,500/km²) has
// its hexagons shrunk in proportion: 1,000 km² at 7 km hold 23 places, at 6,000/km² four times more.
TEST(RankSize, DenseRegionsHoldMorePlaces) {
  SitesOptions o;
  EXPECT_EQ(settleable_count(1000, o, 100 * 1000.0), 23u);
  EXPECT_EQ(settleable_count(1000, o, 1500 * 1000.0), 23u);
  EXPECT_EQ(settleable_count(1000, o, 6000 * 1000.0), 94u);  // 1000 / (42.435 / 4) = 94.3
}

// The law's tail from rank 2 (one existing place above): 3000 people, q = 1. N = 2: 3000 x (1/3) /
// (1/2 + 1/3) = 1200 >= 1000; N = 3: 3000 x (1/4) / (13/12) = 692 < 1000. So 1800 and 1200.
TEST(RankSize, TailOfTheLawBelowExistingPlaces) {
  EXPECT_EQ(rank_size_populations(3000, 1.0, 1000, std::numeric_limits<std::size_t>::max(), 2),
            (std::vector<std::int64_t>{1800, 1200}));
  EXPECT_EQ(rank_size_populations(3000, 1.0, 1000, std::numeric_limits<std::size_t>::max(), 1), rank_size_populations(3000, 1.0, 1000));
  EXPECT_THROW(rank_size_populations(3000, 1.0, 1000, 10, 0), Error);
}

// Three places of 20,000, 8,000 and 3,000 given, 40,000 people: the 9,000 left are the law's ranks 4
// on (9000 x (1/4) / (1/4 + ... + 1/9) = 2260 down to 1004 at rank 9; rank 10 would hold 821), all
// below the smallest given place, placed, and adding up.
TEST(RankSize, NewPlacesTakeTheRanksBelowTheGivenOnes) {
  SilentProgress progress;
  const auto flat = fixtures::flat_scenario(200, 200, 100.0);
  SitesOptions o = with_three_places(flat.density);
  const SitesResult r = place_sites(flat.density, flat.buildable, o, progress);
  std::vector<std::int64_t> created;
  for (const Site& s : r.sites)
    if (!s.existing) created.push_back(s.population);
  std::sort(created.begin(), created.end(), std::greater<>());
  EXPECT_EQ(created, rank_size_populations(9000, 1.0, 1000, std::numeric_limits<std::size_t>::max(), 4));
  ASSERT_EQ(created.size(), 6u);
  EXPECT_EQ(created.front(), 2260);
  EXPECT_EQ(std::accumulate(created.begin(), created.end(), std::int64_t(0)), 9000);
  EXPECT_EQ(r.unplaced_people, 0);
  // 500 people beside the places, too few for a settlement of 1,000: none made, the 500 reported.
  o.population = 31500;
  const SitesResult few = place_sites(flat.density, flat.buildable, o, progress);
  EXPECT_EQ(few.sites.size(), 3u);
  EXPECT_EQ(few.unplaced, 0);
  EXPECT_EQ(few.unplaced_people, 500);
}

// Density peaking at the centre of a flat 20 km x 20 km region: without the spacing rule the
// densest candidates, all near the peak, become the towns; with it no two centres of one class are
// closer than min_distance_share x sqrt(400 km2 / settlements) (the least any class keeps), and the
// two largest lie at least share x sqrt(400 km2 / 2) apart (the second keeps that from the first).
TEST(RankSize, CentresKeepTheCentralPlaceSpacing) {
  SilentProgress progress;
  auto peak = fixtures::flat_scenario(200, 200, 100.0);
  for (int r = 0; r < 200; ++r)
    for (int c = 0; c < 200; ++c) peak.density(c, r) = float(1.0 / (1.0 + std::hypot(c - 100.0, r - 100.0) / 20.0));
  SitesOptions o = fixed_law();
  o.population = 60000;
  o.spacing_km = 0;
  const GridDistance distance(peak.density.georef(), 200, 200);
  const auto closest = [&](const SitesResult& r) {  // of two centres of one class
    double best = std::numeric_limits<double>::infinity();
    for (std::size_t a = 0; a < r.sites.size(); ++a)
      for (std::size_t b = a + 1; b < r.sites.size(); ++b)
        if (r.sites[a].radius_class == r.sites[b].radius_class)
          best = std::min(best, distance(r.sites[a].col, r.sites[a].row, r.sites[b].col, r.sites[b].row));
    return best;
  };
  const auto two_largest = [&](const SitesResult& r) {
    return distance(r.sites[0].col, r.sites[0].row, r.sites[1].col, r.sites[1].row);
  };
  o.min_distance_share = 0.5;
  const SitesResult spaced = place_sites(peak.density, peak.buildable, o, progress);
  ASSERT_EQ(spaced.crowded, 0);
  const double metres = 0.5 * std::sqrt(400e6 / double(spaced.sites.size()));
  EXPECT_GE(closest(spaced), metres);
  ASSERT_GE(spaced.sites.size(), 2u);
  EXPECT_GE(two_largest(spaced), 0.5 * std::sqrt(400e6 / 2));
  o.min_distance_share = 0;
  const SitesResult packed = place_sites(peak.density, peak.buildable, o, progress);
  EXPECT_EQ(packed.sites.size(), spaced.sites.size());
  EXPECT_LT(closest(packed), 0.5 * metres);
  EXPECT_LT(two_largest(packed), 0.5 * std::sqrt(400e6 / 2));
}
