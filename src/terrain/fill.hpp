// Filling DEM voids and rebuilding DEMs from sparse heights, by DMMC or multigrid splines.
// SPDX-License-Identifier: MIT
#pragma once
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "core/progress.hpp"
#include "core/raster.hpp"
#include "terrain/spline.hpp"
#include "terrain/subdivision.hpp"

namespace terrapolis::terrain {

/// How unknown cells are computed.
enum class FillMethod {
  dmmc,        ///< Belhadj 2007 Alg. 11 (bottom-up-down midpoint displacement), §5.2.1 low-pass
  harmonic,    ///< multigrid Laplace interpolation
  thin_plate,  ///< multigrid thin-plate spline with tension (our default: lowest error, see docs/terrain.md)
};

/// Parses "dmmc", "harmonic", "thin-plate"; throws bad_input naming `option` otherwise.
FillMethod parse_fill_method(const std::string& option, const std::string& text);
const char* to_string(FillMethod method);

struct FillParams {
  FillMethod method = FillMethod::thin_plate;
  DmmcParams dmmc;      ///< used by FillMethod::dmmc
  SplineParams spline;  ///< used by harmonic / thin_plate (smoothness is set from the method)
};

/// Computes every NaN cell of `raster` from its finite cells, which are kept exactly.
void reconstruct(Raster<float>& raster, const FillParams& params, Progress* progress = nullptr);

/// Which nodata cells are voids to fill.
struct VoidOptions {
  std::optional<double> sea_level_m;  ///< cells at or below this height connected to the border are sea
  bool fill_border = false;           ///< also fill nodata connected to the grid border (else it is outside)
  std::optional<double> max_area_km2; ///< voids larger than this stay nodata
};

struct VoidReport {
  std::size_t voids = 0, voids_filled = 0, cells_filled = 0, too_large = 0;
  double largest_km2 = 0;
};

/// Marks (1) the nodata cells of `dem` that are voids to fill: nodata not connected (8-neighbours)
/// to the border through nodata or sea cells, unless `fill_border`; components larger than
/// max_area_km2 (geodesic cell areas) are left out.
std::vector<std::uint8_t> find_voids(const Dem& dem, const VoidOptions& options, VoidReport* report = nullptr);

/// Fills the cells marked in `voids`, one window per void (its bounding box plus a margin of known
/// cells), windows in parallel; the result does not depend on the thread count.
void fill_voids(Dem& dem, const std::vector<std::uint8_t>& voids, const FillParams& params, Progress* progress = nullptr);

}  // namespace terrapolis::terrain
