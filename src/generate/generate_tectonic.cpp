// Tectonic relief after the procedural-tectonics report (seeds/004): plates as Voronoi cells of
// mountain points moving from their centroid towards their mountain, merged when they move alike;
// folds from an fBm distorted by the plates' motion and damped with the distance to the plate
// boundaries; a river base map grown from the oceans along the rivers; the two blended by the
// distance to the nearest river ("à proximité des rivières et océans, la carte de rivière est prise
// en compte fortement. Puis plus on s'éloigne, plus la carte de plis joue un rôle").
// SPDX-License-Identifier: MIT
#include <algorithm>
#include <chrono>
#include <cmath>
#include <numeric>
#include <queue>

#include "core/neighbours.hpp"
#include "generate/distance_field.hpp"
#include "generate/generators.hpp"
#include "core/random.hpp"

namespace terrapolis::generate {
namespace {

using Vec = std::array<double, 2>;

/// Value noise on the integer lattice (smoothstep-interpolated), summed over octaves: fBm in [-1,1].
double fbm(std::uint64_t seed, double x, double y, int octaves, double hurst = 0.7) {
  double sum = 0, norm = 0, amplitude = 1;
  for (int o = 0; o < octaves; ++o) {
    const double fx = std::floor(x), fy = std::floor(y);
    const int ix = int(fx), iy = int(fy);
    auto s = [](double t) { return t * t * (3 - 2 * t); };
    const double tx = s(x - fx), ty = s(y - fy);
    const std::uint64_t so = seed + 0x9e37u * std::uint64_t(o);
    const double v00 = terrain::position_noise(so, ix, iy), v10 = terrain::position_noise(so, ix + 1, iy);
    const double v01 = terrain::position_noise(so, ix, iy + 1), v11 = terrain::position_noise(so, ix + 1, iy + 1);
    sum += amplitude * ((v00 * (1 - tx) + v10 * tx) * (1 - ty) + (v01 * (1 - tx) + v11 * tx) * ty);
    norm += amplitude;
    amplitude *= std::pow(2.0, -hurst);
    x *= 2, y *= 2;
  }
  return sum / norm;
}

struct Plates {
  std::vector<int> of;     ///< plate of each cell
  std::vector<Vec> velocity;  ///< cells per unit time, by plate
};

/// Voronoi cells of the mountains, each moving from its centroid to its mountain, merged with a
/// neighbour while their normalised velocities agree (dot > `agree`), velocities area-weighted.
Plates make_plates(const std::vector<GridPoint>& mountains, int cols, int rows, double agree) {
  const std::size_t n = std::size_t(cols) * rows, m = mountains.size();
  Plates p;
  p.of.assign(n, 0);
  std::vector<double> area(m, 0);
  std::vector<Vec> centroid(m, Vec{0, 0});
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) {
      std::size_t best = 0;
      double bd = 1e300;
      for (std::size_t k = 0; k < m; ++k) {
        const double d = std::pow(c - mountains[k][0], 2) + std::pow(r - mountains[k][1], 2);
        if (d < bd) bd = d, best = k;
      }
      p.of[std::size_t(r) * std::size_t(cols) + std::size_t(c)] = int(best);
      area[best] += 1, centroid[best][0] += c, centroid[best][1] += r;
    }
  std::vector<Vec> v(m, Vec{0, 0});
  for (std::size_t k = 0; k < m; ++k)
    if (area[k] > 0) v[k] = {mountains[k][0] - centroid[k][0] / area[k], mountains[k][1] - centroid[k][1] / area[k]};
  // Fusion, in a fixed order (the boundary pairs by index): union-find with area-weighted velocities.
  std::vector<int> parent(m);
  std::iota(parent.begin(), parent.end(), 0);
  auto find = [&](int k) {
    while (parent[std::size_t(k)] != k) k = parent[std::size_t(k)] = parent[std::size_t(parent[std::size_t(k)])];
    return k;
  };
  std::vector<std::pair<int, int>> pairs;
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) {
      const int a = p.of[std::size_t(r) * std::size_t(cols) + std::size_t(c)];
      if (c + 1 < cols) pairs.push_back(std::minmax(a, p.of[std::size_t(r) * std::size_t(cols) + std::size_t(c + 1)]));
      if (r + 1 < rows) pairs.push_back(std::minmax(a, p.of[std::size_t(r + 1) * std::size_t(cols) + std::size_t(c)]));
    }
  std::sort(pairs.begin(), pairs.end());
  pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
  for (bool merged = true; merged;) {
    merged = false;
    for (const auto& [a0, b0] : pairs) {
      const int a = find(a0), b = find(b0);
      if (a == b) continue;
      const double na = std::hypot(v[std::size_t(a)][0], v[std::size_t(a)][1]), nb = std::hypot(v[std::size_t(b)][0], v[std::size_t(b)][1]);
      if (na == 0 || nb == 0) continue;
      const double dot = (v[std::size_t(a)][0] * v[std::size_t(b)][0] + v[std::size_t(a)][1] * v[std::size_t(b)][1]) / (na * nb);
      if (dot <= agree) continue;
      const double s = area[std::size_t(a)] + area[std::size_t(b)];
      for (int d = 0; d < 2; ++d)
        v[std::size_t(a)][std::size_t(d)] = (area[std::size_t(a)] * v[std::size_t(a)][std::size_t(d)] + area[std::size_t(b)] * v[std::size_t(b)][std::size_t(d)]) / s;
      area[std::size_t(a)] = s;
      parent[std::size_t(b)] = a;
      merged = true;
    }
  }
  for (auto& o : p.of) o = find(o);
  p.velocity = v;
  return p;
}

/// Random mountain chains: a few lines of points, as a user would sketch them.
std::vector<GridPoint> random_mountains(int cols, int rows, Rng& rng) {
  const double size = std::min(cols, rows);
  std::vector<GridPoint> mountains;
  const int chains = std::max(2, int(std::lround(double(cols) * rows / 40000.0)));
  for (int k = 0; k < chains; ++k) {
    const double x = (0.15 + 0.7 * rng.uniform()) * cols, y = (0.15 + 0.7 * rng.uniform()) * rows;
    const double t = rng.uniform() * 3.14159265358979;
    for (int j = -2; j <= 2; ++j)
      mountains.push_back({x + j * size / 12 * std::cos(t) + rng.symmetric() * size / 40, y + j * size / 12 * std::sin(t) + rng.symmetric() * size / 40});
  }
  return mountains;
}

/// Folds: an fBm stretched across each plate's motion (ridges perpendicular to the shortening)
/// and distorted by the velocity field, damped with the distance to a boundary; convergent
/// boundaries fold fully, divergent ones a quarter (the report's suggested map of boundary types).
std::vector<double> plate_folds(const Plates& plates, int cols, int rows, std::uint64_t seed) {
  const std::size_t n = std::size_t(cols) * rows;
  const double size = std::min(cols, rows);
  // Plate boundaries and how much they converge: (v_a - v_b) . o > 0 when plate a moves towards b.
  std::vector<char> boundary(n, 0);
  std::vector<double> convergence(n, 0);
  double vmax = 1e-9;
  for (const auto& v : plates.velocity) vmax = std::max(vmax, std::hypot(v[0], v[1]));
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) {
      const std::size_t i = std::size_t(r) * std::size_t(cols) + std::size_t(c);
      for (int k = 0; k < 8; k += 2) {
        const int nc = c + dcol[std::size_t(k)], nr = r + drow[std::size_t(k)];
        if (nc < 0 || nr < 0 || nc >= cols || nr >= rows) continue;
        const int a = plates.of[i], b = plates.of[std::size_t(nr) * std::size_t(cols) + std::size_t(nc)];
        if (a == b) continue;
        boundary[i] = 1;
        const Vec& va = plates.velocity[std::size_t(a)];
        const Vec& vb = plates.velocity[std::size_t(b)];
        convergence[i] = std::max(convergence[i], ((va[0] - vb[0]) * dcol[std::size_t(k)] + (va[1] - vb[1]) * drow[std::size_t(k)]) / (2 * vmax));
      }
    }
  std::vector<double> to_boundary;
  std::vector<std::size_t> nearest_boundary;
  if (std::find(boundary.begin(), boundary.end(), 1) == boundary.end()) boundary[0] = 1;  // one plate: damp from a corner
  distance_to(boundary, cols, rows, to_boundary, nearest_boundary);

  const double wavelength = size / 10, damping = size / 6;
  std::vector<double> folds(n);
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) {
      const std::size_t i = std::size_t(r) * std::size_t(cols) + std::size_t(c);
      const Vec& v = plates.velocity[std::size_t(plates.of[i])];
      const double norm = std::hypot(v[0], v[1]);
      const Vec u = norm > 0 ? Vec{v[0] / norm, v[1] / norm} : Vec{1, 0};
      const double warp = 0.5 * fbm(seed ^ 0x51u, c / wavelength, r / wavelength, 3);
      const double x = c + warp * v[0], y = r + warp * v[1];
      const double along = (x * u[0] + y * u[1]) / wavelength, across = (-x * u[1] + y * u[0]) / (4 * wavelength);
      const double fold = 0.5 + 0.5 * fbm(seed, along, across, 5);
      const double kind = 0.25 + 0.75 * std::clamp(convergence[nearest_boundary[i]], 0.0, 1.0);
      folds[i] = fold * kind * std::exp(-std::pow(to_boundary[i] / damping, 2));
    }
  return folds;
}

/// The drainage tree: each cell's receiver (n for the ocean) and the cells in growth order.
struct DrainageTree {
  std::vector<std::size_t> receiver, order;
};

/// The river base map's tree, grown from the ocean (the grid border): invasion percolation
/// (Stark 1991, Nature 352), the front always taking the land cell of least resistance, so the
/// network grows headwards; low folds resist least, so rivers take the fold valleys.
DrainageTree drainage_tree(const std::vector<double>& folds, int cols, int rows, std::uint64_t seed) {
  const std::size_t n = std::size_t(cols) * rows;
  DrainageTree tree{std::vector<std::size_t>(n, n), {}};
  std::vector<double> cost(n, 1e300);
  tree.order.reserve(n);
  using Item = std::pair<double, std::size_t>;
  std::priority_queue<Item, std::vector<Item>, std::greater<>> queue;
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c)
      if (r == 0 || c == 0 || r == rows - 1 || c == cols - 1) {
        const std::size_t i = std::size_t(r) * std::size_t(cols) + std::size_t(c);
        cost[i] = 0, queue.push({0.0, i});
      }
  std::vector<char> done(n, 0);
  while (!queue.empty()) {
    const std::size_t i = queue.top().second;
    queue.pop();
    if (done[i]) continue;
    done[i] = 1;
    tree.order.push_back(i);
    const int c = int(i % std::size_t(cols)), r = int(i / std::size_t(cols));
    for (int k = 0; k < 8; ++k) {
      const int nc = c + dcol[std::size_t(k)], nr = r + drow[std::size_t(k)];
      if (nc < 0 || nr < 0 || nc >= cols || nr >= rows) continue;
      const std::size_t j = std::size_t(nr) * std::size_t(cols) + std::size_t(nc);
      if (done[j]) continue;
      // Folds steer the growth: rivers grow more easily where the folds are low (the valleys).
      const double resistance = terrain::position_noise(seed ^ 0xa5u, nc, nr) + 1 + 3 * folds[j];
      if (resistance < cost[j]) cost[j] = resistance, tree.receiver[j] = i, queue.push({resistance, j});
    }
  }
  return tree;
}

/// The skeleton: river paths from every source down the tree to the ocean or a confluence.
std::vector<RiverPath> tree_rivers(const DrainageTree& tree, const std::vector<char>& river, int cols) {
  const std::size_t n = river.size();
  const auto& receiver = tree.receiver;
  std::vector<int> path_of(n, -1);
  std::vector<std::size_t> index_in(n, 0);
  std::vector<char> has_upstream(n, 0);
  for (std::size_t i = 0; i < n; ++i)
    if (river[i] && receiver[i] < n && river[receiver[i]]) has_upstream[receiver[i]] = 1;
  std::vector<RiverPath> paths;
  for (std::size_t k = tree.order.size(); k-- > 0;) {  // sources in a fixed order: upstream first
    const std::size_t s = tree.order[k];
    if (!river[s] || has_upstream[s]) continue;
    RiverPath p;
    const int id = int(paths.size());
    std::size_t i = s;
    for (; i < n && river[i] && path_of[i] < 0; i = receiver[i]) {
      path_of[i] = id, index_in[i] = p.line.size();
      p.line.push_back({double(i % std::size_t(cols)), double(i / std::size_t(cols))});
    }
    if (i < n) {
      p.line.push_back({double(i % std::size_t(cols)), double(i / std::size_t(cols))});
      if (path_of[i] >= 0) p.into = path_of[i], p.at = index_in[i];
    }
    if (p.line.size() >= 2) paths.push_back(std::move(p));
  }
  return paths;
}

}  // namespace

GeneratedTerrain generate_tectonic(const GenerateRequest& request) {
  const auto t0 = std::chrono::steady_clock::now();
  const int cols = request.grid.cols(), rows = request.grid.rows();
  const std::size_t n = std::size_t(cols) * rows;
  const double size = std::min(cols, rows);
  Rng rng(request.seed);

  const std::vector<GridPoint> mountains = request.points.empty() ? random_mountains(cols, rows, rng) : request.points;
  const Plates plates = make_plates(mountains, cols, rows, 0.9);
  const std::vector<double> folds = plate_folds(plates, cols, rows, request.seed);

  // River base map along a random drainage tree; heights then rise from the ocean along the tree
  // with Flint's slope-area law S = k A^-0.5 (Flint 1974), the concave long profiles of real rivers.
  const DrainageTree tree = drainage_tree(folds, cols, rows, request.seed);
  const auto& receiver = tree.receiver;
  std::vector<double> area(n, 1.0);
  for (std::size_t k = tree.order.size(); k-- > 0;)
    if (receiver[tree.order[k]] < n) area[receiver[tree.order[k]]] += area[tree.order[k]];
  const double cell_km2 = request.cell_m * request.cell_m / 1e6;
  const double channel_cells = std::max(8.0, 0.1 / cell_km2);  // channels from 0.1 km² upstream
  std::vector<double> base(n, 0.0);
  const double k_s = 0.5 * request.relief_m / (size * request.cell_m) * std::sqrt(channel_cells);
  for (std::size_t i : tree.order) {
    if (receiver[i] >= n) continue;
    const std::size_t j = receiver[i];
    const int dc = int(i % std::size_t(cols)) - int(j % std::size_t(cols)), dr = int(i / std::size_t(cols)) - int(j / std::size_t(cols));
    const double d = std::hypot(dc, dr) * request.cell_m;
    base[i] = base[j] + d * std::min(0.5, k_s / std::sqrt(area[i]));
  }

  // The rivers: tree cells draining at least the channel area.
  std::vector<char> river(n, 0);
  for (std::size_t i = 0; i < n; ++i) river[i] = area[i] >= channel_cells && receiver[i] < n ? 1 : 0;
  std::vector<double> to_river;
  std::vector<std::size_t> nearest_river;
  std::vector<char> water = river;
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c)
      if (r == 0 || c == 0 || r == rows - 1 || c == cols - 1) water[std::size_t(r) * std::size_t(cols) + std::size_t(c)] = 1;
  distance_to(water, cols, rows, to_river, nearest_river);

  // The blend: near rivers and the ocean the base map, away from them base + folds.
  GeneratedTerrain out;
  out.dem = request.grid;
  const double blend = size / 30;
  for (std::size_t i = 0; i < n; ++i) {
    const double w = 1 - std::exp(-std::pow(to_river[i] / blend, 2));
    out.dem[i] = float(base[i] + w * request.relief_m * folds[i]);
  }

  std::vector<RiverPath> paths = tree_rivers(tree, river, cols);
  // Wider downstream: log2 of the upstream cells over the channel area, as the flow method does.
  for (auto& p : paths)
    for (const auto& q : p.line)
      p.width_m.push_back(std::max(1.0, std::log2(area[std::size_t(q[1]) * std::size_t(cols) + std::size_t(q[0])] / channel_cells)) * request.cell_m);
  out.plan.rivers = reaches_from_paths(paths);
  out.channel_head_m2 = channel_cells * request.cell_m * request.cell_m;
  out.timings.emplace_back("tectonic", std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  return out;
}

}  // namespace terrapolis::generate
