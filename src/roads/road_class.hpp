// Road classes: one table of names, colours and widths, shared by the layers, the preview and the QGIS styles.
// SPDX-License-Identifier: MIT
#pragma once
#include <array>
#include <optional>
#include <string_view>

namespace terrapolis::roads {

/// The class of a road, from the settlement hierarchy (see link_class); `maritime` marks a ferry link.
enum class RoadClass { motorway, national, departmental, local, maritime };

struct RoadClassStyle {
  RoadClass road_class;
  std::string_view name;    ///< the value of the layers' `class` field
  std::string_view label;   ///< the legend's text
  std::string_view colour;  ///< #rrggbb, in the preview and in QGIS
  double width_mm;          ///< QGIS line width; the preview scales it
  bool dashed;
};

/// The table, most important class first.
inline constexpr std::array<RoadClassStyle, 5> kRoadClasses = {{
    {RoadClass::motorway, "motorway", "motorway", "#e31a1c", 1.2, false},
    {RoadClass::national, "national", "national road", "#ff7f00", 0.8, false},
    {RoadClass::departmental, "departmental", "departmental road", "#d4a017", 0.5, false},
    {RoadClass::local, "local", "local road", "#969696", 0.3, false},
    {RoadClass::maritime, "maritime", "maritime link", "#1f78b4", 0.5, true},
}};

constexpr const RoadClassStyle& style_of(RoadClass c) { return kRoadClasses[std::size_t(c)]; }
constexpr std::string_view name_of(RoadClass c) { return style_of(c).name; }
/// The class named `name`, or nullopt.
std::optional<RoadClass> road_class_named(std::string_view name);

/// The class of a link between two settlements of hierarchy levels `a` and `b` (0 = the top,
/// `classes` levels in all): a link is as important as its smaller end (Galin et al. 2011 route a
/// level of the hierarchy between the settlements of that level and above). The smaller end's
/// level, as a fraction of the levels, picks the road class by quarters: motorways join the top
/// quarter, then national, departmental and local roads (network::road_links gives 4 levels).
/// Unknown levels (negative) give a departmental road.
RoadClass link_class(int a, int b, int classes);

}  // namespace terrapolis::roads
