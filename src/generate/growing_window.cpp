// Belhadj 2007 §2.1 (Alg. 1, "déplacement des milieux par fenêtrage croissant"): constraints dilated
// scale by scale, each new patch a small midpoint displacement. See growing_window.hpp.
// SPDX-License-Identifier: MIT
#include "generate/growing_window.hpp"

#include "generate/generators.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>

namespace terrapolis::generate {
namespace {

using terrain::CellState;

class Window {
 public:
  Window(terrain::SubdivisionGrid& grid, const terrain::MidpointParams& params)
      : g_(grid), p_(params), ref_(double(std::max(grid.cols, grid.rows) - 1)),
        noise_per_cell_(terrain::thesis_noise_per_cell_m(params.scale_m)) {}

  /// Alg. 1's first part at scale `pas`: reads the states as they were before the scale (T) and
  /// writes the new cells (T_c). The printed loop visits squares by rows then columns and a later
  /// square overwrites an earlier one's corner, so each cell takes the last square that reaches it:
  /// the one below-right of it first, then below-left, above-right, above-left.
  void extrapolate(int pas) {
    const std::vector<CellState> before = g_.state;
    const int nx = (g_.cols - 1) / pas, ny = (g_.rows - 1) / pas;
    tbb::parallel_for(tbb::blocked_range<int>(0, ny + 1), [&](const tbb::blocked_range<int>& r) {
      for (int b = r.begin(); b != r.end(); ++b)
        for (int a = 0; a <= nx; ++a) {
          const int x = a * pas, y = b * pas;
          const std::size_t i = at(x, y);
          if (before[i] != CellState::unknown) continue;
          for (const auto& [ox, oy] : {std::pair{0, 0}, {-pas, 0}, {0, -pas}, {-pas, -pas}}) {
            const int sx = x + ox, sy = y + oy;
            if (sx < 0 || sy < 0) continue;
            double sum = 0;
            int n = 0;
            for (const int cy : {sy, sy + pas})
              for (const int cx : {sx, sx + pas})
                if (cx < g_.cols && cy < g_.rows && before[at(cx, cy)] != CellState::unknown) {
                  sum += g_.z[at(cx, cy)];
                  ++n;
                }
            if (n == 0) continue;
            g_.z[i] = float(sum / n + pas * noise_per_cell_ * (terrain::position_noise(p_.seed, x, y) + p_.t));
            g_.state[i] = CellState::known;
            break;
          }
        }
    });
  }

  /// Alg. 1's second part: dm() on every pas-square whose four corners are known. Squares of one
  /// colour (column and row parity) share no cell, so each colour runs in parallel; two squares of
  /// different colours share an edge whose cells depend on that edge only (below), so the order of
  /// the colours does not change the result.
  void interpolate(int pas) {
    const int nx = (g_.cols - 1) / pas, ny = (g_.rows - 1) / pas;
    for (int colour = 0; colour < 4; ++colour)
      tbb::parallel_for(tbb::blocked_range<int>(0, ny), [&](const tbb::blocked_range<int>& r) {
        for (int b = r.begin(); b != r.end(); ++b) {
          if (b % 2 != colour / 2) continue;
          for (int a = colour % 2; a < nx; a += 2) {
            const int x = a * pas, y = b * pas;
            if (known(x, y) && known(x + pas, y) && known(x, y + pas) && known(x + pas, y + pas)) subdivide(x, y, pas);
          }
        }
      });
  }

  bool any_unknown() const {
    return std::find(g_.state.begin(), g_.state.end(), CellState::unknown) != g_.state.end();
  }

 private:
  std::size_t at(int x, int y) const { return std::size_t(y) * std::size_t(g_.cols) + std::size_t(x); }
  bool known(int x, int y) const { return g_.state[at(x, y)] != CellState::unknown; }
  double z(int x, int y) const { return g_.z[at(x, y)]; }

  /// Eq. 1.1 for a cell made by halving a square of side h: the level such a square has in the
  /// whole grid (the root, side ref, makes level 1), so a patch is as rough as DMMC at its scale.
  double displacement(int x, int y, int h) const {
    if (p_.scale_m == 0.0) return 0.0;
    return (terrain::position_noise(p_.seed, x, y) + p_.t) * p_.scale_m * std::pow(h / (2.0 * ref_), p_.dimension * p_.hurst);
  }

  void set(int x, int y, double mean, int h) {
    const std::size_t i = at(x, y);
    if (g_.state[i] != CellState::unknown) return;
    g_.z[i] = float(mean + displacement(x, y, h));
    g_.state[i] = CellState::known;
  }

  /// Midpoint displacement inside the square of corner (x0, y0) and side pas (the thesis's dm on a
  /// sub-rectangle, §2.1.1 (*)). Diamond-Square's edge midpoints on the square's own border use the
  /// two edge ends only: the square beside it would see other centres, and both must agree.
  void subdivide(int x0, int y0, int pas) {
    const bool diamond = p_.subdivision == terrain::Subdivision::diamond_square;
    for (int h = pas; h >= 2; h /= 2) {
      const int half = h / 2, n = pas / h;
      for (int b = 0; b < n; ++b)
        for (int a = 0; a < n; ++a) {
          const int x = x0 + a * h, y = y0 + b * h;
          set(x + half, y + half, (z(x, y) + z(x + h, y) + z(x, y + h) + z(x + h, y + h)) / 4, h);
        }
      for (int b = 0; b <= n; ++b)
        for (int a = 0; a < n; ++a) {
          const int x = x0 + a * h + half, y = y0 + b * h;  // horizontal edge midpoint
          const bool inner = diamond && b > 0 && b < n;
          set(x, y, inner ? (z(x - half, y) + z(x + half, y) + z(x, y - half) + z(x, y + half)) / 4
                          : (z(x - half, y) + z(x + half, y)) / 2, h);
        }
      for (int b = 0; b < n; ++b)
        for (int a = 0; a <= n; ++a) {
          const int x = x0 + a * h, y = y0 + b * h + half;  // vertical edge midpoint
          const bool inner = diamond && a > 0 && a < n;
          set(x, y, inner ? (z(x - half, y) + z(x + half, y) + z(x, y - half) + z(x, y + half)) / 4
                          : (z(x, y - half) + z(x, y + half)) / 2, h);
        }
    }
  }

  terrain::SubdivisionGrid& g_;
  const terrain::MidpointParams& p_;
  double ref_, noise_per_cell_;
};

}  // namespace

void growing_window(Raster<float>& raster, const terrain::MidpointParams& params) {
  terrain::SubdivisionGrid grid = terrain::SubdivisionGrid::from_raster(raster);
  const int side = std::min(grid.cols, grid.rows) - 1;
  Window window(grid, params);
  for (int pas = 1; pas >= 1 && pas <= side; pas *= 2) {
    window.extrapolate(pas);
    if (pas > 1) window.interpolate(pas);
  }
  if (window.any_unknown()) {
    terrain::MidpointParams rest = params;
    rest.shape = 0.0;
    terrain::midpoint_displacement(grid, rest);
  }
  raster.values() = std::move(grid.z);
}

GeneratedTerrain generate_window(const GenerateRequest& request) {
  GeneratedTerrain out;
  out.dem = request.grid;
  const auto t0 = std::chrono::steady_clock::now();
  growing_window(out.dem, request.dmmc.top_down);
  out.timings.emplace_back("growing window", std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  return out;
}

}  // namespace terrapolis::generate
