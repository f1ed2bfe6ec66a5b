// Scenario files: parsed, overridden with --set, validated against schemas/scenario.schema.json, defaults filled.
// SPDX-License-Identifier: MIT
#pragma once
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

namespace terrapolis::pipeline {

/// The scenario schema, embedded at build time from schemas/scenario.schema.json.
std::string_view scenario_schema_text();

/// A validated scenario with every default filled in.
struct Scenario {
  nlohmann::ordered_json resolved;  ///< the complete scenario, as recorded in run.json
  std::filesystem::path base_dir;   ///< relative paths in the scenario are relative to this
  std::string source;               ///< the scenario file, or "(default scenario)"
  /// Path field (a top-level key or a JSON pointer such as "/roads/costs") resolved against base_dir;
  /// "" stays "" (the field is unset).
  std::string path(const std::string& field) const;
  /// A file name from the scenario resolved against base_dir; `bundled_fallback` also looks in the
  /// source tree (the default scenario's bundled DEM).
  std::string file(const std::string& name, bool bundled_fallback = false) const;
};

/// Loads `file` (empty: the embedded default scenario, relative to the working folder), applies
/// `sets` ("stage.field=value", value parsed as JSON when it parses, else as a string) and `seed`,
/// validates and fills defaults. Throws bad_input naming the file, the JSON pointer and the problem.
Scenario load_scenario(const std::string& file, const std::vector<std::string>& sets = {},
                       std::optional<std::uint64_t> seed = std::nullopt);

/// The same from the scenario's JSON text; `source` names it in errors (base_dir is left empty).
/// Bounded before parsing (core/json_input.hpp). The scenario fuzz harness's entry point.
Scenario scenario_from_text(const std::string& text, const std::string& source, const std::vector<std::string>& sets = {},
                            std::optional<std::uint64_t> seed = std::nullopt);

/// The object of all defaults declared in the schema (the embedded default scenario).
nlohmann::ordered_json schema_defaults();

/// Validates a scenario document; returns "" or "/json/pointer: problem" for the first error.
std::string validate_scenario(const nlohmann::ordered_json& scenario);

}  // namespace terrapolis::pipeline
