// The state the erosions share: heights in double, the loose layer, which cells may change, cell sizes (internal).
// SPDX-License-Identifier: MIT
#pragma once
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "core/geodesy.hpp"
#include "core/neighbours.hpp"
#include "erode/erosion.hpp"

namespace terrapolis::erode {

/// Excess heights and loose films thinner than this (m) are stable: the relaxation converges
/// geometrically, and heights are written as float32 (a step of 6e-5 m at 1000 m) anyway.
inline constexpr double stable_m = 1e-6;

/// Heights (m) and the domain: cells with data inside the mask. Cells outside the domain never
/// change; the processes treat them as outside the grid.
struct Domain {
  int cols = 0, rows = 0;
  std::vector<double> height;      ///< the surface, m, NaN outside the data
  /// Loose material on the bedrock, m >= 0 (the bedrock is height - loose); empty: one material that
  /// all moves (hydraulic, thermal), filled: only this layer slides (layered, Peytavie 2010 §2.3).
  std::vector<double> loose;
  std::vector<std::uint8_t> in;    ///< 1: may change
  const CellMetrics* metrics = nullptr;

  std::size_t index(int c, int r) const { return std::size_t(r) * std::size_t(cols) + std::size_t(c); }
  /// Cell (c, r) lies on the grid.
  bool on_grid(int c, int r) const { return c >= 0 && r >= 0 && c < cols && r < rows; }
  /// Neighbour k of (c, r) when it is inside the domain.
  bool inside(int c, int r, int k) const {
    const int cc = c + dcol[k], rr = r + drow[k];
    return on_grid(cc, rr) && in[index(cc, rr)];
  }
};

/// Runs body(r) for every row in parallel (each row writes only its own cells).
template <class Body>
void for_rows(int rows, Body&& body) {
  tbb::parallel_for(tbb::blocked_range<int>(0, rows), [&](const tbb::blocked_range<int>& range) {
    for (int r = range.begin(); r < range.end(); ++r) body(r);
  });
}

/// Runs body(r) for every row in parallel; the row's figures go to per_row[r] and are summed in
/// row order, so the total does not depend on the threads.
template <class Body>
double rows_sum(int rows, Body&& body) {
  std::vector<double> per_row(std::size_t(rows), 0.0);
  for_rows(rows, [&](int r) { per_row[std::size_t(r)] = body(r); });
  return std::accumulate(per_row.begin(), per_row.end(), 0.0);
}

/// Virtual-pipe hydraulic erosion (Mei, Decaudin & Hu 2007) on a Domain, one iteration per step().
class Hydraulic {
 public:
  Hydraulic(Domain& domain, const HydraulicOptions& options);
  /// One iteration: rain, pipe fluxes, water, velocity, transport, dissolution/deposition, evaporation.
  void step();
  /// Deposits the sediment still in suspension where it is (the end of the run).
  void settle();
  double sediment_out_m3 = 0;  ///< sediment that left the domain with the water, m³
  double water_out_m3 = 0;     ///< water that left the domain, m³

 private:
  double fluxes(int r);     // pass 1 of a row: rain, outflow per pipe scaled to the water, slope
  void transport(int r);    // pass 2 of a row: water, velocity, sediment, erosion, evaporation
  double sediment_in(int c, int r) const;  // m³ arriving from the neighbours' pipes

  Domain& d_;
  HydraulicOptions o_;
  std::vector<double> water_, rained_, sediment_, sediment_next_, sin_slope_;
  std::vector<std::array<double, 4>> flux_;  ///< outflow per pipe (east, south, west, north), m³/s
  std::vector<double> water_out_row_;
};

/// Thermal erosion to the angle of repose (Musgrave, Kolb & Mace 1989; Peytavie 2010 §2.3.4).
class Thermal {
 public:
  Thermal(Domain& domain, const ThermalOptions& options);
  /// One iteration; returns the volume moved, m³ (0: stable).
  double step();

 private:
  double outflows(int r);  // pass 1 of a row: the volume each cell sends to each lower neighbour
  void gather(int r);      // pass 2 of a row: heights from what left and what arrived

  Domain& d_;
  double rate_;
  std::vector<double> tan_, next_, next_loose_;
  std::vector<std::array<double, 8>> out_;  ///< m³ sent to neighbour k (neighbours.hpp order)
};

/// Global erosion of the bedrock (Peytavie 2010 §2.3.2): each cell's top rock voxel weathers by
/// eta <- eta - a(p) S(p) while it touches the air, and turns into loose material when eta reaches 0.
class GlobalErosion {
 public:
  /// Throws bad_input naming /erode/radius_m when the sphere spans more than max_reach cells.
  GlobalErosion(Domain& domain, const LayeredOptions& options);
  /// One iteration; returns the rock turned loose, m³.
  double step();
  static constexpr int max_reach = 25;  ///< cells from the centre the sphere may reach

 private:
  struct Chord {
    int dc, dr;
    double half_m, weight_m4;  ///< half the sphere's vertical chord above the column, m; x 2 x area
  };
  std::vector<Chord> sphere(int r) const;  // the columns within radius_m of a cell of row r
  double accessibility(int c, int r, const std::vector<Chord>& chords) const;
  double strength(double z) const;  // S(p) at height z, per iteration
  bool exposed(std::size_t i) const;
  double weather(int r);  // one row of step()

  Domain& d_;
  LayeredOptions o_;
  std::vector<double> eta_;  ///< erosion value of each cell's top rock voxel, 1: intact
  int reach_c_ = 0, reach_r_ = 0;
};

/// A thickness raster of a layered ground (m per cell: the loose layer, the rock broken off), checked
/// for the setting `pointer`: on the domain's grid, then each value used finite and >= 0.
inline void check_grid(const char* pointer, const Raster<float>& thickness, const Domain& d) {
  if (thickness.cols() != d.cols || thickness.rows() != d.rows) throw bad_input(std::string(pointer) + ": not on the DEM's grid");
}
inline double checked_thickness(const char* pointer, double t) {
  if (!(t >= 0 && std::isfinite(t))) throw bad_input(std::string(pointer) + ": thickness " + std::to_string(t) + " m is not a finite value >= 0");
  return t;
}

/// Local erosion (Peytavie 2010 §2.3.3): breaks `rockfall_m` (m per cell, on the grid) of rock off
/// into loose material inside the domain; returns the volume, m³. Throws bad_input on a value that is
/// negative or infinite.
double break_off(Domain& domain, const Raster<float>& rockfall_m);

}  // namespace terrapolis::erode
