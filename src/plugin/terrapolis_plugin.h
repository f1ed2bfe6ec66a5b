/* The public, stable C ABI of Terrapolis plugins: density factors and road cost terms.
 * SPDX-License-Identifier: MIT
 *
 * A plugin is a shared library exporting one function, terrapolis_plugin_entry(), that returns a
 * static TerrapolisPlugin. The host refuses a library whose abi_version differs from
 * TERRAPOLIS_PLUGIN_ABI_VERSION, that lacks the entry point, or whose parameter schema is not a
 * valid JSON Schema (draft 7) object. Parameters are validated against that schema by the host
 * before any call, so a plugin may trust their shape. This header is plain C99 and includes only
 * <stddef.h> and <stdint.h>; a plugin needs nothing else from Terrapolis. See docs/plugins.md.
 */
#ifndef TERRAPOLIS_PLUGIN_H
#define TERRAPOLIS_PLUGIN_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/** Bumped whenever a struct or a function signature below changes. */
#define TERRAPOLIS_PLUGIN_ABI_VERSION 1u

/** The DEM grid the plugin works on. Every array is owned by the host and valid during the call. */
typedef struct TerrapolisGrid {
  int32_t cols, rows;          /**< grid size; cells are row-major, row 0 north */
  double geotransform[6];      /**< GDAL geotransform of the grid (CRS units, corner of cell 0,0) */
  const char* crs_wkt;         /**< WKT2 of the grid's CRS (empty string when unreferenced) */
  int32_t geographic;          /**< 1 when CRS coordinates are longitude/latitude degrees */
  const float* elevation;      /**< cols*rows elevations in metres, NaN = no data */
  const double* cell_width_m;  /**< rows entries: east-west distance between cell centres of row r, metres (geodesic) */
  const double* cell_height_m; /**< rows entries: north-south distance between centres of rows r and r+1, metres (last row: r-1..r) */
  /** Reports the fraction (0..1) of the call done, from the calling thread only. Returns 0 when
   *  the user cancelled: the plugin should then return non-zero soon (its message is ignored). */
  int (*progress)(void* progress_context, double fraction);
  void* progress_context;
} TerrapolisGrid;

/** Computes a density factor. Writes cols*rows values in [0,1] to `factor` (1 = most attractive;
 *  NaN, the value on entry, = no opinion: the factor takes no part in that cell's weighted
 *  combination) and may set cells of `excluded` (cols*rows, all 0 on entry) to 1 to make them
 *  uninhabitable. `params_json` is the plugin's parameter object, validated against its schema,
 *  printed compactly (no whitespace, keys sorted; defaults are not filled in). On failure returns
 *  non-zero and writes a one-line message (no trailing newline) to `error` (size `error_size`). */
typedef int (*TerrapolisDensityFactorFn)(const TerrapolisGrid* grid, const char* params_json, float* factor,
                                         uint8_t* excluded, char* error, size_t error_size);

/** Computes a road cost term. Writes cols*rows values of a characteristic kappa to `characteristic`
 *  and writes to `transfer_json` (size `transfer_size`, at least 65536 bytes) a JSON object with
 *  up to three keys "road", "bridge", "tunnel", each a transfer function in the format of the
 *  cost model file: {"points": [[kappa, cost per metre], ...], "threshold": kappa0 or null}
 *  (piecewise linear, constant beyond its ends, +infinity above the threshold). The term adds
 *  mu(kappa) per metre of a structure whose key is present, and nothing to the others. A cell
 *  whose kappa is NaN costs nothing; +infinity forbids the cell to the structures present.
 *  Errors as for the density factor. */
typedef int (*TerrapolisRoadCostFn)(const TerrapolisGrid* grid, const char* params_json, float* characteristic,
                                    char* transfer_json, size_t transfer_size, char* error, size_t error_size);

/** What a plugin provides. Strings and the struct itself must stay valid while the library is loaded. */
typedef struct TerrapolisPlugin {
  uint32_t abi_version;                   /**< TERRAPOLIS_PLUGIN_ABI_VERSION */
  const char* id;                         /**< [a-z0-9_]+, also the library's name: terrapolis_<id>.so */
  const char* description;                /**< one line */
  const char* parameter_schema;           /**< JSON Schema (draft 7) of the parameter object */
  TerrapolisDensityFactorFn density_factor; /**< NULL when the plugin has no density factor */
  TerrapolisRoadCostFn road_cost;           /**< NULL when the plugin has no road cost term */
} TerrapolisPlugin;

#if defined(_WIN32)
#define TERRAPOLIS_PLUGIN_EXPORT __declspec(dllexport)
#else
#define TERRAPOLIS_PLUGIN_EXPORT __attribute__((visibility("default")))
#endif

/** The one symbol the host looks up. */
typedef const TerrapolisPlugin* (*TerrapolisPluginEntryFn)(void);
#define TERRAPOLIS_PLUGIN_ENTRY_SYMBOL "terrapolis_plugin_entry"

#ifdef __cplusplus
}
#endif

#endif /* TERRAPOLIS_PLUGIN_H */
