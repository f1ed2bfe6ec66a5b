// The human population density model (MNDPH) of Belhadj 2007, §4.2: masks, four terrain
// characteristics, user layers and their weighted combination into a raster in [0,1].
// SPDX-License-Identifier: MIT
#pragma once
#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/geodesy.hpp"
#include "core/progress.hpp"
#include "core/raster.hpp"
#include "density/global_terms.hpp"

namespace terrapolis::density {

/// The terrain terms the thesis does not have (fitted by `terrapolis calibrate`), in [0,1] on land:
/// - altitude, slope: ranks among the region's land cells (share lower, ties half): scale-free;
/// - coast_near: exp(-d / 10 km), d the distance to the nearest water cell (0 with no water);
/// - river_near: exp(-d / 2 km), d the distance to the nearest river cell (0 with no rivers);
/// - position_1km, position_5km: rank of the topographic position, the altitude minus the mean
///   altitude of the land within 1 and 5 km (Weiss 2001; Guisan et al. 1999): valley floors low,
///   ridges high.
enum class TerrainTerm : std::size_t { altitude, slope, coast_near, river_near, position_1km, position_5km };
inline constexpr std::array<const char*, 6> kTerrainTerms = {"altitude", "slope", "coast_near", "river_near", "position_1km", "position_5km"};
inline constexpr std::size_t kTerrainCount = kTerrainTerms.size();
/// The terms ranked among the region's land cells (LandRanks).
inline constexpr std::array<TerrainTerm, 4> kRankedTerms = {TerrainTerm::altitude, TerrainTerm::slope, TerrainTerm::position_1km,
                                                           TerrainTerm::position_5km};

class BoostedModel;

/// Everything the density model needs besides the DEM and its hydrometry. Defaults are the
/// thesis's (Belhadj 2007, §4.2.1 and §4.2.2.2, Corsica example) unless said otherwise.
struct DensityOptions {
  // ---- water -------------------------------------------------------------------------------
  /// Cells at or below this altitude (metres) are water (SRTM seas are exactly 0 m).
  double sea_level_m = 0.0;
  /// Nodata cells are sea (SRTM/NZ coasts) rather than unknown.
  bool nodata_is_sea = false;
  /// Water the altitudes do not show (lakes, a user's mask), on the DEM's grid: non-zero cells
  /// are water; empty: none.
  Raster<std::uint8_t> water_mask;

  // ---- uninhabitable cells (density 0) -------------------------------------------------------
  /// Cells above this altitude (metres) are uninhabitable (thesis: 4000 m, after Potosí, 3967 m).
  double max_altitude_m = 4000.0;
  /// Cells steeper than this (degrees, 0..90) are uninhabitable; unset: no slope limit.
  std::optional<double> max_slope_deg;
  /// Cells whose hydrometry (0..1) is above this are river beds, uninhabitable; unset: none.
  std::optional<double> river_bed_cap;

  // ---- radii ---------------------------------------------------------------------------------
  /// Inner radius of the ring and radius of the plain disc, metres (a hamlet's radius). 500 m is
  /// the thesis's Corsica radius step dr (one 500 m cell). Raised to the largest cell step of the
  /// grid when smaller, so the plain disc always holds the 4-neighbours.
  double r_min_m = 500.0;
  /// Outer radius of the ring, metres (a large city's radius): 5 km, i.e. two million people by
  /// the thesis's x = 400 r (§4.3.1.1). Must exceed r_min.
  double r_max_m = 5000.0;
  /// Rows per disc above which a disc is approximated by this many bands of rows (see DiscPlan).
  int ring_bands = 16;

  // ---- plateau and plain ---------------------------------------------------------------------
  /// Altitudes (metres) of plateau ground: [plateau_min_m, plateau_max_m].
  double plateau_min_m = 400.0, plateau_max_m = 4000.0;
  /// Standard deviation of altitude (metres) within r_min at and above which a cell is no plain.
  double plain_max_variation_m = 50.0;

  // ---- combination ---------------------------------------------------------------------------
  /// Weights of (coast, hydrometry, plateau, plain): negative repulsive, 0 neutral, positive attractive.
  std::array<double, 4> weights{1, 1, 1.5, 0};

  /// Weights of the terrain terms (kTerrainTerms, in that order), combined with the four
  /// characteristics: 0 leaves them out (the thesis's model).
  std::array<double, kTerrainCount> terrain_weights{};
  /// Computes the terrain terms even when their weights are 0 (calibration, realism figures).
  bool terrain_terms = false;
  /// Boosted trees over the ten terms (`terrapolis calibrate --model boosted`): when set, their
  /// density stands in for the weighted sum of the terms (the weights are not read), and the
  /// user's factors combine with it as a term of weight 1.
  std::shared_ptr<const BoostedModel> model;
  /// Cells of the river network on the DEM's grid (non-zero = river), for river_near; empty: no
  /// rivers known (river_near 0).
  Raster<std::uint8_t> rivers;

  // ---- user layers and plugins, on the DEM's grid (the callers read the files) ---------------
  /// A factor with values in [0,1] and its weight, combined after the four characteristics in
  /// the order given; a NaN cell takes no part in that cell's combination (the factor has no
  /// opinion there; a cell where every weight is then 0 gets 0). A user layer is a factor read
  /// bilinearly and put through to_unit_range.
  struct Factor {
    std::string name;
    Raster<float> values;
    double weight = 1;
  };
  std::vector<Factor> factors;
  /// Exclusion masks (user rasters, plugins): non-zero cells are uninhabitable.
  std::vector<Raster<std::uint8_t>> exclusion_masks;
};

/// The checks of the settings alone, before any raster is read: throws bad_input naming the
/// setting by its scenario pointer ("/density/plateau_max_m: ..."; the density command names its
/// flags instead). `layer_weights`: the weights of the user's layers, whose rasters come later.
void check_settings(const DensityOptions& options, const std::vector<double>& layer_weights);

/// Figures for the calibration report.
struct DensityStats {
  std::size_t cells = 0;             ///< all cells of the grid
  std::size_t known_cells = 0;       ///< cells that are land with data or water
  std::size_t water_cells = 0;       ///< water cells
  std::size_t buildable_cells = 0;   ///< habitable cells
  std::array<std::size_t, 10> histogram{};  ///< buildable cells per density decile [0,0.1) .. [0.9,1]
  double mean_density = 0.0;         ///< mean density over buildable cells
  double land_area_km2 = 0.0;        ///< area of the land cells (with data, not water), km²
  double r_min_m = 0.0, r_max_m = 0.0;  ///< radii actually used (r_min may have been raised)
  int ring_bands = 0;                ///< largest number of bands per disc (rows when exact)
  bool ring_exact = true;            ///< every disc was summed row by row
  double density_sum = 0.0;          ///< sum of the density over buildable cells
  /// Coast and plateau shares before their division by these maxima over habitable land.
  float coast_max = 0.0f, plateau_max = 0.0f;
};

/// The model's rasters, all on the DEM's grid and CRS. Float rasters are in [0,1], NaN where the
/// DEM has no data and the cell is not water; characteristics are 0 on water.
struct DensityResult {
  Raster<float> coast;       ///< share of water in the ring [r_min, r_max], divided by its maximum over land
  Raster<float> plateau;     ///< share of rough plateau ground in the ring, divided by its maximum over land
  Raster<float> plain;       ///< 1 - std(altitude within r_min) / plain_max_variation, clamped to [0,1]
  Raster<float> hydrometry;  ///< the hydrometry used (input), 0 on water
  Raster<float> density;     ///< the weighted combination, 0 where uninhabitable
  Raster<std::uint8_t> buildable;  ///< 1 habitable, 0 uninhabitable (water, too high, too steep...), 255 nodata
  /// Terrain terms in kTerrainTerms order, computed when a terrain weight is not 0 or
  /// options.terrain_terms (empty rasters otherwise); in [0,1] on land, NaN off land.
  std::array<Raster<float>, kTerrainCount> terrain;
  const Raster<float>& term(TerrainTerm t) const { return terrain[std::size_t(t)]; }
  DensityStats stats;
};

/// Maps sum_i P_i D_i (D_i in [0,1]) onto [0,1] by its exact bounds: with N = sum of negative
/// weights and |P| = sum |P_i|, D = (sum_i P_i D_i - N) / |P|. Equals the thesis's sum P_i D_i /
/// sum P_i when no weight is negative, and stays meaningful when sum P_i <= 0 (the thesis's
/// (0, 1, -1.5, 0.3) sums to -0.2): a repulsive characteristic counts as the attractiveness of its
/// absence, |P_i| (1 - D_i). Throws bad_input when every weight is 0.
double combine(const double* weights, const double* values, std::size_t n);

/// Computes the density model (Belhadj 2007, §4.2.1 and Fig. 4.2-4.3).
/// `hydrometry` is on the DEM's grid, values in [0,1] (NaN read as 0). Deterministic whatever the
/// thread count. Throws bad_input for inconsistent options or a raster not on the DEM's grid.
DensityResult compute_density(const Dem& dem, const Raster<float>& hydrometry, const DensityOptions& options,
                              Progress& progress);

/// The least and greatest values of a layer over a grid, NaN (no data) left out; added window by
/// window, a grid read by tiles gets the whole grid's range.
struct ValueRange {
  float lo = std::numeric_limits<float>::infinity(), hi = -std::numeric_limits<float>::infinity();
  void add(const Raster<float>& values);
};

/// A user layer as the model reads it: used as is when the grid's values already lie in [0,1],
/// otherwise rescaled linearly from the grid's [min, max] (`range`: the whole grid's when `layer`
/// is a window of it); NaN (no data) reads as 0.
void to_unit_range(Raster<float>& layer, const ValueRange& range);
/// The same, `layer` being the whole grid.
void to_unit_range(Raster<float>& layer);


/// Whether the terrain terms are computed: a terrain weight not 0, options.terrain_terms, or boosted trees.
bool needs_terrain_terms(const DensityOptions& options);

/// The features of the terrain terms' distances, 1 on a feature cell: the water (at or below the
/// sea level, nodata when it is sea, the water mask) and the rivers (non-zero, not nodata).
std::vector<std::uint8_t> water_cells(const Dem& dem, const DensityOptions& options);
/// 1 on the land: data, not water (the cells the terrain terms and the realism figures read).
std::vector<std::uint8_t> land_cells(const Dem& dem, const DensityOptions& options);
std::vector<std::uint8_t> river_mask(const Raster<std::uint8_t>& rivers);

}  // namespace terrapolis::density
