// One road on a grid larger than memory: the search runs on a window of the grid, grown until a
// bound proves that no road leaving it could cost less, so the road is the whole grid's.
// SPDX-License-Identifier: MIT
#pragma once
#include <cstddef>
#include <functional>
#include <memory>
#include <optional>
#include <vector>

#include "core/progress.hpp"
#include "roads/road_network.hpp"

namespace terrapolis::roads {

struct WindowOptions {
  /// The most cells a window may hold: the memory the road may take, at kWindowBytesPerCell
  /// (0: the whole grid if need be).
  std::size_t max_cells = 0;
  /// Cells read beyond the searched area on each side, so that every cost a road inside it reads
  /// is the grid's: the road radius (water depth), the corridor's reach, and 2 for the bilinear
  /// samples (window_margin_cells).
  int margin_cells = 2;
  /// The first searched area holds the two ends' bounding box padded by this many cells, and what
  /// the bound needs for a road costing first_ratio x the straight line at the cheapest cost per
  /// metre (a road of 53 km between ends 35 km apart in the Alps costs 1.6 times it).
  int pad_cells = 32;
  double first_ratio = 1.6;
  /// Past max_cells, give up at once (WindowedRoad::limited, no road) instead of searching the
  /// largest window the limit allows: for a caller that routes such a link again with a larger limit.
  bool give_up_at_limit = false;
};

/// Bytes a window takes per cell while its road is searched: the terrain (surface, ground, depth,
/// water, land components: 17), its inputs while it is built (DEM, inland water, raw depth: 13), and
/// the search's per-cell arrays (nodes, arc caches, relaxed distances: about 30). The nodes the
/// search stores come on top (RoutingOptions::max_nodes; pipeline::road_windows counts 48 bytes each).
inline constexpr double kWindowBytesPerCell = 60;
/// Bytes a cell of a road held by the network by windows takes: its entry in the road cells' ordered
/// map (about 64), its chain's cell and step, the log of changed factors and, for a given road
/// (roads.existing), its place in GivenCells and the result's copy.
inline constexpr double kRoadCellBytes = 96;
/// Bytes a search node takes (RoutingOptions::max_nodes counts them): node slots of 16 bytes and arc
/// costs cached 4 to a unit; with their share of the queue about 32 bytes each, and 16 more for the
/// long arcs' cost cache that follows it (4 floats a unit, TargetSearch).
inline constexpr double kSearchBytesPerNode = 48;
/// Bytes a cell of the reach bound's region takes (two times and a factor as floats, flags, and
/// about three queue entries of 16 bytes): its region holds at most the nodes' bytes, which the
/// search freed, at this rate.
inline constexpr double kReachBytesPerCell = 64;

/// How many times longer the 8-connected steps along a straight move can be than the move, on
/// cells whose widths lie in [w_min, w_max], heights in [h_min, h_max], diagonals at most d_max
/// (metres): 1.0824 on square cells, more on a geographic grid's narrower ones (1.13 at 47.5
/// degrees). The reach bound divides its steps by it.
double octile_slack(double w_min, double w_max, double h_min, double h_max, double d_max);

/// The margin WindowOptions::margin_cells needs: the road radius and a reach (the corridor's:
/// its platform's half-width plus its tallest side), in the grid's smallest cells, plus 2.
int window_margin_cells(double road_radius_m, double reach_m, double min_cell_m);

struct WindowedRoad {
  std::optional<Road> road;             ///< as route_road returns it, in the grid's cells
  std::unique_ptr<TerrainField> terrain;  ///< the last window: its cells, positions and metrics are the grid's
  int windows = 0;                      ///< windows searched
  std::size_t largest_cells = 0;        ///< cells of the largest window read
  bool proved = false;                  ///< the bound proved the road the grid's (false: the window was the grid, or limited)
  bool proved_by_reach = false;         ///< proved by the reach bound (road reuse), the straight line could not
  /// No window the limit allows proved the road (or found one): `road` is the largest window's
  /// answer, the best road within it, a ferry between its land masses, or none (none when the
  /// windows outgrew max_cells under WindowOptions::give_up_at_limit).
  bool limited = false;
};

/// Routes a road between two cells of `grid` by windows (route_road on each). A window is accepted
/// when its road stays in the searched area I (the window less its margin) and costs less than any
/// road that leaves I could: cheapest cost per metre x 0.995 x the shortest length from one end to
/// the other through a cell outside I (the straight-line bound of RoadGraph::lower_bound, at the
/// grid's smallest cell). Then the road's cost is the whole grid's optimum; its cells are the
/// whole grid's road too unless two roads cost exactly the same. Else the area grows: to the box
/// the reach bound needs (below), or at least doubled and holding what the straight line needs; past
/// max_cells, at once to the largest window it allows, unless that is less than a quarter more. A road
/// still not proved, not found, or a ferry (the window's land masses) is then the largest window's
/// answer (WindowedRoad::limited), as is the
/// previous window's when a search stores more than RoutingOptions::max_nodes (no road on the first). A first
/// window (the ends and pad_cells) past max_cells throws bad_input naming it. The Bézier router is
/// not searched by windows (bad_input).
/// With road reuse the straight-line bound is scaled by the smallest factor; when that cannot tell,
/// the reach bound (Dijkstra over a larger region of the grid, on the cheapest cost per metre times
/// the factors of the roads nearby, read from no terrain) proves the road or names the area a cheaper
/// road could use, which the next window holds. Its region takes the memory the search's nodes
/// freed (kReachBytesPerCell against kSearchBytesPerNode).
///
/// Road reuse (route_network by windows): the roads built so far.
struct WindowReuse {
  /// Their discount over a window's cells (ArcDiscount on the window's indices), or nullptr for
  /// none; called for each window searched.
  std::function<const ArcDiscount*(const TerrainField& window)> over_window;
  /// Their factors over the grid's cells [c0, c1] x [r0, r1] into `out`, row-major, 1 off the roads.
  std::function<void(int c0, int r0, int c1, int r1, std::vector<float>& out)> over_box;
  /// The reach bound read the factors within an arc's reach of the cells marked in `cells` (over
  /// [c0, c1] x [r0, r1], row-major; nonzero: read).
  std::function<void(int c0, int r0, int c1, int r1, const std::vector<std::uint8_t>& cells)> read;
};
WindowedRoad route_by_windows(const TerrainGrid& grid, const ReadTerrainWindow& read, const CostModel& model, const GraphOptions& graph,
                              Cell from, Cell to, const RoutingOptions& options, const WindowOptions& window, Progress* progress = nullptr,
                              const WindowReuse* reuse = nullptr);

/// The network by windows: route_network with each link routed by route_by_windows on `read`'s
/// windows (the grid, the windows' limit and margin in `window`), on the roads built before it.
/// The links searched at once (links_at_once) share the limits, each taking its part of
/// window.max_cells and max_nodes; a link then left limited (or refused) is searched again alone
/// with all of them, so a road is the same whatever the threads: the grid's, or the whole
/// limit's largest window's answer.
struct NetworkWindows {
  TerrainGrid grid;
  ReadTerrainWindow read;
  WindowOptions window;
  std::size_t max_nodes = 0;  ///< the search nodes the limit allows one link alone (0: RoutingOptions::max_nodes only)
};
/// route_network by windows: `frame` is TerrainField::frame(windows.grid) (the roads' cells are its
/// indices, the layers are drawn on it), `base` a graph on it (its model and options; the searches
/// build theirs on each window). The same roads as route_network on the whole grid, given roads
/// (roads.existing, drawn on the frame) included: they are kept per road cell as the roads built.
NetworkResult route_network_by_windows(const TerrainField& frame, const RoadGraph& base, const std::vector<Link>& links,
                                       const RoutingOptions& options, Progress& progress, const NetworkWindows& windows,
                                       const ExistingRoads* existing = nullptr);

}  // namespace terrapolis::roads
