// Helpers shared by the C++ plugins of this repository (header-only; plugins link nothing of Terrapolis).
// SPDX-License-Identifier: MIT
#pragma once
#include <cpl_conv.h>
#include <cpl_string.h>
#include <gdal.h>
#include <gdalwarper.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "terrapolis_plugin.h"

namespace terrapolis_plugins {

using nlohmann::json;

/// Runs `work`, turning any exception into the ABI's error convention (non-zero, one-line message).
template <class F>
int guarded(char* error, std::size_t size, F&& work) {
  try {
    work();
    return 0;
  } catch (const std::exception& e) {
    std::snprintf(error, size, "%s", e.what());
    return 1;
  }
}

/// Keeps GDAL's own messages off stderr while alive: the plugin reports errors through the ABI.
struct QuietGdal {
  QuietGdal() { CPLPushErrorHandler(CPLQuietErrorHandler); }
  ~QuietGdal() { CPLPopErrorHandler(); }
  QuietGdal(const QuietGdal&) = delete;
  QuietGdal& operator=(const QuietGdal&) = delete;
};

/// Reports progress to the host; throws when the user cancelled (guarded() turns it into a failure).
inline void report(const TerrapolisGrid& g, double fraction) {
  if (g.progress && !g.progress(g.progress_context, fraction)) throw std::runtime_error("cancelled");
}

inline std::size_t cells(const TerrapolisGrid& g) { return std::size_t(g.cols) * std::size_t(g.rows); }

/// A piecewise-linear curve through (x, y) points with increasing x, constant beyond its ends.
struct Curve {
  std::vector<std::array<double, 2>> points;
  static Curve from(const json& j) {
    Curve c;
    for (const auto& p : j) c.points.push_back({p.at(0).get<double>(), p.at(1).get<double>()});
    for (std::size_t k = 1; k < c.points.size(); ++k)
      if (!(c.points[k][0] > c.points[k - 1][0])) throw std::runtime_error("curve points must have increasing x");
    return c;
  }
  double operator()(double x) const {
    if (points.empty()) return 0.0;
    if (x <= points.front()[0]) return points.front()[1];
    if (x >= points.back()[0]) return points.back()[1];
    auto it = std::upper_bound(points.begin(), points.end(), x, [](double v, const std::array<double, 2>& p) { return v < p[0]; });
    const auto& b = *it;
    const auto& a = *(it - 1);
    return a[1] + (x - a[0]) / (b[0] - a[0]) * (b[1] - a[1]);
  }
};

/// Writes the transfer functions JSON the host reads: `fn` for every structure in `structures`.
inline void write_transfer(char* out, std::size_t size, const json& fn, const json& structures) {
  json t = json::object();
  for (const auto& s : structures) t[s.get<std::string>()] = fn;
  const std::string text = t.dump();
  if (text.size() + 1 > size) throw std::runtime_error("transfer functions do not fit the host's buffer");
  std::snprintf(out, size, "%s", text.c_str());
}

/// The transfer function mu(kappa) = kappa: the characteristic already is a cost per metre.
inline json identity_transfer() { return {{"points", json::array({json::array({0.0, 0.0}), json::array({1e12, 1e12})})}, {"threshold", nullptr}}; }

/// Band `band` of any GDAL raster warped onto the plugin's grid with nearest resampling (class
/// codes must not be blended); NaN where the source has no data or does not cover the cell.
inline std::vector<double> read_on_grid(const TerrapolisGrid& g, const std::string& path, int band) {
  GDALAllRegister();
  const QuietGdal quiet;
  GDALDatasetH src = GDALOpen(path.c_str(), GA_ReadOnly);
  if (!src) throw std::runtime_error(path + ": cannot open the raster");
  struct Closer {
    GDALDatasetH h;
    ~Closer() { GDALClose(h); }
  } close_src{src};
  if (band < 1 || band > GDALGetRasterCount(src)) throw std::runtime_error(path + ": band " + std::to_string(band) + " does not exist");
  const char* src_wkt = GDALGetProjectionRef(src);
  if (!src_wkt || !*src_wkt) throw std::runtime_error(path + ": has no CRS; cannot place it on the DEM's grid");
  std::vector<double> out(cells(g), std::numeric_limits<double>::quiet_NaN());
  GDALDatasetH dst = GDALCreate(GDALGetDriverByName("MEM"), "", g.cols, g.rows, 0, GDT_Float64, nullptr);
  Closer close_dst{dst};
  char pointer[64] = {};
  CPLPrintPointer(pointer, out.data(), sizeof(pointer) - 1);
  const std::string opt = std::string("DATAPOINTER=") + pointer;
  char* band_options[] = {const_cast<char*>(opt.c_str()), nullptr};
  GDALAddBand(dst, GDT_Float64, band_options);
  GDALSetGeoTransform(dst, const_cast<double*>(g.geotransform));
  GDALSetProjection(dst, g.crs_wkt);
  GDALSetRasterNoDataValue(GDALGetRasterBand(dst, 1), std::numeric_limits<double>::quiet_NaN());
  GDALWarpOptions* wo = GDALCreateWarpOptions();
  wo->hSrcDS = src;
  wo->hDstDS = dst;
  wo->nBandCount = 1;
  wo->panSrcBands = static_cast<int*>(CPLMalloc(sizeof(int)));
  wo->panSrcBands[0] = band;
  wo->panDstBands = static_cast<int*>(CPLMalloc(sizeof(int)));
  wo->panDstBands[0] = 1;
  int has_nodata = 0;
  const double nodata = GDALGetRasterNoDataValue(GDALGetRasterBand(src, band), &has_nodata);
  if (has_nodata) {
    wo->padfSrcNoDataReal = static_cast<double*>(CPLMalloc(sizeof(double)));
    wo->padfSrcNoDataReal[0] = nodata;
  }
  wo->padfDstNoDataReal = static_cast<double*>(CPLMalloc(sizeof(double)));
  wo->padfDstNoDataReal[0] = std::numeric_limits<double>::quiet_NaN();
  wo->papszWarpOptions = CSLSetNameValue(wo->papszWarpOptions, "INIT_DEST", "NO_DATA");
  wo->eResampleAlg = GRA_NearestNeighbour;
  wo->pTransformerArg = GDALCreateGenImgProjTransformer(src, src_wkt, dst, g.crs_wkt, FALSE, 0.0, 1);
  wo->pfnTransformer = GDALGenImgProjTransform;
  CPLErr err = CE_Failure;
  if (wo->pTransformerArg) {
    GDALWarpOperationH op = GDALCreateWarpOperation(wo);
    if (op) {
      err = GDALChunkAndWarpImage(op, 0, 0, g.cols, g.rows);
      GDALDestroyWarpOperation(op);
    }
    GDALDestroyGenImgProjTransformer(wo->pTransformerArg);
  }
  GDALDestroyWarpOptions(wo);
  if (err != CE_None) throw std::runtime_error(path + ": cannot resample onto the DEM grid (" + CPLGetLastErrorMsg() + ")");
  return out;
}

}  // namespace terrapolis_plugins
