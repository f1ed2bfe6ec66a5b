// The density folder as the sites command and a resumed run read it: one reader, nodata kept.
// SPDX-License-Identifier: MIT
#include <gtest/gtest.h>

#include <cmath>

#include "core/error.hpp"
#include "io/crs.hpp"
#include "io/raster_io.hpp"
#include "pipeline/density_folder.hpp"
#include "support/georefs.hpp"
#include "support/temp_dir.hpp"

using namespace terrapolis;

namespace {
Georef utm_grid() {
  Georef g = test::projected(100.0);
  g.crs = crs_from_user("EPSG:32632");
  return g;
}
}  // namespace

// A 3 x 2 grid: buildable 1, 0, 255 (nodata) and density 0.5, 0, NaN read back cell for cell.
TEST(DensityFolder, NodataStaysNodata) {
  test::TempDir dir;
  Raster<float> density(3, 2, utm_grid(), 0.0f);
  Raster<std::uint8_t> buildable(3, 2, utm_grid(), 0);
  buildable.nodata = 255;
  const std::uint8_t b[6] = {1, 0, 255, 1, 1, 0};
  const float d[6] = {0.5f, 0.0f, NAN, 1.0f, 0.25f, 0.0f};
  for (std::size_t i = 0; i < 6; ++i) buildable[i] = b[i], density[i] = d[i];
  write_raster((dir.path() / "density.tif").string(), density);
  write_raster((dir.path() / "buildable.tif").string(), buildable);
  const pipeline::DensityFolder in = pipeline::read_density_folder(dir.path().string());
  ASSERT_EQ(in.buildable.size(), 6u);
  for (std::size_t i = 0; i < 6; ++i) {
    EXPECT_EQ(in.buildable[i], b[i]) << i;
    if (std::isnan(d[i])) EXPECT_TRUE(std::isnan(in.density[i]));
    else EXPECT_EQ(in.density[i], d[i]) << i;
  }
  EXPECT_TRUE(in.buildable.is_nodata(2));
}

TEST(DensityFolder, RefusesAMissingMaskAndOutOfRangeDensities) {
  test::TempDir dir;
  Raster<float> density(3, 2, utm_grid(), 0.5f);
  write_raster((dir.path() / "density.tif").string(), density);
  EXPECT_THROW(pipeline::read_density_folder(dir.path().string()), Error);  // no buildable.tif
  write_raster((dir.path() / "buildable.tif").string(), Raster<std::uint8_t>(3, 2, utm_grid(), 1));
  density[0] = 2.0f;
  WriteOptions replace;
  replace.overwrite = true;
  write_raster((dir.path() / "density.tif").string(), density, replace);
  EXPECT_THROW(pipeline::read_density_folder(dir.path().string()), Error);
  EXPECT_THROW(pipeline::read_density_folder((dir.path() / "none").string()), Error);
}
