// Small helpers shared by the hydrology kernels: which cells are outlets, neighbour offsets.
// SPDX-License-Identifier: MIT
#pragma once
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <memory>
#include <new>
#include <optional>
#include <vector>
#if defined(__linux__)
#include <sys/mman.h>
#endif

#include "core/neighbours.hpp"
#include "core/raster.hpp"

namespace terrapolis::hydro {

/// D8 receiver codes used in memory (not in files): 0..7 is the neighbours.hpp index,
/// `kTerminal` a cell that keeps its water (pit left unfilled, sea cell), `kNoData` a nodata cell.
inline constexpr std::uint8_t kTerminal = 8;
inline constexpr std::uint8_t kNoData = 255;

/// True when `z` is a sea cell under `sea_level` (cells at or below it are outlets).
inline bool is_sea(float z, const std::optional<double>& sea_level) { return sea_level && double(z) <= *sea_level; }

/// True when a valid cell touches the outside of the DEM: the grid border or a nodata neighbour.
/// Such cells are outlets: water may leave the grid through them (Barnes et al. 2014).
inline bool touches_outside(const Dem& dem, int col, int row) {
  if (col == 0 || row == 0 || col == dem.cols() - 1 || row == dem.rows() - 1) return true;
  for (int k = 0; k < 8; ++k)
    if (std::isnan(dem(col + dcol[k], row + drow[k]))) return true;
  return false;
}

/// Allocator for the large per-cell scratch arrays of the kernels: blocks of 4 MiB or more are
/// 2 MiB-aligned and marked for transparent huge pages (Linux madvise; a hint, ignored elsewhere
/// or when disabled), which spares the TLB misses of breadth-first waves that touch every row.
template <class T>
struct HugePageAllocator {
  using value_type = T;
  static constexpr std::size_t kHuge = std::size_t(2) << 20;
  static constexpr std::size_t kMinimum = std::size_t(4) << 20;
  HugePageAllocator() = default;
  template <class U>
  HugePageAllocator(const HugePageAllocator<U>&) {}
  T* allocate(std::size_t n) {
    const std::size_t bytes = n * sizeof(T);
    if (bytes < kMinimum) return std::allocator<T>{}.allocate(n);
    void* p = std::aligned_alloc(kHuge, (bytes + kHuge - 1) / kHuge * kHuge);
    if (!p) throw std::bad_alloc();
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    madvise(p, (bytes + kHuge - 1) / kHuge * kHuge, MADV_HUGEPAGE);
#endif
    return static_cast<T*>(p);
  }
  void deallocate(T* p, std::size_t n) {
    if (n * sizeof(T) < kMinimum) std::allocator<T>{}.deallocate(p, n);
    else std::free(p);
  }
  template <class U>
  bool operator==(const HugePageAllocator<U>&) const { return true; }
};

/// A per-cell scratch array (see HugePageAllocator).
template <class T>
using BigVector = std::vector<T, HugePageAllocator<T>>;

/// Index offset of neighbour k in a row-major grid of `cols` columns.
inline std::ptrdiff_t neighbour_offset(int cols, int k) { return std::ptrdiff_t(drow[k]) * cols + dcol[k]; }

}  // namespace terrapolis::hydro
