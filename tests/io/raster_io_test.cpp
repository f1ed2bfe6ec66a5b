// GeoTIFF round trips and reading of the awkward real sample DEMs.
// SPDX-License-Identifier: MIT
#include <gtest/gtest.h>

#include <gdal_priv.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "core/error.hpp"
#include "io/crs.hpp"
#include "io/raster_io.hpp"
#include "support/temp_dir.hpp"

using namespace terrapolis;
using terrapolis::test::sample;
using terrapolis::test::TempDir;

namespace {
std::size_t count_nodata(const Dem& d) {
  std::size_t n = 0;
  for (std::size_t i = 0; i < d.size(); ++i) n += d.is_nodata(i);
  return n;
}
}  // namespace

TEST(RasterIo, FloatRoundTripIsBitExact) {
  TempDir dir;
  const Dem in = read_dem(sample("whiteboxR_DEM_vermont.tif"));
  Dem copy = in;
  copy[5] = std::nanf("");  // nodata survives
  WriteOptions options;
  options.description = "test";
  options.metadata = {{"TERRAPOLIS_TEST", "1"}};
  write_raster(dir.file("out.tif"), copy, options);
  const Dem back = read_dem(dir.file("out.tif"));
  ASSERT_EQ(back.cols(), in.cols());
  ASSERT_EQ(back.rows(), in.rows());
  EXPECT_TRUE(back.is_nodata(5));
  for (std::size_t i = 0; i < in.size(); ++i)
    if (i != 5) {
      ASSERT_EQ(std::memcmp(&back[i], &copy[i], sizeof(float)), 0) << i;
    }
  EXPECT_EQ(back.georef().transform, in.georef().transform);
  EXPECT_EQ(back.georef().crs.epsg, std::optional<int>(26918));
  EXPECT_EQ(back.georef().crs.name, in.georef().crs.name);
}

TEST(RasterIo, IntegerRoundTripKeepsNodataAndCog) {
  TempDir dir;
  const Dem dem = read_dem(sample("terra_elev_luxembourg.tif"));
  Raster<std::int16_t> r = dem.like<std::int16_t>();
  r.nodata = -32768;
  for (std::size_t i = 0; i < r.size(); ++i) r[i] = dem.is_nodata(i) ? -32768 : std::int16_t(dem[i]);
  WriteOptions cog;
  cog.cog = true;
  write_raster(dir.file("cog.tif"), r, cog);
  const Dem back = read_dem(dir.file("cog.tif"));
  EXPECT_EQ(count_nodata(back), count_nodata(dem));
  for (std::size_t i = 0; i < r.size(); ++i)
    if (!dem.is_nodata(i)) {
      ASSERT_EQ(back[i], float(r[i]));
    }
  GDALDataset* ds = GDALDataset::Open(dir.file("cog.tif").c_str(), GDAL_OF_RASTER);
  ASSERT_NE(ds, nullptr);
  const char* layout = ds->GetMetadataItem("LAYOUT", "IMAGE_STRUCTURE");
  EXPECT_STREQ(layout, "COG");
  EXPECT_STREQ(ds->GetMetadataItem("COMPRESSION", "IMAGE_STRUCTURE"), "DEFLATE");
  GDALClose(ds);
}

TEST(RasterIo, SameInputSameBytes) {
  TempDir dir;
  const Dem dem = read_dem(sample("spDataLarge_dem_mongon.tif"));
  write_raster(dir.file("a.tif"), dem);
  write_raster(dir.file("b.tif"), dem);
  EXPECT_EQ(std::filesystem::file_size(dir.file("a.tif")), std::filesystem::file_size(dir.file("b.tif")));
  std::ifstream a(dir.file("a.tif"), std::ios::binary), b(dir.file("b.tif"), std::ios::binary);
  EXPECT_TRUE(std::equal(std::istreambuf_iterator<char>(a), {}, std::istreambuf_iterator<char>(b)));
}

TEST(RasterIo, RefusesExistingOutputUnlessOverwrite) {
  TempDir dir;
  const Dem dem = read_dem(sample("spDataLarge_dem_mongon.tif"));
  write_raster(dir.file("a.tif"), dem);
  EXPECT_THROW(write_raster(dir.file("a.tif"), dem), Error);
  WriteOptions overwrite;
  overwrite.overwrite = true;
  EXPECT_NO_THROW(write_raster(dir.file("a.tif"), dem, overwrite));
  EXPECT_THROW(write_raster(dir.file("missing/a.tif"), dem), Error);
  for (const auto& e : std::filesystem::directory_iterator(dir.path()))
    EXPECT_EQ(e.path().filename().string().find(".tmp"), std::string::npos) << "temporary left behind";
}

TEST(RasterIo, AsciiGridWithPrjIsGeoreferenced) {
  const Dem d = read_dem(sample("gebco2022_15s_north_corsica_capcorse.asc"));
  EXPECT_EQ(d.cols(), 175);
  EXPECT_TRUE(d.georef().crs.geographic);
  EXPECT_EQ(d.georef().crs.epsg, std::optional<int>(4326));
  EXPECT_NEAR(d.georef().transform[0], 8.7125, 1e-9);
  EXPECT_NEAR(d.georef().transform[1], 15.0 / 3600.0, 1e-9);
  EXPECT_NEAR(d.georef().transform[3], 43.208333333, 1e-6);
  float lo = 1e9f;
  for (float v : d.values()) lo = std::min(lo, v);
  EXPECT_EQ(lo, -2601.0f);  // bathymetry is data, not nodata
}

TEST(RasterIo, AwkwardNodataConventions) {
  // UInt16 with 65535, NaN nodata, and a file without a nodata tag.
  const Dem zion = read_dem(sample("spDataLarge_srtm_zion.tif"));
  for (float v : zion.values()) ASSERT_TRUE(std::isnan(v) || (v >= 1024 && v <= 2892));
  const Dem nz = read_dem(sample("spDataLarge_nz_elev.tif"));
  EXPECT_NEAR(double(count_nodata(nz)) / double(nz.size()), 0.834, 0.001);
  EXPECT_FALSE(nz.georef().crs.epsg.has_value());  // NZTM2000 by parameters, no code in the file
  EXPECT_FALSE(nz.georef().crs.geographic);
  const Dem olinda = read_dem(sample("stars_olinda_dem_utm25s.tif"));
  EXPECT_EQ(count_nodata(olinda), 0u);
  const Dem lux = read_dem(sample("terra_elev_luxembourg.tif"));
  EXPECT_NEAR(double(count_nodata(lux)) / double(lux.size()), 0.461, 0.001);
}

TEST(RasterIo, ScaleOffsetAndFeetBecomeMetres) {
  TempDir dir;
  // A VRT over a real DEM that declares feet, a scale and an offset.
  init_gdal();
  const std::string src = sample("spDataLarge_dem_mongon.tif");
  const std::string vrt = dir.file("feet.vrt");
  GDALDataset* s = GDALDataset::Open(src.c_str(), GDAL_OF_RASTER);
  GDALDriver* drv = GetGDALDriverManager()->GetDriverByName("VRT");
  GDALDataset* v = drv->CreateCopy(vrt.c_str(), s, FALSE, nullptr, nullptr, nullptr);
  v->GetRasterBand(1)->SetUnitType("ft");
  v->GetRasterBand(1)->SetScale(2.0);
  v->GetRasterBand(1)->SetOffset(10.0);
  GDALClose(v);
  GDALClose(s);
  const Dem metres = read_dem(src), feet = read_dem(vrt);
  for (std::size_t i = 0; i < metres.size(); i += 97)
    EXPECT_NEAR(feet[i], (metres[i] * 2.0 + 10.0) * 0.3048, 1e-3);
}

TEST(RasterIo, ResampledOntoItsOwnGridIsIdentity) {
  const std::string path = sample("whiteboxR_DEM_vermont.tif");
  const Dem d = read_dem(path);
  const Raster<float> r = read_resampled(path, d.georef(), d.cols(), d.rows(), Resampling::nearest);
  for (std::size_t i = 0; i < d.size(); ++i) ASSERT_EQ(r[i], d[i]);
}

TEST(RasterIo, UtmCornersInLonLatMatchGdalinfo) {
  const Dem d = read_dem(sample("whiteboxR_DEM_vermont.tif"));
  const GridLocator loc(d.georef());
  const auto dms = [](double deg, double min, double sec) { return deg + min / 60.0 + sec / 3600.0; };
  const auto ul = loc.crs_to_lonlat(664692.0, 4895824.0);
  EXPECT_NEAR(ul[0], -dms(72, 56, 20.40), 1e-5);
  EXPECT_NEAR(ul[1], dms(44, 11, 49.36), 1e-5);
  const auto p = loc.pixel_to_crs(d.cols(), d.rows());
  const auto lr = loc.crs_to_lonlat(p[0], p[1]);
  EXPECT_NEAR(lr[0], -dms(72, 40, 41.69), 1e-5);
  EXPECT_NEAR(lr[1], dms(44, 2, 22.95), 1e-5);
  const auto back = loc.crs_to_pixel(p[0], p[1]);
  EXPECT_NEAR(back[0], d.cols(), 1e-9);
  EXPECT_NEAR(back[1], d.rows(), 1e-9);
  const auto xy = loc.lonlat_to_crs(lr[0], lr[1]);
  EXPECT_NEAR(xy[0], p[0], 1e-4);
}

TEST(RasterIo, CellSamplerReadsTheCellsThroughItsBlocks) {
  // Random cells of a real DEM through blocks of 37 cells, two at most held:
  // every value the whole raster's, across block edges, the last partial blocks and evictions.
  const std::string path = sample("whiteboxR_DEM_vermont.tif");
  const Dem whole = read_dem(path);
  const DemWindowReader reader(path);
  CellSampler cells(reader, 37, 2);
  std::uint64_t state = 12345;
  for (int k = 0; k < 5000; ++k) {
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    const int c = int((state >> 33) % std::uint64_t(whole.cols())), r = int((state >> 13) % std::uint64_t(whole.rows()));
    const float v = cells.at(c, r), w = whole(c, r);
    ASSERT_TRUE(std::isnan(w) ? std::isnan(v) : v == w) << c << "," << r;
  }
  EXPECT_EQ(cells.at(whole.cols() - 1, whole.rows() - 1), whole(whole.cols() - 1, whole.rows() - 1));
}
