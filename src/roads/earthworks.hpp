// Cut-and-fill of the terrain along the surface sections of roads (Peytavie 2010 §4.4.3).
// SPDX-License-Identifier: MIT
#pragma once
#include <vector>

#include "core/raster.hpp"
#include "roads/road_geometry.hpp"
#include "roads/terrain_field.hpp"

namespace terrapolis::roads {

struct EarthworkOptions {
  double half_width_m = 4;     ///< half the carriageway: the ground is levelled to the deck within it (m, > 0)
  double side_slope = 1.5;     ///< embankment and cutting sides: metres across per metre up or down (1.5 = 2:3, 33.7 deg)
  double max_height_m = 50;    ///< deepest cut / highest fill reached by the sides (bounds the work area), m
  /// Optional per-cell side slope (same grid as the DEM, metres across per metre; NaN or <= 0:
  /// `side_slope`), e.g. from a map of materials.
  const Raster<float>* side_slopes = nullptr;

  /// The side slope at cell k.
  double slope_at(std::size_t k) const {
    const double s = side_slopes ? double((*side_slopes)[k]) : 0.0;
    return s > 0 ? s : side_slope;
  }
};

/// The DEM after the earthworks of the roads' surface sections (Peytavie 2010 §4.4.3: the terrain
/// is excavated and filled so that the road can be laid). Each cell takes the deck height of its
/// nearest surface segment (the road's profile, linear between its points) and is levelled to it
/// within `half_width_m` of the centreline; beyond, it is cut or filled only as far as the side
/// slope requires: |z' - deck| <= (d - half_width) / side_slope. Bridges and tunnels are left
/// alone; water and nodata cells are kept. The result depends only on the set of segments (nearest
/// segment by distance, then lower deck), not on their order.
Dem earthworks(const Dem& dem, const TerrainField& terrain, const std::vector<const RoadGeometry*>& roads,
               const EarthworkOptions& options = {});

}  // namespace terrapolis::roads
