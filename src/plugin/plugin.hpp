// Loading plugins (terrapolis_plugin.h) and running their density factors and road cost terms.
// SPDX-License-Identifier: MIT
#pragma once
#include <nlohmann/json.hpp>

#include <array>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/progress.hpp"
#include "core/raster.hpp"
#include "density/density.hpp"
#include "roads/terrain_field.hpp"

struct TerrapolisPlugin;

namespace terrapolis::plugin {

/// One plugin as a scenario or the command line names it: {"id": "landcover", "weight": 2,
/// "params": {...}}. The weight applies to the density factor (as a user layer's weight); road
/// cost terms are priced by their own transfer functions.
struct PluginSpec {
  std::string id;
  double weight = 1;
  nlohmann::json params = nlohmann::json::object();
  /// Folder that relative paths in the parameters are relative to (the parameter file's or the
  /// scenario's; empty = the current folder). Paths are the top-level string parameters whose
  /// schema says "format": "path"; load_plugins makes them absolute before validation.
  std::string base_dir;
};

/// Parses a JSON list of specs [{"id": ..., "weight": ..., "params": {...}}, ...]; `origin`
/// names the list in errors, `base_dir` goes to every spec. Throws bad_input.
std::vector<PluginSpec> parse_plugin_list(const nlohmann::json& list, const std::string& origin, const std::string& base_dir = "");
/// Parses the command-line form ID[:WEIGHT][:PARAMS] where PARAMS is a JSON file (relative paths
/// inside are relative to its folder) or an inline JSON object ("{...}", relative to the current
/// folder). Throws bad_input naming --plugin.
PluginSpec parse_plugin_option(const std::string& text);

/// A shared library opened with dlopen and checked (ABI version, entry point, schema).
class Library;

/// A loaded, validated plugin with its parameters.
struct LoadedPlugin {
  PluginSpec spec;
  std::string file;                   ///< the library's path
  std::shared_ptr<const Library> module;  ///< keeps the shared library loaded
  const TerrapolisPlugin* api = nullptr;
  std::string description() const;
  bool has_density_factor() const;
  bool has_road_cost() const;
};
using PluginSet = std::vector<LoadedPlugin>;

/// Folders searched for `terrapolis_<id>.so`, in order: TERRAPOLIS_PLUGIN_PATH (':'-separated),
/// then `<exe dir>/../lib/terrapolis/plugins` (install), `<exe dir>/../plugins`, and the build
/// tree's plugin folder.
std::vector<std::filesystem::path> search_path();
/// The library of plugin `id`; throws bad_input listing the folders searched when none holds it.
std::filesystem::path find_plugin(const std::string& id);
/// Opens and checks one library (ABI version, entry symbol, id, schema). Throws bad_input naming the file.
LoadedPlugin open_plugin(const std::filesystem::path& file);
/// Throws bad_input naming the plugin when `params` does not satisfy its schema.
void validate_params(const LoadedPlugin& plugin, const nlohmann::json& params);

/// Finds, opens, checks every plugin of the list and validates its parameters.
PluginSet load_plugins(const std::vector<PluginSpec>& specs, const Log& log);
/// Same from the JSON list form (a scenario's "plugins" array; relative paths in the parameters
/// are relative to `base_dir`, e.g. the scenario's folder).
PluginSet load_plugins(const nlohmann::json& list, const Log& log, const std::string& base_dir = "");

/// A plugin's density factor on the DEM's grid.
struct DensityFactor {
  std::string id;
  Raster<float> factor;                        ///< [0,1], NaN = no opinion at that cell
  double weight = 1;
  std::optional<Raster<std::uint8_t>> excluded; ///< 1 = uninhabitable; absent when the plugin excluded nothing
};
/// Runs the density factor of every plugin that has one (others are skipped with a detail line).
std::vector<DensityFactor> density_factors(const PluginSet& set, const Dem& dem, Progress& progress, const Log& log);
/// Adds factors to density options: each as a weighted factor, its mask as an exclusion mask.
void add_to_density(std::vector<DensityFactor> factors, density::DensityOptions& options);

/// A plugin's road cost term on the DEM's grid.
struct RoadTerm {
  std::string id;
  Raster<float> characteristic;
  std::array<roads::TransferFunction, 3> transfer;  ///< road, bridge, tunnel
  std::array<bool, 3> priced{};                      ///< whether the plugin gave each structure's function
};
/// Runs the road cost term of every plugin that has one.
std::vector<RoadTerm> road_terms(const PluginSet& set, const Dem& dem, Progress& progress, const Log& log);
/// Adds the terms to the terrain the road search prices (TerrainField::add_cost_layer).
void add_to_terrain(const std::vector<RoadTerm>& terms, roads::TerrainField& terrain);

}  // namespace terrapolis::plugin
