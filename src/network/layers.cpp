// Conversion of the network to a vector layer.
// SPDX-License-Identifier: MIT
#include "network/layers.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>

#include "core/error.hpp"

namespace terrapolis::network {

VectorLayer network_layer(const SiteGraph& graph, const std::vector<sites::Site>& sites, const Crs& crs) {
  VectorLayer layer;
  layer.name = "network";
  layer.geometry = GeometryType::line_string;
  layer.crs = crs;
  layer.fields = {{"from", FieldType::integer}, {"to", FieldType::integer},      {"kind", FieldType::string},
                  {"kept", FieldType::integer}, {"length_m", FieldType::real}, {"detour_ratio", FieldType::real}};
  for (const Edge& e : graph.edges) {
    const auto& a = sites[std::size_t(e.from)];
    const auto& b = sites[std::size_t(e.to)];
    Feature f;
    f.parts = {{{a.x, a.y}, {b.x, b.y}}};
    // One value at a time: a braced list of variants trips GCC's -Wmaybe-uninitialized.
    f.values.resize(layer.fields.size());
    f.values[0] = std::int64_t(a.id);
    f.values[1] = std::int64_t(b.id);
    f.values[2] = std::string(to_string(e.kind));
    f.values[3] = std::int64_t(e.kept ? 1 : 0);
    f.values[4] = e.length_m;
    if (!std::isnan(e.detour_ratio)) f.values[5] = e.detour_ratio;
    layer.features.push_back(std::move(f));
  }
  return layer;
}

namespace {
std::optional<std::int64_t> as_int(const FieldValue& v) {
  if (const auto* i = std::get_if<std::int64_t>(&v)) return *i;
  if (const auto* d = std::get_if<double>(&v)) return std::int64_t(std::llround(*d));
  return std::nullopt;
}
}  // namespace

/// The fewest people of a city at a motorway's end, at a national road's.
constexpr double kMotorwayPeople = 100000, kNationalPeople = 10000;

std::vector<roads::Link> road_links(const VectorLayer& network, const VectorLayer* cities) {
  const int f_from = network.field_index("from"), f_to = network.field_index("to"), f_kept = network.field_index("kept");
  if (f_from < 0 || f_to < 0) throw bad_input(network.name + ": the network needs integer fields 'from' and 'to'");
  if (network.geometry != GeometryType::line_string) throw bad_input(network.name + ": the network must hold LineStrings");
  // The hierarchy level of each city from its rank by population (then size class, then id): the
  // levels of a central-place hierarchy of ratio 3 (Christaller 1933; docs/roads.md): the 1 + 3
  // highest centres are level 0, the next 9 level 1, the next 27 level 2, the rest level 3.
  std::map<std::int64_t, int> city_class;
  const int classes = 4;
  if (cities) {
    const int f_id = cities->field_index("id"), f_class = cities->field_index("class"), f_pop = cities->field_index("population");
    if (f_id < 0 || f_class < 0) throw bad_input(cities->name + ": the cities need integer fields 'id' and 'class'");
    struct Ranked {
      double population;
      std::int64_t size_class, id;
    };
    std::vector<Ranked> ranked;
    for (const Feature& f : cities->features) {
      const auto id = as_int(f.values[std::size_t(f_id)]), cls = as_int(f.values[std::size_t(f_class)]);
      if (!id || !cls || *cls < 0) continue;
      double population = 0;
      if (f_pop >= 0) {
        if (const auto* d = std::get_if<double>(&f.values[std::size_t(f_pop)])) population = *d;
        else if (const auto i = as_int(f.values[std::size_t(f_pop)])) population = double(*i);
      }
      ranked.push_back({population, *cls, *id});
    }
    std::sort(ranked.begin(), ranked.end(), [](const Ranked& x, const Ranked& y) {
      if (x.population != y.population) return x.population > y.population;
      return x.size_class != y.size_class ? x.size_class < y.size_class : x.id < y.id;
    });
    // A level also needs the people of its order: a motorway end a city of 100,000 or more, a
    // national road's one of 10,000 (the levels of access.levels_population), so the towns of a
    // rural region are joined by departmental roads, not by roads built to 6-7 % grades.
    const auto floor_level = [](double people) { return people >= kMotorwayPeople ? 0 : people >= kNationalPeople ? 1 : 2; };
    for (std::size_t r = 0; r < ranked.size(); ++r)
      city_class[ranked[r].id] = std::max(r < 4 ? 0 : r < 13 ? 1 : r < 40 ? 2 : 3, floor_level(ranked[r].population));
  }
  auto class_of = [&](std::int64_t id) {
    const auto it = city_class.find(id);
    return it == city_class.end() ? -1 : it->second;
  };
  std::vector<roads::Link> links;
  for (const Feature& f : network.features) {
    if (f_kept >= 0) {
      const auto kept = as_int(f.values[std::size_t(f_kept)]);
      if (kept && *kept == 0) continue;
    }
    if (f.parts.empty() || f.parts[0].size() < 2) continue;
    roads::Link l;
    l.from = as_int(f.values[std::size_t(f_from)]).value_or(-1);
    l.to = as_int(f.values[std::size_t(f_to)]).value_or(-1);
    l.a = f.parts[0].front();
    l.b = f.parts[0].back();
    l.road_class = roads::link_class(class_of(l.from), class_of(l.to), classes);
    links.push_back(l);
  }
  return links;
}

}  // namespace terrapolis::network
