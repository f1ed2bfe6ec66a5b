// The state and passes of one run of the tile engine (run_tiled_hydro), private to src/hydro/tiled:
// the per-tile records the passes hand on, and TiledRun, whose passes live one group a file.
// SPDX-License-Identifier: MIT
#pragma once
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <exception>
#include <filesystem>
#include <limits>
#include <mutex>
#include <optional>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include "core/geodesy.hpp"
#include "hydro/depressions.hpp"
#include "hydro/exact_accumulation.hpp"
#include "hydro/grid.hpp"
#include "hydro/spill_graph.hpp"
#include "hydro/tiled/tile_bytes.hpp"
#include "hydro/tiled/tiled_hydro.hpp"

namespace terrapolis::hydro::tiled {

inline constexpr std::uint32_t kVoid = 0xFFFFFFFFu, kOpen = 0xFFFFFFFEu;  // labels: nodata, not reached yet

/// The cells of a tile within `width` cells of its edges (every cell when it is under 2 x width
/// cells wide or high), numbered: the north rows, the south rows, then the west and east cells of
/// each row between.
class Border {
 public:
  Border() = default;
  Border(const TileRect& r, int width) : cols_(r.cols), rows_(r.rows), w_(width) {}
  std::size_t size() const {
    return whole() ? cells(cols_) * cells(rows_) : 2 * cells(w_) * (cells(cols_) + cells(rows_ - 2 * w_));
  }
  bool contains(int c, int r) const { return std::min({c, r, cols_ - 1 - c, rows_ - 1 - r}) < w_; }
  std::size_t index(int c, int r) const {
    if (whole() || r < w_) return cells(r) * cells(cols_) + cells(c);
    if (r >= rows_ - w_) return cells(w_ + r - (rows_ - w_)) * cells(cols_) + cells(c);
    return 2 * cells(w_) * cells(cols_) + cells(r - w_) * 2 * cells(w_) + cells(c < w_ ? c : w_ + c - (cols_ - w_));
  }

 private:
  static std::size_t cells(int n) { return std::size_t(n); }
  bool whole() const { return cols_ < 2 * w_ || rows_ < 2 * w_; }
  int cols_ = 0, rows_ = 0, w_ = 1;
};

/// The cells of a tile within two of its edges (where neighbouring tiles look): filled values
/// and global labels after the first pass.
class Frame : public Border {
 public:
  Frame() = default;
  /// The shape only, or with room for the values.
  explicit Frame(const TileRect& r, bool with_values = true) : Border(r, 2) {
    if (!with_values) return;
    z.resize(size());
    label.resize(size());
  }
  std::vector<float> z;
  std::vector<std::uint32_t> label;  // global
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
TileFill fill_tile(const Dem& window, const std::optional<double>& sea_level);  // fill_pass.cpp

/// The outer ring of cells of a tile (its border one cell wide).
struct Ring : Border {
  explicit Ring(const TileRect& r) : Border(r, 1) {}
};

inline constexpr std::int32_t kFar = std::numeric_limits<std::int32_t>::max() / 4;  // no wave reaches the cell
inline constexpr std::uint32_t kNoPiece = 0xFFFFFFFFu;

/// A cell of a tile's outer ring in a flat that crosses tile edges (Barnes et al. 2014b's flat:
/// the 8-connected cells of one elevation, undrained and draining, non-terminal): the piece of the
/// flat it belongs to in its tile (kNoPiece: none), and its distances in cell steps over the flat's
/// undrained cells from the nearest high edge (`away`) and from the nearest low edge (`towards`),
/// kFar where no path reaches. Draining cells: kFar and 0 (they are the low edges).
struct RingCell {
  std::uint32_t piece;
  std::int32_t away, towards;
  friend bool operator==(const RingCell&, const RingCell&) = default;
};

/// The cells of a flat crossing tile edges that lie in one tile and are connected inside it: whether
/// they hold undrained and draining cells, and the largest away + 1 over their undrained cells (0:
/// none reached), whose maximum over the flat is Barnes 2014b's flat height.
struct FlatPiece {
  std::uint8_t undrained, draining;
  std::int32_t height;
};

/// Cells of `near` (a tile with a halo of one cell) whose equal-elevation component of non-terminal
/// cells, by first-pass codes `first`, reaches the halo: their flat is not whole in the tile.
std::vector<std::uint8_t> flats_reaching_halo(const Dem& near, const Raster<std::uint8_t>& first);

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

/// The D8 codes of a tile kept on a scratch file between passes (tiled_run.cpp).
void write_codes(const std::string& path, const Raster<std::uint8_t>& d8);
void read_codes(const std::string& path, Raster<std::uint8_t>& d8);

/// One run of the engine: the state its passes hand on to each other. Each pass works on the
/// tiles this process owns, then exchange() gives every process what it learnt about every tile.
class TiledRun {
 public:
  TiledRun(int cols, int rows, const Georef& georef, const ReadWindow& read, const TiledOptions& options, const TileSinks& sinks,
           Progress& progress, TileDriver& driver);
  ~TiledRun();
  TiledRun(const TiledRun&) = delete;
  TiledRun& operator=(const TiledRun&) = delete;

  /// The passes in order (tiled_run.cpp).
  TiledReport run();

 private:
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
    for (int t : own_) report_.bytes_sent += bytes[std::size_t(t)].size();
    driver_.share(bytes, failure);
    for (int t = 0; t < tiles_; ++t)
      if (!driver_.owns(t)) {
        report_.bytes_received += bytes[std::size_t(t)].size();
        Unpack in(bytes[std::size_t(t)]);
        unpack(t, in);
        release(bytes[std::size_t(t)]);
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

  // fill_pass.cpp: pass 1 and the spill graph (Barnes 2016).
  void fill_tiles();
  void solve_spill_graph();
  void add_edges_across_tiles(std::vector<SpillEdge>& edges) const;

  // direction_pass.cpp: pass 2, first-pass D8 and the flats inside each tile.
  void direct_tiles();
  void direct_tile(int t, const TileRect& r);
  Dem with_halo(const TileRect& r, const Dem& filled) const;

  // shared_flats.cpp: the flats that cross tile edges, drained by tiles.
  void share_tile_flats(int t, const TileRect& r, const Dem& near, const Raster<std::uint8_t>& first,
                        const std::vector<std::uint8_t>& member);
  const RingCell* ring_cell(int gc, int gr) const;
  void join_pieces();
  void solve_shared_flats();
  bool flat_round(std::vector<std::uint8_t>& solving);
  void solve_tile_flats(int t, const TileRect& r, std::vector<RingCell>& ring);
  void direct_tile_flats(int t, const TileRect& r, Raster<std::uint8_t>& d8) const;
  std::string flats_path(int t) const { return (scratch_ / ("flats-" + std::to_string(t) + ".bin")).string(); }

  // accumulation_pass.cpp: pass 3, final directions, accumulation inside each tile, links (Barnes 2017).
  std::vector<std::int64_t> own_units(const Raster<std::uint8_t>& d8, const TileRect& r) const;
  std::int64_t crossing(int t, int gc, int gr, std::uint8_t k) const;
  /// Where the D8 paths of tile t end, in row-major order: its outlets (a cell that keeps its water,
  /// or flows off the mosaic or onto nodata: drainage_basins' outlets) and the cells that flow into
  /// another tile (its links, with their targets).
  struct PathEnds {
    std::vector<std::uint32_t> outlets, exits;
    std::vector<std::int64_t> targets;
  };
  PathEnds path_ends(int t, const TileRect& r, const Raster<std::uint8_t>& d8) const;
  void accumulate_tiles();
  void accumulate_tile(int t, const TileRect& r);

  // link_graph.cpp: the links solved across tiles, the outlets numbered for the basins.
  std::int32_t edge_exit_at(std::int64_t g, int& u) const;
  std::uint32_t basin_of_outlet(int u, std::uint32_t j) const;
  void solve_link_graph();
  void number_outlets();
  void label_links(const std::vector<Link>& all, const std::vector<std::int64_t>& next);

  // final_accumulation.cpp: pass 4, the outputs; the stream cells gathered.
  bool final_accumulation();
  void finish_tile(int t, const TileRect& r);
  void gather_streams();

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
  // Pass 2 and the shared flats: each tile's outer ring and pieces of them, the global flats.
  std::vector<std::vector<RingCell>> ring_, fresh_ring_;  // by tile, Ring order; empty: no shared flat
  std::vector<std::vector<FlatPiece>> pieces_;
  std::vector<std::uint64_t> flat_cells_;  // by tile: undrained cells of shared flats (> 0: a scratch file)
  std::vector<std::uint32_t> piece_base_;  // global piece = base + piece in its tile
  std::vector<std::uint32_t> flat_of_;     // global piece -> its flat (the smallest global piece of it)
  std::vector<std::int32_t> flat_height_;  // by flat: Barnes 2014b's flat height; -1: no low edge, undrainable
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

}  // namespace terrapolis::hydro::tiled
