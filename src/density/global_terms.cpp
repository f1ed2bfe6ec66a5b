// The land ranks and the distances to water and rivers, in memory or by strips.
// SPDX-License-Identifier: MIT
#include "density/global_terms.hpp"

#include <fcntl.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <unistd.h>

#include <algorithm>
#include <bit>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <limits>

#include "core/error.hpp"

namespace terrapolis::density {
namespace {

constexpr double inf = std::numeric_limits<double>::infinity();

/// The 1-D squared distance transform of f sampled at increasing positions y (Felzenszwalb &
/// Huttenlocher 2012, non-uniform samples): d[q] = min_p f[p] + (y[q] - y[p])^2.
void lower_envelope(const std::vector<double>& y, const std::vector<double>& f, std::vector<double>& d, std::vector<int>& v,
                    std::vector<double>& z) {
  const int n = int(y.size());
  int k = -1;
  for (int q = 0; q < n; ++q) {
    if (!std::isfinite(f[std::size_t(q)])) continue;
    while (k >= 0) {
      const int p = v[std::size_t(k)];
      const double s = ((f[std::size_t(q)] + y[std::size_t(q)] * y[std::size_t(q)]) - (f[std::size_t(p)] + y[std::size_t(p)] * y[std::size_t(p)])) /
                       (2 * (y[std::size_t(q)] - y[std::size_t(p)]));
      if (s <= z[std::size_t(k)]) --k;
      else {
        z[std::size_t(k + 1)] = s;
        break;
      }
    }
    if (k < 0) z[0] = -inf;
    v[std::size_t(++k)] = q;
    z[std::size_t(k + 1)] = inf;
  }
  if (k < 0) {
    std::fill(d.begin(), d.end(), inf);
    return;
  }
  for (int q = 0, j = 0; q < n; ++q) {
    while (z[std::size_t(j + 1)] < y[std::size_t(q)]) ++j;
    const int p = v[std::size_t(j)];
    d[std::size_t(q)] = f[std::size_t(p)] + (y[std::size_t(q)] - y[std::size_t(p)]) * (y[std::size_t(q)] - y[std::size_t(p)]);
  }
}

/// One row's transform: squared metres to the row's nearest feature cell, at the row's width.
struct RowTransform {
  std::vector<double> y, f, d, z;
  std::vector<int> v;
  explicit RowTransform(std::size_t cols) : y(cols), f(cols), d(cols), z(cols + 1), v(cols) {}
  void run(const std::uint8_t* feature, double width_m) {
    for (std::size_t c = 0; c < y.size(); ++c) {
      y[c] = double(c) * width_m;
      f[c] = feature[c] ? 0.0 : inf;
    }
    lower_envelope(y, f, d, v, z);
  }
};

/// The rows' transform of rows [row0, row0 + rows) of `feature` (`cols` a row, row-major, the
/// band's first row first) into `squared`, laid out the same.
void row_distances(const std::uint8_t* feature, const CellMetrics& metrics, int row0, int rows, int cols, std::vector<double>& squared) {
  tbb::parallel_for(tbb::blocked_range<int>(0, rows, 8), [&](const tbb::blocked_range<int>& range) {
    RowTransform t(std::size_t(std::max(cols, 0)));
    for (int r = range.begin(); r < range.end(); ++r) {
      t.run(feature + std::size_t(r) * std::size_t(cols), metrics.width_m[std::size_t(row0 + r)]);
      std::copy(t.d.begin(), t.d.end(), squared.begin() + std::ptrdiff_t(std::size_t(r) * std::size_t(cols)));
    }
  });
}

/// The grid's northings: the column transform's sample positions.
std::vector<double> northings(const CellMetrics& metrics, int rows) {
  std::vector<double> northing(static_cast<std::size_t>(rows), 0.0);
  for (int r = 1; r < rows; ++r) northing[std::size_t(r)] = northing[std::size_t(r - 1)] + metrics.height_m[std::size_t(r)];
  return northing;
}

/// One column's transform of the rows' squared distances f: metres to the nearest feature cell.
struct ColumnTransform {
  const std::vector<double>& northing;
  std::vector<double> f, d, z;
  std::vector<int> v;
  ColumnTransform(const std::vector<double>& n, int rows)
      : northing(n), f(std::size_t(std::max(rows, 0))), d(std::size_t(std::max(rows, 0))), z(std::size_t(std::max(rows, 0)) + 1),
        v(std::size_t(std::max(rows, 0))) {}
  void run() { lower_envelope(northing, f, d, v, z); }
};

/// The columns' transform of `squared` (the rows' squared distances, `cols` a row, row-major)
/// into the distances in metres, `out` laid out the same.
void column_distances(const std::vector<double>& northing, int cols, const std::vector<double>& squared, std::vector<float>& out) {
  const int rows = int(northing.size());
  tbb::parallel_for(tbb::blocked_range<int>(0, cols, 4), [&](const tbb::blocked_range<int>& range) {
    ColumnTransform t(northing, rows);
    for (int c = range.begin(); c < range.end(); ++c) {
      for (int r = 0; r < rows; ++r) t.f[std::size_t(r)] = squared[std::size_t(r) * std::size_t(cols) + std::size_t(c)];
      t.run();
      for (int r = 0; r < rows; ++r) out[std::size_t(r) * std::size_t(cols) + std::size_t(c)] = float(std::sqrt(t.d[std::size_t(r)]));
    }
  });
}

void write_all(int fd, const void* data, std::size_t bytes, off_t at, const std::string& path) {
  const char* p = static_cast<const char*>(data);
  while (bytes > 0) {
    const ssize_t n = ::pwrite(fd, p, bytes, at);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) throw processing_error(path + ": cannot write scratch data (" + std::strerror(n < 0 ? errno : ENOSPC) + ")");
    p += n, bytes -= std::size_t(n), at += n;
  }
}

void read_all(int fd, void* data, std::size_t bytes, off_t at, const std::string& path) {
  char* p = static_cast<char*>(data);
  while (bytes > 0) {
    const ssize_t n = ::pread(fd, p, bytes, at);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) throw processing_error(path + ": cannot read scratch data back");
    p += n, bytes -= std::size_t(n), at += n;
  }
}

int make_scratch(const std::string& dir, std::string& path) {
  std::string name = dir + "/distancesXXXXXX";
  const int fd = ::mkstemp(name.data());
  if (fd < 0) throw processing_error(dir + ": cannot make a scratch file (" + std::strerror(errno) + ")");
  ::unlink(name.c_str());  // gone with the descriptor, even if the process is killed
  path = name;
  return fd;
}

}  // namespace

// ---- land ranks --------------------------------------------------------------------------

LandRanks::LandRanks() : counts_(std::size_t(1) << kKeyBits, 0) {}

std::size_t LandRanks::key(float v) {
  // The float's bits in the order of the values (negatives flipped), -0 read as +0, then the top 20.
  const std::uint32_t u = std::bit_cast<std::uint32_t>(v == 0 ? 0.0f : v);
  const std::uint32_t ordered = (u & 0x80000000u) ? ~u : (u | 0x80000000u);
  return std::size_t(ordered >> (32 - kKeyBits));
}

void LandRanks::add(const float* values, std::size_t n) {
  for (std::size_t i = 0; i < n; ++i)
    if (!std::isnan(values[i])) {
      if (++counts_[key(values[i])] == 0) throw processing_error("density: more than 4.3 billion land cells of one value to rank");
      ++total_;
    }
}

void LandRanks::finish() {
  ranks_.assign(counts_.size(), 0.0f);
  const double n = double(total_);
  std::uint64_t below = 0;
  for (std::size_t k = 0; k < counts_.size(); ++k) {
    ranks_[k] = float((double(below) + 0.5 * double(counts_[k])) / n);  // a value never counted: the share below it
    below += counts_[k];
  }
  std::vector<std::uint32_t>().swap(counts_);
}

float LandRanks::rank(float v) const { return std::isnan(v) ? v : ranks_[key(v)]; }

// ---- distances ---------------------------------------------------------------------------

std::vector<float> distance_to_m(const std::vector<std::uint8_t>& feature, const CellMetrics& metrics, int cols, int rows) {
  const std::size_t n = std::size_t(cols) * std::size_t(rows);
  std::vector<double> row_d2(n);
  row_distances(feature.data(), metrics, 0, rows, cols, row_d2);
  std::vector<float> out(n);
  column_distances(northings(metrics, rows), cols, row_d2, out);
  return out;
}

// A strip of columns [c0, c0 + w) holds its cells row by row from offset c0 * rows: a band of rows
// of a strip, and a whole strip, are each one contiguous run of the file.
DistanceStrips::DistanceStrips(const CellMetrics& metrics, int cols, int rows, int features, const std::string& scratch_dir,
                               double budget_bytes, const ReadBand& read, Progress& progress)
    : cols_(cols), rows_(rows), any_(std::size_t(features), false) {
  // Strips of at most 512 columns keep a tile's read to a few MB.
  strip_ = int(std::clamp(budget_bytes / (kStripBytesPerCell * rows), 1.0, std::min(512.0, double(cols))));
  const int band = int(std::clamp(budget_bytes / (kBandBytesPerCell * features * cols), 1.0, double(rows)));
  const auto cell_at = [&](int c0, int w, int r) { return std::size_t(c0) * std::size_t(rows) + std::size_t(r) * std::size_t(w); };
  std::vector<std::string> squared_paths(static_cast<std::size_t>(features));
  std::vector<int> squared(std::size_t(features), -1);
  files_.assign(std::size_t(features), -1);
  paths_.assign(std::size_t(features), "");
  try {
    for (int k = 0; k < features; ++k) squared[std::size_t(k)] = make_scratch(scratch_dir, squared_paths[std::size_t(k)]);
    for (int k = 0; k < features; ++k) files_[std::size_t(k)] = make_scratch(scratch_dir, paths_[std::size_t(k)]);
    {
      ProgressStep step(progress, "density by tiles: distances along the rows");
      std::vector<double> d2(std::size_t(band) * std::size_t(cols)), segment;
      for (int r0 = 0; r0 < rows; r0 += band) {
        const int n = std::min(band, rows - r0);
        const std::vector<std::vector<std::uint8_t>> masks = read(r0, n);
        for (int k = 0; k < features; ++k) {
          const std::vector<std::uint8_t>& mask = masks[std::size_t(k)];
          if (mask.size() != std::size_t(n) * std::size_t(cols)) throw processing_error("density: a band of the distances' features is not on the grid");
          if (std::any_of(mask.begin(), mask.end(), [](std::uint8_t m) { return m != 0; })) any_[std::size_t(k)] = true;
          row_distances(mask.data(), metrics, r0, n, cols, d2);
          for (int c0 = 0; c0 < cols; c0 += strip_) {
            const int w = std::min(strip_, cols - c0);
            segment.resize(std::size_t(w) * std::size_t(n));
            for (int r = 0; r < n; ++r)
              std::copy_n(&d2[std::size_t(r) * std::size_t(cols) + std::size_t(c0)], w, &segment[std::size_t(r) * std::size_t(w)]);
            write_all(squared[std::size_t(k)], segment.data(), segment.size() * sizeof(double), off_t(cell_at(c0, w, r0) * sizeof(double)),
                      squared_paths[std::size_t(k)]);
          }
        }
        step.update(double(r0 + n) / rows);
      }
    }
    ProgressStep step(progress, "density by tiles: distances along the columns");
    const std::vector<double> northing = northings(metrics, rows);
    std::vector<double> in;
    std::vector<float> out;
    for (int k = 0; k < features; ++k)
      for (int c0 = 0; c0 < cols; c0 += strip_) {
        const int w = std::min(strip_, cols - c0);
        in.resize(std::size_t(w) * std::size_t(rows));
        out.resize(in.size());
        read_all(squared[std::size_t(k)], in.data(), in.size() * sizeof(double), off_t(cell_at(c0, w, 0) * sizeof(double)),
                 squared_paths[std::size_t(k)]);
        column_distances(northing, w, in, out);
        write_all(files_[std::size_t(k)], out.data(), out.size() * sizeof(float), off_t(cell_at(c0, w, 0) * sizeof(float)), paths_[std::size_t(k)]);
        step.update((double(k) + double(c0 + w) / cols) / features);
        if (c0 + w == cols) ::close(squared[std::size_t(k)]), squared[std::size_t(k)] = -1;  // its disk space back before the next feature's
      }
  } catch (...) {
    for (int fd : squared)
      if (fd >= 0) ::close(fd);
    close_files();
    throw;
  }
}

DistanceStrips::~DistanceStrips() { close_files(); }

void DistanceStrips::close_files() {
  for (std::size_t k = 0; k < files_.size(); ++k)
    if (files_[k] >= 0) ::close(files_[k]), files_[k] = -1;
}

std::vector<float> DistanceStrips::window(int k, int col0, int row0, int cols, int rows) const {
  std::vector<float> out(std::size_t(cols) * std::size_t(rows)), block;
  for (int s0 = col0 / strip_ * strip_; s0 < col0 + cols; s0 += strip_) {
    const int w = std::min(strip_, cols_ - s0);
    block.resize(std::size_t(w) * std::size_t(rows));
    read_all(files_[std::size_t(k)], block.data(), block.size() * sizeof(float),
             off_t((std::size_t(s0) * std::size_t(rows_) + std::size_t(row0) * std::size_t(w)) * sizeof(float)), paths_[std::size_t(k)]);
    const int c_lo = std::max(col0, s0), c_hi = std::min(col0 + cols, s0 + w);
    for (int r = 0; r < rows; ++r)
      std::copy_n(block.data() + std::size_t(r) * std::size_t(w) + std::size_t(c_lo - s0), c_hi - c_lo,
                  out.data() + std::size_t(r) * std::size_t(cols) + std::size_t(c_lo - col0));
  }
  return out;
}

}  // namespace terrapolis::density
