// The placement read by blocks and bands (a mosaic's tiles) against the whole grid at once: the same sites.
// SPDX-License-Identifier: MIT
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "core/error.hpp"
#include "sites/fixtures.hpp"
#include "sites/sites.hpp"

using namespace terrapolis;
using namespace terrapolis::sites;

namespace {

/// A landscape of hills (density), with lakes and steep land cut out of the buildable mask, a
/// nodata corner, on a projected 100 m grid or a geographic 3" one.
fixtures::SitesScenario random_land(std::mt19937_64& random, bool geographic) {
  std::uniform_int_distribution<int> side(90, 230);
  const int cols = side(random), rows = side(random);
  Georef g;
  if (geographic) {
    const double cell = 3.0 / 3600;
    g.transform = {8.0, cell, 0.0, 61.0, 0.0, -cell};  // far north: the columns narrow from row to row
    g.crs.wkt = "GEOGCS[\"WGS 84\"]";
    g.crs.epsg = 4326;
    g.crs.geographic = true;
  } else {
    g = fixtures::flat_scenario(1, 1, 100).density.georef();
  }
  fixtures::SitesScenario s{Raster<float>(cols, rows, g, 0.0f), Raster<std::uint8_t>(cols, rows, g, 0)};
  s.buildable.nodata = 255;
  std::uniform_real_distribution<double> unit(0, 1);
  struct Bump { double c, r, width, height; };
  std::vector<Bump> bumps(6);
  for (Bump& b : bumps) b = {unit(random) * cols, unit(random) * rows, 5 + 30 * unit(random), unit(random)};
  const double water = 0.15 + 0.2 * unit(random);
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) {
      if (c + r < 12) {  // nodata
        s.density(c, r) = std::numeric_limits<float>::quiet_NaN();
        s.buildable(c, r) = 255;
        continue;
      }
      double d = 0;
      for (const Bump& b : bumps) d += b.height * std::exp(-((c - b.c) * (c - b.c) + (r - b.r) * (r - b.r)) / (2 * b.width * b.width));
      const double v = std::min(1.0, d + 0.05 * unit(random));
      s.density(c, r) = float(v);
      s.buildable(c, r) = v > water && unit(random) > 0.02 ? 1 : 0;  // and scattered steep cells
    }
  return s;
}

/// The land as a mosaic's tiles give it: each window a copy of its own cells alone (a read outside
/// it reads past its vectors, which AddressSanitizer reports), in blocks and bands of the given sizes.
class CopiedLand : public Land {
 public:
  CopiedLand(const fixtures::SitesScenario& s, int block, int band)
      : Land(s.density.georef(), s.density.cols(), s.density.rows()), s_(s), block_(block), band_(band) {}
  LandView window(int col0, int row0, int w, int h) const override {
    EXPECT_TRUE(col0 >= 0 && row0 >= 0 && w > 0 && h > 0 && col0 + w <= cols() && row0 + h <= rows());
    LandView v;
    v.col0 = col0, v.row0 = row0, v.cols = w, v.rows = h;
    v.stride = std::size_t(w);
    for (int r = row0; r < row0 + h; ++r)
      for (int c = col0; c < col0 + w; ++c) {
        v.own_density.push_back(s_.density(c, r));
        v.own_buildable.push_back(s_.buildable(c, r) == 1 ? 1 : 0);
      }
    v.density = v.own_density.data();
    v.buildable = v.own_buildable.data();
    return v;
  }
  int block_side(int, int) const override { return block_; }
  int band_rows() const override { return band_; }

 private:
  const fixtures::SitesScenario& s_;
  int block_, band_;
};

void expect_same(const SitesResult& a, const SitesResult& b, const std::string& what) {
  ASSERT_EQ(a.sites.size(), b.sites.size()) << what;
  for (std::size_t k = 0; k < a.sites.size(); ++k) {
    const Site &x = a.sites[k], &y = b.sites[k];
    EXPECT_TRUE(x.col == y.col && x.row == y.row && x.radius_m == y.radius_m && x.radius_class == y.radius_class &&
                x.population == y.population && x.density == y.density && x.parent == y.parent && x.depth == y.depth &&
                x.existing == y.existing && x.gained == y.gained)
        << what << ": site " << k;
  }
  EXPECT_EQ(a.candidates, b.candidates) << what;
  EXPECT_EQ(a.crowded, b.crowded) << what;
  EXPECT_EQ(a.unplaced, b.unplaced) << what;
  EXPECT_EQ(a.sizes_exponent, b.sizes_exponent) << what;
  EXPECT_EQ(a.land_area_km2, b.land_area_km2) << what;
}

// Every way of placing: both quota tables, both disc tests, sizes from the catchments, existing
// places and a growth scenario; on random land read whole, then by blocks of 7 to 61 cells and
// bands of 1 to 40 rows, each window a copy of its cells alone. The disc tests read each block
// grown by the largest disc: with a margin too narrow a clear disc near a block's edge would be seen
// clear too far, and the sites differ.
TEST(LandByBlocks, SameSitesAsTheWholeGrid) {
  std::mt19937_64 random(20261206);
  SilentProgress progress;
  int placed = 0;
  for (int trial = 0; trial < 16; ++trial) {
    const bool geographic = trial % 2 == 1;
    const fixtures::SitesScenario land = random_land(random, geographic);
    SitesOptions o;
    switch (trial % 4) {
      case 0: o.sizes = SitesOptions::Sizes::rank_size; break;
      case 1: o = fixtures::thesis_options(); o.quota_scale = 0.01; o.disc_test = SitesOptions::DiscTest::perimeter; break;
      case 2: o.disc_test = SitesOptions::DiscTest::perimeter; o.mode = SitesOptions::Mode::manhattan; break;
      default: break;  // the defaults: catchment sizes, exact discs, paris
    }
    o.population = 4000 + 6000 * double(trial);
    o.min_population = 300;
    o.town_density_per_km2 = 400;  // large discs against the blocks
    o.seed = std::uint64_t(trial) + 1;
    if (trial % 5 == 3 && o.quotas == SitesOptions::Quotas::rank_size) {  // existing places, and a growth scenario on every other
      for (int k = 0; k < 3; ++k) {
        Site e;
        e.col = land.density.cols() / 4 * (k + 1), e.row = land.density.rows() / 2;
        e.population = 800 * (k + 1);
        e.existing = true;
        e.name = "place " + std::to_string(k);
        o.existing.push_back(e);
      }
      if (trial % 2 == 1) o.growth = 0.2, o.growth_new_share = 0.5;
    }
    const SitesResult whole = place_sites(LandRasters(land.density, land.buildable), o, progress);
    placed += int(whole.sites.size());
    for (const auto& [block, band] : {std::pair{7, 1}, std::pair{23, 40}, std::pair{61, 9}}) {
      const SitesResult tiled = place_sites(CopiedLand(land, block, band), o, progress);
      expect_same(whole, tiled, "trial " + std::to_string(trial) + ", blocks of " + std::to_string(block));
    }
    // The rasters' own views by blocks (no copy) too.
    expect_same(whole, place_sites(LandRasters(land.density, land.buildable, 31, 5), o, progress), "trial " + std::to_string(trial));
  }
  EXPECT_GT(placed, 16 * 3);  // the trials place settlements, not nothing
}

// The same on a real DEM's land (Cap Corse), with the defaults.
TEST(LandByBlocks, CorsicaByTilesOfOneHundredCells) {
  const fixtures::SitesScenario land = fixtures::scenario_from_sample("gebco2022_15s_north_corsica_capcorse.asc");
  SilentProgress progress;
  const SitesResult whole = place_sites(LandRasters(land.density, land.buildable), SitesOptions(), progress);
  const SitesResult tiled = place_sites(CopiedLand(land, 100, 37), SitesOptions(), progress);
  ASSERT_GT(whole.sites.size(), 5u);
  expect_same(whole, tiled, "Cap Corse");
  const std::vector<double> a = catchment_people(LandRasters(land.density, land.buildable), whole.sites, 1e5);
  const std::vector<double> b = catchment_people(CopiedLand(land, 0, 13), whole.sites, 1e5);
  EXPECT_EQ(a, b);
}

TEST(LandByBlocks, BuildableNodataOfOneIsRefused) {
  fixtures::SitesScenario land = fixtures::flat_scenario(10, 10, 100);
  land.buildable.nodata = 1;
  EXPECT_THROW(LandRasters(land.density, land.buildable), Error);
}

}  // namespace
