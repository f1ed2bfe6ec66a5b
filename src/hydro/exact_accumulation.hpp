// D8 accumulation in fixed point: sums that do not depend on the order of the additions.
// SPDX-License-Identifier: MIT
#pragma once
#include <cstdint>
#include <vector>

#include "core/geodesy.hpp"
#include "core/raster.hpp"
#include "hydro/accumulation.hpp"
#include "hydro/grid.hpp"

namespace terrapolis::hydro {

/// Each cell's contribution as an integer number of 2^-shift units (m² or cells). The shift is
/// the largest that keeps the contributions of every cell of the grid below 2^62, so no sum of
/// upstream cells overflows, and it depends only on the grid's geometry. Integer sums are exact,
/// hence the same in any order: the whole grid, its tiles (Barnes 2017's second pass adds the
/// incoming flow after the local sums) and any rank count give the same bits. The rounding of a
/// contribution is below 2^-(shift+1), about 1e-15 of a cell on a 1e9-cell grid.
struct FixedPointUnits {
  int shift = 0;
  std::vector<std::int64_t> per_row;  ///< contribution of one cell of row r
  double value(std::int64_t units) const;
};

/// The units of a `cols` x (metrics rows) grid in `unit`.
FixedPointUnits fixed_point_units(const CellMetrics& metrics, int cols, AccumulationUnit unit);

/// Accumulates `acc` (in: each cell's own contribution; out: the cell's plus its upstream cells')
/// down the D8 receivers `d8` (flow_directions.hpp codes) of a grid; a receiver outside the grid
/// or on nodata takes nothing. Kahn order, serial; 1 byte/cell beside `acc`.
void accumulate_d8_units(const Raster<std::uint8_t>& d8, std::vector<std::int64_t>& acc);

}  // namespace terrapolis::hydro
