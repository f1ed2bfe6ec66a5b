// Command-line options declared by the scenario schema (schemas/scenario.schema.json), and the file
// kinds of the commands' own path options: what --help, --describe-json and the QGIS provider read.
// SPDX-License-Identifier: MIT
#pragma once
#include <nlohmann/json.hpp>

#include <deque>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "pipeline/scenario.hpp"

namespace CLI {
class App;
class Option;
}  // namespace CLI

namespace terrapolis::cli {

/// What a path-valued option reads or writes, for GUIs (QGIS parameter types).
enum class FileKind { raster_in, vector_in, file_in, folder_in, raster_out, vector_out, file_out, folder_out };

/// Marks a command's own path option (positional arguments, outputs, files outside the schema) with
/// its kind; returns the option. The small per-command table of docs/architecture.md.
CLI::Option* file_kind(CLI::Option* option, FileKind kind);

/// Where --describe-json reads an option's description: its schema field ("" pointer for the
/// command's own options, whose CLI11 declaration is then the description) and its file kind.
struct OptionSource {
  std::string pointer;          ///< "/hydro/fill"; "" for a command's own option
  nlohmann::ordered_json field;  ///< the schema's field, with the command's default in "default"
  std::string kind;              ///< raster_in, file_out, ...; "" for values that are not paths
};
/// The source of `option`, or nullptr for an option declared without either (a number, a flag).
const OptionSource* option_source(const CLI::Option& option);


/// The schema fields a command exposes: every field whose "x-cli" names the command, as
/// `"x-cli": {"hydro": "--fill"}` (or {"flag": "--sea-level", "default": null} where the command's
/// default differs from the scenario's; null: off unless given). Adding such a field to the schema
/// adds the option to the command; the command's stage settings function reads it from the scenario.
class SchemaOptions {
 public:
  /// Declares each field as an option of `app`: help = description and unit, default, range and
  /// choices. `names_messages`: the command's error messages name these fields by their flags
  /// (with_flag_names); off for `run`, whose messages name the scenario's settings by pointer.
  void setup(CLI::App& app, const std::string& command, bool names_messages = true);
  /// True when the option of the field at `pointer` ("/water/sea_level_m") was given.
  bool given(const std::string& pointer) const;
  /// The command's settings as a scenario: `base` ("section.field=value", the command's own
  /// defaults and table options), then the options given, validated and completed by the schema
  /// exactly as a scenario file is. Errors name the command's flags.
  pipeline::Scenario scenario(const std::vector<std::string>& base = {}) const;
  /// Runs a stage's settings function on the command's scenario; its errors name flags, not pointers.
  template <class Make>
  auto settings(Make&& make) const -> decltype(make()) {
    try {
      return make();
    } catch (const Error& e) {
      throw Error(e.kind(), with_flags(e.what()));
    }
  }
  /// Names the schema fields under `pointer` by a command's own option (`--weights` for /density/weights).
  void name_as(const std::string& pointer, const std::string& flag) { aliases_.emplace_back(pointer, flag); }
  /// `message` with the JSON pointers and dotted names of this command's fields replaced by their flags.
  std::string with_flags(std::string message) const;

 private:
  struct Entry {
    std::string pointer, flag;
    nlohmann::ordered_json field;
    CLI::Option* option = nullptr;
    std::string text;  ///< the value typed, for valued options
    bool on = false;   ///< the value of a flag
    bool own_default = false;  ///< the command's default differs from the scenario's
  };
  std::string command_;
  std::vector<std::pair<std::string, std::string>> aliases_;  ///< (pointer, flag) of the command's own options
  std::deque<Entry> entries_;  // CLI11 binds to the members: addresses must stay put
};

/// A module's message names a setting by its JSON pointer ("/roads/k: ..."); the user of a command
/// knows it by the command's flag: SchemaOptions::with_flags of `command` (the message unchanged
/// when the command declares no schema options).
std::string with_flag_names(const std::string& message, const std::string& command);

/// The schema's fields of `command` as (JSON pointer, field with x-cli), in schema order.
std::vector<std::pair<std::string, nlohmann::ordered_json>> schema_fields_of(const std::string& command);

}  // namespace terrapolis::cli
