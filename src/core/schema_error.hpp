// The one formatter of JSON Schema errors (scenarios, plugin parameters): valijson reports the
// failing field and every object enclosing it; the deepest report is the specific one.
// SPDX-License-Identifier: MIT
#pragma once
#include <nlohmann/json.hpp>
#include <valijson/validation_results.hpp>

#include <algorithm>

#include <string>
#include <string_view>
#include <utility>

#include "core/text.hpp"

namespace terrapolis {

/// valijson's description of a problem in a user's words: "Expected number less than or equal to
/// 100.000000" is "must be <= 100"; a type or choice the schema refuses says so.
inline std::string plain_problem(const std::string& description) {
  static const std::pair<std::string_view, std::string_view> bounds[] = {{"Expected number less than or equal to ", "must be <= "},
                                                                         {"Expected number greater than or equal to ", "must be >= "},
                                                                         {"Expected number less than ", "must be < "},
                                                                         {"Expected number greater than ", "must be > "}};
  for (const auto& [said, meant] : bounds)
    if (description.starts_with(said)) {
      std::string number = description.substr(said.size());
      if (number.find('.') != std::string::npos) {  // std::to_string's six decimals, trailing zeros dropped
        number.erase(number.find_last_not_of('0') + 1);
        if (number.back() == '.') number.pop_back();
      }
      return std::string(meant) + number;
    }
  static const std::pair<std::string_view, std::string_view> counts[] = {{"Array should contain no more than ", "at most "},
                                                                         {"Array should contain no fewer than ", "at least "}};
  for (const auto& [said, meant] : counts)
    if (description.starts_with(said) && description.ends_with(" elements."))
      return "must have " + std::string(meant) + description.substr(said.size(), description.size() - said.size() - 10) + " items";
  if (description == "Value type not permitted by 'type' constraint.") return "wrong type (see the schema)";
  if (description == "Failed to match against any enum values.") return "not one of the allowed values (see --help or the schema)";
  return description;
}

/// The schema's field of the value at `pointer` (nullptr when the walk finds none): the schema walked
/// along the pointer's keys (properties, array items, local "#/definitions/..." references).
inline const nlohmann::json* schema_field(const nlohmann::json& schema, const std::string& pointer) {
  const nlohmann::json* node = &schema;
  auto resolve = [&] {
    while (node->is_object() && node->contains("$ref") && (*node)["$ref"].is_string()) {
      const std::string ref = (*node)["$ref"].get<std::string>();
      if (!ref.starts_with("#/")) return;
      node = &schema.at(nlohmann::json::json_pointer(ref.substr(1)));
    }
  };
  std::size_t at = 1;
  while (at <= pointer.size() && pointer != "/") {
    const std::size_t next = std::min(pointer.find('/', at), pointer.size());
    const std::string key = pointer.substr(at, next - at);
    resolve();
    if (node->contains("properties") && (*node)["properties"].contains(key)) node = &(*node)["properties"][key];
    else if (node->contains("items") && (*node)["items"].is_object()) node = &(*node)["items"];
    else return nullptr;
    at = next + 1;
  }
  resolve();
  return node->is_object() ? node : nullptr;
}

/// What the field wants, said from its schema: "must be one of a, b, c" (its choices) or "must be
/// an integer" (its type); "" when the field says neither.
inline std::string field_wants(const nlohmann::json& field, const std::string& problem) {
  if (field.contains("enum")) {
    std::string choices;
    for (const auto& c : field["enum"]) choices += (choices.empty() ? "" : ", ") + (c.is_string() ? c.get<std::string>() : c.dump());
    return "must be one of " + choices;
  }
  if (problem != "Value type not permitted by 'type' constraint." || !field.contains("type")) return "";
  static const std::pair<std::string_view, std::string_view> names[] = {
      {"integer", "an integer"}, {"number", "a number"}, {"string", "a string"}, {"boolean", "true or false"},
      {"array", "a list [...]"}, {"object", "an object {...}"}, {"null", "null"}};
  std::string wanted;
  for (const auto& t : field["type"].is_array() ? field["type"] : nlohmann::json::array({field["type"]}))
    for (const auto& [type, said] : names)
      if (t.is_string() && t.get<std::string>() == type) wanted += (wanted.empty() ? "" : " or ") + std::string(said);
  return wanted.empty() ? "" : "must be " + wanted;
}

/// The JSON pointer ("/density/r_max_m", "/" for the root) and the problem of the most specific
/// error. A key the schema does not declare is named by its own pointer: "/road/slope", "unknown key";
/// a value outside the schema's choices lists them when `schema` is given.
inline std::pair<std::string, std::string> schema_error(const valijson::ValidationResults& results, const nlohmann::json* schema = nullptr) {
  valijson::ValidationResults::Error best;
  for (const auto& e : results)
    if (e.context.size() > best.context.size()) best = e;
  std::string pointer = json_pointer_of(best.context);
  static constexpr std::string_view kUndeclared = "Object contains a property that could not be validated using 'properties' or 'additionalProperties' constraints: '";
  if (best.description.starts_with(kUndeclared) && best.description.ends_with("'.")) {
    const std::string key = best.description.substr(kUndeclared.size(), best.description.size() - kUndeclared.size() - 2);
    return {(pointer == "/" ? "" : pointer) + "/" + key, "unknown key"};
  }
  if (const nlohmann::json* field = schema ? schema_field(*schema, pointer) : nullptr)
    if (std::string wants = field_wants(*field, best.description); !wants.empty()) return {pointer, wants};
  return {pointer, plain_problem(best.description)};
}

}  // namespace terrapolis
