// `terrapolis --describe-json`: every command and option as JSON, from the schema and CLI11's own objects.
// SPDX-License-Identifier: MIT
#include "cli/describe.hpp"

#include "cli/schema_options.hpp"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <regex>
#include <sstream>

namespace terrapolis::cli {
namespace {

using nlohmann::ordered_json;

/// A schema-declared option, described by its schema field (cli/schema_options.hpp).
ordered_json describe_schema_option(CLI::Option& o, const OptionSource& source) {
  const ordered_json& f = source.field;
  ordered_json j;
  j["name"] = o.get_name();
  std::vector<std::string> names;
  for (const auto& n : o.get_lnames()) names.push_back("--" + n);
  j["names"] = names;
  j["positional"] = false;
  j["help"] = f.value("description", "");
  j["unit"] = f.value("x-unit", "");
  j["schema"] = source.pointer;
  j["type"] = f.value("type", "string");
  j["cli_type"] = o.get_type_name();
  j["default"] = f.value("default", ordered_json());
  j["required"] = false;
  j["repeatable"] = false;
  if (f.contains("enum")) j["choices"] = f["enum"];
  if (f.contains("minimum")) j["minimum"] = f["minimum"].get<double>();
  if (f.contains("exclusiveMinimum")) j["exclusive_minimum"] = f["exclusiveMinimum"].get<double>();
  if (f.contains("maximum")) j["maximum"] = f["maximum"].get<double>();
  j["kind"] = source.kind.empty() ? ordered_json(nullptr) : ordered_json(source.kind);
  return j;
}

ordered_json describe_option(CLI::Option& o) {
  const OptionSource* source = option_source(o);
  if (source && !source->pointer.empty()) return describe_schema_option(o, *source);
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
  } else if (validators.find("NONNEGATIVE") != std::string::npos) {
    j["minimum"] = 0.0;
  } else if (validators.find("POSITIVE") != std::string::npos) {
    j["exclusive_minimum"] = 0.0;
  }
  j["kind"] = source ? ordered_json(source->kind) : ordered_json(nullptr);
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
