// Road classes from the settlement hierarchy.
// SPDX-License-Identifier: MIT
#include "roads/road_class.hpp"

#include <algorithm>

namespace terrapolis::roads {

std::optional<RoadClass> road_class_named(std::string_view name) {
  for (const RoadClassStyle& s : kRoadClasses)
    if (s.name == name) return s.road_class;
  return std::nullopt;
}

RoadClass link_class(int a, int b, int classes) {
  if (a < 0 || b < 0 || classes <= 0) return RoadClass::departmental;
  const int smaller = std::min(std::max(a, b), classes - 1);
  return RoadClass(std::min(3, 4 * smaller / classes));
}

}  // namespace terrapolis::roads
