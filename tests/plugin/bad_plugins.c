/* Broken plugins the host must refuse: compiled three times with BAD_ABI, BAD_SCHEMA or NO_ENTRY.
 * SPDX-License-Identifier: MIT */
#include "terrapolis_plugin.h"

#if !defined(NO_ENTRY)
static int density(const TerrapolisGrid* g, const char* params, float* factor, uint8_t* excluded, char* error, size_t size) {
  (void)params, (void)excluded, (void)error, (void)size;
  for (size_t i = 0; i < (size_t)g->cols * (size_t)g->rows; ++i) factor[i] = 1.0f;
  return 0;
}
#endif

#if defined(BAD_ABI)
static const TerrapolisPlugin plugin = {TERRAPOLIS_PLUGIN_ABI_VERSION + 41, "bad_abi", "wrong ABI version", "{\"type\":\"object\"}", density, 0};
#elif defined(BAD_SCHEMA)
static const TerrapolisPlugin plugin = {TERRAPOLIS_PLUGIN_ABI_VERSION, "bad_schema", "schema with a wrong keyword type",
                                        "{\"type\":\"object\",\"properties\":{\"x\":{\"type\":12}}}", density, 0};
#endif

#if defined(NO_ENTRY)
TERRAPOLIS_PLUGIN_EXPORT int terrapolis_plugin_something_else(void) { return 0; }
#else
TERRAPOLIS_PLUGIN_EXPORT const TerrapolisPlugin* terrapolis_plugin_entry(void) { return &plugin; }
#endif
