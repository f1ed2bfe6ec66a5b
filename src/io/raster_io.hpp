// Reading DEMs and rasters from any GDAL format, and writing GeoTIFF / Cloud Optimized GeoTIFF.
// SPDX-License-Identifier: MIT
#pragma once
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/raster.hpp"

namespace terrapolis {

/// Registers GDAL's drivers and quiets its side files (.aux.xml); safe to call many times.
void init_gdal();

struct ReadOptions {
  std::optional<int> band;                ///< 1-based band; required for multi-band files
  std::optional<std::string> assume_crs;  ///< CRS for files that carry none ("EPSG:n", WKT, PROJ)
  /// The raster is read by windows (DemWindowReader): no whole-raster size check.
  bool windowed = false;
};

/// ReadOptions of a DEM input as commands and scenarios give it: `band` 0 for the only band,
/// `assume_crs` "" for none (the scenario's input.band and input.assume_crs, --band and --assume-crs).
ReadOptions read_options(int band, const std::string& assume_crs);

/// What a raster file holds, read from its header only (no pixel is read).
struct RasterHeader {
  int cols = 0, rows = 0, bands = 0;
  std::string driver, data_type, vertical_unit;
  Georef georef;
  std::optional<double> nodata;
  double scale = 1.0, offset = 0.0;
};

/// The georeferencing checks every raster read applies (finite, non-degenerate cells; an extent on
/// the globe; cells that transform to WGS 84), for a grid built in code: throws bad_input naming `what`.
void check_grid_georeferencing(const std::string& what, const RasterHeader& header);

/// Reads the header of `path`, applying the same checks as read_dem except for reading pixels.
RasterHeader read_header(const std::string& path, const ReadOptions& options = {});
/// The grid of a raster in memory: size, georeferencing, nodata.
template <class T>
RasterHeader grid_of(const Raster<T>& raster) {
  RasterHeader h;
  h.cols = raster.cols();
  h.rows = raster.rows();
  h.bands = 1;
  h.georef = raster.georef();
  return h;
}

/// Reads an elevation model as metres in float32, NaN where there is no data.
/// Honours the nodata value (including NaN, and 65535 in UInt16), the mask band, scale/offset, and
/// vertical units in feet. Throws bad_input, naming the file, when the file is missing, unreadable,
/// corrupt, has no CRS (unless assume_crs), is a multi-band colour image (unless band), is smaller
/// than 2x2, would not fit in memory, or holds no data at all.
Dem read_dem(const std::string& path, const ReadOptions& options = {});

/// GDAL resampling methods offered for layers read onto a DEM's grid.
enum class Resampling { nearest, bilinear, cubic, average, mode };

/// GDAL's warp scale (its XSCALE and YSCALE: destination cells per source cell along each axis),
/// which sizes the resampling kernel when a layer is downsampled.
struct WarpScale {
  double x = 1, y = 1;
};

/// Reads band `band` of any GDAL raster warped onto the grid of `like` (NaN where nodata/outside).
/// `scale`: a kernel size fixed for the whole warp (warp_scale), or nullptr for GDAL's own, which it
/// sets for each chunk it warps: a window of a grid is then not the whole grid's, bit for bit.
Raster<float> read_resampled(const std::string& path, const Georef& like, int cols, int rows,
                             Resampling resampling = Resampling::bilinear, int band = 1, const WarpScale* scale = nullptr);

/// The warp scale of `path` onto the grid of `like` (`cols` x `rows`) at the grid's centre: from the
/// source cells a square of destination cells spans there, as GDAL measures a square chunk. One scale
/// for a grid and all its windows makes each window's warp the grid's.
WarpScale warp_scale(const std::string& path, const Georef& like, int cols, int rows);

/// read_resampled of `path` onto the grid of `like` (`cols` x `rows`) band by band, for a grid
/// larger than memory: bands of whole rows of at most `band_cells` cells (8 bytes a cell while
/// read, 16 MB by default), each handed to `band` with its first row.
void read_resampled_by_bands(const std::string& path, const Georef& like, int cols, int rows, Resampling resampling, const WarpScale* scale,
                             const std::function<void(const Raster<float>& band, int row0)>& band, std::size_t band_cells = std::size_t(1) << 21);

struct WriteOptions {
  bool cog = false;        ///< Cloud Optimized GeoTIFF layout (GDAL's COG driver)
  bool overwrite = false;  ///< replace an existing file
  std::string description;  ///< what the raster is, stored as the band description
  std::vector<std::pair<std::string, std::string>> metadata;  ///< dataset metadata items (provenance)
  /// DEFLATE level, 1 (fastest) to 9 (smallest); 6 is GDAL's default. Level 1 writes a 13 M-cell
  /// float raster about 3 times faster for files about 4 % larger.
  int deflate_level = 6;
};

/// Writes a GeoTIFF (tiled, DEFLATE with predictor, BigTIFF when needed) under a temporary name
/// then renames it. CRS, geotransform and nodata are kept. Instantiated for float, double,
/// uint8, int16, uint16, int32, uint32.
template <class T>
void write_raster(const std::string& path, const Raster<T>& raster, const WriteOptions& options = {});

/// Reads windows of an elevation model too large to hold whole: a GeoTIFF (BigTIFF), a GDAL VRT
/// mosaic, or a folder of GeoTIFF tiles (joined into an in-memory VRT, which refuses tiles of
/// different CRSs or resolutions). Values as read_dem's: metres, NaN nodata.
/// The GeoTIFF tiles (.tif, .tiff) of a folder DEM, in name order: the order they are joined in.
std::vector<std::string> folder_tiles(const std::string& folder);

/// Bounds what GDAL holds while a mosaic is read by windows under a memory limit: its block cache to
/// min(64 MB, limit / 8) and its pool of open source files to 16 (about 0.8 MB each), unless the user
/// set GDAL_CACHEMAX or GDAL_MAX_DATASET_POOL_SIZE. Returns the MB the tiles must leave free: those
/// two and the process's resident memory now (libraries, GDAL and PROJ set up, about 66 MB).
double reserve_reader_memory(double limit_mb);

class DemWindowReader {
 public:
  explicit DemWindowReader(const std::string& path, ReadOptions options = {});
  ~DemWindowReader();
  DemWindowReader(const DemWindowReader&) = delete;
  DemWindowReader& operator=(const DemWindowReader&) = delete;
  const RasterHeader& header() const { return header_; }
  const std::string& path() const { return path_; }
  /// The cells [col0, col0 + cols) x [row0, row0 + rows); those outside the raster are NaN. The
  /// georeferencing is the window's. Serialised: one reader may be shared between threads.
  Dem read(int col0, int row0, int cols, int rows) const;
  /// Reads every cell once, by strips of rows, as read_dem would check them: throws bad_input for a
  /// file that cannot be read through or holds no data (before a tiled run's first stage).
  void check_cells() const;

 private:
  struct Dataset;
  std::string path_;
  RasterHeader header_;
  std::unique_ptr<Dataset> dataset_;
};

/// Writes a GDAL VRT mosaic of `tiles` (paths stored relative to the VRT's folder) under a
/// temporary name, then renames it.
void write_vrt(const std::string& path, const std::vector<std::string>& tiles, bool overwrite);

/// A folder for temporary files, created empty and removed with everything in it when it goes
/// out of scope, errors included.
class ScratchFolder {
 public:
  explicit ScratchFolder(std::string path);
  ~ScratchFolder();
  ScratchFolder(const ScratchFolder&) = delete;
  ScratchFolder& operator=(const ScratchFolder&) = delete;
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

/// Single cells of a raster read by windows (a mosaic larger than memory), through a cache of
/// square blocks: `max_blocks` blocks of `block` cells a side at most (4 bytes a cell), all dropped
/// when it is full. Not thread-safe.
class CellSampler {
 public:
  explicit CellSampler(const DemWindowReader& reader, int block = 256, std::size_t max_blocks = 64);
  /// The value at (col, row), inside the raster; NaN on nodata.
  float at(int col, int row);

 private:
  const DemWindowReader& reader_;
  int block_;
  std::size_t max_blocks_;
  std::map<std::pair<int, int>, Dem> blocks_;
};

/// A raster written tile by tile: tile t of a mosaic `across` tiles wide as
/// DIR/NAME/tile_RRRR_CCCC.tif, then DIR/NAME.vrt over them all.
struct MosaicFiles {
  std::string dir, name;
  std::string tile(int t, int across) const;
  std::string vrt() const { return dir + "/" + name + ".vrt"; }
  /// Creates DIR/NAME/ for the tiles, empty (DIR is a folder being written: a staging or run folder).
  void create() const;
  /// Writes the VRT over tiles 0 .. tiles - 1, replacing the one there.
  void finish(int tiles, int across) const;
};

}  // namespace terrapolis
