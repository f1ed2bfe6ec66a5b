// Settlement sizes read from the land: catchments over the density model, the law split over a
// given count, and the catchment sizes of place_sites against their slow recomposition.
// SPDX-License-Identifier: MIT
#include <gtest/gtest.h>

#include <cmath>
#include <numeric>

#include "core/error.hpp"
#include "sites/fixtures.hpp"
#include "sites/sites.hpp"

using namespace terrapolis;
using namespace terrapolis::sites;

namespace {
Site at(int col, int row) {
  Site s;
  s.col = col, s.row = row;
  return s;
}
}  // namespace

// P_k = total k^-q / H_n(q) over a given count. q = 1, 100,000 over 5: as in CountLimitedBySpacing.
// q = 0: equal shares, 10 over 3 = 3.33 each, one more person to the first. 2 people over 3 ranks
// (H_3 = 11/6: 1.09, 0.55, 0.36): floors 1, 0, 0, the one left to the largest fraction (rank 2).
TEST(SettlementCatchment, SplitOverAGivenCount) {
  EXPECT_EQ(rank_size_split(100000, 1.0, 5), (std::vector<std::int64_t>{43796, 21898, 14598, 10949, 8759}));
  EXPECT_EQ(rank_size_split(10, 0.0, 3), (std::vector<std::int64_t>{4, 3, 3}));
  EXPECT_EQ(rank_size_split(2, 1.0, 3), (std::vector<std::int64_t>{1, 1, 0}));
  EXPECT_TRUE(rank_size_split(1000, 1.0, 0).empty());
  EXPECT_THROW(rank_size_split(1000, -0.5, 3), Error);
}

// A strip of 10 cells of 100 m, equal density. Centres in columns 1 and 6: columns 0-3 are nearer
// the first (column 3: 200 m against 300 m), 4-9 the second: 4 and 6 tenths of 1000 people.
// Centres in columns 2 and 6: column 4 is 200 m from both and goes to the lower index.
TEST(SettlementCatchment, NearestCentreByHand) {
  auto g = fixtures::flat_scenario(10, 1, 100.0);
  auto people = catchment_people(LandRasters(g.density, g.buildable), {at(1, 0), at(6, 0)}, 1000);
  EXPECT_NEAR(people[0], 400, 1e-9);
  EXPECT_NEAR(people[1], 600, 1e-9);
  people = catchment_people(LandRasters(g.density, g.buildable), {at(2, 0), at(6, 0)}, 1000);
  EXPECT_NEAR(people[0], 500, 1e-9);
  people = catchment_people(LandRasters(g.density, g.buildable), {at(6, 0), at(2, 0)}, 1000);
  EXPECT_NEAR(people[0], 600, 1e-9);
  EXPECT_NEAR(people[1], 400, 1e-9);
  // Unbuildable and nodata land holds nobody: columns 1-3 against 4-8.
  g.buildable[0] = 0;
  g.density[9] = std::numeric_limits<float>::quiet_NaN();
  people = catchment_people(LandRasters(g.density, g.buildable), {at(1, 0), at(6, 0)}, 1000);
  EXPECT_NEAR(people[0], 375, 1e-9);
  EXPECT_NEAR(people[1], 625, 1e-9);
  EXPECT_TRUE(catchment_people(LandRasters(g.density, g.buildable), {}, 1000).empty());
}

// 21 x 21 cells, density 0.001 but 1 at (5,5); centres at (5,5) and (15,15). The cells with
// col + row <= 20 (231, the anti-diagonal's ties included) go to the first: 1 + 230 x 0.001 =
// 1.23 of the mass 1 + 440 x 0.001 = 1.44; the other 210 cells 0.21. 14,400 people: 12,300 and 2,100.
TEST(SettlementCatchment, OnePeakGivesItsCentreTheCatchmentsPeople) {
  auto g = fixtures::flat_scenario(21, 21, 100.0);
  for (std::size_t i = 0; i < g.density.size(); ++i) g.density[i] = 0.001f;
  g.density(5, 5) = 1.0f;
  const auto people = catchment_people(LandRasters(g.density, g.buildable), {at(5, 5), at(15, 15)}, 14400);
  EXPECT_NEAR(people[0], 12300, 0.5);
  EXPECT_NEAR(people[1], 2100, 0.5);
  EXPECT_NEAR(people[0] + people[1], 14400, 1e-6);
}

// place_sites with sizes read from the catchments, against the slow obvious recomposition: the
// central places of the fixed law for all the people, their catchments of the settled share,
// the exponent of those of 1,000 or more, and the settled people split over as many settlements.
TEST(SettlementCatchment, SizesFollowTheCatchmentsExponent) {
  SilentProgress progress;
  auto g = fixtures::scenario_from_sample("gebco2022_15s_north_corsica_capcorse.asc");
  SitesOptions o;
  o.population = 200000;
  const SitesResult r = place_sites(g.density, g.buildable, o, progress);
  SitesOptions pilot = o;
  pilot.sizes = SitesOptions::Sizes::rank_size;
  pilot.urban_share = 1;
  pilot.influence_factor = 0;
  pilot.min_distance_share = 0;  // the first placement is unspaced
  const SitesResult central = place_sites(g.density, g.buildable, pilot, progress);
  std::vector<double> large;
  for (double p : catchment_people(LandRasters(g.density, g.buildable), central.sites, 110000))
    if (p >= 1000) large.push_back(p);
  ASSERT_GE(large.size(), 3u);
  const double q = rank_size_exponent(large);
  EXPECT_EQ(r.settled_population, 110000);  // 0.55 x 200,000
  EXPECT_DOUBLE_EQ(r.sizes_exponent, q);
  EXPECT_GT(q, 0.2);
  EXPECT_LT(q, 2.0);
  const auto expected = rank_size_split(110000, q, central.sites.size());
  int quota = 0;
  for (const auto& c : r.quotas) quota += c.quota;
  EXPECT_EQ(std::size_t(quota), expected.size());
  std::vector<std::int64_t> sizes;
  for (const Site& s : r.sites) sizes.push_back(s.population);
  std::sort(sizes.begin(), sizes.end(), std::greater<>());
  if (sizes.size() == expected.size()) EXPECT_EQ(sizes, expected);
  else for (std::size_t k = 0; k < sizes.size(); ++k) EXPECT_LE(sizes[k], expected.front());
}

// Same land, two grids: the same count of settlements; ten times the people, many more; the
// settled people add up to urban_share x the population when every settlement finds room.
TEST(SettlementCatchment, CountsFollowThePopulationNotTheGrid) {
  SilentProgress progress;
  SitesOptions o;
  o.population = 200000;
  o.spacing_km = 0;
  const auto coarse = fixtures::flat_scenario(200, 200, 100.0), fine = fixtures::flat_scenario(400, 400, 50.0);
  const SitesResult a = place_sites(coarse.density, coarse.buildable, o, progress);
  const SitesResult b = place_sites(fine.density, fine.buildable, o, progress);
  EXPECT_EQ(a.sites.size(), b.sites.size());
  EXPECT_EQ(a.sites.size(), rank_size_populations(200000, 1, 1000).size());
  std::int64_t people = 0;
  for (const auto& s : a.sites) people += s.population;
  EXPECT_EQ(people, 110000);
  o.population = 2000000;  // the law's count (its quotas): 400 km2 leave no room for every one of them
  int quota = 0;
  for (const auto& q : place_sites(coarse.density, coarse.buildable, o, progress).quotas) quota += q.quota;
  EXPECT_GT(std::size_t(quota), 3 * a.sites.size());
  o.urban_share = 0;
  EXPECT_THROW(place_sites(coarse.density, coarse.buildable, o, progress), Error);
}
