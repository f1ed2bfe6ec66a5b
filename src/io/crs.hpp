// CRS parsing and coordinate transformations through PROJ (via GDAL/OGR).
// SPDX-License-Identifier: MIT
#pragma once
#include <array>
#include <memory>
#include <optional>
#include <string>

#include "core/raster.hpp"

namespace terrapolis {

/// A CRS from what a user types: "EPSG:4326", a WKT string, a PROJ string. Throws bad_input.
Crs crs_from_user(const std::string& definition);

/// WGS 84 longitude/latitude, longitude first.
Crs wgs84();

/// A CRS spelled every way a client without PROJ's database lookup may need (QGIS's
/// <spatialrefsys>): WKT (WKT1 when it can hold the CRS, else WKT2), PROJ string, and the
/// acronyms of its projection ("longlat", "utm") and ellipsoid ("EPSG:7030", else PROJ's name).
struct CrsDefinition {
  std::string wkt, proj4, description, projection_acronym, ellipsoid_acronym;
  std::optional<int> epsg;
  bool geographic = false;
};
CrsDefinition crs_definition(const Crs& crs);

/// Transforms coordinates from one CRS to another, longitude first for geographic CRSs.
class CrsTransform {
 public:
  CrsTransform(const Crs& from, const Crs& to);
  ~CrsTransform();
  CrsTransform(CrsTransform&&) noexcept;
  CrsTransform& operator=(CrsTransform&&) noexcept;
  /// Returns {x, y} in the target CRS; NaN if the point cannot be transformed.
  std::array<double, 2> operator()(double x, double y) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Pixel <-> CRS <-> WGS 84 lon/lat for one grid.
class GridLocator {
 public:
  explicit GridLocator(const Georef& georef);
  /// CRS coordinates of a pixel position (col,row as GDAL pixel/line, corners at integers).
  std::array<double, 2> pixel_to_crs(double col, double row) const;
  /// Pixel position (fractional) of CRS coordinates. Throws bad_input if the geotransform is singular.
  std::array<double, 2> crs_to_pixel(double x, double y) const;
  std::array<double, 2> crs_to_lonlat(double x, double y) const { return to_lonlat_(x, y); }
  std::array<double, 2> lonlat_to_crs(double lon, double lat) const { return from_lonlat_(lon, lat); }
  /// {lon, lat} of the centre of cell (col,row).
  std::array<double, 2> cell_lonlat(int col, int row) const;

 private:
  Georef georef_;
  CrsTransform to_lonlat_, from_lonlat_;
};

}  // namespace terrapolis
