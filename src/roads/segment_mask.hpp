// Segment masks M_k of the anisotropic shortest path (Galin et al. 2010; Peytavie 2010 §4.3.1).
// SPDX-License-Identifier: MIT
#pragma once
#include <cstdint>
#include <vector>

namespace terrapolis::roads {

/// One arc of a mask: a grid offset (dcol, drow), row + 1 being south, and its direction.
struct MaskArc {
  int dcol = 0, drow = 0;
  double angle_rad = 0;  ///< atan2(-drow, dcol) in [0, 2*pi): 0 east, pi/2 north (grid angle, cells assumed square)
};

/// The segment mask M_k (Peytavie 2010 §4.3.1, table 4.1): every offset (i,j) in [-k,k]^2 with
/// gcd(|i|,|j|) = 1, so no two arcs are collinear. |M_k| = 8, 16, 32, 48, 80, 96, 144, 176, 224,
/// 256 for k = 1..10; the masks are nested (M_k is a subset of M_{k+1}) and the arcs are sorted by
/// angle. Throws bad_input for k outside 1..16.
std::vector<MaskArc> segment_mask(int k);

/// Offsets (dcol, drow) whose length in cells lies in [r_min, r_max] (the bridge and tunnel masks
/// A of Peytavie §4.3.3), in a fixed order (row-major). r_min >= 1.
std::vector<MaskArc> annulus_mask(double r_min_cells, double r_max_cells);

}  // namespace terrapolis::roads
