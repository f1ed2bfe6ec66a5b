// Catchments of the settlements: the people of the land nearest to each centre (Voronoi over the density).
// SPDX-License-Identifier: MIT
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include "core/error.hpp"
#include "sites/sites.hpp"

namespace terrapolis::sites {

std::vector<double> catchment_people(const Land& land, const std::vector<Site>& sites, double total) {
  const int cols = land.cols(), rows = land.rows();
  std::vector<double> people(sites.size(), 0.0);
  if (sites.empty()) return people;
  const GridDistance distance(land.georef(), cols, rows);
  const CellMetrics& metrics = distance.metrics();
  // Sites by row: a cell's search runs outwards from its own row and stops once the
  // north-south distance alone exceeds the nearest centre found.
  std::vector<int> by_row(sites.size());
  std::iota(by_row.begin(), by_row.end(), 0);
  std::stable_sort(by_row.begin(), by_row.end(), [&](int a, int b) { return sites[std::size_t(a)].row < sites[std::size_t(b)].row; });
  double mass = 0;
  std::vector<int> owner;
  land.for_each_band([&](const LandView& band) {
    owner.assign(std::size_t(band.rows) * std::size_t(cols), -1);
    tbb::parallel_for(tbb::blocked_range<int>(band.row0, band.row0 + band.rows), [&](const tbb::blocked_range<int>& range) {
      for (int r = range.begin(); r < range.end(); ++r) {
        const auto first = std::lower_bound(by_row.begin(), by_row.end(), r, [&](int k, int row) { return sites[std::size_t(k)].row < row; });
        const std::ptrdiff_t start = first - by_row.begin();
        const double y = distance.northing(r);
        for (int c = 0; c < cols; ++c) {
          if (!band.habitable(c, r)) continue;
          double best = std::numeric_limits<double>::infinity();
          int nearest = -1;
          const auto consider = [&](std::ptrdiff_t k) {  // false once every further site in this direction is farther
            const Site& s = sites[std::size_t(by_row[std::size_t(k)])];
            if (std::abs(distance.northing(s.row) - y) > best) return false;
            const double d = distance(c, r, s.col, s.row);
            const int id = by_row[std::size_t(k)];
            if (d < best || (d == best && id < nearest)) best = d, nearest = id;
            return true;
          };
          for (std::ptrdiff_t k = start; k < std::ptrdiff_t(by_row.size()) && consider(k); ++k) {
          }
          for (std::ptrdiff_t k = start - 1; k >= 0 && consider(k); --k) {
          }
          owner[std::size_t(r - band.row0) * std::size_t(cols) + std::size_t(c)] = nearest;
        }
      }
    });
    // Sequential sums in cell order: the same figures whatever the threads and the bands.
    for (int r = band.row0; r < band.row0 + band.rows; ++r)
      for (int c = 0; c < cols; ++c) {
        const int o = owner[std::size_t(r - band.row0) * std::size_t(cols) + std::size_t(c)];
        if (o < 0) continue;
        const double w = double(band.density[band.at(c, r)]) * metrics.area_m2[std::size_t(r)];
        people[std::size_t(o)] += w;
        mass += w;
      }
  });
  if (mass > 0)
    for (double& p : people) p *= total / mass;
  return people;
}

PeopleOnLand::PeopleOnLand(const Georef& grid, int cols, int rows, double total)
    : area_m2_(cell_metrics(grid, cols, rows).area_m2), total_(total) {}

Raster<float> people_on_land(const Raster<float>& density, const Raster<std::uint8_t>& buildable, double total) {
  if (buildable.cols() != density.cols() || buildable.rows() != density.rows())
    throw bad_input("sites: the buildable mask and the density model are not on the same grid");
  PeopleOnLand people(density.georef(), density.cols(), density.rows(), total);
  people.add(density, buildable, 0);
  return people.people(density, buildable, 0);
}

}  // namespace terrapolis::sites
