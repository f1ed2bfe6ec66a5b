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
  throw bad_input("/input/memory_limit_mb: " + std::to_string(int(memory_limit_mb)) + " MB is too little for tiles of 64 x 64 cells on a " +
                  std::to_string(cols) + " x " + std::to_string(rows) + " mosaic");
}

namespace {

/// One run of the engine: the state its passes hand on to each other. Each pass works on the
/// tiles this process owns, then exchange() gives every process what it learnt about every tile.
class TiledRun {
 public:
  TiledRun(int cols, int rows, const Georef& georef, const ReadWindow& read, const TiledOptions& options, const TileSinks& sinks,
           Progress& progress, TileDriver& driver)
      : cols_(cols), rows_(rows), georef_(georef), read_(read), options_(options), sinks_(sinks), progress_(progress), driver_(driver),
        report_(sized_report(cols, rows, options)), grid_(cols, rows, report_.tile_size), tiles_(grid_.count()),
        metrics_(cell_metrics(georef, cols, rows)), arena_(report_.concurrent_tiles),
        scratch_(options.scratch_dir.empty() ? std::filesystem::temp_directory_path() : std::filesystem::path(options.scratch_dir)) {
    report_.tiles = tiles_;
    for (int t = 0; t < tiles_; ++t)
      if (driver.owns(t)) own_.push_back(t);
  }
  ~TiledRun() {
    std::error_code ec;
    for (int t = 0; t < tiles_; ++t) std::filesystem::remove(codes_path(t), ec);
  }
  TiledRun(const TiledRun&) = delete;
  TiledRun& operator=(const TiledRun&) = delete;

  TiledReport run() {
    fill_tiles();
    solve_spill_graph();
    direct_tiles();
    drain_shared_flats();
    accumulate_tiles();
    solve_link_graph();
    if (!final_accumulation()) return report_;
    gather_streams();
    return report_;
  }

 private:
  static TiledReport sized_report(int cols, int rows, const TiledOptions& options) {
    TiledReport report;
    report.concurrent_tiles = options.concurrent_tiles > 0 ? options.concurrent_tiles : allowed_threads();
    report.tile_size = options.tile_size > 0 ? std::max(options.tile_size, 8)
                                             : tile_size_for(cols, rows, options.memory_limit_mb, report.concurrent_tiles);
    report.tile_state_bytes = kTileBytesPerCell * double(report.tile_size + 4) * double(report.tile_size + 4);
    return report;
  }

  /// A pass over this process's tiles; its error, if any, for the driver to agree on.
  template <class Body>
  std::exception_ptr for_tiles(const char* what, Body&& body) {
    try {
      ProgressStep step(progress_, what);
      std::atomic<int> done{0};
      std::mutex m;
      arena_.execute([&] {
        tbb::parallel_for(0, int(own_.size()), 1, [&](int k) {
          body(own_[std::size_t(k)], grid_.rect(own_[std::size_t(k)]));
          const int d = ++done;
          std::unique_lock lock(m, std::try_to_lock);
          if (lock) step.update(double(d) / double(own_.size()));
        });
      });
    } catch (...) {
      return std::current_exception();
    }
    return nullptr;
  }

  /// After a pass: what it learnt about each tile, from the process that owns it, everywhere.
  template <class PackFn, class UnpackFn>
  void exchange(std::exception_ptr failure, PackFn&& pack, UnpackFn&& unpack) {
    if (driver_.ranks() == 1) return driver_.check(failure);
    std::vector<std::vector<char>> bytes(static_cast<std::size_t>(tiles_));
    if (!failure)
      for (int t : own_) pack(t, bytes[std::size_t(t)]);
    driver_.share(bytes, failure);
    for (int t = 0; t < tiles_; ++t)
      if (!driver_.owns(t)) {
        Unpack in(bytes[std::size_t(t)]);
        unpack(t, in);
        bytes[std::size_t(t)] = {};
      }
  }

  Dem read_tile(const TileRect& r) const { return read_(r.col0 - 1, r.row0 - 1, r.cols + 2, r.rows + 2); }
  std::string codes_path(int t) const { return (scratch_ / ("d8-" + std::to_string(t) + ".bin")).string(); }
  bool off_mosaic(int gc, int gr) const { return gc < 0 || gr < 0 || gc >= cols_ || gr >= rows_; }
  Raster<std::uint8_t> tile_codes(const TileRect& r) const {
    return Raster<std::uint8_t>(r.cols, r.rows, shifted(georef_, r.col0, r.row0), kNoData);
  }

  /// Global labels: 0 for the true outlets, then each tile's edge seeds in tile order.
  std::uint32_t global(int t, std::uint32_t l) const { return l == 0 || l == kVoid ? l : base_[std::size_t(t)] + l; }

  /// Cells of a frame by mosaic coordinates.
  void frame_cell(int gc, int gr, float& z, std::uint32_t& label) const {
    const int u = grid_.tile_of(gc, gr);
    const TileRect ru = grid_.rect(u);
    const std::size_t j = frames_[std::size_t(u)].index(gc - ru.col0, gr - ru.row0);
    z = frames_[std::size_t(u)].z[j];
    label = frames_[std::size_t(u)].label[j];
  }

  float final_z(float z, std::uint32_t label) const {
    return label == kVoid ? std::numeric_limits<float>::quiet_NaN() : label == 0 ? z : std::max(z, level_[label]);
  }

  // 1. Each tile filled with its edges as outlets; its frame and spill edges kept (Barnes 2016).
  void fill_tiles() {
    frames_.resize(static_cast<std::size_t>(tiles_));
    tile_edges_.resize(static_cast<std::size_t>(tiles_));
    tile_labels_.resize(static_cast<std::size_t>(tiles_));
    std::exception_ptr failure = for_tiles("fill tiles", [&](int t, const TileRect& r) {
      TileFill f = fill_tile(read_tile(r), options_.sea_level);
      Frame frame(r);
      for (int row = 0; row < r.rows; ++row)
        for (int c = 0; c < r.cols; ++c)
          if (frame.contains(c, row)) {
            const std::size_t i = f.z.index(c, row), j = frame.index(c, row);
            frame.z[j] = f.z[i];
            frame.label[j] = f.label[i];  // local for now
          }
      frames_[std::size_t(t)] = std::move(frame);
      tile_edges_[std::size_t(t)] = std::move(f.edges);
      tile_labels_[std::size_t(t)] = f.labels;
    });
    exchange(
        failure,
        [&](int t, std::vector<char>& out) {
          put(out, frames_[std::size_t(t)].z);
          put(out, frames_[std::size_t(t)].label);
          put(out, tile_edges_[std::size_t(t)]);
          put(out, std::vector<std::uint32_t>{tile_labels_[std::size_t(t)]});
        },
        [&](int t, Unpack& in) {
          Frame& frame = frames_[std::size_t(t)] = Frame(grid_.rect(t), false);
          frame.z = in.take<float>();
          frame.label = in.take<std::uint32_t>();
          tile_edges_[std::size_t(t)] = in.take<SpillEdge>();
          tile_labels_[std::size_t(t)] = in.take<std::uint32_t>().at(0);
        });
  }

  /// The tiles' labels made global, the spill edges across tile edges added, and the spill graph
  /// solved: the level each label fills to.
  void solve_spill_graph() {
    base_.resize(static_cast<std::size_t>(tiles_));
    std::uint64_t nodes = 1;
    for (int t = 0; t < tiles_; ++t) {
      base_[std::size_t(t)] = std::uint32_t(nodes - 1);
      nodes += tile_labels_[std::size_t(t)] - 1;
    }
    if (nodes >= kOpen) throw bad_input("tiles: too many tile-edge labels; use larger tiles (--tile-size)");
    std::vector<SpillEdge> edges;
    for (int t = 0; t < tiles_; ++t) {
      for (SpillEdge e : tile_edges_[std::size_t(t)]) edges.push_back({global(t, e.a), global(t, e.b), e.spill});
      tile_edges_[std::size_t(t)] = {};
      for (auto& l : frames_[std::size_t(t)].label) l = global(t, l);
    }
    add_edges_across_tiles(edges);
    report_.labels = nodes;
    report_.spill_edges = edges.size();
    for (const auto& f : frames_) frame_bytes_ += double(f.z.size()) * 12;  // frame values + edge exits
    report_.global_state_bytes = frame_bytes_ + double(nodes) * 12 + double(edges.size()) * 28;
    level_ = spill_levels(std::uint32_t(nodes), edges);
  }

  /// Spill edges across tile edges, each pair of cells once (from the lower-numbered tile).
  void add_edges_across_tiles(std::vector<SpillEdge>& edges) const {
    for (int t = 0; t < tiles_; ++t) {
      const TileRect r = grid_.rect(t);
      for (int row = 0; row < r.rows; ++row)
        for (int c = 0; c < r.cols; ++c) {
          if (row != 0 && c != 0 && row != r.rows - 1 && c != r.cols - 1) continue;
          float za;
          std::uint32_t la;
          frame_cell(r.col0 + c, r.row0 + row, za, la);
          if (la == kVoid) continue;
          for (int k = 0; k < 8; ++k) {
            const int gc = r.col0 + c + dcol[k], gr = r.row0 + row + drow[k];
            if (off_mosaic(gc, gr) || grid_.tile_of(gc, gr) <= t) continue;
            float zb;
            std::uint32_t lb;
            frame_cell(gc, gr, zb, lb);
            if (lb != kVoid && lb != la) edges.push_back({la, lb, std::max(za, zb)});
          }
        }
    }
  }

  // 2. Filled tiles (the flood again, each cell raised to its label's level), first-pass D8 on
  // the tile and a one-cell halo, flats inside the tile drained; cells of flats reaching the halo
  // handed on.
  void direct_tiles() {
    shared_.resize(static_cast<std::size_t>(tiles_));
    std::exception_ptr failure = for_tiles("flow directions of tiles", [&](int t, const TileRect& r) { direct_tile(t, r); });
    exchange(
        failure, [&](int t, std::vector<char>& out) { put(out, shared_[std::size_t(t)]); },
        [&](int t, Unpack& in) { shared_[std::size_t(t)] = in.take<SharedEntry>(); });
  }

  void direct_tile(int t, const TileRect& r) {
    TileFill f = fill_tile(read_tile(r), options_.sea_level);
    for (std::size_t i = 0; i < f.z.size(); ++i) f.z[i] = final_z(f.z[i], global(t, f.label[i]));
    f.label = {};
    f.z.georef() = shifted(georef_, r.col0, r.row0);
    if (sinks_.filled) sinks_.filled(t, f.z);
    Dem wide = with_halo(r, f.z);
    f.z = Dem();
    // The tile with a halo of one cell: filled values and first-pass codes.
    Dem near(r.cols + 2, r.rows + 2, shifted(georef_, r.col0 - 1, r.row0 - 1));
    Raster<std::uint8_t> first = near.like<std::uint8_t>(kNoData);
    bool any_flat = false;
    for (int row = 0; row < near.rows(); ++row) {
      const int gr = r.row0 - 1 + row;
      double step[8];
      if (gr >= 0 && gr < rows_)
        for (int k = 0; k < 8; ++k) step[k] = metrics_.step_m(gr, k);
      for (int c = 0; c < near.cols(); ++c) {
        near(c, row) = wide(c + 1, row + 1);
        if (gr < 0 || gr >= rows_) continue;
        first(c, row) = d8_first_pass(wide, step, options_.sea_level, c + 1, row + 1);
        any_flat |= first(c, row) == kNoFlow;
      }
    }
    wide = Dem();
    Raster<std::uint8_t> drained = first;
    if (any_flat) drain_flats(near, drained);
    const std::vector<std::uint8_t> member = flats_reaching_halo(near, first);
    Raster<std::uint8_t> d8 = tile_codes(r);
    d8.nodata = kNoData;
    auto& out = shared_[std::size_t(t)];
    for (int row = 0; row < r.rows; ++row)
      for (int c = 0; c < r.cols; ++c) {
        const std::size_t i = near.index(c + 1, row + 1);
        bool next_to_member = member[i];
        for (int k = 0; k < 8 && !next_to_member; ++k) next_to_member = member[near.index(c + 1 + dcol[k], row + 1 + drow[k])];
        d8(c, row) = member[i] ? first[i] : drained[i];
        if (next_to_member)
          out.push_back({std::int64_t(r.row0 + row) * cols_ + (r.col0 + c), SharedCell{near[i], first[i], member[i] != 0}});
      }
    write_codes(codes_path(t), d8);
  }

  /// The filled tile `filled` with a halo of two cells (from the neighbours' frames), NaN off the mosaic.
  Dem with_halo(const TileRect& r, const Dem& filled) const {
    Dem wide(r.cols + 4, r.rows + 4, shifted(georef_, r.col0 - 2, r.row0 - 2), std::numeric_limits<float>::quiet_NaN());
    for (int row = 0; row < wide.rows(); ++row)
      for (int c = 0; c < wide.cols(); ++c) {
        const int gc = r.col0 - 2 + c, gr = r.row0 - 2 + row;
        if (off_mosaic(gc, gr)) continue;
        if (gc >= r.col0 && gr >= r.row0 && gc < r.col0 + r.cols && gr < r.row0 + r.rows) {
          wide(c, row) = filled(gc - r.col0, gr - r.row0);
        } else {
          float z;
          std::uint32_t label;
          frame_cell(gc, gr, z, label);
          wide(c, row) = final_z(z, label);
        }
      }
    return wide;
  }

  /// Cells whose equal-elevation component (drain_flats' flats and the draining cells that join
  /// them) reaches the halo of `near`: their flat is not whole in this tile.
  static std::vector<std::uint8_t> flats_reaching_halo(const Dem& near, const Raster<std::uint8_t>& first) {
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
    return member;
  }

  /// The cells handed on by the tiles, by mosaic index, and the flats that cross tile edges among them.
  struct SharedFlats {
    std::unordered_map<std::int64_t, std::uint32_t> slot;
    std::vector<std::int64_t> cell_of;
    std::vector<SharedCell> cells;
  };

  std::int64_t neighbour(std::int64_t g, int k) const {
    const int gc = int(g % cols_) + dcol[k], gr = int(g / cols_) + drow[k];
    if (off_mosaic(gc, gr)) return -1;
    return std::int64_t(gr) * cols_ + gc;
  }

  /// Members of each equal-elevation component of shared cells that holds a flat cell, by root.
  std::unordered_map<std::uint32_t, std::vector<std::uint32_t>> flat_groups(const SharedFlats& s) const {
    const auto& cells = s.cells;
    Sets sets{std::vector<std::uint32_t>(cells.size())};
    std::iota(sets.parent.begin(), sets.parent.end(), 0u);
    for (std::uint32_t a = 0; a < cells.size(); ++a) {
      if (!cells[a].member) continue;
      for (int k = 0; k < 8; ++k) {
        const std::int64_t n = neighbour(s.cell_of[a], k);
        if (n < 0) continue;
        const auto it = s.slot.find(n);
        if (it != s.slot.end() && cells[it->second].member && cells[it->second].z == cells[a].z) sets.join(a, it->second);
      }
    }
    std::unordered_map<std::uint32_t, std::vector<std::uint32_t>> groups;  // root -> members holding a flat cell
    std::vector<std::uint8_t> has_flat(cells.size(), 0);
    for (std::uint32_t a = 0; a < cells.size(); ++a)
      if (cells[a].member && cells[a].code == kNoFlow) has_flat[sets.find(a)] = 1;
    for (std::uint32_t a = 0; a < cells.size(); ++a)
      if (cells[a].member && has_flat[sets.find(a)]) groups[sets.find(a)].push_back(a);
    return groups;
  }

  // Flats that cross tile edges, each gathered whole (its cells and their neighbours) on a
  // window of its bounding box and drained there: the same rings, hence the same directions.
  void drain_shared_flats() {
    SharedFlats s;
    for (auto& list : shared_) {
      for (const auto& [g, cell] : list) {
        s.slot.emplace(g, std::uint32_t(s.cells.size()));
        s.cell_of.push_back(g);
        s.cells.push_back(cell);
      }
      list = {};
    }
    std::unordered_map<std::uint32_t, std::vector<std::uint32_t>> groups = flat_groups(s);
    patches_.resize(static_cast<std::size_t>(tiles_));
    std::vector<std::uint32_t> roots;
    for (const auto& [root, members] : groups) roots.push_back(root);
    std::sort(roots.begin(), roots.end());
    for (std::uint32_t root : roots) drain_shared_flat(s, groups[root]);
    report_.global_state_bytes = std::max(report_.global_state_bytes, frame_bytes_ + double(s.cells.size()) * 48);
  }

  void drain_shared_flat(const SharedFlats& s, const std::vector<std::uint32_t>& members) {
    int c0 = cols_, r0 = rows_, c1 = -1, r1 = -1;
    for (std::uint32_t m : members) {
      const int c = int(s.cell_of[m] % cols_), r = int(s.cell_of[m] / cols_);
      c0 = std::min(c0, c);
      r0 = std::min(r0, r);
      c1 = std::max(c1, c);
      r1 = std::max(r1, r);
    }
    c0 -= 1, r0 -= 1, c1 += 1, r1 += 1;
    Dem z(c1 - c0 + 1, r1 - r0 + 1, {}, std::numeric_limits<float>::quiet_NaN());
    Raster<std::uint8_t> d8 = z.like<std::uint8_t>(kNoData);
    auto copy_cell = [&](std::int64_t g) {
      const auto it = s.slot.find(g);
      if (it == s.slot.end()) return;
      const int c = int(g % cols_) - c0, r = int(g / cols_) - r0;
      z(c, r) = s.cells[it->second].z;
      d8(c, r) = s.cells[it->second].code;
    };
    for (std::uint32_t m : members) {
      copy_cell(s.cell_of[m]);
      for (int k = 0; k < 8; ++k)
        if (const std::int64_t n = neighbour(s.cell_of[m], k); n >= 0) copy_cell(n);
    }
    report_.flat_cells_shared += members.size();
    drain_flats(z, d8);
    for (std::uint32_t m : members) {
      if (s.cells[m].code != kNoFlow) continue;
      const int gc = int(s.cell_of[m] % cols_), gr = int(s.cell_of[m] / cols_);
      const int t = grid_.tile_of(gc, gr);
      const TileRect rt = grid_.rect(t);
      patches_[std::size_t(t)].push_back({std::uint32_t((gr - rt.row0) * rt.cols + (gc - rt.col0)), d8(gc - c0, gr - r0)});
    }
  }

  std::vector<std::int64_t> own_units(const Raster<std::uint8_t>& d8, const TileRect& r) const {
    std::vector<std::int64_t> acc(d8.size(), 0);
    for (int row = 0; row < r.rows; ++row)
      for (int c = 0; c < r.cols; ++c)
        if (d8(c, row) != kNoData) acc[d8.index(c, row)] = units_.per_row[std::size_t(r.row0 + row)];
    return acc;
  }

  /// Target of the D8 code of mosaic cell (gc, gr) when it lies in another tile on valid data, else -1.
  std::int64_t crossing(int t, int gc, int gr, std::uint8_t k) const {
    if (k >= 8) return -1;
    const int nc = gc + dcol[k], nr = gr + drow[k];
    if (off_mosaic(nc, nr) || grid_.tile_of(nc, nr) == t) return -1;
    float z;
    std::uint32_t label;
    frame_cell(nc, nr, z, label);
    return label == kVoid ? -1 : std::int64_t(nr) * cols_ + nc;
  }

  /// Where the D8 paths of tile t end, in row-major order: its outlets (a cell that keeps its water,
  /// or flows off the mosaic or onto nodata: drainage_basins' outlets) and the cells that flow into
  /// another tile (its links, with their targets).
  struct PathEnds {
    std::vector<std::uint32_t> outlets, exits;
    std::vector<std::int64_t> targets;
  };
  PathEnds path_ends(int t, const TileRect& r, const Raster<std::uint8_t>& d8) const {
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
  }

  // 3. Final directions; accumulation inside each tile; the links between tiles (Barnes 2017).
  void accumulate_tiles() {
    units_ = fixed_point_units(metrics_, cols_, options_.unit);
    links_.resize(static_cast<std::size_t>(tiles_));
    outlet_rows_.resize(static_cast<std::size_t>(tiles_));
    edge_exit_.resize(static_cast<std::size_t>(tiles_));
    std::exception_ptr failure = for_tiles("accumulation of tiles", [&](int t, const TileRect& r) { accumulate_tile(t, r); });
    exchange(
        failure,
        [&](int t, std::vector<char>& out) {
          put(out, links_[std::size_t(t)]);
          put(out, edge_exit_[std::size_t(t)]);
          put(out, outlet_rows_[std::size_t(t)]);
        },
        [&](int t, Unpack& in) {
          links_[std::size_t(t)] = in.take<Link>();
          edge_exit_[std::size_t(t)] = in.take<std::int32_t>();
          outlet_rows_[std::size_t(t)] = in.take<std::uint32_t>();
        });
  }

  void accumulate_tile(int t, const TileRect& r) {
    Raster<std::uint8_t> d8 = tile_codes(r);
    d8.nodata = kNoData;
    read_codes(codes_path(t), d8);
    for (const auto& [i, k] : patches_[std::size_t(t)]) d8[i] = k;
    patches_[std::size_t(t)] = {};
    if (sinks_.d8) sinks_.d8(t, d8);
    write_codes(codes_path(t), d8);
    std::vector<std::int64_t> acc = own_units(d8, r);
    accumulate_d8_units(d8, acc);
    // Exits and outlets, then for each edge cell where its path ends: exit e >= 0, outlet j of the
    // tile (row-major) as -3 - j, -1 on nodata.
    std::vector<std::int32_t> down(d8.size(), -2);
    const PathEnds ends = path_ends(t, r, d8);
    auto& out = links_[std::size_t(t)];
    for (std::size_t e = 0; e < ends.exits.size(); ++e) {
      const std::uint32_t i = ends.exits[e];
      down[i] = std::int32_t(e);
      out.push_back({std::int64_t(r.row0) * cols_ + r.col0 + std::int64_t(i / std::uint32_t(r.cols)) * cols_ + i % std::uint32_t(r.cols),
                     ends.targets[e], acc[i]});
    }
    std::vector<std::uint32_t>& per_row = outlet_rows_[std::size_t(t)];
    per_row.assign(std::size_t(r.rows), 0);
    for (std::size_t j = 0; j < ends.outlets.size(); ++j) {
      down[ends.outlets[j]] = -3 - std::int32_t(j);
      ++per_row[ends.outlets[j] / std::uint32_t(r.cols)];
    }
    edge_exit_[std::size_t(t)] = edge_exits(r, d8, down);
  }

  /// For each edge cell of a tile (Frame order, first ring only used), the end of its path as in
  /// `down` (filled in along the way).
  static std::vector<std::int32_t> edge_exits(const TileRect& r, const Raster<std::uint8_t>& d8, std::vector<std::int32_t>& down) {
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
    return exits;
  }

  /// The exit (>= 0) or outlet (-3 - j) of the path through mosaic cell `g` of tile `u`.
  std::int32_t edge_exit_at(std::int64_t g, int& u) const {
    const int gc = int(g % cols_), gr = int(g / cols_);
    u = grid_.tile_of(gc, gr);
    const TileRect ru = grid_.rect(u);
    return edge_exit_[std::size_t(u)][Frame(ru, false).index(gc - ru.col0, gr - ru.row0)];
  }

  /// Outlet j of tile u: its basin label, outlets numbered in row-major order of the mosaic.
  std::uint32_t basin_of_outlet(int u, std::uint32_t j) const {
    const auto& above = outlets_above_[std::size_t(u)];
    const std::size_t row = std::size_t(std::upper_bound(above.begin(), above.end(), j) - above.begin()) - 1;
    std::uint64_t rank = before_row_[std::size_t(grid_.rect(u).row0) + row] + (j - above[row]);
    for (int v = u - u % grid_.across(); v < u; ++v) rank += outlet_rows_[std::size_t(v)][row];  // on the row, to the west
    return std::uint32_t(rank + 1);
  }

  // The link graph: each link flows into the tile of its target and leaves it by that cell's
  // exit; solved in topological order, the sums exact.
  void solve_link_graph() {
    link_base_.assign(static_cast<std::size_t>(tiles_) + 1, 0);
    for (int t = 0; t < tiles_; ++t) link_base_[std::size_t(t) + 1] = link_base_[std::size_t(t)] + std::uint32_t(links_[std::size_t(t)].size());
    const std::uint32_t link_count = link_base_.back();
    report_.links = link_count;
    std::vector<Link> all;
    all.reserve(link_count);
    for (auto& l : links_) {
      all.insert(all.end(), l.begin(), l.end());
      l = {};
    }
    std::vector<std::int64_t> next(link_count, -1);
    std::vector<std::uint32_t> indegree(link_count, 0);
    for (std::uint32_t y = 0; y < link_count; ++y) {
      int u = 0;
      const std::int32_t e = edge_exit_at(all[y].target, u);
      if (e >= 0) {
        next[y] = link_base_[std::size_t(u)] + std::uint32_t(e);
        ++indegree[std::size_t(next[y])];
      }
    }
    number_outlets();
    if (sinks_.basins) label_links(all, next);
    edge_exit_ = {};
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
    inflow_.resize(static_cast<std::size_t>(tiles_));
    for (std::uint32_t y = 0; y < link_count; ++y) {
      const int gc = int(all[y].target % cols_), gr = int(all[y].target / cols_);
      const int u = grid_.tile_of(gc, gr);
      const TileRect ru = grid_.rect(u);
      inflow_[std::size_t(u)].push_back({std::uint32_t((gr - ru.row0) * ru.cols + (gc - ru.col0)), total[y]});
    }
    report_.global_state_bytes = std::max(report_.global_state_bytes, frame_bytes_ + double(link_count) * 60 + double(rows_) * 16);
  }

  // Basins: outlets numbered in row-major order of the mosaic (drainage_basins), from the tiles'
  // outlets by row.
  void number_outlets() {
    before_row_.assign(std::size_t(rows_) + 1, 0);  // outlets of the mosaic's rows above
    outlets_above_.resize(static_cast<std::size_t>(tiles_));  // a tile's, above each row
    for (int t = 0; t < tiles_; ++t) {
      const TileRect r = grid_.rect(t);
      auto& above = outlets_above_[std::size_t(t)];
      above.assign(std::size_t(r.rows) + 1, 0);
      for (int row = 0; row < r.rows; ++row) {
        const std::uint32_t n = outlet_rows_[std::size_t(t)][std::size_t(row)];
        above[std::size_t(row) + 1] = above[std::size_t(row)] + n;
        before_row_[std::size_t(r.row0 + row) + 1] += n;
      }
    }
    for (int row = 0; row < rows_; ++row) before_row_[std::size_t(row) + 1] += before_row_[std::size_t(row)];
    if (sinks_.basins && before_row_.back() >= 0xFFFFFFFFu) throw bad_input("basins: more than 2^32 - 2 outlets");
  }

  /// Each link labelled with the basin its chain of links ends in.
  void label_links(const std::vector<Link>& all, const std::vector<std::int64_t>& next) {
    link_basin_.assign(all.size(), 0);
    std::vector<std::uint32_t> chain;
    for (std::uint32_t y = 0; y < link_basin_.size(); ++y) {
      chain.clear();
      std::uint32_t z = y;
      for (; link_basin_[z] == 0 && next[z] >= 0; z = std::uint32_t(next[z])) chain.push_back(z);
      if (link_basin_[z] == 0) {
        int u = 0;
        const std::int32_t e = edge_exit_at(all[z].target, u);
        link_basin_[z] = basin_of_outlet(u, std::uint32_t(-3 - e));
      }
      for (std::uint32_t x : chain) link_basin_[x] = link_basin_[z];
    }
  }

  // 4. The accumulation again, with what flows in from the other tiles; the stream cells kept.
  // False when there are no streams to gather (every process's tiles written).
  bool final_accumulation() {
    if (sinks_.streams && options_.unit != AccumulationUnit::area_m2)
      throw bad_input("tiles: streams need the accumulation as an area (--area-units m2 or km2)");
    stream_cells_.resize(static_cast<std::size_t>(tiles_));
    std::exception_ptr failure = nullptr;
    if (sinks_.accumulation || sinks_.streams || sinks_.basins)
      failure = for_tiles("accumulation", [&](int t, const TileRect& r) { finish_tile(t, r); });
    if (!sinks_.streams) {
      driver_.check(failure);
      return false;
    }
    exchange(
        failure, [&](int t, std::vector<char>& out) { put(out, stream_cells_[std::size_t(t)]); },
        [&](int t, Unpack& in) { stream_cells_[std::size_t(t)] = in.take<StreamCell>(); });
    return true;
  }

  void finish_tile(int t, const TileRect& r) {
    Raster<std::uint8_t> d8 = tile_codes(r);
    read_codes(codes_path(t), d8);
    if (sinks_.basins) {
      Raster<std::uint32_t> basins = d8.like<std::uint32_t>(0);
      basins.nodata = 0;
      const PathEnds ends = path_ends(t, r, d8);
      for (std::size_t e = 0; e < ends.exits.size(); ++e) basins[ends.exits[e]] = link_basin_[link_base_[std::size_t(t)] + e];
      for (std::size_t j = 0; j < ends.outlets.size(); ++j) basins[ends.outlets[j]] = basin_of_outlet(t, std::uint32_t(j));
      label_by_descent(d8, basins);
      sinks_.basins(t, basins);
    }
    if (!sinks_.accumulation && !sinks_.streams) return;
    std::vector<std::int64_t> acc = own_units(d8, r);
    for (const auto& [i, v] : inflow_[std::size_t(t)]) acc[i] += v;
    inflow_[std::size_t(t)] = {};
    accumulate_d8_units(d8, acc);
    Raster<double> out = d8.like<double>(0.0);
    for (std::size_t i = 0; i < out.size(); ++i) out[i] = d8[i] == kNoData ? NAN : units_.value(acc[i]);
    if (sinks_.streams)
      for (int row = 0; row < r.rows; ++row)
        for (int c = 0; c < r.cols; ++c)
          if (const double a = out(c, row); d8(c, row) != kNoData && a >= options_.streams_threshold_m2)
            stream_cells_[std::size_t(t)].push_back({std::int64_t(r.row0 + row) * cols_ + r.col0 + c, a, d8(c, row)});
    if (sinks_.accumulation) sinks_.accumulation(t, out);
  }

  /// The stream cells of every tile, in mosaic order, handed to the streams sink on rank 0.
  void gather_streams() {
    if (driver_.rank() != 0) return;
    std::vector<StreamCell> network;
    for (auto& part : stream_cells_) {
      network.insert(network.end(), part.begin(), part.end());
      part = {};
    }
    std::sort(network.begin(), network.end(), [](const StreamCell& a, const StreamCell& b) { return a.index < b.index; });
    StreamCells streams{cols_, rows_, {}, {}, {}};
    for (const StreamCell& cell : network) {
      streams.index.push_back(cell.index);
      streams.code.push_back(cell.code);
      streams.area_m2.push_back(cell.area_m2);
    }
    report_.stream_cells = network.size();
    report_.global_state_bytes = std::max(report_.global_state_bytes, frame_bytes_ + double(network.size()) * 40);
    network = {};
    sinks_.streams(streams);
  }

  const int cols_, rows_;
  const Georef& georef_;
  const ReadWindow& read_;
  const TiledOptions& options_;
  const TileSinks& sinks_;
  Progress& progress_;
  TileDriver& driver_;
  TiledReport report_;
  const TileGrid grid_;
  const int tiles_;
  const CellMetrics metrics_;
  tbb::task_arena arena_;
  const std::filesystem::path scratch_;
  std::vector<int> own_;  // the tiles this process reads and writes
  // Pass 1 and the spill graph.
  std::vector<Frame> frames_;
  std::vector<std::vector<SpillEdge>> tile_edges_;
  std::vector<std::uint32_t> tile_labels_, base_;
  std::vector<float> level_;
  double frame_bytes_ = 0;
  // Pass 2 and the shared flats: the cells handed on, then the codes of the flats solved whole.
  std::vector<std::vector<SharedEntry>> shared_;
  std::vector<std::vector<std::pair<std::uint32_t, std::uint8_t>>> patches_;
  // Pass 3 and the link graph.
  FixedPointUnits units_;
  std::vector<std::vector<Link>> links_;
  std::vector<std::vector<std::uint32_t>> outlet_rows_;  // outlets of each tile by row (the basins' numbering)
  std::vector<std::vector<std::int32_t>> edge_exit_;     // for each edge cell of a tile (Frame order), the link its flow leaves by
  std::vector<std::uint32_t> link_base_, link_basin_;
  std::vector<std::uint64_t> before_row_;
  std::vector<std::vector<std::uint32_t>> outlets_above_;
  std::vector<std::vector<std::pair<std::uint32_t, std::int64_t>>> inflow_;
  // Pass 4.
  std::vector<std::vector<StreamCell>> stream_cells_;
};

}  // namespace

TiledReport run_tiled_hydro(int cols, int rows, const Georef& georef, const ReadWindow& read, const TiledOptions& options,
                            const TileSinks& sinks, Progress& progress, TileDriver& driver) {
  TiledRun run(cols, rows, georef, read, options, sinks, progress, driver);
  return run.run();
}

}  // namespace terrapolis::hydro::tiled
