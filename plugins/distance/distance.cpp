// The `distance` plugin: attractiveness or road cost as a piecewise-linear function of the distance
// in metres to the features of an OGR vector layer (lines, points, polygons: inside = 0).
// SPDX-License-Identifier: MIT
#include <gdal_alg.h>
#include <ogr_api.h>
#include <ogr_srs_api.h>

#include <cmath>

#include "distance_transform.hpp"
#include "plugin_support.hpp"

namespace {

using namespace terrapolis_plugins;

const char* const kSchema = R"json({
  "$schema": "http://json-schema.org/draft-07/schema#",
  "title": "distance plugin parameters",
  "type": "object",
  "additionalProperties": false,
  "required": ["vector"],
  "definitions": {
    "curve": {"type": "array", "minItems": 1, "description": "[[distance_m, value], ...] with increasing distances, constant beyond its ends",
              "items": {"type": "array", "minItems": 2, "maxItems": 2, "items": {"type": "number"}}}
  },
  "properties": {
    "vector": {"type": "string", "format": "path", "description": "vector file (any OGR format with a CRS): roads, stations, protected-area polygons..."},
    "layer": {"type": "string", "description": "layer name (default: the first layer)"},
    "where": {"type": "string", "description": "OGR SQL attribute filter, e.g. \"class = 'motorway'\""},
    "density": {
      "type": "object", "additionalProperties": false,
      "properties": {
        "points": {"$ref": "#/definitions/curve", "description": "attractiveness in [0,1] against distance (m)"},
        "exclude_within_m": {"type": "number", "minimum": 0, "description": "cells this close (m) are uninhabitable; 0 = on or inside features"}
      }
    },
    "road": {
      "type": "object", "additionalProperties": false,
      "properties": {
        "points": {"$ref": "#/definitions/curve", "description": "extra cost per metre of road (>= 0) against distance (m)"},
        "forbidden_within_m": {"type": "number", "minimum": 0, "description": "cells this close (m) are forbidden; 0 = on or inside features"},
        "structures": {"type": "array", "items": {"enum": ["road", "bridge", "tunnel"]}, "uniqueItems": true,
                       "default": ["road", "bridge"], "description": "structures priced (by default tunnels pass under)"}
      }
    }
  }
})json";

/// Distance (m) from every cell centre to the features, via a mask of the cells they touch.
std::vector<double> distances(const TerrapolisGrid& g, const json& p) {
  GDALAllRegister();
  const QuietGdal quiet;
  const std::string path = p["vector"].get<std::string>();
  GDALDatasetH ds = GDALOpenEx(path.c_str(), GDAL_OF_VECTOR | GDAL_OF_READONLY, nullptr, nullptr, nullptr);
  if (!ds) throw std::runtime_error(path + ": cannot open the vector file");
  struct Closer {
    GDALDatasetH h;
    ~Closer() { GDALClose(h); }
  } close_ds{ds};
  OGRLayerH layer = p.contains("layer") ? GDALDatasetGetLayerByName(ds, p["layer"].get<std::string>().c_str())
                                        : (GDALDatasetGetLayerCount(ds) > 0 ? GDALDatasetGetLayer(ds, 0) : nullptr);
  if (!layer) throw std::runtime_error(path + ": no layer " + (p.contains("layer") ? p["layer"].get<std::string>() : std::string("at all")));
  if (!OGR_L_GetSpatialRef(layer)) throw std::runtime_error(path + ": the layer has no CRS");
  if (p.contains("where") && OGR_L_SetAttributeFilter(layer, p["where"].get<std::string>().c_str()) != OGRERR_NONE)
    throw std::runtime_error(path + ": invalid where filter '" + p["where"].get<std::string>() + "'");
  // Cells touched by a feature (ALL_TOUCHED: thin lines stay connected; polygons cover their inside).
  std::vector<unsigned char> mask(cells(g), 0);
  GDALDatasetH mem = GDALCreate(GDALGetDriverByName("MEM"), "", g.cols, g.rows, 0, GDT_Byte, nullptr);
  Closer close_mem{mem};
  char pointer[64] = {};
  CPLPrintPointer(pointer, mask.data(), sizeof(pointer) - 1);
  const std::string opt = std::string("DATAPOINTER=") + pointer;
  char* band_options[] = {const_cast<char*>(opt.c_str()), nullptr};
  GDALAddBand(mem, GDT_Byte, band_options);
  GDALSetGeoTransform(mem, const_cast<double*>(g.geotransform));
  GDALSetProjection(mem, g.crs_wkt);
  int band = 1;
  double burn = 1;
  char* options[] = {const_cast<char*>("ALL_TOUCHED=TRUE"), nullptr};
  if (GDALRasterizeLayers(mem, 1, &band, 1, &layer, nullptr, nullptr, &burn, options, nullptr, nullptr) != CE_None)
    throw std::runtime_error(path + ": cannot rasterize the features on the DEM grid (" + CPLGetLastErrorMsg() + ")");
  report(g, 0.2);
  std::vector<double> d = distance_transform_m(mask.data(), g.cols, g.rows, g.cell_width_m, g.cell_height_m,
                                               [&](double f) { report(g, 0.2 + 0.75 * f); });
  // No feature on the grid: every cell is "far" (a finite value, so no cell reads as forbidden).
  for (double& v : d)
    if (std::isinf(v)) v = 1e20;
  return d;
}

int density(const TerrapolisGrid* g, const char* params, float* factor, uint8_t* excluded, char* error, size_t size) {
  return guarded(error, size, [&] {
    const json p = json::parse(params);
    if (!p.contains("density")) throw std::runtime_error("params has no \"density\" object: this plugin cannot be a density factor");
    const json& dp = p["density"];
    const bool curve_given = dp.contains("points");
    const Curve curve = curve_given ? Curve::from(dp["points"]) : Curve{};
    const double exclude = dp.value("exclude_within_m", -1.0);
    const std::vector<double> d = distances(*g, p);
    for (std::size_t i = 0; i < d.size(); ++i) {
      if (curve_given) factor[i] = float(std::clamp(curve(d[i]), 0.0, 1.0));  // else NaN: exclusions only
      if (d[i] <= exclude) excluded[i] = 1;
    }
  });
}

int road(const TerrapolisGrid* g, const char* params, float* kappa, char* transfer, size_t transfer_size, char* error, size_t size) {
  return guarded(error, size, [&] {
    const json p = json::parse(params);
    if (!p.contains("road")) throw std::runtime_error("params has no \"road\" object: this plugin cannot be a road cost");
    const json& rp = p["road"];
    const double forbidden = rp.value("forbidden_within_m", -1.0);
    const std::vector<double> d = distances(*g, p);
    // kappa = distance (m), +infinity inside the forbidden zone; mu = the curve, priced as is.
    for (std::size_t i = 0; i < d.size(); ++i) kappa[i] = d[i] <= forbidden ? INFINITY : float(d[i]);
    json fn = {{"points", rp.contains("points") ? rp["points"] : json::array()}, {"threshold", nullptr}};
    for (const auto& pt : fn["points"])
      if (pt[1].get<double>() < 0) throw std::runtime_error("road.points: costs must be >= 0");
    write_transfer(transfer, transfer_size, fn, rp.value("structures", json::array({"road", "bridge"})));
  });
}

const TerrapolisPlugin plugin = {
    TERRAPOLIS_PLUGIN_ABI_VERSION,
    "distance",
    "Distance in metres to vector features (exact distance transform): attractiveness, exclusion, road cost or ban",
    kSchema,
    density,
    road,
};

}  // namespace

extern "C" TERRAPOLIS_PLUGIN_EXPORT const TerrapolisPlugin* terrapolis_plugin_entry(void) { return &plugin; }
