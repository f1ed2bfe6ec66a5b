// Realism figures of a run against real places, and settlement warnings.
// SPDX-License-Identifier: MIT
#include "pipeline/realism.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <memory>
#include <limits>
#include <optional>
#include <random>

#include "core/error.hpp"
#include "core/geodesy.hpp"
#include "density/calibration.hpp"
#include "io/crs.hpp"
#include "io/mask_io.hpp"
#include "pipeline/by_tiles.hpp"
#include "pipeline/places.hpp"
#include "pipeline/stage_options.hpp"

namespace terrapolis::pipeline {
namespace {

using json = nlohmann::ordered_json;

double rounded(double v, double step) { return std::isfinite(v) ? std::round(v / step) * step : v; }

/// People per km² of land above which a region is denser than any real one: Manila, the densest
/// city of millions over its whole land (1.85 M people on 42.9 km², 43,000/km², PSA 2020 census);
/// Dhaka's city corporations and Macau (21,000/km²) are below it, New York City (11,000) far below.
constexpr double kPlausiblePeoplePerKm2 = 45000;

}  // namespace

std::vector<std::string> settlement_warnings(const RunState& s, const sites::SitesResult& r) {
  std::vector<std::string> warnings;
  // The 9 x 9 cells around each centre (NaN outside the grid): from the DEM, or its file by windows.
  std::optional<DemWindowReader> tiles;
  if (s.by_tiles) tiles.emplace(s.by_tiles->dem_path, s.by_tiles->read);
  const auto around = [&](int col, int row) {
    if (tiles) return tiles->read(col - 4, row - 4, 9, 9);
    Dem near(9, 9, s.dem.georef(), std::numeric_limits<float>::quiet_NaN());
    for (int r = 0; r < 9; ++r)
      for (int c = 0; c < 9; ++c)
        if (s.dem.inside(col - 4 + c, row - 4 + r)) near(c, r) = s.dem(col - 4 + c, row - 4 + r);
    return near;
  };
  int flat = 0, nodata = 0;
  std::string first_flat;
  for (const auto& site : r.sites) {
    const Dem near = around(site.col, site.row);
    const float z = near(4, 4);
    if (std::isnan(z)) {
      ++nodata;
      continue;
    }
    bool same = true;
    for (int dr = 0; dr < 9 && same; ++dr)
      for (int dc = 0; dc < 9 && same; ++dc) same = near(dc, dr) == z;  // false on NaN
    if (same && flat++ == 0) first_flat = "city " + std::to_string(site.id) + " at " + std::to_string(int(std::lround(z))) + " m";
  }
  if (flat)
    warnings.push_back(std::to_string(flat) + " settlement(s) on a perfectly flat surface (9 x 9 cells of one altitude, e.g. " + first_flat +
                       "): a lake or reservoir in SRTM-like DEMs; pass it as water (water.water_mask) or check");
  if (nodata) warnings.push_back(std::to_string(nodata) + " settlement(s) centred on a nodata cell");
  if (r.unplaced > 0)
    warnings.push_back(std::to_string(r.unplaced) + " settlement(s) of the law (" + std::to_string(r.unplaced_people) +
                       " people) found no candidate outside the others' discs: in no settlement (raise sites.candidates)");
  else if (r.unplaced_people > 0)  // the settled people the given places leave, fewer than one settlement holds
    warnings.push_back(std::to_string(r.unplaced_people) + " settled people beside the given places, too few for a settlement of "
                       "sites.min_population: in no settlement");
  if (r.land_area_km2 > 0 && r.target_population / r.land_area_km2 > kPlausiblePeoplePerKm2)
    warnings.push_back("population " + std::to_string(std::llround(r.target_population)) + " on " + std::to_string(std::llround(r.land_area_km2)) +
                       " km2 of land is " + std::to_string(std::llround(r.target_population / r.land_area_km2)) +
                       " people/km2, denser than Manila (43,000/km2, the densest real city; check sites.population)");
  return warnings;
}

namespace {

/// What the figures read of the grid: the places on land, the skill at them, and the land cells
/// for the random draws.
struct RealismGrid {
  std::vector<density::Place> places;
  int dropped = 0;
  density::Skill skill;
  std::uint64_t land_cells = 0;
  std::function<std::array<double, 2>(std::uint64_t k)> land_cell_centre;  ///< of the k-th land cell, row-major
};

/// On the whole grid: the terrain terms computed once more (switched on for the baselines and the land).
RealismGrid on_whole_grid(RunState& s, density::DensityOptions options, const std::string& reference, Progress& progress) {
  options.terrain_terms = true;
  const density::DensityResult terms = density::compute_density(s.dem, *s.hydrometry, options, progress);
  const std::vector<std::uint8_t> land = density::land_cells(terms);
  RealismGrid g;
  g.places = read_places(reference, s.dem, land, g.dropped);
  if (!g.places.empty()) g.skill = density::skill(*s.density, terms, g.places, land);
  auto cells = std::make_shared<std::vector<std::size_t>>();
  for (std::size_t i = 0; i < land.size(); ++i)
    if (land[i]) cells->push_back(i);
  g.land_cells = cells->size();
  g.land_cell_centre = [cells, georef = s.dem.georef(), cols = std::size_t(s.dem.cols())](std::uint64_t k) {
    const std::size_t i = (*cells)[std::size_t(k)];
    return georef.cell_centre(int(i % cols), int(i / cols));
  };
  return g;
}

/// By tiles: the density stage's tiles computed once more with the terms, each land cell's scores
/// counted (density::SkillCounter) and the land cells counted per row; a place's land and the k-th
/// land cell read back by windows.
RealismGrid by_tiles(RunState& s, density::DensityOptions options, const std::string& reference, Progress& progress) {
  const TiledInput& in = *s.by_tiles;
  const int cols = s.grid.cols, rows = s.grid.rows;
  const Georef georef = s.grid.georef;
  // Land: data, not water (the density's cell kinds), from the DEM and the inland water alone.
  auto dem = std::make_shared<const DemWindowReader>(in.dem_path, in.read);
  const LandWindow land_of = [dem, options, water = (s.folder / "inland_water.vrt").string()](int c0, int r0, int w, int h) {
    density::DensityOptions o = options;
    const Dem window = dem->read(c0, r0, w, h);
    o.water_mask = read_mask(water, window.georef(), w, h);
    return density::land_cells(window, o);
  };
  RealismGrid g;
  g.places = read_places(reference, georef, cols, rows, land_of, g.dropped);
  if (g.places.empty()) return g;  // no figure reads the land then
  density::SkillCounter counter;  // its tables before the limit is counted again
  s.by_tiles->reserve();
  options.terrain_terms = true;
  const RunDensityWindows windows(in.dem_path, in.read, s.folder.string(), s.scenario, options);
  const GridLocator locator(georef);
  constexpr float nan_f = std::numeric_limits<float>::quiet_NaN();
  std::vector<density::Scores> at(g.places.size(), density::Scores{nan_f, nan_f, nan_f, nan_f});
  auto below = std::make_shared<std::vector<std::uint64_t>>(std::size_t(rows) + 1, 0);  // land cells per row, then before each row
  const ScratchFolder scratch((s.folder / ".scratch").string());
  density::run_tiled_density(
      cols, rows, georef, windows.read(), windows.options(), in.tiles.tile_size, in.tiles.limit_mb(), scratch.path(),
      [&](int, int, const density::DensityResult& tile) {
        const GeoTransform& t = tile.density.georef().transform;
        const std::array<double, 2> corner = locator.crs_to_pixel(t[0], t[3]);  // the tile's first cell in the grid
        const int c0 = int(std::lround(corner[0])), r0 = int(std::lround(corner[1]));
        const Raster<float>& altitude = tile.term(density::TerrainTerm::altitude);  // NaN off land
        for (int y = 0; y < tile.density.rows(); ++y)
          for (int x = 0; x < tile.density.cols(); ++x)
            if (const std::size_t i = tile.density.index(x, y); !std::isnan(altitude[i]))
              counter.add_land(density::scores_at(tile.density, tile, i)), ++(*below)[std::size_t(r0 + y) + 1];
        for (std::size_t k = 0; k < g.places.size(); ++k)
          if (const auto& p = g.places[k]; tile.density.inside(p.col - c0, p.row - r0))
            at[k] = density::scores_at(tile.density, tile, tile.density.index(p.col - c0, p.row - r0));
      },
      progress, in.reserved_mb, density_file_bytes_per_cell(s.scenario));
  std::vector<double> populations;
  for (const auto& p : g.places) populations.push_back(p.population);
  g.skill = counter.skill(at, populations);
  for (int r = 0; r < rows; ++r) (*below)[std::size_t(r) + 1] += (*below)[std::size_t(r)];
  g.land_cells = below->back();
  g.land_cell_centre = [below, land_of, georef, cols](std::uint64_t k) {
    const int row = int(std::upper_bound(below->begin(), below->end(), k) - below->begin()) - 1;
    const std::vector<std::uint8_t> land = land_of(0, row, cols, 1);
    std::uint64_t seen = (*below)[std::size_t(row)];
    for (int c = 0; c < cols; ++c)
      if (land[std::size_t(c)] && seen++ == k) return georef.cell_centre(c, row);
    throw processing_error("realism: the land of row " + std::to_string(row) + " read back differs from its count");
  };
  return g;
}

}  // namespace

json realism_figures(RunState& s, density::DensityOptions options, const sites::SitesResult& r, const std::string& reference,
                     std::vector<std::string>& warnings, Progress& progress) {
  RealismGrid grid = s.by_tiles ? by_tiles(s, std::move(options), reference, progress) : on_whole_grid(s, std::move(options), reference, progress);
  const std::vector<density::Place>& places = grid.places;
  const int dropped = grid.dropped;
  const double min_population = s.scenario.resolved["sites"]["min_population"].get<double>();
  std::vector<double> real_sizes, generated_sizes;
  double real_total = 0, generated_total = 0;
  for (const auto& p : places)
    if (p.population >= min_population) real_sizes.push_back(p.population), real_total += p.population;
  for (const auto& site : r.sites)
    if (double(site.population) >= min_population) generated_sizes.push_back(double(site.population)), generated_total += double(site.population);
  std::sort(generated_sizes.begin(), generated_sizes.end(), std::greater<>());
  json out;
  out["reference"] = reference;
  out["places"] = places.size();
  out["places_dropped"] = dropped;
  out["count"] = {{"generated", generated_sizes.size()}, {"reference", real_sizes.size()},
                  {"ratio", real_sizes.empty() ? json(nullptr) : json(rounded(double(generated_sizes.size()) / double(real_sizes.size()), 1e-3))}};
  out["total"] = {{"generated", generated_total}, {"reference", real_total},
                  {"ratio", real_total > 0 ? json(rounded(generated_total / real_total, 1e-3)) : json(nullptr)}};
  out["largest"] = {{"generated", generated_sizes.empty() ? 0.0 : generated_sizes[0]}, {"reference", real_sizes.empty() ? 0.0 : real_sizes[0]}};
  const double q_gen = sites::rank_size_exponent(generated_sizes), q_ref = sites::rank_size_exponent(real_sizes);
  out["rank_size_exponent"] = {{"generated", std::isfinite(q_gen) ? json(rounded(q_gen, 1e-3)) : json(nullptr)},
                               {"reference", std::isfinite(q_ref) ? json(rounded(q_ref, 1e-3)) : json(nullptr)}};
  if (places.empty()) return out;

  const density::Skill& skill = grid.skill;
  json baselines = json::object();
  for (std::size_t k = 0; k < 3; ++k)
    baselines[density::kBaselineNames[k]] = {{"auc", rounded(skill.baseline_auc[k], 1e-3)}, {"weighted_auc", rounded(skill.baseline_weighted_auc[k], 1e-3)}};
  out["skill"] = {{"auc", rounded(skill.auc, 1e-3)}, {"weighted_auc", rounded(skill.weighted_auc, 1e-3)}, {"baselines", baselines}};
  if (skill.auc < skill.best_baseline()) {
    // Rounded as in the summary's figures (truncating would print 0.654 beside a summary's 0.655).
    char aucs[64];
    std::snprintf(aucs, sizeof aucs, "(AUC %.3f) than a single-factor baseline (AUC %.3f)", skill.auc, skill.best_baseline());
    warnings.push_back("the density model ranks the reference places worse " + std::string(aucs) + "; calibrate it (terrapolis calibrate)");
  }

  // Location: the ten largest real places against the ten largest generated settlements.
  const Crs& crs = s.grid.georef.crs;
  const std::size_t top = std::min<std::size_t>(10, places.size()), top_gen = std::min<std::size_t>(10, r.sites.size());
  std::vector<std::size_t> order(r.sites.size());
  for (std::size_t k = 0; k < order.size(); ++k) order[k] = k;
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return r.sites[a].population > r.sites[b].population; });
  auto nearest = [&](double x, double y, const std::vector<std::array<double, 2>>& points) {
    double best = INFINITY;
    for (const auto& p : points) best = std::min(best, crs_distance_m(crs, x, y, p[0], p[1]));
    return best;
  };
  std::vector<std::array<double, 2>> generated;
  for (std::size_t k = 0; k < top_gen; ++k) generated.push_back({r.sites[order[k]].x, r.sites[order[k]].y});
  json largest = json::array();
  int within = 0;
  for (std::size_t k = 0; k < top; ++k) {
    const double d = nearest(places[k].x, places[k].y, generated);
    within += d <= 10000;
    largest.push_back({{"name", places[k].name}, {"population", places[k].population},
                       {"nearest_top_km", std::isfinite(d) ? json(rounded(d / 1000, 0.01)) : json(nullptr)}});
  }
  // The same count for random land points in place of the generated settlements (seeded draws).
  std::mt19937_64 generator(s.scenario.resolved["seed"].get<std::uint64_t>());
  const int draws = 100;
  double random_within = 0;
  for (int d = 0; d < draws && top_gen > 0 && grid.land_cells > 0; ++d) {
    std::vector<std::array<double, 2>> points;
    for (std::size_t k = 0; k < top_gen; ++k) {
      points.push_back(grid.land_cell_centre(generator() % grid.land_cells));
    }
    for (std::size_t k = 0; k < top; ++k) random_within += nearest(places[k].x, places[k].y, points) <= 10000;
  }
  out["top10"] = {{"within_10km", within}, {"random_within_10km", rounded(random_within / draws, 0.01)}, {"places", largest}};
  return out;
}

}  // namespace terrapolis::pipeline
