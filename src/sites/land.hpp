// The density model and the buildable mask a placement reads: by bands of rows and by windows, so
// that a region larger than memory is placed from its tiles with the whole grid's result.
// SPDX-License-Identifier: MIT
#pragma once
#include <cstddef>
#include <cmath>
#include <cstdint>
#include <functional>
#include <optional>
#include <vector>

#include "core/raster.hpp"

namespace terrapolis::sites {

/// Cells [col0, col0 + cols) x [row0, row0 + rows) of the density model and the buildable mask,
/// row after row `stride` values apart. buildable is 1 on buildable land (never on nodata).
struct LandView {
  LandView() = default;
  LandView(LandView&&) = default;  // a move keeps the pointers into own_density and own_buildable valid
  LandView& operator=(LandView&&) = default;
  LandView(const LandView&) = delete;
  LandView& operator=(const LandView&) = delete;
  int col0 = 0, row0 = 0, cols = 0, rows = 0;
  std::size_t stride = 0;
  const float* density = nullptr;
  const std::uint8_t* buildable = nullptr;
  std::size_t at(int col, int row) const { return std::size_t(row - row0) * stride + std::size_t(col - col0); }
  /// A site may stand here: buildable with a density value.
  bool habitable(int col, int row) const {
    const std::size_t i = at(col, row);
    return buildable[i] == 1 && std::isfinite(density[i]);
  }
  // The cells when the view holds its own copy (a window read from disk).
  std::vector<float> own_density;
  std::vector<std::uint8_t> own_buildable;
};

/// Where the placement reads the land. The result of place_sites depends only on the cells, never
/// on how they are read (bands, windows and their sizes).
class Land {
 public:
  Land(Georef georef, int cols, int rows) : georef_(std::move(georef)), cols_(cols), rows_(rows) {}
  virtual ~Land() = default;
  const Georef& georef() const { return georef_; }
  int cols() const { return cols_; }
  int rows() const { return rows_; }
  /// The whole grid once, in row order, by bands of band_rows() whole rows (`f` is called once a band).
  void for_each_band(const std::function<void(const LandView&)>& f) const;
  virtual int band_rows() const = 0;
  /// A window inside the grid.
  virtual LandView window(int col0, int row0, int cols, int rows) const = 0;
  /// The habitable cells (LandView::habitable), counted on the first call: one pass less for every
  /// later placement on the same land (the catchment sizes place twice).
  std::uint64_t habitable_cells() const;
  /// The side, in cells, of the blocks the disc tests read at once, each grown by `margin_cols` and
  /// `margin_rows` cells (the largest disc) on every side; 0: the whole grid at once.
  virtual int block_side(int margin_cols, int margin_rows) const = 0;

 private:
  Georef georef_;
  int cols_, rows_;
  mutable std::optional<std::uint64_t> habitable_;
};

/// The land in memory: views into the two rasters, read without a copy. `block_side` and
/// `band_rows` 0: the whole grid at once; smaller ones read it as a mosaic's tiles would be.
class LandRasters : public Land {
 public:
  /// Throws bad_input when the two rasters are not on one grid.
  LandRasters(const Raster<float>& density, const Raster<std::uint8_t>& buildable, int block_side = 0, int band_rows = 0);
  LandView window(int col0, int row0, int cols, int rows) const override;
  int block_side(int, int) const override { return block_side_; }
  int band_rows() const override { return band_rows_; }

 private:
  const Raster<float>& density_;
  const Raster<std::uint8_t>& buildable_;
  int block_side_, band_rows_;
};

}  // namespace terrapolis::sites
