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
// Order in which a receiver gathers from its senders: the row-major order in which the thesis's
// serial loop visits them (north-west, north, north-east, west, east, south-west, south,
// south-east), so the floating-point sums equal the literal scatter's.
constexpr int kGatherOrder[8] = {5, 6, 7, 4, 0, 3, 2, 1};
constexpr int kSafetyCap = 300;
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
  w_.assign(padded, 0.0);
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

struct RowView {
  const double* __restrict z;
  const double* __restrict valid;
  const double* __restrict fx;
  const double* __restrict fy;
  const double* __restrict fz;
  const double* __restrict q;
  const double* __restrict w;
};

/// Pass 1 on a row of `n` cells starting at padded index i0: Σn, w = Q / Σn, Acc += Q.
TP_KERNEL double sender_row(const RowView& v, std::size_t i0, int n, const std::ptrdiff_t* off, const double* hx,
                            const double* hy, bool all, double* __restrict sn, double* __restrict w,
                            double* __restrict acc) {
  const double* __restrict z = v.z + i0;
  const double* __restrict fx = v.fx + i0;
  const double* __restrict fy = v.fy + i0;
  const double* __restrict fz = v.fz + i0;
  const double* __restrict q = v.q + i0;
  for (int c = 0; c < n; ++c) sn[c] = 0.0;
  for (int k = 0; k < 8; ++k) {
    const double* __restrict zn = z + off[k];
    const double vx = hx[k], vy = hy[k];
    for (int c = 0; c < n; ++c) {
      const double dz = zn[c] - z[c];
      const double rx = fx[c] + vx, ry = fy[c] + vy, rz = fz[c] + dz;
      const double s = rx * vx + ry * vy + rz * dz;
      const double norm = std::sqrt(rx * rx + ry * ry + rz * rz);
      sn[c] += (all || s > 0) ? norm : 0.0;
    }
  }
  double sum = 0;
  for (int c = 0; c < n; ++c) {
    w[i0 + std::size_t(c)] = sn[c] > 0 ? q[c] / sn[c] : 0.0;
    acc[i0 + std::size_t(c)] += q[c];
  }
  for (int c = 0; c < n; ++c) sum += q[c];
  return sum;
}

/// Pass 2 on a row: each receiver gathers R and |R| w from the senders whose R . V > 0.
TP_KERNEL void receiver_row(const RowView& v, std::size_t i0, int n, const std::ptrdiff_t* off, const int* order,
                            const double* const* hx_row, const double* const* hy_row, double* __restrict ax,
                            double* __restrict ay, double* __restrict az, double* __restrict aq) {
  const double* __restrict z = v.z + i0;
  for (int c = 0; c < n; ++c) ax[c] = ay[c] = az[c] = aq[c] = 0.0;
  for (int g = 0; g < 8; ++g) {
    const int k = order[g];
    const int j = opposite(k);  // the sender's direction towards the receiver
    const double vx = hx_row[g][j], vy = hy_row[g][j];
    const std::ptrdiff_t o = off[k];
    const double* __restrict zn = z + o;
    const double* __restrict valid = v.valid + i0 + o;
    const double* __restrict fx = v.fx + i0 + o;
    const double* __restrict fy = v.fy + i0 + o;
    const double* __restrict fz = v.fz + i0 + o;
    const double* __restrict w = v.w + i0 + o;
    for (int c = 0; c < n; ++c) {
      const double vz = z[c] - zn[c];
      const double rx = fx[c] + vx, ry = fy[c] + vy, rz = fz[c] + vz;
      const double s = rx * vx + ry * vy + rz * vz;
      const double m = s > 0 ? valid[c] : 0.0;
      ax[c] += m * rx;
      ay[c] += m * ry;
      az[c] += m * rz;
      aq[c] += m * (std::sqrt(rx * rx + ry * ry + rz * rz) * w[c]);
    }
  }
}

}  // namespace

double BelhadjModel::step() {
  std::ptrdiff_t off[8];
  for (int k = 0; k < 8; ++k) off[k] = std::ptrdiff_t(drow[k]) * stride_ + dcol[k];
  const bool all = share_ == BelhadjShare::all_neighbours;
  const RowView cur{z_.data(), valid_.data(), fx_.data(), fy_.data(), fz_.data(), q_.data(), w_.data()};
  // Pass 1: each sender's Σn over its 8 neighbours, its share factor w = Q / Σn, Acc += Q.
  tbb::parallel_for(tbb::blocked_range<int>(0, rows_), [&](const tbb::blocked_range<int>& range) {
    std::vector<double> sn(static_cast<std::size_t>(cols_));
    for (int r = range.begin(); r < range.end(); ++r) {
      const std::size_t pr = std::size_t(r + 1), i0 = pr * std::size_t(stride_) + 1;
      row_sum_[std::size_t(r)] =
          sender_row(cur, i0, cols_, off, &hx_[pr * 8], &hy_[pr * 8], all, sn.data(), w_.data(), acc_.data());
    }
  });
  // Pass 2: each receiver gathers from its senders in the thesis's serial order.
  tbb::parallel_for(tbb::blocked_range<int>(0, rows_), [&](const tbb::blocked_range<int>& range) {
    std::vector<double> buf(4 * std::size_t(cols_));
    double* ax = buf.data();
    double* ay = ax + cols_;
    double* az = ay + cols_;
    double* aq = az + cols_;
    for (int r = range.begin(); r < range.end(); ++r) {
      const std::size_t pr = std::size_t(r + 1), i0 = pr * std::size_t(stride_) + 1;
      const double* hx_row[8];
      const double* hy_row[8];
      for (int g = 0; g < 8; ++g) {
        const std::size_t sender_row_index = std::size_t(std::ptrdiff_t(pr) + drow[kGatherOrder[g]]);
        hx_row[g] = &hx_[sender_row_index * 8];
        hy_row[g] = &hy_[sender_row_index * 8];
      }
      receiver_row(cur, i0, cols_, off, kGatherOrder, hx_row, hy_row, ax, ay, az, aq);
      const double* valid = valid_.data() + i0;
      for (int c = 0; c < cols_; ++c) {
        fx2_[i0 + std::size_t(c)] = valid[c] * ax[c];
        fy2_[i0 + std::size_t(c)] = valid[c] * ay[c];
        fz2_[i0 + std::size_t(c)] = valid[c] * az[c];
        q2_[i0 + std::size_t(c)] = valid[c] * aq[c];
      }
    }
  });
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
