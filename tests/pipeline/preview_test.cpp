// preview.png at every small width the schema allows, on the sample DEMs: OpenImageIO used to abort
// (imagebuf.h pos_xincr assertion) when the legend's text fell outside a small image.
#include <gtest/gtest.h>

#include <gdal_priv.h>

#include <filesystem>

#include "io/raster_io.hpp"
#include "pipeline/preview.hpp"
#include "pipeline/run_state.hpp"
#include "pipeline/scenario.hpp"

namespace terrapolis::pipeline {
namespace {

TEST(Preview, SmallWidthsOnEverySampleDem) {
  const Scenario scenario = load_scenario("");
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / ("tp_preview_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  for (const char* name : {"spDataLarge_dem_mongon.tif", "spDataLarge_nz_elev.tif", "spDataLarge_srtm_zion.tif",
                           "stars_olinda_dem_utm25s.tif", "terra_elev_luxembourg.tif", "whiteboxR_DEM_vermont.tif",
                           "gebco2022_15s_north_corsica_capcorse.asc"}) {
    Dem dem = read_dem(std::string(TERRAPOLIS_SAMPLES) + "/" + name);
    const RasterHeader grid = grid_of(dem);
    RunState state(scenario, dir, "", std::move(dem), grid);
    state.density = state.dem.like<float>(0.5f);
    for (int width : {64, 65, 66, 80, 99, 100, 127, 128, 200}) {
      const std::string png = (dir / (std::string(name) + "-" + std::to_string(width) + ".png")).string();
      ASSERT_NO_THROW(write_preview(state, png, width)) << name << " at " << width;
      GDALDataset* ds = static_cast<GDALDataset*>(GDALOpen(png.c_str(), GA_ReadOnly));
      ASSERT_NE(ds, nullptr) << png;
      EXPECT_EQ(ds->GetRasterXSize(), width) << png;
      EXPECT_GE(ds->GetRasterYSize(), 16) << png;
      GDALClose(ds);
    }
  }
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace terrapolis::pipeline
