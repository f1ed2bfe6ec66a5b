// The land of a placement held in memory (sites::LandRasters).
// SPDX-License-Identifier: MIT
#include "sites/land.hpp"

#include <algorithm>

#include "core/error.hpp"

namespace terrapolis::sites {

std::uint64_t Land::habitable_cells() const {
  if (!habitable_) {
    std::uint64_t n = 0;
    for_each_band([&](const LandView& v) {
      for (int r = v.row0; r < v.row0 + v.rows; ++r)
        for (int c = v.col0; c < v.col0 + v.cols; ++c) n += v.habitable(c, r);
    });
    habitable_ = n;
  }
  return *habitable_;
}

LandRasters::LandRasters(const Raster<float>& density, const Raster<std::uint8_t>& buildable, int block_side, int band_rows)
    : Land(density.georef(), density.cols(), density.rows()), density_(density), buildable_(buildable), block_side_(block_side),
      band_rows_(band_rows > 0 ? band_rows : std::max(1, density.rows())) {
  if (buildable.cols() != density.cols() || buildable.rows() != density.rows())
    throw bad_input("sites: the buildable mask and the density model are not on the same grid");
  // A view's buildable cells are those of value 1: nodata must not be 1.
  if (buildable.nodata && *buildable.nodata == 1) throw bad_input("sites: the buildable mask's nodata value is 1, the buildable value");
}

LandView LandRasters::window(int col0, int row0, int cols, int rows) const {
  LandView v;
  v.col0 = col0, v.row0 = row0, v.cols = cols, v.rows = rows;
  v.stride = std::size_t(density_.cols());
  const std::size_t first = density_.index(col0, row0);
  v.density = density_.data() + first;
  v.buildable = buildable_.data() + first;
  return v;
}

void Land::for_each_band(const std::function<void(const LandView&)>& f) const {
  const int band = std::max(1, band_rows());
  for (int r = 0; r < rows(); r += band) f(window(0, r, cols(), std::min(band, rows() - r)));
}

}  // namespace terrapolis::sites
