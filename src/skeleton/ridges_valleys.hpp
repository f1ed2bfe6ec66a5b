// Ridge and valley lines of a real DEM by the form index and path following (Belhadj 2007, §5.2.2),
// and the sparse raster of their cells from which `reconstruct` rebuilds the DEM.
// SPDX-License-Identifier: MIT
#pragma once
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "core/geodesy.hpp"
#include "core/progress.hpp"
#include "core/raster.hpp"
#include "io/vector_io.hpp"

namespace terrapolis::skeleton {

enum class Kind { ridge, valley };
enum class Lines { both, ridges, valleys };

struct SkeletonOptions {
  double tolerance = 0.10;   ///< a step keeps within ± this fraction of the previous cell's form index (the thesis's ±10 %)
  double seed_share = 0.05;  ///< share of the valid cells, most extreme form index first, a line may start from (each sign)
  int min_cells = 3;         ///< shorter lines are dropped
  Lines lines = Lines::both; ///< the thesis's "creux" (valleys) or "creux et crêtes" (both)
  /// Also keep every `lattice`-th cell of every `lattice`-th row (from lattice / 2), so that slopes,
  /// plateaus and the DEM's edges hold samples too; 0 keeps the lines' cells only (the thesis's
  /// literal form). docs/skeleton.md: the lines alone lose to random cells at the same share.
  int lattice = 6;
  /// Keep every `line_step`-th cell along a line (and its last): neighbours on a line add little that
  /// a surface through every third does not (docs/skeleton.md); 1 keeps them all (the thesis's form).
  int line_step = 3;
};

/// Belhadj's form index (§5.2.2, footnote 14): the mean of the vertical components of the unit
/// vectors V_i from the eight neighbours to the cell, in [-1, 1]: > 0 on peaks and ridges, < 0 in
/// valleys and pits, 0 on a plane. Vectors are in metres (geodesic steps on geographic CRSs). Only
/// pairs of opposite neighbours that both hold data count, so a plane reads 0 up to the DEM's edge
/// and nodata (the thesis put missing neighbours at height -1 instead); NaN without such a pair.
Raster<float> form_index(const Dem& dem, const CellMetrics& metrics);

/// One ridge or valley line: 8-connected cells in path order (a line may end on a cell of an
/// earlier line, where it joins it).
struct Line {
  Kind kind = Kind::ridge;
  std::vector<std::size_t> cells;  ///< row * cols + col
  double length_m = 0;             ///< sum of the geodesic steps
  double relief_m = 0;             ///< highest minus lowest ground along the line
  float index = 0;                 ///< form index of the seed cell
};

struct Skeleton {
  Raster<float> index;       ///< the form index
  std::vector<Line> lines;   ///< ridges and valleys, in the order they were traced
  Raster<float> kept;        ///< the DEM's heights on the lines' and the lattice's cells, NaN elsewhere
  std::size_t kept_cells = 0, valid_cells = 0, ridges = 0, valleys = 0;
  std::size_t line_cells = 0;     ///< cells kept from the lines (every line_step-th of each)
  std::size_t lattice_cells = 0;  ///< valid lattice cells (some of them on a line too)
};

/// Traces the lines: from the most extreme unvisited seed cell (the `seed_share` highest form
/// indices for ridges, lowest for valleys), a path is followed both ways through 8-neighbours whose
/// form index lies within ± tolerance of the previous cell's, turning by at most 45° a step and
/// taking the most extreme such neighbour; it stops where no neighbour qualifies or on a cell of an
/// earlier line. Nodata is never entered. Every `line_step`-th cell of a line is kept, then the
/// valid cells of the lattice (`lattice` > 0) too. Deterministic.
Skeleton extract_skeleton(const Dem& dem, const CellMetrics& metrics, const SkeletonOptions& options, Progress& progress);

/// Whether the j-th of a line's n cells is kept: every `step`-th from the first, and the last.
inline bool kept_on_line(std::size_t j, std::size_t n, int step) { return j % std::size_t(step) == 0 || j + 1 == n; }

/// Whether cell (col, row) is on the supplementary lattice of spacing `lattice` (never when 0).
inline bool on_lattice(int col, int row, int lattice) {
  return lattice > 0 && col % lattice == lattice / 2 && row % lattice == lattice / 2;
}

/// One kind of line as LineStrings through the cell centres in the DEM's CRS, with fields `id`,
/// `kind`, `cells`, `length_m`, `relief_m` and `form_index` (of the seed).
VectorLayer lines_layer(const Skeleton& skeleton, Kind kind);

/// A QGIS 3 style (.qml) for a layer of `lines_layer`: ridges brown, valleys blue, wider with relief.
std::string lines_qml(Kind kind);

}  // namespace terrapolis::skeleton
