// GDAL raster reading and GeoTIFF writing.
// SPDX-License-Identifier: MIT
#include "io/raster_io.hpp"

#include <cpl_conv.h>
#include <cpl_error.h>
#include <gdal_priv.h>
#include <gdal_utils.h>
#include <gdalwarper.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <memory>
#include <mutex>
#include <string>
#include <unistd.h>

#include "core/error.hpp"
#include "core/interrupt.hpp"
#include "core/memory.hpp"
#include "io/gdal_util.hpp"

namespace terrapolis {
namespace {

struct DatasetCloser {
  void operator()(GDALDataset* d) const { if (d) GDALClose(GDALDataset::ToHandle(d)); }
};
using DatasetPtr = std::unique_ptr<GDALDataset, DatasetCloser>;

using detail::QuietGdal;

DatasetPtr open_raster(const std::string& path) {
  init_gdal();
  std::error_code ec;
  if (!std::filesystem::exists(path, ec) && path.rfind("/vsi", 0) != 0)
    throw bad_input(path + ": no such file");
  QuietGdal quiet;
  auto* ds = GDALDataset::Open(path.c_str(), GDAL_OF_RASTER | GDAL_OF_READONLY);
  if (!ds) throw bad_input(path + ": not a raster GDAL can read (" + detail::last_gdal_error("unknown format") + ")");
  if (ds->GetRasterCount() == 0) {
    GDALClose(ds);
    throw bad_input(path + ": holds no raster band");
  }
  return DatasetPtr(ds);
}

/// Metres per vertical unit from the band's unit string or a compound CRS's vertical part.
double vertical_factor(const std::string& path, GDALRasterBand* band, const OGRSpatialReference* srs, std::string& unit) {
  unit = band->GetUnitType() ? band->GetUnitType() : "";
  std::string u = unit;
  std::transform(u.begin(), u.end(), u.begin(), [](unsigned char c) { return std::tolower(c); });
  if (u.empty() && srs && srs->IsCompound()) {
    const char* name = nullptr;
    const double f = srs->GetTargetLinearUnits("VERT_CS", &name);
    if (name) unit = name;
    if (f > 0) return f;
  }
  if (u.empty() || u == "m" || u == "metre" || u == "meter" || u == "metres" || u == "meters") return 1.0;
  if (u == "ft" || u == "foot" || u == "feet" || u == "international foot") return 0.3048;
  if (u == "us-ft" || u == "us survey foot" || u == "ftus" || u == "foot_us") return 1200.0 / 3937.0;
  if (u == "cm") return 0.01;
  if (u == "km") return 1000.0;
  throw bad_input(path + ": unknown vertical unit '" + unit + "'");
}

std::string number(double v) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.10g", v);
  return text;
}

/// Refuses a geotransform no stage can work on: non-finite terms, a zero or degenerate cell (its
/// two axes parallel), a geographic extent off the globe, or a projected extent larger than the Earth.
void check_georeferencing(const std::string& path, const RasterHeader& h) {
  const GeoTransform& gt = h.georef.transform;
  if (!std::all_of(gt.begin(), gt.end(), [](double v) { return std::isfinite(v); }))
    throw bad_input(path + ": geotransform has a NaN or infinite term (" + number(gt[0]) + ", " + number(gt[1]) + ", " +
                    number(gt[2]) + ", " + number(gt[3]) + ", " + number(gt[4]) + ", " + number(gt[5]) + ")");
  const double width = std::hypot(gt[1], gt[4]), height = std::hypot(gt[2], gt[5]);
  if (width == 0 || height == 0)
    throw bad_input(path + ": geotransform has a zero cell size (" + number(width) + " x " + number(height) + ")");
  // |det| = width * height * sin(angle between the axes): near 0, the cells are flat parallelograms.
  const double det = gt[1] * gt[5] - gt[2] * gt[4];
  if (std::abs(det) < 1e-6 * width * height)
    throw bad_input(path + ": geotransform is degenerate (its pixel and line axes are parallel)");
  const double xs[4] = {gt[0], gt[0] + h.cols * gt[1], gt[0] + h.rows * gt[2], gt[0] + h.cols * gt[1] + h.rows * gt[2]};
  const double ys[4] = {gt[3], gt[3] + h.cols * gt[4], gt[3] + h.rows * gt[5], gt[3] + h.cols * gt[4] + h.rows * gt[5]};
  const auto [xmin, xmax] = std::minmax_element(std::begin(xs), std::end(xs));
  const auto [ymin, ymax] = std::minmax_element(std::begin(ys), std::end(ys));
  if (h.georef.crs.geographic) {
    // Half a cell of slack: grids registered on their nodes put cell edges just past the poles or the antimeridian.
    const double sx = 0.5 * width + 1e-9, sy = 0.5 * height + 1e-9;
    if (*ymin < -90 - sy || *ymax > 90 + sy || *xmin < -180 - sx || *xmax > 360 + sx || *xmax - *xmin > 360 + 2 * sx)
      throw bad_input(path + ": geographic extent lon " + number(*xmin) + " .. " + number(*xmax) + ", lat " + number(*ymin) +
                      " .. " + number(*ymax) + " is outside [-180, 360] x [-90, 90] (a pixel-unit geotransform labelled with a "
                      "geographic CRS?)");
    // Cell widths vanish at a pole: a row centred on it (a node-registered global grid) has no area.
    const double top = gt[3] + 0.5 * gt[5], bottom = gt[3] + (h.rows - 0.5) * gt[5];
    if (std::max(std::abs(top), std::abs(bottom)) >= 90)
      throw bad_input(path + ": a row of cells is centred on a pole (a node-registered grid?); crop that row");
  } else {
    const double unit = h.georef.crs.linear_unit_m, earth = 5e7;  // the equator (40,075 km), with margin
    if ((*xmax - *xmin) * unit > earth || (*ymax - *ymin) * unit > earth)
      throw bad_input(path + ": extent " + number((*xmax - *xmin) * unit / 1000) + " x " + number((*ymax - *ymin) * unit / 1000) +
                      " km is larger than the Earth (wrong cell size or unit?)");
  }
}

/// Every output vector is written in WGS 84 lon/lat (RFC 7946): refuse up front a DEM whose cells
/// cannot all be transformed there (a CRS used outside its projection's domain, e.g. a UTM zone
/// labelling coordinates thousands of kilometres from its meridian), rather than fail on an output.
/// Tests cell centres on a lattice of at most 257 x 257, its last row and column on the grid's.
void check_lonlat_domain(const std::string& path, const RasterHeader& h) {
  if (h.georef.crs.empty()) return;
  const OGRSpatialReference from = detail::to_ogr(h.georef.crs);
  OGRSpatialReference to;
  to.SetWellKnownGeogCS("WGS84");
  to.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
  QuietGdal quiet;
  std::unique_ptr<OGRCoordinateTransformation> ct(OGRCreateCoordinateTransformation(&from, &to));
  if (!ct) throw bad_input(path + ": its CRS cannot be transformed to WGS 84 (" + detail::last_gdal_error("no transformation") + ")");
  auto lattice = [](int n) {
    std::vector<double> at;
    const int step = std::max(1, n / 256);
    for (int i = 0; i < n; i += step) at.push_back(i + 0.5);
    if (at.back() != n - 0.5) at.push_back(n - 0.5);
    return at;
  };
  const std::vector<double> cols = lattice(h.cols), rows = lattice(h.rows);
  const GeoTransform& gt = h.georef.transform;
  std::vector<double> x, y;
  for (double r : rows)
    for (double c : cols) x.push_back(gt[0] + c * gt[1] + r * gt[2]), y.push_back(gt[3] + c * gt[4] + r * gt[5]);
  std::vector<double> lon = x, lat = y;
  std::vector<int> ok(x.size(), 0);
  ct->Transform(x.size(), lon.data(), lat.data(), nullptr, ok.data());
  for (std::size_t i = 0; i < x.size(); ++i)
    if (!ok[i] || !std::isfinite(lon[i]) || !std::isfinite(lat[i]) || std::abs(lat[i]) > 90)
      throw bad_input(path + ": the cell at " + h.georef.crs.name + " (" + number(x[i]) + ", " + number(y[i]) +
                      ") cannot be transformed to WGS 84 lon/lat (" + detail::last_gdal_error("outside the CRS's domain") +
                      "); is the CRS right?");
}

RasterHeader header_of(const std::string& path, GDALDataset& ds, const ReadOptions& options, GDALRasterBand*& band_out,
                       double& vfactor) {
  RasterHeader h;
  h.cols = ds.GetRasterXSize();
  h.rows = ds.GetRasterYSize();
  h.bands = ds.GetRasterCount();
  h.driver = ds.GetDriver() ? ds.GetDriver()->GetDescription() : "";
  int band = 1;
  if (options.band) {
    band = *options.band;
    if (band < 1 || band > h.bands)
      throw bad_input(path + ": band " + std::to_string(band) + " does not exist (the file has " + std::to_string(h.bands) + ")");
  } else if (h.bands > 1) {
    throw bad_input(path + ": has " + std::to_string(h.bands) +
                    " bands (a colour image?), not a DEM; choose one with --band N");
  }
  GDALRasterBand* b = ds.GetRasterBand(band);
  if (!options.band && (b->GetColorTable() || b->GetColorInterpretation() == GCI_PaletteIndex))
    throw bad_input(path + ": is a palette colour image, not a DEM; use --band 1 to read its indices as heights");
  h.data_type = GDALGetDataTypeName(b->GetRasterDataType());
  if (h.cols < 2 || h.rows < 2)
    throw bad_input(path + ": is " + std::to_string(h.cols) + "x" + std::to_string(h.rows) + " cells; a DEM needs at least 2x2");
  // Refuse before allocating anything: float values plus the working copies a stage makes.
  const double bytes = double(h.cols) * double(h.rows) * sizeof(float);
  const double memory = double(sysconf(_SC_PHYS_PAGES)) * double(sysconf(_SC_PAGE_SIZE));
  if (!options.windowed && (double(h.cols) * double(h.rows) > double(std::numeric_limits<std::int32_t>::max()) || bytes * 4 > memory))
    throw bad_input(path + ": size " + std::to_string(h.cols) + "x" + std::to_string(h.rows) + " (" +
                    std::to_string(std::int64_t(bytes / 1e6)) + " MB as float) is too large for this machine's memory");
  std::array<double, 6> gt;
  if (ds.GetGeoTransform(gt.data()) != CE_None)
    throw bad_input(path + ": has no geotransform (not georeferenced)");
  h.georef.transform = gt;
  const OGRSpatialReference* srs = ds.GetSpatialRef();
  if (srs && !srs->IsEmpty()) {
    h.georef.crs = detail::describe(*srs);
  } else if (options.assume_crs) {
    OGRSpatialReference user;
    QuietGdal quiet;
    if (user.SetFromUserInput(options.assume_crs->c_str()) != OGRERR_NONE)
      throw bad_input(path + ": unknown CRS '" + *options.assume_crs + "' given to --assume-crs");
    h.georef.crs = detail::describe(user);
  } else {
    throw bad_input(path + ": has no CRS; give one with --assume-crs EPSG:n");
  }
  if (h.georef.crs.geographic && (gt[2] != 0 || gt[4] != 0))
    throw bad_input(path + ": rotated geographic grids are not supported");
  check_georeferencing(path, h);
  check_lonlat_domain(path, h);
  int has_nodata = 0;
  const double nd = b->GetNoDataValue(&has_nodata);
  if (has_nodata) h.nodata = nd;
  int has = 0;
  h.scale = b->GetScale(&has);
  if (!has) h.scale = 1.0;
  h.offset = b->GetOffset(&has);
  if (!has) h.offset = 0.0;
  vfactor = vertical_factor(path, b, srs, h.vertical_unit);
  band_out = b;
  return h;
}

GDALDataType gdal_type(float) { return GDT_Float32; }
GDALDataType gdal_type(double) { return GDT_Float64; }
GDALDataType gdal_type(std::uint8_t) { return GDT_Byte; }
GDALDataType gdal_type(std::int16_t) { return GDT_Int16; }
GDALDataType gdal_type(std::uint16_t) { return GDT_UInt16; }
GDALDataType gdal_type(std::int32_t) { return GDT_Int32; }
GDALDataType gdal_type(std::uint32_t) { return GDT_UInt32; }

/// Turns the raw values of a window (col0, row0) read into `dem` into metres, NaN on nodata (the
/// nodata value, the mask band, non-finite values); returns the number of valid cells.
std::size_t to_metres(const std::string& path, GDALRasterBand* band, const RasterHeader& h, double vfactor, int col0, int row0,
                      Dem& dem) {
  // A mask band that is not just "nodata value" or "all valid" (alpha, internal mask) also hides cells.
  std::vector<std::uint8_t> mask;
  const int flags = band->GetMaskFlags();
  if (!(flags & GMF_ALL_VALID) && !(flags & GMF_NODATA)) {
    mask.resize(dem.size());
    QuietGdal quiet;
    if (band->GetMaskBand()->RasterIO(GF_Read, col0, row0, dem.cols(), dem.rows(), mask.data(), dem.cols(), dem.rows(), GDT_Byte, 0, 0) != CE_None)
      throw bad_input(path + ": corrupt mask band (" + detail::last_gdal_error("read failed") + ")");
  }
  // Compare in float: the nodata value went through the same conversion as the data.
  const bool has_nd = h.nodata.has_value() && !std::isnan(*h.nodata);
  const float nd = has_nd ? float(*h.nodata) : 0.0f;
  const double factor = h.scale * vfactor, offset = h.offset * vfactor;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  std::size_t valid = 0;
  for (std::size_t i = 0; i < dem.size(); ++i) {
    float& v = dem[i];
    if ((has_nd && v == nd) || (!mask.empty() && mask[i] == 0) || !std::isfinite(v)) {
      v = nan;
      continue;
    }
    if (factor != 1.0 || offset != 0.0) v = float(v * factor + offset);
    ++valid;
  }
  return valid;
}

/// The DEM at `path`: a raster GDAL reads (a GeoTIFF, a VRT mosaic, ...) or a folder of GeoTIFF
/// tiles, joined into an in-memory VRT (tiles of one grid and CRS; where they overlap, the last in
/// name order wins).
DatasetPtr open_dem_source(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fs::is_directory(path, ec)) return open_raster(path);
  const std::vector<std::string> tiles = folder_tiles(path);
  if (tiles.empty()) throw bad_input(path + ": folder holds no GeoTIFF tile (.tif)");
  // A VRT would leave out tiles of another CRS and resample those of another resolution: refuse them.
  std::array<double, 6> first{};
  OGRSpatialReference first_srs;
  for (std::size_t i = 0; i < tiles.size(); ++i) {
    auto tile = open_raster(tiles[i]);
    std::array<double, 6> gt{};
    if (tile->GetGeoTransform(gt.data()) != CE_None) throw bad_input(tiles[i] + ": has no geotransform (not georeferenced)");
    const OGRSpatialReference* srs = tile->GetSpatialRef();
    if (i == 0) {
      first = gt;
      if (srs) first_srs = *srs;
    } else if (gt[1] != first[1] || gt[5] != first[5] || gt[2] != first[2] || gt[4] != first[4]) {
      throw bad_input(tiles[i] + ": cell size differs from " + tiles[0] + "'s; the tiles of a mosaic share one grid");
    } else if ((srs == nullptr) != first_srs.IsEmpty() || (srs && !srs->IsSame(&first_srs))) {
      throw bad_input(tiles[i] + ": CRS differs from " + tiles[0] + "'s; the tiles of a mosaic share one CRS");
    }
  }
  std::vector<const char*> names;
  for (const auto& t : tiles) names.push_back(t.c_str());
  init_gdal();
  QuietGdal quiet;
  int usage_error = 0;
  GDALDatasetH vrt = GDALBuildVRT("", int(names.size()), nullptr, names.data(), nullptr, &usage_error);
  if (!vrt) throw bad_input(path + ": cannot join its tiles (" + detail::last_gdal_error("unknown error") + ")");
  return DatasetPtr(GDALDataset::FromHandle(vrt));
}

}  // namespace

void check_grid_georeferencing(const std::string& what, const RasterHeader& header) {
  check_georeferencing(what, header);
  check_lonlat_domain(what, header);
}

void init_gdal() {
  static std::once_flag once;  // GDAL's driver registry is process-wide by design
  std::call_once(once, [] {
    GDALAllRegister();
    CPLSetConfigOption("GDAL_PAM_ENABLED", "NO");  // never write .aux.xml beside inputs or outputs
    // GDAL's messages never reach the terminal on their own ("ERROR 1: ..." before our line): each
    // failure is reported once, naming the input, from CPLGetLastErrorMsg (recorded before handlers run).
    CPLSetErrorHandler(CPLQuietErrorHandler);
  });
}

std::vector<std::string> folder_tiles(const std::string& folder) {
  std::vector<std::string> tiles;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(folder, ec)) {
    std::string ext = entry.path().extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
    if (entry.is_regular_file() && (ext == ".tif" || ext == ".tiff")) tiles.push_back(entry.path().string());
  }
  if (ec) throw bad_input(folder + ": cannot be read (" + ec.message() + ")");
  std::sort(tiles.begin(), tiles.end());  // a fixed order: where tiles overlap, the last one wins
  return tiles;
}

double reserve_reader_memory(double limit_mb) {
  init_gdal();
  map_large_blocks();
  release_free_memory();  // what an earlier step freed is not the process's any more
  double cache_mb = std::min(64.0, limit_mb / 8);
  if (!CPLGetConfigOption("GDAL_CACHEMAX", nullptr)) GDALSetCacheMax64(GIntBig(cache_mb * 1e6));
  else cache_mb = double(GDALGetCacheMax64()) / 1e6;
  constexpr int kPool = 16;  // GDAL's default is 100 open files, each with its own buffers
  int pool = kPool;
  if (const char* user = CPLGetConfigOption("GDAL_MAX_DATASET_POOL_SIZE", nullptr)) pool = std::max(2, std::atoi(user));
  else CPLSetConfigOption("GDAL_MAX_DATASET_POOL_SIZE", std::to_string(kPool).c_str());
  return cache_mb + 0.8 * pool + resident_mb();
}

ReadOptions read_options(int band, const std::string& assume_crs) {
  ReadOptions o;
  if (band > 0) o.band = band;
  if (!assume_crs.empty()) o.assume_crs = assume_crs;
  return o;
}

RasterHeader read_header(const std::string& path, const ReadOptions& options) {
  auto ds = open_dem_source(path);
  GDALRasterBand* band = nullptr;
  double vfactor = 1.0;
  return header_of(path, *ds, options, band, vfactor);
}

Dem read_dem(const std::string& path, const ReadOptions& options) {
  auto ds = open_dem_source(path);
  GDALRasterBand* band = nullptr;
  double vfactor = 1.0;
  const RasterHeader h = header_of(path, *ds, options, band, vfactor);

  Dem dem(h.cols, h.rows, h.georef);
  {
    QuietGdal quiet;
    if (band->RasterIO(GF_Read, 0, 0, h.cols, h.rows, dem.data(), h.cols, h.rows, GDT_Float32, 0, 0) != CE_None)
      throw bad_input(path + ": corrupt or truncated (" + detail::last_gdal_error("read failed") + ")");
  }
  const std::size_t valid = to_metres(path, band, h, vfactor, 0, 0, dem);
  if (valid == 0) throw bad_input(path + ": holds no data (every cell is nodata)");
  return dem;
}

WarpScale warp_scale(const std::string& path, const Georef& like, int cols, int rows) {
  auto src = open_raster(path);
  const OGRSpatialReference* srs = src->GetSpatialRef();
  if (!srs || srs->IsEmpty()) throw bad_input(path + ": has no CRS; cannot place it on the DEM's grid");
  std::array<double, 6> src_gt{};
  if (src->GetGeoTransform(src_gt.data()) != CE_None) throw bad_input(path + ": has no geotransform; cannot place it on the DEM's grid");
  char* src_wkt = nullptr;
  srs->exportToWkt(&src_wkt);
  void* transformer = GDALCreateGenImgProjTransformer3(src_wkt, src_gt.data(), like.crs.wkt.c_str(), like.transform.data());
  CPLFree(src_wkt);
  if (!transformer) throw bad_input(path + ": cannot be placed on the DEM's grid");
  // The grid's centre and a square of 16 cells from it, into source pixels.
  constexpr double kSide = 16;
  const double cx = 0.5 * cols, cy = 0.5 * rows;
  double x[3] = {cx, cx + kSide, cx}, y[3] = {cy, cy, cy + kSide}, z[3] = {0, 0, 0};
  int ok[3] = {0, 0, 0};
  GDALGenImgProjTransform(transformer, TRUE, 3, x, y, z, ok);
  GDALDestroyGenImgProjTransformer(transformer);
  if (!ok[0] || !ok[1] || !ok[2]) throw bad_input(path + ": the DEM's centre does not fall on it");
  const double span_x = std::fabs(x[1] - x[0]) + std::fabs(x[2] - x[0]), span_y = std::fabs(y[1] - y[0]) + std::fabs(y[2] - y[0]);
  return {span_x > 0 ? kSide / span_x : 1.0, span_y > 0 ? kSide / span_y : 1.0};
}

Raster<float> read_resampled(const std::string& path, const Georef& like, int cols, int rows, Resampling resampling, int band,
                             const WarpScale* scale) {
  auto src = open_raster(path);
  if (band < 1 || band > src->GetRasterCount()) throw bad_input(path + ": band " + std::to_string(band) + " does not exist");
  const OGRSpatialReference* srs = src->GetSpatialRef();
  if (!srs || srs->IsEmpty()) throw bad_input(path + ": has no CRS; cannot place it on the DEM's grid");
  Raster<float> out(cols, rows, like, std::numeric_limits<float>::quiet_NaN());
  GDALDriver* mem = GetGDALDriverManager()->GetDriverByName("MEM");
  DatasetPtr dst(mem->Create("", cols, rows, 0, GDT_Float32, nullptr));
  char pointer[64] = {};  // CPLPrintPointer does not null-terminate: keep a zero at the end
  CPLPrintPointer(pointer, out.data(), sizeof(pointer) - 1);
  const std::string opt = std::string("DATAPOINTER=") + pointer;
  char* band_options[] = {const_cast<char*>(opt.c_str()), nullptr};
  dst->AddBand(GDT_Float32, band_options);
  dst->SetGeoTransform(const_cast<double*>(like.transform.data()));
  const OGRSpatialReference dst_srs = detail::to_ogr(like.crs);
  dst->SetSpatialRef(&dst_srs);
  dst->GetRasterBand(1)->SetNoDataValue(std::numeric_limits<double>::quiet_NaN());

  GDALWarpOptions* wo = GDALCreateWarpOptions();
  wo->hSrcDS = GDALDataset::ToHandle(src.get());
  wo->hDstDS = GDALDataset::ToHandle(dst.get());
  wo->nBandCount = 1;
  wo->panSrcBands = static_cast<int*>(CPLMalloc(sizeof(int)));
  wo->panSrcBands[0] = band;
  wo->panDstBands = static_cast<int*>(CPLMalloc(sizeof(int)));
  wo->panDstBands[0] = 1;
  int has_nd = 0;
  const double nd = src->GetRasterBand(band)->GetNoDataValue(&has_nd);
  if (has_nd) {
    wo->padfSrcNoDataReal = static_cast<double*>(CPLMalloc(sizeof(double)));
    wo->padfSrcNoDataReal[0] = nd;
  }
  wo->padfDstNoDataReal = static_cast<double*>(CPLMalloc(sizeof(double)));
  wo->padfDstNoDataReal[0] = std::numeric_limits<double>::quiet_NaN();
  wo->papszWarpOptions = CSLSetNameValue(wo->papszWarpOptions, "INIT_DEST", "NO_DATA");
  if (scale) {
    char value[32];
    std::snprintf(value, sizeof value, "%.17g", scale->x);
    wo->papszWarpOptions = CSLSetNameValue(wo->papszWarpOptions, "XSCALE", value);
    std::snprintf(value, sizeof value, "%.17g", scale->y);
    wo->papszWarpOptions = CSLSetNameValue(wo->papszWarpOptions, "YSCALE", value);
  }
  switch (resampling) {
    case Resampling::nearest: wo->eResampleAlg = GRA_NearestNeighbour; break;
    case Resampling::bilinear: wo->eResampleAlg = GRA_Bilinear; break;
    case Resampling::cubic: wo->eResampleAlg = GRA_Cubic; break;
    case Resampling::average: wo->eResampleAlg = GRA_Average; break;
    case Resampling::mode: wo->eResampleAlg = GRA_Mode; break;
  }
  char* src_wkt = nullptr;
  srs->exportToWkt(&src_wkt);
  wo->pTransformerArg = GDALCreateGenImgProjTransformer(wo->hSrcDS, src_wkt, wo->hDstDS, like.crs.wkt.c_str(), FALSE, 0.0, 1);
  CPLFree(src_wkt);
  wo->pfnTransformer = GDALGenImgProjTransform;
  CPLErr err = CE_Failure;
  {
    QuietGdal quiet;
    if (wo->pTransformerArg) {
      GDALWarpOperation op;
      if (op.Initialize(wo) == CE_None) err = op.ChunkAndWarpImage(0, 0, cols, rows);
    }
    const std::string msg = detail::last_gdal_error("warp failed");
    if (wo->pTransformerArg) GDALDestroyGenImgProjTransformer(wo->pTransformerArg);
    GDALDestroyWarpOptions(wo);
    if (err != CE_None) throw bad_input(path + ": cannot resample onto the DEM grid (" + msg + ")");
  }
  return out;
}

template <class T>
void write_raster(const std::string& path, const Raster<T>& raster, const WriteOptions& options) {
  init_gdal();
  detail::check_output(path, options.overwrite);
  GDALDriver* mem = GetGDALDriverManager()->GetDriverByName("MEM");
  DatasetPtr src(mem->Create("", raster.cols(), raster.rows(), 0, gdal_type(T{}), nullptr));
  char pointer[64] = {};  // CPLPrintPointer does not null-terminate: keep a zero at the end
  CPLPrintPointer(pointer, const_cast<T*>(raster.data()), sizeof(pointer) - 1);
  const std::string opt = std::string("DATAPOINTER=") + pointer;
  char* band_options[] = {const_cast<char*>(opt.c_str()), nullptr};
  src->AddBand(gdal_type(T{}), band_options);
  src->SetGeoTransform(const_cast<double*>(raster.georef().transform.data()));
  if (!raster.georef().crs.empty()) {
    const OGRSpatialReference srs = detail::to_ogr(raster.georef().crs);
    src->SetSpatialRef(&srs);
  }
  GDALRasterBand* band = src->GetRasterBand(1);
  if constexpr (std::is_floating_point_v<T>) band->SetNoDataValue(std::numeric_limits<double>::quiet_NaN());
  else if (raster.nodata) band->SetNoDataValue(*raster.nodata);
  if (!options.description.empty()) {
    band->SetDescription(options.description.c_str());
    src->SetMetadataItem("DESCRIPTION", options.description.c_str());
  }
  for (const auto& [key, value] : options.metadata) src->SetMetadataItem(key.c_str(), value.c_str());

  const bool is_float = std::is_floating_point_v<T>;
  CPLStringList co;
  co.SetNameValue("COMPRESS", "DEFLATE");
  if (options.deflate_level != 6)  // the COG driver calls it LEVEL, GTiff ZLEVEL
    co.SetNameValue(options.cog ? "LEVEL" : "ZLEVEL", std::to_string(std::clamp(options.deflate_level, 1, 9)).c_str());
  co.SetNameValue("BIGTIFF", "IF_SAFER");
  // Blocks compressed on the threads --threads allows; GDAL writes them in order: same bytes.
  co.SetNameValue("NUM_THREADS",
                  std::to_string(tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism)).c_str());
  GDALDriver* driver = nullptr;
  if (options.cog) {
    driver = GetGDALDriverManager()->GetDriverByName("COG");
    co.SetNameValue("PREDICTOR", "YES");
    co.SetNameValue("OVERVIEW_RESAMPLING", is_float ? "AVERAGE" : "NEAREST");
  } else {
    driver = GetGDALDriverManager()->GetDriverByName("GTiff");
    co.SetNameValue("TILED", "YES");
    co.SetNameValue("PREDICTOR", is_float ? "3" : "2");
  }
  const std::string tmp = detail::temporary_name(path);
  {
    QuietGdal quiet;
    // GDAL's progress callback stops a long write at an interrupt (SIGINT/SIGTERM).
    const auto keep_going = [](double, const char*, void*) -> int { return interrupt_signal() == 0; };
    errno = 0;
    GDALDataset* out = driver->CreateCopy(tmp.c_str(), src.get(), FALSE, co.List(), keep_going, nullptr);
    if (out) GDALClose(GDALDataset::ToHandle(out));
    // Errors of the last blocks' flush are raised by the close: check after it.
    const bool ok = out && CPLGetLastErrorType() < CE_Failure;
    if (!ok) {
      const int error = errno;
      const std::string msg = detail::last_gdal_error("write failed");
      detail::discard_file(tmp);
      stop_if_interrupted();
      throw detail::write_failure(path, error, msg);
    }
  }
  detail::commit_file(tmp, path);
}

template void write_raster(const std::string&, const Raster<float>&, const WriteOptions&);
template void write_raster(const std::string&, const Raster<double>&, const WriteOptions&);
template void write_raster(const std::string&, const Raster<std::uint8_t>&, const WriteOptions&);
template void write_raster(const std::string&, const Raster<std::int16_t>&, const WriteOptions&);
template void write_raster(const std::string&, const Raster<std::uint16_t>&, const WriteOptions&);
template void write_raster(const std::string&, const Raster<std::int32_t>&, const WriteOptions&);
template void write_raster(const std::string&, const Raster<std::uint32_t>&, const WriteOptions&);

struct DemWindowReader::Dataset {
  DatasetPtr dataset;
  GDALRasterBand* band = nullptr;
  double vfactor = 1.0;
  std::mutex mutex;  // GDAL datasets are not thread-safe
};

DemWindowReader::DemWindowReader(const std::string& path, ReadOptions options)
    : path_(path), dataset_(std::make_unique<Dataset>()) {
  options.windowed = true;
  dataset_->dataset = open_dem_source(path);
  header_ = header_of(path, *dataset_->dataset, options, dataset_->band, dataset_->vfactor);
}

DemWindowReader::~DemWindowReader() = default;

Dem DemWindowReader::read(int col0, int row0, int cols, int rows) const {
  const Georef georef = header_.georef.window(col0, row0);
  Dem window(cols, rows, georef, std::numeric_limits<float>::quiet_NaN());
  const int c0 = std::max(col0, 0), r0 = std::max(row0, 0);
  const int c1 = std::min(col0 + cols, header_.cols), r1 = std::min(row0 + rows, header_.rows);
  if (c0 >= c1 || r0 >= r1) return window;
  Dem part(c1 - c0, r1 - r0, georef);
  {
    std::lock_guard lock(dataset_->mutex);
    QuietGdal quiet;
    if (dataset_->band->RasterIO(GF_Read, c0, r0, part.cols(), part.rows(), part.data(), part.cols(), part.rows(), GDT_Float32, 0,
                                 0) != CE_None)
      throw bad_input(path_ + ": corrupt or truncated (" + detail::last_gdal_error("read failed") + ")");
    to_metres(path_, dataset_->band, header_, dataset_->vfactor, c0, r0, part);
  }
  for (int r = 0; r < part.rows(); ++r)
    std::copy_n(&part(0, r), part.cols(), &window(c0 - col0, r0 - row0 + r));
  return window;
}

void read_resampled_by_bands(const std::string& path, const Georef& like, int cols, int rows, Resampling resampling, const WarpScale* scale,
                             const std::function<void(const Raster<float>& band, int row0)>& band, std::size_t band_cells) {
  const int n = int(std::clamp(double(band_cells) / std::max(1, cols), 1.0, double(std::max(1, rows))));
  for (int r = 0; r < rows; r += n) band(read_resampled(path, like.window(0, r), cols, std::min(n, rows - r), resampling, 1, scale), r);
}

CellSampler::CellSampler(const DemWindowReader& reader, int block, std::size_t max_blocks)
    : reader_(reader), block_(std::max(1, block)), max_blocks_(std::max<std::size_t>(1, max_blocks)) {}

float CellSampler::at(int col, int row) {
  const std::pair<int, int> key{col / block_, row / block_};
  auto it = blocks_.find(key);
  if (it == blocks_.end()) {
    if (blocks_.size() >= max_blocks_) blocks_.clear();
    const RasterHeader& h = reader_.header();
    const int c0 = key.first * block_, r0 = key.second * block_;
    it = blocks_.emplace(key, reader_.read(c0, r0, std::min(block_, h.cols - c0), std::min(block_, h.rows - r0))).first;
  }
  return it->second(col - key.first * block_, row - key.second * block_);
}

void DemWindowReader::check_cells() const {
  const int strip = std::max(1, int(std::min<std::int64_t>(header_.rows, (1 << 22) / std::max(1, header_.cols))));  // ~16 MB a strip
  for (int r0 = 0; r0 < header_.rows; r0 += strip) {
    const Dem part = read(0, r0, header_.cols, std::min(strip, header_.rows - r0));
    if (std::any_of(part.values().begin(), part.values().end(), [](float v) { return !std::isnan(v); })) {
      for (int r1 = r0 + strip; r1 < header_.rows; r1 += strip) read(0, r1, header_.cols, std::min(strip, header_.rows - r1));
      return;
    }
  }
  throw bad_input(path_ + ": holds no data (every cell is nodata)");
}

void write_vrt(const std::string& path, const std::vector<std::string>& tiles, bool overwrite) {
  init_gdal();
  detail::check_output(path, overwrite);
  std::vector<const char*> names;
  for (const auto& t : tiles) names.push_back(t.c_str());
  const std::string tmp = detail::temporary_name(path);
  QuietGdal quiet;
  int usage_error = 0;
  GDALDatasetH vrt = GDALBuildVRT(tmp.c_str(), int(names.size()), nullptr, names.data(), nullptr, &usage_error);
  const bool ok = vrt && CPLGetLastErrorType() < CE_Failure;
  if (vrt) GDALClose(vrt);
  if (!ok) {
    const std::string msg = detail::last_gdal_error("write failed");
    detail::discard_file(tmp);
    throw bad_input(path + ": cannot write output (" + msg + ")");
  }
  detail::commit_file(tmp, path);
}

ScratchFolder::ScratchFolder(std::string path) : path_(std::move(path)) {
  std::filesystem::remove_all(path_);
  std::filesystem::create_directories(path_);
}

ScratchFolder::~ScratchFolder() {
  std::error_code ec;
  std::filesystem::remove_all(path_, ec);
}

std::string MosaicFiles::tile(int t, int across) const {
  char file[64];
  std::snprintf(file, sizeof file, "tile_%04d_%04d.tif", t / across, t % across);
  return dir + "/" + name + "/" + file;
}

void MosaicFiles::create() const {
  std::filesystem::remove_all(dir + "/" + name);  // a rerun's tiles may be cut otherwise
  std::filesystem::create_directories(dir + "/" + name);
}

void MosaicFiles::finish(int tiles, int across) const {
  std::vector<std::string> files;
  for (int t = 0; t < tiles; ++t) files.push_back(tile(t, across));
  write_vrt(vrt(), files, true);
}

}  // namespace terrapolis
