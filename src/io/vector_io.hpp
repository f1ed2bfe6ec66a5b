// Vector layers: GeoJSON (RFC 7946) or GeoPackage through GDAL/OGR, chosen by the file's extension.
// SPDX-License-Identifier: MIT
#pragma once
#include <array>
#include <cstdint>
#include <string>
#include <variant>
#include <vector>

#include "core/raster.hpp"

namespace terrapolis {

enum class GeometryType { point, line_string, polygon };
enum class FieldType { integer, real, string };

struct FieldDef {
  std::string name;
  FieldType type;
};

/// A field value; monostate writes a null.
using FieldValue = std::variant<std::monostate, std::int64_t, double, std::string>;

/// One feature. Geometry in the layer's CRS: a point is parts[0][0], a line string parts[0],
/// a polygon's rings are parts (outer ring first, any orientation: writers fix it).
struct Feature {
  std::vector<std::vector<std::array<double, 2>>> parts;
  std::vector<FieldValue> values;  ///< one per field of the layer, in order
};

struct VectorLayer {
  std::string name;
  GeometryType geometry = GeometryType::point;
  Crs crs;  ///< CRS of the coordinates in `features`
  std::vector<FieldDef> fields;
  std::vector<Feature> features;

  /// Index of a field by name, or -1.
  int field_index(const std::string& field) const;
};

/// Writes `layer` to `path`: ".geojson"/".json" as RFC 7946 GeoJSON (reprojected to WGS 84 lon/lat,
/// right-hand rule, no crs member), ".gpkg" as GeoPackage in the layer's CRS. Temporary name, then rename.
void write_vector(const std::string& path, const VectorLayer& layer, bool overwrite = false);

/// A QGIS style for one layer of a GeoPackage (its layer_styles table).
struct LayerStyle {
  std::string layer;        ///< the layer's name
  std::string qml;          ///< the whole .qml document
  std::string description;
};

/// Writes several layers into one GeoPackage (".gpkg", each in its CRS), with `styles` in its
/// layer_styles table as each layer's default QGIS style; a ".geojson" path takes one layer and no
/// style. Temporary name, then rename; the same layers give the same bytes.
void write_vectors(const std::string& path, const std::vector<const VectorLayer*>& layers, const std::vector<LayerStyle>& styles,
                   bool overwrite = false);

/// Reads the first layer of any OGR vector file with its coordinates transformed to `target`.
/// Multi-geometries are split into single features (attributes repeated).
VectorLayer read_vector(const std::string& path, const Crs& target);

/// Whether the first layer of a vector file declares its CRS (GeoJSON always does: RFC 7946 makes
/// it WGS 84). Throws bad_input when the file cannot be read.
bool vector_has_crs(const std::string& path);

}  // namespace terrapolis
