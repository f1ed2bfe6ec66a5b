// Plain Priority-Flood filling on row strips in parallel (Barnes 2016), private to the hydro stage.
// SPDX-License-Identifier: MIT
#pragma once
#include <optional>

#include "core/progress.hpp"
#include "core/raster.hpp"

namespace terrapolis::hydro {

/// Fills `z` in place as FillMethod::priority_flood does, on `strips` row strips filled in
/// parallel and joined through their spillover graph: the same result for any strip count.
void fill_in_strips(Dem& z, const std::optional<double>& sea_level, int strips, Progress& progress);

}  // namespace terrapolis::hydro
