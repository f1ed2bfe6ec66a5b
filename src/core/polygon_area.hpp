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

}  // namespace terrapolis
