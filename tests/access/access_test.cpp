// Accessibility: times against hand-computed walks and drives, water, bridges, tunnels, coverage.
// SPDX-License-Identifier: MIT
#include <gtest/gtest.h>

#include <cmath>
#include <algorithm>
#include <random>

#include "access/access.hpp"
#include "io/crs.hpp"

using namespace terrapolis;
using namespace terrapolis::access;

namespace {

constexpr double kCell = 100;  // metres

/// A projected grid (UTM 32N) of 100 m cells with elevation z(col, row).
template <class F>
Dem grid(int cols, int rows, F z) {
  Georef g;
  g.transform = {500000.0, kCell, 0.0, 5000000.0, 0.0, -kCell};
  g.crs = crs_from_user("EPSG:32632");
  Dem dem(cols, rows, g, 0.0f);
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) dem(c, r) = float(z(c, r));
  return dem;
}

RoadCells no_roads(const Dem& dem) { return {dem.like<float>(0.0f), dem.like<std::uint8_t>(0)}; }
Raster<std::uint8_t> all_land(const Dem& dem) { return dem.like<std::uint8_t>(1); }

/// Minutes to walk `metres` at slope s with the default options.
double walk_minutes(double metres, double s) { return metres / (0.6 * tobler_kmh(s) * 1000 / 60); }

SilentProgress quiet;

}  // namespace

TEST(Access, ToblerHikingFunction) {
  EXPECT_NEAR(tobler_kmh(0), 5.0366, 1e-3);       // 6 e^-0.175
  EXPECT_NEAR(tobler_kmh(-0.05), 6.0, 1e-12);     // fastest a little downhill
  EXPECT_LT(tobler_kmh(0.2), tobler_kmh(-0.2));   // climbing is slower than descending
}

TEST(Access, FlatGroundIsDistanceOverWalkingSpeed) {
  const Dem dem = grid(41, 41, [](int, int) { return 100.0; });
  const AccessResult r = travel_time(dem, all_land(dem), no_roads(dem), {{20, 20, 7}}, AccessOptions{}, quiet);
  EXPECT_EQ(r.minutes(20, 20), 0.0f);
  EXPECT_NEAR(r.minutes(30, 20), walk_minutes(1000, 0), 1e-3);   // 10 cells east
  EXPECT_NEAR(r.minutes(20, 5), walk_minutes(1500, 0), 1e-3);    // 15 cells north
  EXPECT_NEAR(r.minutes(30, 30), walk_minutes(1000 * std::sqrt(2.0), 0), 1e-3);  // the diagonal
  EXPECT_NEAR(r.minutes(40, 30), walk_minutes(100 * std::hypot(20.0, 10.0), 0), 1e-3);  // knight's moves
  // Any direction within 3 % of the straight line (knight's moves), every cell reached, one owner.
  for (int row = 0; row < 41; ++row)
    for (int col = 0; col < 41; ++col) {
      const double straight = walk_minutes(100 * std::hypot(col - 20.0, row - 20.0), 0);
      EXPECT_GE(r.minutes(col, row), straight - 1e-3);
      EXPECT_LE(r.minutes(col, row), 1.03 * straight + 1e-3);
      EXPECT_EQ(r.nearest(col, row), 7);
    }
  EXPECT_EQ(r.unreachable_land, 0u);
  // With 8 neighbours only, a knight's direction is walked as a diagonal and a straight step: slower.
  AccessOptions eight;
  eight.knight_moves = false;
  const AccessResult e = travel_time(dem, all_land(dem), no_roads(dem), {{20, 20, 7}}, eight, quiet);
  EXPECT_NEAR(e.minutes(40, 30), walk_minutes(1000 + 1000 * std::sqrt(2.0), 0), 1e-3);
}

TEST(Access, UphillToTheTownIsSlowerThanDownhill) {
  // A plane rising 5 m per cell eastwards (5 %): the town in the middle.
  const Dem dem = grid(21, 3, [](int c, int) { return 5.0 * c; });
  const AccessResult r = travel_time(dem, all_land(dem), no_roads(dem), {{10, 1, 0}}, AccessOptions{}, quiet);
  // From the west one climbs to the town, from the east one walks down to it.
  EXPECT_NEAR(r.minutes(0, 1), walk_minutes(1000, 0.05), 1e-3);  // Tobler: horizontal distance over speed
  EXPECT_NEAR(r.minutes(20, 1), walk_minutes(1000, -0.05), 1e-3);
  EXPECT_GT(r.minutes(0, 1), r.minutes(20, 1));
}

TEST(Access, RoadsAtTheirClassSpeedWaterOnlyByBridge) {
  // Columns 0-9 land, 10-14 a river, 15-29 land; the town on the west bank.
  const Dem dem = grid(30, 5, [](int, int) { return 10.0; });
  Raster<std::uint8_t> land = all_land(dem);
  for (int r = 0; r < 5; ++r)
    for (int c = 10; c < 15; ++c) land(c, r) = 0;
  const std::vector<Destination> town = {{0, 2, 1}};
  const AccessResult walled = travel_time(dem, land, no_roads(dem), town, AccessOptions{}, quiet);
  EXPECT_TRUE(std::isnan(walled.minutes(20, 2)));  // across the river: no way
  EXPECT_TRUE(std::isnan(walled.minutes(12, 2)));  // the river itself
  EXPECT_EQ(walled.nearest(20, 2), -1);
  EXPECT_EQ(walled.unreachable_land, 15u * 5u);
  // A departmental road along row 2, bridging the river: 60 km/h = 1000 m/min.
  VectorLayer road;
  road.geometry = GeometryType::line_string;
  road.crs = dem.georef().crs;
  road.fields = {{"class", FieldType::string}};
  road.features.push_back({{{dem.georef().cell_centre(0, 2), dem.georef().cell_centre(29, 2)}}, {std::string("departmental")}});
  const RoadCells cells = road_cells(road, dem, AccessOptions{});
  EXPECT_EQ(cells.kmh(12, 2), 60.0f);
  EXPECT_EQ(cells.kmh(12, 1), 0.0f);
  const AccessResult bridged = travel_time(dem, land, cells, town, AccessOptions{}, quiet);
  EXPECT_NEAR(bridged.minutes(29, 2), 2900.0 / 1000.0, 1e-4);
  // Beside the road: the drive to the nearest road cell, then a step on foot.
  EXPECT_NEAR(bridged.minutes(25, 4), 2500.0 / 1000.0 + walk_minutes(200, 0), 1e-3);
}

TEST(Access, TunnelsAreEnteredAtTheirPortalsOnly) {
  // A ridge (columns 8-12, 500 m high) crossed by a tunnel along row 3; the town to the west.
  const Dem dem = grid(21, 7, [](int c, int) { return c >= 8 && c <= 12 ? 500.0 : 10.0; });
  VectorLayer road;
  road.geometry = GeometryType::line_string;
  road.crs = dem.georef().crs;
  road.fields = {{"class", FieldType::string}, {"structure", FieldType::string}};
  const auto& g = dem.georef();
  road.features.push_back({{{g.cell_centre(0, 3), g.cell_centre(7, 3)}}, {std::string("local"), std::string("road")}});
  road.features.push_back({{{g.cell_centre(7, 3), g.cell_centre(13, 3)}}, {std::string("local"), std::string("tunnel")}});
  road.features.push_back({{{g.cell_centre(13, 3), g.cell_centre(20, 3)}}, {std::string("local"), std::string("road")}});
  const RoadCells cells = road_cells(road, dem, AccessOptions{});
  EXPECT_EQ(cells.tunnel(10, 3), 1);
  EXPECT_EQ(cells.tunnel(7, 3), 0);  // the portals carry the surface road too
  const AccessResult r = travel_time(dem, all_land(dem), cells, {{0, 3, 0}}, AccessOptions{}, quiet);
  // On the ridge above the tunnel one walks: the climb from the portal, not a step up from the tunnel.
  EXPECT_NEAR(r.minutes(10, 3), 1000.0 / (40.0 * 1000 / 60), 1e-4);  // in the tunnel: 1 km at 40 km/h
  EXPECT_GT(r.minutes(10, 2), r.minutes(10, 3) + 5.0);
}

TEST(Access, CoverageCountsPeopleWithinEachThreshold) {
  Raster<float> minutes(4, 1, Georef{}, 0.0f), people(4, 1, Georef{}, 0.0f);
  const float t[4] = {5, 20, 45, NAN};
  const float p[4] = {100, 300, 600, 50};
  for (int c = 0; c < 4; ++c) minutes(c, 0) = t[c], people(c, 0) = p[c];
  const Coverage c = coverage(minutes, people, {15, 30, 60});
  EXPECT_DOUBLE_EQ(c.total_people, 1050);
  EXPECT_DOUBLE_EQ(c.within_people[0], 100);
  EXPECT_DOUBLE_EQ(c.within_people[1], 400);
  EXPECT_DOUBLE_EQ(c.within_people[2], 1000);
  EXPECT_DOUBLE_EQ(c.unreachable_people, 50);
  EXPECT_DOUBLE_EQ(c.mean_minutes, (5 * 100 + 20 * 300 + 45 * 600) / 1000.0);
  EXPECT_DOUBLE_EQ(c.p90_minutes, 45);
}

TEST(Access, ByTilesTheWholeGridsTimesAndIds) {
  // Random hills, lakes, nodata, roads of every class (some tunnels), destinations: by tiles of 2
  // to 37 cells (a knight's move crosses a tile of 2), the times and ids are the whole grid's, bit for
  // bit, and so is the count of land that reaches nothing. A flat grid makes exact ties, where the
  // smaller id must win on both sides.
  std::mt19937_64 rng(34);
  std::uniform_real_distribution<double> u(0, 1);
  for (int trial = 0; trial < 14; ++trial) {
    const int cols = 30 + int(rng() % 50), rows = 25 + int(rng() % 45);
    const bool flat = trial % 5 == 0;
    std::vector<std::array<double, 4>> hills;
    for (int k = 0; k < 6; ++k) hills.push_back({u(rng) * cols, u(rng) * rows, 50 + 300 * u(rng), 3 + 8 * u(rng)});
    Dem dem = grid(cols, rows, [&](int c, int r) {
      if (flat) return 10.0;
      double z = 20;
      for (const auto& h : hills) z += h[2] * std::exp(-((c - h[0]) * (c - h[0]) + (r - h[1]) * (r - h[1])) / (2 * h[3] * h[3]));
      return z;
    });
    if (trial % 3 == 2) {  // geographic, 3" cells: a window's origin differs from the grid's in the last bits
      dem.georef().transform = {9.0, 1.0 / 1200, 0.0, 47.5, 0.0, -1.0 / 1200};
      dem.georef().crs = crs_from_user("EPSG:4326");
    }
    Dem holed = dem;
    Raster<std::uint8_t> land = all_land(dem);
    for (int k = 0; k < 3; ++k) {  // lakes
      const int c0 = int(rng() % std::uint64_t(cols)), r0 = int(rng() % std::uint64_t(rows)), rad = 1 + int(rng() % 5);
      for (int r = std::max(0, r0 - rad); r < std::min(rows, r0 + rad); ++r)
        for (int c = std::max(0, c0 - rad); c < std::min(cols, c0 + rad); ++c) land(c, r) = 0;
    }
    if (trial % 3 == 1) holed(int(rng() % std::uint64_t(cols)), int(rng() % std::uint64_t(rows))) = NAN;
    VectorLayer roads;
    roads.geometry = GeometryType::line_string;
    roads.crs = dem.georef().crs;
    roads.fields = {{"class", FieldType::string}, {"structure", FieldType::string}};
    const char* classes[] = {"motorway", "national", "departmental", "local"};
    for (int k = 0; k < 4; ++k) {
      const auto a = dem.georef().cell_centre(double(rng() % std::uint64_t(cols)), double(rng() % std::uint64_t(rows)));
      const auto b = dem.georef().cell_centre(double(rng() % std::uint64_t(cols)), double(rng() % std::uint64_t(rows)));
      roads.features.push_back({{{a, b}}, {std::string(classes[k]), std::string(k == 3 && trial % 2 ? "tunnel" : "road")}});
    }
    AccessOptions options;
    options.knight_moves = trial % 4 != 3;
    std::vector<Destination> towns;
    for (int k = 0; k < 2 + trial % 5; ++k) towns.push_back({int(rng() % std::uint64_t(cols)), int(rng() % std::uint64_t(rows)), 10 - k});
    if (flat) {  // mirror images: a whole column equally far from both; and two on one cell
      towns = {{cols / 2 - 9, rows / 2, 7}, {cols / 2 + 9, rows / 2, 4}, {cols / 2 - 9, rows / 2 - 9, 5}, {cols / 2 - 9, rows / 2, 2}};
      roads.features.clear();
    }
    if (flat) land = all_land(dem);
    const RoadCells cells = road_cells(roads, dem, options);
    const AccessResult whole = travel_time(holed, land, cells, towns, options, quiet);

    const int tile = trial == 0 ? 2 : 2 + int(rng() % 36);
    const ReadAccessWindow read = [&](int c0, int r0, int w, int h) {
      const Georef g = dem.georef().window(c0, r0);
      AccessWindow out{Raster<float>(w, h, g), Raster<std::uint8_t>(w, h, g), {}};
      for (int r = 0; r < h; ++r)
        for (int c = 0; c < w; ++c) {
          out.dem(c, r) = holed(c0 + c, r0 + r);
          out.passable(c, r) = land(c0 + c, r0 + r);
        }
      out.roads = road_cells(roads, out.dem, options, dem.georef(), c0, r0);  // drawn on each window, as the run does
      return out;
    };
    Raster<float> minutes = dem.like<float>(-7.0f);
    Raster<std::int32_t> nearest = dem.like<std::int32_t>(-7);
    int written = 0;
    const WriteAccessTile write = [&](int c0, int r0, AccessResult&& t) {
      ++written;
      EXPECT_EQ(t.minutes.georef().transform[0], dem.georef().transform[0] + c0 * dem.georef().transform[1]);
      for (int r = 0; r < t.minutes.rows(); ++r)
        for (int c = 0; c < t.minutes.cols(); ++c) {
          minutes(c0 + c, r0 + r) = t.minutes(c, r);
          nearest(c0 + c, r0 + r) = t.nearest(c, r);
        }
    };
    const TiledAccess tiled = travel_time_by_tiles(dem.georef(), cols, rows, tile, read, towns, options, write, quiet);
    EXPECT_EQ(std::size_t(written), tiled.tile_runs) << trial;  // each search written, the last of each tile final
    EXPECT_GE(tiled.tile_runs, tiled.tiles) << trial;
    EXPECT_EQ(tiled.unreachable_land, whole.unreachable_land) << trial;
    for (std::size_t i = 0; i < dem.size(); ++i) {
      ASSERT_EQ(std::isnan(whole.minutes[i]), std::isnan(minutes[i])) << trial << " cell " << i << " tile " << tile;
      if (!std::isnan(whole.minutes[i])) {
        ASSERT_EQ(whole.minutes[i], minutes[i]) << trial << " cell " << i << " tile " << tile;
      }
      ASSERT_EQ(whole.nearest[i], nearest[i]) << trial << " cell " << i << " tile " << tile;
    }
  }
}

TEST(Access, CoverageByBandsIsTheWholeGridsBitForBit) {
  // Times with ties, NaN (unreached) and nobody (people 0 or NaN), counted by bands of 1 to 9 rows
  // in two passes: the same figures, bit for bit; the 90th percentile against a sort of every cell.
  std::mt19937_64 rng(90);
  for (int trial = 0; trial < 20; ++trial) {
    const int cols = 13 + int(rng() % 20), rows = 11 + int(rng() % 30);
    const Dem dem = grid(cols, rows, [](int, int) { return 0.0; });
    Raster<float> minutes = dem.like<float>(0.0f), people = dem.like<float>(0.0f);
    for (std::size_t i = 0; i < minutes.size(); ++i) {
      minutes[i] = rng() % 10 == 0 ? NAN : float(rng() % 7 == 0 ? 30.0 : double(rng() % 100000) / 997.0);
      people[i] = rng() % 6 == 0 ? 0.0f : rng() % 17 == 0 ? NAN : float(double(rng() % 1000) / 7.0);
    }
    const std::vector<double> thresholds = {15, 30, 60};
    const Coverage whole = coverage(minutes, people, thresholds);
    const int band = 1 + int(rng() % 9);
    CoverageCount count(thresholds);
    for (int pass = 0; pass < 2; ++pass) {
      if (pass == 1 && !count.percentile_pass()) break;
      for (int r = 0; r < rows; r += band) {
        const std::size_t at = minutes.index(0, r), n = std::size_t(cols) * std::size_t(std::min(band, rows - r));
        pass == 0 ? count.count(minutes.data() + at, people.data() + at, n) : count.collect(minutes.data() + at, people.data() + at, n);
      }
    }
    const Coverage banded = count.finish();
    EXPECT_EQ(whole.total_people, banded.total_people) << trial;
    EXPECT_EQ(whole.unreachable_people, banded.unreachable_people) << trial;
    EXPECT_EQ(whole.within_people, banded.within_people) << trial;
    EXPECT_EQ(whole.mean_minutes, banded.mean_minutes) << trial;
    EXPECT_EQ(whole.p90_minutes, banded.p90_minutes) << trial;
    std::vector<std::pair<float, double>> all;  // the percentile by a sort of every reached cell
    double weight = 0;
    for (std::size_t i = 0; i < minutes.size(); ++i)
      if (people[i] > 0 && !std::isnan(minutes[i])) all.push_back({minutes[i], people[i]}), weight += people[i];
    std::sort(all.begin(), all.end());
    double seen = 0;
    float p90 = 0;
    for (const auto& [m, p] : all)
      if ((seen += p) >= 0.9 * weight) {
        p90 = m;
        break;
      }
    EXPECT_NEAR(banded.p90_minutes, p90, 1e-9 + 1e-6 * p90) << trial;
  }
}
