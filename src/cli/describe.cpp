// `terrapolis --describe-json`: every command and option as JSON, read from CLI11's own objects.
// SPDX-License-Identifier: MIT
#include "cli/describe.hpp"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <cctype>
#include <regex>
#include <sstream>

namespace terrapolis::cli {
namespace {

using nlohmann::ordered_json;

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return s;
}

bool contains(const std::string& text, const std::string& word) { return lower(text).find(lower(word)) != std::string::npos; }

/// What a path-valued option holds, for GUIs (QGIS parameter types): raster_in, vector_in,
/// file_in, folder_in, raster_out, vector_out, file_out, folder_out; "" for other text (CRS
/// codes, coordinates, lists). Read from the option's name and help text, the only place the
/// command line states it; docs/plugins.md lists the wording rules.
std::string kind_of(const CLI::Option& o) {
  const std::string name = o.nonpositional() ? o.get_name() : o.get_name(true), help = o.get_description();
  // FILE:WEIGHT pairs, plugin specs and CRS codes are text.
  if (contains(help, "FILE:") || name == "--plugin" || help.rfind("CRS", 0) == 0) return "";
  if (name == "DEM" || help.rfind("DEM ", 0) == 0) return "raster_in";
  if (name == "OUTDIR" || name == "--output") return "folder_out";
  if (name == "OUT" || help.rfind("Also write", 0) == 0) {
    if (contains(help, ".geojson") || contains(help, "polygon") || contains(help, "road") || contains(help, "sections")) return "vector_out";
    if (contains(help, "GeoTIFF")) return "raster_out";
    return "file_out";
  }
  if (contains(help, "folder")) return "folder_in";
  if (contains(help, ".csv")) return "file_in";  // several formats: let the user pick any file
  if (contains(help, "raster")) return "raster_in";
  if (contains(help, ".geojson") || contains(help, "(Points") || contains(help, "line of this file") || contains(help, "City points"))
    return "vector_in";
  if (contains(help, "file")) return "file_in";
  return "";
}

ordered_json describe_option(CLI::Option& o) {
  ordered_json j;
  const bool positional = !o.nonpositional();
  j["name"] = positional ? o.get_name(true) : o.get_name();
  std::vector<std::string> names;
  for (const auto& n : o.get_lnames()) names.push_back("--" + n);
  for (const auto& n : o.get_snames()) names.push_back("-" + n);
  for (const auto& n : o.get_fnames())
    if (std::find(names.begin(), names.end(), n) == names.end() && n.rfind("--", 0) == 0) names.push_back(n);
  if (!positional) j["names"] = names;
  j["positional"] = positional;
  j["help"] = o.get_description();
  // The option's current value is its default: capture it from the bound variable.
  o.capture_default_str();
  const std::string full = o.get_type_name();
  const std::string base = full.substr(0, full.find(':'));
  const bool flag = full.empty();  // flags have no type name
  std::string type = flag ? "boolean" : base == "INT" || base == "UINT" ? "integer" : base == "FLOAT" ? "number" : "string";
  j["type"] = type;
  j["cli_type"] = full;
  const std::string def = o.get_default_str();
  if (flag) {
    // A flag with a negated alias (--bridges,!--no-bridges) is on unless negated.
    bool on = false;
    for (const auto& n : o.get_lnames()) on = on || (n.rfind("no-", 0) == 0 && j["name"] != "--" + n);
    j["default"] = on;
  } else if (def.empty()) {
    j["default"] = nullptr;
  } else if (type == "integer" || type == "number") {
    try {
      j["default"] = type == "integer" ? ordered_json(std::stoll(def)) : ordered_json(std::stod(def));
    } catch (const std::exception&) {
      j["default"] = def;
    }
  } else {
    j["default"] = def;
  }
  j["required"] = o.get_required();
  j["repeatable"] = !flag && (o.get_expected_max() > 1 || o.get_items_expected_max() > 1);
  if (j["repeatable"] && j["default"].is_string()) {  // CLI11 prints vectors as "[a,b]"
    std::string list = j["default"].get<std::string>();
    if (list.size() >= 2 && list.front() == '[' && list.back() == ']') list = list.substr(1, list.size() - 2);
    ordered_json items = ordered_json::array();
    std::stringstream ss(list);
    std::string item;
    while (std::getline(ss, item, ',')) items.push_back(item);
    j["default"] = items;
  }
  // Validators print as "{a,b}" (IsMember), "INT in [1 - 16]" (Range), "NONNEGATIVE", "POSITIVE".
  const std::regex set_re(R"(\{([^}]*)\})"), range_re(R"(\[\s*([-+0-9.eE]+)\s*-\s*([-+0-9.eE]+)\s*\])");
  std::smatch m;
  std::string validators = full.find(':') == std::string::npos ? "" : full.substr(full.find(':') + 1);
  if (std::regex_search(validators, m, set_re)) {
    ordered_json choices = ordered_json::array();
    std::stringstream ss(m[1].str());
    std::string item;
    while (std::getline(ss, item, ',')) choices.push_back(item);
    j["choices"] = choices;
  }
  if (std::regex_search(validators, m, range_re)) {
    j["minimum"] = std::stod(m[1].str());
    j["maximum"] = std::stod(m[2].str());
  } else if (contains(validators, "NONNEGATIVE")) {
    j["minimum"] = 0.0;
  } else if (contains(validators, "POSITIVE")) {
    j["exclusive_minimum"] = 0.0;
  }
  const std::string kind = type == "string" && !j.contains("choices") ? kind_of(o) : "";
  j["kind"] = kind.empty() ? ordered_json(nullptr) : ordered_json(kind);
  return j;
}

ordered_json describe_options(CLI::App& app) {
  ordered_json list = ordered_json::array();
  for (CLI::Option* o : app.get_options([](const CLI::Option* o) { return o->get_name() != "--help" && o->get_name() != "-h"; })) {
    if (o->get_name() == "--help" || o->get_name() == "--version" || o->get_name() == "--describe-json") continue;
    list.push_back(describe_option(*o));
  }
  return list;
}

}  // namespace

nlohmann::ordered_json describe_cli(CLI::App& app, const std::string& version) {
  ordered_json j;
  j["program"] = app.get_name();
  j["version"] = version;
  j["description"] = app.get_description();
  j["global_options"] = describe_options(app);
  ordered_json commands = ordered_json::array();
  for (CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; }))
    commands.push_back({{"name", sub->get_name()}, {"summary", sub->get_description()}, {"options", describe_options(*sub)}});
  j["commands"] = commands;
  return j;
}

}  // namespace terrapolis::cli
