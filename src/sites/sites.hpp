// City sites: size quotas, placement on a density model and the inclusion hierarchy (Belhadj §4.3.1).
// SPDX-License-Identifier: MIT
#pragma once
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "core/geodesy.hpp"
#include "core/progress.hpp"
#include "core/raster.hpp"
#include "sites/land.hpp"

namespace terrapolis::sites {

/// One agglomeration site: a disc on the DEM grid (Belhadj 2007, §4.3.1: "a couple of coordinates
/// associated with a radius").
struct Site {
  int id = 0;                    ///< index of the site in its list (sorted by radius, decreasing)
  double x = 0, y = 0;           ///< centre in the DEM's CRS (centre of cell col,row)
  int col = 0, row = 0;          ///< the cell holding the centre
  double radius_m = 0;           ///< disc radius, metres (geodesic)
  int radius_class = 0;          ///< 0 = the largest radius class
  std::int64_t population = 0;   ///< rank_size: the settlement's share of the rank-size law; belhadj2007: people_per_m x radius_m (eq. 4.2)
  double density = 0;            ///< density model value at the centre, in [0,1]
  int parent = -1;               ///< index of the parent site, -1 for a root (Algorithm 15)
  int depth = 0;                 ///< 0 for roots, parent's depth + 1 otherwise
  bool existing = false;         ///< a real place given by SitesOptions::existing (its position and population kept)
  std::string name;              ///< an existing place's name
  /// Growth scenario (SitesOptions::growth): people the settlement gained (an existing place's
  /// share of the growth, or all the people of a new one); its population includes them.
  std::int64_t gained = 0;
};

struct SitesOptions {
  /// Where the size classes and their quotas come from. rank_size: a region's population split
  /// by a rank-size (Zipf) law down to min_population, radii from an urban-area allometry;
  /// belhadj2007: the thesis's census table for metropolitan France (Algorithm 13, eq. 4.1-4.2).
  enum class Quotas { rank_size, belhadj2007 } quotas = Quotas::rank_size;
  // ---- rank_size -------------------------------------------------------------------------------
  /// People in the region (a census figure); 0: people_per_km2 x land_area_km2.
  double population = 0;
  /// Default density of people when `population` is 0: 60 per km² of land, the world's average
  /// (World Bank, World Development Indicators EN.POP.DNST, 2020).
  double people_per_km2 = 60;
  /// Share of the region's people living in the settlements (of min_population or more); the
  /// rest lives in hamlets and scattered houses. 0.55: the urban share of the world's population
  /// (UN DESA, World Urbanization Prospects 2018); the EU's cities, towns and suburbs hold 0.75
  /// (Eurostat, degree of urbanisation, 2021). 1: every person in a settlement.
  double urban_share = 0.55;
  /// How the settled people are split. rank_size: P_k = P_1 k^-zipf_exponent down to
  /// min_population. catchment: the exponent is read from the land: a first placement by the
  /// rank_size law (all the region's people, zipf_exponent) gives the central places, the
  /// people spread over the land by the density model go to the nearest centre (catchments),
  /// and q is the rank-size exponent of the catchments of min_population or more; the settled
  /// people are then split over as many settlements by P_k = P_1 k^-q, and placed again.
  enum class Sizes { rank_size, catchment } sizes = Sizes::catchment;
  /// Land area of the region, km²; 0: the area of the buildable cells.
  double land_area_km2 = 0;
  /// q of the rank-size law P_k = P_1 k^-q (Zipf's law: q = 1, Gabaix 1999; Soo 2005 measures
  /// Pareto exponents 1/q around 1.1 over 73 countries).
  double zipf_exponent = 1;
  /// The smallest settlement, people: the law stops at the last rank still this large.
  double min_population = 1000;
  /// Central places of min_population people lie at least this far apart, km, on a hexagonal
  /// lattice (Christaller 1933: the Marktorte, the smallest central places, of about 1,000 people,
  /// 7 km apart): the land holds at most land / (sqrt(3)/2 spacing^2 x min_population / 1000) of
  /// them, and a population the law would split into more is split over that many (the smallest
  /// then above min_population). 0: no limit, the count follows the law alone.
  double spacing_km = 7;
  /// rank_size: central places by rank (Christaller 1933): the settlement of rank k keeps this
  /// share of sqrt(land area / k), the spacing of the k largest places spread evenly, from every
  /// centre at least as large (existing places included). Real places lie more evenly than random
  /// points (Clark and Evans 1954: R of 0.8-1.35 on the shared regions, the nearest place at a
  /// median 0.35-0.65 of sqrt(land / places); 0.5 wins the placement backtest). 0: the discs
  /// alone keep them apart (Belhadj 2007).
  double min_distance_share = 0.5;
  /// b of the urban-area allometry A = A_0 (P / 1000)^b: built-up area grows slower than
  /// population (Bettencourt 2013, Science 340: b between 2/3 and 5/6).
  double area_exponent = 5.0 / 6.0;
  /// People per km² of built-up area of a settlement of 1,000 people (A_0 = 1000 / this):
  /// 1,500, the cell density of the EU-OECD degree of urbanisation's urban centres
  /// (Dijkstra & Poelman 2014).
  double town_density_per_km2 = 1500;
  /// Suburbs (Belhadj §4.3.1: "la banlieue et son centre"): a settlement's influence area holds
  /// influence_factor x its people at the region's mean density (target population / land area),
  /// so a town's reach grows as the square root of its size and shrinks where land is crowded;
  /// a settlement at most half as large whose centre lies in it becomes its suburb. 1: the area
  /// whose people equal the town's own (the central place's complementary region, Christaller
  /// 1933, at its simplest); 0: no suburbs beyond partial inclusions. Mode manhattan: none.
  double influence_factor = 1;
  /// The settlements that exist (sites.existing: col, row, x, y, population, name set): each is
  /// kept where it is with its people, counts towards the settled people, and the model places
  /// settlements only for the rest, outside the existing discs; all are then classed and put in
  /// the hierarchy together by their sizes. rank_size quotas only.
  std::vector<Site> existing;
  /// Growth scenario over the existing settlements: the region's people grow by this share (0.2:
  /// +20 %), the settled people E of the existing places by as many, E x growth. Of those new
  /// people, growth_new_share go to new settlements placed by the model (split by the rank-size
  /// law, outside the grown discs of the existing places) and the rest to the existing places in
  /// proportion to their size: Gibrat's law of proportionate growth (Gibrat 1931; Eeckhout 2004
  /// finds it holds for every US place, large or small, 1990-2000). New people the model cannot
  /// place (fewer than min_population, or no room) go to the existing places too. With growth
  /// above 0 the existing places are the region's whole settled population today: the model fills
  /// nothing else. 0: no growth scenario (the model places the rest of the settled share).
  double growth = 0;
  double growth_new_share = 0;
  // ---- belhadj2007 -----------------------------------------------------------------------------
  std::uint64_t seed = 1;   ///< seed of the candidate draw (std::mt19937_64)
  int candidates = 0;       ///< M, candidate positions drawn; 0: automatic (20 x N_sites, at most every buildable cell)
  double r_min_m = 0;       ///< smallest radius, metres; 0: the class step dr
  double r_max_m = 0;       ///< radii run r_min .. r_max - dr, metres; 0: x_max / people_per_m + dr
  double dr_min_m = 50;     ///< smallest class step, metres: dr = max(dr_min, floor(cell size))
  double u_min = 4;         ///< units in the largest class (over x_max people), eq. 4.1
  double u_max = 1072;      ///< units in the smallest class, eq. 4.1
  double x_max = 1e6;       ///< people at which f reaches u_min, eq. 4.1
  double p = 4;             ///< decay exponent of f (> 1), eq. 4.1
  double people_per_m = 400;  ///< g(r) = people_per_m x r, eq. 4.2
  /// Multiplies every quota: Q[i] = floor(quota_scale x f(g(r_i))). The census fit describes
  /// metropolitan France (543 940 km², INSEE 1999); a region of A km² is A / 543940 of it.
  /// 1 is the thesis (the whole fit on any DEM).
  double quota_scale = 1;
  /// Inclusion removal (Belhadj §4.3.1.2): paris keeps partially included sites at most half the
  /// size of their container as suburbs (radio-concentric cities); manhattan removes every
  /// site whose centre lies in a larger one (regular tiling).
  enum class Mode { paris, manhattan } mode = Mode::paris;
  /// How a growing disc is tested against uninhabitable cells. exact: the whole disc, from a
  /// distance transform in metres; perimeter: only the discrete circle of each radius, as the
  /// thesis's intersecte_seuil does (obstacles between two radii slip inside, its Fig. 4.5).
  enum class DiscTest { exact, perimeter } disc_test = DiscTest::exact;
  /// Refill rounds after the inclusion removal: the quota of removed sites goes back to the
  /// growth, which resumes on the candidates not reached yet whose centre is in no kept disc,
  /// then inclusions are removed again. 0 is Algorithm 14 as printed (the imbalance stays).
  int refill_rounds = 8;
};

/// The checks of the settings alone, before any grid is read (cross-field rules included): throws
/// bad_input naming the setting by its scenario pointer ("/sites/u_max: ..."; the sites command
/// names its flags instead). place_sites and compute_quotas start with it.
void check_settings(const SitesOptions& options);

/// One radius class of the quota table (Algorithm 13).
struct QuotaClass {
  double radius_m = 0;  ///< class radius, metres
  int quota = 0;        ///< Q[i] = floor(f(g(radius))), or the settlements of the rank-size law in this class
  int placed = 0;       ///< sites given this class by the growth, all rounds (first round: never above quota)
  int kept = 0;         ///< sites of this class in the result (never above quota)
};

/// The quota table: classes ordered from the largest radius (class 0) to the smallest.
struct QuotaTable {
  double dr_m = 0;      ///< class step, metres
  double r_min_m = 0, r_max_m = 0;
  std::vector<QuotaClass> classes;
  /// rank_size: the populations of each class, largest first (empty for belhadj2007).
  std::vector<std::vector<std::int64_t>> populations;
  int total() const;    ///< N_sites, the sum of quotas
};

struct SitesResult {
  std::vector<Site> sites;          ///< sorted by radius, decreasing; id = index
  std::vector<QuotaClass> quotas;   ///< class 0 (largest radius) first
  double dr_m = 0;                  ///< class step used, metres
  int candidates = 0;               ///< M, candidates drawn
  std::uint64_t seed = 1;           ///< seed used
  double target_population = 0;     ///< rank_size: the region's people (at least the existing places')
  double settled_population = 0;    ///< rank_size: urban_share x target_population (at least the existing places' people), split over the settlements
  double sizes_exponent = 0;        ///< rank_size: q of the law that split them (zipf_exponent, or read from the catchments)
  double land_area_km2 = 0;         ///< rank_size: the land area used for the default population
  bool population_assumed = false;  ///< rank_size: target from people_per_km2 (no census figure given)
  std::int64_t room = 0;            ///< rank_size: settlements the land holds at spacing_km (settleable_count); 0: no limit
  bool count_limited = false;       ///< rank_size: the law would have made more settlements than `room`
  double existing_population = 0;   ///< people of the existing settlements (SitesOptions::existing), before any growth
  /// Growth scenario: the new people (existing_population x growth), those that went to the
  /// existing places and those in new settlements (growth_to_existing + growth_to_new = growth_people).
  std::int64_t growth_people = 0, growth_to_existing = 0, growth_to_new = 0;
  /// rank_size: settlements placed without a disc clear of unbuildable land (no candidate had one;
  /// their discs reach over water or steep land), and those of the law with no place at all and
  /// their people (the settled people are the placed ones plus these).
  std::int64_t crowded = 0, unplaced = 0, unplaced_people = 0;
};

/// f(x) of Belhadj eq. 4.1: urban units of x people. For x >= x_max the base is clamped at 0
/// (the thesis's formula grows again past x_max, and is undefined for non-integer p).
double units_for_people(double people, const SitesOptions& options);

/// The class step dr = max(dr_min, floor(cell_size_m)) (Algorithm 13).
double class_step_m(double cell_size_m, const SitesOptions& options);

/// Algorithm 13: quotas for classes r_min + i dr, i in 0..n-1, n = floor((r_max - r_min) / dr),
/// for a grid whose cells are `cell_size_m` metres. Throws bad_input when the range is empty
/// or a parameter is out of range.
QuotaTable compute_quotas(double cell_size_m, const SitesOptions& options);

/// The rank-size law fitted to `total` people: P_k = total k^-q / H_N(q), H_N(q) = sum_{k<=N} k^-q,
/// with N the largest count whose smallest settlement P_N still reaches min_population (none when
/// total < min_population), and at most `max_count`. Rounded to whole people by largest
/// remainders: the sizes add up to round(total) exactly. Largest first.
/// `first_rank` > 1: the law's tail, ranks first_rank .. first_rank + N - 1 (the places below
/// first_rank - 1 existing ones), P_k = total k^-q / sum_{first_rank <= j < first_rank + N} j^-q.
std::vector<std::int64_t> rank_size_populations(double total, double zipf_exponent, double min_population,
                                                std::size_t max_count = std::numeric_limits<std::size_t>::max(),
                                                std::size_t first_rank = 1);

/// `total` people split in proportion to `weights` (>= 0, not all 0), by largest remainders (ties:
/// the earlier index): the shares add up to `total` exactly.
std::vector<std::int64_t> proportional_split(std::int64_t total, const std::vector<std::int64_t>& weights);

/// `total` people split over `count` ranks from `first_rank` on by P_k proportional to k^-q (q >= 0),
/// rounded to whole people by largest remainders (they add up to round(total)). Largest first.
std::vector<std::int64_t> rank_size_split(double total, double q, std::size_t count, std::size_t first_rank = 1);

/// People of each site's catchment: `total` people spread over the habitable cells (buildable 1,
/// density finite) in proportion to density x cell area, each cell's people going to the site
/// whose centre is nearest (ties: the lower index). The result adds up to `total` (up to
/// rounding) when a site and a habitable cell exist.
std::vector<double> catchment_people(const Land& land, const std::vector<Site>& sites, double total);

/// `total` people spread over the habitable cells as catchment_people spreads them (in proportion
/// to density x cell area), per cell; 0 elsewhere.
Raster<float> people_on_land(const Raster<float>& density, const Raster<std::uint8_t>& buildable, double total);

/// people_on_land over a grid read by bands of whole rows: add() every band, in order (the density's
/// mass over the land, summed in the whole grid's order), then people() of any band gives the
/// whole grid's values. `buildable` is the mask as written (1 habitable) or read back as floats.
class PeopleOnLand {
 public:
  PeopleOnLand(const Georef& grid, int cols, int rows, double total);
  template <class B>
  void add(const Raster<float>& density, const Raster<B>& buildable, int row0) {
    for (int r = 0; r < density.rows(); ++r)
      for (int c = 0; c < density.cols(); ++c)
        if (habitable(density, buildable, density.index(c, r))) mass_ += double(density(c, r)) * area_m2_[std::size_t(row0 + r)];
  }
  /// The grid's cell area per row (m²).
  const std::vector<double>& area_m2() const { return area_m2_; }
  template <class B>
  Raster<float> people(const Raster<float>& density, const Raster<B>& buildable, int row0) const {
    Raster<float> out = density.template like<float>(0.0f);
    if (mass_ > 0)
      for (int r = 0; r < density.rows(); ++r)
        for (int c = 0; c < density.cols(); ++c)
          if (habitable(density, buildable, density.index(c, r)))
            out(c, r) = float(total_ * double(density(c, r)) * area_m2_[std::size_t(row0 + r)] / mass_);
    return out;
  }

 private:
  template <class B>
  static bool habitable(const Raster<float>& density, const Raster<B>& buildable, std::size_t i) {
    return buildable[i] == B(1) && !buildable.is_nodata(i) && std::isfinite(density[i]);
  }
  std::vector<double> area_m2_;  ///< the grid's cell area per row
  double total_ = 0, mass_ = 0;
};

/// People per km² above which a whole region counts as urban: the cell density of an urban
/// centre in the EU-OECD degree of urbanisation (1,500; Dijkstra & Poelman 2014).
constexpr double kUrbanCentrePeoplePerKm2 = 1500;

/// The most settlements of min_population people `land_area_km2` holds at options.spacing_km
/// apart on a hexagonal lattice (at least 1; unlimited when spacing_km is 0). Christaller's
/// lattice is that of a rural land with its towns; where `people` on that land are denser than an
/// urban centre (kUrbanCentrePeoplePerKm2), the hexagons shrink in proportion (a metropolis holds
/// hundreds of places of 1,000 or more, not the few of a 7 km lattice).
std::size_t settleable_count(double land_area_km2, const SitesOptions& options, double people = 0);

/// q of the rank-size law fitted to `sizes` by least squares on ln P_k = c - q ln(k - 1/2)
/// (the rank shifted by 1/2 against the small-sample bias, Gabaix & Ibragimov 2011); NaN for
/// fewer than 3 sizes.
double rank_size_exponent(std::vector<double> sizes);

/// Radius, metres, of the disc whose area is the built-up area of `people`: A = (1000 /
/// town_density) (people / 1000)^area_exponent km².
double urban_radius_m(double people, const SitesOptions& options);

/// The size classes of `populations` (largest first): class radii r_min + i dr with r_min = dr,
/// each settlement in the smallest class whose radius covers urban_radius_m of its population.
QuotaTable rank_size_quotas(double cell_size_m, const std::vector<std::int64_t>& populations, const SitesOptions& options);

/// Algorithms 13, 14 and 15: places sites on `density` (values in [0,1], NaN nodata) where
/// `buildable` is 1; any other cell, and everything outside the grid, is uninhabitable.
/// Candidates are drawn with options.seed; the result depends only on the inputs and options.
SitesResult place_sites(const Raster<float>& density, const Raster<std::uint8_t>& buildable, const SitesOptions& options,
                        Progress& progress);
/// place_sites on a Land: the land in memory or read from a mosaic's tiles, with the same result.
SitesResult place_sites(const Land& land, const SitesOptions& options, Progress& progress);

/// Distance in metres between the centres of two cells of a grid, by the mid-latitude formula
/// with the exact meridian arc (geodesic to well under a millimetre within a few kilometres);
/// Euclidean on projected grids.
class GridDistance {
 public:
  GridDistance(const Georef& georef, int cols, int rows);
  /// Metres from the centre of (c0,r0) to the centre of (c1,r1); rows may lie one outside the grid.
  double operator()(int c0, int r0, int c1, int r1) const;
  /// Northing of the centre of row r (r in -1..rows), metres from row 0.
  double northing(int r) const { return y_[std::size_t(r + 1)]; }
  /// East-west metres per column at the mid-latitude of rows r0 and r1.
  double width_between(int r0, int r1) const;
  const CellMetrics& metrics() const { return metrics_; }

 private:
  CellMetrics metrics_;
  std::vector<double> y_;  // northing of rows -1..rows
  int rows_;
};

/// Algorithms 14 (second part) and 15: with `sites` sorted by radius, decreasing, removes the
/// included sites according to `mode` and links each kept partially included site to its
/// parent (the first, hence largest, kept site containing its centre). Sites lie on a
/// `cols` x `rows` grid; distances between centres come from `distance`. Returns the kept
/// sites in the same order with ids, parents and depths renumbered.
std::vector<Site> resolve_inclusions(const std::vector<Site>& sites, SitesOptions::Mode mode, const GridDistance& distance,
                                     int cols, int rows);

/// Makes each root a suburb of the settlement that attracts it most (population over squared
/// distance, Reilly 1931) among those at least twice as populous whose influence radius
/// (`influence_m`, per site) reaches its centre; then renumbers depths. `sites` are ordered by
/// size, decreasing (a parent always comes first), as place_sites leaves them.
void attach_suburbs(std::vector<Site>& sites, const std::vector<double>& influence_m, const GridDistance& distance);

/// Radius, metres, of the disc of land holding `factor` x `people` at `people_per_km2`.
double influence_radius_m(double people, double factor, double people_per_km2);

}  // namespace terrapolis::sites
