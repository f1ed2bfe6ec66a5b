// Unions of polygons (GEOS through GDAL/OGR), so that overlapping areas count once.
// SPDX-License-Identifier: MIT
#pragma once
#include <vector>

#include "core/polygon_area.hpp"

namespace terrapolis {

/// The union of `polygons` (each valid: a simple outer ring and holes inside it) as disjoint
/// polygons with holes, in the same coordinates (GEOS's cascaded union through OGR). Throws
/// processing_error when GDAL was built without GEOS.
std::vector<Polygon> polygon_union(const std::vector<Polygon>& polygons);

}  // namespace terrapolis
