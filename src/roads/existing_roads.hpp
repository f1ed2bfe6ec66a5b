// Roads that exist (roads.existing): a user's lines drawn onto the grid, with their classes, for the
// network to reuse (Galin et al. 2011) and the outputs to tell apart from the new roads.
// SPDX-License-Identifier: MIT
#pragma once
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "io/vector_io.hpp"
#include "roads/network_sections.hpp"
#include "roads/road_class.hpp"
#include "roads/terrain_field.hpp"

namespace terrapolis::roads {

/// The class of an existing road from the value of its class field: a class name of ours
/// (motorway, national, departmental, local: a run's own roads.geojson), an OpenStreetMap
/// `highway` tag (motorway, trunk and their links: motorway; primary: national; secondary,
/// tertiary: departmental; any other: local) or a French national class (autoroute, nationale,
/// départementale, communale). Unknown or empty: local. nullopt for a ferry (maritime, ferry):
/// no road on the ground.
std::optional<RoadClass> existing_road_class(std::string_view value);

/// The field holding the class, the first of `class`, `highway`, `fclass` (Geofabrik's extracts)
/// and `cl_admin` (IGN BD TOPO) the layer has, or -1 (every road local).
int existing_class_field(const VectorLayer& lines);

/// The given roads on the grid: each line (in the DEM's CRS) drawn as the chain of 8-connected
/// cells it crosses (sampled every quarter cell: every cell it passes through, so a search's arcs
/// along it find their start, middle and end cells on it), cut where it leaves the grid.
struct ExistingRoads {
  std::vector<CellChain> chains;     ///< steps all Structure::road
  std::vector<RoadClass> classes;    ///< one per chain
  std::vector<std::string> source_class;  ///< the class field's value ("" without one)
  std::vector<double> chain_length_m;     ///< length of each line inside the grid (m, geodesic on geographic grids)
  std::size_t lines = 0;             ///< lines read (multi-lines split)
  std::size_t outside = 0;           ///< lines with no step on the grid, left out
  std::size_t ferries = 0;           ///< ferry lines, left out
  /// Length of the lines inside the grid per class (motorway .. local), m.
  std::array<double, 4> length_m{};
  bool empty() const { return chains.empty(); }
};
ExistingRoads rasterise_roads(const TerrainField& terrain, const VectorLayer& lines);

/// The checks that need no grid, before a run's first stage: the file exists and GDAL reads it,
/// it declares a CRS (a GeoPackage or shapefile without one is refused; GeoJSON is WGS 84), its
/// features are line strings and there is at least one. Throws bad_input naming the file.
void check_existing_roads(const std::string& path, const Crs& dem_crs);

/// The file read onto the grid (check_existing_roads, then rasterise_roads). Throws bad_input
/// when no given road has a step on the DEM.
ExistingRoads read_existing_roads(const std::string& path, const TerrainField& terrain);

/// existing_roads.geojson: each chain drawn through its cells' centres (the roads as the run saw
/// them), with class, source_class and length_m.
VectorLayer existing_roads_layer(const TerrainField& terrain, const ExistingRoads& existing);

}  // namespace terrapolis::roads
