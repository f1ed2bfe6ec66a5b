// Road corridors: hand-computed zone widths and areas, analytic cut and fill, the levelled DEM's
// differences, side slopes no steeper than the material's, structures without earthworks.
// SPDX-License-Identifier: MIT
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "core/error.hpp"
#include "core/geodesy.hpp"
#include "io/raster_io.hpp"
#include "roads/corridor.hpp"
#include "roads/cost_model.hpp"
#include "roads/windowed_route.hpp"
#include "roads_fixtures.hpp"
#include "support/georefs.hpp"
#include "support/windows.hpp"

using namespace terrapolis;
using namespace terrapolis::roads;

namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

/// A straight road along `row` from column c0 to c1, points every half cell, deck from `deck(col)`.
RoadGeometry straight_road(double row, double c0, double c1, const std::function<double(double)>& deck) {
  RoadGeometry g;
  for (double c = c0; c <= c1 + 1e-9; c += 0.5) {
    g.points.push_back({c, row});
    g.z.push_back(deck(c));
  }
  g.segments.assign(g.points.size() - 1, Structure::road);
  return g;
}

CorridorOptions options(double angle_deg) {
  CorridorOptions o;
  o.half_width_m = 4;
  o.side_angle_deg = angle_deg;
  return o;
}

double field(const VectorLayer& layer, std::size_t feature, const std::string& name) {
  return std::get<double>(layer.features[feature].values[std::size_t(layer.field_index(name))]);
}

/// Steepest slope between 8-neighbours of `z` (rise over run) within columns c0..c1, on a
/// projected grid of `cell` m.
double steepest(const Dem& z, double cell, int c0 = 0, int c1 = -1) {
  if (c1 < 0) c1 = z.cols() - 1;
  double worst = 0;
  for (int r = 0; r < z.rows(); ++r)
    for (int c = c0; c <= c1; ++c)
      for (const auto& [dc, dr] : {std::pair{1, 0}, std::pair{0, 1}, std::pair{1, 1}, std::pair{1, -1}}) {
        const int c2 = c + dc, r2 = r + dr;
        if (c2 > c1 || r2 < 0 || r2 >= z.rows()) continue;
        worst = std::max(worst, std::fabs(z(c2, r2) - z(c, r)) / (cell * std::hypot(dc, dr)));
      }
  return worst;
}

/// Cut and fill (m³) as the sums over cells of (levelled - dem) x cell area, split by sign.
std::pair<double, double> levelled_volumes(const Dem& dem, const Dem& levelled) {
  const CellMetrics metrics = cell_metrics(dem.georef(), dem.cols(), dem.rows());
  double cut = 0, fill = 0;
  for (int r = 0; r < dem.rows(); ++r)
    for (int c = 0; c < dem.cols(); ++c) {
      const double d = double(levelled(c, r)) - double(dem(c, r));
      (d > 0 ? fill : cut) += std::fabs(d) * metrics.area_m2[std::size_t(r)];
    }
  return {cut, fill};
}

}  // namespace

TEST(Corridor, MaterialsFromTheThesisTable) {
  // Peytavie 2010 table 2.3, lower bounds: sand 30-35, stones 40-45, earth 25-40; rock 1 across for 2 up.
  EXPECT_EQ(repose_angle_deg("sand"), 30);
  EXPECT_EQ(repose_angle_deg("earth"), 25);
  EXPECT_EQ(repose_angle_deg("stones"), 40);
  EXPECT_NEAR(std::tan(repose_angle_deg("rock") * kDeg), 2.0, 1e-12);
  EXPECT_THROW(repose_angle_deg("clay"), Error);
  Raster<float> slopes;
  EXPECT_THROW(earthwork_options(options(90), slopes), Error);
  EXPECT_THROW(earthwork_options(options(0), slopes), Error);
}

TEST(Corridor, FlatPlaneGivesLengthTimesTwoRAndNoVolume) {
  const double cell = 1.0;
  const Dem dem = roads::test::make_dem(60, 40, cell, [](int, int) { return 100.0; });
  const TerrainField terrain(dem, 0.0, 10.0, 0.0);
  const RoadGeometry road = straight_road(20.0, 10, 50, [](double) { return 100.0; });
  const Corridors c = corridors(terrain, {&road}, options(30));
  ASSERT_EQ(c.sections.size(), 1u);
  // On a plane the sides meet the ground at once: R = r, area = 40 m x 2 x 4 m (square ends).
  EXPECT_NEAR(c.sections[0].mean_half_width_m, 4.0, 1e-9);
  const VectorLayer layer = corridors_layer(terrain, c);
  ASSERT_EQ(layer.features.size(), 3u);  // earthworks, carriageway, the run's land take
  for (std::size_t i = 0; i < 3; ++i) EXPECT_NEAR(field(layer, i, "area_ha"), 40 * 2 * 4 / 1e4, 1e-6);
  EXPECT_EQ(std::get<std::string>(layer.features[2].values[3]), "land_take");
  EXPECT_EQ(c.run.cut_m3, 0);
  EXPECT_EQ(c.run.fill_m3, 0);
  EXPECT_NEAR(c.run.land_take_ha, 40 * 2 * 4 / 1e4, 1e-6);
  EXPECT_FALSE(c.vegetation);
}

TEST(Corridor, ContourRoadOnAnInclinedPlaneGivesTheAnalyticWidthAndVolumes) {
  // A hillside rising tan(beta) = 0.2 southwards; the road along a contour (level deck).
  const double cell = 0.5, tan_beta = 0.2, r = 4;
  const int cols = 80, rows = 80;
  const Dem dem = roads::test::make_dem(cols, rows, cell, [&](int, int row) { return 100.0 + tan_beta * row * cell; });
  const TerrainField terrain(dem, 0.0, 10.0, 0.0);
  const double row = 40.0, deck = 100.0 + tan_beta * row * cell;
  // From edge to edge of the grid, so that every cell's nearest point is within the road.
  const RoadGeometry road = straight_road(row, -0.5, cols - 0.5, [&](double) { return deck; });
  const double length = cols * cell;
  for (const double angle : {30.0, 40.0}) {
    const double tan_a = std::tan(angle * kDeg);
    const CorridorOptions o = options(angle);
    const Corridors c = corridors(terrain, {&road}, o);
    // Hand computation: the cut side meets the ground where x tan(beta) = (x - r) tan(alpha).
    const double big_r = r * tan_a / (tan_a - tan_beta);
    ASSERT_EQ(c.sections.size(), 1u);
    EXPECT_NEAR(c.sections[0].mean_half_width_m, big_r, 1e-4) << angle;  // the DEM holds float heights
    EXPECT_NEAR(c.sections[0].max_half_width_m, big_r, 1e-4) << angle;
    EXPECT_NEAR(c.run.land_take_ha, length * 2 * big_r / 1e4, 1e-5 * length * 2 * big_r / 1e4) << angle;
    // Cut and fill cross-sections: the triangle of ground above the deck minus the side's wedge.
    const double section = big_r * big_r * tan_beta / 2 - (big_r - r) * (big_r - r) * tan_a / 2;
    EXPECT_NEAR(c.run.cut_m3, section * length, 1e-5 * section * length) << angle;
    EXPECT_NEAR(c.run.fill_m3, section * length, 1e-5 * section * length) << angle;
    // The levelled DEM's differences give the same volumes, to the cells' resolution.
    Raster<float> slopes;
    const Dem levelled = earthworks(dem, terrain, {&road}, earthwork_options(o, slopes));
    const auto [cut, fill] = levelled_volumes(dem, levelled);
    EXPECT_NEAR(cut, c.run.cut_m3, 0.02 * c.run.cut_m3) << angle;
    EXPECT_NEAR(fill, c.run.fill_m3, 0.02 * c.run.fill_m3) << angle;
    // No side steeper than the material allows (the hillside itself is gentler).
    EXPECT_LE(steepest(levelled, cell), tan_a + 1e-3) << angle;
  }
  // A steeper material needs a narrower zone.
  const Corridors sand = corridors(terrain, {&road}, options(repose_angle_deg("sand")));
  const Corridors earth = corridors(terrain, {&road}, options(repose_angle_deg("earth")));
  EXPECT_LT(sand.run.land_take_ha, earth.run.land_take_ha);
}

TEST(Corridor, EmbankmentAcrossATrenchGivesTheAnalyticFill) {
  // A flat plain at 100 m cut by a trench 10 m wide and h = 5 m deep, crossed by a level road.
  const double cell = 0.5, r = 4, h = 5, width = 10, angle = 30;
  const Dem dem = roads::test::make_dem(160, 100, cell, [&](int col, int) { return col >= 60 && col < 80 ? 100.0 - h : 100.0; });
  const TerrainField terrain(dem, 0.0, 10.0, 0.0);
  const RoadGeometry road = straight_road(50.0, -0.5, 159.5, [](double) { return 100.0; });
  const CorridorOptions o = options(angle);
  const Corridors c = corridors(terrain, {&road}, o);
  // The embankment's cross-section: a trapezoid, top 2r, sides at the angle down to the floor.
  const double fill = width * h * (2 * r + h / std::tan(angle * kDeg));
  EXPECT_NEAR(c.run.fill_m3, fill, 0.01 * fill);
  EXPECT_EQ(c.run.cut_m3, 0);
  EXPECT_NEAR(c.sections[0].max_half_width_m, r + h / std::tan(angle * kDeg), 1e-6);
  // Land take: 2r along the road, 2R over the trench (the bilinear walls ramp over one cell).
  const double zone = (160 * cell - width) * 2 * r + width * 2 * (r + h / std::tan(angle * kDeg));
  EXPECT_NEAR(c.run.land_take_ha * 1e4, zone, 0.02 * zone);
  Raster<float> slopes;
  const Dem levelled = earthworks(dem, terrain, {&road}, earthwork_options(o, slopes));
  const auto [cut, filled] = levelled_volumes(dem, levelled);
  EXPECT_NEAR(filled, fill, 0.02 * fill);
  EXPECT_EQ(cut, 0);
  // On the trench's floor the fill's sides keep to the angle (its walls stay as they were).
  EXPECT_LE(steepest(levelled, cell, 60, 79), std::tan(angle * kDeg) + 1e-3);
}

TEST(Corridor, GeodesicAreasAndPerRoadFiguresOnARealDem) {
  const Dem dem = read_dem(std::string(TERRAPOLIS_SAMPLES) + "/gebco2022_15s_north_corsica_capcorse.asc");
  const TerrainField terrain(dem, 0.0, 10.0, 10.0);
  const CostModel model = default_cost_model();
  // Two roads on Cap Corse's land: from the west coast up to the ridge, and from it down east.
  const RoadGeometry a = surface_geometry(terrain, model, {{145, 125}, {148, 120}, {155, 100}, {160, 80}});
  const RoadGeometry b = surface_geometry(terrain, model, {{155, 100}, {162, 110}, {170, 122}});
  const Corridors c = corridors(terrain, {&a, &b}, options(repose_angle_deg("earth")));
  ASSERT_GT(c.run.cut_m3 + c.run.fill_m3, 0);
  ASSERT_EQ(c.roads.size(), 2u);
  EXPECT_NEAR(c.roads[0].cut_m3 + c.roads[1].cut_m3, c.run.cut_m3, 1e-6 * c.run.cut_m3);
  EXPECT_NEAR(c.roads[0].fill_m3 + c.roads[1].fill_m3, c.run.fill_m3, 1e-6 * c.run.fill_m3);
  // They meet at the ridge: the run's land take is their union, less than the sum by the overlap.
  EXPECT_LT(c.run.land_take_ha, c.roads[0].land_take_ha + c.roads[1].land_take_ha);
  EXPECT_GT(c.run.land_take_ha, 0.95 * (c.roads[0].land_take_ha + c.roads[1].land_take_ha));
  for (const SectionCorridor& s : c.sections) {
    if (s.structure != "road") continue;
    EXPECT_GE(s.mean_half_width_m, 4.0);
    EXPECT_GE(s.totals.land_take_ha, 0.99 * s.length_m * 8 / 1e4);  // at least the carriageway
  }
  // Geodesic: the carriageway polygons' areas are their length times 2r within the corners' slack.
  const VectorLayer layer = corridors_layer(terrain, c);
  double lane_ha = 0, length_m = 0;
  for (std::size_t i = 0; i < layer.features.size(); ++i)
    if (std::get<std::string>(layer.features[i].values[3]) == "carriageway") {
      lane_ha += field(layer, i, "area_ha");
      length_m += field(layer, i, "length_m");
    }
  EXPECT_NEAR(lane_ha, length_m * 8 / 1e4, 0.01 * length_m * 8 / 1e4);
  // The roads layer gains the per-road figures.
  VectorLayer roads;
  roads.fields = {{"from", FieldType::integer}};
  roads.features.resize(2, Feature{{}, {std::int64_t(0)}});
  add_corridor_fields(roads, c);
  EXPECT_NEAR(field(roads, 0, "cut_m3") + field(roads, 1, "cut_m3"), c.run.cut_m3, 0.2);
  EXPECT_TRUE(std::holds_alternative<std::monostate>(roads.features[0].values[std::size_t(roads.field_index("cleared_ha"))]));
}

TEST(Corridor, BridgesAndTunnelsHaveNoEarthworks) {
  const Dem dem = roads::test::make_dem(60, 40, 1.0, [](int, int r) { return 100.0 + 0.3 * r; });
  const TerrainField terrain(dem, 0.0, 10.0, 0.0);
  RoadGeometry road = straight_road(20.0, 5, 55, [](double) { return 100.0 + 0.3 * 20; });
  for (auto& s : road.segments) s = Structure::bridge;
  const Corridors c = corridors(terrain, {&road}, options(30));
  EXPECT_EQ(c.run.cut_m3 + c.run.fill_m3, 0);
  EXPECT_EQ(c.run.land_take_ha, 0);
  const VectorLayer layer = corridors_layer(terrain, c);
  ASSERT_EQ(layer.features.size(), 1u);  // the deck only
  EXPECT_EQ(std::get<std::string>(layer.features[0].values[3]), "carriageway");
  EXPECT_NEAR(field(layer, 0, "area_ha"), 50 * 8 / 1e4, 1e-6);
}

TEST(Corridor, SideAngleMapAndVegetation) {
  // The contour road of the inclined plane; rock (63.4 deg) north of the road, the default south.
  const double cell = 0.5, tan_beta = 0.2, r = 4;
  const Dem dem = roads::test::make_dem(80, 80, cell, [&](int, int row) { return 100.0 + tan_beta * row * cell; });
  TerrainField terrain(dem, 0.0, 10.0, 0.0);
  const RoadGeometry road = straight_road(40.0, 0, 79, [&](double) { return 100.0 + tan_beta * 40 * cell; });
  CorridorOptions o = options(30);
  o.side_angles_deg = dem.like<float>();
  for (int row = 0; row < 80; ++row)
    for (int col = 0; col < 80; ++col) o.side_angles_deg(col, row) = row < 40 ? float(repose_angle_deg("rock")) : NAN;
  Raster<float> cover = dem.like<float>();
  for (std::size_t k = 0; k < cover.size(); ++k) cover[k] = 0.5f;  // half-covered everywhere
  terrain.set_vegetation(cover);
  const Corridors c = corridors(terrain, {&road}, o);
  const double rock = r * 2 / (2 - tan_beta), soft = r * std::tan(30 * kDeg) / (std::tan(30 * kDeg) - tan_beta);
  EXPECT_NEAR(c.sections[0].mean_half_width_m, 0.5 * (rock + soft), 1e-3);
  EXPECT_NEAR(c.sections[0].max_half_width_m, soft, 1e-3);
  EXPECT_TRUE(c.vegetation);
  EXPECT_NEAR(c.run.cleared_ha, 0.5 * c.run.land_take_ha, 1e-5 * c.run.land_take_ha);
}

namespace {

/// East along row y0 from column x0 to x1, a half-turn of `radius` (cells, every degree) about
/// (x1, y0 + radius), and back west along row y0 + 2 radius to x0: a hairpin on a flat plane.
RoadGeometry hairpin(double x0, double x1, double y0, double radius) {
  RoadGeometry g;
  for (double c = x0; c < x1; c += 0.5) g.points.push_back({c, y0});
  for (int a = 0; a <= 180; ++a)
    g.points.push_back({x1 + radius * std::sin(a * kDeg), y0 + radius - radius * std::cos(a * kDeg)});
  for (double c = x1 - 0.5; c >= x0 - 1e-9; c -= 0.5) g.points.push_back({c, y0 + 2 * radius});
  g.z.assign(g.points.size(), 100.0);
  g.segments.assign(g.points.size() - 1, Structure::road);
  return g;
}

}  // namespace

TEST(Corridor, HairpinAndOverlappingRoadsCountTheirGroundOnce) {
  // On a flat plane R = r = 4 m. The hairpin's legs are 6 m apart: their 8 m strips overlap by
  // 2 m, and the half-turn (radius 3 m < r) sweeps a half-disc of radius 3 + 4 m; the union is
  // the 14 m x 40 m band and the half-disc, 560 + 49 pi / 2 m2 (the ring of the old offsets
  // crossed itself there).
  const Dem dem = roads::test::make_dem(80, 50, 1.0, [](int, int) { return 100.0; });
  const TerrainField terrain(dem, 0.0, 10.0, 0.0);
  const RoadGeometry road = hairpin(10, 50, 20, 3);
  const Corridors c = corridors(terrain, {&road}, options(30));
  const double hairpin_m2 = 560 + 49 * std::numbers::pi / 2;
  EXPECT_NEAR(c.roads[0].land_take_ha * 1e4, hairpin_m2, 0.005 * hairpin_m2);
  EXPECT_NEAR(c.run.land_take_ha * 1e4, hairpin_m2, 0.005 * hairpin_m2);
  ASSERT_EQ(c.sections.size(), 1u);
  ASSERT_EQ(c.sections[0].zone.size(), 1u);  // one valid polygon
  // Two parallel straight roads 6 m apart, each 40 m x 8 m: the run's land take is their union
  // (14 m x 40 m), each road keeps its own 320 m2, and the union is never more than the sum.
  const RoadGeometry a = straight_road(20.0, 10, 50, [](double) { return 100.0; });
  const RoadGeometry b = straight_road(26.0, 10, 50, [](double) { return 100.0; });
  const Corridors two = corridors(terrain, {&a, &b}, options(30));
  EXPECT_NEAR(two.roads[0].land_take_ha * 1e4, 320, 1e-6);
  EXPECT_NEAR(two.roads[1].land_take_ha * 1e4, 320, 1e-6);
  EXPECT_NEAR(two.run.land_take_ha * 1e4, 560, 1e-6);
  const VectorLayer layer = corridors_layer(terrain, two);
  double land_take_m2 = 0;
  for (std::size_t i = 0; i < layer.features.size(); ++i)
    if (std::get<std::string>(layer.features[i].values[3]) == "land_take") land_take_m2 += field(layer, i, "area_ha") * 1e4;
  EXPECT_NEAR(land_take_m2, 560, 1e-6);
}

TEST(Corridor, WidthsFollowTheRoadClass) {
  // On a plane the zone is the platform: 40 m x the class's platform width; the carriageway its own.
  const Dem dem = roads::test::make_dem(60, 60, 1.0, [](int, int) { return 100.0; });
  const TerrainField terrain(dem, 0.0, 10.0, 0.0);
  const RoadGeometry road = straight_road(30.0, 10, 50, [](double) { return 100.0; });
  CorridorOptions o;  // the per-class defaults, no override
  const std::vector<RoadClass> classes = {RoadClass::motorway, RoadClass::local};
  const Corridors c = corridors(terrain, {&road, &road}, o, classes);
  for (std::size_t k = 0; k < 2; ++k) {
    const ClassWidths& w = o.widths[std::size_t(classes[k])];
    EXPECT_NEAR(c.roads[k].land_take_ha * 1e4, 40 * w.platform_m, 1e-6) << k;
    EXPECT_NEAR(polygons_area_m2(dem.georef().crs, c.sections[k].carriageway), 40 * w.carriageway_m, 1e-6) << k;
  }
  // The same road twice: the motorway's platform covers the local road's.
  EXPECT_NEAR(c.run.land_take_ha * 1e4, 40 * o.widths[0].platform_m, 1e-6);
  // The override: every road at r.
  o.half_width_m = 3;
  EXPECT_NEAR(corridors(terrain, {&road}, o, {RoadClass::motorway}).run.land_take_ha * 1e4, 40 * 6, 1e-6);
  o.half_width_m = 0;
  o.widths[3] = {8, 6};  // a platform narrower than its carriageway
  Raster<float> slopes;
  EXPECT_THROW(earthwork_options(o, slopes, RoadClass::local), Error);
}

namespace {

/// The corridors as text (every section's figures and polygons, the land take), for a comparison
/// byte for byte.
std::string corridors_text(const Corridors& c) {
  std::string s;
  char buf[128];
  const auto rings = [&](const std::vector<Polygon>& polygons) {
    for (const Polygon& p : polygons)
      for (const Ring& ring : p.rings)
        for (const auto& v : ring) s += (std::snprintf(buf, sizeof buf, "%.17g %.17g;", v[0], v[1]), buf);
    s += "\n";
  };
  for (const SectionCorridor& x : c.sections) {
    s += (std::snprintf(buf, sizeof buf, "%zu %zu %.17g %.17g %.17g %.17g|", x.road, x.section, x.totals.cut_m3, x.totals.fill_m3,
                        x.max_half_width_m, x.walled_m), buf);
    rings(x.zone), rings(x.carriageway);
  }
  rings(c.land_take);
  return s + (std::snprintf(buf, sizeof buf, "%.17g %.17g %.17g", c.run.land_take_ha, c.run.cut_m3, c.run.fill_m3), buf);
}

}  // namespace

TEST(Corridor, ByWindowsAroundEachRoadTheWholeGridsCorridors) {
  // A run by tiles reads each road's corridor on a window holding the road and the corridor's reach
  // (CorridorWindows): the sections, volumes and land take are the whole grid's, on projected and
  // geographic grids, roads cutting and filling through rough hills up to the grid's edge. With no
  // margin the cross-sections stop at the window's edge: the figures differ (the test can fail).
  // With a map of side angles (trials 4 to 7: random angles, some shallow, some NaN or out of range)
  // read on each road's window, the margin counts the map's shallowest angle; counting the default
  // angle alone, the figures differ.
  std::mt19937_64 rng(31);
  std::uniform_real_distribution<double> u(0, 1);
  int differs_without_margin = 0, differs_without_least = 0;
  for (int trial = 0; trial < 8; ++trial) {
    const int cols = 120, rows = 90;
    struct Bump { double c, r, h, s; };
    std::vector<Bump> bumps;
    const double relief = trial >= 4 ? 120 : 40;  // with the map: cuts and fills to max_height_m
    for (int i = 0; i < 12; ++i) bumps.push_back({u(rng) * cols, u(rng) * rows, (u(rng) - 0.4) * relief, 3 + 8 * u(rng)});
    Dem dem(cols, rows, trial % 2 ? terrapolis::test::geographic(46.0, 1.0 / 3600) : terrapolis::test::projected(25.0));
    for (int r = 0; r < rows; ++r)
      for (int c = 0; c < cols; ++c) {
        double z = 50;
        for (const Bump& b : bumps) z += b.h * std::exp(-((c - b.c) * (c - b.c) + (r - b.r) * (r - b.r)) / (2 * b.s * b.s));
        dem(c, r) = float(z);
      }
    const TerrainField whole(dem, 0.0, 10.0, 0.0);
    std::vector<RoadGeometry> roads;
    for (int k = 0; k < 4; ++k) {  // polylines at a level deck, the last one reaching the grid's edge
      const double c0 = 2 + u(rng) * (cols - 4), r0 = 2 + u(rng) * (rows - 4);
      const double c1 = k == 3 ? cols - 1 : 2 + u(rng) * (cols - 4);
      const double r1 = trial >= 4 ? r0 : 2 + u(rng) * (rows - 4);  // with the map, east-west: every side meets the window's edge
      const double deck = 50 + 10 * u(rng);
      RoadGeometry g;
      const int n = int(2 * std::hypot(c1 - c0, r1 - r0)) + 2;
      for (int i = 0; i <= n; ++i) {
        g.points.push_back({c0 + (c1 - c0) * i / n, r0 + (r1 - r0) * i / n});
        g.z.push_back(deck);
      }
      g.segments.assign(g.points.size() - 1, Structure::road);
      roads.push_back(std::move(g));
    }
    std::vector<const RoadGeometry*> pointers;
    for (const RoadGeometry& g : roads) pointers.push_back(&g);
    CorridorOptions o = options(30);
    o.max_height_m = 6;
    Raster<float> map(cols, rows, dem.georef());
    if (trial >= 4) {
      for (float& a : map.values()) {
        const double v = u(rng);
        a = v < 0.1 ? NAN : v < 0.2 ? 95.0f : float(8 + 12 * u(rng));  // shallow sides: wide corridors
      }
      o.side_angles_deg = map;
      o.max_height_m = 40;
    }
    const std::string expected = corridors_text(corridors(whole, pointers, o));
    const TerrainGrid grid{dem.georef(), cols, rows, whole.has_bathymetry()};
    const TerrainField frame = TerrainField::frame(grid);
    std::size_t reads = 0;
    const ReadTerrainWindow read = [&](int c0, int r0, int w, int h) {
      ++reads;
      return TerrainField(terrapolis::test::window_of(dem, c0, r0, w, h), c0, r0, grid, 0.0, 10.0, 0.0);
    };
    CorridorWindows::ReadAngles angles;
    if (trial >= 4) angles = [&](int c0, int r0, int w, int h) { return terrapolis::test::window_of(map, c0, r0, w, h); };
    CorridorOptions by_windows = o;  // the map is read on the windows, its shallowest angle counted in the margin
    by_windows.side_angles_deg = {};
    if (trial >= 4) by_windows.least_side_angle_deg = 8;
    for (float a : map.values())
      if (trial >= 4 && a > 0 && a < 90) by_windows.least_side_angle_deg = std::min(by_windows.least_side_angle_deg, double(a));
    const CorridorWindows windows{read, window_margin_cells(0, corridor_reach_m(by_windows), whole.min_cell_m()), false, angles};
    EXPECT_EQ(expected, corridors_text(corridors(frame, pointers, by_windows, {}, &windows))) << trial;
    EXPECT_EQ(reads, roads.size()) << trial;  // a window a road
    const CorridorWindows no_margin{read, 0, false, angles};
    differs_without_margin += expected != corridors_text(corridors(frame, pointers, by_windows, {}, &no_margin));
    if (trial >= 4) {
      const CorridorWindows default_margin{read, window_margin_cells(0, corridor_reach_m(o), whole.min_cell_m()), false, angles};
      differs_without_least += expected != corridors_text(corridors(frame, pointers, by_windows, {}, &default_margin));
    }
  }
  EXPECT_GE(differs_without_margin, 4);
  EXPECT_GE(differs_without_least, 1);
}
