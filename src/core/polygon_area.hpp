// Areas of polygons in a CRS: geodesic on geographic CRSs, planar on projected ones.
// SPDX-License-Identifier: MIT
#pragma once
#include <array>
#include <vector>

#include "core/raster.hpp"

namespace terrapolis {

/// Area in m² of a simple polygon ring (vertices in the CRS of `crs`, any orientation, not closed):
/// geodesic on geographic CRSs (Karney 2013, GeographicLib's PolygonArea on the CRS's ellipsoid),
/// the shoelace formula times the linear unit squared on projected ones.
double polygon_area_m2(const Crs& crs, const std::vector<std::array<double, 2>>& ring);

using Ring = std::vector<std::array<double, 2>>;

/// A polygon: the outer ring first, then its holes (rings not closed, any orientation).
struct Polygon {
  std::vector<Ring> rings;
};

/// Area in m² of disjoint polygons: each outer ring's area less its holes'.
double polygons_area_m2(const Crs& crs, const std::vector<Polygon>& polygons);

}  // namespace terrapolis
