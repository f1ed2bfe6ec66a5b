// Scenario loading and validation (valijson against the embedded JSON Schema).
// SPDX-License-Identifier: MIT
#include "pipeline/scenario.hpp"

#include <valijson/adapters/nlohmann_json_adapter.hpp>
#include <valijson/schema.hpp>
#include <valijson/schema_parser.hpp>
#include <valijson/validator.hpp>

#include <sstream>

#include "core/error.hpp"
#include "core/json_input.hpp"
#include "core/schema_error.hpp"
#include "core/text.hpp"

namespace terrapolis::pipeline {
namespace {

using json = nlohmann::ordered_json;

const nlohmann::json& schema_json_for_validation(nlohmann::json& storage) {
  storage = nlohmann::json::parse(scenario_schema_text());
  return storage;
}

/// Defaults of an object schema, recursively ("default" of each property; objects from their properties).
json defaults_of(const nlohmann::json& schema) {
  if (schema.value("type", "") == "object" && schema.contains("properties")) {
    json out = json::object();
    for (const auto& [key, sub] : schema["properties"].items()) {
      json d = defaults_of(sub);
      if (!d.is_null()) out[key] = d;
    }
    return out;
  }
  if (schema.contains("default")) return json(schema["default"]);
  return nullptr;
}

/// The complete scenario in the schema's key order: the user's value where given, else the default
/// (objects merged recursively), so equal scenarios print and hash the same however they were typed.
json with_defaults(const json& doc, const json& defaults) {
  json out = json::object();
  for (const auto& [key, value] : defaults.items()) {
    if (!doc.contains(key)) out[key] = value;
    else if (value.is_object() && doc[key].is_object()) out[key] = with_defaults(doc[key], value);
    else out[key] = doc[key];
  }
  return out;
}


/// Adds to `doc` what `values` has and it has not, object by object (nothing given is replaced).
void fill_missing(json& doc, const json& values) {
  for (const auto& [key, value] : values.items()) {
    if (!doc.contains(key)) doc[key] = value;
    else if (value.is_object() && doc[key].is_object()) fill_missing(doc[key], value);
  }
}

void apply_set(json& doc, const std::string& set) {
  const auto eq = set.find('=');
  if (eq == std::string::npos || eq == 0) throw bad_input("--set " + set + ": expected stage.field=value");
  const std::string key = set.substr(0, eq), text = set.substr(eq + 1);
  check_json_text(text, "--set " + key);
  json value;
  try {
    value = json::parse(text);
  } catch (const json::parse_error&) {
    value = text;  // a bare word is a string
  } catch (const json::exception& e) {
    throw bad_input("--set " + set + ": " + json_error_text(e.what()));
  }
  json* node = &doc;
  std::stringstream parts(key);
  std::string part;
  std::vector<std::string> path;
  while (std::getline(parts, part, '.')) path.push_back(part);
  if (path.size() > std::size_t(kMaxJsonDepth)) throw bad_input("--set " + key + ": nests deeper than " + std::to_string(kMaxJsonDepth) + " levels");
  for (std::size_t i = 0; i + 1 < path.size(); ++i) {
    json& next = (*node)[path[i]];
    if (next.is_null()) next = json::object();
    if (!next.is_object()) throw bad_input("--set " + set + ": " + path[i] + " is not a section");
    node = &next;
  }
  (*node)[path.back()] = value;
}

}  // namespace

std::string Scenario::path(const std::string& field) const {
  const json& value = field.starts_with('/') ? resolved.at(json::json_pointer(field)) : resolved.at(field);
  return file(value.get<std::string>(), field == "dem");
}

std::string Scenario::file(const std::string& name, bool bundled_fallback) const {
  const std::filesystem::path p = name;
  if (name.empty() || p.is_absolute()) return name;
  if (!base_dir.empty()) return (base_dir / p).lexically_normal().string();
  // The default scenario names the bundled DEM relative to the source tree; find it from elsewhere too.
  std::error_code ec;
  const std::filesystem::path bundled = std::filesystem::path(TERRAPOLIS_SOURCE_DIR) / p;
  if (bundled_fallback && !std::filesystem::exists(p, ec) && std::filesystem::exists(bundled, ec)) return bundled.string();
  return p.string();
}

json schema_defaults() { return defaults_of(nlohmann::json::parse(scenario_schema_text())); }

std::string validate_scenario(const json& scenario) {
  nlohmann::json schema_doc;
  schema_json_for_validation(schema_doc);
  valijson::Schema schema;
  valijson::SchemaParser parser;
  valijson::adapters::NlohmannJsonAdapter schema_adapter(schema_doc);
  parser.populateSchema(schema_adapter, schema);
  const nlohmann::json doc = nlohmann::json::parse(scenario.dump());
  valijson::Validator validator;
  valijson::ValidationResults results;
  valijson::adapters::NlohmannJsonAdapter target(doc);
  if (validator.validate(schema, target, &results)) return "";
  const auto [pointer, problem] = schema_error(results, &schema_doc);
  return pointer + ": " + problem;
}

namespace {

/// Overrides, validation and defaults over a parsed document.
void resolve(Scenario& s, json doc, const std::vector<std::string>& sets, std::optional<std::uint64_t> seed) {
  if (!doc.is_object()) throw bad_input(s.source + ": /: a scenario is a JSON object");
  for (const auto& set : sets) apply_set(doc, set);
  if (seed) doc["seed"] = *seed;
  const std::string problem = validate_scenario(doc);
  if (!problem.empty()) throw bad_input(s.source + ": " + problem);
  // A section's preset (density.preset, network.preset): its settings stand in for the schema's
  // defaults of the settings not given (x-presets of the section's preset field).
  const nlohmann::json schema_doc = nlohmann::json::parse(scenario_schema_text());
  for (const auto& [section, sub] : schema_doc["properties"].items()) {
    if (!sub.contains("properties") || !sub["properties"].contains("preset") || !doc.contains(section) || !doc[section].contains("preset")) continue;
    const json& presets = sub["properties"]["preset"]["x-presets"];
    if (const std::string preset = doc[section]["preset"].get<std::string>(); presets.contains(preset))
      fill_missing(doc[section], presets[preset]);
  }
  s.resolved = with_defaults(doc, schema_defaults());
  // Objects listed in a top-level array (plugins) get their own defaults too.
  for (const auto& [key, sub] : schema_doc["properties"].items())
    if (sub.value("type", "") == "array" && sub.contains("items") && sub["items"].contains("properties")) {
      const json item_defaults = defaults_of(sub["items"]);
      for (auto& item : s.resolved[key])
        for (const auto& [field, value] : item_defaults.items())
          if (!item.contains(field)) item[field] = value;
    }
}

}  // namespace

Scenario scenario_from_text(const std::string& text, const std::string& source, const std::vector<std::string>& sets,
                            std::optional<std::uint64_t> seed) {
  Scenario s;
  s.source = source;
  check_json_text(text, source);
  json doc;
  try {
    doc = json::parse(text);
  } catch (const json::exception& e) {
    throw bad_input(source + ": not valid JSON (" + json_error_text(e.what()) + ")");
  }
  resolve(s, std::move(doc), sets, seed);
  return s;
}

Scenario load_scenario(const std::string& file, const std::vector<std::string>& sets, std::optional<std::uint64_t> seed) {
  if (file.empty()) {
    Scenario s;
    s.source = "(default scenario)";
    resolve(s, json::object(), sets, seed);
    return s;
  }
  std::error_code ec;
  if (!std::filesystem::is_regular_file(file, ec)) throw bad_input(file + ": no such scenario file");
  Scenario s = scenario_from_text(read_json_file(file), file, sets, seed);
  s.base_dir = std::filesystem::path(file).parent_path();
  return s;
}

}  // namespace terrapolis::pipeline
