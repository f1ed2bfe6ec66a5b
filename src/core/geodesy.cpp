// Cell metrics and geodesics (GeographicLib; Karney 2013).
// SPDX-License-Identifier: MIT
#include "core/geodesy.hpp"

#include <GeographicLib/Ellipsoid.hpp>
#include <GeographicLib/Geodesic.hpp>

#include <algorithm>
#include <cmath>

#include "core/error.hpp"

namespace terrapolis {
namespace {

double clamp_lat(double lat) { return std::clamp(lat, -90.0, 90.0); }

CellMetrics geographic_metrics(const Georef& g, int rows) {
  const auto& t = g.transform;
  if (t[2] != 0.0 || t[4] != 0.0) throw bad_input("rotated geographic grids are not supported (geotransform has rotation terms)");
  const GeographicLib::Geodesic geod(g.crs.ellipsoid.semi_major_m, g.crs.ellipsoid.flattening());
  const GeographicLib::Ellipsoid ell(g.crs.ellipsoid.semi_major_m, g.crs.ellipsoid.flattening());
  const double dlon = std::abs(t[1]);
  const double dlat = t[5];  // usually negative: row 0 is north
  const auto centre_lat = [&](int r) { return clamp_lat(t[3] + (r + 0.5) * dlat); };

  CellMetrics m;
  m.width_m.resize(rows);
  m.area_m2.resize(rows);
  m.height_m.resize(rows + 1);
  m.diagonal_m.resize(rows + 1);
  // Area of the band between two parallels, per degree of longitude, from the authalic latitude.
  const double band_per_degree = ell.Area() / 720.0;
  for (int r = 0; r < rows; ++r) {
    double s12;
    geod.Inverse(centre_lat(r), 0.0, centre_lat(r), dlon, s12);
    m.width_m[r] = s12;
    const double lat_top = clamp_lat(t[3] + r * dlat), lat_bottom = clamp_lat(t[3] + (r + 1) * dlat);
    const double xi1 = ell.AuthalicLatitude(lat_top) * M_PI / 180.0, xi2 = ell.AuthalicLatitude(lat_bottom) * M_PI / 180.0;
    m.area_m2[r] = band_per_degree * std::abs(std::sin(xi1) - std::sin(xi2)) * dlon;
  }
  for (int r = 0; r <= rows; ++r) {
    const double la = clamp_lat(t[3] + (r - 0.5) * dlat), lb = centre_lat(r);
    double s12;
    geod.Inverse(la, 0.0, lb, 0.0, s12);
    m.height_m[r] = s12;
    geod.Inverse(la, 0.0, lb, dlon, s12);
    m.diagonal_m[r] = s12;
  }
  return m;
}

CellMetrics projected_metrics(const Georef& g, int rows) {
  const auto& t = g.transform;
  const double u = g.crs.linear_unit_m;
  const double w = std::hypot(t[1], t[4]) * u, h = std::hypot(t[2], t[5]) * u;
  CellMetrics m;
  m.width_m.assign(rows, w);
  m.area_m2.assign(rows, std::abs(t[1] * t[5] - t[2] * t[4]) * u * u);
  m.height_m.assign(rows + 1, h);
  m.diagonal_m.assign(rows + 1, std::hypot((t[1] + t[2]) * u, (t[4] + t[5]) * u));
  return m;
}

}  // namespace

CellMetrics metric_rows(const CellMetrics& m, int row0, int rows) {
  auto part = [&](const std::vector<double>& v, int n) { return std::vector<double>(v.begin() + row0, v.begin() + row0 + n); };
  CellMetrics out;
  out.width_m = part(m.width_m, rows);
  out.area_m2 = part(m.area_m2, rows);
  out.height_m = part(m.height_m, rows + 1);
  out.diagonal_m = part(m.diagonal_m, rows + 1);
  return out;
}

double CellMetrics::total_area_m2(int cols) const {
  double s = 0;
  for (double a : area_m2) s += a;
  return s * cols;
}

CellMetrics cell_metrics(const Georef& georef, int /*cols*/, int rows) {
  CellMetrics m = georef.crs.geographic ? geographic_metrics(georef, rows) : projected_metrics(georef, rows);
  // Every stage divides by these: a zero, NaN or infinite cell (a geotransform that slipped past the
  // reader, e.g. a grid built in code) is refused here rather than turned into a huge disc or loop.
  const auto bad = [](double v) { return !std::isfinite(v) || v <= 0; };
  if (std::any_of(m.width_m.begin(), m.width_m.end(), bad) || std::any_of(m.height_m.begin(), m.height_m.end(), bad) ||
      std::any_of(m.area_m2.begin(), m.area_m2.end(), bad))
    throw bad_input("the grid's geotransform gives a zero, negative or non-finite cell size");
  return m;
}

double geodesic_distance_m(const Ellipsoid& e, double lon1, double lat1, double lon2, double lat2) {
  const GeographicLib::Geodesic geod(e.semi_major_m, e.flattening());
  double s12;
  geod.Inverse(lat1, lon1, lat2, lon2, s12);
  return s12;
}

double crs_distance_m(const Crs& crs, double x1, double y1, double x2, double y2) {
  if (crs.geographic) return geodesic_distance_m(crs.ellipsoid, x1, y1, x2, y2);
  return std::hypot(x2 - x1, y2 - y1) * crs.linear_unit_m;
}

std::array<double, 2> geodesic_destination(const Ellipsoid& e, double lon, double lat, double azimuth_deg,
                                           double distance_m) {
  const GeographicLib::Geodesic geod(e.semi_major_m, e.flattening());
  double lat2, lon2;
  geod.Direct(lat, lon, azimuth_deg, distance_m, lat2, lon2);
  return {lon2, lat2};
}

}  // namespace terrapolis
