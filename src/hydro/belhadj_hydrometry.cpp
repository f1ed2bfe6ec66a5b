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
// Order in which a sender feeds its neighbours (fixed, so sums are reproducible).
constexpr int kGatherOrder[8] = {5, 6, 7, 4, 0, 3, 2, 1};
constexpr int kSafetyCap = 160;  // |F| <= ~8^t: |F|^2 stays below DBL_MAX up to t ~ 170
}  // namespace

BelhadjModel::BelhadjModel(const Dem& dem, const CellMetrics& metrics, VerticalScale vertical,
                           std::optional<double> sea_level, BelhadjShare share)
    : cols_(dem.cols()), rows_(dem.rows()), stride_(dem.cols() + 2), share_(share) {
  const std::size_t padded = std::size_t(stride_) * std::size_t(rows_ + 2);
  double lo = INFINITY, hi = -INFINITY;
  for (float v : dem.values())
    if (!std::isnan(v) && !is_sea(v, sea_level)) {
      lo = std::min(lo, double(v));
      hi = std::max(hi, double(v));
    }
  if (!(lo <= hi)) throw bad_input("hydrometry: the DEM has no land cell (all nodata or below sea level)");
  z_out_ = vertical == VerticalScale::normalised16 ? -1.0 : lo - std::max(hi - lo, 1.0);
  z_.assign(padded, z_out_);
  valid_.assign(padded, 0.0);
  for (int r = 0; r < rows_; ++r)
    for (int c = 0; c < cols_; ++c) {
      const float v = dem(c, r);
      if (std::isnan(v) || is_sea(v, sea_level)) continue;
      double z = v;
      if (vertical == VerticalScale::normalised16) z = double(v) / 65535.0;  // 16-bit metres / (2^16-1)
      z_[at(c, r)] = z;
      valid_[at(c, r)] = 1.0;
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
  fx_.assign(padded, 0.0);
  fy_.assign(padded, 0.0);
  fz_.assign(padded, 0.0);
  q_.assign(padded, 0.0);
  acc_.assign(padded, 0.0);
  for (std::size_t i = 0; i < padded; ++i)
    if (valid_[i] != 0) {
      fz_[i] = -1.0;
      q_[i] = 1.0;
    }
  fx2_ = fx_;
  fy2_ = fy_;
  fz2_ = fz_;
  q2_ = q_;
  row_sum_.assign(std::size_t(rows_), 0.0);
}

namespace {

// The two passes over one row, written column-innermost on restrict pointers so that the
// compiler vectorises them (sqrt included: the file is built with -fno-math-errno). Only
// element-wise IEEE operations and per-cell sums in a fixed order are used, so every ISA
// variant (target_clones) gives the same bits.
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define TP_KERNEL __attribute__((target_clones("avx2", "default")))
#else
#define TP_KERNEL
#endif

struct State {
  const double* __restrict z;
  const double* __restrict valid;
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

/// One sender row of `n` cells starting at padded index i0: computes its 8 R_i, N_i = |R_i| and
/// S_i = R_i . V_i, Σn, Acc += Q, then adds R_i and N_i Q / Σn to the fed receivers (scatter,
/// as the thesis's loop). `scratch` holds 9 n doubles. Returns Σ Q over the row.
TP_KERNEL double sender_row(const State& st, std::size_t i0, int n, const std::ptrdiff_t* off, const int* order,
                            const double* hx, const double* hy, bool all, double* __restrict scratch) {
  const double* __restrict z = st.z + i0;
  const double* __restrict fx = st.fx + i0;
  const double* __restrict fy = st.fy + i0;
  const double* __restrict fz = st.fz + i0;
  const double* __restrict q = st.q + i0;
  double* __restrict sn = scratch;
  // 8 rows of N_i for the fed inside neighbours, 0 for the others (a fed neighbour with N_i = 0
  // has R_i = 0 and so receives nothing either way).
  double* __restrict norms = scratch + n;
  const double keep = all ? 1.0 : 0.0;  // Σn over unfed neighbours too (Algorithm 12 as printed)
  for (int c = 0; c < n; ++c) sn[c] = 0.0;
  for (int k = 0; k < 8; ++k) {
    const double* __restrict zn = z + off[k];
    const double* __restrict vn = st.valid + i0 + off[k];
    double* __restrict nk = norms + std::size_t(k) * std::size_t(n);
    const double vx = hx[k], vy = hy[k];
    for (int c = 0; c < n; ++c) {
      const double dz = zn[c] - z[c];
      const double rx = fx[c] + vx, ry = fy[c] + vy, rz = fz[c] + dz;
      const double s = rx * vx + ry * vy + rz * dz;
      const double norm = std::sqrt(rx * rx + ry * ry + rz * rz);
      const double inside = vn[c];  // loaded unconditionally so the loop has no branch
      nk[c] = s > 0 ? inside * norm : 0.0;
      sn[c] += s > 0 ? norm : keep * norm;
    }
  }
  double sum = 0;
  for (int c = 0; c < n; ++c) {
    st.acc[i0 + std::size_t(c)] += q[c];
    sn[c] = sn[c] > 0 ? q[c] / sn[c] : 0.0;  // from here on: the share factor Q / Σn
  }
  for (int c = 0; c < n; ++c) sum += q[c];
  for (int g = 0; g < 8; ++g) {
    const int k = order[g];
    const double* __restrict zn = z + off[k];
    const double* __restrict nk = norms + std::size_t(k) * std::size_t(n);
    double* __restrict ox = st.fx2 + i0 + off[k];
    double* __restrict oy = st.fy2 + i0 + off[k];
    double* __restrict oz = st.fz2 + i0 + off[k];
    double* __restrict oq = st.q2 + i0 + off[k];
    const double vx = hx[k], vy = hy[k];
    for (int c = 0; c < n; ++c) {
      const double m = nk[c] > 0 ? 1.0 : 0.0;
      ox[c] += m * (fx[c] + vx);
      oy[c] += m * (fy[c] + vy);
      oz[c] += m * (fz[c] + (zn[c] - z[c]));
      oq[c] += m * (nk[c] * sn[c]);
    }
  }
  return sum;
}

}  // namespace

double BelhadjModel::step() {
  std::ptrdiff_t off[8];
  for (int k = 0; k < 8; ++k) off[k] = std::ptrdiff_t(drow[k]) * stride_ + dcol[k];
  const bool all = share_ == BelhadjShare::all_neighbours;
  std::fill(fx2_.begin(), fx2_.end(), 0.0);
  std::fill(fy2_.begin(), fy2_.end(), 0.0);
  std::fill(fz2_.begin(), fz2_.end(), 0.0);
  std::fill(q2_.begin(), q2_.end(), 0.0);
  const State st{z_.data(), valid_.data(), fx_.data(), fy_.data(), fz_.data(), q_.data(), acc_.data(),
                 fx2_.data(), fy2_.data(), fz2_.data(), q2_.data()};
  // A sender row writes to rows r-1..r+1, so rows 3 apart never write the same cell: three
  // phases (r mod 3), each parallel over its rows. Every receiver then sums its inputs in the
  // same order (by phase, then neighbour order) whatever the number of threads.
  for (int phase = 0; phase < 3; ++phase) {
    const int count = (rows_ - phase + 2) / 3;
    tbb::parallel_for(tbb::blocked_range<int>(0, count), [&](const tbb::blocked_range<int>& range) {
      std::vector<double> scratch(9 * static_cast<std::size_t>(cols_));
      for (int t = range.begin(); t < range.end(); ++t) {
        const int r = phase + 3 * t;
        const std::size_t pr = std::size_t(r + 1), i0 = pr * std::size_t(stride_) + 1;
        row_sum_[std::size_t(r)] =
            sender_row(st, i0, cols_, off, kGatherOrder, &hx_[pr * 8], &hy_[pr * 8], all, scratch.data());
      }
    });
  }
  fx_.swap(fx2_);
  fy_.swap(fy2_);
  fz_.swap(fz2_);
  q_.swap(q2_);
  double total = 0;
  for (double s : row_sum_) total += s;  // fixed order: deterministic
  return valid_count_ ? total / double(valid_count_) : 0.0;
}

BelhadjRun belhadj_hydrometry(const Dem& dem, const CellMetrics& metrics, const BelhadjOptions& options,
                              Progress& progress) {
  if (options.max_iterations < 0) throw bad_input("--iterations: must be 0 (until convergence) or positive");
  if (!(options.threshold > 0)) throw bad_input("--threshold: must be a positive number");
  ProgressStep step(progress, "hydrometry (Belhadj)");
  BelhadjModel model(dem, metrics, options.vertical, options.sea_level, options.share);
  BelhadjRun run;
  const int limit = options.max_iterations > 0 ? options.max_iterations : kSafetyCap;
  const double log_target = std::log(options.threshold);
  for (;;) {
    run.final_mean = model.step();
    ++run.iterations;
    if (run.final_mean < options.threshold || run.iterations >= limit) break;
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
  const double span = hi > lo ? hi - lo : 1.0;
  for (int r = 0; r < dem.rows(); ++r)
    for (int c = 0; c < dem.cols(); ++c) {
      if (model.valid(c, r)) run.hydrometry(c, r) = float((model.acc(c, r) - lo) / span);
      else if (!std::isnan(dem(c, r))) run.hydrometry(c, r) = 0.0f;  // sea
    }
  return run;
}

}  // namespace terrapolis::hydro
