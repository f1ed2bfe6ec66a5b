// Roads by windows: a road searched on windows of the grid is the whole grid's road.
// SPDX-License-Identifier: MIT
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <mutex>
#include <random>

#include "core/error.hpp"
#include "roads/existing_roads.hpp"
#include "roads/windowed_route.hpp"
#include "support/georefs.hpp"
#include "support/windows.hpp"

using namespace terrapolis;
using namespace terrapolis::roads;

namespace {

/// Random hills, some pits below sea level, and on request a wall across the grid with one gap.
Dem landscape(std::mt19937_64& rng, int cols, int rows, const Georef& georef, bool wall) {
  std::uniform_real_distribution<double> u(0, 1);
  struct Bump { double c, r, h, s; };
  std::vector<Bump> bumps;
  for (int i = 0; i < 14; ++i) bumps.push_back({u(rng) * cols, u(rng) * rows, (u(rng) - 0.3) * 60, 3 + 10 * u(rng)});
  const int wall_col = cols / 2, gap = int(u(rng) * (rows - 6)) + 3;
  Dem dem(cols, rows, georef);
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) {
      double z = 8;
      for (const auto& b : bumps) z += b.h * std::exp(-((c - b.c) * (c - b.c) + (r - b.r) * (r - b.r)) / (2 * b.s * b.s));
      if (wall && std::abs(c - wall_col) <= 1 && std::abs(r - gap) > 1) z += 400;  // a cliff the slope threshold closes
      dem(c, r) = float(z);
    }
  if (u(rng) < 0.3) dem(int(u(rng) * cols), int(u(rng) * rows)) = std::numeric_limits<float>::quiet_NaN();
  return dem;
}

using test::window_of;

CostModel test_model(std::mt19937_64& rng) {
  CostModel m = default_cost_model();
  m.road.slope_deg.threshold = 12 + 10 * double(rng() % 100) / 100;
  m.bridge.enabled = rng() % 2 == 0;
  m.tunnel.enabled = rng() % 2 == 0;
  for (StructureCosts* s : {&m.bridge, &m.tunnel}) {
    s->min_length_cells = 2;
    s->max_length_cells = 6;
    s->samples = 12;
  }
  m.road_radius_m = rng() % 2 ? 0.0 : 25.0;
  return m;
}

}  // namespace

TEST(RoadByWindows, GivesTheWholeGridsRoadOnRandomLandscapes) {
  std::mt19937_64 rng(2026);
  int windowed = 0, grown = 0, routed = 0;
  for (int trial = 0; trial < 24; ++trial) {
    const bool geographic = trial % 3 == 2;
    const int cols = 150 + int(rng() % 80), rows = 120 + int(rng() % 60);
    const Dem dem = landscape(rng, cols, rows, geographic ? test::geographic(62.0, 1.0 / 1200) : test::projected(10.0), trial % 4 == 1);
    const CostModel model = test_model(rng);
    const GraphOptions graph{int(1 + rng() % 4), 8, rng()};
    const TerrainField whole(dem, 0.0, 10.0, model.road_radius_m);
    const RoadGraph whole_graph(whole, model, graph);
    const TerrainGrid grid{dem.georef(), cols, rows, whole.has_bathymetry()};
    std::size_t cells_read = 0;
    const ReadTerrainWindow read = [&](int c0, int r0, int w, int h) {
      cells_read += std::size_t(w) * std::size_t(h);
      return TerrainField(window_of(dem, c0, r0, w, h), c0, r0, grid, 0.0, 10.0, model.road_radius_m);
    };
    WindowOptions options;
    options.margin_cells = window_margin_cells(model.road_radius_m, 0, whole.min_cell_m());
    options.pad_cells = 8;
    RoutingOptions routing;
    for (int k = 0; k < 3; ++k) {
      const Cell a{int(rng() % std::uint64_t(cols)), int(rng() % std::uint64_t(rows))};
      const Cell b{int(rng() % std::uint64_t(cols)), int(rng() % std::uint64_t(rows))};
      if (a == b || !snap_to_land(whole, a, routing.snap_cells) || !snap_to_land(whole, b, routing.snap_cells)) continue;
      const std::optional<Road> expected = route_road(whole, whole_graph, a, b, routing);
      WindowedRoad got;
      try {
        got = route_by_windows(grid, read, model, graph, a, b, routing, options);
      } catch (const Error& e) {
        ADD_FAILURE() << trial << ": " << e.what();
        continue;
      }
      ASSERT_EQ(bool(expected), bool(got.road)) << trial;
      if (!expected) continue;
      ASSERT_EQ(expected->ferry, got.road->ferry) << trial;
      ASSERT_EQ(bool(expected->cost), bool(got.road->cost)) << trial;
      if (expected->cost) {
        EXPECT_EQ(*expected->cost, *got.road->cost) << trial << " " << k;  // bit for bit
      }
      // The same cells (as grid cells), the same geometry, the same figures.
      ASSERT_EQ(expected->chain.cells.size(), got.road->chain.cells.size()) << trial;
      for (std::size_t i = 0; i < expected->chain.cells.size(); ++i) {
        ASSERT_EQ(whole.col_of(expected->chain.cells[i]), got.terrain->col_of(got.road->chain.cells[i])) << trial;
        ASSERT_EQ(whole.row_of(expected->chain.cells[i]), got.terrain->row_of(got.road->chain.cells[i])) << trial;
      }
      ASSERT_EQ(expected->geometry.points.size(), got.road->geometry.points.size()) << trial;
      for (std::size_t i = 0; i < expected->geometry.points.size(); ++i) {
        EXPECT_EQ(expected->geometry.points[i].col, got.road->geometry.points[i].col) << trial;
        EXPECT_EQ(expected->geometry.points[i].row, got.road->geometry.points[i].row) << trial;
        EXPECT_EQ(expected->geometry.z[i], got.road->geometry.z[i]) << trial;
      }
      EXPECT_EQ(expected->stats.length_m, got.road->stats.length_m) << trial;
      EXPECT_EQ(expected->stats.bridge_m, got.road->stats.bridge_m) << trial;
      EXPECT_EQ(expected->stats.tunnel_m, got.road->stats.tunnel_m) << trial;
      ++routed;
      windowed += got.largest_cells < std::size_t(cols) * std::size_t(rows);
      grown += got.windows > 1;
    }
  }
  EXPECT_GE(routed, 40);
  EXPECT_GE(windowed, 20);  // most roads never read the whole grid
  EXPECT_GE(grown, 3);      // and some needed a second window (the walls' detours)
}

TEST(RoadByWindows, UnderRoadReuseTheReachBoundProvesTheWholeGridsRoad) {
  // Roads already built (factor 0.5 along random lines): the straight-line bound at half the
  // cheapest cost per metre rarely proves a road; the reach bound (the roads' factors only where
  // they are) does, and the road is still the whole grid's. (Checked by hand: with the bound made
  // 4 times too large, an invalid proof, this test fails.)
  std::mt19937_64 rng(7);
  int routed = 0, by_reach = 0;
  for (int trial = 0; trial < 12; ++trial) {
    const int cols = 160 + int(rng() % 60), rows = 130 + int(rng() % 50);
    const Dem dem = landscape(rng, cols, rows, trial % 3 == 2 ? test::geographic(50.0, 1.0 / 1200) : test::projected(10.0), trial % 2 == 1);
    const CostModel model = test_model(rng);
    const GraphOptions graph{int(1 + rng() % 4), 8, rng()};
    const TerrainField whole(dem, 0.0, 10.0, model.road_radius_m);
    const RoadGraph whole_graph(whole, model, graph);
    const TerrainGrid grid{dem.georef(), cols, rows, whole.has_bathymetry()};
    std::vector<float> factor(std::size_t(cols) * std::size_t(rows), 1.0f);
    for (int line = 0; line < 3; ++line) {  // a straight road across the grid, 8-connected
      const int c0 = int(rng() % std::uint64_t(cols)), r0 = int(rng() % std::uint64_t(rows));
      const int c1 = int(rng() % std::uint64_t(cols)), r1 = int(rng() % std::uint64_t(rows));
      const int n = std::max(std::abs(c1 - c0), std::abs(r1 - r0));
      for (int k = 0; k <= n; ++k)
        factor[std::size_t(r0 + (r1 - r0) * k / std::max(n, 1)) * std::size_t(cols) + std::size_t(c0 + (c1 - c0) * k / std::max(n, 1))] = 0.5f;
    }
    const ArcDiscount whole_discount{factor, 0.5};
    std::vector<float> window_factor;
    ArcDiscount window_discount;
    WindowReuse reuse;
    reuse.over_window = [&](const TerrainField& w) -> const ArcDiscount* {
      window_factor.assign(w.size(), 1.0f);
      for (int r = 0; r < rows; ++r)
        for (int c = 0; c < cols; ++c)
          if (w.inside(c, r)) window_factor[w.index(c, r)] = factor[std::size_t(r) * std::size_t(cols) + std::size_t(c)];
      window_discount = ArcDiscount{window_factor, 0.5};
      return &window_discount;
    };
    reuse.over_box = [&](int c0, int r0, int c1, int r1, std::vector<float>& out) {
      out.clear();
      for (int r = r0; r <= r1; ++r)
        for (int c = c0; c <= c1; ++c) out.push_back(factor[std::size_t(r) * std::size_t(cols) + std::size_t(c)]);
    };
    reuse.read = [](int, int, int, int, const std::vector<std::uint8_t>&) {};
    const ReadTerrainWindow read = [&](int c0, int r0, int w, int h) {
      return TerrainField(window_of(dem, c0, r0, w, h), c0, r0, grid, 0.0, 10.0, model.road_radius_m);
    };
    WindowOptions options;
    options.margin_cells = window_margin_cells(model.road_radius_m, 0, whole.min_cell_m());
    options.pad_cells = 2;
    options.first_ratio = 1.0;  // tight first windows: a wrong proof would keep a road the grid beats
    RoutingOptions routing;
    for (int k = 0; k < 4; ++k) {
      const Cell a{int(rng() % std::uint64_t(cols / 2)) + cols / 4, int(rng() % std::uint64_t(rows / 2)) + rows / 4};
      const Cell b{int(rng() % std::uint64_t(cols / 2)) + cols / 4, int(rng() % std::uint64_t(rows / 2)) + rows / 4};
      if (a == b || !snap_to_land(whole, a, routing.snap_cells) || !snap_to_land(whole, b, routing.snap_cells)) continue;
      const std::optional<Road> expected = route_road(whole, whole_graph, a, b, routing, nullptr, nullptr, &whole_discount);
      const WindowedRoad got = route_by_windows(grid, read, model, graph, a, b, routing, options, nullptr, &reuse);
      ASSERT_EQ(bool(expected), bool(got.road)) << trial;
      if (!expected || !expected->cost) continue;
      ASSERT_TRUE(got.road->cost) << trial;
      EXPECT_EQ(*expected->cost, *got.road->cost) << trial << " " << k;  // bit for bit
      ASSERT_EQ(expected->chain.cells.size(), got.road->chain.cells.size()) << trial;
      for (std::size_t i = 0; i < expected->chain.cells.size(); ++i) {
        ASSERT_EQ(whole.col_of(expected->chain.cells[i]), got.terrain->col_of(got.road->chain.cells[i])) << trial;
        ASSERT_EQ(whole.row_of(expected->chain.cells[i]), got.terrain->row_of(got.road->chain.cells[i])) << trial;
      }
      ++routed;
      by_reach += got.proved_by_reach;
    }
  }
  EXPECT_GE(routed, 30);
  EXPECT_GE(by_reach, 5);  // the reach bound decided some, and rightly
}

TEST(RoadByWindows, TheReachBoundsSlackCoversEveryMoveOnNarrowCells) {
  // Square cells: the 8-connected steps along a move are at most 1.0824 times as long (22.5 degrees).
  const double square = octile_slack(30, 30, 30, 30, 30 * std::sqrt(2.0));
  EXPECT_GT(square, 1.0823);
  EXPECT_LT(square, 1.0840);
  // Cells 3" wide at 47.5 degrees (63 x 93 m): more, and every move of up to 60 cells within it.
  std::mt19937_64 rng(4);
  for (int trial = 0; trial < 50; ++trial) {
    const double lat = 60 * double(rng() % 1000) / 1000, h = 92.6, w = h * std::cos(lat / 57.29577951308232);
    const double spread = 1 + 0.01 * double(rng() % 5);  // rows of slightly different widths
    const double slack = octile_slack(w, w * spread, h, h * spread, std::hypot(w * spread, h * spread));
    for (int a = 0; a <= 60; ++a)
      for (int b = 0; b <= 60; ++b) {
        if (a == 0 && b == 0) continue;
        const int lo = std::min(a, b), hi = std::max(a, b);
        const double steps = (hi - lo) * (a >= b ? w * spread : h * spread) + lo * std::hypot(w * spread, h * spread);
        ASSERT_LE(steps / std::hypot(a * w, b * h), slack) << lat << " " << a << " " << b;
      }
    if (lat > 40) {
      EXPECT_GT(slack, 1.10) << lat;  // the square cells' 1.09 would not do
    }
  }
}

TEST(RoadByWindows, ARoadLargerThanTheLimitIsRefusedNamingIt) {
  std::mt19937_64 rng(5);
  const Dem dem = landscape(rng, 160, 160, test::projected(10.0), true);
  const CostModel model = default_cost_model();
  const TerrainField whole(dem, 0.0, 10.0, 0.0);
  const TerrainGrid grid{dem.georef(), 160, 160, whole.has_bathymetry()};
  std::size_t largest = 0;
  const ReadTerrainWindow read = [&](int c0, int r0, int w, int h) {
    largest = std::max(largest, std::size_t(w) * std::size_t(h));
    return TerrainField(window_of(dem, c0, r0, w, h), c0, r0, grid, 0.0, 10.0, 0.0);
  };
  WindowOptions options;
  options.max_cells = 2000;  // 44 x 44: the ends alone are 120 cells apart
  try {
    route_by_windows(grid, read, model, GraphOptions{}, {20, 20}, {140, 140}, RoutingOptions{}, options);
    FAIL() << "a window past the limit was searched";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::bad_input);
    EXPECT_NE(std::string(e.what()).find("2000 cells"), std::string::npos) << e.what();
  }
  EXPECT_LE(largest, options.max_cells);  // nothing past the limit was read
}

namespace {
/// The layers of a network's roads, as text, for a comparison byte for byte.
std::string layers_text(const TerrainField& t, const NetworkResult& r) {
  std::string s;
  for (const VectorLayer& l : {roads_layer(t, r.roads, &r.layout), sections_layer(t, r.roads), network_sections_layer(t, r.layout),
                               junctions_layer(t, r.layout)})
    for (const auto& f : l.features) {
      char buf[64];
      for (const auto& p : f.parts[0]) s += (std::snprintf(buf, sizeof buf, "%.17g %.17g;", p[0], p[1]), buf);
      for (const auto& v : f.values) {
        if (const auto* i = std::get_if<std::int64_t>(&v)) s += std::to_string(*i);
        if (const auto* d = std::get_if<double>(&v)) s += (std::snprintf(buf, sizeof buf, "%.17g", *d), buf);
        if (const auto* x = std::get_if<std::string>(&v)) s += *x;
        s += "|";
      }
      s += "\n";
    }
  for (const auto& list : {r.failed, r.redundant, r.limited})
    for (const std::string& name : list) s += name + ";";
  return s;
}
}  // namespace

TEST(RoadByWindows, ANetworkByWindowsIsTheWholeGridsNetwork) {
  // Links routed by importance, each reusing the roads before it, two at once ahead: by windows
  // (the roads built so far kept per road cell, each window's factors copied from them) the layers
  // are the whole grid's, byte for byte; under a limit no window read exceeds it (a counter).
  std::mt19937_64 rng(11);
  int limited_runs = 0, limited_links = 0;
  for (int trial = 0; trial < 6; ++trial) {
    const int cols = 220, rows = 170;
    const Dem dem = landscape(rng, cols, rows, trial % 2 ? test::geographic(45.0, 1.0 / 1200) : test::projected(10.0), trial % 3 == 0);
    CostModel model = default_cost_model();
    model.bridge.max_length_cells = model.tunnel.max_length_cells = 6;
    model.bridge.samples = model.tunnel.samples = 12;
    const TerrainField whole(dem, 0.0, 10.0, model.road_radius_m);
    const RoadGraph whole_graph(whole, model, GraphOptions{});
    std::vector<Link> links;
    for (int k = 0; k < 7; ++k) {
      // Ends up to 60 cells apart: most first windows fit the limit below.
      const Cell a{int(rng() % cols), int(rng() % rows)};
      const Cell b{std::clamp(a.col + int(rng() % 121) - 60, 0, cols - 1), std::clamp(a.row + int(rng() % 121) - 60, 0, rows - 1)};
      links.push_back({k, k + 1, dem.georef().cell_centre(a.col, a.row), dem.georef().cell_centre(b.col, b.row),
                       k < 2 ? RoadClass::national : RoadClass::departmental});
    }
    RoutingOptions options;
    options.lookahead = 2;
    SilentProgress silent;
    const NetworkResult expected = route_network(whole, whole_graph, links, options, silent);
    const TerrainGrid grid{dem.georef(), cols, rows, whole.has_bathymetry()};
    const TerrainField frame = TerrainField::frame(grid);
    const RoadGraph frame_graph(frame, model, GraphOptions{});
    std::size_t largest = 0;
    std::mutex largest_mutex;  // two links are routed at once
    const ReadTerrainWindow read = [&](int c0, int r0, int w, int h) {
      {
        const std::lock_guard<std::mutex> lock(largest_mutex);
        largest = std::max(largest, std::size_t(w) * std::size_t(h));
      }
      return TerrainField(window_of(dem, c0, r0, w, h), c0, r0, grid, 0.0, 10.0, model.road_radius_m);
    };
    WindowOptions window;
    window.margin_cells = window_margin_cells(model.road_radius_m, 0, whole.min_cell_m());
    window.pad_cells = 8;
    const NetworkResult got = route_network_by_windows(frame, frame_graph, links, options, silent, {grid, read, window});
    EXPECT_TRUE(got.limited.empty()) << trial;
    EXPECT_EQ(layers_text(whole, expected), layers_text(frame, got)) << trial;
    // Under a limit of a quarter of the grid: no window past it; what was not proved is listed, a
    // link whose first window is past the limit refused. The two links routed at once take an
    // eighth each and a link so limited is routed again alone: the same roads with one, two or
    // three at once.
    largest = 0;
    window.max_cells = std::size_t(cols) * std::size_t(rows) / 4;
    std::string first;
    for (const std::size_t at_once : {2, 1, 3}) {
      options.lookahead = at_once;
      std::string text;
      try {
        const NetworkResult bounded = route_network_by_windows(frame, frame_graph, links, options, silent, {grid, read, window});
        if (at_once == 2) limited_runs += !bounded.limited.empty(), limited_links += int(bounded.limited.size());
        if (bounded.limited.empty()) {
          EXPECT_EQ(layers_text(whole, expected), layers_text(frame, bounded)) << trial;
        }
        text = layers_text(frame, bounded);
        for (const std::string& l : bounded.limited) text += " limited " + l;
      } catch (const Error& e) {
        EXPECT_EQ(e.kind(), ErrorKind::bad_input) << e.what();
        EXPECT_NE(std::string(e.what()).find("the memory limit allows windows of"), std::string::npos) << e.what();
        limited_runs += at_once == 2;
        text = e.what();
      }
      if (at_once == 2) first = text;
      EXPECT_EQ(first, text) << trial << ": " << at_once << " at once";
    }
    options.lookahead = 2;
    EXPECT_LE(largest, window.max_cells) << trial;
  }
  EXPECT_GE(limited_runs, 1);  // the limit bit somewhere: the counter was tested at its bound
  EXPECT_GE(limited_links, 2);  // left limited even alone: the whole limit's answer, at any number at once
}

TEST(RoadByWindows, GivenRoadsByWindowsGiveTheWholeGridsNetwork) {
  // roads.existing by windows: the given lines drawn on the frame are the whole grid's chains, kept
  // per road cell as the roads built before the first link; the links reuse them, and the layers
  // (which sections are on them, each road's new and existing metres) are the whole grid's.
  std::mt19937_64 rng(23);
  double on_given = 0;
  for (int trial = 0; trial < 4; ++trial) {
    const int cols = 200, rows = 160;
    const Dem dem = landscape(rng, cols, rows, trial % 2 ? test::geographic(45.0, 1.0 / 1200) : test::projected(10.0), false);
    CostModel model = default_cost_model();
    model.bridge.enabled = model.tunnel.enabled = false;
    const TerrainField whole(dem, 0.0, 10.0, model.road_radius_m);
    const RoadGraph whole_graph(whole, model, GraphOptions{});
    std::vector<Link> links;
    std::vector<Cell> ends;
    for (int k = 0; k < 6; ++k) {
      const Cell a{int(rng() % cols), int(rng() % rows)}, b{int(rng() % cols), int(rng() % rows)};
      ends.push_back(a), ends.push_back(b);
      links.push_back({k, k + 1, dem.georef().cell_centre(a.col, a.row), dem.georef().cell_centre(b.col, b.row),
                       k < 2 ? RoadClass::national : RoadClass::departmental});
    }
    // Given lines from link ends through a bend to other link ends, one a national, one local, and
    // one leaving the grid (cut where it leaves).
    VectorLayer given;
    given.geometry = GeometryType::line_string;
    given.crs = dem.georef().crs;
    given.fields = {{"highway", FieldType::string}};
    const char* tags[] = {"primary", "residential", "secondary"};
    for (int k = 0; k < 3; ++k) {
      const Cell a = ends[rng() % ends.size()], b = ends[rng() % ends.size()];
      Feature f;
      f.parts.push_back({dem.georef().cell_centre(a.col, a.row), dem.georef().cell_centre((a.col + b.col) / 2 + 9, (a.row + b.row) / 2 - 7),
                         dem.georef().cell_centre(b.col, b.row)});
      if (k == 2) f.parts[0].push_back(dem.georef().cell_centre(cols + 40, b.row));
      f.values = {std::string(tags[k])};
      given.features.push_back(std::move(f));
    }
    RoutingOptions options;
    options.lookahead = 2;
    SilentProgress silent;
    const ExistingRoads on_whole = rasterise_roads(whole, given);
    const NetworkResult expected = route_network(whole, whole_graph, links, options, silent, &on_whole);
    const TerrainGrid grid{dem.georef(), cols, rows, whole.has_bathymetry()};
    const TerrainField frame = TerrainField::frame(grid);
    const RoadGraph frame_graph(frame, model, GraphOptions{});
    const ReadTerrainWindow read = [&](int c0, int r0, int w, int h) {
      return TerrainField(window_of(dem, c0, r0, w, h), c0, r0, grid, 0.0, 10.0, model.road_radius_m);
    };
    WindowOptions window;
    window.margin_cells = window_margin_cells(model.road_radius_m, 0, whole.min_cell_m());
    const ExistingRoads on_frame = rasterise_roads(frame, given);
    ASSERT_EQ(on_whole.chains.size(), on_frame.chains.size());
    for (std::size_t k = 0; k < on_whole.chains.size(); ++k) EXPECT_EQ(on_whole.chains[k].cells, on_frame.chains[k].cells) << trial;
    EXPECT_EQ(on_whole.length_m, on_frame.length_m) << trial;
    const NetworkResult got = route_network_by_windows(frame, frame_graph, links, options, silent, {grid, read, window}, &on_frame);
    EXPECT_TRUE(got.limited.empty()) << trial;
    EXPECT_EQ(layers_text(whole, expected), layers_text(frame, got)) << trial;
    EXPECT_TRUE(got.layout.with_existing);
    for (const Road& r : got.roads) on_given += r.existing_share;
  }
  EXPECT_GT(on_given, 0.5);  // the links ran on the given roads: the test compared what they change
}
