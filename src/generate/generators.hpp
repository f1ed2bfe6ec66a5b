// The terrain generators behind `terrapolis generate --method`, one source file each.
// SPDX-License-Identifier: MIT
#pragma once
#include "generate/generator.hpp"

namespace terrapolis::generate {

/// Belhadj 2007 §2.2 (generate_flow.cpp): ridges (random from the seed, or request.lines), basins,
/// river particles, then DMMC constrained by the ridge and river cells.
GeneratedTerrain generate_flow(const GenerateRequest& request);

/// The procedural-tectonics report (generate_tectonic.cpp): plates from mountain points
/// (request.points, or random chains), folds, a river base map from the border, blended.
GeneratedTerrain generate_tectonic(const GenerateRequest& request);

/// Génévaux et al. (river_grammar.cpp): mouths on the coast (request.polygons, or a seeded island),
/// the open grammar, Voronoi ridges, discharge and types, blended primitives carved by the rivers.
GeneratedTerrain generate_coast(const GenerateRequest& request);

/// The planar-maps chapter §6.2-6.3 (planar_basins.cpp): a binary river tree on a planar map,
/// ridge altitudes by linear programming, fractalised facets.
GeneratedTerrain generate_planar(const GenerateRequest& request);

/// Belhadj 2007 §2.1, Alg. 1 (growing_window.cpp): the sketch in request.grid (finite cells, kept
/// exactly) dilated scale by scale by small midpoint displacements (request.dmmc.top_down).
GeneratedTerrain generate_window(const GenerateRequest& request);

/// Belhadj 2007 §1.2.3 (river_fractal.cpp): a Mandelbrot necklace from two sides of the grid, its
/// edge labels in a binary search tree, and the midpoint displacement converging to its bed.
GeneratedTerrain generate_river(const GenerateRequest& request);

}  // namespace terrapolis::generate
