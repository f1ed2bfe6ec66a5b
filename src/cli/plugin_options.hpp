// The --plugin option shared by density, path and roads (one declaration for all).
// SPDX-License-Identifier: MIT
#pragma once
#include <CLI/CLI.hpp>

#include <string>
#include <vector>

#include "plugin/plugin.hpp"

namespace terrapolis::cli {

struct PluginOptions {
  std::vector<std::string> specs;

  void setup(CLI::App& app, const std::string& what) {
    app.add_option("--plugin", specs,
                   "Plugin ID[:WEIGHT][:PARAMS] (repeatable): " + what +
                       "; PARAMS is a JSON file or an inline {...} object, WEIGHT (default 1) weighs density factors")
        ->type_name("PLUGIN");
  }
  /// Finds, checks and validates the named plugins (before any heavy work).
  plugin::PluginSet load(const Log& log) const {
    std::vector<plugin::PluginSpec> list;
    for (const std::string& s : specs) list.push_back(plugin::parse_plugin_option(s));
    return plugin::load_plugins(list, log);
  }
};

}  // namespace terrapolis::cli
