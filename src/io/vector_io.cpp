// GDAL/OGR vector writing and reading.
// SPDX-License-Identifier: MIT
#include "io/vector_io.hpp"

#include <cpl_error.h>
#include <cpl_vsi.h>
#include <gdal_priv.h>
#include <ogrsf_frmts.h>

#include <algorithm>
#include <atomic>
#include <filesystem>
#include <memory>
#include <optional>

#include "core/error.hpp"
#include "io/gdal_util.hpp"
#include "io/raster_io.hpp"

namespace terrapolis {
namespace {

std::string lower_extension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext;
}

OGRwkbGeometryType ogr_type(GeometryType t) {
  switch (t) {
    case GeometryType::point: return wkbPoint;
    case GeometryType::line_string: return wkbLineString;
    case GeometryType::polygon: return wkbPolygon;
  }
  return wkbUnknown;
}

std::unique_ptr<OGRGeometry> make_geometry(GeometryType t, const Feature& f) {
  switch (t) {
    case GeometryType::point: {
      if (f.parts.empty() || f.parts[0].empty()) return nullptr;
      return std::make_unique<OGRPoint>(f.parts[0][0][0], f.parts[0][0][1]);
    }
    case GeometryType::line_string: {
      auto line = std::make_unique<OGRLineString>();
      if (!f.parts.empty())
        for (const auto& p : f.parts[0]) line->addPoint(p[0], p[1]);
      return line;
    }
    case GeometryType::polygon: {
      auto poly = std::make_unique<OGRPolygon>();
      for (const auto& ring_points : f.parts) {
        OGRLinearRing ring;
        for (const auto& p : ring_points) ring.addPoint(p[0], p[1]);
        ring.closeRings();
        poly->addRing(&ring);
      }
      return poly;
    }
  }
  return nullptr;
}

}  // namespace

int VectorLayer::field_index(const std::string& field) const {
  for (std::size_t i = 0; i < fields.size(); ++i)
    if (fields[i].name == field) return int(i);
  return -1;
}

namespace {

/// Writes one layer into `ds` (the caller's dataset of `path`); throws through `fail`.
template <class Fail>
void add_layer(GDALDataset* ds, const VectorLayer& layer, bool geojson, const Fail& fail) {
  OGRSpatialReference srs = detail::to_ogr(layer.crs);
  CPLStringList lco;
  if (geojson) {
    lco.SetNameValue("RFC7946", "YES");
    lco.SetNameValue("WRITE_NAME", "YES");
  }
  OGRLayer* out = ds->CreateLayer(layer.name.c_str(), &srs, ogr_type(layer.geometry), lco.List());
  if (!out) fail("layer creation failed");
  for (const auto& f : layer.fields) {
    OGRFieldDefn def(f.name.c_str(), f.type == FieldType::integer ? OFTInteger64 : f.type == FieldType::real ? OFTReal : OFTString);
    if (out->CreateField(&def) != OGRERR_NONE) fail("field creation failed");
  }
  for (const auto& f : layer.features) {
    OGRFeature feature(out->GetLayerDefn());
    for (std::size_t i = 0; i < layer.fields.size() && i < f.values.size(); ++i) {
      const auto& v = f.values[i];
      if (std::holds_alternative<std::int64_t>(v)) feature.SetField(int(i), GIntBig(std::get<std::int64_t>(v)));
      else if (std::holds_alternative<double>(v)) feature.SetField(int(i), std::get<double>(v));
      else if (std::holds_alternative<std::string>(v)) feature.SetField(int(i), std::get<std::string>(v).c_str());
      else feature.SetFieldNull(int(i));
    }
    auto geometry = make_geometry(layer.geometry, f);
    if (geometry) {
      geometry->assignSpatialReference(&srs);
      feature.SetGeometryDirectly(geometry.release());
    }
    if (out->CreateFeature(&feature) != OGRERR_NONE) fail("feature write failed");
  }
}

/// The layer_styles table as QGIS writes it into a GeoPackage: QGIS applies the row whose
/// f_table_name is a layer's and useAsDefault is set when it loads that layer.
template <class Fail>
void add_styles(GDALDataset* ds, const std::vector<LayerStyle>& styles, const Fail& fail) {
  OGRLayer* table = ds->CreateLayer("layer_styles", nullptr, wkbNone, nullptr);
  if (!table) fail("layer_styles creation failed");
  const char* text_fields[] = {"f_table_catalog", "f_table_schema", "f_table_name", "f_geometry_column", "styleName",
                               "styleQML",        "styleSLD",       "description",  "owner",             "ui"};
  for (const char* name : text_fields) {
    OGRFieldDefn def(name, OFTString);
    if (table->CreateField(&def) != OGRERR_NONE) fail("layer_styles field creation failed");
  }
  OGRFieldDefn use("useAsDefault", OFTInteger);
  use.SetSubType(OFSTBoolean);
  OGRFieldDefn time("update_time", OFTDateTime);
  if (table->CreateField(&use) != OGRERR_NONE || table->CreateField(&time) != OGRERR_NONE) fail("layer_styles field creation failed");
  for (const LayerStyle& st : styles) {
    OGRFeature row(table->GetLayerDefn());
    row.SetField("f_table_catalog", "");
    row.SetField("f_table_schema", "");
    row.SetField("f_table_name", st.layer.c_str());
    row.SetField("f_geometry_column", "geom");
    row.SetField("styleName", st.layer.c_str());
    row.SetField("styleQML", st.qml.c_str());
    row.SetField("styleSLD", "");
    row.SetField("description", st.description.c_str());
    row.SetField("owner", "");
    row.SetField("ui", "");
    row.SetField("useAsDefault", 1);
    row.SetField("update_time", 2000, 1, 1, 0, 0, 0.0f, 100);  // fixed: the same run gives the same bytes
    if (table->CreateFeature(&row) != OGRERR_NONE) fail("layer_styles write failed");
  }
}

}  // namespace

void write_vector(const std::string& path, const VectorLayer& layer, bool overwrite) { write_vectors(path, {&layer}, {}, overwrite); }

void write_vectors(const std::string& path, const std::vector<const VectorLayer*>& layers, const std::vector<LayerStyle>& styles,
                   bool overwrite) {
  init_gdal();
  detail::check_output(path, overwrite);
  const std::string ext = lower_extension(path);
  const bool geojson = ext == ".geojson" || ext == ".json";
  if (!geojson && ext != ".gpkg") throw bad_input(path + ": unknown vector format (use .geojson or .gpkg)");
  if (geojson && (layers.size() != 1 || !styles.empty())) throw processing_error(path + ": a GeoJSON file holds one layer and no style");
  GDALDriver* driver = GetGDALDriverManager()->GetDriverByName(geojson ? "GeoJSON" : "GPKG");
  // OGR's GeoJSON writer does not check its writes: build the file in memory, then write its bytes
  // with every write checked (a full disk fails the command instead of leaving a cut file).
  static std::atomic<int> serial{0};
  const std::string mem = "/vsimem/terrapolis-" + std::to_string(serial++) + ext;
  std::optional<detail::QuietGdal> quiet(std::in_place);
  // A GeoPackage records when each table changed (gpkg_contents.last_change): a fixed date, so
  // the same run gives the same bytes.
  CPLSetThreadLocalConfigOption("OGR_CURRENT_DATE", "2000-01-01T00:00:00.000Z");
  GDALDataset* ds = nullptr;
  auto fail = [&](const std::string& what) {
    const std::string msg = detail::last_gdal_error(what);
    if (ds) GDALClose(GDALDataset::ToHandle(ds));
    CPLSetThreadLocalConfigOption("OGR_CURRENT_DATE", nullptr);
    quiet.reset();
    VSIUnlink(mem.c_str());
    throw processing_error(path + ": cannot write output (" + msg + ")");
  };
  ds = driver->Create(mem.c_str(), 0, 0, 0, GDT_Unknown, nullptr);
  if (!ds) fail("create failed");
  if (!geojson) ds->StartTransaction();
  for (const VectorLayer* layer : layers) add_layer(ds, *layer, geojson, fail);
  if (!styles.empty()) add_styles(ds, styles, fail);
  if (!geojson && ds->CommitTransaction() != OGRERR_NONE) fail("commit failed");
  GDALClose(GDALDataset::ToHandle(ds));
  CPLSetThreadLocalConfigOption("OGR_CURRENT_DATE", nullptr);
  const bool closed = CPLGetLastErrorType() < CE_Failure;
  const std::string msg = detail::last_gdal_error("write failed");
  quiet.reset();
  vsi_l_offset size = 0;
  GByte* bytes = closed ? VSIGetMemFileBuffer(mem.c_str(), &size, FALSE) : nullptr;
  const std::string tmp = detail::temporary_name(path);
  const int error = bytes ? detail::write_bytes(tmp, bytes, std::size_t(size)) : 0;
  VSIUnlink(mem.c_str());
  if (!bytes || error) {
    detail::discard_file(tmp);
    throw detail::write_failure(path, error, bytes ? "" : msg);
  }
  detail::commit_file(tmp, path);
}

namespace {

using DatasetPtr = std::unique_ptr<GDALDataset, void (*)(GDALDataset*)>;

/// The vector file at `path`, read-only, with at least one layer; bad_input naming it otherwise.
DatasetPtr open_vector(const std::string& path) {
  init_gdal();
  std::error_code ec;
  if (!std::filesystem::exists(path, ec) && path.rfind("/vsi", 0) != 0) throw bad_input(path + ": no such file");
  DatasetPtr ds([&] {
    const detail::QuietGdal quiet;
    return GDALDataset::Open(path.c_str(), GDAL_OF_VECTOR | GDAL_OF_READONLY);
  }(), [](GDALDataset* d) { if (d) GDALClose(GDALDataset::ToHandle(d)); });
  if (!ds || ds->GetLayerCount() == 0) throw bad_input(path + ": not a vector layer GDAL can read");
  return ds;
}

}  // namespace

bool vector_has_crs(const std::string& path) { return open_vector(path)->GetLayer(0)->GetSpatialRef() != nullptr; }

VectorLayer read_vector(const std::string& path, const Crs& target) {
  const DatasetPtr ds = open_vector(path);
  OGRLayer* in = ds->GetLayer(0);
  VectorLayer layer;
  layer.name = in->GetName();
  layer.crs = target;
  OGRFeatureDefn* defn = in->GetLayerDefn();
  for (int i = 0; i < defn->GetFieldCount(); ++i) {
    const OGRFieldType t = defn->GetFieldDefn(i)->GetType();
    layer.fields.push_back({defn->GetFieldDefn(i)->GetNameRef(), t == OFTInteger || t == OFTInteger64 ? FieldType::integer
                                                                  : t == OFTReal                       ? FieldType::real
                                                                                                       : FieldType::string});
  }
  const OGRSpatialReference* src_srs = in->GetSpatialRef();
  OGRSpatialReference wgs;
  wgs.SetWellKnownGeogCS("WGS84");
  OGRSpatialReference from = src_srs ? *src_srs : wgs;  // GeoJSON without crs is WGS 84 (RFC 7946)
  from.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
  const OGRSpatialReference to = detail::to_ogr(target);
  std::unique_ptr<OGRCoordinateTransformation> ct(OGRCreateCoordinateTransformation(&from, &to));
  if (!ct) throw bad_input(path + ": cannot transform its CRS to the DEM's");
  bool type_set = false;
  in->ResetReading();
  for (auto& feature : *in) {
    OGRGeometry* g = feature->GetGeometryRef();
    if (!g) continue;
    std::unique_ptr<OGRGeometry> geometry(g->clone());
    if (geometry->transform(ct.get()) != OGRERR_NONE) throw bad_input(path + ": a feature cannot be transformed to the DEM's CRS");
    std::vector<FieldValue> values;
    for (int i = 0; i < defn->GetFieldCount(); ++i) {
      if (!feature->IsFieldSetAndNotNull(i)) values.emplace_back(std::monostate{});
      else if (layer.fields[i].type == FieldType::integer) values.emplace_back(std::int64_t(feature->GetFieldAsInteger64(i)));
      else if (layer.fields[i].type == FieldType::real) values.emplace_back(feature->GetFieldAsDouble(i));
      else values.emplace_back(std::string(feature->GetFieldAsString(i)));
    }
    std::vector<OGRGeometry*> singles;
    if (auto* collection = dynamic_cast<OGRGeometryCollection*>(geometry.get()))
      for (auto* part : *collection) singles.push_back(part);
    else singles.push_back(geometry.get());
    for (OGRGeometry* single : singles) {
      Feature f;
      f.values = values;
      const auto flat = wkbFlatten(single->getGeometryType());
      GeometryType t;
      if (flat == wkbPoint) {
        auto* p = single->toPoint();
        f.parts = {{{p->getX(), p->getY()}}};
        t = GeometryType::point;
      } else if (flat == wkbLineString) {
        std::vector<std::array<double, 2>> pts;
        for (const auto& p : *single->toLineString()) pts.push_back({p.getX(), p.getY()});
        f.parts = {pts};
        t = GeometryType::line_string;
      } else if (flat == wkbPolygon) {
        for (auto* ring : *single->toPolygon()) {
          std::vector<std::array<double, 2>> pts;
          for (const auto& p : *ring) pts.push_back({p.getX(), p.getY()});
          f.parts.push_back(pts);
        }
        t = GeometryType::polygon;
      } else {
        continue;
      }
      if (type_set && t != layer.geometry) throw bad_input(path + ": mixes geometry types");
      layer.geometry = t;
      type_set = true;
      layer.features.push_back(std::move(f));
    }
  }
  return layer;
}

}  // namespace terrapolis
