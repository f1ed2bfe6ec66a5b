// Catchment delineation: snap, upstream walk on D8, GDALPolygonize of the mask.
// SPDX-License-Identifier: MIT
#include "hydro/catchment.hpp"

#include <gdal_alg.h>
#include <gdal_priv.h>
#include <ogrsf_frmts.h>
#include <vrtdataset.h>

#include <cmath>
#include <memory>
#include <vector>

#include "core/error.hpp"
#include "hydro/grid.hpp"
#include "io/crs.hpp"
#include "io/raster_io.hpp"

namespace terrapolis::hydro {

namespace {

/// GDALPolygonize of a band of labels (8-connected; labels < 0 are none).
std::vector<std::pair<std::int32_t, Feature>> polygonize_band(GDALRasterBand* band) {
  GDALDriver* vmem = GetGDALDriverManager()->GetDriverByName("Memory");
  if (!vmem) vmem = GetGDALDriverManager()->GetDriverByName("MEM");
  std::unique_ptr<GDALDataset> vds(vmem->Create("", 0, 0, 0, GDT_Unknown, nullptr));
  OGRLayer* layer = vds->CreateLayer("labels", nullptr, wkbPolygon, nullptr);
  OGRFieldDefn field("value", OFTInteger);
  layer->CreateField(&field);
  char** options = CSLSetNameValue(nullptr, "8CONNECTED", "8");
  const CPLErr err = GDALPolygonize(band, nullptr, layer, 0, options, nullptr, nullptr);
  CSLDestroy(options);
  if (err != CE_None) throw processing_error("polygonize: GDALPolygonize failed");
  std::vector<std::pair<std::int32_t, Feature>> out;
  layer->ResetReading();
  for (auto& feature : *layer) {
    const std::int32_t value = feature->GetFieldAsInteger(0);
    const OGRGeometry* g = feature->GetGeometryRef();
    if (value < 0 || !g || wkbFlatten(g->getGeometryType()) != wkbPolygon) continue;
    const auto* poly = g->toPolygon();
    Feature f;
    auto ring_points = [](const OGRLinearRing* ring) {
      std::vector<std::array<double, 2>> pts;
      for (int i = 0; i < ring->getNumPoints(); ++i) pts.push_back({ring->getX(i), ring->getY(i)});
      return pts;
    };
    f.parts.push_back(ring_points(poly->getExteriorRing()));
    for (int h = 0; h < poly->getNumInteriorRings(); ++h) f.parts.push_back(ring_points(poly->getInteriorRing(h)));
    out.emplace_back(value, std::move(f));
  }
  return out;
}

}  // namespace

std::vector<std::pair<std::int32_t, Feature>> polygonize_labels(const Raster<std::int32_t>& labels) {
  init_gdal();
  GDALDriver* mem = GetGDALDriverManager()->GetDriverByName("MEM");
  if (!mem) throw processing_error("polygonize: GDAL's MEM driver is missing");
  std::unique_ptr<GDALDataset> ds(mem->Create("", labels.cols(), labels.rows(), 1, GDT_Int32, nullptr));
  GeoTransform gt = labels.georef().transform;
  ds->SetGeoTransform(gt.data());
  GDALRasterBand* band = ds->GetRasterBand(1);
  if (band->RasterIO(GF_Write, 0, 0, labels.cols(), labels.rows(), const_cast<std::int32_t*>(labels.values().data()), labels.cols(),
                     labels.rows(), GDT_Int32, 0, 0) != CE_None)
    throw processing_error("polygonize: cannot fill the in-memory raster");
  return polygonize_band(band);
}

std::vector<std::pair<std::int32_t, Feature>> polygonize_labels(const std::string& path, const Georef& grid) {
  init_gdal();
  std::unique_ptr<GDALDataset> source(GDALDataset::Open(path.c_str(), GDAL_OF_RASTER | GDAL_OF_READONLY));
  if (!source || source->GetRasterCount() < 1) throw processing_error("polygonize: cannot read " + path);
  // Read through a virtual raster on the grid's own geotransform (a VRT of tiles may differ from it
  // in the last bit): the polygons' coordinates are the in-memory grid's.
  GDALDriver* vrt = GetGDALDriverManager()->GetDriverByName("VRT");
  if (!vrt) throw processing_error("polygonize: GDAL's VRT driver is missing");
  const int cols = source->GetRasterXSize(), rows = source->GetRasterYSize();
  std::unique_ptr<GDALDataset> view(vrt->Create("", cols, rows, 0, GDT_Int32, nullptr));
  GeoTransform gt = grid.transform;
  view->SetGeoTransform(gt.data());
  view->AddBand(GDT_Int32, nullptr);
  auto* band = static_cast<VRTSourcedRasterBand*>(view->GetRasterBand(1));
  if (band->AddSimpleSource(source->GetRasterBand(1), 0, 0, cols, rows, 0, 0, cols, rows) != CE_None)
    throw processing_error("polygonize: cannot read " + path + " through a virtual raster");
  return polygonize_band(band);
}

std::vector<Feature> polygonize(const Raster<std::uint8_t>& mask) {
  Raster<std::int32_t> labels = mask.like<std::int32_t>(-1);
  for (std::size_t i = 0; i < mask.size(); ++i)
    if (mask[i] == 1) labels[i] = 1;
  std::vector<Feature> out;
  for (auto& [value, f] : polygonize_labels(labels)) out.push_back(std::move(f));
  return out;
}

void label_by_descent(const Raster<std::uint8_t>& d8, Raster<std::uint32_t>& labels) {
  std::vector<std::size_t> path;
  for (std::size_t start = 0; start < d8.size(); ++start) {
    if (labels[start] != 0 || d8[start] == kNoData) continue;
    std::size_t i = start;
    while (labels[i] == 0) {
      path.push_back(i);
      const std::uint8_t k = d8[i];
      const int nc = int(i % std::size_t(d8.cols())) + (k < 8 ? dcol[k] : 0), nr = int(i / std::size_t(d8.cols())) + (k < 8 ? drow[k] : 0);
      if (k >= 8 || !d8.inside(nc, nr) || d8(nc, nr) == kNoData)
        throw processing_error("basins: a D8 path ends at a cell without a label");
      i = d8.index(nc, nr);
    }
    for (std::size_t p : path) labels[p] = labels[i];
    path.clear();
  }
}

Raster<std::uint32_t> drainage_basins(const Raster<std::uint8_t>& d8) {
  Raster<std::uint32_t> labels = d8.like<std::uint32_t>(0);
  labels.nodata = 0;
  std::uint64_t outlets = 0;
  for (int r = 0; r < d8.rows(); ++r)
    for (int c = 0; c < d8.cols(); ++c) {
      const std::uint8_t k = d8(c, r);
      if (k == kNoData) continue;
      const int nc = c + (k < 8 ? dcol[k] : 0), nr = r + (k < 8 ? drow[k] : 0);
      if (k >= 8 || !d8.inside(nc, nr) || d8(nc, nr) == kNoData) {
        if (++outlets >= 0xFFFFFFFFu) throw bad_input("basins: more than 2^32 - 2 outlets");
        labels(c, r) = std::uint32_t(outlets);
      }
    }
  label_by_descent(d8, labels);
  return labels;
}

Catchment delineate_catchment(const Raster<std::uint8_t>& d8, const Raster<double>& area, const CellMetrics& metrics,
                              double x, double y, double snap_radius_m, Progress& progress) {
  if (!(snap_radius_m >= 0) || !std::isfinite(snap_radius_m)) throw bad_input("snap radius: must be >= 0 metres");
  ProgressStep step(progress, "catchment");
  const GridLocator locator(d8.georef());
  const auto px = locator.crs_to_pixel(x, y);
  const int pc = int(std::floor(px[0])), pr = int(std::floor(px[1]));
  if (!std::isfinite(px[0]) || !d8.inside(pc, pr))
    throw bad_input("outlet: the point is outside the DEM");
  // Snap: highest upstream area within the radius (ties: lowest row, then column).
  const double cell_min = std::min(metrics.width_m[std::size_t(pr)], metrics.height_m[std::size_t(pr)]);
  const int reach = int(std::ceil(snap_radius_m / cell_min)) + 1;
  int best_c = -1, best_r = -1;
  double best = -1;
  for (int r = std::max(0, pr - reach); r <= std::min(d8.rows() - 1, pr + reach); ++r)
    for (int c = std::max(0, pc - reach); c <= std::min(d8.cols() - 1, pc + reach); ++c) {
      if (d8(c, r) == kNoData) continue;
      const bool same = c == pc && r == pr;
      if (!same) {
        const auto a = d8.georef().cell_centre(c, r);
        if (crs_distance_m(d8.georef().crs, x, y, a[0], a[1]) > snap_radius_m) continue;
      }
      if (area(c, r) > best) {
        best = area(c, r);
        best_c = c;
        best_r = r;
      }
    }
  if (best_c < 0) throw bad_input("outlet: no valid DEM cell within the snap radius of the point");
  Catchment out;
  out.outlet_col = best_c;
  out.outlet_row = best_r;
  const auto centre = d8.georef().cell_centre(best_c, best_r);
  out.outlet_x = centre[0];
  out.outlet_y = centre[1];
  out.mask = d8.like<std::uint8_t>(0);
  out.mask.nodata = 255;
  for (std::size_t i = 0; i < d8.size(); ++i)
    if (d8[i] == kNoData) out.mask[i] = 255;
  std::vector<std::size_t> stack{d8.index(best_c, best_r)};
  out.mask(best_c, best_r) = 1;
  double area_m2 = 0;
  while (!stack.empty()) {
    const std::size_t i = stack.back();
    stack.pop_back();
    const int c = int(i % std::size_t(d8.cols())), r = int(i / std::size_t(d8.cols()));
    area_m2 += metrics.area_m2[std::size_t(r)];
    ++out.cells;
    for (int k = 0; k < 8; ++k) {
      const int nc = c + dcol[k], nr = r + drow[k];
      if (!d8.inside(nc, nr)) continue;
      const std::size_t n = d8.index(nc, nr);
      if (out.mask[n] == 0 && d8[n] == opposite(k)) {
        out.mask[n] = 1;
        stack.push_back(n);
      }
    }
  }
  out.area_km2 = area_m2 / 1e6;
  step.update(0.5);
  out.polygon.name = "catchment";
  out.polygon.geometry = GeometryType::polygon;
  out.polygon.crs = d8.georef().crs;
  out.polygon.fields = {{"area_km2", FieldType::real}, {"cells", FieldType::integer}, {"outlet_x", FieldType::real},
                        {"outlet_y", FieldType::real}};
  for (auto& f : polygonize(out.mask)) {
    f.values = {out.area_km2, std::int64_t(out.cells), out.outlet_x, out.outlet_y};
    out.polygon.features.push_back(std::move(f));
  }
  return out;
}

}  // namespace terrapolis::hydro
