// Belhadj's iterative rain-diffusion hydrometry (thesis, Paris 8, 2007, §4.2.2, Algorithm 12).
// SPDX-License-Identifier: MIT
#pragma once
#include <array>
#include <optional>
#include <vector>

#include "core/geodesy.hpp"
#include "core/progress.hpp"
#include "core/raster.hpp"
#include "hydro/grid.hpp"

namespace terrapolis::hydro {

/// Vertical unit of the vectors V_i = (dx, dy, dz) of Algorithm 12.
enum class VerticalScale {
  /// dx, dy and dz all in metres (geodesic cell steps on geographic CRSs): slopes are real.
  metres,
  /// The thesis: the 16-bit altitude (metres in its NGDC data) divided by 2^16-1, dx, dy in
  /// cells (1 or -1): the vertical is tiny against the horizontal. Outside cells are at -1.
  normalised16,
};

/// What Σn, the denominator of each neighbour's share, sums over.
enum class BelhadjShare {
  /// Algorithm 12 as printed: all 8 neighbours, fed or not, so the shares of the neighbours that
  /// get nothing (R_i . V_i <= 0, or outside the grid) are lost. Converges geometrically.
  all_neighbours,
  /// Only the neighbours with R_i . V_i > 0 (outside cells included: their share leaves the
  /// grid): water is conserved except what leaves through outlets, so it gathers in valleys and
  /// between obstacles (as the thesis's Fig. 4.1 shows) and converges when it has run off.
  fed_neighbours,
};

/// The state of the diffusion on a grid padded with a one-cell halo of "outside" cells
/// (beyond the border, on nodata, at or below sea level), which get an altitude far below every
/// cell and never receive water. Kept public so tests can check a single iteration by hand.
class BelhadjModel {
 public:
  /// Initial state: F = (0, 0, -1) (a falling drop: straight down), Q = 1, Acc = 0 on every valid cell.
  /// `land_range`: the lowest and highest land altitude of the whole grid when `dem` is a window of
  /// it (the outside altitude follows them); unset, `dem`'s own.
  BelhadjModel(const Dem& dem, const CellMetrics& metrics, VerticalScale vertical, std::optional<double> sea_level,
               BelhadjShare share = BelhadjShare::all_neighbours, std::optional<std::array<double, 2>> land_range = std::nullopt);
  BelhadjModel(const BelhadjModel&) = delete;  // the array pointers point into the model's own block
  BelhadjModel& operator=(const BelhadjModel&) = delete;

  /// One iteration of Algorithm 12, simultaneously for all cells (double buffer): each valid cell c
  /// sends R_i = F(c) + V_i(c) and the share |R_i| Q(c) / Σ_j |R_j| of its water to every inside
  /// neighbour i with R_i . V_i(c) > 0 (Σ over all 8 neighbours, or the fed ones); Acc += Q.
  /// Outside cells send nothing. Returns the mean Q over valid cells before the step (the
  /// thesis's stop test). Computed as a gather in two passes per row band (what each cell sends,
  /// then what each cell pulls from its 8 neighbours, summed in neighbour order k = 0..7 of
  /// core/neighbours.hpp): bit-identical for any thread count.
  double step();

  int cols() const { return cols_; }
  int rows() const { return rows_; }
  /// State of cell (col,row) of the DEM grid.
  double q(int col, int row) const { return q_[at(col, row)]; }
  double acc(int col, int row) const { return acc_[at(col, row)]; }
  std::array<double, 3> flow(int col, int row) const {
    const std::size_t i = at(col, row);
    return {fx_[i], fy_[i], fz_[i]};
  }
  /// Altitude used for the outside cells (normalised16: -1; metres: min - (max - min), at least 1 m below).
  double outside_altitude() const { return z_out_; }
  /// Horizontal part (dx east, dy south) of V_i for a cell of DEM row `row` and neighbour k.
  std::array<double, 2> step_vector(int row, int k) const {
    const std::size_t i = std::size_t(row + 1) * 8 + std::size_t(k);
    return {hx_[i], hy_[i]};
  }
  bool valid(int col, int row) const { return z_[at(col, row)] > z_out_; }

 private:
  std::size_t at(int col, int row) const { return std::size_t(row + 1) * std::size_t(stride_) + std::size_t(col + 1); }
  int cols_, rows_, stride_;
  BelhadjShare share_;
  std::size_t valid_count_ = 0;
  double z_out_ = -1;
  // The ten padded per-cell arrays share one block: one allocation, a few huge pages instead of
  // thousands of page faults (on the thesis's 256 x 256 case, setting up cost as much as 10 steps).
  BigVector<double> block_;
  double* z_;                          // padded altitude, z_out_ outside
  double *fx_, *fy_, *fz_, *q_, *acc_;  // current state
  double *fx2_, *fy2_, *fz2_, *q2_;     // next state
  std::vector<double> hx_, hy_;        // per padded row, 8 horizontal steps (east, south)
  std::vector<double> row_sum_;
};

struct BelhadjOptions {
  int max_iterations = 0;                ///< 0: until convergence (with a safety cap of 160)
  double threshold = 1.0 / 1048576;      ///< stop when the mean quantity is below this (2^-20)
  VerticalScale vertical = VerticalScale::metres;
  std::optional<double> sea_level;       ///< cells at or below are outside (outlets)
  BelhadjShare share = BelhadjShare::all_neighbours;
};

struct BelhadjRun {
  Raster<float> hydrometry;  ///< Acc rescaled to [0,1] over valid cells; NaN on nodata, 0 on sea
  int iterations = 0;        ///< iterations done
  double final_mean = 0;     ///< mean quantity at the last iteration
};

/// The iterations the diffusion may run: max_iterations, or the safety cap of 160.
int belhadj_iteration_limit(const BelhadjOptions& options);
/// Whether the diffusion stops after iteration `iteration` (1-based), whose step began at this mean quantity.
inline bool belhadj_stops(const BelhadjOptions& options, int iteration, double mean) {
  return mean < options.threshold || iteration >= belhadj_iteration_limit(options);
}
/// Lowest and highest land altitude (not nodata, above the sea level) of `dem`: +inf, -inf without land.
std::array<double, 2> belhadj_land_range(const Dem& dem, std::optional<double> sea_level);
/// The hydrometry of a cell from its Acc, rescaled by the lowest and highest Acc of the grid's valid cells.
inline float belhadj_rescale(double acc, double lo, double hi) { return float((acc - lo) / (hi > lo ? hi - lo : 1.0)); }

/// Runs the diffusion until the mean quantity drops below `threshold` or `max_iterations`.
/// The cap of 160 iterations keeps the flow vectors finite (|F| can grow 8-fold per iteration on a
/// flat, and |F|^2 must stay below 1.8e308: 8^340 would not); the thesis's cases converge in 20 to 51 iterations.
BelhadjRun belhadj_hydrometry(const Dem& dem, const CellMetrics& metrics, const BelhadjOptions& options,
                              Progress& progress);

}  // namespace terrapolis::hydro
