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

/// The disc tests of Algorithm 14 (intersecte_seuil), for discs centred on cell centres, on a
/// window of the land: a block of candidates grown by the largest disc (clear_classes_of). The
/// grid's edges count as uninhabitable; a window's edge inside the grid does not, and the margin
/// makes it never matter (clear_classes_of).
class DiscTester {
 public:
  DiscTester(const LandView& window, int cols, int rows, const GridDistance& distance)
      : w_(window), cols_(cols), rows_(rows), distance_(distance) {}

  /// Row pass of a separable distance transform: for every cell, the number of columns to
  /// the nearest uninhabitable cell of its row (the columns just outside the grid count as
  /// uninhabitable), capped at 65535. The column pass is evaluated exactly, per candidate,
  /// in clear_distance_m.
  void build_row_pass() {
    row_gap_.assign(std::size_t(w_.cols) * std::size_t(w_.rows), kFar);
    const long none = -long(kFar) - 1;  // no uninhabitable cell seen yet in the window (the gap stays kFar)
    const long west = w_.col0 == 0 ? -1 : none, east = w_.col0 + w_.cols == cols_ ? cols_ : long(cols_) + kFar + w_.cols;
    tbb::parallel_for(tbb::blocked_range<int>(w_.row0, w_.row0 + w_.rows), [&](const tbb::blocked_range<int>& range) {
      for (int r = range.begin(); r < range.end(); ++r) {
        std::uint16_t* gap = row_gap_.data() + std::size_t(r - w_.row0) * std::size_t(w_.cols);  // gap[c - col0]
        long last = west;  // the virtual column west of the grid, or none
        for (int c = w_.col0; c < w_.col0 + w_.cols; ++c) {
          if (!w_.habitable(c, r)) last = c;
          gap[c - w_.col0] = std::uint16_t(std::min<long>(c - last, kFar));
        }
        last = east;  // the virtual column east of the grid, or none
        for (int c = w_.col0 + w_.cols - 1; c >= w_.col0; --c) {
          if (!w_.habitable(c, r)) last = c;
          gap[c - w_.col0] = std::uint16_t(std::min<long>({long(gap[c - w_.col0]), last - c, long(kFar)}));
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
        const double gap = row_gap_[std::size_t(r - w_.row0) * std::size_t(w_.cols) + std::size_t(c0 - w_.col0)];
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
      if (!w_.habitable(c, r)) return true;
    }
    return false;
  }

 private:
  const LandView& w_;
  int cols_, rows_;
  const GridDistance& distance_;
  std::vector<std::uint16_t> row_gap_;  // over the window
};

/// For each candidate cell (pool, in density order), the number of leading radius classes (ascending
/// `radius`) whose disc is clear of uninhabitable land: the growth stops at the first intersection.
/// It depends on the land alone, so every candidate is tested once, block by block of the land
/// (Land::block_side), each block read with a margin as wide as the largest disc: a window's edge
/// inside the grid is farther from its candidates than any disc reaches, so the result is the
/// whole grid's.
std::vector<int> clear_classes_of(const Land& land, const std::vector<std::uint32_t>& pool, const std::vector<double>& radius,
                                  const SitesOptions& options, const GridDistance& distance, ProgressStep& step) {
  std::vector<int> limit(pool.size(), 0);
  if (radius.empty() || pool.empty()) return limit;
  const int cols = land.cols(), rows = land.rows();
  const bool exact = options.disc_test == SitesOptions::DiscTest::exact;
  const double cap = radius.back() + 1.0;  // the exact test's search radius, beyond the largest disc
  const CellMetrics& m = distance.metrics();
  const double width = std::max(*std::min_element(m.width_m.begin(), m.width_m.end()), 1e-9);
  const double height = std::max(*std::min_element(m.height_m.begin(), m.height_m.end()), 1e-9);
  const auto margin = [&](double cell_m, int extent) { return int(std::min<double>(std::ceil(cap / cell_m) + 2, extent)); };
  const int margin_cols = margin(width, cols), margin_rows = margin(height, rows);
  const int given = land.block_side(margin_cols, margin_rows), side = given > 0 ? given : std::max(cols, rows);
  const int across = (cols + side - 1) / side;
  // Candidates by block (then density order).
  std::vector<std::pair<std::uint64_t, std::uint32_t>> by_block(pool.size());
  for (std::size_t k = 0; k < pool.size(); ++k) {
    const std::uint32_t c = pool[k] % std::uint32_t(cols), r = pool[k] / std::uint32_t(cols);
    by_block[k] = {std::uint64_t(r / std::uint32_t(side)) * std::uint64_t(across) + c / std::uint32_t(side), std::uint32_t(k)};
  }
  std::sort(by_block.begin(), by_block.end());
  for (std::size_t begin = 0; begin < by_block.size();) {
    std::size_t end = begin;
    while (end < by_block.size() && by_block[end].first == by_block[begin].first) ++end;
    const int bc = int(by_block[begin].first % std::uint64_t(across)), br = int(by_block[begin].first / std::uint64_t(across));
    const int c0 = std::max(0, bc * side - margin_cols), r0 = std::max(0, br * side - margin_rows);
    const int c1 = std::min(cols, (bc + 1) * side + margin_cols), r1 = std::min(rows, (br + 1) * side + margin_rows);
    const LandView window = land.window(c0, r0, c1 - c0, r1 - r0);
    DiscTester tester(window, cols, rows, distance);
    if (exact) tester.build_row_pass();
    tbb::parallel_for(tbb::blocked_range<std::size_t>(begin, end, 16), [&](const tbb::blocked_range<std::size_t>& range) {
      for (std::size_t b = range.begin(); b < range.end(); ++b) {
        const std::uint32_t k = by_block[b].second;
        const int c = int(pool[k] % std::uint32_t(cols)), r = int(pool[k] / std::uint32_t(cols));
        if (exact) {
          const double d = tester.clear_distance_m(c, r, cap);
          limit[k] = int(std::lower_bound(radius.begin(), radius.end(), d) - radius.begin());  // classes with radius < d
        } else {
          int i = 0;
          while (i < int(radius.size()) && !tester.circle_hits(c, r, radius[std::size_t(i)])) ++i;
          limit[k] = i;
        }
      }
    });
    begin = end;
    step.update(double(end) / double(by_block.size()));
  }
  return limit;
}

/// The candidate cells, for the test of which of them lie inside a disc.
class CandidateCells {
 public:
  explicit CandidateCells(const std::vector<std::uint32_t>& pool) : by_cell_(pool.size()) {
    for (std::size_t k = 0; k < pool.size(); ++k) by_cell_[k] = {pool[k], std::uint32_t(k)};
    std::sort(by_cell_.begin(), by_cell_.end());
  }

  /// Flags (by candidate) those whose cell centre lies strictly inside the disc of `s` (the centre
  /// test of the inclusion rules).
  void mark_disc(const Site& s, const GridDistance& distance, int cols, int rows, std::vector<std::uint8_t>& covered) const {
    const double y0 = distance.northing(s.row);
    for (int dir : {1, -1})
      for (int r = dir == 1 ? s.row : s.row - 1; r >= 0 && r < rows; r += dir) {
        const double dy = std::abs(distance.northing(r) - y0);
        if (dy >= s.radius_m) break;
        const double w = distance.width_between(s.row, r);
        const int reach = int(std::sqrt(s.radius_m * s.radius_m - dy * dy) / w) + 1;
        const std::uint32_t row_start = std::uint32_t(r) * std::uint32_t(cols);
        const std::uint32_t first = row_start + std::uint32_t(std::max(0, s.col - reach));
        const std::uint32_t last = row_start + std::uint32_t(std::min(cols - 1, s.col + reach));
        for (auto it = std::lower_bound(by_cell_.begin(), by_cell_.end(), std::pair<std::uint32_t, std::uint32_t>{first, 0});
             it != by_cell_.end() && it->first <= last; ++it)
          if (distance(s.col, s.row, int(it->first - row_start), r) < s.radius_m) covered[it->second] = 1;
      }
  }

  /// Flags the candidates inside one of the discs of `sites`.
  std::vector<std::uint8_t> covered(const std::vector<Site>& sites, const GridDistance& distance, int cols, int rows) const {
    std::vector<std::uint8_t> flags(by_cell_.size(), 0);
    for (const Site& s : sites) mark_disc(s, distance, cols, rows, flags);
    return flags;
  }

 private:
  std::vector<std::pair<std::uint32_t, std::uint32_t>> by_cell_;  // (cell, candidate), by cell
};

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
QuotaTable rank_size_table(const Land& land, const SitesOptions& options,
                           const CellMetrics& metrics, double cell_size, SitesResult& result, Progress& progress) {
  double land_km2 = options.land_area_km2;
  if (!(land_km2 > 0)) {
    double m2 = 0;
    land.for_each_band([&](const LandView& v) {
      for (int r = v.row0; r < v.row0 + v.rows; ++r)
        for (int c = v.col0; c < v.col0 + v.cols; ++c)
          if (v.buildable[v.at(c, r)] == 1) m2 += metrics.area_m2[std::size_t(r)];
    });
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
    const SitesResult central = place_sites(land, pilot, progress);
    result.room = central.room;
    result.count_limited = central.count_limited;
    std::vector<double> settled;
    for (double p : catchment_people(land, central.sites, result.settled_population))
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

/// The candidates: M distinct cells drawn uniformly among the habitable ones (partial Fisher-Yates
/// over their row-major list), by density, decreasing; equal densities keep the draw order, itself
/// random. The list is never held: the shuffle keeps only the positions it moved, and one pass over
/// the land turns the drawn positions into cells.
struct Candidates {
  std::vector<std::uint32_t> cells;
  std::vector<float> density;
};
Candidates draw_candidates(const Land& land, std::int64_t wanted, std::uint64_t seed) {
  if (std::uint64_t(land.cols()) * std::uint64_t(land.rows()) > std::numeric_limits<std::uint32_t>::max())
    throw bad_input("sites: grid larger than 2^32 cells");
  const std::uint64_t habitable = land.habitable_cells();
  if (habitable == 0) throw bad_input("sites: no buildable cell in the density model");
  const std::size_t m = std::size_t(std::clamp<std::int64_t>(wanted, 1, std::int64_t(std::min<std::uint64_t>(habitable, INT64_MAX))));
  // Position p of the list holds habitable cell number p until the shuffle moves it. Position k is
  // final once step k is done (later steps swap positions after it).
  std::unordered_map<std::uint64_t, std::uint64_t> moved;
  const auto at = [&](std::uint64_t p) {
    const auto it = moved.find(p);
    return it == moved.end() ? p : it->second;
  };
  std::mt19937_64 generator(seed);
  std::vector<std::uint64_t> drawn(m);  // habitable cell numbers, in draw order
  for (std::size_t k = 0; k < m; ++k) {
    const std::uint64_t j = k + bounded(generator, habitable - k);
    drawn[k] = at(j);
    moved[j] = at(k);
  }
  // Habitable cell numbers to cells and their densities, in one pass.
  std::vector<std::uint32_t> order(m);
  std::iota(order.begin(), order.end(), 0u);
  std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) { return drawn[a] < drawn[b]; });
  Candidates drawn_cells{std::vector<std::uint32_t>(m), std::vector<float>(m)};
  std::uint64_t number = 0;
  std::size_t next = 0;
  land.for_each_band([&](const LandView& v) {
    for (int r = v.row0; r < v.row0 + v.rows && next < m; ++r)
      for (int c = v.col0; c < v.col0 + v.cols && next < m; ++c) {
        if (!v.habitable(c, r)) continue;
        if (drawn[order[next]] == number) {
          drawn_cells.cells[order[next]] = std::uint32_t(r) * std::uint32_t(land.cols()) + std::uint32_t(c);
          drawn_cells.density[order[next]] = v.density[v.at(c, r)];
          ++next;
        }
        ++number;
      }
  });
  std::iota(order.begin(), order.end(), 0u);  // back to draw order
  std::stable_sort(order.begin(), order.end(),
                   [&](std::uint32_t a, std::uint32_t b) { return drawn_cells.density[a] > drawn_cells.density[b]; });
  Candidates out{std::vector<std::uint32_t>(m), std::vector<float>(m)};
  for (std::size_t k = 0; k < m; ++k) out.cells[k] = drawn_cells.cells[order[k]], out.density[k] = drawn_cells.density[order[k]];
  return out;
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
  Growth(const Land& land, Candidates candidates, std::vector<double> radius, const SitesOptions& options, const GridDistance& distance,
         Progress& progress)
      : georef_(land.georef()), pool_(std::move(candidates.cells)), pool_density_(std::move(candidates.density)),
        radius_(std::move(radius)), options_(options), cols_(land.cols()), rows_(land.rows()), distance_(distance), cells_(pool_) {
    ProgressStep step(progress, "sites: disc tests");
    limit_ = clear_classes_of(land, pool_, radius_, options, distance, step);
  }

  /// Flags the candidates that lie inside one of the discs of `sites`.
  std::vector<std::uint8_t> covered(const std::vector<Site>& sites) const { return cells_.covered(sites, distance_, cols_, rows_); }

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
  void crowd(std::vector<int>& quota, QuotaTable& table, std::vector<Site>& out, std::vector<std::uint8_t>& covered) {
    const int n = int(radius_.size());
    int j = n - 1;
    for (std::size_t k = 0; k < pool_.size(); ++k) {
      while (j >= 0 && quota[std::size_t(j)] == 0) --j;
      if (j < 0) break;
      if (covered[k]) continue;
      --quota[std::size_t(j)];
      ++table.classes[std::size_t(n - 1 - j)].placed;
      out.push_back(site_at(k, j));
      cells_.mark_disc(out.back(), distance_, cols_, rows_, covered);
    }
  }

  /// From candidate `next_` on, with quota[] left, skipping the `covered` candidates; appends the
  /// sites to `out`, in density order.
  void grow(const std::vector<std::uint8_t>* covered, std::vector<int>& quota, QuotaTable& table, std::vector<Site>& out, ProgressStep& step) {
    const std::size_t m = pool_.size();
    const int n = int(radius_.size());
    int remaining = std::accumulate(quota.begin(), quota.end(), 0);
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
    for (; next_ < m && remaining > 0; ++next_) {
      const std::size_t k = next_;
      if (k % 4096 == 0) step.update(double(k) / double(m));
      const int c = int(pool_[k] % std::uint32_t(cols_)), r = int(pool_[k] / std::uint32_t(cols_));
      // The largest valid class with quota left, spaced from the larger centres.
      int j = (covered && (*covered)[k] ? 0 : limit_[k]) - 1;
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

  /// By radius, decreasing; equal radii keep the density order.
  void sort_by_size(std::vector<Site>& sites) const {
    std::sort(sites.begin(), sites.end(), [&](const Site& a, const Site& b) {
      if (a.radius_m != b.radius_m) return a.radius_m > b.radius_m;
      return rank_of_.at(std::uint32_t(a.row) * std::uint32_t(cols_) + std::uint32_t(a.col)) <
             rank_of_.at(std::uint32_t(b.row) * std::uint32_t(cols_) + std::uint32_t(b.col));
    });
  }

 private:
  /// The site of candidate k in radius index j.
  Site site_at(std::size_t k, int j) {
    const int n = int(radius_.size());
    Site s;
    s.col = int(pool_[k] % std::uint32_t(cols_));
    s.row = int(pool_[k] / std::uint32_t(cols_));
    const auto xy = georef_.cell_centre(s.col, s.row);
    s.x = xy[0];
    s.y = xy[1];
    s.radius_m = radius_[std::size_t(j)];
    s.radius_class = n - 1 - j;
    s.population = std::llround(options_.people_per_m * s.radius_m);
    s.density = pool_density_[k];
    rank_of_[pool_[k]] = k;
    return s;
  }

  const Georef& georef_;
  const std::vector<std::uint32_t> pool_;   // candidate cells, by density, decreasing
  const std::vector<float> pool_density_;   // their densities
  const std::vector<double> radius_;
  const SitesOptions& options_;
  const int cols_, rows_;
  const GridDistance& distance_;
  const CandidateCells cells_;
  std::vector<int> limit_;  // by candidate: the leading classes whose disc is clear (clear_classes_of)
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
void crowd_the_rest(Growth& growth, QuotaTable& table, const std::vector<std::uint8_t>& occupied, SitesResult& result) {
  const int n = int(table.classes.size());
  std::vector<int> quota(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) quota[std::size_t(i)] = table.classes[std::size_t(n - 1 - i)].quota;
  for (const Site& s : result.sites) --quota[std::size_t(n - 1 - s.radius_class)];
  if (std::accumulate(quota.begin(), quota.end(), 0) == 0) return;
  std::vector<std::uint8_t> covered = growth.covered(result.sites);
  for (std::size_t i = 0; i < occupied.size(); ++i) covered[i] |= occupied[i];
  std::vector<Site>& sites = result.sites;
  for (std::size_t k = 0; k < sites.size(); ++k) sites[k].id = int(k);
  const std::size_t before = sites.size();
  growth.crowd(quota, table, sites, covered);
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
  return place_sites(LandRasters(density, buildable), options, progress);
}

SitesResult place_sites(const Land& land, const SitesOptions& options, Progress& progress) {
  check_settings(options);
  if (options.growth > 0 && options.existing.empty()) throw bad_input("/sites/growth: needs /sites/existing, the places that grow");
  const int cols = land.cols(), rows = land.rows();
  if (cols < 1 || rows < 1) throw bad_input("sites: empty density grid");
  const GridDistance distance(land.georef(), cols, rows);
  const CellMetrics& metrics = distance.metrics();
  // The DEM's scale e of Algorithm 13 (1/e = metres per cell): the coarser side of a cell at the centre row.
  const int centre = rows / 2;
  const double cell_size = std::max(metrics.width_m[std::size_t(centre)], metrics.height_m[std::size_t(centre)]);
  SitesResult result;
  QuotaTable table = options.quotas == SitesOptions::Quotas::belhadj2007 ? compute_quotas(cell_size, options)
                                                                         : rank_size_table(land, options, metrics, cell_size, result, progress);
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

  const std::int64_t wanted = options.candidates > 0 ? std::int64_t(options.candidates) : 20 * std::int64_t(table.total());
  Candidates candidates = draw_candidates(land, wanted, options.seed);
  result.candidates = int(candidates.cells.size());
  Growth growth(land, std::move(candidates), std::move(radius), options, distance, progress);

  // Existing settlements occupy their built-up discs (grown by the whole growth share in a growth
  // scenario, the most they may reach): no generated centre falls in one.
  std::vector<Site> existing = options.existing;
  for (Site& e : existing) e.radius_m = urban_radius_m(double(e.population) * (1 + options.growth), options);
  const std::vector<std::uint8_t> occupied = existing.empty() ? std::vector<std::uint8_t>() : growth.covered(existing);
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
    std::vector<std::uint8_t> covered = growth.covered(result.sites);
    for (std::size_t i = 0; i < occupied.size(); ++i) covered[i] |= occupied[i];
    std::vector<Site> merged = result.sites;
    const std::size_t before = merged.size();
    growth.grow(&covered, quota, table, merged, step);
    if (merged.size() == before) break;
    growth.sort_by_size(merged);
    result.sites = resolve_inclusions(merged, options.mode, distance, cols, rows);
  }
  if (options.quotas == SitesOptions::Quotas::rank_size) crowd_the_rest(growth, table, occupied, result);
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
        if (x.existing) {
          const float d = land.window(x.col, x.row, 1, 1).density[0];
          x.density = std::isfinite(d) ? d : 0.0;
        }
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
