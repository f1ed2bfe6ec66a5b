// GeoJSON written per RFC 7946 (lon/lat, right-hand rule, no crs member) and read back.
// SPDX-License-Identifier: MIT
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include "io/crs.hpp"
#include "io/vector_io.hpp"
#include "support/temp_dir.hpp"

using namespace terrapolis;
using terrapolis::test::TempDir;

TEST(VectorIo, GeoJsonIsRfc7946) {
  TempDir dir;
  VectorLayer layer;
  layer.name = "squares";
  layer.geometry = GeometryType::polygon;
  layer.crs = crs_from_user("EPSG:26918");  // UTM 18N
  layer.fields = {{"id", FieldType::integer}, {"label", FieldType::string}, {"area_m2", FieldType::real}};
  // A clockwise square in UTM: the writer must make the outer ring counter-clockwise.
  const double x = 670000, y = 4890000;
  layer.features.push_back({{{{x, y}, {x, y + 1000}, {x + 1000, y + 1000}, {x + 1000, y}, {x, y}}}, {std::int64_t(7), std::string("a"), 1e6}});
  write_vector(dir.file("sq.geojson"), layer);
  std::ifstream in(dir.file("sq.geojson"));
  const auto j = nlohmann::json::parse(in);
  EXPECT_FALSE(j.contains("crs"));
  const auto& ring = j["features"][0]["geometry"]["coordinates"][0];
  double lon = ring[0][0], lat = ring[0][1];
  EXPECT_NEAR(lon, -72.87, 0.1);
  EXPECT_NEAR(lat, 44.15, 0.1);
  double twice_area = 0;  // shoelace: positive means counter-clockwise
  for (std::size_t i = 0; i + 1 < ring.size(); ++i)
    twice_area += double(ring[i][0]) * double(ring[i + 1][1]) - double(ring[i + 1][0]) * double(ring[i][1]);
  EXPECT_GT(twice_area, 0);
  EXPECT_EQ(j["features"][0]["properties"]["id"], 7);

  const VectorLayer back = read_vector(dir.file("sq.geojson"), layer.crs);
  ASSERT_EQ(back.features.size(), 1u);
  EXPECT_EQ(back.geometry, GeometryType::polygon);
  EXPECT_NEAR(back.features[0].parts[0][0][0], x, 0.05);  // 7 decimals of a degree is about 1 cm
  EXPECT_EQ(back.field_index("label"), 1);
}

TEST(VectorIo, GeoPackageKeepsTheLayerCrs) {
  TempDir dir;
  VectorLayer layer;
  layer.name = "pts";
  layer.geometry = GeometryType::point;
  layer.crs = crs_from_user("EPSG:32611");
  layer.fields = {{"z", FieldType::real}};
  layer.features.push_back({{{{400000.0, 3800000.0}}}, {1.5}});
  write_vector(dir.file("p.gpkg"), layer);
  const VectorLayer back = read_vector(dir.file("p.gpkg"), layer.crs);
  ASSERT_EQ(back.features.size(), 1u);
  EXPECT_NEAR(back.features[0].parts[0][0][0], 400000.0, 1e-6);
  EXPECT_DOUBLE_EQ(std::get<double>(back.features[0].values[0]), 1.5);
}
