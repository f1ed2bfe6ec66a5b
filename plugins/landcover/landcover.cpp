// The `landcover` plugin: a land-cover raster (any GDAL raster) whose class codes map, through a
// table, to a density attractiveness (or exclusion) and to a road cost per metre (or a ban).
// SPDX-License-Identifier: MIT
#include <cmath>
#include <map>

#include "plugin_support.hpp"

namespace {

using namespace terrapolis_plugins;

const char* const kSchema = R"json({
  "$schema": "http://json-schema.org/draft-07/schema#",
  "title": "landcover plugin parameters",
  "type": "object",
  "additionalProperties": false,
  "required": ["raster", "classes"],
  "definitions": {
    "density": {"description": "attractiveness in [0,1], or \"excluded\" (uninhabitable)",
                "oneOf": [{"type": "number", "minimum": 0, "maximum": 1}, {"enum": ["excluded"]}]},
    "road_cost": {"description": "extra cost per metre of road (1 = one more metre of flat road), or \"forbidden\"",
                  "oneOf": [{"type": "number", "minimum": 0}, {"enum": ["forbidden"]}]}
  },
  "properties": {
    "raster": {"type": "string", "format": "path", "description": "land-cover raster (any GDAL raster with a CRS), resampled nearest onto the DEM grid"},
    "band": {"type": "integer", "minimum": 1, "default": 1},
    "classes": {
      "type": "array", "minItems": 1,
      "items": {
        "type": "object",
        "additionalProperties": false,
        "required": ["codes"],
        "properties": {
          "codes": {"type": "array", "minItems": 1, "items": {"type": "integer"}},
          "name": {"type": "string"},
          "density": {"$ref": "#/definitions/density"},
          "road_cost": {"$ref": "#/definitions/road_cost"}
        }
      }
    },
    "default": {"type": "object", "additionalProperties": false,
                "description": "effect of codes not in the table and of no-data cells (default: no density opinion, road cost 0)",
                "properties": {"density": {"$ref": "#/definitions/density"}, "road_cost": {"$ref": "#/definitions/road_cost"}}},
    "structures": {"type": "array", "items": {"enum": ["road", "bridge", "tunnel"]}, "uniqueItems": true,
                   "default": ["road"], "description": "structures that pay the road cost (by default bridges pass over land cover, tunnels under it)"}
  }
})json";

/// What one class does: attractiveness (NaN = no opinion), exclusion, cost per metre (infinity = forbidden).
struct Effect {
  double density = NAN;
  bool excluded = false;
  double road_cost = 0.0;
};

Effect effect_of(const json& j, Effect e) {
  if (j.contains("density")) {
    e.excluded = j["density"].is_string();
    e.density = e.excluded ? NAN : j["density"].get<double>();
  }
  if (j.contains("road_cost")) e.road_cost = j["road_cost"].is_string() ? INFINITY : j["road_cost"].get<double>();
  return e;
}

struct Table {
  std::map<long long, Effect> classes;
  Effect fallback;
  explicit Table(const json& p) {
    if (p.contains("default")) fallback = effect_of(p["default"], fallback);
    for (const auto& c : p["classes"]) {
      const Effect e = effect_of(c, fallback);
      for (const auto& code : c["codes"]) classes[code.get<long long>()] = e;
    }
  }
  const Effect& operator()(double code) const {
    if (std::isnan(code) || code != std::floor(code)) return fallback;
    const auto it = classes.find((long long)code);
    return it == classes.end() ? fallback : it->second;
  }
};

std::vector<double> codes_on_grid(const TerrapolisGrid& g, const json& p) {
  std::vector<double> codes = read_on_grid(g, p["raster"].get<std::string>(), p.value("band", 1));
  report(g, 0.9);
  return codes;
}

int density(const TerrapolisGrid* g, const char* params, float* factor, uint8_t* excluded, char* error, size_t size) {
  return guarded(error, size, [&] {
    const json p = json::parse(params);
    const Table table(p);
    const std::vector<double> codes = codes_on_grid(*g, p);
    for (std::size_t i = 0; i < codes.size(); ++i) {
      const Effect& e = table(codes[i]);
      factor[i] = float(e.density);
      if (e.excluded) excluded[i] = 1;
    }
  });
}

int road(const TerrapolisGrid* g, const char* params, float* kappa, char* transfer, size_t transfer_size, char* error, size_t size) {
  return guarded(error, size, [&] {
    const json p = json::parse(params);
    const Table table(p);
    const std::vector<double> codes = codes_on_grid(*g, p);
    // kappa is the table's cost per metre itself (+infinity where forbidden): class codes are
    // categories, not a scale a curve could interpolate.
    for (std::size_t i = 0; i < codes.size(); ++i) kappa[i] = float(table(codes[i]).road_cost);
    write_transfer(transfer, transfer_size, identity_transfer(), p.value("structures", json::array({"road"})));
  });
}

const TerrapolisPlugin plugin = {
    TERRAPOLIS_PLUGIN_ABI_VERSION,
    "landcover",
    "Land-cover raster: a table maps class codes to density attractiveness (or exclusion) and road cost per metre (or a ban)",
    kSchema,
    density,
    road,
};

}  // namespace

extern "C" TERRAPOLIS_PLUGIN_EXPORT const TerrapolisPlugin* terrapolis_plugin_entry(void) { return &plugin; }
