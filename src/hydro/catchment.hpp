// Catchment of an outlet: snapping to the stream, upstream mask, polygon and area.
// SPDX-License-Identifier: MIT
#pragma once
#include <cstdint>
#include <utility>
#include <vector>

#include "core/geodesy.hpp"
#include "core/progress.hpp"
#include "core/raster.hpp"
#include "io/vector_io.hpp"

namespace terrapolis::hydro {

struct Catchment {
  int outlet_col = 0, outlet_row = 0;  ///< the snapped outlet cell
  double outlet_x = 0, outlet_y = 0;   ///< its centre in the DEM's CRS
  Raster<std::uint8_t> mask;           ///< 1 inside the catchment, 0 outside, 255 on nodata
  double area_km2 = 0;                 ///< geodesic area of the masked cells, km²
  std::size_t cells = 0;
  VectorLayer polygon;                 ///< one polygon (8-connected cells, holes kept), DEM CRS
};

/// Polygons (outer ring, then holes; DEM CRS; 8-connected) of the cells of `mask` equal to 1,
/// by GDALPolygonize. Fields are left empty. Also the lakes' shorelines.
std::vector<Feature> polygonize(const Raster<std::uint8_t>& mask);
/// Polygons of the regions of equal label (8-connected; labels < 0 are none), each with its label.
std::vector<std::pair<std::int32_t, Feature>> polygonize_labels(const Raster<std::int32_t>& labels);
/// The same of a raster file of labels (a VRT of tiles too), read by rows as GDALPolygonize goes,
/// placed on `grid`'s geotransform.
std::vector<std::pair<std::int32_t, Feature>> polygonize_labels(const std::string& path, const Georef& grid);

/// The cells whose D8 path passes through the outlet. The outlet (x, y) in the DEM's CRS is
/// snapped to the cell of highest upstream area whose centre lies within `snap_radius_m` metres
/// (geodesic on geographic CRSs) of it; radius 0 takes the cell containing the point.
/// Throws bad_input when the point is off the grid or on nodata with no valid cell in the radius.
/// The polygon comes from GDALPolygonize (8-connectedness) on the mask; fields `area_km2`,
/// `cells`, `outlet_x`, `outlet_y`.
/// Every valid cell labelled with its drainage basin: 1 + the rank, in row-major order, of the
/// outlet its D8 path ends at (a cell that keeps its water, or flows off the grid or onto
/// nodata); 0 on nodata. The `basins` output of `terrapolis hydro`; the tile engine gives the same
/// labels. Throws bad_input beyond 2^32 - 2 outlets.
Raster<std::uint32_t> drainage_basins(const Raster<std::uint8_t>& d8);

/// Gives every valid cell of `d8` whose label is 0 the label of the first labelled cell on its D8
/// path (the caller labels every cell where a path ends: outlets, and on tiles the cells that flow
/// into another tile).
void label_by_descent(const Raster<std::uint8_t>& d8, Raster<std::uint32_t>& labels);

Catchment delineate_catchment(const Raster<std::uint8_t>& d8, const Raster<double>& area_m2, const CellMetrics& metrics,
                              double x, double y, double snap_radius_m, Progress& progress);

}  // namespace terrapolis::hydro
