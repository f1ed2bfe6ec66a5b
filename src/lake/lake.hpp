// Lakes and reservoirs: flooding a DEM to a level from a seed (Peytavie 2010, §2.4.1).
// SPDX-License-Identifier: MIT
#pragma once
#include <array>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "core/geodesy.hpp"
#include "core/progress.hpp"
#include "core/raster.hpp"
#include "io/vector_io.hpp"

namespace terrapolis::lake {

/// A dam: a polyline in the DEM's CRS whose cells are raised to the crest.
struct Dam {
  std::vector<std::array<double, 2>> line;
  double crest_m = 0;
};

struct Lake {
  double level_m = 0;                 ///< water surface, metres
  int seed_col = 0, seed_row = 0;
  Raster<float> depth;                ///< level - ground (m) on flooded cells, NaN elsewhere
  Raster<std::uint8_t> mask;          ///< 1 flooded, 0 dry, 255 nodata
  std::size_t cells = 0;
  double area_km2 = 0;                ///< geodesic: the flooded cells' ellipsoidal areas
  double volume_m3 = 0;               ///< sum of depth x cell area
  double max_depth_m = 0;
  bool spills = false;                ///< the water reaches the DEM's edge or nodata: it would run on beyond
  std::size_t dam_cells = 0;          ///< cells of the dam line (0 without a dam)
};

/// The cells of a polyline (DEM CRS) as a 4-connected chain, so that no 8-connected flood slips
/// diagonally through it. Vertices off the grid are clipped by sampling.
std::vector<std::size_t> line_cells(const Georef& georef, int cols, int rows, const std::vector<std::array<double, 2>>& line);

/// Peytavie's fill by propagation on a height field: from the seed cell, every 8-connected cell
/// whose ground is below `level_m` is flooded, and ground at or above the level stops the front.
/// With a dam, its cells count as ground at max(ground, crest). Throws bad_input when the seed is
/// off the grid, on nodata or not below the level. Deterministic; O(flooded cells).
Lake flood(const Dem& dem, const CellMetrics& metrics, int seed_col, int seed_row, double level_m, const Dam* dam, Progress& progress);

/// A lake as a user states it: a seed in lon/lat (WGS 84), a level (or a depth above the seed's
/// ground) and an optional dam, its line in lon/lat. The command and the scenario's
/// `water.reservoirs` both go through it.
struct LakeSpec {
  double lon = 0, lat = 0;
  std::optional<double> level_m, depth_m;              ///< exactly one, or none with a dam (level = crest)
  std::vector<std::array<double, 2>> dam_lonlat;       ///< empty: no dam
  std::optional<double> crest_m;                       ///< required with a dam
};

/// The checks of a spec alone, before any DEM is read: throws bad_input naming the field at fault by
/// its pointer within the spec ("/at", "/level_m", "/depth_m", "/dam", "/crest_m"; the scenario's
/// water.reservoirs items have these fields, the lake command maps them to its flags).
void check_spec(const LakeSpec& spec);

/// Floods `dem` as `spec` says (check_spec first). Throws bad_input naming the field at fault as check_spec does.
Lake flood(const Dem& dem, const CellMetrics& metrics, const LakeSpec& spec, Progress& progress);

/// A lake flooded on a window of a grid read by windows: its rasters cover the window whose first
/// cell is (`col0`, `row0`) in the grid; its seed is in the grid's cells.
struct WindowLake {
  Lake lake;
  int col0 = 0, row0 = 0;
  int windows = 0;  ///< windows flooded, the last one holding the lake
};
/// A window [col0, col0 + cols) x [row0, row0 + rows) of the grid's DEM, on the grid's cells.
using ReadWindow = std::function<Dem(int col0, int row0, int cols, int rows)>;
/// flood(spec) on a grid (`grid`, `cols` x `rows`) larger than memory, read by windows: a square
/// around the seed, twice as wide each time the water reaches its side, until the lake and its
/// neighbouring cells lie inside (or the grid's edge). The cells, the figures and `spills` are the
/// whole grid's flood's, bit for bit. Throws bad_input as flood does, and when the water needs a
/// window of more than `max_cells` cells.
WindowLake flood_by_windows(const Georef& grid, int cols, int rows, const ReadWindow& read, const LakeSpec& spec, std::size_t max_cells,
                            Progress& progress);

/// The shoreline: polygons of the flooded cells with `level_m`, `area_km2`, `volume_m3` (of the whole lake).
VectorLayer shoreline_layer(const Lake& lake);

/// Metres of `roads` (line strings on the lake's grid CRS) over flooded cells, sampled at a
/// tenth of a cell; and the ids of the cities (points with `radius_m`) whose disc holds a flooded cell.
double flooded_length_m(const Lake& lake, const VectorLayer& roads);
std::vector<std::int64_t> cities_touched(const Lake& lake, const CellMetrics& metrics, const VectorLayer& cities);

}  // namespace terrapolis::lake
