// Does a generated terrain hold the rivers it was built from, and do they look like real ones?
// SPDX-License-Identifier: MIT
#pragma once
#include <cstdint>
#include <optional>
#include <vector>

#include "core/raster.hpp"
#include "io/vector_io.hpp"
#include "generate/river_ridge_plan.hpp"

namespace terrapolis::generate {

/// Horton's laws (Horton 1945; Strahler 1957) on a Strahler-ordered network. A stream of order w
/// is a maximal chain of reaches of order w. Rb and Rl are the antilogs of the least-squares
/// slopes of log N_w and log mean L_w over w (Strahler 1957, fig. 2), the usual way to fold
/// all orders into one figure. Real basins: Rb 3-5, Rl 1.5-3.5.
struct HortonRatios {
  std::vector<int> streams;           ///< N_w, index w-1
  std::vector<double> mean_length_m;  ///< mean L_w, index w-1
  std::optional<double> bifurcation;  ///< Rb; none with fewer than 2 orders
  std::optional<double> length;       ///< Rl; none with fewer than 2 orders
};
HortonRatios horton_ratios(const RiverRidgePlan& plan, double cell_m);

/// The generated rivers against the D8 streams `terrapolis hydro` extracts from the generated DEM.
struct D8Consistency {
  double river_length_m = 0;    ///< generated river length sampled
  double matched_length_m = 0;  ///< of it, within `radius_cells` of a D8 stream of order w-1..w+1
  int mouths = 0;               ///< reaches ending at an outlet (downstream -1)
  int ending_in_pit = 0;        ///< of them, ending away from the border, nodata and the sea
  double share() const { return river_length_m > 0 ? matched_length_m / river_length_m : 0.0; }
};

/// `stream_order`: Strahler order of the D8 stream through each cell, 0 off-stream (see
/// stream_order_raster). `dem`: the generated DEM (NaN nodata); cells at or below `sea_level_m`
/// are sea. A mouth must end within one cell of the border, a nodata or a sea cell.
D8Consistency d8_consistency(const RiverRidgePlan& plan, const Raster<std::uint8_t>& stream_order, const Raster<float>& dem,
                             double cell_m, double radius_cells = 2.0, std::optional<double> sea_level_m = std::nullopt);

/// Rasterises a D8 streams layer (hydro/streams.hpp: vertices at cell centres, field `strahler`)
/// onto `grid`: the highest order through each cell, 0 elsewhere.
Raster<std::uint8_t> stream_order_raster(const VectorLayer& streams, const Georef& georef, int cols, int rows);

/// The D8 stream threshold (m²) that starts D8 streams where the generator starts its rivers: the
/// median D8 upstream area at the first point of the source reaches (those nothing flows into).
/// 1 m² when there is no source.
double channel_head_threshold_m2(const RiverRidgePlan& plan, const Raster<double>& area_m2);

/// Total river length (km) per land area (km²): cells that are finite and above `sea_level_m`.
double drainage_density(const RiverRidgePlan& plan, const Raster<float>& dem, double cell_m,
                        std::optional<double> sea_level_m = std::nullopt);

}  // namespace terrapolis::generate
