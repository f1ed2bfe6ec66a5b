// `terrapolis --describe-json`: every command and option as JSON, read from CLI11's own objects.
// SPDX-License-Identifier: MIT
#include "cli/describe.hpp"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <cctype>
#include <regex>

namespace terrapolis::cli {
namespace {

using nlohmann::ordered_json;

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return s;
}

bool contains(const std::string& text, const std::string& word) { return lower(text).find(lower(word)) != std::string::npos; }

/// What a file-valued option holds, for GUIs (QGIS parameter types), from its name and help text:
/// raster_in, vector_in, file_in, raster_out, vector_out, file_out, folder_out, folder_in, or none.
std::string kind_of(const CLI::Option& o, const std::string& type) {
  if (type != "string") return "";
  const std::string name = o.get_name(), help = o.get_description();
  if (name == "--plugin" || name == "--set" || name == "--from" || name == "--to") return "";
  if (name == "DEM" || name == "--dem") return "raster_in";
  const bool out = name == "OUT" || name == "OUTDIR" || name == "--output" || name == "-o" || name == "--sections" ||
                   contains(help, "write") || contains(help, "output");
  if (contains(help, "folder") || name == "OUTDIR" || name == "RUN" || name == "RUN1" || name == "RUN2") {
    if (name == "OUTDIR" || contains(help, "folder for") || name == "--output" || name == "-o") return "folder_out";
    if (contains(help, "run folder") || name.rfind("RUN", 0) == 0) return "folder_in";
  }
  if (out) {
    if (contains(help, ".geojson") || contains(help, "road") || contains(help, "vector")) return "vector_out";
    if (contains(help, ".tif") || contains(help, "raster")) return "raster_out";
    if (name == "OUT" || name == "--sections") return "file_out";
  }
  if (contains(help, "json file") || contains(help, "scenario")) return "file_in";
  if (contains(help, "raster") || contains(help, "hydrometry") || contains(help, "density")) return "raster_in";
  if (contains(help, "network") || contains(help, "cities") || contains(help, "line") || contains(help, "vector") ||
      contains(help, ".geojson"))
    return "vector_in";
  return "file_in";
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
  const bool flag = o.get_type_size_max() == 0;
  std::string type = flag ? "boolean" : base == "INT" || base == "UINT" ? "integer" : base == "FLOAT" ? "number" : "string";
  j["type"] = type;
  j["cli_type"] = full;
  const std::string def = o.get_default_str();
  if (def.empty()) {
    j["default"] = flag ? ordered_json(false) : ordered_json(nullptr);
  } else if (flag) {
    j["default"] = def == "true" || def == "1";
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
  // Validators print as "{a,b}" (IsMember), "INT in [1 - 16]" (Range), "NONNEGATIVE", "POSITIVE".
  static const std::regex set_re(R"(\{([^}]*)\})"), range_re(R"(\[\s*([-+0-9.eE]+)\s*-\s*([-+0-9.eE]+)\s*\])");
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
  const std::string kind = kind_of(o, type);
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
