// Depression handling: Priority-Flood filling (plain, epsilon), breaching, and flat resolution.
// SPDX-License-Identifier: MIT
#pragma once
#include <cstdint>
#include <optional>

#include "core/progress.hpp"
#include "core/raster.hpp"

namespace terrapolis::hydro {

enum class FillMethod {
  /// Priority-Flood (Barnes, Lehman, Mulla 2014, "Priority-Flood: an optimal depression-filling and
  /// watershed-labeling algorithm", Algorithm 2): depressions raised to their spill elevation,
  /// leaving flats that `resolve_flats` then drains.
  priority_flood,
  /// Priority-Flood+epsilon (same paper, Algorithm 3): each raised cell is one float ulp above the
  /// cell that floods it (std::nextafter), so every cell has a strictly lower neighbour.
  epsilon,
  /// Breaching by carving (Soille 2004 style, on the Priority-Flood tree): instead of raising a
  /// depression, the path from its bottom to the spill and beyond is lowered to the bottom's
  /// elevation; cells off that path keep their elevation.
  breach,
  /// Leave the DEM as it is: pits stay terminal cells.
  none,
};

struct FillOptions {
  FillMethod method = FillMethod::priority_flood;
  /// Cells at or below this elevation (m) are outlets and are never modified (coastal DEMs).
  std::optional<double> sea_level;
};

/// Returns the conditioned DEM (same grid, NaN where `dem` is nodata).
/// @pre `dem` holds metres, NaN nodata.
/// @post priority_flood / epsilon: no cell is lowered; from every valid cell a path of
///   non-increasing (epsilon: strictly decreasing) elevation leads to an outlet: a cell on the
///   grid border, next to nodata, or at or below `sea_level`.
/// @post breach: no cell is raised; the same non-increasing path exists.
/// Deterministic: queue ties are broken by cell index. O(n log n) time; 1 byte/cell beside the output
/// (breach: 6 bytes/cell).
Dem fill_depressions(const Dem& dem, const FillOptions& options, Progress& progress);

/// Flat resolution result (Barnes, Lehman, Mulla 2014, "An efficient assignment of drainage
/// direction over flat surfaces in raster digital elevation models", Computers & Geosciences 62).
struct FlatGradient {
  /// Per cell: 0 outside flats; in a flat, an increment combining "away from higher terrain" and
  /// "towards lower terrain" (twice weighted): water goes to the neighbour of the same flat with
  /// the smallest value.
  Raster<std::int32_t> mask;
  /// Per cell: 0 outside flats, else the label (1..) of the flat the cell belongs to.
  Raster<std::int32_t> labels;
};

/// Computes the flat gradient of `filled` given first-pass D8 receivers `d8` (0..7, kTerminal,
/// kNoData, and kNoFlow for cells without a strictly lower neighbour that are not outlets).
/// @post following the smallest-mask neighbour of the same label from a kNoFlow cell of a flat
///   that has an outlet reaches a draining cell in finitely many steps (mask strictly decreases).
FlatGradient resolve_flats(const Dem& filled, const Raster<std::uint8_t>& d8);

/// First-pass code: a valid cell with no strictly lower neighbour that is not an outlet.
inline constexpr std::uint8_t kNoFlow = 9;

}  // namespace terrapolis::hydro
