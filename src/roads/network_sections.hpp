// The road network drawn once: shared sections and junctions from the roads' cell chains
// (Galin et al. 2011: roads merge into trunks and branch at junctions).
// SPDX-License-Identifier: MIT
#pragma once
#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include "io/vector_io.hpp"
#include "roads/anisotropic_search.hpp"
#include "roads/road_class.hpp"
#include "roads/terrain_field.hpp"

namespace terrapolis::roads {

/// A road's route as a chain of 8-connected cells (grid indices), each arc of the search path
/// drawn cell by cell; `structures[i]` is the structure of the step from cells[i] to cells[i + 1].
struct CellChain {
  std::vector<std::uint32_t> cells;
  std::vector<Structure> structures;
};
/// The chain of a path of cells joined by arcs (`structures`: one per arc, or empty for surface arcs).
CellChain cell_chain(const TerrainField& terrain, const std::vector<Cell>& path, const std::vector<Structure>& structures = {});

/// The cells of the given roads (roads.existing), grid indices, sorted and distinct: sparse, so that
/// a grid larger than memory (roads by windows) holds only the roads' cells.
class GivenCells {
 public:
  GivenCells() = default;
  explicit GivenCells(std::vector<std::uint32_t> cells) : cells_(std::move(cells)) {
    std::sort(cells_.begin(), cells_.end());
    cells_.erase(std::unique(cells_.begin(), cells_.end()), cells_.end());
  }
  /// The cells of `chains`.
  explicit GivenCells(const std::vector<CellChain>& chains);
  bool empty() const { return cells_.empty(); }
  bool holds(std::uint32_t cell) const { return std::binary_search(cells_.begin(), cells_.end(), cell); }

 private:
  std::vector<std::uint32_t> cells_;
};

/// One piece of the network between two breakpoints (a junction, a road's end, or where the set of
/// roads using it or the structure changes), written once whatever the number of roads on it.
struct NetworkSection {
  std::vector<std::uint32_t> cells;  ///< grid indices, in order along the section
  std::vector<std::size_t> roads;    ///< indices of the roads using it, ascending
  RoadClass road_class = RoadClass::local;  ///< the most important class among them
  Structure structure = Structure::road;
  double length_m = 0;
  bool existing = false;  ///< every step on cells of the given roads (roads.existing): nothing to build
};

/// A cell where three or more sections meet.
struct Junction {
  std::uint32_t cell = 0;
  int degree = 0;                   ///< sections meeting
  std::vector<RoadClass> classes;   ///< classes of those sections, most important first, distinct
  std::size_t roads = 0;            ///< distinct roads through the cell
};

struct RoadNetworkLayout {
  std::vector<NetworkSection> sections;
  std::vector<Junction> junctions;
  std::vector<std::vector<std::size_t>> road_sections;  ///< per road: its sections in order along it
  bool with_existing = false;  ///< given roads were in (roads.existing): the layers say what is new
};

/// Sections and junctions of the roads' chains (`classes[i]` the class of road i). Deterministic:
/// sections are numbered in the order of their first edge by cell index. `existing`: the cells of
/// the given roads (roads.existing), or empty; a step on them (on_existing) is existing, and a
/// section also breaks where that changes.
RoadNetworkLayout network_layout(const TerrainField& terrain, const std::vector<CellChain>& chains, const std::vector<RoadClass>& classes,
                                 const GivenCells& existing = {});

/// Whether the step between cells `a` and `b` (grid indices) lies on the given roads (`existing`,
/// roads.existing): one of the two cells is theirs and the other is theirs or
/// touches one of theirs. The tolerance of one cell absorbs how differently a given line and a
/// route along it cross the cells (a staircase drawn the other way round); a road one cell beside
/// a given one, touching none of its cells, is new.
bool on_existing(const TerrainField& terrain, const GivenCells& existing, std::uint32_t a, std::uint32_t b);

/// A chain of cells as a line through their centres in the DEM's CRS, its staircase drawn as
/// straight runs within half a cell (Douglas-Peucker).
std::vector<std::array<double, 2>> chain_line(const TerrainField& terrain, const std::vector<std::uint32_t>& cells);

/// The layers: sections (LineString: id, roads "i,j,...", count, class, structure, length_m, and
/// `existing` 0/1 when given roads were in) and
/// junctions (Point: degree, classes "national,local", roads). Road ids are the features' order
/// in roads.geojson.
VectorLayer network_sections_layer(const TerrainField& terrain, const RoadNetworkLayout& layout);
VectorLayer junctions_layer(const TerrainField& terrain, const RoadNetworkLayout& layout);

/// "a,b,c" from a list of numbers (the ids fields).
std::string id_list(const std::vector<std::size_t>& ids);

}  // namespace terrapolis::roads
