// Conversions between sites and vector layers.
// SPDX-License-Identifier: MIT
#include "sites/layers.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>

#include "core/error.hpp"
#include "core/geodesy.hpp"
#include "io/crs.hpp"

namespace terrapolis::sites {

VectorLayer cities_layer(const SitesResult& result, const Crs& crs) {
  VectorLayer layer;
  layer.name = "cities";
  layer.geometry = GeometryType::point;
  layer.crs = crs;
  layer.fields = {{"id", FieldType::integer},     {"radius_m", FieldType::real}, {"class", FieldType::integer},
                  {"population", FieldType::integer}, {"density", FieldType::real},  {"parent", FieldType::integer},
                  {"depth", FieldType::integer},  {"seed", FieldType::integer}};
  // Given places (sites.existing) are told apart, by name; without any the layer is as it was.
  const bool with_existing = std::any_of(result.sites.begin(), result.sites.end(), [](const Site& s) { return s.existing; });
  if (with_existing) layer.fields.insert(layer.fields.end(), {{"existing", FieldType::integer}, {"name", FieldType::string}});
  // A growth scenario says what each settlement gained (a new one: all its people).
  const bool with_growth = result.growth_people > 0;
  if (with_growth) layer.fields.push_back({"gained", FieldType::integer});
  for (const Site& s : result.sites) {
    Feature f;
    f.parts = {{{s.x, s.y}}};
    // One value at a time: a braced list of variants trips GCC's -Wmaybe-uninitialized.
    f.values.resize(layer.fields.size());
    f.values[0] = std::int64_t(s.id);
    f.values[1] = s.radius_m;
    f.values[2] = std::int64_t(s.radius_class);
    f.values[3] = std::int64_t(s.population);
    f.values[4] = s.density;
    if (s.parent >= 0) f.values[5] = std::int64_t(s.parent);
    f.values[6] = std::int64_t(s.depth);
    f.values[7] = std::int64_t(result.seed);
    if (with_existing) {
      f.values[8] = std::int64_t(s.existing);
      if (s.existing) f.values[9] = s.name;
    }
    if (with_growth) f.values[10] = std::int64_t(s.gained);
    layer.features.push_back(std::move(f));
  }
  return layer;
}

VectorLayer city_extents_layer(const SitesResult& result, const Crs& crs, int vertices) {
  VectorLayer layer;
  layer.name = "city_extents";
  layer.geometry = GeometryType::polygon;
  layer.crs = wgs84();
  layer.fields = {{"id", FieldType::integer}, {"radius_m", FieldType::real}, {"class", FieldType::integer}, {"depth", FieldType::integer},
                  {"seed", FieldType::integer}};
  const CrsTransform to_lonlat(crs, wgs84());
  std::vector<std::array<double, 2>> centres;
  for (const Site& s : result.sites) centres.push_back(to_lonlat(s.x, s.y));
  const Ellipsoid wgs84_ellipsoid;
  layer.features.resize(result.sites.size());
  // Each circle is independent (and the geodesic problems are the cost): in parallel.
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, result.sites.size(), 64), [&](const tbb::blocked_range<std::size_t>& range) {
    for (std::size_t i = range.begin(); i < range.end(); ++i) {
      const Site& s = result.sites[i];
      std::vector<std::array<double, 2>> ring;
      for (int k = 0; k < vertices; ++k)  // clockwise from north
        ring.push_back(geodesic_destination(wgs84_ellipsoid, centres[i][0], centres[i][1], 360.0 * k / vertices, s.radius_m));
      ring.push_back(ring.front());
      Feature& f = layer.features[i];
      f.parts = {ring};
      f.values.resize(layer.fields.size());
      f.values[0] = std::int64_t(s.id);
      f.values[1] = s.radius_m;
      f.values[2] = std::int64_t(s.radius_class);
      f.values[3] = std::int64_t(s.depth);
      f.values[4] = std::int64_t(result.seed);
    }
  });
  return layer;
}

void snap_to_cells(std::vector<Site>& sites, const Georef& georef, int cols, int rows) {
  const GeoTransform& t = georef.transform;
  if (t[2] != 0 || t[4] != 0) return;
  for (auto& site : sites) {
    site.col = std::clamp(int(std::floor((site.x - t[0]) / t[1])), 0, cols - 1);
    site.row = std::clamp(int(std::floor((site.y - t[3]) / t[5])), 0, rows - 1);
    const auto xy = georef.cell_centre(site.col, site.row);
    site.x = xy[0];
    site.y = xy[1];
  }
}

std::vector<Site> sites_from_layer(const VectorLayer& layer, const std::string& path) {
  if (!layer.features.empty() && layer.geometry != GeometryType::point) throw bad_input(path + ": cities must be points");
  const int radius = layer.field_index("radius_m"), id = layer.field_index("id"), parent = layer.field_index("parent"),
            population = layer.field_index("population");
  if (radius < 0) throw bad_input(path + ": no radius_m field (the radius of each city, metres)");
  auto number = [&](const Feature& f, int field, std::size_t k) -> std::optional<double> {
    const auto& v = f.values[std::size_t(field)];
    if (std::holds_alternative<std::int64_t>(v)) return double(std::get<std::int64_t>(v));
    if (std::holds_alternative<double>(v)) return std::get<double>(v);
    if (std::holds_alternative<std::monostate>(v)) return std::nullopt;
    throw bad_input(path + ": feature " + std::to_string(k) + ": field " + layer.fields[std::size_t(field)].name + " is not a number");
  };
  std::vector<Site> sites;
  std::map<std::int64_t, int> index_of;
  std::vector<std::optional<double>> parents;
  for (std::size_t k = 0; k < layer.features.size(); ++k) {
    const Feature& f = layer.features[k];
    Site s;
    s.x = f.parts[0][0][0];
    s.y = f.parts[0][0][1];
    const auto r = number(f, radius, k);
    if (!r || !std::isfinite(*r) || *r <= 0) throw bad_input(path + ": feature " + std::to_string(k) + ": radius_m must be a positive number");
    s.radius_m = *r;
    const auto given = id >= 0 ? number(f, id, k) : std::optional<double>(double(k));
    if (!given || *given != std::floor(*given)) throw bad_input(path + ": feature " + std::to_string(k) + ": id must be an integer");
    s.id = int(*given);
    if (!index_of.emplace(std::int64_t(*given), int(k)).second) throw bad_input(path + ": id " + std::to_string(s.id) + " is used twice");
    parents.push_back(parent >= 0 ? number(f, parent, k) : std::nullopt);
    if (const auto p = population >= 0 ? number(f, population, k) : std::nullopt) s.population = std::llround(*p);
    sites.push_back(s);
  }
  for (std::size_t k = 0; k < sites.size(); ++k) {
    if (!parents[k]) continue;
    const auto it = index_of.find(std::int64_t(*parents[k]));
    if (it == index_of.end() || *parents[k] != std::floor(*parents[k]))
      throw bad_input(path + ": city " + std::to_string(sites[k].id) + " has parent " + std::to_string(std::llround(*parents[k])) + ", which is not a city id");
    sites[k].parent = it->second;
  }
  return sites;
}

}  // namespace terrapolis::sites
