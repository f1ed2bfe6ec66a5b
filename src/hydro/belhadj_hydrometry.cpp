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

double BelhadjModel::step() {
  std::ptrdiff_t off[8];
  for (int k = 0; k < 8; ++k) off[k] = std::ptrdiff_t(drow[k]) * stride_ + dcol[k];
  const double* z = z_.data();
  const double* valid = valid_.data();
  const bool all = share_ == BelhadjShare::all_neighbours;
  // Pass 1: each sender's Σn over its 8 neighbours, its share factor w = Q / Σn, Acc += Q.
  tbb::parallel_for(tbb::blocked_range<int>(0, rows_), [&](const tbb::blocked_range<int>& range) {
    for (int r = range.begin(); r < range.end(); ++r) {
      const std::size_t pr = std::size_t(r + 1), base = pr * std::size_t(stride_) + 1;
      const double* hx = &hx_[pr * 8];
      const double* hy = &hy_[pr * 8];
      double sum = 0;
      for (int c = 0; c < cols_; ++c) {
        const std::size_t i = base + std::size_t(c);
        double sn = 0;
        for (int k = 0; k < 8; ++k) {
          const double dz = z[std::ptrdiff_t(i) + off[k]] - z[i];
          const double rx = fx_[i] + hx[k], ry = fy_[i] + hy[k], rz = fz_[i] + dz;
          const double s = rx * hx[k] + ry * hy[k] + rz * dz;
          sn += (all || s > 0) ? std::sqrt(rx * rx + ry * ry + rz * rz) : 0.0;
        }
        w_[i] = sn > 0 ? q_[i] / sn : 0.0;
        acc_[i] += q_[i];
        sum += q_[i];
      }
      row_sum_[std::size_t(r)] = sum;
    }
  });
  // Pass 2: each receiver gathers R and |R| w from the senders whose R . V > 0.
  tbb::parallel_for(tbb::blocked_range<int>(0, rows_), [&](const tbb::blocked_range<int>& range) {
    for (int r = range.begin(); r < range.end(); ++r) {
      const std::size_t pr = std::size_t(r + 1), base = pr * std::size_t(stride_) + 1;
      for (int c = 0; c < cols_; ++c) {
        const std::size_t i = base + std::size_t(c);
        double ax = 0, ay = 0, az = 0, aq = 0;
        for (int g = 0; g < 8; ++g) {
          const int k = kGatherOrder[g];
          const std::size_t n = std::size_t(std::ptrdiff_t(i) + off[k]);
          const int j = opposite(k);  // the sender's direction towards this cell
          const std::size_t pn = std::size_t(std::ptrdiff_t(pr) + drow[k]) * 8 + std::size_t(j);
          const double vx = hx_[pn], vy = hy_[pn], vz = z[i] - z[n];
          const double rx = fx_[n] + vx, ry = fy_[n] + vy, rz = fz_[n] + vz;
          const double s = rx * vx + ry * vy + rz * vz;
          const double m = s > 0 ? valid[n] : 0.0;
          ax += m * rx;
          ay += m * ry;
          az += m * rz;
          aq += m * (std::sqrt(rx * rx + ry * ry + rz * rz) * w_[n]);
        }
        const double self = valid[i];
        fx2_[i] = self * ax;
        fy2_[i] = self * ay;
        fz2_[i] = self * az;
        q2_[i] = self * aq;
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
