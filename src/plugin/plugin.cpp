// Plugin discovery (TERRAPOLIS_PLUGIN_PATH, install and build folders), checks, and calls.
// SPDX-License-Identifier: MIT
#include "plugin/plugin.hpp"

#define VALIJSON_USE_EXCEPTIONS 1  // report invalid schemas as exceptions, not aborts
#include <dlfcn.h>
#include <valijson/adapters/nlohmann_json_adapter.hpp>
#include <valijson/schema.hpp>
#include <valijson/schema_parser.hpp>
#include <valijson/validator.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <fstream>
#include <sstream>

#include "core/error.hpp"
#include "core/json_input.hpp"
#include "core/schema_error.hpp"
#include "core/text.hpp"
#include "core/geodesy.hpp"
#include "plugin/terrapolis_plugin.h"

namespace terrapolis::plugin {

namespace fs = std::filesystem;
using nlohmann::json;

class Library {
 public:
  Library(const fs::path& file, void* handle) : file_(file), handle_(handle) {}
  ~Library() {
    if (handle_) dlclose(handle_);
  }
  Library(const Library&) = delete;
  Library& operator=(const Library&) = delete;
  void* symbol(const char* name) const { return dlsym(handle_, name); }
  json schema;

 private:
  fs::path file_;
  void* handle_ = nullptr;
};

namespace {

/// Plugin ids: lower-case letters, digits, underscores (they name files).
bool valid_id(const std::string& id) {
  return !id.empty() && std::all_of(id.begin(), id.end(), [](char c) { return (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_'; });
}


/// Parses `schema` with valijson; throws (std::exception) when it is not a valid schema.
void parse_schema(const json& schema, valijson::Schema& out) {
  valijson::SchemaParser parser;
  valijson::adapters::NlohmannJsonAdapter adapter(schema);
  parser.populateSchema(adapter, out);
}


bool is_number(const std::string& text) {
  try {
    std::size_t used = 0;
    (void)std::stod(text, &used);
    return used == text.size() && !text.empty();
  } catch (const std::exception&) {
    return false;
  }
}

/// The grid handed to plugins; owns the arrays it points to.
struct GridView {
  TerrapolisGrid grid{};
  std::vector<double> width, height;
  std::string wkt;
  explicit GridView(const Dem& dem) : wkt(dem.georef().crs.wkt) {
    const CellMetrics m = cell_metrics(dem.georef(), dem.cols(), dem.rows());
    width = m.width_m;
    height.resize(std::size_t(dem.rows()));
    // height_m[r] spans rows r-1..r; the plugin's entry r spans r..r+1 (the last row: r-1..r).
    for (int r = 0; r < dem.rows(); ++r) height[std::size_t(r)] = m.height_m[std::size_t(r + 1 < dem.rows() ? r + 1 : r)];
    grid.cols = dem.cols();
    grid.rows = dem.rows();
    for (int k = 0; k < 6; ++k) grid.geotransform[k] = dem.georef().transform[std::size_t(k)];
    grid.crs_wkt = wkt.c_str();
    grid.geographic = dem.georef().crs.geographic ? 1 : 0;
    grid.elevation = dem.values().data();
    grid.cell_width_m = width.data();
    grid.cell_height_m = height.data();
  }
};

std::string where(const LoadedPlugin& p) { return "plugin " + p.spec.id + " (" + p.file + ")"; }

/// Forwards a plugin's progress to a Progress sink; remembers a cancel (exceptions must not cross the C ABI).
struct ProgressBridge {
  Progress& progress;
  bool cancelled = false;
  static int report(void* context, double fraction) {
    auto* self = static_cast<ProgressBridge*>(context);
    if (!self->progress.update(fraction)) self->cancelled = true;
    return self->cancelled ? 0 : 1;
  }
  /// Runs one plugin call with the bridge installed in `grid`; throws on cancel or failure.
  template <class F>
  void call(TerrapolisGrid& grid, const LoadedPlugin& p, const char* what, const Log& log, F&& fn) {
    const auto t0 = std::chrono::steady_clock::now();
    grid.progress = &ProgressBridge::report;
    grid.progress_context = this;
    std::vector<char> error(1024, '\0');
    const int status = fn(error.data(), error.size());
    grid.progress = nullptr;
    grid.progress_context = nullptr;
    if (cancelled) throw Error(ErrorKind::cancelled, "cancelled");
    error.back() = '\0';  // messages stay one terminated line whatever the plugin wrote
    std::replace_if(error.begin(), error.end(), [](char c) { return c == '\n' || c == '\r'; }, ' ');
    if (status != 0) throw bad_input(where(p) + ": " + (error[0] ? std::string(error.data()) : std::string(what) + " failed"));
    char line[128];
    std::snprintf(line, sizeof line, ": %s in %.3f s", what, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    log.detail("plugin " + p.spec.id + line);
  }
};

}  // namespace

std::string LoadedPlugin::description() const { return api && api->description ? api->description : ""; }
bool LoadedPlugin::has_density_factor() const { return api && api->density_factor; }
bool LoadedPlugin::has_road_cost() const { return api && api->road_cost; }

std::vector<PluginSpec> parse_plugin_list(const json& list, const std::string& origin, const std::string& base_dir) {
  if (!list.is_array()) throw bad_input(origin + ": expected an array of {\"id\", \"weight\", \"params\"} objects");
  std::vector<PluginSpec> specs;
  for (std::size_t k = 0; k < list.size(); ++k) {
    const json& e = list[k];
    const std::string at = origin + "/" + std::to_string(k);
    if (!e.is_object()) throw bad_input(at + ": expected an object {\"id\", \"weight\", \"params\"}");
    PluginSpec s;
    s.base_dir = base_dir;
    for (auto it = e.begin(); it != e.end(); ++it) {
      if (it.key() == "id") {
        if (!it->is_string()) throw bad_input(at + "/id: expected a string");
        s.id = it->get<std::string>();
      } else if (it.key() == "weight") {
        if (!it->is_number() || !std::isfinite(it->get<double>())) throw bad_input(at + "/weight: expected a number");
        s.weight = it->get<double>();
      } else if (it.key() == "params") {
        if (!it->is_object()) throw bad_input(at + "/params: expected an object");
        s.params = *it;
      } else {
        throw bad_input(at + "/" + it.key() + ": unknown key (expected id, weight, params)");
      }
    }
    if (!valid_id(s.id)) throw bad_input(at + "/id: '" + s.id + "' is not a plugin id ([a-z0-9_]+)");
    specs.push_back(std::move(s));
  }
  return specs;
}

PluginSpec parse_plugin_option(const std::string& text) {
  const std::string option = "--plugin " + text;
  PluginSpec s;
  const auto colon = text.find(':');
  s.id = text.substr(0, colon);
  if (!valid_id(s.id)) throw bad_input(option + ": expected ID[:WEIGHT][:PARAMS] with ID made of [a-z0-9_]");
  if (colon == std::string::npos) return s;
  std::string rest = text.substr(colon + 1);
  const auto next = rest.find(':');
  const std::string first = rest.substr(0, next);
  if (is_number(first)) {
    const auto weight = parse_number(first);
    if (!weight) throw bad_input(option + ": weight '" + first + "' is not a number");
    s.weight = *weight;
    rest = next == std::string::npos ? "" : rest.substr(next + 1);
  }
  if (rest.empty()) return s;
  std::string body;
  std::string origin = option;
  if (rest.front() == '{') {
    body = rest;
  } else {
    std::error_code ec;
    if (!fs::is_regular_file(rest, ec)) throw bad_input(option + ": " + rest + ": no such parameter file");
    body = read_json_file(rest);
    origin = rest;
    s.base_dir = fs::path(rest).parent_path().string();
  }
  check_json_text(body, origin);
  try {
    s.params = json::parse(body);
  } catch (const json::exception& e) {
    throw bad_input(origin + ": parameters are not valid JSON (" + json_error_text(e.what()) + ")");
  }
  if (!s.params.is_object()) throw bad_input(origin + ": parameters must be a JSON object");
  return s;
}

std::vector<fs::path> search_path() {
  std::vector<fs::path> dirs;
  if (const char* env = std::getenv("TERRAPOLIS_PLUGIN_PATH")) {
    std::stringstream ss(env);
    std::string part;
    while (std::getline(ss, part, ':'))
      if (!part.empty()) dirs.emplace_back(part);
  }
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    dirs.push_back(exe.parent_path() / ".." / "lib" / "terrapolis" / "plugins");
    dirs.push_back(exe.parent_path() / ".." / "plugins");
  }
#ifdef TERRAPOLIS_BUILD_PLUGIN_DIR
  dirs.emplace_back(TERRAPOLIS_BUILD_PLUGIN_DIR);
#endif
  return dirs;
}

fs::path find_plugin(const std::string& id) {
  std::string searched;
  for (const fs::path& dir : search_path()) {
    const fs::path file = dir / ("terrapolis_" + id + ".so");
    std::error_code ec;
    if (fs::is_regular_file(file, ec)) return file.lexically_normal();
    searched += (searched.empty() ? "" : ", ") + dir.lexically_normal().string();
  }
  throw bad_input("plugin " + id + ": no terrapolis_" + id + ".so in TERRAPOLIS_PLUGIN_PATH or " + searched);
}

LoadedPlugin open_plugin(const fs::path& file) {
  const std::string name = file.string();
  dlerror();
  void* handle = dlopen(name.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (!handle) {
    const char* why = dlerror();
    throw bad_input(name + ": cannot load the plugin (" + std::string(why ? why : "unknown reason") + ")");
  }
  auto library = std::make_shared<Library>(file, handle);
  void* entry = library->symbol(TERRAPOLIS_PLUGIN_ENTRY_SYMBOL);
  if (!entry) throw bad_input(name + ": not a Terrapolis plugin (no " TERRAPOLIS_PLUGIN_ENTRY_SYMBOL " symbol)");
  const TerrapolisPlugin* api = reinterpret_cast<TerrapolisPluginEntryFn>(entry)();
  if (!api) throw bad_input(name + ": " TERRAPOLIS_PLUGIN_ENTRY_SYMBOL " returned nothing");
  if (api->abi_version != TERRAPOLIS_PLUGIN_ABI_VERSION)
    throw bad_input(name + ": plugin ABI version " + std::to_string(api->abi_version) + ", this Terrapolis needs version " +
                    std::to_string(TERRAPOLIS_PLUGIN_ABI_VERSION) + " (rebuild the plugin)");
  const std::string id = api->id ? api->id : "";
  if (!valid_id(id)) throw bad_input(name + ": plugin id '" + id + "' is not made of [a-z0-9_]");
  if (!api->density_factor && !api->road_cost) throw bad_input(name + ": plugin " + id + " provides neither a density factor nor a road cost");
  try {
    library->schema = json::parse(api->parameter_schema ? api->parameter_schema : "");
  } catch (const json::exception& e) {
    throw bad_input(name + ": invalid parameter schema, not JSON (" + std::string(e.what()) + ")");
  }
  if (!library->schema.is_object()) throw bad_input(name + ": invalid parameter schema, not a JSON object");
  try {
    valijson::Schema parsed;
    parse_schema(library->schema, parsed);
  } catch (const std::exception& e) {
    throw bad_input(name + ": invalid parameter schema (" + std::string(e.what()) + ")");
  }
  LoadedPlugin p;
  p.spec.id = id;
  p.file = name;
  p.module = library;
  p.api = api;
  return p;
}

void validate_params(const LoadedPlugin& plugin, const json& params) {
  valijson::Schema schema;
  parse_schema(plugin.module->schema, schema);
  valijson::Validator validator;
  valijson::ValidationResults results;
  valijson::adapters::NlohmannJsonAdapter target(params);
  if (validator.validate(schema, target, &results)) return;
  const auto [pointer, problem] = schema_error(results, &plugin.module->schema);
  throw bad_input(where(plugin) + ": params" + (pointer == "/" ? "" : pointer) + ": " + problem);
}

PluginSet load_plugins(const std::vector<PluginSpec>& specs, const Log& log) {
  PluginSet set;
  for (const PluginSpec& spec : specs) {
    LoadedPlugin p = open_plugin(find_plugin(spec.id));
    if (p.spec.id != spec.id) throw bad_input(p.file + ": declares id '" + p.spec.id + "', expected '" + spec.id + "'");
    p.spec = spec;
    // Relative paths (top-level string parameters declared "format": "path") from base_dir.
    const json& properties = p.module->schema.contains("properties") ? p.module->schema["properties"] : json::object();
    if (!spec.base_dir.empty() && properties.is_object())
      for (auto it = p.spec.params.begin(); it != p.spec.params.end(); ++it) {
        const auto prop = properties.find(it.key());
        if (prop == properties.end() || !prop->is_object() || prop->value("format", "") != "path" || !it->is_string()) continue;
        const fs::path path(it->get<std::string>());
        if (path.is_relative()) *it = (fs::path(spec.base_dir) / path).lexically_normal().string();
      }
    validate_params(p, p.spec.params);
    log.detail("plugin " + spec.id + ": " + p.file + " (" + p.description() + ")");
    set.push_back(std::move(p));
  }
  return set;
}

PluginSet load_plugins(const json& list, const Log& log, const std::string& base_dir) {
  return load_plugins(parse_plugin_list(list, "plugins", base_dir), log);
}

std::vector<DensityFactor> density_factors(const PluginSet& set, const Dem& dem, Progress& progress, const Log& log) {
  std::vector<DensityFactor> out;
  GridView view(dem);
  for (const LoadedPlugin& p : set) {
    if (!p.has_density_factor()) {
      log.detail("plugin " + p.spec.id + ": no density factor");
      continue;
    }
    ProgressStep step(progress, "plugin " + p.spec.id + ": density factor");
    DensityFactor f;
    f.id = p.spec.id;
    f.weight = p.spec.weight;
    f.factor = dem.like<float>(std::numeric_limits<float>::quiet_NaN());
    Raster<std::uint8_t> excluded = dem.like<std::uint8_t>(0);
    const std::string params = p.spec.params.dump();
    ProgressBridge bridge{progress};
    bridge.call(view.grid, p, "density factor", log, [&](char* error, std::size_t size) {
      return p.api->density_factor(&view.grid, params.c_str(), f.factor.values().data(), excluded.values().data(), error, size);
    });
    for (float& v : f.factor.values())
      if (!std::isnan(v)) v = std::clamp(v, 0.0f, 1.0f);
    bool any = false;
    for (std::uint8_t& e : excluded.values()) {
      e = e != 0;
      any = any || e;
    }
    if (any) f.excluded = std::move(excluded);
    step.update(1.0);
    out.push_back(std::move(f));
  }
  return out;
}

void add_to_density(std::vector<DensityFactor> factors, density::DensityOptions& options) {
  for (DensityFactor& f : factors) {
    options.factors.push_back({"plugin " + f.id, std::move(f.factor), f.weight});
    if (f.excluded) options.exclusion_masks.push_back(std::move(*f.excluded));
  }
}

std::vector<RoadTerm> road_terms(const PluginSet& set, const Dem& dem, Progress& progress, const Log& log) {
  std::vector<RoadTerm> out;
  GridView view(dem);
  for (const LoadedPlugin& p : set) {
    if (!p.has_road_cost()) {
      log.detail("plugin " + p.spec.id + ": no road cost term");
      continue;
    }
    ProgressStep step(progress, "plugin " + p.spec.id + ": road cost");
    RoadTerm t;
    t.id = p.spec.id;
    t.characteristic = dem.like<float>(std::numeric_limits<float>::quiet_NaN());
    std::vector<char> transfer(1 << 16, '\0');
    const std::string params = p.spec.params.dump();
    ProgressBridge bridge{progress};
    bridge.call(view.grid, p, "road cost", log, [&](char* error, std::size_t size) {
      return p.api->road_cost(&view.grid, params.c_str(), t.characteristic.values().data(), transfer.data(), transfer.size(), error, size);
    });
    transfer.back() = '\0';
    const std::string origin = where(p) + ": transfer functions";
    const std::string text(transfer.data());
    check_json_text(text, origin);
    json j;
    try {
      j = json::parse(text);
    } catch (const json::exception& e) {
      throw bad_input(origin + ": not valid JSON (" + json_error_text(e.what()) + ")");
    }
    if (!j.is_object()) throw bad_input(origin + ": expected an object with road, bridge, tunnel keys");
    for (auto it = j.begin(); it != j.end(); ++it) {
      int s = it.key() == "road" ? 0 : it.key() == "bridge" ? 1 : it.key() == "tunnel" ? 2 : -1;
      if (s < 0) throw bad_input(origin + ": unknown key '" + it.key() + "' (expected road, bridge, tunnel)");
      t.transfer[std::size_t(s)] = roads::parse_transfer_function(it->dump(), origin + "/" + it.key());
      t.priced[std::size_t(s)] = true;
    }
    step.update(1.0);
    out.push_back(std::move(t));
  }
  return out;
}

void add_to_terrain(const std::vector<RoadTerm>& terms, roads::TerrainField& terrain) {
  for (const RoadTerm& t : terms) terrain.add_cost_layer("plugin " + t.id, t.characteristic, t.transfer, t.priced);
}

}  // namespace terrapolis::plugin
