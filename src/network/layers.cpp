// Conversion of the network to a vector layer.
// SPDX-License-Identifier: MIT
#include "network/layers.hpp"

#include <cmath>

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

}  // namespace terrapolis::network
