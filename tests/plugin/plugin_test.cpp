// Plugins: loading and refusal, parameters, density factors by weight, road cost layers, the distance transform.
// SPDX-License-Identifier: MIT
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <random>

#include "../../plugins/distance/distance_transform.hpp"
#include "core/error.hpp"
#include "density/density.hpp"
#include "io/crs.hpp"
#include "io/raster_io.hpp"
#include "core/geodesy.hpp"
#include "plugin/plugin.hpp"
#include "support/temp_dir.hpp"

namespace terrapolis {
namespace {

using nlohmann::json;
namespace fs = std::filesystem;

fs::path plugin_file(const std::string& dir, const std::string& id) { return fs::path(dir) / ("terrapolis_" + id + ".so"); }

/// Message of the bad_input the call throws ("" when it does not throw bad_input).
template <class F>
std::string bad_input_of(F&& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.kind() == ErrorKind::bad_input ? e.what() : "";
  }
  return "";
}

TEST(Plugin, LoadsTheExampleAndReadsItsDescription) {
  const auto p = plugin::open_plugin(plugin_file(TERRAPOLIS_PLUGIN_DIR, "example"));
  EXPECT_EQ(p.spec.id, "example");
  EXPECT_TRUE(p.has_density_factor());
  EXPECT_TRUE(p.has_road_cost());
  EXPECT_NE(p.description().find("Constant density factor"), std::string::npos);
  // Found by id through the build folder too.
  EXPECT_EQ(plugin::find_plugin("example").filename(), "terrapolis_example.so");
}

TEST(Plugin, RefusesWrongAbiMissingEntryAndBrokenSchemaNamingTheFile) {
  const auto abi = plugin_file(TERRAPOLIS_BAD_PLUGIN_DIR, "bad_abi").string();
  std::string m = bad_input_of([&] { plugin::open_plugin(abi); });
  EXPECT_EQ(m.rfind(abi + ": plugin ABI version 42, this Terrapolis needs version 1", 0), 0u) << m;
  const auto schema = plugin_file(TERRAPOLIS_BAD_PLUGIN_DIR, "bad_schema").string();
  m = bad_input_of([&] { plugin::open_plugin(schema); });
  EXPECT_EQ(m.rfind(schema + ": invalid parameter schema", 0), 0u) << m;
  const auto none = plugin_file(TERRAPOLIS_BAD_PLUGIN_DIR, "no_entry").string();
  m = bad_input_of([&] { plugin::open_plugin(none); });
  EXPECT_EQ(m.rfind(none + ": not a Terrapolis plugin (no terrapolis_plugin_entry symbol)", 0), 0u) << m;
  m = bad_input_of([&] { plugin::find_plugin("nowhere_to_be_found"); });
  EXPECT_NE(m.find("no terrapolis_nowhere_to_be_found.so"), std::string::npos) << m;
  EXPECT_EQ(m.find('\n'), std::string::npos);
}

TEST(Plugin, ValidatesParametersAgainstTheSchema) {
  const Log quiet(LogLevel::quiet);
  EXPECT_NO_THROW(plugin::load_plugins(json::parse(R"([{"id": "example", "weight": 2, "params": {"value": 0.25}}])"), quiet));
  std::string m = bad_input_of([&] { plugin::load_plugins(json::parse(R"([{"id": "example", "params": {"value": 3}}])"), quiet); });
  EXPECT_NE(m.find("plugin example ("), std::string::npos) << m;
  EXPECT_NE(m.find("params/value"), std::string::npos) << m;
  m = bad_input_of([&] { plugin::load_plugins(json::parse(R"([{"id": "example", "params": {"colour": 1}}])"), quiet); });
  EXPECT_NE(m.find("params"), std::string::npos) << m;
  m = bad_input_of([&] { plugin::load_plugins(json::parse(R"([{"id": "Example"}])"), quiet); });
  EXPECT_NE(m.find("plugins/0/id"), std::string::npos) << m;
  m = bad_input_of([&] { plugin::load_plugins(json::parse(R"([{"id": "example", "wieght": 1}])"), quiet); });
  EXPECT_NE(m.find("plugins/0/wieght: unknown key"), std::string::npos) << m;
}

TEST(Plugin, ParsesTheCommandLineForm) {
  auto s = plugin::parse_plugin_option("example");
  EXPECT_EQ(s.id, "example");
  EXPECT_EQ(s.weight, 1);
  EXPECT_TRUE(s.params.empty());
  s = plugin::parse_plugin_option("example:2.5");
  EXPECT_EQ(s.weight, 2.5);
  s = plugin::parse_plugin_option("example:-1:{\"value\":0.1}");
  EXPECT_EQ(s.weight, -1);
  EXPECT_EQ(s.params["value"], 0.1);
  s = plugin::parse_plugin_option("example:{\"value\":0.2}");
  EXPECT_EQ(s.weight, 1);
  EXPECT_EQ(s.params["value"], 0.2);
  test::TempDir dir;
  { std::ofstream(dir.file("p.json")) << R"({"value": 0.3})"; }
  s = plugin::parse_plugin_option("example:0:" + dir.file("p.json"));
  EXPECT_EQ(s.weight, 0);
  EXPECT_EQ(s.params["value"], 0.3);
  EXPECT_EQ(fs::path(s.base_dir), dir.path());
  EXPECT_NE(bad_input_of([] { plugin::parse_plugin_option("Bad-Id"); }).find("--plugin Bad-Id"), std::string::npos);
  EXPECT_NE(bad_input_of([] { plugin::parse_plugin_option("example:nofile.json"); }).find("nofile.json: no such parameter file"), std::string::npos);
  EXPECT_NE(bad_input_of([] { plugin::parse_plugin_option("example:{oops"); }).find("not valid JSON"), std::string::npos);
}

TEST(Plugin, RelativePathsAreResolvedFromTheBaseFolder) {
  const json list = json::parse(R"([{"id": "distance", "params": {"vector": "layers/roads.geojson", "where": "a = 'b'"}}])");
  const auto set = plugin::load_plugins(list, Log(LogLevel::quiet), "/data/scenario");
  EXPECT_EQ(set[0].spec.params["vector"], "/data/scenario/layers/roads.geojson");
  EXPECT_EQ(set[0].spec.params["where"], "a = 'b'");  // not a path
  EXPECT_EQ(plugin::load_plugins(list, Log(LogLevel::quiet))[0].spec.params["vector"], "layers/roads.geojson");
}

/// The density of the Corsica sample with the example plugin's constant factor `value` at `weight`.
density::DensityResult corsica_density(const Dem& dem, double weight, double value, std::optional<double> top = {}) {
  density::DensityOptions o;
  json params = {{"value", value}};
  if (top) params["max_altitude_m"] = *top;
  if (weight != 0 || top) {
    const auto set = plugin::load_plugins(json::array({{{"id", "example"}, {"weight", weight}, {"params", params}}}), Log(LogLevel::quiet));
    SilentProgress progress;
    plugin::add_to_density(plugin::density_factors(set, dem, progress, Log(LogLevel::quiet)), o);
  }
  SilentProgress progress;
  return density::compute_density(dem, dem.like<float>(0.0f), o, progress);
}

TEST(Plugin, DensityFactorMovesDensityAsItsWeightSays) {
  const Dem dem = read_dem(test::sample("gebco2022_15s_north_corsica_capcorse.asc"));
  const auto base = corsica_density(dem, 0, 0);
  const auto zero = corsica_density(dem, 0, 0.9, 1e9);  // loaded with weight 0, nothing excluded
  const double total = 1 + 1 + 1.5 + 0;                 // default weights, none negative
  std::size_t buildable = 0;
  for (std::size_t i = 0; i < dem.size(); ++i) {
    ASSERT_EQ(base.buildable[i], zero.buildable[i]);
    if (base.buildable[i] != 1) continue;
    ++buildable;
    ASSERT_FLOAT_EQ(zero.density[i], base.density[i]);  // weight 0: no change
  }
  ASSERT_GT(buildable, 1000u);
  for (double w : {1.0, 4.0}) {
    const auto with = corsica_density(dem, w, 0.9);
    double moved = 0;
    for (std::size_t i = 0; i < dem.size(); ++i) {
      if (base.buildable[i] != 1) continue;
      // Combined like a user layer: (sum P_i D_i + w v) / (sum |P_i| + w).
      const double expected = (total * base.density[i] + w * 0.9) / (total + w);
      ASSERT_NEAR(with.density[i], expected, 1e-5);
      moved += std::fabs(with.density[i] - 0.9) - std::fabs(base.density[i] - 0.9);
    }
    EXPECT_LT(moved, 0.0);  // closer to the factor everywhere on the whole
  }
}

TEST(Plugin, NanFactorCellsTakeNoPartInTheCombination) {
  const Dem dem = read_dem(test::sample("gebco2022_15s_north_corsica_capcorse.asc"));
  SilentProgress progress;
  const auto base = density::compute_density(dem, dem.like<float>(0.0f), density::DensityOptions{}, progress);
  density::DensityOptions o;
  Raster<float> factor = dem.like<float>(std::numeric_limits<float>::quiet_NaN());
  for (int r = 0; r < dem.rows(); ++r)
    for (int c = 0; c < dem.cols() / 2; ++c) factor(c, r) = 0.9f;  // an opinion on the west half only
  o.factors.push_back({"half", factor, 2.0});
  const auto with = density::compute_density(dem, dem.like<float>(0.0f), o, progress);
  for (int r = 0; r < dem.rows(); ++r)
    for (int c = 0; c < dem.cols(); ++c) {
      if (base.buildable(c, r) != 1) continue;
      const double expected = c < dem.cols() / 2 ? (3.5 * base.density(c, r) + 2 * 0.9) / 5.5 : base.density(c, r);
      ASSERT_NEAR(with.density(c, r), expected, 1e-5) << c << "," << r;
    }
}

TEST(Plugin, DensityExclusionsMakeCellsUninhabitable) {
  const Dem dem = read_dem(test::sample("gebco2022_15s_north_corsica_capcorse.asc"));
  const auto r = corsica_density(dem, 1, 0.5, 300.0);
  std::size_t high = 0;
  for (std::size_t i = 0; i < dem.size(); ++i)
    if (!std::isnan(dem[i]) && dem[i] > 300) {
      ++high;
      ASSERT_EQ(r.buildable[i], 0);
      ASSERT_EQ(r.density[i], 0.0f);
    }
  EXPECT_GT(high, 100u);
}

TEST(Plugin, RoadTermsBecomeCostLayersAndInfinityForbids) {
  const Dem dem = read_dem(test::sample("gebco2022_15s_north_corsica_capcorse.asc"));
  const auto set = plugin::load_plugins(json::parse(R"([{"id": "example", "params": {"max_altitude_m": 300}}])"), Log(LogLevel::quiet));
  SilentProgress progress;
  const auto terms = plugin::road_terms(set, dem, progress, Log(LogLevel::quiet));
  ASSERT_EQ(terms.size(), 1u);
  EXPECT_TRUE(terms[0].priced[0] && terms[0].priced[1] && !terms[0].priced[2]);
  roads::TerrainField terrain(dem, 0, 10, 10);
  plugin::add_to_terrain(terms, terrain);
  for (int r = 0; r < dem.rows(); ++r)
    for (int c = 0; c < dem.cols(); ++c) {
      const float z = dem(c, r);
      const float road = terrain.extra_cost_at(roads::Structure::road, c, r);
      ASSERT_EQ(road, z > 300 ? INFINITY : 0.0f) << c << "," << r;
      ASSERT_EQ(terrain.extra_cost_at(roads::Structure::bridge, c, r), road);
      ASSERT_EQ(terrain.extra_cost_at(roads::Structure::tunnel, c, r), 0.0f);  // tunnels not priced
    }
}

TEST(Plugin, CostLayersSumTheirTransferFunctions) {
  Dem dem(3, 1, Georef{}, 0.0f);
  roads::TerrainField terrain(dem, -100, 10, 0);
  Raster<float> kappa = dem.like<float>(0.0f);
  kappa[0] = 0, kappa[1] = 2, kappa[2] = std::numeric_limits<float>::quiet_NaN();
  roads::TransferFunction mu{{{0, 1}, {4, 5}}, roads::kInfinity};
  terrain.add_cost_layer("a", kappa, {mu, mu, mu}, {true, false, false});
  terrain.add_cost_layer("b", kappa, {mu, mu, mu}, {true, false, false});
  EXPECT_EQ(terrain.extra_cost_at(roads::Structure::road, 0, 0), 2.0f);  // 1 + 1
  EXPECT_EQ(terrain.extra_cost_at(roads::Structure::road, 1, 0), 6.0f);  // 3 + 3
  EXPECT_EQ(terrain.extra_cost_at(roads::Structure::road, 2, 0), 0.0f);  // NaN costs nothing
  EXPECT_EQ(terrain.extra_cost_at(roads::Structure::bridge, 1, 0), 0.0f);
}

/// Cancels at the first update.
class CancellingProgress final : public Progress {
 public:
  void begin(std::string_view) override {}
  bool update(double) override { return false; }
  void end() override {}
};

TEST(Plugin, DistancePluginOnCorsicaAndCancel) {
  const Dem dem = read_dem(test::sample("gebco2022_15s_north_corsica_capcorse.asc"));
  test::TempDir dir;
  {
    std::ofstream(dir.file("point.geojson"))
        << R"({"type":"FeatureCollection","features":[{"type":"Feature","properties":{},"geometry":{"type":"Point","coordinates":[9.2,42.8]}}]})";
  }
  const json list = json::array({{{"id", "distance"},
                                  {"params", {{"vector", dir.file("point.geojson")}, {"density", {{"points", {{0, 1}, {10000, 0}}}}}}}}});
  const auto set = plugin::load_plugins(list, Log(LogLevel::quiet));
  SilentProgress progress;
  const auto factors = plugin::density_factors(set, dem, progress, Log(LogLevel::quiet));
  ASSERT_EQ(factors.size(), 1u);
  // The point's cell has factor 1; the factor falls by 1 per 10 km: check against geodesic distances.
  const GridLocator locator(dem.georef());
  for (int r = 0; r < dem.rows(); r += 7)
    for (int c = 0; c < dem.cols(); c += 7) {
      const auto ll = locator.cell_lonlat(c, r);
      const double d = geodesic_distance_m(dem.georef().crs.ellipsoid, ll[0], ll[1], 9.2, 42.8);
      // Raster distance between cell centres: within one cell diagonal (~600 m) plus 0.2 %.
      ASSERT_NEAR(factors[0].factor(c, r), std::clamp(1 - d / 10000, 0.0, 1.0), (600 + 0.002 * d) / 10000) << c << "," << r;
    }
  CancellingProgress cancel;
  try {
    plugin::density_factors(set, dem, cancel, Log(LogLevel::quiet));
    FAIL() << "not cancelled";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::cancelled);
  }
}

/// Brute-force distance under the same metric model as the transform.
std::vector<double> brute_distance(const std::vector<unsigned char>& f, int cols, int rows, const std::vector<double>& w,
                                   const std::vector<double>& h) {
  std::vector<double> y(std::size_t(rows), 0.0);
  for (int r = 1; r < rows; ++r) y[std::size_t(r)] = y[std::size_t(r) - 1] + h[std::size_t(r) - 1];
  std::vector<double> d(f.size(), INFINITY);
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c)
      for (int rr = 0; rr < rows; ++rr)
        for (int cc = 0; cc < cols; ++cc) {
          if (!f[std::size_t(rr * cols + cc)]) continue;
          const double dx = (c - cc) * w[std::size_t(rr)], dy = y[std::size_t(r)] - y[std::size_t(rr)];
          d[std::size_t(r * cols + c)] = std::min(d[std::size_t(r * cols + c)], std::sqrt(dx * dx + dy * dy));
        }
  return d;
}

TEST(Plugin, DistanceTransformEqualsBruteForce) {
  std::mt19937_64 rng(7);
  for (int trial = 0; trial < 40; ++trial) {
    const int cols = 1 + int(rng() % 23), rows = 1 + int(rng() % 19);
    const bool geographic = trial % 2 == 1;
    std::vector<double> w(static_cast<std::size_t>(rows)), h(static_cast<std::size_t>(rows));
    for (int r = 0; r < rows; ++r) {
      w[std::size_t(r)] = geographic ? 90.0 * std::cos((45.0 + 0.5 * r) * M_PI / 180) : 30.0;
      h[std::size_t(r)] = geographic ? 92.0 + 0.01 * r : 25.0;
    }
    std::vector<unsigned char> f(std::size_t(cols * rows));
    const int density = 1 + int(rng() % 30);
    for (auto& v : f) v = rng() % 100 < std::uint64_t(density);
    if (trial == 0) std::fill(f.begin(), f.end(), 0);  // no feature: all infinite
    const auto fast = terrapolis_plugins::distance_transform_m(f.data(), cols, rows, w.data(), h.data());
    const auto slow = brute_distance(f, cols, rows, w, h);
    for (std::size_t i = 0; i < f.size(); ++i) {
      if (std::isinf(slow[i])) ASSERT_TRUE(std::isinf(fast[i]));
      else ASSERT_NEAR(fast[i], slow[i], 1e-6 * (1 + slow[i])) << "trial " << trial << " cell " << i;
    }
  }
}

TEST(Plugin, DistanceTransformGoldenCase) {
  // One feature cell at (1,1) on a 30 m x 40 m grid: 3-4-5 triangles.
  std::vector<unsigned char> f(16, 0);
  f[5] = 1;
  const std::vector<double> w(4, 30.0), h(4, 40.0);
  const auto d = terrapolis_plugins::distance_transform_m(f.data(), 4, 4, w.data(), h.data());
  EXPECT_DOUBLE_EQ(d[5], 0.0);
  EXPECT_DOUBLE_EQ(d[0], 50.0);
  EXPECT_DOUBLE_EQ(d[6], 30.0);
  EXPECT_DOUBLE_EQ(d[9], 40.0);
  EXPECT_DOUBLE_EQ(d[15], std::hypot(60.0, 80.0));
}

}  // namespace
}  // namespace terrapolis
