// Tile engine: Barnes 2016 filling, cross-tile flats, Barnes 2017 accumulation, tile by tile.
// SPDX-License-Identifier: MIT
#include "hydro/tiled/tiled_hydro.hpp"

#include <tbb/global_control.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <type_traits>
#include <deque>
#include <filesystem>
#include <fstream>
#include <limits>
#include <mutex>
#include <numeric>
#include <unordered_map>

#include "core/error.hpp"
#include "core/geodesy.hpp"
#include "hydro/catchment.hpp"
#include "hydro/depressions.hpp"
#include "hydro/exact_accumulation.hpp"
#include "hydro/flood_queue.hpp"
#include "hydro/flow_directions.hpp"
#include "hydro/grid.hpp"
#include "hydro/spill_graph.hpp"

namespace terrapolis::hydro::tiled {
namespace {

constexpr std::uint32_t kVoid = 0xFFFFFFFFu, kOpen = 0xFFFFFFFEu;  // labels: nodata, not reached yet

std::vector<int> bounds(int n, int tile_size) {
  const int parts = std::max(1, (n + tile_size - 1) / tile_size);
  std::vector<int> b(std::size_t(parts) + 1);
  for (int i = 0; i <= parts; ++i) b[std::size_t(i)] = int(std::int64_t(n) * i / parts);
  return b;
}

bool out_code(std::uint8_t v) { return v == kNoData || v == kTerminal; }  // drain_flats' "outside" cells

/// The cells of a tile within two of its edges (where neighbouring tiles look): filled values
/// and global labels after the first pass.
class Frame {
 public:
  Frame() = default;
  /// The shape only, or with room for the values.
  explicit Frame(const TileRect& r, bool with_values = true) : cols_(r.cols), rows_(r.rows) {
    if (!with_values) return;
    z.resize(size());
    label.resize(size());
  }
  std::size_t size() const {
    return whole() ? std::size_t(cols_) * std::size_t(rows_) : std::size_t(4) * (std::size_t(cols_) + std::size_t(rows_) - 4);
  }
  bool contains(int c, int r) const { return std::min({c, r, cols_ - 1 - c, rows_ - 1 - r}) < 2; }
  std::size_t index(int c, int r) const {
    if (whole()) return std::size_t(r) * std::size_t(cols_) + std::size_t(c);
    if (r < 2) return std::size_t(r) * std::size_t(cols_) + std::size_t(c);
    if (r >= rows_ - 2) return std::size_t(2 + r - (rows_ - 2)) * std::size_t(cols_) + std::size_t(c);
    return std::size_t(4) * std::size_t(cols_) + std::size_t(r - 2) * 4 + std::size_t(c < 2 ? c : 2 + c - (cols_ - 2));
  }
  std::vector<float> z;
  std::vector<std::uint32_t> label;  // global

 private:
  bool whole() const { return cols_ < 4 || rows_ < 4; }
  int cols_ = 0, rows_ = 0;
};

/// One tile filled with its edges as outlets (Barnes 2016, first stage): every cell labelled
/// with the seed that flooded it (0: a true outlet), and the lowest spill between labels.
struct TileFill {
  Dem z;                             // the tile's cells, filled
  std::vector<std::uint32_t> label;  // local labels, kVoid on nodata
  std::uint32_t labels = 1;          // local labels used (0 included)
  std::vector<SpillEdge> edges;      // local labels
};

/// `window` is the tile with a halo of one cell (NaN outside the mosaic), so that a cell next to
/// nodata in a neighbouring tile, or on the mosaic's border, is a true outlet as in the whole grid.
TileFill fill_tile(const Dem& window, const std::optional<double>& sea_level) {
  const int cols = window.cols() - 2, rows = window.rows() - 2;
  TileFill f;
  f.z = Dem(cols, rows, shifted(window.georef(), 1, 1));
  for (int r = 0; r < rows; ++r) std::copy_n(&window(1, r + 1), cols, &f.z(0, r));
  f.label.assign(f.z.size(), kOpen);
  Dem& z = f.z;
  RadixQueue open;
  std::deque<std::uint32_t> pit;
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) {
      const std::size_t i = z.index(c, r);
      if (std::isnan(z[i])) {
        f.label[i] = kVoid;
        continue;
      }
      bool outlet = is_sea(z[i], sea_level);
      for (int k = 0; k < 8 && !outlet; ++k) outlet = std::isnan(window(c + 1 + dcol[k], r + 1 + drow[k]));
      if (outlet) {
        f.label[i] = 0;
      } else if (r == 0 || c == 0 || r == rows - 1 || c == cols - 1) {
        f.label[i] = f.labels++;
      } else {
        continue;
      }
      open.push(flood_key(z[i], std::uint32_t(i)));
    }
  while (!open.empty() || !pit.empty()) {
    const std::uint32_t i = next_cell(open, pit);
    flood_neighbours(i, cols, 0, rows, z, f.label.data(), kOpen, kVoid, open, pit,
                     [&](std::uint32_t a, std::uint32_t b, float spill) { f.edges.push_back({a, b, spill}); });
    if (f.edges.size() > (std::size_t(1) << 20)) keep_lowest_edges(f.edges);
  }
  keep_lowest_edges(f.edges);
  return f;
}

/// Union-find over the cells of flats that cross tile edges.
struct Sets {
  std::vector<std::uint32_t> parent;
  std::uint32_t find(std::uint32_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  }
  void join(std::uint32_t a, std::uint32_t b) {
    a = find(a);
    b = find(b);
    if (a != b) parent[std::max(a, b)] = std::min(a, b);
  }
};

/// A cell given to the global flat resolution: its filled value and first-pass D8 code, and
/// whether it belongs to a flat that reaches beyond its tile.
struct SharedCell {
  float z;
  std::uint8_t code;
  bool member;
};
struct SharedEntry {
  std::int64_t cell;  // mosaic index
  SharedCell value;
};

/// A cell of the stream network, as a tile hands it on.
struct StreamCell {
  std::int64_t index;
  double area_m2;
  std::uint8_t code;
};

/// A flow path leaving a tile (Barnes 2017): the last cell in the tile, what it has gathered
/// inside the tile, and the cell of the next tile it flows into.
struct Link {
  std::int64_t exit, target;
  std::int64_t local;
};

void write_codes(const std::string& path, const Raster<std::uint8_t>& d8) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(d8.data()), std::streamsize(d8.size()));
  if (!out) throw bad_input(path + ": cannot write scratch data (disk full?)");
}

void read_codes(const std::string& path, Raster<std::uint8_t>& d8) {
  std::ifstream in(path, std::ios::binary);
  in.read(reinterpret_cast<char*>(d8.data()), std::streamsize(d8.size()));
  if (!in) throw bad_input(path + ": cannot read scratch data back");
}

/// Vectors of plain values appended to a tile's bytes for TileDriver::share (count, then values).
template <class T>
void put(std::vector<char>& bytes, const std::vector<T>& v) {
  static_assert(std::is_trivially_copyable_v<T>);
  const std::uint64_t n = v.size();
  const char* count = reinterpret_cast<const char*>(&n);
  bytes.insert(bytes.end(), count, count + sizeof n);
  bytes.insert(bytes.end(), reinterpret_cast<const char*>(v.data()), reinterpret_cast<const char*>(v.data() + v.size()));
}

/// The vectors of a tile's bytes, in the order they were put.
class Unpack {
 public:
  explicit Unpack(const std::vector<char>& bytes) : bytes_(bytes) {}
  template <class T>
  std::vector<T> take() {
    std::uint64_t n = 0;
    if (at_ + sizeof n > bytes_.size()) throw processing_error("tiles: truncated message from another process");
    std::memcpy(&n, bytes_.data() + at_, sizeof n);
    at_ += sizeof n;
    if (n > (bytes_.size() - at_) / sizeof(T)) throw processing_error("tiles: truncated message from another process");
    std::vector<T> v(n);
    std::memcpy(v.data(), bytes_.data() + at_, n * sizeof(T));
    at_ += n * sizeof(T);
    return v;
  }

 private:
  const std::vector<char>& bytes_;
  std::size_t at_ = 0;
};

}  // namespace

Georef shifted(const Georef& g, int col0, int row0) {
  Georef out = g;
  const GeoTransform& t = g.transform;
  out.transform[0] = t[0] + col0 * t[1] + row0 * t[2];
  out.transform[3] = t[3] + col0 * t[4] + row0 * t[5];
  return out;
}

TileGrid::TileGrid(int cols, int rows, int tile_size)
    : col_bounds_(bounds(cols, std::max(tile_size, 8))), row_bounds_(bounds(rows, std::max(tile_size, 8))) {}

TileRect TileGrid::rect(int tile) const {
  const int i = tile % across(), j = tile / across();
  return {col_bounds_[std::size_t(i)], row_bounds_[std::size_t(j)], col_bounds_[std::size_t(i) + 1] - col_bounds_[std::size_t(i)],
          row_bounds_[std::size_t(j) + 1] - row_bounds_[std::size_t(j)]};
}

int TileGrid::tile_of(int col, int row) const {
  const int i = int(std::upper_bound(col_bounds_.begin(), col_bounds_.end(), col) - col_bounds_.begin()) - 1;
  const int j = int(std::upper_bound(row_bounds_.begin(), row_bounds_.end(), row) - row_bounds_.begin()) - 1;
  return j * across() + i;
}

namespace {
/// Global state per tile and cell of its side, at worst (every edge cell its own label): frames
/// (two rings: float + label, 64), exits of the edge cells (32), labels (4 a side, 12 bytes each:
/// 48) and their spill edges (about 4 a label, 28 bytes each in list and adjacency: 448).
constexpr double kGlobalBytesPerTileSide = 600;
}  // namespace

int allowed_threads() {
  return int(tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism));
}

int tile_size_for(int cols, int rows, double memory_limit_mb, int concurrent) {
  const double limit = memory_limit_mb * 1e6;
  for (int side = 1 << 15; side >= 64; side = side * 7 / 8) {
    const TileGrid grid(cols, rows, side);
    const double tile = kTileBytesPerCell * double(side + 4) * double(side + 4) * concurrent;
    const double global = kGlobalBytesPerTileSide * double(grid.count()) * double(side) + 40.0 * rows;
    if (tile + global <= limit) return side;
  }
  throw bad_input("--memory-limit: " + std::to_string(int(memory_limit_mb)) + " MB is too little for tiles of 64 x 64 cells on a " +
                  std::to_string(cols) + " x " + std::to_string(rows) + " mosaic");
}

TiledReport run_tiled_hydro(int cols, int rows, const Georef& georef, const ReadWindow& read, const TiledOptions& options,
                            const TileSinks& sinks, Progress& progress, TileDriver& driver) {
  namespace fs = std::filesystem;
  TiledReport report;
  report.concurrent_tiles = options.concurrent_tiles > 0 ? options.concurrent_tiles : allowed_threads();
  report.tile_size = options.tile_size > 0 ? std::max(options.tile_size, 8)
                                           : tile_size_for(cols, rows, options.memory_limit_mb, report.concurrent_tiles);
  const TileGrid grid(cols, rows, report.tile_size);
  const int tiles = report.tiles = grid.count();
  report.tile_state_bytes = kTileBytesPerCell * double(report.tile_size + 4) * double(report.tile_size + 4);
  const CellMetrics metrics = cell_metrics(georef, cols, rows);
  const std::optional<double> sea = options.sea_level;
  tbb::task_arena arena(report.concurrent_tiles);
  std::vector<int> own;  // the tiles this process reads and writes
  for (int t = 0; t < tiles; ++t)
    if (driver.owns(t)) own.push_back(t);
  // A pass over this process's tiles; its error, if any, for the driver to agree on.
  auto for_tiles = [&](const char* what, auto&& body) -> std::exception_ptr {
    try {
      ProgressStep step(progress, what);
      std::atomic<int> done{0};
      std::mutex m;
      arena.execute([&] {
        tbb::parallel_for(0, int(own.size()), 1, [&](int k) {
          body(own[std::size_t(k)], grid.rect(own[std::size_t(k)]));
          const int d = ++done;
          std::unique_lock lock(m, std::try_to_lock);
          if (lock) step.update(double(d) / double(own.size()));
        });
      });
    } catch (...) {
      return std::current_exception();
    }
    return nullptr;
  };
  // After a pass: what it learnt about each tile, from the process that owns it, everywhere.
  auto exchange = [&](std::exception_ptr failure, auto&& pack, auto&& unpack) {
    if (driver.ranks() == 1) return driver.check(failure);
    std::vector<std::vector<char>> bytes(static_cast<std::size_t>(tiles));
    if (!failure)
      for (int t : own) pack(t, bytes[std::size_t(t)]);
    driver.share(bytes, failure);
    for (int t = 0; t < tiles; ++t)
      if (!driver.owns(t)) {
        Unpack in(bytes[std::size_t(t)]);
        unpack(t, in);
        bytes[std::size_t(t)] = {};
      }
  };
  auto read_tile = [&](const TileRect& r) { return read(r.col0 - 1, r.row0 - 1, r.cols + 2, r.rows + 2); };
  const fs::path scratch = options.scratch_dir.empty() ? fs::temp_directory_path() : fs::path(options.scratch_dir);
  auto codes_path = [&](int t) { return (scratch / ("d8-" + std::to_string(t) + ".bin")).string(); };
  struct ScratchCleanup {
    std::function<void()> f;
    ~ScratchCleanup() { f(); }
  } cleanup{[&] {
    std::error_code ec;
    for (int t = 0; t < tiles; ++t) fs::remove(codes_path(t), ec);
  }};

  // 1. Each tile filled with its edges as outlets; its frame and spill edges kept (Barnes 2016).
  std::vector<Frame> frames(static_cast<std::size_t>(tiles));
  std::vector<std::vector<SpillEdge>> tile_edges(static_cast<std::size_t>(tiles));
  std::vector<std::uint32_t> tile_labels(static_cast<std::size_t>(tiles));
  std::exception_ptr failure = for_tiles("fill tiles", [&](int t, const TileRect& r) {
    TileFill f = fill_tile(read_tile(r), sea);
    Frame frame(r);
    for (int row = 0; row < r.rows; ++row)
      for (int c = 0; c < r.cols; ++c)
        if (frame.contains(c, row)) {
          const std::size_t i = f.z.index(c, row), j = frame.index(c, row);
          frame.z[j] = f.z[i];
          frame.label[j] = f.label[i];  // local for now
        }
    frames[std::size_t(t)] = std::move(frame);
    tile_edges[std::size_t(t)] = std::move(f.edges);
    tile_labels[std::size_t(t)] = f.labels;
  });
  exchange(
      failure,
      [&](int t, std::vector<char>& out) {
        put(out, frames[std::size_t(t)].z);
        put(out, frames[std::size_t(t)].label);
        put(out, tile_edges[std::size_t(t)]);
        put(out, std::vector<std::uint32_t>{tile_labels[std::size_t(t)]});
      },
      [&](int t, Unpack& in) {
        Frame& frame = frames[std::size_t(t)] = Frame(grid.rect(t), false);
        frame.z = in.take<float>();
        frame.label = in.take<std::uint32_t>();
        tile_edges[std::size_t(t)] = in.take<SpillEdge>();
        tile_labels[std::size_t(t)] = in.take<std::uint32_t>().at(0);
      });
  // Global labels: 0 for the true outlets, then each tile's edge seeds in tile order.
  std::vector<std::uint32_t> base(static_cast<std::size_t>(tiles));
  std::uint64_t nodes = 1;
  for (int t = 0; t < tiles; ++t) {
    base[std::size_t(t)] = std::uint32_t(nodes - 1);
    nodes += tile_labels[std::size_t(t)] - 1;
  }
  if (nodes >= kOpen) throw bad_input("tiles: too many tile-edge labels; use larger tiles (--tile-size)");
  auto global = [&](int t, std::uint32_t l) { return l == 0 || l == kVoid ? l : base[std::size_t(t)] + l; };
  std::vector<SpillEdge> edges;
  for (int t = 0; t < tiles; ++t) {
    for (SpillEdge e : tile_edges[std::size_t(t)]) edges.push_back({global(t, e.a), global(t, e.b), e.spill});
    tile_edges[std::size_t(t)] = {};
    for (auto& l : frames[std::size_t(t)].label) l = global(t, l);
  }
  // Cells of a frame by mosaic coordinates.
  auto frame_cell = [&](int gc, int gr, float& z, std::uint32_t& label) {
    const int u = grid.tile_of(gc, gr);
    const TileRect ru = grid.rect(u);
    const std::size_t j = frames[std::size_t(u)].index(gc - ru.col0, gr - ru.row0);
    z = frames[std::size_t(u)].z[j];
    label = frames[std::size_t(u)].label[j];
  };
  // Spill edges across tile edges, each pair of cells once (from the lower-numbered tile).
  for (int t = 0; t < tiles; ++t) {
    const TileRect r = grid.rect(t);
    for (int row = 0; row < r.rows; ++row)
      for (int c = 0; c < r.cols; ++c) {
        if (row != 0 && c != 0 && row != r.rows - 1 && c != r.cols - 1) continue;
        float za;
        std::uint32_t la;
        frame_cell(r.col0 + c, r.row0 + row, za, la);
        if (la == kVoid) continue;
        for (int k = 0; k < 8; ++k) {
          const int gc = r.col0 + c + dcol[k], gr = r.row0 + row + drow[k];
          if (gc < 0 || gr < 0 || gc >= cols || gr >= rows || grid.tile_of(gc, gr) <= t) continue;
          float zb;
          std::uint32_t lb;
          frame_cell(gc, gr, zb, lb);
          if (lb != kVoid && lb != la) edges.push_back({la, lb, std::max(za, zb)});
        }
      }
  }
  report.labels = nodes;
  report.spill_edges = edges.size();
  double frame_bytes = 0;
  for (const auto& f : frames) frame_bytes += double(f.z.size()) * 12;  // frame values + edge exits
  report.global_state_bytes = frame_bytes + double(nodes) * 12 + double(edges.size()) * 28;
  const std::vector<float> level = spill_levels(std::uint32_t(nodes), edges);
  auto final_z = [&](float z, std::uint32_t label) {
    return label == kVoid ? std::numeric_limits<float>::quiet_NaN() : label == 0 ? z : std::max(z, level[label]);
  };

  // 2. Filled tiles (the flood again, each cell raised to its label's level), first-pass D8 on
  // the tile and a one-cell halo, flats inside the tile drained; cells of flats reaching the halo
  // handed on.
  std::vector<std::vector<SharedEntry>> shared(static_cast<std::size_t>(tiles));
  failure = for_tiles("flow directions of tiles", [&](int t, const TileRect& r) {
    TileFill f = fill_tile(read_tile(r), sea);
    for (std::size_t i = 0; i < f.z.size(); ++i) f.z[i] = final_z(f.z[i], global(t, f.label[i]));
    f.label = {};
    f.z.georef() = shifted(georef, r.col0, r.row0);
    if (sinks.filled) sinks.filled(t, f.z);
    // The filled tile with a halo of two cells (from the neighbours' frames), NaN off the mosaic.
    Dem wide(r.cols + 4, r.rows + 4, shifted(georef, r.col0 - 2, r.row0 - 2), std::numeric_limits<float>::quiet_NaN());
    for (int row = 0; row < wide.rows(); ++row)
      for (int c = 0; c < wide.cols(); ++c) {
        const int gc = r.col0 - 2 + c, gr = r.row0 - 2 + row;
        if (gc < 0 || gr < 0 || gc >= cols || gr >= rows) continue;
        if (gc >= r.col0 && gr >= r.row0 && gc < r.col0 + r.cols && gr < r.row0 + r.rows) {
          wide(c, row) = f.z(gc - r.col0, gr - r.row0);
        } else {
          float z;
          std::uint32_t label;
          frame_cell(gc, gr, z, label);
          wide(c, row) = final_z(z, label);
        }
      }
    f.z = Dem();
    // The tile with a halo of one cell: filled values and first-pass codes.
    Dem near(r.cols + 2, r.rows + 2, shifted(georef, r.col0 - 1, r.row0 - 1));
    Raster<std::uint8_t> first = near.like<std::uint8_t>(kNoData);
    bool any_flat = false;
    for (int row = 0; row < near.rows(); ++row) {
      const int gr = r.row0 - 1 + row;
      double step[8];
      if (gr >= 0 && gr < rows)
        for (int k = 0; k < 8; ++k) step[k] = metrics.step_m(gr, k);
      for (int c = 0; c < near.cols(); ++c) {
        near(c, row) = wide(c + 1, row + 1);
        if (gr < 0 || gr >= rows) continue;
        first(c, row) = d8_first_pass(wide, step, sea, c + 1, row + 1);
        any_flat |= first(c, row) == kNoFlow;
      }
    }
    wide = Dem();
    Raster<std::uint8_t> drained = first;
    if (any_flat) drain_flats(near, drained);
    // Cells whose equal-elevation component (drain_flats' flats and the draining cells that join
    // them) reaches the halo: their flat is not whole in this tile.
    std::vector<std::uint8_t> member(near.size(), 0);
    std::vector<std::size_t> stack;
    for (int row = 0; row < near.rows(); ++row)
      for (int c = 0; c < near.cols(); ++c) {
        if (row != 0 && c != 0 && row != near.rows() - 1 && c != near.cols() - 1) continue;
        const std::size_t i = near.index(c, row);
        if (out_code(first[i])) continue;
        member[i] = 1;
        stack.push_back(i);
      }
    while (!stack.empty()) {
      const std::size_t i = stack.back();
      stack.pop_back();
      const int c = int(i % std::size_t(near.cols())), row = int(i / std::size_t(near.cols()));
      for (int k = 0; k < 8; ++k) {
        const int nc = c + dcol[k], nr = row + drow[k];
        if (!near.inside(nc, nr)) continue;
        const std::size_t n = near.index(nc, nr);
        if (member[n] || out_code(first[n]) || near[n] != near[i]) continue;
        member[n] = 1;
        stack.push_back(n);
      }
    }
    Raster<std::uint8_t> d8(r.cols, r.rows, shifted(georef, r.col0, r.row0), kNoData);
    d8.nodata = kNoData;
    auto& out = shared[std::size_t(t)];
    for (int row = 0; row < r.rows; ++row)
      for (int c = 0; c < r.cols; ++c) {
        const std::size_t i = near.index(c + 1, row + 1);
        bool next_to_member = member[i];
        for (int k = 0; k < 8 && !next_to_member; ++k) next_to_member = member[near.index(c + 1 + dcol[k], row + 1 + drow[k])];
        d8(c, row) = member[i] ? first[i] : drained[i];
        if (next_to_member)
          out.push_back({std::int64_t(r.row0 + row) * cols + (r.col0 + c), SharedCell{near[i], first[i], member[i] != 0}});
      }
    write_codes(codes_path(t), d8);
  });
  exchange(
      failure, [&](int t, std::vector<char>& out) { put(out, shared[std::size_t(t)]); },
      [&](int t, Unpack& in) { shared[std::size_t(t)] = in.take<SharedEntry>(); });

  // Flats that cross tile edges, each gathered whole (its cells and their neighbours) on a
  // window of its bounding box and drained there: the same rings, hence the same directions.
  std::unordered_map<std::int64_t, std::uint32_t> slot;
  std::vector<std::int64_t> cell_of;
  std::vector<SharedCell> cells;
  for (auto& list : shared) {
    for (const auto& [g, cell] : list) {
      slot.emplace(g, std::uint32_t(cells.size()));
      cell_of.push_back(g);
      cells.push_back(cell);
    }
    list = {};
  }
  Sets sets{std::vector<std::uint32_t>(cells.size())};
  std::iota(sets.parent.begin(), sets.parent.end(), 0u);
  auto neighbour = [&](std::int64_t g, int k) -> std::int64_t {
    const int gc = int(g % cols) + dcol[k], gr = int(g / cols) + drow[k];
    if (gc < 0 || gr < 0 || gc >= cols || gr >= rows) return -1;
    return std::int64_t(gr) * cols + gc;
  };
  for (std::uint32_t s = 0; s < cells.size(); ++s) {
    if (!cells[s].member) continue;
    for (int k = 0; k < 8; ++k) {
      const std::int64_t n = neighbour(cell_of[s], k);
      if (n < 0) continue;
      const auto it = slot.find(n);
      if (it != slot.end() && cells[it->second].member && cells[it->second].z == cells[s].z) sets.join(s, it->second);
    }
  }
  std::unordered_map<std::uint32_t, std::vector<std::uint32_t>> groups;  // root -> members holding a flat cell
  {
    std::vector<std::uint8_t> has_flat(cells.size(), 0);
    for (std::uint32_t s = 0; s < cells.size(); ++s)
      if (cells[s].member && cells[s].code == kNoFlow) has_flat[sets.find(s)] = 1;
    for (std::uint32_t s = 0; s < cells.size(); ++s)
      if (cells[s].member && has_flat[sets.find(s)]) groups[sets.find(s)].push_back(s);
  }
  std::vector<std::vector<std::pair<std::uint32_t, std::uint8_t>>> patches(static_cast<std::size_t>(tiles));
  std::vector<std::uint32_t> roots;
  for (const auto& [root, members] : groups) roots.push_back(root);
  std::sort(roots.begin(), roots.end());
  for (std::uint32_t root : roots) {
    const auto& members = groups[root];
    int c0 = cols, r0 = rows, c1 = -1, r1 = -1;
    for (std::uint32_t s : members) {
      const int c = int(cell_of[s] % cols), r = int(cell_of[s] / cols);
      c0 = std::min(c0, c);
      r0 = std::min(r0, r);
      c1 = std::max(c1, c);
      r1 = std::max(r1, r);
    }
    c0 -= 1, r0 -= 1, c1 += 1, r1 += 1;
    Dem z(c1 - c0 + 1, r1 - r0 + 1, {}, std::numeric_limits<float>::quiet_NaN());
    Raster<std::uint8_t> d8 = z.like<std::uint8_t>(kNoData);
    auto put = [&](std::int64_t g) {
      const auto it = slot.find(g);
      if (it == slot.end()) return;
      const int c = int(g % cols) - c0, r = int(g / cols) - r0;
      z(c, r) = cells[it->second].z;
      d8(c, r) = cells[it->second].code;
    };
    for (std::uint32_t s : members) {
      put(cell_of[s]);
      for (int k = 0; k < 8; ++k)
        if (const std::int64_t n = neighbour(cell_of[s], k); n >= 0) put(n);
    }
    report.flat_cells_shared += members.size();
    drain_flats(z, d8);
    for (std::uint32_t s : members) {
      if (cells[s].code != kNoFlow) continue;
      const int gc = int(cell_of[s] % cols), gr = int(cell_of[s] / cols);
      const int t = grid.tile_of(gc, gr);
      const TileRect rt = grid.rect(t);
      patches[std::size_t(t)].push_back({std::uint32_t((gr - rt.row0) * rt.cols + (gc - rt.col0)), d8(gc - c0, gr - r0)});
    }
  }
  report.global_state_bytes = std::max(report.global_state_bytes, frame_bytes + double(cells.size()) * 48);
  slot = {};
  cells = {};
  cell_of = {};
  groups = {};

  // 3. Final directions; accumulation inside each tile; the links between tiles (Barnes 2017).
  const FixedPointUnits units = fixed_point_units(metrics, cols, options.unit);
  auto own_units = [&](const Raster<std::uint8_t>& d8, const TileRect& r) {
    std::vector<std::int64_t> acc(d8.size(), 0);
    for (int row = 0; row < r.rows; ++row)
      for (int c = 0; c < r.cols; ++c)
        if (d8(c, row) != kNoData) acc[d8.index(c, row)] = units.per_row[std::size_t(r.row0 + row)];
    return acc;
  };
  // Target of the D8 code of mosaic cell (gc, gr) when it lies in another tile on valid data, else -1.
  auto crossing = [&](int t, int gc, int gr, std::uint8_t k) -> std::int64_t {
    if (k >= 8) return -1;
    const int nc = gc + dcol[k], nr = gr + drow[k];
    if (nc < 0 || nr < 0 || nc >= cols || nr >= rows || grid.tile_of(nc, nr) == t) return -1;
    float z;
    std::uint32_t label;
    frame_cell(nc, nr, z, label);
    return label == kVoid ? -1 : std::int64_t(nr) * cols + nc;
  };
  // Where the D8 paths of tile t end, in row-major order: its outlets (a cell that keeps its water,
  // or flows off the mosaic or onto nodata: drainage_basins' outlets) and the cells that flow into
  // another tile (its links, with their targets).
  struct PathEnds {
    std::vector<std::uint32_t> outlets, exits;
    std::vector<std::int64_t> targets;
  };
  auto path_ends = [&](int t, const TileRect& r, const Raster<std::uint8_t>& d8) {
    PathEnds ends;
    for (int row = 0; row < r.rows; ++row)
      for (int c = 0; c < r.cols; ++c) {
        const std::uint8_t k = d8(c, row);
        if (k == kNoData) continue;
        const std::uint32_t i = std::uint32_t(d8.index(c, row));
        const int nc = c + (k < 8 ? dcol[k] : 0), nr = row + (k < 8 ? drow[k] : 0);
        if (k < 8 && d8.inside(nc, nr)) {
          if (d8(nc, nr) == kNoData) ends.outlets.push_back(i);
          continue;
        }
        if (const std::int64_t target = crossing(t, r.col0 + c, r.row0 + row, k); target >= 0) {
          ends.exits.push_back(i);
          ends.targets.push_back(target);
        } else {
          ends.outlets.push_back(i);
        }
      }
    return ends;
  };
  std::vector<std::vector<Link>> links(static_cast<std::size_t>(tiles));
  // Outlets of each tile by row (the basins' numbering).
  std::vector<std::vector<std::uint32_t>> outlet_rows(static_cast<std::size_t>(tiles));
  // For each edge cell of a tile (Frame order, first ring only used), the link its flow leaves by.
  std::vector<std::vector<std::int32_t>> edge_exit(static_cast<std::size_t>(tiles));
  failure = for_tiles("accumulation of tiles", [&](int t, const TileRect& r) {
    Raster<std::uint8_t> d8(r.cols, r.rows, shifted(georef, r.col0, r.row0), kNoData);
    d8.nodata = kNoData;
    read_codes(codes_path(t), d8);
    for (const auto& [i, k] : patches[std::size_t(t)]) d8[i] = k;
    patches[std::size_t(t)] = {};
    if (sinks.d8) sinks.d8(t, d8);
    write_codes(codes_path(t), d8);
    std::vector<std::int64_t> acc = own_units(d8, r);
    accumulate_d8_units(d8, acc);
    // Exits and outlets, then for each edge cell where its path ends: exit e >= 0, outlet j of the
    // tile (row-major) as -3 - j, -1 on nodata.
    std::vector<std::int32_t> down(d8.size(), -2);
    const PathEnds ends = path_ends(t, r, d8);
    auto& out = links[std::size_t(t)];
    for (std::size_t e = 0; e < ends.exits.size(); ++e) {
      const std::uint32_t i = ends.exits[e];
      down[i] = std::int32_t(e);
      out.push_back({std::int64_t(r.row0) * cols + r.col0 + std::int64_t(i / std::uint32_t(r.cols)) * cols + i % std::uint32_t(r.cols),
                     ends.targets[e], acc[i]});
    }
    std::vector<std::uint32_t>& per_row = outlet_rows[std::size_t(t)];
    per_row.assign(std::size_t(r.rows), 0);
    for (std::size_t j = 0; j < ends.outlets.size(); ++j) {
      down[ends.outlets[j]] = -3 - std::int32_t(j);
      ++per_row[ends.outlets[j] / std::uint32_t(r.cols)];
    }
    std::vector<std::size_t> path;
    const Frame frame(r, false);
    std::vector<std::int32_t> exits(frame.size(), -1);
    for (int row = 0; row < r.rows; ++row)
      for (int c = 0; c < r.cols; ++c) {
        if (row != 0 && c != 0 && row != r.rows - 1 && c != r.cols - 1) continue;
        std::size_t i = d8.index(c, row);
        path.clear();
        std::int32_t exit = -1;
        for (;;) {
          if (down[i] != -2) {
            exit = down[i];
            break;
          }
          path.push_back(i);
          const std::uint8_t k = d8[i];
          const int nc = int(i % std::size_t(r.cols)) + (k < 8 ? dcol[k] : 0), nr = int(i / std::size_t(r.cols)) + (k < 8 ? drow[k] : 0);
          if (k >= 8 || !d8.inside(nc, nr) || d8(nc, nr) == kNoData) break;
          i = d8.index(nc, nr);
        }
        for (std::size_t p : path) down[p] = exit;
        exits[frame.index(c, row)] = exit;
      }
    edge_exit[std::size_t(t)] = std::move(exits);
  });
  exchange(
      failure,
      [&](int t, std::vector<char>& out) {
        put(out, links[std::size_t(t)]);
        put(out, edge_exit[std::size_t(t)]);
        put(out, outlet_rows[std::size_t(t)]);
      },
      [&](int t, Unpack& in) {
        links[std::size_t(t)] = in.take<Link>();
        edge_exit[std::size_t(t)] = in.take<std::int32_t>();
        outlet_rows[std::size_t(t)] = in.take<std::uint32_t>();
      });
  // The link graph: each link flows into the tile of its target and leaves it by that cell's
  // exit; solved in topological order, the sums exact.
  std::vector<std::uint32_t> link_base(static_cast<std::size_t>(tiles) + 1, 0);
  for (int t = 0; t < tiles; ++t) link_base[std::size_t(t) + 1] = link_base[std::size_t(t)] + std::uint32_t(links[std::size_t(t)].size());
  const std::uint32_t link_count = link_base.back();
  report.links = link_count;
  std::vector<Link> all;
  all.reserve(link_count);
  for (auto& l : links) {
    all.insert(all.end(), l.begin(), l.end());
    l = {};
  }
  std::vector<std::int64_t> next(link_count, -1);
  std::vector<std::uint32_t> indegree(link_count, 0);
  for (std::uint32_t y = 0; y < link_count; ++y) {
    const int gc = int(all[y].target % cols), gr = int(all[y].target / cols);
    const int u = grid.tile_of(gc, gr);
    const TileRect ru = grid.rect(u);
    const std::int32_t e = edge_exit[std::size_t(u)][Frame(ru, false).index(gc - ru.col0, gr - ru.row0)];
    if (e >= 0) {
      next[y] = link_base[std::size_t(u)] + std::uint32_t(e);
      ++indegree[std::size_t(next[y])];
    }
  }
  // Basins: outlets numbered in row-major order of the mosaic (drainage_basins), from the tiles'
  // outlets by row; each link labelled with the basin its chain of links ends in.
  std::vector<std::uint64_t> before_row(std::size_t(rows) + 1, 0);  // outlets of the mosaic's rows above
  std::vector<std::vector<std::uint32_t>> outlets_above(static_cast<std::size_t>(tiles));  // a tile's, above each row
  for (int t = 0; t < tiles; ++t) {
    const TileRect r = grid.rect(t);
    auto& above = outlets_above[std::size_t(t)];
    above.assign(std::size_t(r.rows) + 1, 0);
    for (int row = 0; row < r.rows; ++row) {
      const std::uint32_t n = outlet_rows[std::size_t(t)][std::size_t(row)];
      above[std::size_t(row) + 1] = above[std::size_t(row)] + n;
      before_row[std::size_t(r.row0 + row) + 1] += n;
    }
  }
  for (int row = 0; row < rows; ++row) before_row[std::size_t(row) + 1] += before_row[std::size_t(row)];
  if (sinks.basins && before_row.back() >= 0xFFFFFFFFu) throw bad_input("basins: more than 2^32 - 2 outlets");
  auto basin_of_outlet = [&](int u, std::uint32_t j) {  // outlet j of tile u
    const auto& above = outlets_above[std::size_t(u)];
    const std::size_t row = std::size_t(std::upper_bound(above.begin(), above.end(), j) - above.begin()) - 1;
    std::uint64_t rank = before_row[std::size_t(grid.rect(u).row0) + row] + (j - above[row]);
    for (int v = u - u % grid.across(); v < u; ++v) rank += outlet_rows[std::size_t(v)][row];  // on the row, to the west
    return std::uint32_t(rank + 1);
  };
  std::vector<std::uint32_t> link_basin(sinks.basins ? link_count : 0, 0);
  std::vector<std::uint32_t> chain;
  for (std::uint32_t y = 0; y < link_basin.size(); ++y) {
    chain.clear();
    std::uint32_t z = y;
    for (; link_basin[z] == 0 && next[z] >= 0; z = std::uint32_t(next[z])) chain.push_back(z);
    if (link_basin[z] == 0) {
      const int gc = int(all[z].target % cols), gr = int(all[z].target / cols);
      const int u = grid.tile_of(gc, gr);
      const TileRect ru = grid.rect(u);
      link_basin[z] = basin_of_outlet(u, std::uint32_t(-3 - edge_exit[std::size_t(u)][Frame(ru, false).index(gc - ru.col0, gr - ru.row0)]));
    }
    for (std::uint32_t x : chain) link_basin[x] = link_basin[z];
  }
  edge_exit = {};
  std::vector<std::int64_t> total(link_count);
  for (std::uint32_t y = 0; y < link_count; ++y) total[y] = all[y].local;
  std::vector<std::uint32_t> ready;
  for (std::uint32_t y = 0; y < link_count; ++y)
    if (indegree[y] == 0) ready.push_back(y);
  while (!ready.empty()) {
    const std::uint32_t y = ready.back();
    ready.pop_back();
    if (next[y] < 0) continue;
    const std::size_t x = std::size_t(next[y]);
    total[x] += total[y];
    if (--indegree[x] == 0) ready.push_back(std::uint32_t(x));
  }
  // What flows into each tile, by target cell.
  std::vector<std::vector<std::pair<std::uint32_t, std::int64_t>>> inflow(static_cast<std::size_t>(tiles));
  for (std::uint32_t y = 0; y < link_count; ++y) {
    const int gc = int(all[y].target % cols), gr = int(all[y].target / cols);
    const int u = grid.tile_of(gc, gr);
    const TileRect ru = grid.rect(u);
    inflow[std::size_t(u)].push_back({std::uint32_t((gr - ru.row0) * ru.cols + (gc - ru.col0)), total[y]});
  }
  report.global_state_bytes = std::max(report.global_state_bytes, frame_bytes + double(link_count) * 60 + double(rows) * 16);
  all = {};
  total = {};

  // 4. The accumulation again, with what flows in from the other tiles; the stream cells kept.
  if (sinks.streams && options.unit != AccumulationUnit::area_m2)
    throw bad_input("tiles: streams need the accumulation as an area (--area-units m2 or km2)");
  std::vector<std::vector<StreamCell>> stream_cells(static_cast<std::size_t>(tiles));
  failure = nullptr;
  if (sinks.accumulation || sinks.streams || sinks.basins)
    failure = for_tiles("accumulation", [&](int t, const TileRect& r) {
      Raster<std::uint8_t> d8(r.cols, r.rows, shifted(georef, r.col0, r.row0), kNoData);
      read_codes(codes_path(t), d8);
      if (sinks.basins) {
        Raster<std::uint32_t> basins = d8.like<std::uint32_t>(0);
        basins.nodata = 0;
        const PathEnds ends = path_ends(t, r, d8);
        for (std::size_t e = 0; e < ends.exits.size(); ++e) basins[ends.exits[e]] = link_basin[link_base[std::size_t(t)] + e];
        for (std::size_t j = 0; j < ends.outlets.size(); ++j) basins[ends.outlets[j]] = basin_of_outlet(t, std::uint32_t(j));
        label_by_descent(d8, basins);
        sinks.basins(t, basins);
      }
      if (!sinks.accumulation && !sinks.streams) return;
      std::vector<std::int64_t> acc = own_units(d8, r);
      for (const auto& [i, v] : inflow[std::size_t(t)]) acc[i] += v;
      inflow[std::size_t(t)] = {};
      accumulate_d8_units(d8, acc);
      Raster<double> out = d8.like<double>(0.0);
      for (std::size_t i = 0; i < out.size(); ++i) out[i] = d8[i] == kNoData ? NAN : units.value(acc[i]);
      if (sinks.streams)
        for (int row = 0; row < r.rows; ++row)
          for (int c = 0; c < r.cols; ++c)
            if (const double a = out(c, row); d8(c, row) != kNoData && a >= options.streams_threshold_m2)
              stream_cells[std::size_t(t)].push_back({std::int64_t(r.row0 + row) * cols + r.col0 + c, a, d8(c, row)});
      if (sinks.accumulation) sinks.accumulation(t, out);
    });
  if (!sinks.streams) {
    driver.check(failure);  // every process's tiles written
    return report;
  }
  exchange(
      failure, [&](int t, std::vector<char>& out) { put(out, stream_cells[std::size_t(t)]); },
      [&](int t, Unpack& in) { stream_cells[std::size_t(t)] = in.take<StreamCell>(); });
  if (driver.rank() != 0) return report;
  std::vector<StreamCell> network;
  for (auto& part : stream_cells) {
    network.insert(network.end(), part.begin(), part.end());
    part = {};
  }
  std::sort(network.begin(), network.end(), [](const StreamCell& a, const StreamCell& b) { return a.index < b.index; });
  StreamCells streams{cols, rows, {}, {}, {}};
  for (const StreamCell& cell : network) {
    streams.index.push_back(cell.index);
    streams.code.push_back(cell.code);
    streams.area_m2.push_back(cell.area_m2);
  }
  report.stream_cells = network.size();
  report.global_state_bytes = std::max(report.global_state_bytes, frame_bytes + double(network.size()) * 40);
  network = {};
  sinks.streams(streams);
  return report;
}

}  // namespace terrapolis::hydro::tiled
