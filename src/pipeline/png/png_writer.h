/* The PNG writer module: OpenImageIO kept out of the terrapolis process until a preview is written
   (OpenImageIO pulls in some 250 shared libraries, about 0.35 s and 80 MB at every start).
   SPDX-License-Identifier: MIT */
#ifndef TERRAPOLIS_PNG_WRITER_H
#define TERRAPOLIS_PNG_WRITER_H

#ifdef __cplusplus
extern "C" {
#endif

/** One line of text drawn on the image: baseline origin in pixels, height in pixels, RGB in 0..1. */
typedef struct TerrapolisPngText {
  int x, y, size;
  float rgb[3];
  const char* text;
} TerrapolisPngText;

/** Writes `rgb` (width x height x 3 floats in 0..1, row 0 at the top) with `texts` drawn in the
    TrueType `font` (skipped when the font is missing) as an 8-bit PNG at `path`.
    Returns 0, or 1 with a message in `error` (`error_size` bytes, NUL-terminated). */
typedef int (*TerrapolisWritePng)(const float* rgb, int width, int height, const TerrapolisPngText* texts, int count,
                                  const char* font, const char* path, char* error, int error_size);

#define TERRAPOLIS_WRITE_PNG_SYMBOL "terrapolis_write_png"

#ifdef __cplusplus
}
#endif
#endif
