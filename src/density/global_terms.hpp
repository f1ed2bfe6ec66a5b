// What the terrain terms take from the whole grid: the land ranks and the distances to water and
// rivers, in memory or, for a grid larger than memory, by bands, strips and a scratch file.
// SPDX-License-Identifier: MIT
#pragma once
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "core/geodesy.hpp"
#include "core/progress.hpp"

namespace terrapolis::density {

/// Ranks among the region's land cells (the share of cells below, ties counted half, in [0,1]) on
/// the values rounded down to the float's top 20 bits (11 bits of mantissa): steps of 0.03 m at
/// 100 m of altitude, 0.5 m at 1024-2048 m, 2 m above 4096 m, 0.004 degree at 15 degrees of slope.
/// The rounding makes the counts a fixed table of 2^20 (4 MB) that tiles add up in any order, so a
/// region larger than memory gets the whole grid's ranks bit for bit.
class LandRanks {
 public:
  static constexpr int kKeyBits = 20;
  static constexpr double kBytes = double(std::size_t(1) << kKeyBits) * sizeof(std::uint32_t);
  LandRanks();
  /// Counts the values that are not NaN (throws when one key would hold 2^32 cells).
  void add(const float* values, std::size_t n);
  /// Turns the counts into ranks (call once, after the last add).
  void finish();
  /// The rank of v (finish called): the share of the counted values below v's key, plus half its own.
  float rank(float v) const;
  std::uint64_t count() const { return total_; }

 private:
  static std::size_t key(float v);
  std::vector<std::uint32_t> counts_;
  std::vector<float> ranks_;
  std::uint64_t total_ = 0;
};

/// Distance in metres from each cell's centre to the nearest cell where `feature` is non-zero
/// (infinity when there is none): an exact Euclidean transform (Felzenszwalb & Huttenlocher
/// 2012) with columns measured at the feature row's width, rows by the northings of the grid.
std::vector<float> distance_to_m(const std::vector<std::uint8_t>& feature, const CellMetrics& metrics, int cols, int rows);

/// distance_to_m for a grid larger than memory, for several features at once: the rows'
/// transform by bands of full rows, kept in a scratch file by strips of columns, then the columns'
/// transform strip by strip. The same operations in the same order per row and column: the whole
/// grid's distances bit for bit.
class DistanceStrips {
 public:
  /// The features' cells of rows [row0, row0 + rows), full rows, row-major: one mask per feature.
  using ReadBand = std::function<std::vector<std::vector<std::uint8_t>>(int row0, int rows)>;
  /// Bytes per cell of a band (the features, their rows' transforms, the reader's DEM) and of a
  /// strip (its column transforms and their floats).
  static constexpr double kBandBytesPerCell = 48, kStripBytesPerCell = 24;
  /// `budget_bytes` sizes the bands and strips (a band of one row and a strip of one column at
  /// least). The scratch files in `scratch_dir` are unlinked once open: 12 bytes a cell and
  /// feature at most while one feature is transformed, 4 bytes a cell and feature kept.
  DistanceStrips(const CellMetrics& metrics, int cols, int rows, int features, const std::string& scratch_dir, double budget_bytes,
                 const ReadBand& read, Progress& progress);
  ~DistanceStrips();
  DistanceStrips(const DistanceStrips&) = delete;
  DistanceStrips& operator=(const DistanceStrips&) = delete;
  /// Whether feature k has a cell anywhere in the grid.
  bool any(int k) const { return any_[std::size_t(k)]; }
  /// Feature k's distances over [col0, col0 + cols) x [row0, row0 + rows), row-major.
  std::vector<float> window(int k, int col0, int row0, int cols, int rows) const;

 private:
  void close_files();
  int cols_, rows_, strip_;
  std::vector<bool> any_;
  std::vector<std::string> paths_;
  std::vector<int> files_;
};

}  // namespace terrapolis::density
