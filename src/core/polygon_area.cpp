// Areas of polygons in a CRS (GeographicLib; Karney 2013).
// SPDX-License-Identifier: MIT
#include "core/polygon_area.hpp"

#include <GeographicLib/Geodesic.hpp>
#include <GeographicLib/PolygonArea.hpp>

#include <algorithm>
#include <cmath>

namespace terrapolis {

double polygon_area_m2(const Crs& crs, const std::vector<std::array<double, 2>>& ring) {
  if (ring.size() < 3) return 0;
  if (crs.geographic) {
    const GeographicLib::Geodesic geod(crs.ellipsoid.semi_major_m, crs.ellipsoid.flattening());
    GeographicLib::PolygonArea polygon(geod);
    for (const auto& v : ring) polygon.AddPoint(std::clamp(v[1], -90.0, 90.0), v[0]);
    double perimeter = 0, area = 0;
    polygon.Compute(false, true, perimeter, area);  // signed: a clockwise ring gives a negative area
    return std::abs(area);
  }
  double twice = 0;
  for (std::size_t i = 0, j = ring.size() - 1; i < ring.size(); j = i++) twice += ring[j][0] * ring[i][1] - ring[i][0] * ring[j][1];
  return 0.5 * std::abs(twice) * crs.linear_unit_m * crs.linear_unit_m;
}

double polygons_area_m2(const Crs& crs, const std::vector<Polygon>& polygons) {
  double area = 0;
  for (const Polygon& p : polygons)
    for (std::size_t i = 0; i < p.rings.size(); ++i) area += (i == 0 ? 1 : -1) * polygon_area_m2(crs, p.rings[i]);
  return area;
}

}  // namespace terrapolis
