// The PNG writer module (OpenImageIO), loaded by preview.cpp only when a preview is written.
// SPDX-License-Identifier: MIT
#include "pipeline/png/png_writer.h"

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>

#include <cstdio>
#include <filesystem>
#include <string>

extern "C" __attribute__((visibility("default"))) int terrapolis_write_png(const float* rgb, int width, int height,
                                                                           const TerrapolisPngText* texts, int count,
                                                                           const char* font, const char* path, char* error,
                                                                           int error_size) {
  OIIO::ImageSpec spec(width, height, 3, OIIO::TypeDesc::FLOAT);
  OIIO::ImageBuf buf(spec, const_cast<float*>(rgb));
  OIIO::ImageBuf image;
  image.copy(buf, OIIO::TypeDesc::UINT8);
  // OpenImageIO asserts (imagebuf.h pos_xincr) on text whose box misses the image: draw only text
  // whose baseline and height lie inside it.
  if (std::filesystem::exists(font))
    for (int i = 0; i < count; ++i)
      if (texts[i].size > 0 && texts[i].x >= 0 && texts[i].x < width && texts[i].y - texts[i].size >= 0 && texts[i].y < height)
        OIIO::ImageBufAlgo::render_text(image, texts[i].x, texts[i].y, texts[i].text, texts[i].size, font, texts[i].rgb);
  if (!image.write(path, OIIO::TypeDesc::UINT8, "png")) {
    std::snprintf(error, std::size_t(error_size), "%s", image.geterror().c_str());
    return 1;
  }
  return 0;
}
