// The one formatter of JSON Schema errors (scenarios, plugin parameters): valijson reports the
// failing field and every object enclosing it; the deepest report is the specific one.
// SPDX-License-Identifier: MIT
#pragma once
#include <valijson/validation_results.hpp>

#include <string>
#include <string_view>
#include <utility>

#include "core/text.hpp"

namespace terrapolis {

/// The JSON pointer ("/density/r_max_m", "/" for the root) and the problem of the most specific
/// error. A key the schema does not declare is named by its own pointer: "/road/slope", "unknown key".
inline std::pair<std::string, std::string> schema_error(const valijson::ValidationResults& results) {
  valijson::ValidationResults::Error best;
  for (const auto& e : results)
    if (e.context.size() > best.context.size()) best = e;
  std::string pointer = json_pointer_of(best.context);
  static constexpr std::string_view kUndeclared = "Object contains a property that could not be validated using 'properties' or 'additionalProperties' constraints: '";
  if (best.description.starts_with(kUndeclared) && best.description.ends_with("'.")) {
    const std::string key = best.description.substr(kUndeclared.size(), best.description.size() - kUndeclared.size() - 2);
    return {(pointer == "/" ? "" : pointer) + "/" + key, "unknown key"};
  }
  return {pointer, best.description};
}

}  // namespace terrapolis
