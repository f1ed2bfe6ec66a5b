// Constrained midpoint displacement (Triangle-Edge, Diamond-Square) and Belhadj's DMMC on any grid size.
// SPDX-License-Identifier: MIT
#pragma once
#include <cstdint>
#include <functional>
#include <vector>

#include "core/progress.hpp"
#include "core/raster.hpp"

namespace terrapolis::terrain {

/// What a cell is during subdivision (Belhadj 2007 §1.1.1: every cell has a state and an altitude).
enum class CellState : std::uint8_t {
  unknown = 0,      ///< to be computed
  known = 1,        ///< computed (by the bottom-up pass or earlier in the top-down pass); never recomputed
  constrained = 2,  ///< given by the caller; kept exactly, never smoothed
};

/// The subdivision scheme (Miller 1986; Belhadj 2007 §1.1, fig. 1.1).
enum class Subdivision {
  triangle_edge,  ///< edge midpoints from the 2 edge ends, centres from the 4 corners (bilinear when s = 0)
  diamond_square, ///< edge midpoints from the 2 edge ends and the 2 neighbouring square centres
};

/// Parameters of the top-down pass. Displacement of a cell created at recursion level r (the root
/// rectangle is level 0): delta = (X + t) * scale_m * 2^(-r * dimension * hurst), X uniform in [-1,1]
/// from a hash of (seed, col, row) (Belhadj eq. 1.1 and footnote 2 of §1.1.1).
struct MidpointParams {
  Subdivision subdivision = Subdivision::triangle_edge;
  double scale_m = 0.0;     ///< S of eq. 1.1 in metres (S = dim(a) * s); 0: pure interpolation, no noise
  double t = 0.0;           ///< translation of X (eq. 1.1), in [-1,1]
  double hurst = 0.5;       ///< H of eq. 1.1, in (0,1]; fractal dimension 3 - H
  double dimension = 2.0;   ///< D of eq. 1.1: topological dimension of the surface (2, as eq. 1.2's n = 2)
  double shape = 0.0;       ///< I of eq. 3.4: shapes the interpolated mean with distance; 0 keeps the mean
  std::uint64_t seed = 1;   ///< seed of the position hash
};

/// How the bottom-up pass extrapolates an unknown parent from its known children.
enum class BottomUpRule {
  /// Belhadj Alg. 11 (DMMC, §3.2.3): a = Σ w f_-1(a_e, d) / Σ w, w = d (or 1/d), no noise. The default.
  weighted,
  /// Belhadj Alg. 10 (§3.1.1.3) as printed: the plain mean of the known children plus a noise that
  /// grows with their mean distance, a = Σ a_e / n + (Σ d / n) s X. No shaping (f_-1 is Alg. 11's).
  mean,
};

/// Which way a cell extrapolates its parents in the bottom-up pass (Belhadj §5.1.1: sketch cells
/// labelled *rivière* extrapolate up, *crête* cells down, eq. 3.5 with I_-1 < 0 or > 0).
enum class ExtrapolationLabel : std::uint8_t {
  global = 0,  ///< BottomUpParams::shape as given
  river = 1,   ///< I_-1 = -|shape|: the parents rise above the cell (a valley floor)
  ridge = 2,   ///< I_-1 = +|shape|: the parents fall below the cell (a crest)
};

/// Parameters of the bottom-up pass (Belhadj Alg. 10 or 11, eq. 3.5).
struct BottomUpParams {
  BottomUpRule rule = BottomUpRule::weighted;
  double shape = 0.0;  ///< weighted: I_-1 of eq. 3.5, shapes each child's contribution with distance; 0 keeps it
  /// weighted: Alg. 11 weights each child by its distance d to the parent (a += d f(a_e, d); D += d).
  /// true keeps that; false weights by 1/d (a variant we measured, see docs/terrain.md).
  bool weight_by_distance = true;
  /// mean: s of Alg. 10's noise term, in metres per cell of mean child-to-parent distance (>= 0;
  /// 0: the plain mean). The thesis's s is eq. 1.1's unitless factor of S = dim(T.a) s, so with S
  /// in metres it is S / kThesisAltitudeRange (see thesis_noise_per_cell_m).
  double noise_m_per_cell = 0.0;
};

/// dim(T.a) of eq. 1.1: the range of the thesis's 16-bit signed altitudes (§1.1.1, note 1).
inline constexpr double kThesisAltitudeRange = 65536.0;

/// Alg. 10's s for a top-down scale S (`scale_m`, metres): s = S / dim(T.a), one altitude unit
/// taken as one metre as for S; one cell of mean distance adds at most S / 65536 metres of noise.
inline double thesis_noise_per_cell_m(double scale_m) { return scale_m / kThesisAltitudeRange; }

/// A grid being subdivided: altitudes (metres) and states, row-major, row 0 north.
struct SubdivisionGrid {
  int cols = 0, rows = 0;
  std::vector<float> z;            ///< metres; meaningless where state is unknown
  std::vector<CellState> state;
  /// Per cell, for the weighted bottom-up rule; empty: every cell follows BottomUpParams::shape.
  /// bottom_up gives a parent its children's label when they all share it, else global.
  std::vector<ExtrapolationLabel> label;
  /// A grid from a raster: finite cells become constrained, NaN cells unknown.
  static SubdivisionGrid from_raster(const Raster<float>& raster);
};

/// The subdivision tree of one grid, simulated in O(1) per cell (Belhadj's simu_dm, §3.1.1.3):
/// each axis 0..n-1 is split recursively at integer midpoints, so any size works.
class SubdivisionTree {
 public:
  SubdivisionTree(int cols, int rows);
  /// Recursion level at which (col,row) is created: 0 for the four corners.
  int level(int col, int row) const;
  int levels() const { return levels_; }
  /// The 2, 3 or 4 parents of (col,row) in `scheme` with their interpolation weights (summing to 1);
  /// returns their count (0 for the corners).
  int parents(Subdivision scheme, int col, int row, int (&pc)[4], int (&pr)[4], double (&w)[4]) const;

  struct Axis {
    std::vector<int> depth, lo, hi;            ///< per coordinate: creation level and parent interval
    std::vector<std::vector<int>> created;     ///< per level: coordinates created at that level
    std::vector<std::vector<int>> prev, next;  ///< per level: neighbouring lattice coordinate (-1 none)
  };
  const Axis& x() const { return x_; }
  const Axis& y() const { return y_; }

 private:
  Axis x_, y_;
  int levels_ = 0;
};

/// Visits every cell the tree creates after the corners in midpoint displacement's order: per level
/// the rectangle centres, then the edge midpoints (which may read those centres); the rows of one
/// step in parallel, each cell reading earlier steps only, so any thread count gives the same
/// cells. `level_done(level)` after each level (progress).
void for_each_created_cell(const SubdivisionTree& tree, const std::function<void(int col, int row)>& visit,
                           const std::function<void(int level)>& level_done = {});

/// Top-down constrained midpoint displacement: computes every unknown cell from its parents, level
/// by level, keeping known and constrained cells (Belhadj §1.1.1, `dm`/`dmm` of Alg. 10/11 with the
/// interpolation shaping of eq. 3.4). Unknown corners take the mean of the non-unknown cells (0 if
/// none) plus their level-0 displacement. Deterministic and independent of the thread count.
void midpoint_displacement(SubdivisionGrid& grid, const MidpointParams& params, Progress* progress = nullptr);

/// Bottom-up pass of Belhadj's Alg. 10 / 11: rounds in which every non-unknown cell extrapolates
/// its unknown parents (by `params.rule`), until no parent is left to set. Afterwards every cell
/// whose subtree holds a constraint is known. `seed` draws Alg. 10's X per position (the hash of
/// the top-down pass; a cell is set by one pass only). Returns the number of cells it set.
std::size_t bottom_up(SubdivisionGrid& grid, Subdivision scheme, const BottomUpParams& params, std::uint64_t seed = 1);

/// DMMC parameters: both passes and the optional low-pass of §5.2.1.
struct DmmcParams {
  MidpointParams top_down;
  BottomUpParams bottom_up;
  bool low_pass = false;         ///< 3x3 mean on the computed cells while the held-out error falls
  double holdout_share = 0.05;   ///< share of the constrained cells held out to measure that error
  int max_low_pass = 200;        ///< cap on the number of passes
};

/// Belhadj's DMMC (the bottom-up pass, Alg. 11 or 10, seeded by top_down.seed, then the top-down
/// pass; §5.2.1 low-pass when asked). Cells of `raster` that are finite are kept exactly; NaN cells
/// are computed. `labels` (raster's size, row-major; empty: none) sets which way each cell
/// extrapolates (weighted rule only). Returns the number of low-pass passes.
int dmmc(Raster<float>& raster, const DmmcParams& params, Progress* progress = nullptr,
         const std::vector<ExtrapolationLabel>& labels = {});

/// One 3x3 mean pass over the cells whose state is not constrained (double-buffered, deterministic).
void low_pass(SubdivisionGrid& grid);

/// A uniform number in [-1,1] from a hash of (seed, col, row) (SplitMix64 finaliser).
double position_noise(std::uint64_t seed, int col, int row);

}  // namespace terrapolis::terrain
