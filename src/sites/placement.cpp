// Placement of the sites: seeded candidates, disc growth under quotas (Belhadj 2007, §4.3.1.2, Algorithm 14).
// SPDX-License-Identifier: MIT
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <random>
#include <string>
#include <unordered_map>

#include "core/error.hpp"
#include "sites/sites.hpp"

namespace terrapolis::sites {
namespace {

/// Uniform integer in [0, n) from a 64-bit generator, by rejection: unlike
/// std::uniform_int_distribution its output is the same with every standard library.
std::uint64_t bounded(std::mt19937_64& generator, std::uint64_t n) {
  const std::uint64_t threshold = (0 - n) % n;  // 2^64 mod n
  std::uint64_t x;
  do x = generator();
  while (x < threshold);
  return x % n;
}

constexpr std::uint16_t kFar = std::numeric_limits<std::uint16_t>::max();

/// The disc tests of Algorithm 14 (intersecte_seuil), for discs centred on cell centres.
/// A disc of radius r touches a cell when the cell's centre is within r metres of its centre.
class DiscTester {
 public:
  DiscTester(const std::vector<std::uint8_t>& habitable, int cols, int rows, const GridDistance& distance)
      : habitable_(habitable), cols_(cols), rows_(rows), distance_(distance) {}

  /// Row pass of a separable distance transform: for every cell, the number of columns to
  /// the nearest uninhabitable cell of its row (the columns just outside the grid count as
  /// uninhabitable), capped at 65535. The column pass is evaluated exactly, per candidate,
  /// in clear_distance_m.
  void build_row_pass() {
    row_gap_.assign(habitable_.size(), kFar);
    tbb::parallel_for(tbb::blocked_range<int>(0, rows_), [&](const tbb::blocked_range<int>& range) {
      for (int r = range.begin(); r < range.end(); ++r) {
        const std::size_t base = std::size_t(r) * std::size_t(cols_);
        long last = -1;  // the virtual column west of the grid
        for (int c = 0; c < cols_; ++c) {
          if (!habitable_[base + std::size_t(c)]) last = c;
          row_gap_[base + std::size_t(c)] = std::uint16_t(std::min<long>(c - last, kFar));
        }
        last = cols_;  // the virtual column east of the grid
        for (int c = cols_ - 1; c >= 0; --c) {
          if (!habitable_[base + std::size_t(c)]) last = c;
          auto& g = row_gap_[base + std::size_t(c)];
          g = std::uint16_t(std::min<long>({long(g), last - c, long(kFar)}));
        }
      }
    });
  }

  /// Metres from the centre of (c0,r0) to the nearest uninhabitable cell centre (rows and
  /// columns just outside the grid included), or `cap` if none is nearer. Rows are visited
  /// outwards and the search stops once the north-south distance alone reaches the best found.
  double clear_distance_m(int c0, int r0, double cap) const {
    double best = cap;
    const double y0 = distance_.northing(r0);
    for (int dir : {1, -1}) {
      for (int d = (dir == 1 ? 0 : 1);; ++d) {
        const int r = r0 + dir * d;
        const double dy = std::abs(distance_.northing(r) - y0);
        if (dy >= best) break;
        if (r < 0 || r >= rows_) {  // a whole virtual row of uninhabitable cells
          best = dy;
          break;
        }
        const double gap = row_gap_[std::size_t(r) * std::size_t(cols_) + std::size_t(c0)];
        const double dx = gap * distance_.width_between(r0, r);
        best = std::min(best, std::sqrt(dx * dx + dy * dy));
      }
    }
    return best;
  }

  /// True when the discrete circle of radius `radius_m` around (c0,r0) crosses an
  /// uninhabitable cell or leaves the grid: the thesis's intersecte_seuil, sampled at least
  /// every half cell along the circle so that the discrete circle has no gaps.
  bool circle_hits(int c0, int r0, double radius_m) const {
    const CellMetrics& m = distance_.metrics();
    const double h = m.height_m[std::size_t(r0)];
    const double step = 0.5 * std::min(m.width_m[std::size_t(r0)], h);
    const int samples = std::max(16, int(std::ceil(2 * M_PI * radius_m / step)));
    for (int k = 0; k < samples; ++k) {
      const double theta = 2 * M_PI * k / samples;
      const double north = radius_m * std::cos(theta), east = radius_m * std::sin(theta);
      const int r = r0 - int(std::lround(north / h));
      const int c = c0 + int(std::lround(east / distance_.width_between(r0, r)));
      if (c < 0 || r < 0 || c >= cols_ || r >= rows_) return true;
      if (!habitable_[std::size_t(r) * std::size_t(cols_) + std::size_t(c)]) return true;
    }
    return false;
  }

 private:
  const std::vector<std::uint8_t>& habitable_;
  int cols_, rows_;
  const GridDistance& distance_;
  std::vector<std::uint16_t> row_gap_;
};

/// Marks the cells whose centre lies strictly inside the disc of `s` (the centre test of the
/// inclusion rules).
void mark_disc(const Site& s, const GridDistance& distance, int cols, int rows, std::vector<std::uint8_t>& covered) {
  const double y0 = distance.northing(s.row);
  for (int dir : {1, -1})
    for (int r = dir == 1 ? s.row : s.row - 1; r >= 0 && r < rows; r += dir) {
      const double dy = std::abs(distance.northing(r) - y0);
      if (dy >= s.radius_m) break;
      const double w = distance.width_between(s.row, r);
      const int reach = int(std::sqrt(s.radius_m * s.radius_m - dy * dy) / w) + 1;
      for (int c = std::max(0, s.col - reach); c <= std::min(cols - 1, s.col + reach); ++c)
        if (distance(s.col, s.row, c, r) < s.radius_m) covered[std::size_t(r) * std::size_t(cols) + std::size_t(c)] = 1;
    }
}

/// Cells whose centre lies strictly inside one of the discs of `sites`.
std::vector<std::uint8_t> covered_cells(const std::vector<Site>& sites, const GridDistance& distance, int cols, int rows) {
  std::vector<std::uint8_t> covered(std::size_t(cols) * std::size_t(rows), 0);
  for (const Site& s : sites) mark_disc(s, distance, cols, rows, covered);
  return covered;
}

/// Places left for new settlements out of `room`: those the existing places do not take, and at
/// least the new people's share of the room (where more places are given than the lattice
/// holds, the given places show the land holds more).
std::size_t free_room(std::size_t room, double to_place, const SitesResult& result, const SitesOptions& options) {
  const std::size_t left = room - std::min(room, options.existing.size());
  if (!(to_place > 0) || !(result.settled_population > 0)) return left;
  return std::max(left, std::size_t(std::ceil(double(room) * to_place / result.settled_population)));
}

/// The rank_size quotas: the region's people (the figure given, else the default density times
/// the land area), the settled share of them split by the rank-size law (its exponent given, or
/// read from the catchments of a first placement), at most as many places as the land holds.
QuotaTable rank_size_table(const Raster<float>& density, const Raster<std::uint8_t>& buildable, const SitesOptions& options,
                           const CellMetrics& metrics, double cell_size, SitesResult& result, Progress& progress) {
  double land_km2 = options.land_area_km2;
  if (!(land_km2 > 0)) {
    double m2 = 0;
    for (int r = 0; r < density.rows(); ++r)
      for (int c = 0; c < density.cols(); ++c)
        if (buildable(c, r) == 1) m2 += metrics.area_m2[std::size_t(r)];
    land_km2 = m2 * 1e-6;
  }
  result.population_assumed = !(options.population > 0);
  result.land_area_km2 = land_km2;
  result.target_population = result.population_assumed ? std::round(options.people_per_km2 * land_km2) : options.population;
  result.settled_population = std::round(options.urban_share * result.target_population);
  result.sizes_exponent = options.zipf_exponent;
  // Existing settlements hold their people and the law's first ranks: the rest are its tail, the
  // ranks below the existing places of min_population or more, over the places still free.
  std::size_t first_rank = 1;
  for (const Site& e : options.existing) {
    result.existing_population += double(e.population);
    if (double(e.population) >= options.min_population) ++first_rank;
  }
  // The given places are people that exist: the region holds at least them, and so do its
  // settlements (a total given below them, a settled share they already pass).
  result.target_population = std::max(result.target_population, result.existing_population);
  result.settled_population = std::max(result.settled_population, result.existing_population);
  // Without a census figure the given places are the region's settlements as it is: an assumed
  // density (people_per_km2) invents no town beside them, so a growth of 0 adds nothing and a
  // growth scenario compares with that run. sites.population asks for the towns beyond them.
  if (!options.existing.empty() && result.population_assumed) result.settled_population = result.existing_population;
  double to_place = std::max(0.0, result.settled_population - result.existing_population);
  if (options.growth > 0) {
    // Growth scenario: the existing places are today's settled people; the region grows by
    // `growth`, and the model places only growth_new_share of the new settled people.
    const double today = std::max(result.target_population, result.existing_population);
    result.target_population = std::round(today * (1 + options.growth));
    result.growth_people = std::llround(result.existing_population * options.growth);
    result.settled_population = result.existing_population + double(result.growth_people);
    to_place = std::round(options.growth_new_share * double(result.growth_people));
  }
  const std::size_t full_room = settleable_count(land_km2, options, result.target_population);
  const std::size_t room = full_room == std::numeric_limits<std::size_t>::max() ? full_room : free_room(full_room, to_place, result, options);
  std::vector<std::int64_t> sizes;
  if (options.sizes == SitesOptions::Sizes::catchment) {
    // The central places of all the region's people by the law, their catchments on the
    // density model, and the law's exponent read from those of min_population or more.
    SitesOptions pilot = options;
    pilot.sizes = SitesOptions::Sizes::rank_size;
    pilot.urban_share = 1;
    pilot.influence_factor = 0;
    pilot.population = result.target_population;
    pilot.land_area_km2 = land_km2;
    pilot.existing.clear();
    pilot.growth = 0;
    pilot.min_distance_share = 0;  // the catchments of the densest sites, unspaced, give the sizes their spread
    const SitesResult central = place_sites(density, buildable, pilot, progress);
    result.room = central.room;
    result.count_limited = central.count_limited;
    std::vector<double> settled;
    for (double p : catchment_people(density, buildable, central.sites, result.settled_population))
      if (p >= options.min_population) settled.push_back(p);
    const double q = rank_size_exponent(settled);
    if (std::isfinite(q)) result.sizes_exponent = q;  // fewer than 3 catchments that large: zipf_exponent
    const std::size_t free = free_room(central.sites.size(), to_place, result, options);
    if (options.existing.empty()) sizes = rank_size_split(to_place, result.sizes_exponent, free);
    else if (to_place > 0)  // the law's tail over the free places, none below min_population
      sizes = rank_size_populations(to_place, result.sizes_exponent, options.min_population, free, first_rank);
    sizes.erase(std::find(sizes.begin(), sizes.end(), 0), sizes.end());  // more places than settled people
  } else {
    const auto law = [&](std::size_t max_count) {
      return rank_size_populations(to_place, options.zipf_exponent, options.min_population, max_count, first_rank);
    };
    sizes = law(room);
    if (room != std::numeric_limits<std::size_t>::max()) {
      result.room = std::int64_t(room);
      result.count_limited = sizes.size() == room && law(room + 1).size() > room;
    }
  }
  // People of the law's tail too few for one settlement of min_population: reported, not lost.
  if (!options.existing.empty() && options.growth == 0)
    result.unplaced_people += std::llround(to_place) - std::accumulate(sizes.begin(), sizes.end(), std::int64_t(0));
  QuotaTable table = rank_size_quotas(cell_size, sizes, options);
  return table;
}

/// Habitable cells: buildable == 1 with a density value.
std::vector<std::uint8_t> habitable_cells(const Raster<float>& density, const Raster<std::uint8_t>& buildable) {
  std::vector<std::uint8_t> habitable(density.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, density.size(), 1 << 16), [&](const tbb::blocked_range<std::size_t>& range) {
    for (std::size_t i = range.begin(); i < range.end(); ++i)
      habitable[i] = buildable[i] == 1 && !buildable.is_nodata(i) && std::isfinite(density[i]);
  });
  return habitable;
}

/// M distinct candidates drawn uniformly among the habitable cells (partial Fisher-Yates), by
/// density, decreasing; equal densities keep the draw order, itself random.
std::vector<std::uint32_t> draw_candidates(const Raster<float>& density, const std::vector<std::uint8_t>& habitable, std::int64_t wanted,
                                           std::uint64_t seed) {
  std::vector<std::uint32_t> pool;
  if (density.size() > std::numeric_limits<std::uint32_t>::max()) throw bad_input("sites: grid larger than 2^32 cells");
  for (std::size_t i = 0; i < habitable.size(); ++i)
    if (habitable[i]) pool.push_back(std::uint32_t(i));
  if (pool.empty()) throw bad_input("sites: no buildable cell in the density model");
  const std::size_t m = std::size_t(std::clamp<std::int64_t>(wanted, 1, std::int64_t(pool.size())));
  std::mt19937_64 generator(seed);
  for (std::size_t k = 0; k < m; ++k) std::swap(pool[k], pool[k + bounded(generator, pool.size() - k)]);
  pool.resize(m);
  std::stable_sort(pool.begin(), pool.end(), [&](std::uint32_t a, std::uint32_t b) { return density[a] > density[b]; });
  return pool;
}

/// The centres placed so far, bucketed on a grid of blocks at least `block_metres` wide, for the
/// test that a new centre keeps a distance (of `block_metres` or more) from every one of them.
class Spacing {
 public:
  Spacing(double block_metres, const GridDistance& distance) : block_metres_(block_metres), distance_(distance) {
    if (!(block_metres_ > 0)) return;
    const CellMetrics& m = distance.metrics();
    const double width = *std::min_element(m.width_m.begin(), m.width_m.end());
    const double height = *std::min_element(m.height_m.begin(), m.height_m.end());
    block_cols_ = std::max(1, int(std::ceil(block_metres_ / std::max(width, 1e-9))));
    block_rows_ = std::max(1, int(std::ceil(block_metres_ / std::max(height, 1e-9))));
  }

  void add(int c, int r) {
    if (block_metres_ > 0) blocks_[key(c / block_cols_, r / block_rows_)].push_back({c, r});
  }

  bool too_close(int c, int r, double metres) const {
    if (!(block_metres_ > 0) || blocks_.empty()) return false;
    const int bc = c / block_cols_, br = r / block_rows_;
    const int reach = int(std::ceil(metres / block_metres_ - 1e-9));
    for (int dr = -reach; dr <= reach; ++dr)
      for (int dc = -reach; dc <= reach; ++dc) {
        const auto it = blocks_.find(key(bc + dc, br + dr));
        if (it == blocks_.end()) continue;
        for (const auto& [pc, pr] : it->second)
          if (distance_(c, r, pc, pr) < metres) return true;
      }
    return false;
  }

 private:
  static std::uint64_t key(int bc, int br) { return (std::uint64_t(std::uint32_t(br)) << 32) | std::uint32_t(bc); }
  double block_metres_;
  const GridDistance& distance_;
  int block_cols_ = 1, block_rows_ = 1;
  std::unordered_map<std::uint64_t, std::vector<std::pair<int, int>>> blocks_;
};

/// Growth (Algorithm 14) over the candidates in density order, resumable: each call goes on from
/// the first candidate not reached yet.
class Growth {
 public:
  /// `radius`: ascending radius index i of Algorithm 14 (r = r_min + i dr); class = n - 1 - i.
  Growth(const Raster<float>& density, const std::vector<std::uint8_t>& habitable, std::vector<std::uint32_t> pool,
         std::vector<double> radius, const SitesOptions& options, const GridDistance& distance)
      : density_(density), pool_(std::move(pool)), radius_(std::move(radius)), options_(options), cols_(density.cols()),
        distance_(distance), tester_(habitable, density.cols(), density.rows(), distance) {
    if (options.disc_test == SitesOptions::DiscTest::exact) tester_.build_row_pass();
  }

  /// Central-place spacing, by radius index j: the settlement of rank k (the next of class j has
  /// rank first_rank[j] + those of j placed) keeps share x sqrt(land / k) from every centre at least
  /// as large, a generated one of index j or more or a `fixed` (existing) one of `floor[j]` people
  /// or more. Without it the discs alone keep them apart.
  void keep_apart(double share, double land_m2, std::vector<std::size_t> first_rank, std::vector<std::size_t> last_rank,
                  std::vector<std::int64_t> floor, const std::vector<Site>& fixed) {
    share_ = share;
    land_m2_ = land_m2;
    first_rank_ = std::move(first_rank);
    last_rank_ = std::move(last_rank);
    floor_ = std::move(floor);
    fixed_ = &fixed;
  }

  bool candidates_left() const { return next_ < pool_.size(); }

  /// The settlements still without a place once the growth is done: no candidate's disc was clear
  /// of unbuildable land for them (a city on land cut by water or steep slopes). Each, largest
  /// first, goes to the densest candidate whose cell no disc covers, its disc then reaching over
  /// that land, as a city's does around a bay. `covered` gains every disc placed.
  void crowd(std::vector<int>& quota, QuotaTable& table, std::vector<Site>& out, std::vector<std::uint8_t>& covered,
             const GridDistance& distance) {
    const int n = int(radius_.size());
    int j = n - 1;
    for (std::size_t k = 0; k < pool_.size(); ++k) {
      while (j >= 0 && quota[std::size_t(j)] == 0) --j;
      if (j < 0) break;
      if (covered[pool_[k]]) continue;
      --quota[std::size_t(j)];
      ++table.classes[std::size_t(n - 1 - j)].placed;
      out.push_back(site_at(k, j));
      mark_disc(out.back(), distance, cols_, density_.rows(), covered);
    }
  }

  /// From candidate `next_` on, with quota[] left, skipping candidates whose cell is `covered`;
  /// appends the sites to `out`. Disc tests run in parallel a batch ahead; the quota bookkeeping is
  /// sequential, in density order.
  void grow(const std::vector<std::uint8_t>* covered, std::vector<int>& quota, QuotaTable& table, std::vector<Site>& out, ProgressStep& step) {
    const std::size_t m = pool_.size();
    const int n = int(radius_.size());
    int remaining = std::accumulate(quota.begin(), quota.end(), 0);
    std::vector<int> limit;
    // One grid of centres per class, holding those it keeps its distance from (its blocks as wide
    // as the distance of its last rank, the least it keeps).
    const bool spaced = !first_rank_.empty();
    const auto metres = [&](std::size_t rank) { return share_ * std::sqrt(land_m2_ / double(std::max<std::size_t>(rank, 1))); };
    std::vector<Spacing> spacing;
    std::vector<std::size_t> in_class(std::size_t(n), 0);
    for (int j = 0; j < n; ++j) spacing.emplace_back(spaced ? metres(last_rank_[std::size_t(j)]) : 0.0, distance_);
    const auto add = [&](int c, int r, int index) {
      ++in_class[std::size_t(index)];
      for (int j = 0; j <= index; ++j) spacing[std::size_t(j)].add(c, r);
    };
    const auto too_close = [&](int c, int r, int j) {
      return spaced && spacing[std::size_t(j)].too_close(c, r, metres(first_rank_[std::size_t(j)] + in_class[std::size_t(j)]));
    };
    if (fixed_ && spaced)
      for (const Site& s : *fixed_)
        for (int j = 0; j < n; ++j)
          if (s.population >= floor_[std::size_t(j)]) spacing[std::size_t(j)].add(s.col, s.row);
    for (const Site& s : out) add(s.col, s.row, n - 1 - s.radius_class);
    const std::size_t batch = 4096;
    while (next_ < m && remaining > 0) {
      const std::size_t begin = next_, end = std::min(m, begin + batch);
      limit.assign(end - begin, 0);
      tbb::parallel_for(tbb::blocked_range<std::size_t>(begin, end, 16), [&](const tbb::blocked_range<std::size_t>& range) {
        for (std::size_t k = range.begin(); k < range.end(); ++k)
          limit[k - begin] = covered && (*covered)[pool_[k]] ? 0 : clear_classes(pool_[k]);
      });
      for (std::size_t k = begin; k < end && remaining > 0; ++k, next_ = k) {
        const int c = int(pool_[k] % std::uint32_t(cols_)), r = int(pool_[k] / std::uint32_t(cols_));
        int j = limit[k - begin] - 1;  // the largest valid class with quota left, spaced from the larger centres
        while (j >= 0 && (quota[std::size_t(j)] == 0 || too_close(c, r, j))) --j;
        if (j < 0) continue;  // supprimer(L_sites, S)
        --quota[std::size_t(j)];
        --remaining;
        ++table.classes[std::size_t(n - 1 - j)].placed;
        out.push_back(site_at(k, j));
        add(c, r, j);
      }
      step.update(double(next_) / double(m));
    }
  }

  /// By radius, decreasing; equal radii keep the density order.
  void sort_by_size(std::vector<Site>& sites) const {
    std::sort(sites.begin(), sites.end(), [&](const Site& a, const Site& b) {
      if (a.radius_m != b.radius_m) return a.radius_m > b.radius_m;
      return rank_of_.at(std::uint32_t(a.row) * std::uint32_t(cols_) + std::uint32_t(a.col)) <
             rank_of_.at(std::uint32_t(b.row) * std::uint32_t(cols_) + std::uint32_t(b.col));
    });
  }

 private:
  /// Number of leading classes whose disc is clear: the growth stops at the first intersection.
  int clear_classes(std::uint32_t cell) const {
    const int c = int(cell % std::uint32_t(cols_)), r = int(cell / std::uint32_t(cols_));
    if (options_.disc_test == SitesOptions::DiscTest::exact) {
      const double d = tester_.clear_distance_m(c, r, radius_.back() + 1.0);
      return int(std::lower_bound(radius_.begin(), radius_.end(), d) - radius_.begin());  // classes with radius < d
    }
    int i = 0;
    while (i < int(radius_.size()) && !tester_.circle_hits(c, r, radius_[std::size_t(i)])) ++i;
    return i;
  }

  /// The site of candidate k in radius index j.
  Site site_at(std::size_t k, int j) {
    const int n = int(radius_.size());
    Site s;
    s.col = int(pool_[k] % std::uint32_t(cols_));
    s.row = int(pool_[k] / std::uint32_t(cols_));
    const auto xy = density_.georef().cell_centre(s.col, s.row);
    s.x = xy[0];
    s.y = xy[1];
    s.radius_m = radius_[std::size_t(j)];
    s.radius_class = n - 1 - j;
    s.population = std::llround(options_.people_per_m * s.radius_m);
    s.density = density_[pool_[k]];
    rank_of_[pool_[k]] = k;
    return s;
  }

  const Raster<float>& density_;
  const std::vector<std::uint32_t> pool_;
  const std::vector<double> radius_;
  const SitesOptions& options_;
  const int cols_;
  const GridDistance& distance_;
  DiscTester tester_;
  double share_ = 0, land_m2_ = 0;
  std::vector<std::size_t> first_rank_, last_rank_;
  std::vector<std::int64_t> floor_;
  const std::vector<Site>* fixed_ = nullptr;
  std::size_t next_ = 0;
  std::unordered_map<std::uint32_t, std::size_t> rank_of_;  // candidate cell -> position in density order
};

/// Central places by rank (Christaller 1933: the fewer the places of an order, the farther apart):
/// the k places of rank k or better spread evenly over the land L lie sqrt(L / k) apart, so the
/// settlement of rank k keeps share x sqrt(L / k) from every centre at least as large (existing
/// places ranked among the law's sizes by their people).
void keep_central_places_apart(Growth& growth, const QuotaTable& table, const std::vector<Site>& existing, double share, double land_km2) {
  const std::size_t n = table.classes.size();
  std::vector<std::size_t> first(n, 1), last(n, 1);
  std::vector<std::int64_t> floor(n, std::numeric_limits<std::int64_t>::max());
  std::size_t larger = 0;  // generated settlements of the classes above
  for (std::size_t c = 0; c < n; ++c) {
    const std::vector<std::int64_t>& sizes = table.populations[c];
    const std::size_t j = n - 1 - c;
    std::size_t above = 0;
    if (!sizes.empty())
      for (const Site& e : existing) above += e.population > sizes.front();
    first[j] = 1 + larger + above;
    last[j] = first[j] + std::max<std::size_t>(sizes.size(), 1) - 1;
    if (!sizes.empty()) floor[j] = sizes.back();
    larger += sizes.size();
  }
  growth.keep_apart(share, land_km2 * 1e6, std::move(first), std::move(last), std::move(floor), existing);
}

/// rank_size: every settlement of the law gets a place. Those the growth and its refills left
/// without one are crowded in (Growth::crowd) and the list is put back in size order, parents
/// first; result.crowded counts them.
void crowd_the_rest(Growth& growth, QuotaTable& table, const std::vector<std::uint8_t>& occupied, const GridDistance& distance,
                    int cols, int rows, SitesResult& result) {
  const int n = int(table.classes.size());
  std::vector<int> quota(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) quota[std::size_t(i)] = table.classes[std::size_t(n - 1 - i)].quota;
  for (const Site& s : result.sites) --quota[std::size_t(n - 1 - s.radius_class)];
  if (std::accumulate(quota.begin(), quota.end(), 0) == 0) return;
  std::vector<std::uint8_t> covered = covered_cells(result.sites, distance, cols, rows);
  for (std::size_t i = 0; i < occupied.size(); ++i) covered[i] |= occupied[i];
  std::vector<Site>& sites = result.sites;
  for (std::size_t k = 0; k < sites.size(); ++k) sites[k].id = int(k);
  const std::size_t before = sites.size();
  growth.crowd(quota, table, sites, covered, distance);
  result.crowded = std::int64_t(sites.size() - before);
  for (std::size_t k = before; k < sites.size(); ++k) sites[k].id = int(k);
  growth.sort_by_size(sites);
  std::vector<int> index_of(sites.size());
  for (std::size_t k = 0; k < sites.size(); ++k) index_of[std::size_t(sites[k].id)] = int(k);
  for (std::size_t k = 0; k < sites.size(); ++k) {
    sites[k].id = int(k);
    if (sites[k].parent >= 0) sites[k].parent = index_of[std::size_t(sites[k].parent)];
  }
  for (Site& s : sites) s.depth = s.parent < 0 ? 0 : sites[std::size_t(s.parent)].depth + 1;
}

/// Growth scenario: the new settlements' people are theirs; the rest of the growth goes to the
/// existing places in proportion to their size (Gibrat 1931).
void grow_existing(SitesResult& result, std::vector<Site>& existing) {
  for (Site& s : result.sites) result.growth_to_new += (s.gained = s.population);
  result.growth_to_existing = result.growth_people - result.growth_to_new;
  result.unplaced = result.unplaced_people = 0;  // the people of new settlements with no place grow the existing ones
  std::vector<std::int64_t> sizes;
  for (const Site& e : existing) sizes.push_back(e.population);
  const std::vector<std::int64_t> gains = proportional_split(result.growth_to_existing, sizes);
  for (std::size_t k = 0; k < existing.size(); ++k) {
    existing[k].gained = gains[k];
    existing[k].population += gains[k];
  }
}

}  // namespace

SitesResult place_sites(const Raster<float>& density, const Raster<std::uint8_t>& buildable, const SitesOptions& options,
                        Progress& progress) {
  check_settings(options);
  if (options.growth > 0 && options.existing.empty()) throw bad_input("/sites/growth: needs /sites/existing, the places that grow");
  const int cols = density.cols(), rows = density.rows();
  if (buildable.cols() != cols || buildable.rows() != rows)
    throw bad_input("sites: the buildable mask and the density model are not on the same grid");
  if (cols < 1 || rows < 1) throw bad_input("sites: empty density grid");
  const GridDistance distance(density.georef(), cols, rows);
  const CellMetrics& metrics = distance.metrics();
  // The DEM's scale e of Algorithm 13 (1/e = metres per cell): the coarser side of a cell at the centre row.
  const int centre = rows / 2;
  const double cell_size = std::max(metrics.width_m[std::size_t(centre)], metrics.height_m[std::size_t(centre)]);
  SitesResult result;
  QuotaTable table = options.quotas == SitesOptions::Quotas::belhadj2007 ? compute_quotas(cell_size, options)
                                                                         : rank_size_table(density, buildable, options, metrics, cell_size, result, progress);
  const int n = int(table.classes.size());
  // Ascending radius index i of Algorithm 14 (r = r_min + i dr); class = n - 1 - i.
  std::vector<double> radius(static_cast<std::size_t>(n));
  std::vector<int> quota(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    radius[std::size_t(i)] = table.classes[std::size_t(n - 1 - i)].radius_m;
    quota[std::size_t(i)] = table.classes[std::size_t(n - 1 - i)].quota;
  }

  result.dr_m = table.dr_m;
  result.seed = options.seed;

  const std::vector<std::uint8_t> habitable = habitable_cells(density, buildable);
  const std::int64_t wanted = options.candidates > 0 ? std::int64_t(options.candidates) : 20 * std::int64_t(table.total());
  std::vector<std::uint32_t> pool = draw_candidates(density, habitable, wanted, options.seed);
  result.candidates = int(pool.size());
  Growth growth(density, habitable, std::move(pool), std::move(radius), options, distance);

  // Existing settlements occupy their built-up discs (grown by the whole growth share in a growth
  // scenario, the most they may reach): no generated centre falls in one.
  std::vector<Site> existing = options.existing;
  for (Site& e : existing) e.radius_m = urban_radius_m(double(e.population) * (1 + options.growth), options);
  const std::vector<std::uint8_t> occupied = existing.empty() ? std::vector<std::uint8_t>() : covered_cells(existing, distance, cols, rows);
  if (options.quotas == SitesOptions::Quotas::rank_size && options.min_distance_share > 0 && result.land_area_km2 > 0)
    keep_central_places_apart(growth, table, existing, options.min_distance_share, result.land_area_km2);
  std::vector<Site> placed;
  {
    ProgressStep step(progress, "sites: growth");
    growth.grow(existing.empty() ? nullptr : &occupied, quota, table, placed, step);
  }
  {
    ProgressStep step(progress, "sites: inclusions");
    growth.sort_by_size(placed);
    result.sites = resolve_inclusions(placed, options.mode, distance, cols, rows);
    step.update(1.0);
  }
  // Refill (Belhadj §4.3.1.2 names it as the remedy for the imbalance left by the inclusion
  // removal): the quota of removed sites goes back to the growth, which resumes on the
  // candidates not reached yet, skipping those whose centre lies in a kept disc.
  for (int round = 0; round < options.refill_rounds && growth.candidates_left(); ++round) {
    std::vector<int> kept(static_cast<std::size_t>(n), 0);
    for (const Site& s : result.sites) ++kept[std::size_t(n - 1 - s.radius_class)];
    for (int i = 0; i < n; ++i) quota[std::size_t(i)] = table.classes[std::size_t(n - 1 - i)].quota - kept[std::size_t(i)];
    if (std::accumulate(quota.begin(), quota.end(), 0) == 0) break;
    ProgressStep step(progress, "sites: refill " + std::to_string(round + 1));
    std::vector<std::uint8_t> covered = covered_cells(result.sites, distance, cols, rows);
    for (std::size_t i = 0; i < occupied.size(); ++i) covered[i] |= occupied[i];
    std::vector<Site> merged = result.sites;
    const std::size_t before = merged.size();
    growth.grow(&covered, quota, table, merged, step);
    if (merged.size() == before) break;
    growth.sort_by_size(merged);
    result.sites = resolve_inclusions(merged, options.mode, distance, cols, rows);
  }
  if (options.quotas == SitesOptions::Quotas::rank_size) crowd_the_rest(growth, table, occupied, distance, cols, rows, result);
  for (Site& s : result.sites) {
    QuotaClass& c = table.classes[std::size_t(s.radius_class)];
    // rank_size: within a class, sites (by density order) take the class's sizes, largest first.
    if (!table.populations.empty()) s.population = table.populations[std::size_t(s.radius_class)][std::size_t(c.kept)];
    ++c.kept;
  }
  // Settlements of the law with no place even so (no candidate left outside the discs): reported.
  for (std::size_t c = 0; c < table.populations.size(); ++c)
    for (std::size_t j = std::size_t(table.classes[c].kept); j < table.populations[c].size(); ++j)
      ++result.unplaced, result.unplaced_people += table.populations[c][j];
  if (options.growth > 0) grow_existing(result, existing);
  if (!existing.empty()) {
    // Existing and generated settlements classed together by their sizes, the largest first, and
    // the hierarchy rebuilt over all of them by influence (below).
    std::vector<Site> all = existing;
    all.insert(all.end(), result.sites.begin(), result.sites.end());
    std::stable_sort(all.begin(), all.end(), [](const Site& a, const Site& b) { return a.population > b.population; });
    std::vector<std::int64_t> sizes;
    for (const Site& x : all) sizes.push_back(x.population);
    table = rank_size_quotas(cell_size, sizes, options);
    for (auto& c : table.classes) c.placed = c.kept = 0;
    std::size_t k = 0;
    for (std::size_t c = 0; c < table.classes.size(); ++c)
      for (std::size_t j = 0; j < table.populations[c].size(); ++j, ++k) {
        Site& x = all[k];
        x.id = int(k);
        x.radius_class = int(c);
        x.radius_m = table.classes[c].radius_m;
        x.parent = -1;
        x.depth = 0;
        if (x.existing) x.density = std::isfinite(density(x.col, x.row)) ? density(x.col, x.row) : 0.0;
        ++table.classes[c].kept, ++table.classes[c].placed;
      }
    result.sites = std::move(all);
  }
  // Suburbs by influence (rank_size, paris: Manhattan's regular tiling has none).
  if (options.quotas == SitesOptions::Quotas::rank_size && options.mode == SitesOptions::Mode::paris && result.land_area_km2 > 0) {
    const double people_per_km2 = result.target_population / result.land_area_km2;
    std::vector<double> influence(result.sites.size());
    for (std::size_t k = 0; k < influence.size(); ++k)
      influence[k] = influence_radius_m(double(result.sites[k].population), options.influence_factor, people_per_km2);
    attach_suburbs(result.sites, influence, distance);
  }
  result.quotas = table.classes;
  return result;
}

}  // namespace terrapolis::sites
