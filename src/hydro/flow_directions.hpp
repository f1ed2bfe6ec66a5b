// Flow directions: D8 (with flat resolution), D-infinity (Tarboton 1997) and MFD (Freeman 1991).
// SPDX-License-Identifier: MIT
#pragma once
#include <array>
#include <cstdint>
#include <optional>
#include <string>

#include "core/geodesy.hpp"
#include "core/progress.hpp"
#include "core/raster.hpp"
#include "hydro/grid.hpp"

namespace terrapolis::hydro {

enum class FlowMethod {
  d8,    ///< single steepest-descent neighbour (O'Callaghan & Mark 1984)
  dinf,  ///< D-infinity: steepest facet, split between its two cells (Tarboton 1997, WRR 33(2))
  mfd,   ///< multiple flow directions, share ∝ tan(slope)^p (Freeman 1991, Quinn 1991, Holmgren 1994)
};

/// Code conventions of a D8 raster file.
enum class D8Codes {
  esri,    ///< powers of two: E=1 SE=2 S=4 SW=8 W=16 NW=32 N=64 NE=128; 0 = no outflow (pit, sea)
  grass,   ///< r.watershed: NE=1 N=2 NW=3 W=4 SW=5 S=6 SE=7 E=8; 0 = no outflow
  taudem,  ///< TauDEM: E=1 NE=2 N=3 NW=4 W=5 SW=6 S=7 SE=8; 0 = no outflow
};

/// D8 receivers of a conditioned DEM, as neighbours.hpp indices 0..7, kTerminal (keeps its water:
/// sea cell, unfilled pit or undrainable flat) or kNoData.
/// Slopes are drops over geodesic centre distances (CellMetrics::step_m); ties go to the lowest k.
/// Cells on the border or next to nodata with no lower valid neighbour flow out of the grid (their
/// code points to the first outside neighbour). Flats get directions from `drain_flats`
/// (Barnes et al. 2014). Parallel over rows, deterministic.
Raster<std::uint8_t> d8_directions(const Dem& filled, const CellMetrics& metrics, const std::optional<double>& sea_level,
                                   Progress& progress);

/// The first-pass D8 code of cell (col,row) of `filled`: the steepest strictly lower neighbour,
/// kTerminal on sea, kNoData, the first outside neighbour for outlets without a lower one, or
/// kNoFlow (flats, for drain_flats). `step` holds CellMetrics::step_m of the cell's row for k = 0..7.
/// d8_directions applies it to every cell; the tile engine to tiles with a halo.
std::uint8_t d8_first_pass(const Dem& filled, const double* step, const std::optional<double>& sea_level, int col, int row);

/// File codes of `d8` in `convention` (uint8, nodata 255).
Raster<std::uint8_t> encode_d8(const Raster<std::uint8_t>& d8, D8Codes convention);
/// The file code of neighbour k (neighbours.hpp order: 0 = E, then clockwise) in a convention.
std::uint8_t d8_code(int k, D8Codes convention);
/// Inverse of encode_d8 (for reading rasters written by other tools); throws bad_input on a bad code.
Raster<std::uint8_t> decode_d8(const Raster<std::uint8_t>& codes, D8Codes convention);
/// One-line statement of a convention, stored in the flowdir file's metadata.
std::string describe(D8Codes convention);

/// How one cell passes its water on: up to 8 receivers (neighbour index) with fractions summing to 1.
/// A receiver may lie outside the grid or on nodata: that share leaves the DEM (an outlet).
struct FlowSplit {
  int count = 0;
  std::array<std::uint8_t, 8> k{};
  std::array<double, 8> fraction{};
};

/// Routes water for D8, D-infinity or MFD. Cells without a downslope neighbour (flats, outlets)
/// follow their D8 receiver, so flats resolved for D8 drain for every method.
class FlowRouter {
 public:
  /// `mfd_exponent` p > 0: Freeman 1991 uses 1.1; Holmgren 1994 suggests 4..6 (more convergent).
  FlowRouter(const Dem& filled, const Raster<std::uint8_t>& d8, const CellMetrics& metrics, FlowMethod method,
             double mfd_exponent = 1.1);
  /// The split of cell (col,row); count 0 for terminal and nodata cells.
  void split(int col, int row, FlowSplit& out) const;
  /// Bit k set when neighbour k receives water from (col,row) and lies inside the grid on valid data.
  std::uint8_t inner_receivers(int col, int row) const;
  FlowMethod method() const { return method_; }
  const Raster<std::uint8_t>& d8() const { return d8_; }

 private:
  const Dem& z_;
  const Raster<std::uint8_t>& d8_;
  const CellMetrics& metrics_;
  FlowMethod method_;
  double exponent_;
};

}  // namespace terrapolis::hydro
