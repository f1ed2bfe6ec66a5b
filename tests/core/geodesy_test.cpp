// Cell metrics against GeographicLib's own geodesics and an independent area integral.
// SPDX-License-Identifier: MIT
#include <gtest/gtest.h>

#include <GeographicLib/Geodesic.hpp>

#include <cmath>

#include "core/geodesy.hpp"
#include "core/neighbours.hpp"

using namespace terrapolis;

namespace {

Georef geographic(double west, double north, double step_deg, Ellipsoid e = {}) {
  Georef g;
  g.transform = {west, step_deg, 0, north, 0, -step_deg};
  g.crs.geographic = true;
  g.crs.ellipsoid = e;
  return g;
}

/// Area of the lat/lon quadrangle by Simpson integration of M(phi) N(phi) cos(phi) dphi dlambda.
double quadrangle_area(const Ellipsoid& e, double lat1, double lat2, double dlon_deg) {
  const double a = e.semi_major_m, f = e.flattening(), e2 = f * (2 - f);
  const int n = 2000;
  const double h = (lat2 - lat1) * M_PI / 180.0 / n;
  double s = 0;
  for (int i = 0; i <= n; ++i) {
    const double phi = lat1 * M_PI / 180.0 + i * h;
    const double w = 1 - e2 * std::sin(phi) * std::sin(phi);
    const double m = a * (1 - e2) / std::pow(w, 1.5), nn = a / std::sqrt(w);
    const double v = m * nn * std::cos(phi);
    s += (i == 0 || i == n) ? v : (i % 2 ? 4 * v : 2 * v);
  }
  return s * h / 3.0 * dlon_deg * M_PI / 180.0;
}

}  // namespace

TEST(Geodesy, OneArcSecondAt45North) {
  const double sec = 1.0 / 3600.0;
  // Three rows centred on 45 N.
  const CellMetrics m = cell_metrics(geographic(10.0, 45.0 + 1.5 * sec, sec), 3, 3);
  const GeographicLib::Geodesic& wgs = GeographicLib::Geodesic::WGS84();
  double ew, ns, diag;
  wgs.Inverse(45.0, 10.0, 45.0, 10.0 + sec, ew);
  wgs.Inverse(45.0 + sec, 10.0, 45.0, 10.0, ns);
  wgs.Inverse(45.0 + sec, 10.0, 45.0, 10.0 + sec, diag);
  EXPECT_NEAR(m.width_m[1], ew, 1e-3);
  EXPECT_NEAR(m.height_m[1], ns, 1e-3);
  EXPECT_NEAR(m.diagonal_m[1], diag, 1e-3);
  EXPECT_NEAR(m.width_m[1], 21.9, 0.05);   // the textbook figures
  EXPECT_NEAR(m.height_m[1], 30.9, 0.05);
  // step_m picks the right boundary for northward and southward steps.
  EXPECT_DOUBLE_EQ(m.step_m(1, 6), m.height_m[1]);
  EXPECT_DOUBLE_EQ(m.step_m(1, 2), m.height_m[2]);
  EXPECT_DOUBLE_EQ(m.step_m(1, 1), m.diagonal_m[2]);
  EXPECT_DOUBLE_EQ(m.step_m(1, 7), m.diagonal_m[1]);
  EXPECT_DOUBLE_EQ(m.step_m(1, 0), m.width_m[1]);
}

TEST(Geodesy, CellsNarrowTowardsThePole) {
  const CellMetrics m = cell_metrics(geographic(0, 80, 1.0), 1, 80);
  for (int r = 1; r < 80; ++r) EXPECT_GT(m.width_m[r], m.width_m[r - 1]);
}

TEST(Geodesy, TileAreaIsTheEllipsoidalQuadrangle) {
  // A whole 1 x 1 degree tile at 47-48 N in 3600 x 3600 cells (SRTM 1" spacing, cell edges on the tile).
  const int n = 3600;
  const Georef g = geographic(9.0, 48.0, 1.0 / n);
  const CellMetrics m = cell_metrics(g, n, n);
  EXPECT_NEAR(m.total_area_m2(n) / quadrangle_area(Ellipsoid{}, 47.0, 48.0, 1.0), 1.0, 1e-9);
  // GRS 80 differs from WGS 84 only in the flattening's ninth digit; a sphere differs a lot.
  const Ellipsoid sphere{6371000.0, 0.0};
  const CellMetrics s = cell_metrics(geographic(9.0, 48.0, 1.0 / n, sphere), n, n);
  EXPECT_NEAR(s.total_area_m2(n) / quadrangle_area(sphere, 47.0, 48.0, 1.0), 1.0, 1e-9);
  EXPECT_GT(std::abs(s.total_area_m2(n) / m.total_area_m2(n) - 1.0), 1e-3);
}

TEST(Geodesy, ProjectedCellsUseTheLinearUnit) {
  Georef g;
  g.transform = {500000, 30, 0, 4000000, 0, -30};
  const CellMetrics m = cell_metrics(g, 10, 10);
  EXPECT_DOUBLE_EQ(m.width_m[3], 30.0);
  EXPECT_DOUBLE_EQ(m.height_m[3], 30.0);
  EXPECT_NEAR(m.diagonal_m[3], 30.0 * std::sqrt(2.0), 1e-9);
  EXPECT_DOUBLE_EQ(m.area_m2[3], 900.0);
  g.crs.linear_unit_m = 0.3048;  // a grid in feet
  EXPECT_NEAR(cell_metrics(g, 10, 10).width_m[0], 9.144, 1e-9);
}

TEST(Geodesy, DistancesAndDestinationsAgree) {
  const Ellipsoid wgs{};
  const double d = geodesic_distance_m(wgs, 2.35, 48.85, -0.13, 51.51);  // Paris - London
  EXPECT_NEAR(d, 344.8e3, 0.5e3);
  const auto p = geodesic_destination(wgs, 2.35, 48.85, 45.0, 10000.0);
  EXPECT_NEAR(geodesic_distance_m(wgs, 2.35, 48.85, p[0], p[1]), 10000.0, 1e-6);
  Crs utm;
  EXPECT_DOUBLE_EQ(crs_distance_m(utm, 0, 0, 3, 4), 5.0);
}
