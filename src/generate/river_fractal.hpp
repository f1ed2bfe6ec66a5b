// Belhadj's fractal terrain with one river (2007 §1.2.3): the Mandelbrot necklace refined with the
// midpoint displacement.
// SPDX-License-Identifier: MIT
#pragma once
#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/raster.hpp"
#include "generate/river_ridge_plan.hpp"
#include "terrain/subdivision.hpp"

namespace terrapolis::generate {

/// The river of a Mandelbrot necklace ("cordonnet discret et fractal", §1.2.3.1) on a cols x rows
/// grid, subdivided like terrain::SubdivisionTree: two sides of the grid are the entry (the source)
/// and the exit (the mouth); each rectangle on the path splits into 2 or 4, each river side keeps one
/// river half, and the path crosses 0 to 3 inner sides from the entry half to the exit half.
struct Necklace {
  std::vector<GridPoint> line;     ///< midpoints of the crossed unit edges, source to mouth (cell coordinates)
  std::vector<std::size_t> cells;  ///< river cells (both ends of every crossed unit edge), in the order the river leaves them
  std::vector<std::size_t> edge_of_cell;  ///< per entry of `cells`: the index in `line` of the last edge touching it
  /// Per cell: the level r at which it is created as an end of a river edge of level r (eq. 1.3's
  /// river vertices), -1 for the others.
  std::vector<std::int8_t> river_vertex_level;
  std::size_t tree_nodes = 0;      ///< edges stored in the binary search tree of edge labels
};

/// The necklace of a cols x rows grid (3 to 65535 cells a side, the thesis's 16-bit edge keys),
/// from its own seeded sequence (§1.2.3.2 note 12: the necklace does not depend on the terrain's
/// noise). Throws bad_input outside those sizes.
Necklace mandelbrot_necklace(int cols, int rows, std::uint64_t seed);

/// Parameters of the terrain around the river (eq. 1.1 to 1.3).
struct RiverFractalParams {
  terrain::MidpointParams top_down;  ///< subdivision, S (scale_m), H, t, seed of the displacements
  double relief_m = 1500;            ///< north-west corner; south-east relief / 2, the others relief / 10 (§1.2.3.2)
  double convergence = 16;           ///< I of eq. 1.3 (fig. 1.6(d)): p = (1 - r / r_max)^I pulls river vertices to the bed
  double power = 1.2;                ///< f of eq. 1.2 (fig. 1.5 right, 1.6(f)): delta- = -X S 2^(r^f - r D H), X uniform in [0,1]
  double bed_drop_m = 75;            ///< the bed falls by this much from the source to the mouth (0 m)
};

/// Midpoint displacement on `grid` (NaN cells, georeferenced) crossed by `necklace`'s river: river
/// cells fixed on a bed falling from bed_drop_m to 0 along the river, corners fixed as §1.2.3.2,
/// eq. 1.3 on the river vertices (no lower than the bed of the nearest river cell), cells beside the
/// river no lower than the river cells they touch. Deterministic and independent of the thread count.
void river_fractal(Raster<float>& grid, const Necklace& necklace, const RiverFractalParams& params);

}  // namespace terrapolis::generate
