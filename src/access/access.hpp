// Accessibility: travel time from every cell to the nearest settlement, off-road on foot and on
// the roads at their class speeds, and who lives within 15, 30, 60 minutes (docs/access.md).
// SPDX-License-Identifier: MIT
#pragma once
#include <array>
#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "core/progress.hpp"
#include "core/raster.hpp"
#include "io/vector_io.hpp"

namespace terrapolis::access {

/// Speeds of the friction surface.
struct AccessOptions {
  /// Off-road walking: Tobler's hiking function (Tobler 1993, "Three presentations on geographical
  /// analysis and modeling", NCGIA TR 93-1): v = 6 exp(-3.5 |S + 0.05|) km/h on a path, S the
  /// signed slope dz/dx along the move (5.04 km/h on the flat, fastest 6 km/h at 2.86 degrees
  /// downhill), times this factor off paths (Tobler: 3/5).
  double walk_factor = 0.6;
  /// Road speeds, km/h, per class in roads::kRoadClasses order: motorway, national, departmental,
  /// local, maritime (a ferry link). Bridges and tunnels carry their road's speed.
  std::array<double, 5> road_kmh = {110, 80, 60, 40, 20};
  /// Moves: 8 neighbours, or 16 (adding knight's moves, as r.walk -k): the direction error of a
  /// straight walk drops from 8 % to under 3 %.
  bool knight_moves = true;
};

/// Tobler's hiking function on a path, km/h, at signed slope `dz_dx` (uphill positive).
double tobler_kmh(double dz_dx);

/// A destination of the search: a settlement's cell and its id (the value of the nearest raster).
struct Destination {
  int col = 0, row = 0;
  std::int32_t id = 0;
};

struct AccessResult {
  Raster<float> minutes;            ///< to the nearest destination; NaN: nodata, water, or no way there
  Raster<std::int32_t> nearest;     ///< id of that destination; -1 where minutes is NaN
  std::size_t unreachable_land = 0; ///< land cells (not water, not nodata) from which no destination is reached
};

/// The roads on the grid.
struct RoadCells {
  Raster<float> kmh;              ///< speed of the fastest road through the cell, km/h; 0: no road
  Raster<std::uint8_t> tunnel;    ///< 1: only tunnels pass there (entered and left by road only)
};

/// Every line of `roads` (in the grid's CRS, as read_vector gives it) drawn onto the grid of
/// `like` with 8-connected cells: a `class` field naming a roads::kRoadClasses class sets its speed
/// (lines without one are local roads), a `structure` field "tunnel" marks it underground.
RoadCells road_cells(const VectorLayer& roads, const Raster<float>& like, const AccessOptions& options);
/// The same on a window of `grid` whose first cell is the grid's (col0, row0): the lines are drawn
/// in the grid's pixels, so a window marks exactly the cells the whole grid would.
RoadCells road_cells(const VectorLayer& roads, const Raster<float>& like, const AccessOptions& options, const Georef& grid, int col0,
                     int row0);

/// Travel times to the nearest of `destinations` by one multi-source Dijkstra over the grid,
/// from the destinations outward along reversed moves (a move u -> v is timed from u's side: the
/// slope is z_v - z_u over the move's geodesic length). `dem`: metres, NaN nodata (impassable);
/// `passable`: 1 where one may walk (land), 0 water; a road cell is passable whatever the water
/// (bridges, ferries) and a move between two road cells runs at the slower of their speeds; any
/// other move walks, and never into or out of a tunnel. A cell reached at exactly the same time from
/// two destinations goes to the smaller id (whatever order the search meets them in).
AccessResult travel_time(const Raster<float>& dem, const Raster<std::uint8_t>& passable, const RoadCells& roads,
                         const std::vector<Destination>& destinations, const AccessOptions& options, Progress& progress);

/// What travel_time reads of the grid's cells [col0, col0 + cols) x [row0, row0 + rows): the DEM,
/// where one may walk, the roads (each on the window's own grid).
struct AccessWindow {
  Raster<float> dem;
  Raster<std::uint8_t> passable;
  RoadCells roads;
};
using ReadAccessWindow = std::function<AccessWindow(int col0, int row0, int cols, int rows)>;
/// A tile's times (AccessResult on the tile's own grid, whose first cell is the grid's (col0, row0)).
using WriteAccessTile = std::function<void(int col0, int row0, AccessResult&& tile)>;

struct TiledAccess {
  std::size_t tiles = 0;
  std::size_t tile_runs = 0;         ///< searches of a tile (each tile at least once), each written
  std::size_t unreachable_land = 0;  ///< as AccessResult's
  std::size_t frame_bytes = 0;       ///< what the tiles' frames hold between searches
};

/// travel_time by tiles of `tile_size` (2 or more) cells of a grid of cols x rows (`georef`): each tile is
/// searched on a window of two more cells around it (a knight's move), from its destinations and
/// the times its neighbours' searches gave their two outer rows and columns (each tile's frame,
/// the only state kept between searches); a tile whose neighbours' frames improve is searched
/// again, the earliest change first, until no frame changes. Times only fall, and each tile's
/// search is exact on its frame's times, so they end as the whole grid's, bit for bit; the ids
/// too (ties go to the smaller id). Each search's tile is written at once (`write`: a tile may be
/// written several times, the last is final: that search saw its neighbours' final frames).
TiledAccess travel_time_by_tiles(const Georef& georef, int cols, int rows, int tile_size, const ReadAccessWindow& read,
                                 const std::vector<Destination>& destinations, const AccessOptions& options, const WriteAccessTile& write,
                                 Progress& progress);

/// Who lives how far: `people` per cell (NaN or <= 0: nobody) against `minutes`.
struct Coverage {
  double total_people = 0;
  std::vector<double> within_people;  ///< people within each threshold (minutes <= t), thresholds' order
  double unreachable_people = 0;      ///< people on cells with no time (no way to any destination)
  double mean_minutes = 0;            ///< population-weighted, over the reached people
  double p90_minutes = 0;             ///< population-weighted 90th percentile, over the reached people
};
Coverage coverage(const Raster<float>& minutes, const Raster<float>& people, const std::vector<double>& thresholds_minutes);

/// coverage() over a grid read by bands of whole rows, in order: count() every band, then, if
/// percentile_pass(), collect() every band again; finish() gives coverage()'s figures bit for bit
/// (coverage() is this on one band). The 90th percentile is found in two passes: the people per
/// bucket of times (the float's top 20 bits), then the times of the one bucket it falls in, sorted.
class CoverageCount {
 public:
  explicit CoverageCount(std::vector<double> thresholds_minutes);
  void count(const float* minutes, const float* people, std::size_t cells);
  bool percentile_pass();
  void collect(const float* minutes, const float* people, std::size_t cells);
  Coverage finish();

 private:
  static std::uint32_t bucket(float minutes);
  std::vector<double> thresholds_;
  Coverage c_;
  double sum_ = 0, weight_ = 0, before_ = 0;
  std::vector<double> people_by_bucket_;
  std::uint32_t bucket_ = 0;
  std::vector<std::pair<float, double>> in_bucket_;
};

/// A settlement as a destination of a size level: its cell, id and people.
struct Settlement {
  Destination at;
  double population = 0;
};

/// The catchment of each settlement reached (the cells nearest to it in time) as polygons, in the
/// DEM's CRS: fields id (cities.geojson), population (the settlement's), `counted` (the sum of
/// `weight` over the catchment: "people", or "land_km2" when the weight is each cell's land area),
/// area_km2 (geodesic), mean_minutes (weighted by `weight`; null where it sums to 0). A catchment
/// that water or an unreached area splits has one feature per part, each with the whole
/// catchment's figures.
VectorLayer catchments_layer(const AccessResult& times, const Raster<float>& weight, const std::string& counted,
                             const std::vector<Settlement>& settlements);

/// catchments_layer's figures summed by bands of whole rows (in order, so the same bits), and the
/// layer from them and the catchments' polygons (hydro::polygonize_labels of the ids).
class CatchmentSums {
 public:
  /// The band's ids, times and weights (one raster's rows [row0, row0 + rows)), `area_m2` the
  /// whole grid's cell areas per row (CellMetrics::area_m2).
  void add(const Raster<std::int32_t>& nearest, const Raster<float>& minutes, const Raster<float>& weight, const std::vector<double>& area_m2,
           int row0);
  VectorLayer layer(std::vector<std::pair<std::int32_t, Feature>> polygons, const std::string& counted, const std::vector<Settlement>& settlements,
                    const Crs& crs) const;

 private:
  struct Figures {
    double people = 0, area_m2 = 0, minutes_people = 0;
  };
  std::map<std::int32_t, Figures> by_id_;
};

/// What one size level gives: the settlements of at least `level` people as destinations.
struct LevelFigures {
  double level = 0;              ///< 0: every settlement
  std::string key;               ///< "all", or the level in people ("10000"): the figures' key and file suffix
  std::size_t destinations = 0;
  AccessResult times;
  Coverage coverage;             ///< of `people` against the times
};

/// For each of `levels` (people, increasing) that some settlement reaches, travel_time to those
/// settlements and coverage of `people`; `use` gets each level in turn (its rasters are then freed).
void for_each_level(const Raster<float>& dem, const Raster<std::uint8_t>& passable, const RoadCells& roads,
                    const std::vector<Settlement>& settlements, const std::vector<double>& levels,
                    const std::vector<double>& thresholds_minutes, const Raster<float>& people, const AccessOptions& options,
                    Progress& progress, const std::function<void(const LevelFigures&)>& use);

}  // namespace terrapolis::access
