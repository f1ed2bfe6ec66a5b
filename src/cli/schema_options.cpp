// Command-line options from the scenario schema: one declaration (the schema) for the scenario,
// the command line, --describe-json and the QGIS provider.
// SPDX-License-Identifier: MIT
#include "cli/schema_options.hpp"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <map>
#include <optional>
#include <regex>
#include <sstream>

#include "core/text.hpp"

namespace terrapolis::cli {
namespace {

using json = nlohmann::ordered_json;

std::map<const CLI::Option*, OptionSource>& sources() {
  static std::map<const CLI::Option*, OptionSource> all;
  return all;
}

constexpr const char* kKindNames[] = {"raster_in",  "vector_in",  "file_in",  "folder_in",
                                      "raster_out", "vector_out", "file_out", "folder_out"};

void collect(const json& schema, const std::string& pointer, const std::string& command,
             std::vector<std::pair<std::string, json>>& out) {
  if (!schema.contains("properties")) return;
  for (const auto& [key, field] : schema["properties"].items()) {
    const std::string at = pointer + "/" + key;
    if (field.contains("x-cli") && field["x-cli"].contains(command)) out.emplace_back(at, field);
    collect(field, at, command, out);
    // A list of objects (water.reservoirs): a command's flags fill one item, its first.
    if (field.contains("items") && field["items"].is_object()) collect(field["items"], at + "/0", command, out);
  }
}

/// The command's x-cli entry: its flag and, when the command's default differs, that default.
struct CliEntry {
  std::string flag;
  bool own_default = false;
  json default_value;
};
CliEntry cli_entry(const json& field, const std::string& command) {
  const json& e = field["x-cli"][command];
  if (e.is_string()) return {e.get<std::string>(), false, field.value("default", json())};
  return {e.at("flag").get<std::string>(), e.contains("default"), e.contains("default") ? e["default"] : field.value("default", json())};
}

/// Units worth printing in --help ("1", "flag", "choice" say nothing a reader needs).
bool printable_unit(const std::string& unit) {
  static const char* silent[] = {"", "1", "flag", "choice", "path", "list", "name", "object", "CRS"};
  return std::none_of(std::begin(silent), std::end(silent), [&](const char* s) { return unit == s; });
}

std::string help_of(const json& field) {
  const std::string unit = field.value("x-unit", "");
  std::string help = field.value("description", "");
  if (printable_unit(unit)) help += " [" + unit + "]";
  return help;
}

std::string type_name_of(const json& field) {
  if (field.contains("enum")) {
    std::string names;
    for (const auto& v : field["enum"]) names += (names.empty() ? "" : ",") + v.get<std::string>();
    return "{" + names + "}";
  }
  const std::string type = field.value("type", "string");
  if (type == "array") return field["items"].value("type", "") == "array" ? "LINESTRING" : "X,Y";
  return type == "integer" ? "INT" : type == "number" ? "FLOAT" : "TEXT";
}

/// "LINESTRING (x y, x y, ...)" (WKT) as [[x, y], ...]; nullopt when the text is not one.
std::optional<json> wkt_linestring(const std::string& text) {
  static const std::regex shape(R"(^\s*LINESTRING\s*\(([^()]*)\)\s*$)", std::regex::icase);
  std::smatch m;
  if (!std::regex_match(text, m, shape)) return std::nullopt;
  json points = json::array();
  std::stringstream body(m[1].str());
  for (std::string pair; std::getline(body, pair, ',');) {
    std::istringstream in(pair);
    std::string x, y, rest;
    if (!(in >> x >> y) || (in >> rest)) return std::nullopt;
    const auto px = parse_number(x), py = parse_number(y);
    if (!px || !py) return std::nullopt;
    points.push_back({*px, *py});
  }
  return points;
}

std::string default_text(const json& value) {
  if (value.is_null()) return "";
  return value.is_string() ? value.get<std::string>() : value.dump();
}

/// The typed text as the field's JSON type; left as text when it is not one (the schema then refuses it).
json typed_value(const json& field, const std::string& text) {
  const std::string type = field.value("type", "string");
  if (type == "integer") {
    std::size_t used = 0;
    try {
      const long long v = std::stoll(text, &used);
      if (used == text.size()) return v;
    } catch (const std::exception&) {
    }
    return text;
  }
  if (type == "number") {
    if (const auto v = parse_number(text)) return *v;
    return text;
  }
  if (type == "array") {  // a pair as X,Y; a line as WKT; either as JSON
    if (const json parsed = json::parse(text, nullptr, false); parsed.is_array()) return parsed;
    if (field["items"].value("type", "") == "array") {
      if (auto line = wkt_linestring(text)) return *line;
      throw bad_input("'" + text + "' is not a WKT LINESTRING (lon lat, lon lat, ...)");
    }
    const auto comma = text.find(',');
    const auto x = parse_number(text.substr(0, comma)), y = comma == std::string::npos ? std::nullopt : parse_number(text.substr(comma + 1));
    if (!x || !y) throw bad_input("'" + text + "' is not an X,Y pair of numbers");
    return json::array({*x, *y});
  }
  return text;
}

std::string dotted(const std::string& pointer) {
  std::string d = pointer.substr(1);
  std::replace(d.begin(), d.end(), '/', '.');
  return d;
}

}  // namespace

CLI::Option* file_kind(CLI::Option* option, FileKind kind) {
  sources()[option] = {"", json(), kKindNames[int(kind)]};
  return option;
}

const OptionSource* option_source(const CLI::Option& option) {
  const auto it = sources().find(&option);
  return it == sources().end() ? nullptr : &it->second;
}

namespace {
/// Each command's schema options, by command name (they live as long as their command).
std::map<std::string, const SchemaOptions*>& by_command() {
  static std::map<std::string, const SchemaOptions*> m;
  return m;
}
}  // namespace

std::string with_flag_names(const std::string& message, const std::string& command) {
  const auto it = by_command().find(command);
  return it == by_command().end() ? message : it->second->with_flags(message);
}

std::vector<std::pair<std::string, json>> schema_fields_of(const std::string& command) {
  std::vector<std::pair<std::string, json>> out;
  collect(json::parse(pipeline::scenario_schema_text()), "", command, out);
  return out;
}

void SchemaOptions::setup(CLI::App& app, const std::string& command, bool names_messages) {
  command_ = command;
  if (names_messages) by_command()[command] = this;
  for (auto& [pointer, field] : schema_fields_of(command)) {
    const CliEntry cli = cli_entry(field, command);
    Entry& e = entries_.emplace_back();
    e.pointer = pointer;
    e.flag = cli.flag;
    e.field = field;
    e.field["default"] = cli.default_value;
    e.own_default = cli.own_default;
    e.field.erase("x-cli");
    if (field.value("type", "") == "boolean") {
      e.on = cli.default_value.is_boolean() && cli.default_value.get<bool>();
      e.option = app.add_flag(cli.flag, e.on, help_of(field));
    } else {
      e.option = app.add_option(cli.flag, e.text, help_of(field))->type_name(type_name_of(field));
      if (!cli.default_value.is_null()) e.option->default_str(default_text(cli.default_value));
    }
    sources()[e.option] = {pointer, e.field, field.value("x-kind", "")};
  }
}

bool SchemaOptions::given(const std::string& pointer) const {
  for (const Entry& e : entries_)
    if (e.pointer == pointer) return e.option->count() > 0;
  return false;
}

pipeline::Scenario SchemaOptions::scenario(const std::vector<std::string>& base) const {
  std::vector<std::string> sets = base;
  std::map<std::string, json> items;  // a list's pointer -> its first item, from the fields under ".../0/"
  for (const Entry& e : entries_) {
    const bool flag = e.field.value("type", "") == "boolean";
    json value;
    try {
      if (e.option->count() > 0) value = flag ? json(e.on) : typed_value(e.field, e.text);
      else if (e.own_default) value = e.field["default"];
    } catch (const Error& error) {
      throw Error(error.kind(), e.flag.substr(0, e.flag.find(',')) + ": " + error.what());
    }
    if (value.is_null()) continue;
    if (const auto item = e.pointer.find("/0/"); item != std::string::npos)
      items[e.pointer.substr(0, item)][e.pointer.substr(item + 3)] = value;
    else
      sets.push_back(dotted(e.pointer) + "=" + value.dump());
  }
  for (const auto& [list, item] : items) sets.push_back(dotted(list) + "=" + json::array({item}).dump());
  const std::string source = "command line";
  try {
    return pipeline::scenario_from_text("{}", source, sets);
  } catch (const Error& error) {
    std::string message = error.what();
    if (message.starts_with(source + ": ")) message = message.substr(source.size() + 2);
    throw Error(error.kind(), with_flags(message));
  }
}

std::string SchemaOptions::with_flags(std::string message) const {
  std::vector<std::pair<std::string, std::string>> longest_first = aliases_;
  for (const Entry& e : entries_) longest_first.emplace_back(e.pointer, e.flag.substr(0, e.flag.find(',')));
  std::sort(longest_first.begin(), longest_first.end(), [](const auto& a, const auto& b) { return a.first.size() > b.first.size(); });
  for (const auto& [pointer, flag] : longest_first)
    for (const std::string& name : {pointer, dotted(pointer)}) {
      if (name.find_first_of("/.") == std::string::npos) continue;  // "seed": a word, not a name
      for (std::size_t at = message.find(name); at != std::string::npos; at = message.find(name, at + flag.size()))
        message.replace(at, name.size(), flag);
    }
  // A list item's module names its fields from the item ("/level_m, /depth_m: give one"): the
  // command's flags fill one item, so those names are its flags too.
  for (const Entry& e : entries_)
    if (const auto item = e.pointer.find("/0/"); item != std::string::npos) {
      const std::regex name(R"((^|[\s(,])/)" + e.pointer.substr(item + 3) + R"((?![\w/]))");
      message = std::regex_replace(message, name, "$1" + e.flag.substr(0, e.flag.find(',')));
    }
  return message;
}

}  // namespace terrapolis::cli
