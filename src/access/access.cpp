// SPDX-License-Identifier: MIT
#include "access/access.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <map>
#include <queue>
#include <string>

#include "core/error.hpp"
#include "core/geodesy.hpp"
#include "hydro/catchment.hpp"
#include "io/crs.hpp"
#include "roads/radix_heap.hpp"
#include "roads/road_class.hpp"

namespace terrapolis::access {
namespace {

/// Moves as (dcol, drow): the 8 neighbours, then the 8 knight's moves.
constexpr std::array<std::array<int, 2>, 16> kMoves = {{{1, 0}, {1, 1}, {0, 1}, {-1, 1}, {-1, 0}, {-1, -1}, {0, -1}, {1, -1},
                                                         {2, 1}, {1, 2}, {-1, 2}, {-2, 1}, {-2, -1}, {-1, -2}, {1, -2}, {2, -1}}};

/// Geodesic length of each move from each row, metres (row-major, 16 per row): east-west at the
/// mean width of the rows it spans, north-south by the meridian arcs between them (CellMetrics),
/// combined by Pythagoras (the exact diagonal for one-cell moves). Moves off the grid get 0.
std::vector<double> move_lengths(const Georef& georef, int cols, int rows) {
  const CellMetrics m = cell_metrics(georef, cols, rows);
  auto width = [&](int r) { return m.width_m[std::size_t(std::clamp(r, 0, rows - 1))]; };
  std::vector<double> out(std::size_t(rows) * kMoves.size(), 0.0);
  for (int row = 0; row < rows; ++row)
    for (std::size_t k = 0; k < kMoves.size(); ++k) {
      const int dcol = kMoves[k][0], drow = kMoves[k][1], r2 = row + drow;
      if (r2 < 0 || r2 >= rows) continue;
      double length;
      if (std::abs(drow) == 1 && std::abs(dcol) == 1) {
        length = m.diagonal_m[std::size_t(drow > 0 ? row + 1 : row)];
      } else {
        double north_south = 0;
        for (int r = std::min(row, r2) + 1; r <= std::max(row, r2); ++r) north_south += m.height_m[std::size_t(r)];
        length = std::hypot(std::abs(dcol) * 0.5 * (width(row) + width(r2)), north_south);
      }
      out[std::size_t(row) * kMoves.size() + k] = length;
    }
  return out;
}

}  // namespace

double tobler_kmh(double dz_dx) { return 6.0 * std::exp(-3.5 * std::fabs(dz_dx + 0.05)); }

RoadCells road_cells(const VectorLayer& roads, const Raster<float>& like, const AccessOptions& options) {
  return road_cells(roads, like, options, like.georef(), 0, 0);
}

RoadCells road_cells(const VectorLayer& roads, const Raster<float>& like, const AccessOptions& options, const Georef& grid, int col0,
                     int row0) {
  RoadCells out{like.like<float>(0.0f), like.like<std::uint8_t>(0)};
  Raster<std::uint8_t> surface = like.like<std::uint8_t>(0);  // a road at the surface passes there
  const int class_field = roads.field_index("class"), structure_field = roads.field_index("structure");
  const GridLocator locator(grid);  // the grid's pixels: every window marks the cells the whole grid would
  bool underground = false;
  auto mark = [&](double col, double row, float kmh) {
    const int c = int(std::floor(col)) - col0, r = int(std::floor(row)) - row0;
    if (!out.kmh.inside(c, r)) return;
    out.kmh(c, r) = std::max(out.kmh(c, r), kmh);
    (underground ? out.tunnel : surface)(c, r) = 1;
  };
  auto text = [](const Feature& f, int field) -> std::string {
    if (field < 0) return {};
    const auto* v = std::get_if<std::string>(&f.values[std::size_t(field)]);
    return v ? *v : std::string();
  };
  for (const auto& f : roads.features) {
    double kmh = options.road_kmh[std::size_t(roads::RoadClass::local)];
    if (const auto c = roads::road_class_named(text(f, class_field))) kmh = options.road_kmh[std::size_t(*c)];
    underground = text(f, structure_field) == "tunnel";
    for (const auto& part : f.parts)
      for (std::size_t k = 0; k < part.size(); ++k) {
        const auto b = locator.crs_to_pixel(part[k][0], part[k][1]);
        if (k == 0) {
          mark(b[0], b[1], float(kmh));
          continue;
        }
        // Samples a quarter of a cell apart: consecutive cells touch by a side or a corner.
        const auto a = locator.crs_to_pixel(part[k - 1][0], part[k - 1][1]);
        const double lo_c = std::min(a[0], b[0]) - col0, hi_c = std::max(a[0], b[0]) - col0;
        const double lo_r = std::min(a[1], b[1]) - row0, hi_r = std::max(a[1], b[1]) - row0;
        if (hi_c < -1 || hi_r < -1 || lo_c > like.cols() + 1 || lo_r > like.rows() + 1) continue;  // off this window
        const int steps = std::max(1, int(std::ceil(4 * std::max(std::fabs(b[0] - a[0]), std::fabs(b[1] - a[1])))));
        for (int s = 1; s <= steps; ++s) {
          const double t = double(s) / steps;
          mark(a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]), float(kmh));
        }
      }
  }
  for (std::size_t i = 0; i < surface.size(); ++i)
    if (surface[i]) out.tunnel[i] = 0;  // a portal, or a surface road crossing over the tunnel
  return out;
}

namespace {

/// A cell reached before the search starts: a destination (0 minutes) or, by tiles, a cell of a
/// neighbouring tile with its time so far.
struct Seed {
  std::size_t cell;  ///< in the window
  double minutes;
  std::int32_t id;
};

/// The cells [c0, c1) x [r0, r1) of a window.
struct Area {
  int c0 = 0, r0 = 0, c1 = 0, r1 = 0;
  bool holds(int c, int r) const { return c >= c0 && r >= r0 && c < c1 && r < r1; }
};

/// One Dijkstra from `seeds`, outward along reversed moves (a move u -> v is timed from u's side:
/// the slope is z_v - z_u over the move's geodesic length) into the cells of `area` only; `w` is the
/// window of the grid whose first cell is the grid's row `row0` (the move lengths are the grid's,
/// per row). A cell's nearest destination is its predecessor's; of two predecessors reaching it at
/// exactly the same time, the smaller id: the same answer whatever the order cells are met in, so
/// a grid searched by tiles gives the whole grid's ids.
void settle(const Raster<float>& dem, const Raster<std::uint8_t>& passable, const RoadCells& roads, int row0, const Area& area, const std::vector<Seed>& seeds, const std::vector<double>& length,
            const AccessOptions& options, std::vector<double>& best, std::vector<std::int32_t>& nearest, std::vector<std::uint8_t>& done,
            ProgressStep* step) {
  const Raster<float>& road_kmh = roads.kmh;
  const int cols = dem.cols();
  const std::size_t moves = options.knight_moves ? 16 : 8;
  auto open = [&](int c, int r) {
    const std::size_t i = dem.index(c, r);
    return road_kmh[i] > 0 || (passable[i] == 1 && !std::isnan(dem[i]));
  };
  best.assign(dem.size(), INFINITY);
  nearest.assign(dem.size(), -1);
  done.assign(dem.size(), 0);
  struct Entry {
    double f;  ///< minutes
    std::size_t cell;
  };
  roads::RadixHeap<Entry> queue;  // Dijkstra's keys only grow
  for (const Seed& s : seeds) {
    const int c = int(s.cell % std::size_t(cols)), r = int(s.cell / std::size_t(cols));
    if (!open(c, r)) continue;
    if (s.minutes < best[s.cell] || (s.minutes == best[s.cell] && s.id < nearest[s.cell])) {
      if (s.minutes < best[s.cell]) queue.push({s.minutes, s.cell});
      best[s.cell] = s.minutes;
      nearest[s.cell] = s.id;
    }
  }
  std::size_t settled = 0;
  while (!queue.empty()) {
    const auto [t, v] = queue.pop();
    if (done[v] || t > best[v]) continue;
    done[v] = 1;
    if (step && (++settled & 0x3ffff) == 0) step->update(std::min(0.99, double(settled) / double(dem.size())));
    const int vc = int(v % std::size_t(cols)), vr = int(v / std::size_t(cols));
    const double zv = dem[v];
    for (std::size_t k = 0; k < moves; ++k) {
      // The move u -> v (towards the destination), from u = v - move.
      const int uc = vc - kMoves[k][0], ur = vr - kMoves[k][1];
      if (!area.holds(uc, ur) || !open(uc, ur)) continue;
      const std::size_t u = dem.index(uc, ur);
      if (done[u]) continue;
      // A knight's move crosses the two cells beside its line: both must be open (no corner cut across water).
      if (k >= 8) {
        const int dc = kMoves[k][0], dr = kMoves[k][1];
        const bool wide = std::abs(dc) == 2;
        const int c1 = wide ? uc + dc / 2 : uc, r1 = wide ? ur : ur + dr / 2;
        const int c2 = wide ? uc + dc / 2 : uc + dc, r2 = wide ? ur + dr : ur + dr / 2;
        if (!open(c1, r1) || !open(c2, r2)) continue;
      }
      const double metres = length[std::size_t(row0 + ur) * kMoves.size() + k];
      double kmh;
      if (road_kmh[u] > 0 && road_kmh[v] > 0) {
        kmh = std::min(road_kmh[u], road_kmh[v]);
      } else {
        if (roads.tunnel[u] || roads.tunnel[v]) continue;  // no way into a tunnel but by its road
        const double zu = dem[u];
        if (std::isnan(zu) || std::isnan(zv)) continue;  // a road cell on nodata: reached only by road
        kmh = options.walk_factor * tobler_kmh((zv - zu) / metres);
      }
      const double arrive = t + metres / (kmh / 0.06);  // km/h -> metres per minute: x 1000 / 60
      if (arrive < best[u]) {
        best[u] = arrive;
        nearest[u] = nearest[v];
        queue.push({arrive, u});
      } else if (arrive == best[u] && nearest[v] < nearest[u]) {
        nearest[u] = nearest[v];
      }
    }
  }
}

void check_options(const AccessOptions& options) {
  if (!(options.walk_factor > 0) || !std::isfinite(options.walk_factor)) throw bad_input("/access/walk_factor: must be a positive number");
  for (double v : options.road_kmh)
    if (!(v > 0) || !std::isfinite(v)) throw bad_input("/access/road_kmh: every speed must be a positive number of km/h");
}

/// The area's times and ids as an AccessResult on the area's own grid (`georef`), and its land
/// cells that reach no destination.
AccessResult area_result(const Raster<float>& dem, const Raster<std::uint8_t>& passable, const Area& a, const Georef& georef, const std::vector<double>& best,
                         const std::vector<std::int32_t>& nearest, const std::vector<std::uint8_t>& done) {
  const int cols = a.c1 - a.c0, rows = a.r1 - a.r0;
  AccessResult out{Raster<float>(cols, rows, georef, NAN), Raster<std::int32_t>(cols, rows, georef, -1), 0};
  out.nearest.nodata = -1;
  for (int r = a.r0; r < a.r1; ++r)
    for (int c = a.c0; c < a.c1; ++c) {
      const std::size_t i = dem.index(c, r);
      if (done[i]) {
        out.minutes(c - a.c0, r - a.r0) = float(best[i]);
        out.nearest(c - a.c0, r - a.r0) = nearest[i];
      } else if (passable[i] == 1 && !std::isnan(dem[i])) {
        ++out.unreachable_land;
      }
    }
  return out;
}

}  // namespace

AccessResult travel_time(const Raster<float>& dem, const Raster<std::uint8_t>& passable, const RoadCells& roads,
                         const std::vector<Destination>& destinations, const AccessOptions& options, Progress& progress) {
  const int cols = dem.cols(), rows = dem.rows();
  if (passable.cols() != cols || passable.rows() != rows || roads.kmh.cols() != cols || roads.kmh.rows() != rows ||
      roads.tunnel.cols() != cols || roads.tunnel.rows() != rows)
    throw bad_input("access: the water mask or the roads are not on the DEM's grid");
  check_options(options);
  const std::vector<double> length = move_lengths(dem.georef(), cols, rows);
  std::vector<Seed> seeds;
  for (const auto& d : destinations)
    if (dem.inside(d.col, d.row)) seeds.push_back({dem.index(d.col, d.row), 0.0, d.id});
  std::vector<double> best;
  std::vector<std::int32_t> nearest;
  std::vector<std::uint8_t> done;
  ProgressStep step(progress, "access");
  const Area whole{0, 0, cols, rows};
  settle(dem, passable, roads, 0, whole, seeds, length, options, best, nearest, done, &step);
  return area_result(dem, passable, whole, dem.georef(), best, nearest, done);
}

namespace {

/// Where a tile keeps the cells its neighbours' searches start from: the two outer rows and columns
/// (a knight's move reaches two cells), all of a tile of 4 or fewer rows or columns.
struct Frame {
  int w = 0, h = 0;
  std::vector<double> minutes;  ///< empty until the tile is searched
  std::vector<std::int32_t> id;
  bool all() const { return w <= 4 || h <= 4; }
  std::size_t size() const { return all() ? std::size_t(w) * std::size_t(h) : std::size_t(4 * w + 4 * (h - 4)); }
  /// Stores the tile's searched times and ids (`dem`'s window, the tile its `area`) on the frame;
  /// returns, for each neighbour [dy + 1][dx + 1], the earliest time among the changed cells its
  /// window reads (INFINITY: none changed).
  using Changes = std::array<std::array<double, 3>, 3>;
  Changes store(const Raster<float>& dem, const Area& area, const std::vector<double>& best, const std::vector<std::int32_t>& nearest,
                const std::vector<std::uint8_t>& done) {
    if (minutes.empty()) minutes.assign(size(), INFINITY), id.assign(size(), -1);
    Changes changed;
    for (auto& row : changed) row.fill(INFINITY);
    for (int r = 0; r < h; ++r)
      for (int c = 0; c < w; ++c) {
        const int k = slot(c, r);
        if (k < 0) continue;
        const std::size_t i = dem.index(area.c0 + c, area.r0 + r);
        const double m = done[i] ? best[i] : INFINITY;
        const std::int32_t cell_id = done[i] ? nearest[i] : -1;
        if (m == minutes[std::size_t(k)] && cell_id == id[std::size_t(k)]) continue;
        minutes[std::size_t(k)] = m, id[std::size_t(k)] = cell_id;
        for (int dy = -1; dy <= 1; ++dy)  // the neighbours whose windows hold this cell
          for (int dx = -1; dx <= 1; ++dx) {
            if ((dx < 0 && c >= 2) || (dx > 0 && c < w - 2) || (dy < 0 && r >= 2) || (dy > 0 && r < h - 2)) continue;
            changed[std::size_t(dy + 1)][std::size_t(dx + 1)] = std::min(changed[std::size_t(dy + 1)][std::size_t(dx + 1)], m);
          }
      }
    return changed;
  }
  /// The slot of the tile's cell (c, r), or -1 when it is not on the frame.
  int slot(int c, int r) const {
    if (all() || r < 2) return r * w + c;
    if (r >= h - 2) return (r - h + 4) * w + c;
    const int base = 4 * w + (r - 2) * 4;
    if (c < 2) return base + c;
    if (c >= w - 2) return base + 2 + c - (w - 2);
    return -1;
  }
};

}  // namespace

TiledAccess travel_time_by_tiles(const Georef& georef, int cols, int rows, int tile_size, const ReadAccessWindow& read,
                                 const std::vector<Destination>& destinations, const AccessOptions& options, const WriteAccessTile& write,
                                 Progress& progress) {
  check_options(options);
  // A knight's move reaches two cells: from tiles of 2 or more it reaches only the next tiles.
  if (tile_size < 2) throw bad_input("access by tiles: the tile size must be at least 2 cells");
  const std::vector<double> length = move_lengths(georef, cols, rows);
  const int across = (cols + tile_size - 1) / tile_size, down = (rows + tile_size - 1) / tile_size;
  const std::size_t tiles = std::size_t(across) * std::size_t(down);
  std::vector<Frame> frames(tiles);
  std::vector<std::vector<Destination>> in_tile(tiles);
  for (std::size_t t = 0; t < tiles; ++t) {
    const int tx = int(t % std::size_t(across)), ty = int(t / std::size_t(across));
    frames[t].w = std::min(tile_size, cols - tx * tile_size);
    frames[t].h = std::min(tile_size, rows - ty * tile_size);
  }
  for (const Destination& d : destinations)
    if (d.col >= 0 && d.row >= 0 && d.col < cols && d.row < rows)
      in_tile[std::size_t(d.row / tile_size) * std::size_t(across) + std::size_t(d.col / tile_size)].push_back(d);

  TiledAccess report;
  report.tiles = tiles;
  std::vector<double> best;
  std::vector<std::int32_t> nearest;
  std::vector<std::uint8_t> done;
  // Searches tile t on its frames' times so far: its window (the tile and two cells around) read,
  // the neighbours' frame cells in it as seeds, its destinations at 0.
  auto search = [&](std::size_t t, AccessWindow& w, Area& area) {
    const int tx = int(t % std::size_t(across)), ty = int(t / std::size_t(across));
    const int x0 = tx * tile_size, y0 = ty * tile_size, x1 = x0 + frames[t].w, y1 = y0 + frames[t].h;
    const int wc0 = std::max(0, x0 - 2), wr0 = std::max(0, y0 - 2);
    const int wc1 = std::min(cols, x1 + 2), wr1 = std::min(rows, y1 + 2);
    w = read(wc0, wr0, wc1 - wc0, wr1 - wr0);
    area = {x0 - wc0, y0 - wr0, x1 - wc0, y1 - wr0};
    std::vector<Seed> seeds;
    for (const Destination& d : in_tile[t]) seeds.push_back({w.dem.index(d.col - wc0, d.row - wr0), 0.0, d.id});
    for (int r = wr0; r < wr1; ++r)
      for (int c = wc0; c < wc1; ++c) {
        if (c >= x0 && c < x1 && r >= y0 && r < y1) continue;
        const std::size_t u = std::size_t(r / tile_size) * std::size_t(across) + std::size_t(c / tile_size);
        const Frame& f = frames[u];
        if (f.minutes.empty()) continue;
        const int k = f.slot(c % tile_size, r % tile_size);
        if (k >= 0 && f.minutes[std::size_t(k)] < INFINITY)
          seeds.push_back({w.dem.index(c - wc0, r - wr0), f.minutes[std::size_t(k)], f.id[std::size_t(k)]});
      }
    settle(w.dem, w.passable, w.roads, wr0, area, seeds, length, options, best, nearest, done, nullptr);
    ++report.tile_runs;
  };

  // Tiles by the earliest time a change reached them (a Dijkstra over tiles): a tile is searched
  // again whenever a neighbour's frame improves, until no frame changes; times only fall, so it ends.
  std::vector<double> pending(tiles, INFINITY);
  struct Item {
    double key;
    std::size_t tile;
    bool operator>(const Item& o) const { return key > o.key || (key == o.key && tile > o.tile); }
  };
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> queue;
  for (std::size_t t = 0; t < tiles; ++t)
    if (!in_tile[t].empty()) pending[t] = 0, queue.push({0.0, t});
  ProgressStep step(progress, "access");
  AccessWindow w;
  Area area;
  // Each search's result is written at once: a tile's last search saw its neighbours' final frames
  // (a change to any of them would have queued it again), so its last write is final.
  std::vector<std::size_t> unreachable(tiles, 0);
  std::vector<bool> searched(tiles, false);
  auto write_tile = [&](std::size_t t) {
    const int tx = int(t % std::size_t(across)), ty = int(t / std::size_t(across));
    AccessResult tile = area_result(w.dem, w.passable, area, georef.window(tx * tile_size, ty * tile_size), best, nearest, done);
    unreachable[t] = tile.unreachable_land;
    searched[t] = true;
    write(tx * tile_size, ty * tile_size, std::move(tile));
  };
  while (!queue.empty()) {
    const Item item = queue.top();
    queue.pop();
    if (item.key != pending[item.tile]) continue;
    pending[item.tile] = INFINITY;
    const std::size_t t = item.tile;
    search(t, w, area);
    write_tile(t);
    const int tx = int(t % std::size_t(across)), ty = int(t / std::size_t(across));
    const Frame::Changes changed = frames[t].store(w.dem, area, best, nearest, done);
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        const int nx = tx + dx, ny = ty + dy;
        const double m = changed[std::size_t(dy + 1)][std::size_t(dx + 1)];
        if ((dx == 0 && dy == 0) || nx < 0 || ny < 0 || nx >= across || ny >= down || m == INFINITY) continue;
        const std::size_t n = std::size_t(ny) * std::size_t(across) + std::size_t(nx);
        if (m < pending[n]) pending[n] = m, queue.push({pending[n], n});
      }
    step.update(0.5 * double(report.tile_runs) / double(report.tile_runs + queue.size() + 1));
  }
  // The tiles no time reached (no destination, no neighbour's frame ever changed towards them):
  // searched from no seed, for their unreachable land.
  for (std::size_t t = 0; t < tiles; ++t) {
    if (!searched[t]) {
      search(t, w, area);
      write_tile(t);
    }
    report.unreachable_land += unreachable[t];
    step.update(0.5 + 0.5 * double(t + 1) / double(tiles));
  }
  for (const Frame& f : frames) report.frame_bytes += f.minutes.size() * (sizeof(double) + sizeof(std::int32_t));
  return report;
}

CoverageCount::CoverageCount(std::vector<double> thresholds_minutes) : thresholds_(std::move(thresholds_minutes)) {
  c_.within_people.assign(thresholds_.size(), 0.0);
}

std::uint32_t CoverageCount::bucket(float minutes) { return std::bit_cast<std::uint32_t>(minutes) >> 12; }  // times are >= 0

void CoverageCount::count(const float* minutes, const float* people, std::size_t cells) {
  for (std::size_t i = 0; i < cells; ++i) {
    const double p = people[i];
    if (!(p > 0)) continue;
    c_.total_people += p;
    if (std::isnan(minutes[i])) {
      c_.unreachable_people += p;
      continue;
    }
    for (std::size_t k = 0; k < thresholds_.size(); ++k)
      if (minutes[i] <= thresholds_[k]) c_.within_people[k] += p;
    sum_ += double(minutes[i]) * p, weight_ += p;
    const std::uint32_t b = bucket(minutes[i]);
    if (b >= people_by_bucket_.size()) people_by_bucket_.resize(std::size_t(b) + 1, 0.0);
    people_by_bucket_[b] += p;
  }
}

bool CoverageCount::percentile_pass() {
  if (!(weight_ > 0)) return false;
  double seen = 0;
  for (std::size_t b = 0; b < people_by_bucket_.size(); ++b) {
    bucket_ = std::uint32_t(b);
    if (seen + people_by_bucket_[b] >= 0.9 * weight_ && people_by_bucket_[b] > 0) break;
    seen += people_by_bucket_[b];
  }
  before_ = seen;
  std::vector<double>().swap(people_by_bucket_);
  return true;
}

void CoverageCount::collect(const float* minutes, const float* people, std::size_t cells) {
  for (std::size_t i = 0; i < cells; ++i)
    if (people[i] > 0 && !std::isnan(minutes[i]) && bucket(minutes[i]) == bucket_) in_bucket_.push_back({minutes[i], double(people[i])});
}

Coverage CoverageCount::finish() {
  if (weight_ > 0) {
    c_.mean_minutes = sum_ / weight_;
    std::sort(in_bucket_.begin(), in_bucket_.end());
    double seen = before_;
    for (const auto& [m, p] : in_bucket_) {
      c_.p90_minutes = m;  // the bucket's last time if the sums' rounding never reaches the share
      if ((seen += p) >= 0.9 * weight_) break;
    }
  }
  return c_;
}

Coverage coverage(const Raster<float>& minutes, const Raster<float>& people, const std::vector<double>& thresholds_minutes) {
  if (minutes.cols() != people.cols() || minutes.rows() != people.rows())
    throw bad_input("access: the population raster is not on the DEM's grid");
  CoverageCount count(thresholds_minutes);
  count.count(minutes.data(), people.data(), minutes.size());
  if (count.percentile_pass()) count.collect(minutes.data(), people.data(), minutes.size());
  return count.finish();
}

void CatchmentSums::add(const Raster<std::int32_t>& nearest, const Raster<float>& minutes, const Raster<float>& weight,
                        const std::vector<double>& area_m2, int row0) {
  for (int r = 0; r < nearest.rows(); ++r)
    for (int c = 0; c < nearest.cols(); ++c) {
      const std::int32_t id = nearest(c, r);
      if (id < 0) continue;
      Figures& f = by_id_[id];
      f.area_m2 += area_m2[std::size_t(row0 + r)];
      const double p = weight(c, r);
      if (p > 0) f.people += p, f.minutes_people += p * double(minutes(c, r));
    }
}

VectorLayer CatchmentSums::layer(std::vector<std::pair<std::int32_t, Feature>> polygons, const std::string& counted,
                                 const std::vector<Settlement>& settlements, const Crs& crs) const {
  std::map<std::int32_t, double> population;
  for (const Settlement& s : settlements) population[s.at.id] = s.population;
  VectorLayer layer;
  layer.name = "access_catchments";
  layer.geometry = GeometryType::polygon;
  layer.crs = crs;
  layer.fields = {{"id", FieldType::integer}, {"population", FieldType::integer}, {counted, FieldType::real},
                  {"area_km2", FieldType::real}, {"mean_minutes", FieldType::real}};
  for (auto& [id, feature] : polygons) {
    const auto it = by_id_.find(id);
    const Figures f = it == by_id_.end() ? Figures{} : it->second;
    feature.values = {std::int64_t(id), std::int64_t(std::llround(population[id])), std::round(f.people * 100) / 100,
                      std::round(f.area_m2 / 1e4) / 100,
                      f.people > 0 ? FieldValue(std::round(f.minutes_people / f.people * 10) / 10) : FieldValue(std::monostate{})};
    layer.features.push_back(std::move(feature));
  }
  return layer;
}

VectorLayer catchments_layer(const AccessResult& times, const Raster<float>& weight, const std::string& counted,
                             const std::vector<Settlement>& settlements) {
  const Raster<std::int32_t>& nearest = times.nearest;
  CatchmentSums sums;
  sums.add(nearest, times.minutes, weight, cell_metrics(nearest.georef(), nearest.cols(), nearest.rows()).area_m2, 0);
  return sums.layer(hydro::polygonize_labels(nearest), counted, settlements, nearest.georef().crs);
}

void for_each_level(const Raster<float>& dem, const Raster<std::uint8_t>& passable, const RoadCells& roads,
                    const std::vector<Settlement>& settlements, const std::vector<double>& levels,
                    const std::vector<double>& thresholds_minutes, const Raster<float>& people, const AccessOptions& options,
                    Progress& progress, const std::function<void(const LevelFigures&)>& use) {
  for (const double level : levels) {
    std::vector<Destination> to;
    for (const Settlement& s : settlements)
      if (s.population >= level) to.push_back(s.at);
    if (to.empty()) continue;
    LevelFigures f;
    f.level = level;
    f.key = level > 0 ? std::to_string(std::llround(level)) : "all";
    f.destinations = to.size();
    f.times = travel_time(dem, passable, roads, to, options, progress);
    f.coverage = coverage(f.times.minutes, people, thresholds_minutes);
    use(f);
  }
}

}  // namespace terrapolis::access
