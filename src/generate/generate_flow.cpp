// Belhadj's flow method (thesis 2007, §2.2): ridges by Brownian particle pairs (§2.2.1.1, Alg. 2,
// eq. 2.1), drainage basins filled around each ridge segment (§2.2.1.2, Alg. 3, eq. 2.2-2.3), rivers
// by kinematic particles (§2.2.2, Alg. 4-9), then DMMC constrained by the skeleton (§2.2.3, Alg. 11).
// SPDX-License-Identifier: MIT
#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <numbers>

#include "core/neighbours.hpp"
#include "generate/distance_field.hpp"
#include "generate/generators.hpp"
#include "core/random.hpp"

namespace terrapolis::generate {
namespace {

constexpr double kPi = std::numbers::pi;
using Cell = std::array<int, 2>;

/// The thesis's cell record (§2.2.1.1, footnote 4): altitude, state and the id of the ridge or river.
struct Field {
  int cols = 0, rows = 0;
  std::vector<float> a;          ///< basin-model altitude, metres
  std::vector<int> ridge, river; ///< ridge pair id / river particle id, -1 none
  std::size_t at(int c, int r) const { return std::size_t(r) * std::size_t(cols) + std::size_t(c); }
  bool inside(int c, int r) const { return c >= 0 && r >= 0 && c < cols && r < rows; }
};

/// Cells of the discrete line from a to b (Bresenham), a included; `visit` returns false to stop.
/// Returns false when stopped.
bool discrete_line(Cell a, Cell b, const std::function<bool(Cell, Cell)>& visit) {
  const int dx = std::abs(b[0] - a[0]), dy = -std::abs(b[1] - a[1]);
  const int sx = a[0] < b[0] ? 1 : -1, sy = a[1] < b[1] ? 1 : -1;
  int err = dx + dy;
  Cell prev = a;
  for (Cell p = a;;) {
    if (!visit(p, prev)) return false;
    if (p == b) return true;
    prev = p;
    const int e2 = 2 * err;
    if (e2 >= dy) err += dy, p[0] += sx;
    if (e2 <= dx) err += dx, p[1] += sy;
  }
}

/// The cell holding (x, y). A particle thrown far off the grid (a large velocity) is clamped to
/// 2^24 cells away: it leaves the grid at the first cell outside anyway, and converting a double
/// beyond int's range (or NaN) to int is undefined.
Cell floor_cell(double x, double y) {
  static constexpr double kFar = 1 << 24;
  const auto cell = [](double v) { return int(std::floor(std::isnan(v) ? -kFar : std::clamp(v, -kFar, kFar))); };
  return {cell(x), cell(y)};
}

// ---- Ridges and basins (§2.2.1) -------------------------------------------------------------

struct RidgeParams {
  double speed = 10;                  ///< V, cells per step (the thesis's multi-ridge model: 10)
  double turn_local = kPi / 10;       ///< δΘ_l
  double turn_global = kPi / 4;       ///< δΘ_g: "une petite variation d'orientation" for many ridges (fig. 2.8 bottom)
  double sigma1 = 30, sigma2 = 90;    ///< cells: slope width (4 σ1) and crest decay (eq. 2.2-2.3)
};

/// Alg. 3: the slopes of segment p0 -> p1 (orientations t0, t1, crest height z at p0).
void fill_slopes(Field& f, std::array<double, 2> p0, double t0, std::array<double, 2> p1, double t1, double z,
                 const RidgeParams& rp) {
  const double w = 4 * rp.sigma1;
  using P = std::array<double, 2>;
  auto side = [&](P p, double t, double s) { return P{p[0] + w * std::cos(t + s * kPi / 2), p[1] + w * std::sin(t + s * kPi / 2)}; };
  const P A = side(p0, t0, 1), D = side(p0, t0, -1), B = side(p1, t1, 1), C = side(p1, t1, -1);
  auto cross = [](P o, P a, P b) { return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]); };
  std::vector<std::array<P, 3>> triangles;
  // AD and BC intersect when the particle turned sharply: keep only the outer triangle.
  const double d1 = cross(A, D, B), d2 = cross(A, D, C), d3 = cross(B, C, A), d4 = cross(B, C, D);
  if (d1 * d2 < 0 && d3 * d4 < 0) {
    const double s = d1 / (d1 - d2);
    const P I{B[0] + s * (C[0] - B[0]), B[1] + s * (C[1] - B[1])};
    const bool i_opposite_ab = cross(p0, p1, I) * cross(p0, p1, A) < 0;
    if (i_opposite_ab) triangles.push_back({A, I, B});
    else triangles.push_back({I, D, C});
  } else {
    triangles.push_back({A, D, B});
    triangles.push_back({B, D, C});
  }
  const double ux = p1[0] - p0[0], uy = p1[1] - p0[1], len = std::hypot(ux, uy);
  if (len <= 0) return;
  for (const auto& t : triangles) {
    const int c0 = std::max(0, int(std::floor(std::min({t[0][0], t[1][0], t[2][0]})))),
              c1 = std::min(f.cols - 1, int(std::ceil(std::max({t[0][0], t[1][0], t[2][0]}))));
    const int r0 = std::max(0, int(std::floor(std::min({t[0][1], t[1][1], t[2][1]})))),
              r1 = std::min(f.rows - 1, int(std::ceil(std::max({t[0][1], t[1][1], t[2][1]}))));
    const double area = cross(t[0], t[1], t[2]);
    if (area == 0) continue;
    for (int r = r0; r <= r1; ++r)
      for (int c = c0; c <= c1; ++c) {
        const P m{c + 0.5, r + 0.5};
        const double b0 = cross(t[1], t[2], m) / area, b1 = cross(t[2], t[0], m) / area, b2 = cross(t[0], t[1], m) / area;
        if (b0 < 0 || b1 < 0 || b2 < 0) continue;
        const double along = ((m[0] - p0[0]) * ux + (m[1] - p0[1]) * uy) / len;        // |M'P|
        const double across = std::abs((m[0] - p0[0]) * uy - (m[1] - p0[1]) * ux) / len;  // |MM'|
        const double h = z * std::exp(-std::pow(across / rp.sigma1, 2)) * std::exp(-std::pow(along / rp.sigma2, 2));
        float& a = f.a[f.at(c, r)];
        a = std::max(a, float(h));
      }
  }
}

struct RidgeWalker {
  double x, y, theta, theta0, z;
  int id;
  RidgeLine line;
};

/// Alg. 2 with `pairs` random pairs (eq. 2.1): each pair starts on one cell, opposite orientations.
std::vector<RidgeLine> random_ridges(Field& f, int pairs, double relief_m, const RidgeParams& rp, Rng& rng) {
  std::vector<RidgeWalker> walkers;
  for (int k = 0; k < pairs; ++k) {
    Cell start{};
    for (int tries = 0; tries < 100; ++tries) {  // (x, y) not already a ridge cell
      // eq. 2.1 draws the start anywhere; we keep it off the outer tenth so both slopes fit in.
      start = {int((0.1 + 0.8 * rng.uniform()) * f.cols), int((0.1 + 0.8 * rng.uniform()) * f.rows)};
      if (f.ridge[f.at(start[0], start[1])] < 0) break;
    }
    const double theta = rng.uniform() * kPi;
    const double z = relief_m * (0.6 + 0.4 * rng.uniform());  // eq. 2.1 draws Z in [0, dim(a)]; crests below 60 % would vanish in the noise
    f.ridge[f.at(start[0], start[1])] = k;
    for (int s = 0; s < 2; ++s)
      walkers.push_back({start[0] + 0.5, start[1] + 0.5, theta + s * kPi, theta + s * kPi, z, k, {{{double(start[0]), double(start[1])}}, {float(z)}}});
  }
  std::vector<bool> alive(walkers.size(), true);
  const int max_steps = 4 * (f.cols + f.rows);
  for (int t = 0; t < max_steps; ++t) {
    bool any = false;
    for (std::size_t i = 0; i < walkers.size(); ++i) {
      if (!alive[i]) continue;
      any = true;
      RidgeWalker& p = walkers[i];
      const Cell from = floor_cell(p.x, p.y);
      const double nx = p.x + rp.speed * std::cos(p.theta), ny = p.y + rp.speed * std::sin(p.theta);
      double turn = 0;
      for (int tries = 0; tries < 64; ++tries) {  // the "répéter ... jusqu'à" of Alg. 2
        turn = rng.symmetric() * rp.turn_local;
        if (std::abs(p.theta + turn - p.theta0) <= rp.turn_global) break;
        turn = 0;
      }
      const double theta1 = p.theta + turn;
      const Cell to = floor_cell(nx, ny);
      bool blocked = false;
      discrete_line(from, to, [&](Cell q, Cell prev) {
        if (!f.inside(q[0], q[1])) return !(blocked = true);
        auto other = [&](int c, int r) { return f.inside(c, r) && f.ridge[f.at(c, r)] >= 0 && f.ridge[f.at(c, r)] != p.id; };
        const bool diagonal = q[0] != prev[0] && q[1] != prev[1];
        if (other(q[0], q[1]) || (diagonal && other(q[0], prev[1]) && other(prev[0], q[1]))) return !(blocked = true);
        f.ridge[f.at(q[0], q[1])] = p.id;
        return true;
      });
      if (blocked) {
        alive[i] = false;
        continue;
      }
      fill_slopes(f, {p.x, p.y}, p.theta, {nx, ny}, theta1, p.z, rp);
      p.z *= std::exp(-std::pow(rp.speed / rp.sigma2, 2));  // eq. 2.3
      p.x = nx, p.y = ny, p.theta = theta1;
      p.line.line.push_back({nx - 0.5, ny - 0.5});
      p.line.z_m.push_back(float(p.z));
    }
    if (!any) break;
  }
  // A pair's two walkers make one ridge line: the second reversed, then the first.
  std::vector<RidgeLine> ridges;
  for (std::size_t i = 0; i + 1 < walkers.size(); i += 2) {
    RidgeLine r;
    const auto& b = walkers[i + 1].line;
    for (std::size_t k = b.line.size(); k-- > 1;) r.line.push_back(b.line[k]), r.z_m.push_back(b.z_m[k]);
    r.line.insert(r.line.end(), walkers[i].line.line.begin(), walkers[i].line.line.end());
    r.z_m.insert(r.z_m.end(), walkers[i].line.z_m.begin(), walkers[i].line.z_m.end());
    if (r.line.size() >= 2) ridges.push_back(std::move(r));
  }
  return ridges;
}

/// Ridges the user drew: crests at `relief_m` (the thesis's constant-altitude model, fig. 2.8 top),
/// slopes by Alg. 3 on each segment.
std::vector<RidgeLine> given_ridges(Field& f, const std::vector<std::vector<GridPoint>>& lines, double relief_m, const RidgeParams& rp) {
  std::vector<RidgeLine> ridges;
  for (std::size_t k = 0; k < lines.size(); ++k) {
    const auto& l = lines[k];
    RidgeLine r;
    for (std::size_t i = 0; i + 1 < l.size(); ++i) {
      const std::array<double, 2> p0{l[i][0] + 0.5, l[i][1] + 0.5}, p1{l[i + 1][0] + 0.5, l[i + 1][1] + 0.5};
      const double t = std::atan2(p1[1] - p0[1], p1[0] - p0[0]);
      fill_slopes(f, p0, t, p1, t, relief_m, RidgeParams{rp.speed, rp.turn_local, rp.turn_global, rp.sigma1, 1e12});
      discrete_line(floor_cell(p0[0], p0[1]), floor_cell(p1[0], p1[1]), [&](Cell q, Cell) {
        if (f.inside(q[0], q[1])) f.ridge[f.at(q[0], q[1])] = int(k);
        return true;
      });
    }
    r.line = l;
    r.z_m.assign(l.size(), float(relief_m));
    ridges.push_back(std::move(r));
  }
  return ridges;
}

// ---- Rivers (§2.2.2) ------------------------------------------------------------------------

struct RiverParams {
  double dt = 0.5;
  double gravity = 10;     ///< G of Alg. 4, cells per step² at a slope of 45°
  double r_max = 10;       ///< "une dizaine d'unités-terrain" (§2.2.2.1)
  int max_loops = 30;      ///< B_MAX: "une trentaine de boucles par particule" for a million cells
};

struct Particle {
  double x = 0, y = 0, vx = 0, vy = 0;
  bool stop = false, valid = false;
  int loops = 0, moves = 0;
  double mass = 1;
  int into = -1;          ///< Confluent: the river it joined, -1 none
  std::size_t at = 0;     ///< ... at this index of that river's cells
  std::vector<Cell> cells;
  std::vector<std::pair<std::size_t, int>> tributaries;  ///< (index in cells, particle)
};

class RiverSystem {
 public:
  RiverSystem(Field& f, double cell_m, const RiverParams& p, Rng& rng) : f_(f), cell_m_(cell_m), p_(p), rng_(rng) {}

  void add(Cell c) {
    if (!f_.inside(c[0], c[1]) || f_.river[f_.at(c[0], c[1])] >= 0 || f_.ridge[f_.at(c[0], c[1])] >= 0) return;
    Particle m;
    m.x = c[0] + 0.5, m.y = c[1] + 0.5;
    m.cells.push_back(c);
    f_.river[f_.at(c[0], c[1])] = int(ps_.size());
    ps_.push_back(std::move(m));
  }

  /// Alg. 9: moves every particle until all are stopped, then validates (Alg. 8).
  void run() {
    const int max_moves = int(8 * (f_.cols + f_.rows) / p_.dt);
    for (bool moving = true; moving;) {
      moving = false;
      for (int i = 0; i < int(ps_.size()); ++i) {
        Particle& m = ps_[std::size_t(i)];
        if (m.stop) continue;
        moving = true;
        if (++m.moves > max_moves) { m.stop = true; continue; }
        const int j = move(i);
        if (j >= 0) confluence(i, j);
      }
    }
    std::vector<int> state(ps_.size(), 0);  // 0 unknown, 1 in progress, 2 valid, 3 invalid
    std::function<bool(int)> valid = [&](int i) {  // Alg. 8
      int& s = state[std::size_t(i)];
      if (s >= 2) return s == 2;
      if (s == 1) return false;  // a cycle of confluences drains nowhere
      s = 1;
      const Particle& m = ps_[std::size_t(i)];
      const bool v = m.valid || (m.into >= 0 && valid(m.into));
      s = v ? 2 : 3;
      return v;
    };
    for (int i = 0; i < int(ps_.size()); ++i) valid(i);
    valid_ = state;
  }

  /// The valid rivers as paths (a tributary's last point is its confluence on the receiving river).
  std::vector<RiverPath> paths() const {
    std::vector<int> index(ps_.size(), -1);
    std::vector<RiverPath> out;
    for (std::size_t i = 0; i < ps_.size(); ++i)
      if (valid_[i] == 2 && ps_[i].cells.size() + (ps_[i].into >= 0 ? 1 : 0) >= 2) index[i] = int(out.size()), out.emplace_back();
    for (std::size_t i = 0; i < ps_.size(); ++i) {
      if (index[i] < 0) continue;
      const Particle& m = ps_[i];
      RiverPath& p = out[std::size_t(index[i])];
      for (const Cell& c : m.cells) p.line.push_back({double(c[0]), double(c[1])});
      if (m.into >= 0 && index[std::size_t(m.into)] >= 0) {
        const Cell& c = ps_[std::size_t(m.into)].cells[m.at];
        p.line.push_back({double(c[0]), double(c[1])});
        p.into = index[std::size_t(m.into)];
        p.at = m.at;
      }
    }
    return out;
  }

 private:
  double z(int c, int r) const { return f_.a[f_.at(c, r)]; }

  /// Alg. 4: on each axis the steepest descent (or gentlest ascent) of the two neighbours; off the
  /// grid counts as a drop of one cell size (the thesis's z = -1 there), so the border drains.
  std::array<double, 2> acceleration(Cell c) const {
    std::array<double, 2> a{};
    for (int axis = 0; axis < 2; ++axis) {
      double dz[2];
      for (int s = 0; s < 2; ++s) {
        const int nc = c[0] + (axis == 0 ? 2 * s - 1 : 0), nr = c[1] + (axis == 1 ? 2 * s - 1 : 0);
        dz[s] = f_.inside(nc, nr) ? (z(nc, nr) - z(c[0], c[1])) / cell_m_ : -1.0;
      }
      const int d = dz[0] < dz[1] ? -1 : 1;
      const double slope = d < 0 ? dz[0] : dz[1];
      a[std::size_t(axis)] = d * p_.gravity * std::sin(std::atan(std::abs(slope)));
    }
    return a;
  }

  /// Alg. 7: undoes river i after its cell `keep` (kept); releases the tributaries joined there.
  void undo(int i, std::size_t keep) {
    Particle& m = ps_[std::size_t(i)];
    for (std::size_t k = keep + 1; k < m.cells.size(); ++k) f_.river[f_.at(m.cells[k][0], m.cells[k][1])] = -1;
    m.cells.resize(keep + 1);
    auto& t = m.tributaries;
    for (auto it = t.begin(); it != t.end();) {
      if (it->first > keep) {
        Particle& k = ps_[std::size_t(it->second)];
        k.stop = false, k.into = -1;
        m.mass -= k.mass;
        it = t.erase(it);
      } else {
        ++it;
      }
    }
  }

  /// Alg. 5: meander perturbation and friction, when the particle enters a new cell.
  void perturb(Particle& m) {
    double r = std::hypot(m.vx, m.vy), theta = std::atan2(m.vy, m.vx);
    theta += kPi / 2 * rng_.symmetric() * p_.dt;
    r = std::min(r, p_.r_max);
    r -= p_.dt / (2.0 * p_.r_max) * r * r;
    m.vx = r * std::cos(theta), m.vy = r * std::sin(theta);
  }

  bool drains_into(int j, int i) const {  // does river j flow (through confluences) into river i?
    for (int k = j, guard = 0; k >= 0 && guard <= int(ps_.size()); k = ps_[std::size_t(k)].into, ++guard)
      if (k == i) return true;
    return false;
  }

  /// Alg. 6: one time step of particle i; returns the river it ran into (its Confluent set), or -1.
  int move(int i) {
    Particle& m = ps_[std::size_t(i)];
    const Cell from = floor_cell(m.x, m.y);
    const auto a = acceleration(from);
    m.vx += a[0] * p_.dt, m.vy += a[1] * p_.dt;
    if (std::hypot(m.vx, m.vy) < 1e-6 && std::hypot(a[0], a[1]) < 1e-6) {
      m.stop = true;
      return -1;
    }
    m.x += m.vx * p_.dt, m.y += m.vy * p_.dt;
    const Cell to = floor_cell(m.x, m.y);
    if (to == from) return -1;
    int hit = -1;
    discrete_line(from, to, [&](Cell q, Cell prev) {
      if (q == from) return true;
      if (!f_.inside(q[0], q[1])) {  // an outlet: the river is valid (the thesis's only mouths)
        m.stop = m.valid = true;
        return false;
      }
      Cell h = q;
      int other = f_.river[f_.at(q[0], q[1])];
      if (other < 0 && q[0] != prev[0] && q[1] != prev[1]) {  // a diagonal step through two river cells
        const int s1 = f_.river[f_.at(q[0], prev[1])], s2 = f_.river[f_.at(prev[0], q[1])];
        if (s1 >= 0 && s2 >= 0) other = s1, h = {q[0], prev[1]};
      }
      if (other < 0) {
        f_.river[f_.at(q[0], q[1])] = i;
        m.cells.push_back(q);
        return true;
      }
      if (other != i && !drains_into(other, i)) {
        const auto& oc = ps_[std::size_t(other)].cells;
        m.at = std::size_t(std::find(oc.rbegin(), oc.rend(), h).base() - oc.begin()) - 1;
        m.into = other;
        hit = other;
        return false;
      }
      // A loop (its own trajectory, or a river draining into it): undo back to the loop's start.
      const auto it = std::find(m.cells.begin(), m.cells.end(), h);
      if (it != m.cells.end()) undo(i, std::size_t(it - m.cells.begin()));
      const Cell back = m.cells.back();
      m.x = back[0] + 0.5, m.y = back[1] + 0.5;
      if (++m.loops >= p_.max_loops) m.stop = true;
      perturb(m);
      return false;
    });
    if (!m.stop && hit < 0) perturb(m);
    return hit;
  }

  /// Alg. 9's confluence: i stops; a moving j is undone to the confluence and leaves it with the
  /// masses' weighted velocity and the summed mass. A stopped j just receives the tributary.
  void confluence(int i, int j) {
    Particle& mi = ps_[std::size_t(i)];
    Particle& mj = ps_[std::size_t(j)];
    mi.stop = true;
    if (!mj.stop) {
      undo(j, mi.at);
      const double s = mi.mass + mj.mass;
      mj.vx = (mj.mass * mj.vx + mi.mass * mi.vx) / s;
      mj.vy = (mj.mass * mj.vy + mi.mass * mi.vy) / s;
      mj.mass = s;
      const Cell c = mj.cells.back();
      mj.x = c[0] + 0.5, mj.y = c[1] + 0.5;
    }
    mj.tributaries.emplace_back(mi.at, i);
  }

  Field& f_;
  double cell_m_;
  RiverParams p_;
  Rng& rng_;
  std::vector<Particle> ps_;
  std::vector<int> valid_;
};

// ---- The skeleton DEM (§2.2.3) --------------------------------------------------------------

/// Mass at every point of every path: 1 plus the masses of the tributaries joined upstream of it.
std::vector<std::vector<double>> path_masses(const std::vector<RiverPath>& paths) {
  std::vector<std::vector<std::pair<std::size_t, int>>> joins(paths.size());
  for (std::size_t i = 0; i < paths.size(); ++i)
    if (paths[i].into >= 0) joins[std::size_t(paths[i].into)].emplace_back(paths[i].at, int(i));
  std::vector<std::vector<double>> mass(paths.size());
  std::function<double(int)> total = [&](int i) {
    auto& m = mass[std::size_t(i)];
    if (!m.empty()) return m.back();
    auto j = joins[std::size_t(i)];
    std::sort(j.begin(), j.end());
    double acc = 1;
    std::size_t next = 0;
    m.resize(paths[std::size_t(i)].line.size());
    for (std::size_t k = 0; k < m.size(); ++k) {
      while (next < j.size() && j[next].first <= k) acc += total(j[next++].second);
      m[k] = acc;
    }
    return m.back();
  };
  for (std::size_t i = 0; i < paths.size(); ++i) total(int(i));
  return mass;
}

/// The rivers proper: each track loses its first `head` points (a hollow above the channel head,
/// carved in the DEM but no river), never past a confluence; a track that is all hollow is dropped.
std::vector<RiverPath> channels(const std::vector<RiverPath>& paths, std::size_t head) {
  std::vector<std::size_t> cut(paths.size(), head);
  for (const auto& p : paths)
    if (p.into >= 0) cut[std::size_t(p.into)] = std::min(cut[std::size_t(p.into)], p.at);
  std::vector<int> index(paths.size(), -1);
  std::vector<RiverPath> out;
  for (std::size_t i = 0; i < paths.size(); ++i)
    if (cut[i] + 2 <= paths[i].line.size()) index[i] = int(out.size()), out.push_back(paths[i]);
  for (std::size_t i = 0; i < paths.size(); ++i) {
    if (index[i] < 0) continue;
    RiverPath& p = out[std::size_t(index[i])];
    p.line.erase(p.line.begin(), p.line.begin() + std::ptrdiff_t(cut[i]));
    p.width_m.erase(p.width_m.begin(), p.width_m.begin() + std::ptrdiff_t(cut[i]));
    if (p.into >= 0) p.into = index[std::size_t(p.into)], p.at -= cut[std::size_t(paths[i].into)];
  }
  return out;
}

/// The 3x3 mean the thesis applies to the basins so that segment joints leave no local minimum.
void smooth_basins(Field& f) {
  std::vector<float> s(f.a.size());
  for (int r = 0; r < f.rows; ++r)
    for (int c = 0; c < f.cols; ++c) {
      double sum = 0;
      int n = 0;
      for (int dr = -1; dr <= 1; ++dr)
        for (int dc = -1; dc <= 1; ++dc)
          if (f.inside(c + dc, r + dr)) sum += f.a[f.at(c + dc, r + dr)], ++n;
      s[f.at(c, r)] = float(sum / n);
    }
  f.a.swap(s);
}

/// River particles on both sides of every ridge, one pair every `spacing` ridge cells (§2.2.2).
void seed_particles(RiverSystem& rivers, const std::vector<RidgeLine>& ridges, double spacing) {
  const double offset = 2.0;
  for (const auto& ridge : ridges) {
    double travelled = spacing;
    for (std::size_t i = 1; i < ridge.line.size(); ++i) {
      const auto& p = ridge.line[i - 1];
      const auto& q = ridge.line[i];
      const double len = std::hypot(q[0] - p[0], q[1] - p[1]);
      if (len <= 0) continue;
      const double nx = -(q[1] - p[1]) / len, ny = (q[0] - p[0]) / len;
      for (double s = 0; s < len; s += 1.0) {
        if ((travelled += 1.0) < spacing) continue;
        travelled = 0;
        const double x = p[0] + (q[0] - p[0]) * s / len + 0.5, y = p[1] + (q[1] - p[1]) * s / len + 0.5;
        rivers.add(floor_cell(x + offset * nx, y + offset * ny));
        rivers.add(floor_cell(x - offset * nx, y - offset * ny));
      }
    }
  }
}

/// River beds burnt into `dem`, made to descend (by at least `drop` m a cell) from source to mouth
/// and to reach each confluence above the receiving river, so the DEM drains along them. Returns
/// the river centre cells (their bed is never lowered by a neighbour's bank).
std::vector<char> burn_beds(Raster<float>& dem, const Field& f, const std::vector<RiverPath>& paths,
                            const std::vector<std::vector<double>>& masses, double drop) {
  std::vector<char> centre(dem.size(), 0);
  std::vector<std::vector<double>> bed(paths.size());
  std::vector<int> order;  // receiving rivers before their tributaries
  {
    std::vector<std::vector<int>> children(paths.size());
    for (std::size_t i = 0; i < paths.size(); ++i)
      if (paths[i].into < 0) order.push_back(int(i));
      else children[std::size_t(paths[i].into)].push_back(int(i));
    for (std::size_t k = 0; k < order.size(); ++k)
      for (int ch : children[std::size_t(order[k])]) order.push_back(ch);
  }
  for (int i : order) {
    const RiverPath& p = paths[std::size_t(i)];
    const std::size_t own = p.into >= 0 ? p.line.size() - 1 : p.line.size();  // a tributary's last point is the confluence
    auto& z = bed[std::size_t(i)];
    z.assign(own, 0.0);
    for (std::size_t k = own; k-- > 0;) {
      const double here = f.a[f.at(int(p.line[k][0]), int(p.line[k][1]))];
      const double below = k + 1 < own ? z[k + 1] : (p.into >= 0 ? bed[std::size_t(p.into)][p.at] : -drop);
      z[k] = std::max(here, below + drop);
    }
    for (std::size_t k = 0; k < own; ++k) {  // the bed, log2(m) cells wide (§2.2.2.2)
      const int c0 = int(p.line[k][0]), r0 = int(p.line[k][1]);
      dem(c0, r0) = float(z[k]);
      centre[dem.index(c0, r0)] = 1;
      const double radius = 0.5 * std::log2(masses[std::size_t(i)][k]);
      const int reach = int(std::floor(radius));
      for (int dr = -reach; dr <= reach; ++dr)
        for (int dc = -reach; dc <= reach; ++dc) {
          const int c = c0 + dc, r = r0 + dr;
          if (!dem.inside(c, r) || centre[dem.index(c, r)] || dc * dc + dr * dr > radius * radius) continue;
          float& v = dem(c, r);
          v = std::isfinite(v) ? std::min(v, float(z[k])) : float(z[k]);
        }
    }
  }
  return centre;
}

/// Interfluves (beyond the thesis): the skeleton leaves the ground between two rivers free, and
/// DMMC between two beds at one altitude gives a floor that drains anywhere (45 % of the river
/// length on a D8 stream at 257², seed 3). The cells half-way between rivers (where the nearest
/// river cell jumps) are fixed at the basin height plus a hillslope from the nearer bed as steep
/// as the basin's own slope there (0.15 to 2 m/m, the rise at most half the relief), so that the ground falls towards the river
/// at least as fast as down the basin and DMMC draws a valley around every river.
void fix_interfluves(Raster<float>& dem, const Field& f, const std::vector<char>& centre, double cell_m, double relief_m) {
  const int cols = f.cols, rows = f.rows;
  auto gradient = [&](int c, int r) {  // |grad a| in m/m, central differences
    const int c0 = std::max(0, c - 1), c1 = std::min(cols - 1, c + 1), r0 = std::max(0, r - 1), r1 = std::min(rows - 1, r + 1);
    const double gx = (f.a[f.at(c1, r)] - f.a[f.at(c0, r)]) / ((c1 - c0) * cell_m);
    const double gy = (f.a[f.at(c, r1)] - f.a[f.at(c, r0)]) / ((r1 - r0) * cell_m);
    return std::hypot(gx, gy);
  };
  std::vector<double> dist;
  std::vector<std::size_t> nearest;
  distance_to(centre, cols, rows, dist, nearest);
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) {
      const std::size_t i = dem.index(c, r);
      if (std::isfinite(dem[i]) || dist[i] < 2) continue;
      bool divide = false;
      for (int k = 0; k < 8 && !divide; k += 2) {
        const int nc = c + dcol[std::size_t(k)], nr = r + drow[std::size_t(k)];
        if (!dem.inside(nc, nr)) continue;
        const std::size_t a = nearest[i], b = nearest[dem.index(nc, nr)];
        const double jump = std::hypot(double(a % std::size_t(cols)) - double(b % std::size_t(cols)),
                                       double(a / std::size_t(cols)) - double(b / std::size_t(cols)));
        divide = jump > 3;
      }
      const double hill = std::clamp(gradient(c, r), 0.15, 2.0);  // at most 63°
      const double rise = std::min(hill * dist[i] * cell_m, 0.5 * relief_m);
      if (divide) dem[i] = float(std::max<double>(f.a[i], dem[nearest[i]]) + rise);
    }
}

}  // namespace

GeneratedTerrain generate_flow(const GenerateRequest& request) {
  using clock = std::chrono::steady_clock;
  const auto t0 = clock::now();
  const int cols = request.grid.cols(), rows = request.grid.rows();
  Field f{cols, rows, std::vector<float>(std::size_t(cols) * rows, 0.0f), std::vector<int>(std::size_t(cols) * rows, -1),
          std::vector<int>(std::size_t(cols) * rows, -1)};
  Rng rng(request.seed);
  const double size = std::min(cols, rows);
  RidgeParams rp;
  rp.speed = std::max(2.0, size / 50);
  rp.sigma1 = size / 16;
  rp.sigma2 = size / 4;
  // A base rising gently away from the border: the thesis's only mouths are the border, and this
  // keeps every basin draining to it (the basins alone leave flat floors where particles stall).
  const double base_m = 0.1 * request.relief_m;
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) {
      const double d = std::min({c + 0.5, r + 0.5, cols - c - 0.5, rows - r - 0.5});
      f.a[f.at(c, r)] = float(base_m * std::min(1.0, d / (size / 2)));
    }
  RiverRidgePlan plan;
  if (request.lines.empty()) {
    const int pairs = std::max(2, int(std::lround(double(cols) * rows / 60000.0)));
    plan.ridges = random_ridges(f, pairs, request.relief_m, rp, rng);
  } else {
    plan.ridges = given_ridges(f, request.lines, request.relief_m, rp);
  }
  smooth_basins(f);

  RiverSystem rivers(f, request.cell_m, RiverParams{}, rng);
  // A particle stands for the water of its strip of slope, `spacing` cells wide: its channel head
  // is `spacing` cells down its track, where it drains spacing² cells (see channels()).
  const double spacing = std::max(3.0, size / 20);
  seed_particles(rivers, plan.ridges, spacing);
  rivers.run();
  std::vector<RiverPath> paths = rivers.paths();
  const auto masses = path_masses(paths);
  for (std::size_t i = 0; i < paths.size(); ++i)
    for (double m : masses[i]) paths[i].width_m.push_back(std::max(1.0, std::log2(m)) * request.cell_m);
  plan.rivers = reaches_from_paths(channels(paths, std::size_t(std::lround(spacing))));
  const double skeleton_s = std::chrono::duration<double>(clock::now() - t0).count();

  // The skeleton DEM: ridge and river cells keep their altitude, everything else is unknown.
  GeneratedTerrain out;
  out.dem = request.grid;
  out.plan = std::move(plan);
  Raster<float>& dem = out.dem;
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c)
      if (f.ridge[f.at(c, r)] >= 0) dem(c, r) = f.a[f.at(c, r)];
  const std::vector<char> centre = burn_beds(dem, f, paths, masses, 1e-3 * request.cell_m);
  fix_interfluves(dem, f, centre, request.cell_m, request.relief_m);
  const auto t1 = clock::now();
  terrain::dmmc(dem, request.dmmc, request.progress);
  out.timings.emplace_back("skeleton", skeleton_s);
  out.channel_head_m2 = spacing * spacing * request.cell_m * request.cell_m;
  out.timings.emplace_back("dmmc", std::chrono::duration<double>(clock::now() - t1).count());
  return out;
}

}  // namespace terrapolis::generate
