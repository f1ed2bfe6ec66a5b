// Cell sizes in metres from the georeferencing, and geodesic distances on the CRS's ellipsoid.
// SPDX-License-Identifier: MIT
#pragma once
#include <vector>

#include "core/raster.hpp"

namespace terrapolis {

/// Per-row cell metrics in metres (all values are > 0 and finite).
///
/// On a geographic CRS they are geodesics on the CRS's own ellipsoid (Karney 2013, "Algorithms
/// for geodesics", through GeographicLib; error well below 1 mm), so a cell narrows towards the
/// poles; on a projected CRS they are the grid steps in the CRS's linear unit converted to metres
/// (map metres, not corrected for the projection's scale factor).
struct CellMetrics {
  /// width_m[r]: distance between the centres of two east-west neighbours in row r.
  std::vector<double> width_m;
  /// area_m2[r]: area of one cell of row r (exact ellipsoidal area of the cell's quadrangle).
  std::vector<double> area_m2;
  /// height_m[r]: distance between the centres of (c, r-1) and (c, r), r in 0..rows
  /// (rows -1 and `rows` are the virtual rows just outside the grid).
  std::vector<double> height_m;
  /// diagonal_m[r]: distance between the centres of (c, r-1) and (c+1, r), r in 0..rows.
  std::vector<double> diagonal_m;

  /// Distance in metres from the centre of a cell of row `row` to its neighbour k (neighbours.hpp order).
  double step_m(int row, int k) const {
    static constexpr int kind[8] = {0, 1, 2, 1, 0, 1, 2, 1};  // 0 east-west, 1 diagonal, 2 north-south
    const int dr = (k == 1 || k == 2 || k == 3) ? 1 : (k >= 5 ? -1 : 0);
    const int boundary = dr > 0 ? row + 1 : row;  // the row boundary the step crosses
    switch (kind[k]) {
      case 0: return width_m[row];
      case 2: return height_m[boundary];
      default: return diagonal_m[boundary];
    }
  }
  /// Sum of all cell areas, m².
  double total_area_m2(int cols) const;
};

/// Computes the metrics of a `cols` x `rows` grid. Throws bad_input for a rotated geographic grid.
CellMetrics cell_metrics(const Georef& georef, int cols, int rows);

/// The rows [row0, row0 + rows) of a grid's metrics (height_m and diagonal_m: one more), for a
/// window that must step and weigh its cells exactly as the whole grid does (a window's own
/// cell_metrics may differ in the last bit: its origin is computed, not read).
CellMetrics metric_rows(const CellMetrics& metrics, int row0, int rows);

/// Geodesic distance in metres between two points given in degrees, on `ellipsoid`.
double geodesic_distance_m(const Ellipsoid& ellipsoid, double lon1, double lat1, double lon2, double lat2);

/// Distance in metres between two points in the CRS of `georef` (geodesic on geographic CRSs,
/// Euclidean times the linear unit on projected ones).
double crs_distance_m(const Crs& crs, double x1, double y1, double x2, double y2);

/// Destination of a geodesic from (lon,lat) with azimuth `azimuth_deg` (clockwise from north)
/// over `distance_m`; returns {lon, lat} in degrees.
std::array<double, 2> geodesic_destination(const Ellipsoid& ellipsoid, double lon, double lat, double azimuth_deg,
                                           double distance_m);

}  // namespace terrapolis
