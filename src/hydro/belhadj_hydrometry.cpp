// Belhadj (2007) Algorithm 12 as a double-buffered gather: parallel, deterministic, vectorisable.
// SPDX-License-Identifier: MIT
#include "hydro/belhadj_hydrometry.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "core/error.hpp"
#include "core/neighbours.hpp"
#include "hydro/grid.hpp"

namespace terrapolis::hydro {
namespace {
constexpr int kSafetyCap = 160;  // |F| <= ~8^t: |F|^2 stays below DBL_MAX up to t ~ 170
}  // namespace

std::array<double, 2> belhadj_land_range(const Dem& dem, std::optional<double> sea_level) {
  double lo = INFINITY, hi = -INFINITY;
  for (float v : dem.values())
    if (!std::isnan(v) && !is_sea(v, sea_level)) {
      lo = std::min(lo, double(v));
      hi = std::max(hi, double(v));
    }
  return {lo, hi};
}

int belhadj_iteration_limit(const BelhadjOptions& options) { return options.max_iterations > 0 ? options.max_iterations : kSafetyCap; }

BelhadjModel::BelhadjModel(const Dem& dem, const CellMetrics& metrics, VerticalScale vertical,
                           std::optional<double> sea_level, BelhadjShare share, std::optional<std::array<double, 2>> land_range)
    : cols_(dem.cols()), rows_(dem.rows()), stride_(dem.cols() + 2), share_(share) {
  const std::size_t padded = std::size_t(stride_) * std::size_t(rows_ + 2);
  const auto [lo, hi] = land_range ? *land_range : belhadj_land_range(dem, sea_level);
  if (!(lo <= hi)) throw bad_input("hydrometry: the DEM has no land cell (all nodata or below sea level)");
  z_out_ = vertical == VerticalScale::normalised16 ? -1.0 : lo - std::max(hi - lo, 1.0);
  if (vertical == VerticalScale::normalised16 && lo / 65535.0 <= z_out_)  // valid cells must lie above it
    throw bad_input("hydrometry: elevations at or below -65535 m do not fit the 16-bit normalisation");
  block_.assign(10 * padded, 0.0);  // F = 0, Q = 0, Acc = 0 everywhere to begin with
  double* arrays[10];
  for (std::size_t a = 0; a < 10; ++a) arrays[a] = block_.data() + a * padded;
  z_ = arrays[0], fx_ = arrays[1], fy_ = arrays[2], fz_ = arrays[3], q_ = arrays[4];
  acc_ = arrays[5], fx2_ = arrays[6], fy2_ = arrays[7], fz2_ = arrays[8], q2_ = arrays[9];
  std::fill(z_, z_ + padded, z_out_);
  for (int r = 0; r < rows_; ++r)
    for (int c = 0; c < cols_; ++c) {
      const float v = dem(c, r);
      if (std::isnan(v) || is_sea(v, sea_level)) continue;
      double z = v;
      if (vertical == VerticalScale::normalised16) z = double(v) / 65535.0;  // 16-bit metres / (2^16-1)
      const std::size_t i = at(c, r);
      z_[i] = z;
      fz_[i] = -1.0;
      q_[i] = 1.0;
      ++valid_count_;
    }
  hx_.assign(std::size_t(rows_ + 2) * 8, 0.0);
  hy_.assign(std::size_t(rows_ + 2) * 8, 0.0);
  for (int pr = 0; pr < rows_ + 2; ++pr) {
    const int r = std::clamp(pr - 1, 0, rows_ - 1);
    for (int k = 0; k < 8; ++k) {
      double x = dcol[k], y = drow[k];
      if (vertical == VerticalScale::metres) {
        // Direction of the step on the local east/south plane, length the geodesic step.
        const double a = dcol[k] * metrics.width_m[std::size_t(r)];
        const double b = drow[k] * metrics.step_m(r, drow[k] > 0 ? 2 : 6);
        const double scale = metrics.step_m(r, k) / std::hypot(a, b);
        x = a * scale;
        y = b * scale;
      }
      hx_[std::size_t(pr) * 8 + std::size_t(k)] = x;
      hy_[std::size_t(pr) * 8 + std::size_t(k)] = y;
    }
  }
  row_sum_.assign(std::size_t(rows_), 0.0);
}

namespace {

// The kernels below are written column-innermost on restrict pointers so that the compiler
// vectorises them (sqrt included: the file is built with -fno-math-errno). Only element-wise IEEE
// operations and per-cell sums in a fixed order are used (no contraction into FMA), so every ISA
// variant (target_clones) gives the same bits.
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define TP_KERNEL __attribute__((target_clones("avx512f", "avx2", "default")))
#else
#define TP_KERNEL
#endif

struct State {
  const double* __restrict z;
  double zout;  // the outside altitude: a cell is valid when its altitude is above it
  const double* __restrict fx;
  const double* __restrict fy;
  const double* __restrict fz;
  const double* __restrict q;
  double* __restrict acc;
  double* __restrict fx2;
  double* __restrict fy2;
  double* __restrict fz2;
  double* __restrict q2;
};

/// What one sender row sends: for each direction k, N_k = |R_k| where neighbour k is inside and
/// fed (R_k . V_k > 0), else 0; and the share factor Q / Σn. Each array has a zero cell on both
/// sides so that a receiver row can read its neighbours' columns c-1 and c+1 without a test.
struct SenderRow {
  std::vector<double> buffer;
  int n = 0;
  void resize(int cols) {
    n = cols + 2;
    buffer.assign(9 * std::size_t(n), 0.0);
  }
  double* norm(int k) { return buffer.data() + std::size_t(k) * std::size_t(n) + 1; }
  double* factor() { return buffer.data() + 8 * std::size_t(n) + 1; }
};

/// Pass 1 (sender row of `n` cells at padded index i0): N_k, Σn, the factor Q / Σn, Acc += Q.
/// Outside cells (altitude zout) send nothing. `own`: the row is the caller's (not a neighbour band's
/// edge row computed again), so Acc is updated. Returns Σ Q over the row (column order).
TP_KERNEL double send_row(const State& st, std::size_t i0, int n, const std::ptrdiff_t* off, const double* hx,
                          const double* hy, bool all, bool own, double* const* norms, double* __restrict factor) {
  const double* __restrict z = st.z + i0;
  const double zout = st.zout;
  const double* __restrict fx = st.fx + i0;
  const double* __restrict fy = st.fy + i0;
  const double* __restrict fz = st.fz + i0;
  const double* __restrict q = st.q + i0;
  double* __restrict acc = st.acc + i0;
  const double keep = all ? 1.0 : 0.0;  // Σn over unfed neighbours too (Algorithm 12 as printed)
  for (int c = 0; c < n; ++c) factor[c] = 0.0;  // Σn, in neighbour order
  for (int k = 0; k < 8; ++k) {
    const double* __restrict zn = z + off[k];
    double* __restrict nk = norms[k];
    const double vx = hx[k], vy = hy[k];
    for (int c = 0; c < n; ++c) {
      const double dz = zn[c] - z[c];
      const double rx = fx[c] + vx, ry = fy[c] + vy, rz = fz[c] + dz;
      const double s = rx * vx + ry * vy + rz * dz;
      const double norm = std::sqrt(rx * rx + ry * ry + rz * rz);
      // Valid cells lie above the outside altitude; both tests are selects, not branches.
      nk[c] = s > 0 && zn[c] > zout && z[c] > zout ? norm : 0.0;
      factor[c] += s > 0 ? norm : keep * norm;
    }
  }
  for (int c = 0; c < n; ++c) factor[c] = factor[c] > 0 ? q[c] / factor[c] : 0.0;
  if (!own) return 0;
  double sum = 0;
  for (int c = 0; c < n; ++c) acc[c] += q[c];
  for (int c = 0; c < n; ++c) sum += q[c];
  return sum;
}

/// Pass 2 (receiver row of `n` cells; fx..z point at its first cell): each cell pulls from its 8
/// neighbours, in neighbour order, what they send it: R = F(s) + V(s→c) where fed, and the water
/// N Q(s) / Σn(s). `norms[k]` and `factors[k]` point at what neighbour k's row sends, column-aligned
/// with this row; (vx[k], vy[k]) is the horizontal step from neighbour k to the cell. The sums stay
/// in registers (the direction loop is unrolled inside the column loop) and the restrict parameters
/// let GCC vectorise the column loop without run-time alias checks.
TP_KERNEL void receive_row(int n, const double* __restrict fx, const double* __restrict fy,
                           const double* __restrict fz, const double* __restrict z, const std::ptrdiff_t* offsets,
                           const double* const* norms, const double* const* factors, const double* vxs,
                           const double* vys, double* __restrict fx2, double* __restrict fy2,
                           double* __restrict fz2, double* __restrict q2) {
  std::ptrdiff_t off[8];
  const double* ns[8];
  const double* ws[8];
  double vx[8], vy[8];
  for (int k = 0; k < 8; ++k) {
    off[k] = offsets[k];
    ns[k] = norms[k];
    ws[k] = factors[k];
    vx[k] = vxs[k];
    vy[k] = vys[k];
  }
  for (int c = 0; c < n; ++c) {
    double ax = 0, ay = 0, az = 0, aq = 0;
#pragma GCC unroll 8
    for (int k = 0; k < 8; ++k) {
      // A 0/1 factor rather than a select or a test (GCC would make a conditional store of it):
      // R is finite (the iteration cap keeps |F| below 8^160), so 0 * R is 0 and adding it is exact.
      const double norm = ns[k][c];
      const double fed = norm > 0 ? 1.0 : 0.0;
      const std::ptrdiff_t s = c + off[k];
      ax += fed * (fx[s] + vx[k]);
      ay += fed * (fy[s] + vy[k]);
      az += fed * (fz[s] + (z[c] - z[s]));
      aq += norm * ws[k][c];
    }
    fx2[c] = ax;
    fy2[c] = ay;
    fz2[c] = az;
    q2[c] = aq;
  }
}

}  // namespace

double BelhadjModel::step() {
  std::ptrdiff_t off[8];
  for (int k = 0; k < 8; ++k) off[k] = std::ptrdiff_t(drow[k]) * stride_ + dcol[k];
  const bool all = share_ == BelhadjShare::all_neighbours;
  const State st{z_, z_out_, fx_, fy_, fz_, q_, acc_, fx2_, fy2_, fz2_, q2_};
  // Bands of rows, each computing what its rows and the rows just outside it send (the edge rows
  // are computed twice), then gathering row by row. Every value is a function of the previous
  // state alone, summed in a fixed order: bit-identical whatever the bands and threads.
  const int grain = std::max(8, std::min(64, rows_ / 8));
  tbb::parallel_for(
      tbb::blocked_range<int>(0, rows_, grain),
      [&](const tbb::blocked_range<int>& range) {
        SenderRow ring[3];
        for (auto& row : ring) row.resize(cols_);
        SenderRow empty;  // what the halo rows send: nothing
        empty.resize(cols_);
        auto sender = [&](int r) -> SenderRow* {
          return r < 0 || r >= rows_ ? &empty : &ring[std::size_t((r + 3) % 3)];
        };
        auto send = [&](int r) {
          if (r < 0 || r >= rows_) return;
          SenderRow& row = *sender(r);
          double* norms[8];
          for (int k = 0; k < 8; ++k) norms[k] = row.norm(k);
          const std::size_t pr = std::size_t(r + 1), i0 = pr * std::size_t(stride_) + 1;
          const bool own = r >= range.begin() && r < range.end();
          const double sum = send_row(st, i0, cols_, off, &hx_[pr * 8], &hy_[pr * 8], all, own, norms, row.factor());
          if (own) row_sum_[std::size_t(r)] = sum;
        };
        send(range.begin() - 1);
        send(range.begin());
        for (int r = range.begin(); r < range.end(); ++r) {
          send(r + 1);
          const double* norms[8];
          const double* factors[8];
          double vx[8], vy[8];
          for (int k = 0; k < 8; ++k) {
            const int rs = r + drow[k], back = opposite(k);  // back: from the sender to this cell
            norms[k] = sender(rs)->norm(back) + dcol[k];
            factors[k] = sender(rs)->factor() + dcol[k];
            const std::size_t ps = std::size_t(std::clamp(rs, -1, rows_) + 1);
            vx[k] = hx_[ps * 8 + std::size_t(back)];
            vy[k] = hy_[ps * 8 + std::size_t(back)];
          }
          const std::size_t i0 = std::size_t(r + 1) * std::size_t(stride_) + 1;
          receive_row(cols_, st.fx + i0, st.fy + i0, st.fz + i0, st.z + i0, off, norms, factors, vx, vy, st.fx2 + i0,
                      st.fy2 + i0, st.fz2 + i0, st.q2 + i0);
        }
      },
      tbb::simple_partitioner());
  std::swap(fx_, fx2_);
  std::swap(fy_, fy2_);
  std::swap(fz_, fz2_);
  std::swap(q_, q2_);
  double total = 0;
  for (double s : row_sum_) total += s;  // fixed order: deterministic
  return valid_count_ ? total / double(valid_count_) : 0.0;
}

BelhadjRun belhadj_hydrometry(const Dem& dem, const CellMetrics& metrics, const BelhadjOptions& options,
                              Progress& progress) {
  if (options.max_iterations < 0) throw bad_input("/hydro/iterations: must be 0 (until convergence) or positive");
  if (!(options.threshold > 0)) throw bad_input("/hydro/threshold: must be a positive number");
  ProgressStep step(progress, "hydrometry (Belhadj)");
  BelhadjModel model(dem, metrics, options.vertical, options.sea_level, options.share);
  BelhadjRun run;
  const int limit = belhadj_iteration_limit(options);
  const double log_target = std::log(options.threshold);
  for (;;) {
    run.final_mean = model.step();
    ++run.iterations;
    if (belhadj_stops(options, run.iterations, run.final_mean)) break;
    const double by_mean = run.final_mean > 0 ? std::log(run.final_mean) / log_target : 1.0;
    step.update(std::clamp(std::max(by_mean, double(run.iterations) / limit), 0.0, 1.0));
  }
  run.hydrometry = dem.like<float>(NAN);
  double lo = INFINITY, hi = -INFINITY;
  for (int r = 0; r < dem.rows(); ++r)
    for (int c = 0; c < dem.cols(); ++c)
      if (model.valid(c, r)) {
        lo = std::min(lo, model.acc(c, r));
        hi = std::max(hi, model.acc(c, r));
      }
  for (int r = 0; r < dem.rows(); ++r)
    for (int c = 0; c < dem.cols(); ++c) {
      if (model.valid(c, r)) run.hydrometry(c, r) = belhadj_rescale(model.acc(c, r), lo, hi);
      else if (!std::isnan(dem(c, r))) run.hydrometry(c, r) = 0.0f;  // sea
    }
  return run;
}

}  // namespace terrapolis::hydro
