// Flat inland water: a lake the DEM shows level is found, noisy land and small flats are not, and
// roads given the mask never drive on the lake.
// SPDX-License-Identifier: MIT
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>

#include "hydro/flat_water.hpp"
#include "roads/anisotropic_search.hpp"
#include "roads/terrain_field.hpp"
#include "roads/roads_fixtures.hpp"

using namespace terrapolis;

namespace {

bool in_lake(int c, int r) { return std::hypot(c - 30.0, r - 30.0) <= 12.0; }

/// Integer heights as SRTM stores them: a gentle noisy slope, a lake at 100 m within 12 cells of
/// (30, 30), the shore rising from it, and a 2 x 2 flat patch (too small) in the north-west.
Dem lake_dem() {
  return roads::test::make_dem(60, 60, 10.0, [](int c, int r) {
    if (in_lake(c, r)) return 100.0;
    if (c >= 3 && c <= 4 && r >= 3 && r <= 4) return 150.0;
    const std::uint32_t h = std::uint32_t(c) * 2654435761u ^ std::uint32_t(r) * 40503u;
    return std::round(101.0 + 0.5 * std::hypot(c - 30.0, r - 30.0) - 12 * 0.5 + double(h % 5));
  });
}

}  // namespace

TEST(FlatWater, FindsTheLevelLakeAndNothingElse) {
  const Dem dem = lake_dem();
  const hydro::FlatWater w = hydro::detect_flat_water(dem, {0.02, 0.0, 0.0});
  EXPECT_EQ(w.lakes, 1u);
  int inside = 0, lake = 0, outside = 0;
  for (int r = 0; r < 60; ++r)
    for (int c = 0; c < 60; ++c) {
      lake += in_lake(c, r);
      if (in_lake(c, r)) inside += w.mask(c, r);
      else outside += w.mask(c, r);
    }
  // The lake's cells but the four tips of the disc (a shore cell is reached only from an inner
  // cell level with all its neighbours), and no land (the shore rises at once here).
  EXPECT_EQ(inside, lake - 4);
  EXPECT_EQ(outside, 0);
  EXPECT_NEAR(w.area_km2, inside * 100.0 / 1e6, 1e-9);
  // Above the lake's area, nothing is kept; 0 turns detection off.
  EXPECT_EQ(hydro::detect_flat_water(dem, {1.0, 0.0, 0.0}).lakes, 0u);
  EXPECT_EQ(hydro::detect_flat_water(dem, {0.0, 0.0, 0.0}).lakes, 0u);
  // Below the sea level a flat surface is the sea, not a lake.
  EXPECT_EQ(hydro::detect_flat_water(dem, {0.02, 0.0, 100.0}).lakes, 0u);
}

TEST(FlatWater, RoadsGoAroundOrBridgeTheLakeNeverOnIt) {
  const Dem dem = lake_dem();
  const hydro::FlatWater w = hydro::detect_flat_water(dem, {0.02, 0.0, 0.0});
  const roads::TerrainField terrain(dem, 0.0, 10.0, 0.0, &w.mask);
  EXPECT_TRUE(terrain.water(30, 30));
  roads::CostModel model = roads::default_cost_model();
  model.tunnel.enabled = false;
  for (const bool bridges : {false, true}) {
    model.bridge.enabled = bridges;
    const roads::RoadGraph graph(terrain, model, {3, 8, 1});
    const roads::SearchResult r = roads::shortest_path(graph, {10, 30}, {50, 30}, roads::SearchMethod::astar);
    ASSERT_TRUE(r.found);
    for (std::size_t i = 0; i + 1 < r.cells.size(); ++i)
      if (r.structures[i] == roads::Structure::road) {
        EXPECT_FALSE(terrain.water(r.cells[i].col, r.cells[i].row)) << bridges;
      }
    // Without the mask the flat lake is the cheapest ground, and the road runs straight across.
    const roads::TerrainField blind(dem, 0.0, 10.0, 0.0);
    const roads::RoadGraph g2(blind, model, {3, 8, 1});
    const roads::SearchResult r2 = roads::shortest_path(g2, {10, 30}, {50, 30}, roads::SearchMethod::astar);
    bool crossed = false;
    for (const roads::Cell& c : r2.cells) crossed |= in_lake(c.col, c.row);
    EXPECT_TRUE(crossed);
  }
}

TEST(FlatWater, ALevelValleyFloorThatFallsAwayIsNotALake) {
  // A dead-level plain at 100 m (40 x 40 cells) rising to the north and west but falling away to
  // the east and south, as an alluvial floor does downstream: half its surroundings lie below it.
  const Dem dem = roads::test::make_dem(60, 60, 10.0, [](int c, int r) {
    if (c >= 10 && c < 50 && r >= 10 && r < 50) return 100.0;
    if (c >= 50 || r >= 50) return 90.0 - double((c + r) % 3);
    return 110.0 + double((c * 7 + r * 3) % 4);
  });
  EXPECT_EQ(hydro::detect_flat_water(dem, {0.02, 0.0, 0.0}).lakes, 0u);
}
