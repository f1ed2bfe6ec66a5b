// Belhadj's growing window (2007 §2.1, Alg. 1): constrained midpoint displacement by dilation.
// SPDX-License-Identifier: MIT
#pragma once
#include "core/raster.hpp"
#include "terrain/subdivision.hpp"

namespace terrapolis::generate {

/// Fills every NaN cell of `raster`; finite cells are constraints and keep their altitude exactly.
/// At each scale pas = 1, 2, 4, ... (the largest power of 2 <= min(cols, rows) - 1) the unknown cells
/// of the pas-lattice that are a corner of a pas-square holding a known corner take the mean of that
/// square's known corners plus pas * s * (X + t), s = params.scale_m / 65536 m per cell (Alg. 10's
/// reading of the thesis's s, terrain::thesis_noise_per_cell_m); then (pas > 1) every pas-square whose
/// four corners are known is subdivided (params.subdivision, displacement of eq. 1.1 at the level the
/// square's size has in the whole grid). Cells no square reached (sizes other than 2^n + 1) are then
/// filled by midpoint displacement over the whole grid, as §2.1.2 prescribes. Needs at least one
/// finite cell (else the whole grid is plain midpoint displacement). `params.shape` is not used.
/// Deterministic and independent of the thread count.
void growing_window(Raster<float>& raster, const terrain::MidpointParams& params);

}  // namespace terrapolis::generate
