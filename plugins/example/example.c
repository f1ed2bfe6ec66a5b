/* The smallest real plugin: a constant density factor, and cells above an altitude excluded from
 * cities and forbidden to roads. docs/plugins.md walks through it; the tests load it.
 * SPDX-License-Identifier: MIT */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "terrapolis_plugin.h"

/* Parameters arrive validated and compact ({"key":value,...}, no spaces): a key lookup suffices. */
static double number(const char* json, const char* key, double fallback) {
  char pattern[64];
  snprintf(pattern, sizeof pattern, "\"%s\":", key);
  const char* at = strstr(json, pattern);
  return at ? strtod(at + strlen(pattern), NULL) : fallback;
}

static int density(const TerrapolisGrid* g, const char* params, float* factor, uint8_t* excluded, char* error, size_t size) {
  const double value = number(params, "value", 0.5), top = number(params, "max_altitude_m", INFINITY);
  (void)error, (void)size;
  for (size_t i = 0; i < (size_t)g->cols * (size_t)g->rows; ++i) {
    factor[i] = (float)value;
    if (g->elevation[i] > top) excluded[i] = 1; /* NaN compares false: no data stays habitable */
  }
  return 0;
}

static int road(const TerrapolisGrid* g, const char* params, float* kappa, char* transfer, size_t transfer_size, char* error,
                size_t size) {
  const double top = number(params, "max_altitude_m", INFINITY);
  (void)error, (void)size;
  for (size_t i = 0; i < (size_t)g->cols * (size_t)g->rows; ++i) kappa[i] = g->elevation[i];
  /* kappa = altitude: free up to `top`, forbidden above, for roads and bridges (tunnels pass under). */
  if (isinf(top)) snprintf(transfer, transfer_size, "{}");
  else snprintf(transfer, transfer_size, "{\"road\":{\"points\":[],\"threshold\":%.17g},\"bridge\":{\"points\":[],\"threshold\":%.17g}}", top, top);
  return 0;
}

static const TerrapolisPlugin plugin = {
    TERRAPOLIS_PLUGIN_ABI_VERSION,
    "example",
    "Constant density factor; cells above max_altitude_m excluded from cities and forbidden to roads",
    "{\"type\":\"object\",\"additionalProperties\":false,\"properties\":{"
    "\"value\":{\"type\":\"number\",\"minimum\":0,\"maximum\":1,\"default\":0.5,\"description\":\"the factor everywhere\"},"
    "\"max_altitude_m\":{\"type\":\"number\",\"description\":\"cells above it are excluded and forbidden\"}}}",
    density,
    road,
};

TERRAPOLIS_PLUGIN_EXPORT const TerrapolisPlugin* terrapolis_plugin_entry(void) { return &plugin; }
