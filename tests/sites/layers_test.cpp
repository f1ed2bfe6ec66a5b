// The sites as vector layers: the field contract with the roads stage, and the way back.
// SPDX-License-Identifier: MIT
#include <gtest/gtest.h>

#include "core/error.hpp"
#include "core/geodesy.hpp"
#include "io/crs.hpp"
#include "sites/fixtures.hpp"
#include "sites/layers.hpp"

using namespace terrapolis;
using namespace terrapolis::sites;

TEST(SitesLayers, FieldContractAndRoundTrip) {
  const auto s = fixtures::scenario_from_sample("gebco2022_15s_north_corsica_capcorse.asc");
  SitesOptions o = fixtures::thesis_options();
  o.seed = 21;
  const SitesResult r = fixtures::place(s, o);
  const Crs& crs = s.density.georef().crs;
  const VectorLayer cities = cities_layer(r, crs);
  const std::vector<std::string> names = {"id", "radius_m", "class", "population", "density", "parent", "depth", "seed"};
  ASSERT_EQ(cities.fields.size(), names.size());
  for (std::size_t i = 0; i < names.size(); ++i) EXPECT_EQ(cities.fields[i].name, names[i]);
  EXPECT_EQ(cities.fields[1].type, FieldType::real);
  EXPECT_EQ(cities.fields[5].type, FieldType::integer);
  for (std::size_t i = 0; i < r.sites.size(); ++i) {
    const auto& v = cities.features[i].values;
    EXPECT_EQ(std::holds_alternative<std::monostate>(v[5]), r.sites[i].parent < 0) << "parent is null exactly for roots";
    EXPECT_EQ(std::get<std::int64_t>(v[7]), 21);
  }
  const std::vector<Site> back = sites_from_layer(cities, "cities.geojson");
  ASSERT_EQ(back.size(), r.sites.size());
  for (std::size_t i = 0; i < back.size(); ++i) {
    EXPECT_EQ(back[i].id, r.sites[i].id);
    EXPECT_EQ(back[i].parent, r.sites[i].parent);
    EXPECT_EQ(back[i].radius_m, r.sites[i].radius_m);
  }
  // Extents: closed geodesic circles whose vertices are radius_m from the centre.
  const VectorLayer extents = city_extents_layer(r, crs, 36);
  ASSERT_EQ(extents.features.size(), r.sites.size());
  const auto& ring = extents.features[0].parts[0];
  ASSERT_EQ(ring.size(), 37u);
  EXPECT_EQ(ring.front(), ring.back());
  for (const auto& p : ring) EXPECT_NEAR(geodesic_distance_m(Ellipsoid{}, r.sites[0].x, r.sites[0].y, p[0], p[1]), r.sites[0].radius_m, 1e-6);
}

TEST(SitesLayers, PlannerInputErrors) {
  VectorLayer layer;
  layer.geometry = GeometryType::point;
  layer.fields = {{"id", FieldType::integer}, {"radius_m", FieldType::real}, {"parent", FieldType::integer}};
  auto feature = [](std::int64_t id, double r, FieldValue parent) {
    Feature f;
    f.parts = {{{9.0 + 0.01 * double(id), 42.0}}};
    f.values = {FieldValue{id}, FieldValue{r}, parent};
    return f;
  };
  layer.features = {feature(7, 1000, {}), feature(8, 400, FieldValue{std::int64_t(7)})};
  const auto ok = sites_from_layer(layer, "plan.geojson");
  EXPECT_EQ(ok[1].parent, 0);  // an index into the list, from the id 7
  EXPECT_EQ(ok[1].id, 8);
  auto expect_bad = [](const VectorLayer& l, const char* word) {
    try {
      sites_from_layer(l, "plan.geojson");
      ADD_FAILURE() << "no error for " << word;
    } catch (const Error& e) {
      EXPECT_EQ(e.kind(), ErrorKind::bad_input);
      EXPECT_NE(std::string(e.what()).find(word), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("plan.geojson"), std::string::npos);
    }
  };
  VectorLayer bad = layer;
  bad.features[1] = feature(7, 400, {});
  expect_bad(bad, "used twice");
  bad = layer;
  bad.features[1] = feature(8, -1, {});
  expect_bad(bad, "radius_m");
  bad = layer;
  bad.features[1] = feature(8, 400, FieldValue{std::int64_t(99)});
  expect_bad(bad, "parent 99");
  bad = layer;
  bad.fields[1].name = "r";
  expect_bad(bad, "no radius_m");
}
