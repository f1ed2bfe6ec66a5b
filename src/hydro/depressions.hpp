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
  /// leaving flats that `drain_flats` then drains.
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
/// (breach: 6 bytes/cell). Plain filling of large DEMs runs on row strips in parallel when more
/// than one thread is allowed (see fill_depressions_in_strips): same result, 2 bytes/cell.
Dem fill_depressions(const Dem& dem, const FillOptions& options, Progress& progress);

/// Plain Priority-Flood filling (FillMethod::priority_flood) of `strips` row strips in parallel,
/// joined through their spillover graph (Barnes 2016); the same result as the serial flood for
/// any strip count (clamped to 1..rows) and thread count. fill_depressions uses it on large DEMs
/// when more than one thread is allowed. 2 bytes/cell beside the output (4 beyond 32000 columns).
Dem fill_depressions_in_strips(const Dem& dem, std::optional<double> sea_level, int strips, Progress& progress);

/// Drains flats (Barnes, Lehman, Mulla 2014, "An efficient assignment of drainage direction over
/// flat surfaces in raster digital elevation models", Computers & Geosciences 62): every kNoFlow
/// cell of `d8` (first-pass receivers of `filled`: 0..7, kTerminal, kNoData, kNoFlow) gets the
/// neighbour of its flat with the smallest gradient value, the gradient combining "away from higher
/// terrain" and "towards lower terrain" (twice weighted); cells of flats without an outlet get
/// kTerminal. A flat is a set of 8-connected cells of equal elevation that holds a low edge (a
/// draining cell next to an undrained one).
/// @post from every kNoFlow cell of a drainable flat, following d8 reaches a draining cell (the
///   gradient strictly decreases along the way).
void drain_flats(const Dem& filled, Raster<std::uint8_t>& d8);

/// First-pass code: a valid cell with no strictly lower neighbour that is not an outlet.
inline constexpr std::uint8_t kNoFlow = 9;

}  // namespace terrapolis::hydro
