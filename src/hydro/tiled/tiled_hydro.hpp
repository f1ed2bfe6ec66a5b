// The tile engine of the hydrology stage: fill, D8 directions and accumulation of a mosaic read
// and written tile by tile, in bounded memory, bit-identical to the whole-grid computation.
// SPDX-License-Identifier: MIT
#pragma once
#include <algorithm>
#include <cstdint>
#include <exception>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "core/progress.hpp"
#include "core/raster.hpp"
#include "hydro/accumulation.hpp"
#include "hydro/streams.hpp"

namespace terrapolis::hydro::tiled {

/// A rectangle of cells of the mosaic.
struct TileRect {
  int col0 = 0, row0 = 0, cols = 0, rows = 0;
};

/// The mosaic cut into tiles of about `tile_size` cells a side (at least 8): tiles of a row or a
/// column of tiles differ by at most one cell, tiles are numbered row-major from the north-west.
class TileGrid {
 public:
  TileGrid(int cols, int rows, int tile_size);
  int count() const { return across() * down(); }
  int across() const { return int(col_bounds_.size()) - 1; }
  int down() const { return int(row_bounds_.size()) - 1; }
  int cols() const { return col_bounds_.back(); }
  int rows() const { return row_bounds_.back(); }
  TileRect rect(int tile) const;
  /// The tile holding cell (col,row) of the mosaic (inside it).
  int tile_of(int col, int row) const;
  /// Tile `tile` grown by a halo of `halo_cols` and `halo_rows` cells, within the mosaic.
  TileRect grown(int tile, int halo_cols, int halo_rows) const;

 private:
  std::vector<int> col_bounds_, row_bounds_;
};

/// The georeferencing of the window of `g`'s grid whose first cell is (col0, row0).
Georef shifted(const Georef& g, int col0, int row0);

/// The cells [x0, x0 + cols) x [y0, y0 + rows) of `r` as a raster of their own (empty stays empty).
template <class T>
Raster<T> crop(const Raster<T>& r, int x0, int y0, int cols, int rows) {
  if (r.size() == 0) return r;
  Raster<T> out(cols, rows, shifted(r.georef(), x0, y0));
  out.nodata = r.nodata;
  for (int y = 0; y < rows; ++y) std::copy_n(&r(x0, y0 + y), cols, &out(0, y));
  return out;
}

/// Who processes which tiles, and how what a pass learnt about its tiles (their frames, spill
/// edges, shared flat cells, links: perimeters and global graphs, never whole tiles) reaches every
/// process before the next pass. LocalTiles: all tiles in this process; terrapolis-mpi: tiles
/// dealt round-robin to MPI ranks (src/cli/mpi_main.cpp). Every process solves the global graphs
/// itself, from the same gathered bytes: the same answer everywhere, no further messages.
class TileDriver {
 public:
  virtual ~TileDriver() = default;
  virtual int rank() const = 0;
  virtual int ranks() const = 0;
  bool owns(int tile) const { return tile % ranks() == rank(); }
  /// Collective. `per_tile[t]` holds the bytes of each tile t this process owns; on return, those
  /// of every tile. `failure`: this process's pass failed; if any process's did, every process
  /// throws the lowest failing rank's error (a terrapolis::Error), and share() is not called again.
  virtual void share(std::vector<std::vector<char>>& per_tile, std::exception_ptr failure) = 0;
  /// Collective: share() with nothing to share; throws the first failure of any process.
  void check(std::exception_ptr failure) {
    std::vector<std::vector<char>> none;
    share(none, failure);
  }
};

/// Every tile in this process.
class LocalTiles final : public TileDriver {
 public:
  int rank() const override { return 0; }
  int ranks() const override { return 1; }
  void share(std::vector<std::vector<char>>&, std::exception_ptr failure) override {
    if (failure) std::rethrow_exception(failure);
  }
};

/// Reads cells [col0, col0+cols) x [row0, row0+rows) of the mosaic's DEM (metres, NaN nodata;
/// NaN outside the mosaic). Called from several threads at once, for the tiles this process owns.
using ReadWindow = std::function<Dem(int col0, int row0, int cols, int rows)>;

/// What the engine hands out, one tile this process owns at a time (from several threads at once), each raster on
/// its tile's grid and georeferencing; an empty function skips that output's work where it can.
struct TileSinks {
  std::function<void(int tile, const Dem& filled)> filled;
  std::function<void(int tile, const Raster<std::uint8_t>& d8)> d8;  ///< flow_directions.hpp codes
  std::function<void(int tile, const Raster<double>& accumulation)> accumulation;
  /// drainage_basins (catchment.hpp) of the whole mosaic, on the tile: labels stitched across tiles.
  std::function<void(int tile, const Raster<std::uint32_t>& basins)> basins;
  /// The stream cells of the whole mosaic (TiledOptions::streams_threshold_m2), gathered from
  /// every tile, on rank 0 only: streams_of_cells makes the whole grid's reaches of them.
  std::function<void(StreamCells& cells)> streams;
};

struct TiledOptions {
  /// Tile side in cells; 0: the largest that keeps the state within memory_limit_mb.
  int tile_size = 0;
  /// Memory for the process, MB: the engine's state (tiles being processed, the global graphs) gets
  /// all of it but reserved_mb, what the process and the mosaic's reader hold (reserve_reader_memory).
  double memory_limit_mb = 1024;
  double reserved_mb = 0;
  /// Tiles processed at once by this process (each holds its state): 0 = as many as threads allowed.
  int concurrent_tiles = 0;
  std::optional<double> sea_level;
  AccumulationUnit unit = AccumulationUnit::area_m2;
  /// Upstream area from which a cell is on a stream (m², unit area_m2), for TileSinks::streams.
  double streams_threshold_m2 = 10e6;
  /// Folder for the D8 codes kept between passes (1 byte a cell, removed at the end).
  std::string scratch_dir;
};

/// What a run did, for logs and the memory bound.
struct TiledReport {
  int tile_size = 0, tiles = 0, concurrent_tiles = 0;
  std::uint64_t labels = 0, spill_edges = 0;   ///< Barnes 2016 spillover graph
  std::uint64_t flat_cells_shared = 0;          ///< undrained cells of flats that cross tile edges, drained by tiles
  std::uint64_t flat_rounds = 0;                ///< rounds of tiles exchanging those flats' rings
  std::uint64_t links = 0;                      ///< Barnes 2017: flow paths leaving a tile
  std::uint64_t stream_cells = 0;               ///< cells of the stream network gathered (rank 0)
  double tile_state_bytes = 0;                  ///< per tile processed at once
  double global_state_bytes = 0;                ///< at the largest: frames plus the spill graph, shared flats or links
  std::uint64_t bytes_sent = 0, bytes_received = 0;  ///< by this process in the exchanges between passes (0 on one process)
};

/// Bytes of state per cell of a tile processed at once (the largest pass: the fill's labels and
/// queue, the halo windows, the flat resolution's arrays), used to size tiles from a memory limit.
inline constexpr double kTileBytesPerCell = 48;

/// The tile side that keeps `concurrent` tiles and the global state of a cols x rows mosaic
/// within `memory_limit_mb` less `reserved_mb` (what the process and the mosaic's reader hold:
/// reserve_reader_memory); throws bad_input when not even 64-cell tiles fit.
int tile_size_for(int cols, int rows, double memory_limit_mb, int concurrent, double reserved_mb = 0);
/// The largest tile side, from 32768 down by eighths to 64, whose state `bytes(side)` fits
/// `memory_limit_mb` less `reserved_mb`; throws bad_input (too_little ... "for `what`") when none does.
int largest_tile_side(const std::function<double(int side)>& bytes, double memory_limit_mb, double reserved_mb, const std::string& what);

/// The start of the error of a memory limit too small for any tiling ("/input/memory_limit_mb: L MB
/// (R MB of it held by ...) is too little").
std::string too_little(double memory_limit_mb, double reserved_mb);

/// The threads this process may use (--threads, or what terrapolis-mpi leaves to each rank).
int allowed_threads();

/// Runs priority-flood filling (Barnes 2016), D8 with flat resolution (Barnes et al. 2014b, flats
/// that cross tile edges solved by tiles that exchange their outer rings) and D8 accumulation
/// (Barnes 2017, fixed-point sums) on a `cols` x `rows` mosaic georeferenced by `georef`. The tiles handed to `sinks`,
/// put together, equal fill_depressions (priority_flood), d8_directions and accumulate (D8) on the
/// whole grid bit for bit, for any tile size. Deterministic for any thread and process count.
/// Collective over `driver`'s processes: each reads and hands out only the tiles it owns.
TiledReport run_tiled_hydro(int cols, int rows, const Georef& georef, const ReadWindow& read, const TiledOptions& options,
                            const TileSinks& sinks, Progress& progress, TileDriver& driver);

}  // namespace terrapolis::hydro::tiled
