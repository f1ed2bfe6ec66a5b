// The one formatter of JSON Schema errors (scenarios, plugin parameters): valijson reports the
// failing field and every object enclosing it; the deepest report is the specific one.
// SPDX-License-Identifier: MIT
#pragma once
#include <valijson/validation_results.hpp>

#include <string>
#include <utility>

#include "core/text.hpp"

namespace terrapolis {

/// The JSON pointer ("/density/r_max_m", "/" for the root) and the problem of the most specific error.
inline std::pair<std::string, std::string> schema_error(const valijson::ValidationResults& results) {
  valijson::ValidationResults::Error best;
  for (const auto& e : results)
    if (e.context.size() > best.context.size()) best = e;
  return {json_pointer_of(best.context), best.description};
}

}  // namespace terrapolis
