// Routing single roads and whole networks, and their GeoJSON layers (roads, sections).
// SPDX-License-Identifier: MIT
#pragma once
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "core/progress.hpp"
#include "io/vector_io.hpp"
#include "roads/anisotropic_search.hpp"
#include "roads/bezier_router.hpp"
#include "roads/existing_roads.hpp"
#include "roads/network_sections.hpp"
#include "roads/road_class.hpp"
#include "roads/road_geometry.hpp"

namespace terrapolis::roads {

enum class Router { galin, bezier };

struct RoutingOptions {
  Router router = Router::galin;
  GraphOptions graph;
  SearchMethod search = SearchMethod::astar;
  BezierOptions bezier;
  std::size_t max_nodes = 60'000'000;
  int snap_cells = 3;  ///< an end on water moves to the nearest land cell within this many cells
  double max_seconds = 0;  ///< per-road search budget (wall clock; 0 = none): past it the link is not routed
  /// Road reuse (Galin et al. 2011), per class of the road already on a cell (motorway, national,
  /// departmental, local): the share of a surface arc's cost taken off along it (0 = roads ignore
  /// each other; below 1).
  std::array<double, 4> reuse_discount{0.6, 0.5, 0.4, 0.3};
  /// Redundancy: a link whose route runs on earlier roads for at least this share of its length,
  /// between two ends the network already joins, is dropped (> 1 keeps every link).
  double redundant_share = 0.8;
  /// Design standards per class (motorway, national, departmental, local; docs/roads.md): the
  /// steepest grade (%) of a road, bridge deck or tunnel of the class (the cost model's slope
  /// thresholds are lowered to it), and the smallest curve radius (m) of its smoothing.
  std::array<double, 4> max_grade_pct{6, 7, 10, 12};
  std::array<double, 4> min_radius_m{400, 120, 60, 30};
  /// Links routed at once ahead of the roads they depend on (0: the worker threads). The roads never
  /// depend on it (route_network); not a scenario option, tests set it.
  std::size_t lookahead = 0;
};

/// How many links route_network routes at once: RoutingOptions::lookahead, or the worker threads.
std::size_t links_at_once(const RoutingOptions& options);

/// The cost model of a road class: every slope threshold at most the class's grade, its curve radius.
CostModel class_model(CostModel model, double max_grade_pct, double min_radius_m);

/// One routed road with everything the outputs need.
struct Road {
  std::int64_t from = -1, to = -1;
  RoadClass road_class = RoadClass::departmental;  ///< maritime for a ferry link
  std::string router;          ///< galin, bezier, ferry
  std::optional<double> cost;  ///< cost under the Galin model (null when infinite: Bézier roads may break it)
  RoadGeometry geometry;
  RoadStats stats;
  std::size_t expanded = 0, nodes = 0;
  std::size_t rings_priced = 0;  ///< rings of long bridge/tunnel arcs priced by the search
  std::size_t relaxed_settled = 0;  ///< cells settled by the heuristic's relaxed reverse search
  bool ferry = false;
  bool over_budget = false;  ///< the search ran out of max_seconds: no geometry, not written
  std::vector<GridPoint> ferry_line;  ///< for maritime links: the straight crossing
  CellChain chain;  ///< the route cell by cell (empty for a ferry): reuse, sections, junctions
  /// Share of the route's length on the given roads (roads.existing; its steps on_existing): that
  /// much of the road exists, the rest is new.
  double existing_share = 0;
};

/// Routes one road between two cells. Ends on water are moved to land (snap_cells); ends on two
/// different land masses give a maritime link. Returns nullopt when no road exists (e.g. the slope
/// threshold closes every way) and no maritime link applies.
/// `shared`: the target search of earlier roads ending at the same (snapped) `to`, or nullptr.
/// `discount`: cheaper arcs along earlier roads (road reuse), or nullptr.
std::optional<Road> route_road(const TerrainField& terrain, const RoadGraph& graph, Cell from, Cell to, const RoutingOptions& options,
                               Progress* progress = nullptr, TargetSearch* shared = nullptr, const ArcDiscount* discount = nullptr);

/// A network link to route: its two settlements (ids), their centres in the DEM's CRS, its class.
struct Link {
  std::int64_t from = -1, to = -1;
  std::array<double, 2> a{}, b{};
  RoadClass road_class = RoadClass::departmental;
};

/// Roads of the links, as a network (Galin et al. 2011): links are routed by importance (class,
/// then the longer first), each on the costs discounted along the roads before it, so roads merge
/// into trunks; a link whose route is mostly on earlier roads is dropped (redundant_share).
/// The roads are those of routing the links one after the other in that order: the next links are
/// routed ahead in parallel and kept only when the roads added meanwhile change nothing their search
/// read, else routed again; so the output depends neither on the threads nor on the look-ahead.
/// Links with no road are reported in `failed` and left out. Roads are listed in link order.
/// `existing` (roads.existing): roads already built, on the grid before the first link is routed,
/// as if routed before it with their classes: the links reuse them at their classes' discounts,
/// a link running on them (and the earlier roads) for redundant_share of its length between ends
/// they join is dropped, and each road's existing_share says how much of it they carry.
struct NetworkResult {
  std::vector<Road> roads;
  std::vector<std::string> failed;
  std::vector<std::string> over_budget;  ///< links not routed within roads.max_seconds ("from-to")
  std::vector<std::string> redundant;    ///< links dropped: their route ran on earlier roads ("from-to")
  /// By windows (route_network_by_windows): links no window the memory limit allows proved, kept as
  /// the largest window's answer ("from-to"; WindowedRoad::limited).
  std::vector<std::string> limited;
  RoadNetworkLayout layout;              ///< the roads' shared sections and junctions
  GivenCells existing;                   ///< the given roads' cells (empty without roads.existing)
  std::size_t searches = 0;              ///< links routed, attempts routed again included (depends on the threads)
};
NetworkResult route_network(const TerrainField& terrain, const RoadGraph& graph, const std::vector<Link>& links,
                            const RoutingOptions& options, Progress& progress, const ExistingRoads* existing = nullptr);

/// The roads layer (one LineString per road, in the DEM's CRS) and the sections layer.
/// With `layout`, each road lists its sections' ids (field `sections`), and when given roads were in
/// (layout->with_existing) its `new_m` and `existing_m` (length_m split by existing_share).
VectorLayer roads_layer(const TerrainField& terrain, const std::vector<Road>& roads, const RoadNetworkLayout* layout = nullptr);
VectorLayer sections_layer(const TerrainField& terrain, const std::vector<Road>& roads);

/// The nearest land cell within `radius` cells of `cell` (itself when on land), or nullopt.
std::optional<Cell> snap_to_land(const TerrainField& terrain, Cell cell, int radius);

/// Cell holding a point given in the DEM's CRS, or nullopt when outside the cells held.
std::optional<Cell> cell_at(const TerrainField& terrain, double x, double y);
/// The same on a grid of `cols` x `rows` cells georeferenced by `georef`.
std::optional<Cell> cell_at(const Georef& georef, int cols, int rows, double x, double y);

}  // namespace terrapolis::roads
