// The plan a terrain generator builds its DEM from: river reaches as a tree, ridge lines (what
// `generate` writes as <stem>.skeleton.geojson; not the ridges and valleys that src/skeleton/ traces
// on a DEM).
// SPDX-License-Identifier: MIT
#pragma once
#include <array>
#include <vector>

#include "core/raster.hpp"
#include "io/vector_io.hpp"

namespace terrapolis::generate {

/// A position in cell coordinates: (col, row) as reals, the centre of cell (c,r) at (c,r), row 0 north.
using GridPoint = std::array<double, 2>;

/// One river reach, upstream to downstream. Reaches form a forest: `downstream` is the index of the
/// reach this one flows into (its last point lies on that reach), -1 when it ends at an outlet
/// (the grid border, the sea or nodata).
struct RiverReach {
  std::vector<GridPoint> line;
  int downstream = -1;
  int strahler = 1;      ///< set by assign_strahler (Strahler 1952)
  double width_m = 0;    ///< channel width the generator carved (Belhadj 2007 §2.2.2.2: log2 of the mass, in cells)
};

/// One ridge line (a crest between two slopes) with its crest heights.
struct RidgeLine {
  std::vector<GridPoint> line;
  std::vector<float> z_m;  ///< one per point, metres
};

/// What a generator produced besides the DEM, on the DEM's grid.
struct RiverRidgePlan {
  std::vector<RiverReach> rivers;
  std::vector<RidgeLine> ridges;
};

/// A river as a particle or a grammar traces it, source to end: it ends at an outlet (`into` = -1)
/// or joins river `into` at that river's point `at` (a confluence anywhere along it).
struct RiverPath {
  std::vector<GridPoint> line;
  std::vector<double> width_m;  ///< empty, or one per point
  int into = -1;
  std::size_t at = 0;
};

/// The reaches of `paths` split at every confluence, so that each reach's inflows all join at its
/// first point (what Strahler ordering and Horton's counts assume); orders assigned.
std::vector<RiverReach> reaches_from_paths(const std::vector<RiverPath>& paths);

/// Sets every reach's Strahler order from the tree: 1 for a reach nothing flows into, else the
/// highest order flowing in, +1 when two or more inflows share it (Strahler 1952). Throws
/// std::logic_error on a cycle or a `downstream` out of range.
void assign_strahler(RiverRidgePlan& plan);

/// Length of a line in metres on a grid of square `cell_m` cells.
double line_length_m(const std::vector<GridPoint>& line, double cell_m);

/// The plan as one line layer in the grid's CRS: fields `kind` ("river" | "ridge"), `id`,
/// `strahler`, `width_m`, `downstream_id` (0 at an outlet or for a ridge), `length_m`.
VectorLayer river_ridge_layer(const RiverRidgePlan& plan, const Georef& georef, double cell_m);

}  // namespace terrapolis::generate
