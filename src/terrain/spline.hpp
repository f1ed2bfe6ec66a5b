// Multigrid harmonic and thin-plate (biharmonic, optionally with tension) interpolation of unknown cells.
// SPDX-License-Identifier: MIT
#pragma once
#include "core/progress.hpp"
#include "core/raster.hpp"

namespace terrapolis::terrain {

/// The surface that passes through the known cells.
enum class Smoothness {
  harmonic,    ///< Laplace: lap(z) = 0, a membrane (C0 at the samples, no overshoot)
  thin_plate,  ///< (lap^2 - tension lap)(z) = 0: thin-plate spline on the grid (Briggs 1974), with tension
               ///< blending towards the membrane (Mitasova & Mitas 1993, the idea behind GRASS RST)
};

struct SplineParams {
  Smoothness smoothness = Smoothness::thin_plate;
  double tension = 0.0;        ///< tension in 1/(cell width)^2 at full resolution (>= 0); 0: pure thin plate
  double cell_aspect = 1.0;    ///< cell width (east-west) / cell height (north-south), both in metres
  int max_sweeps = 40;         ///< cap on relaxation sweeps at full resolution (level l: (1 + l) times more)
  double tolerance_m = 1e-2;   ///< a level stops when no cell moves more than this, in metres
};

/// Computes every NaN cell of `raster` so that the surface satisfies the chosen equation there with
/// the finite cells fixed exactly, by cascadic multigrid: the problem is restricted to a pyramid
/// of grids halved in size, solved at the coarsest level, and each solution is interpolated up as the
/// first guess of the next finer level, which 9-colour Gauss-Seidel (independent of the thread count)
/// then relaxes. Grid edges are mirror boundaries. Rectangular cells (geographic grids) are honoured
/// through cell_aspect; its change with latitude inside one grid is ignored.
/// A raster with no finite cell is left as it is.
void spline_fill(Raster<float>& raster, const SplineParams& params, Progress* progress = nullptr);

}  // namespace terrapolis::terrain
