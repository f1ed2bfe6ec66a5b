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
/// mapped on their own (Linux mmap), 2 MiB-aligned and marked for transparent huge pages (a hint,
/// ignored when disabled), which spares the TLB misses of breadth-first waves that touch every
/// row; and, not taken from the heap, their pages go back to the system as soon as they are freed,
/// whatever malloc's thresholds, for the steps that follow. Elsewhere: aligned_alloc.
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
    const std::size_t size = rounded(bytes);
#if defined(__linux__)
    // Map one huge page more than needed, then unmap the unaligned head and the tail.
    void* p = mmap(nullptr, size + kHuge, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (p == MAP_FAILED) throw std::bad_alloc();
    const std::uintptr_t base = reinterpret_cast<std::uintptr_t>(p), start = (base + kHuge - 1) / kHuge * kHuge;
    if (start > base) munmap(p, start - base);
    if (const std::size_t tail = base + size + kHuge - (start + size); tail > 0)
      munmap(reinterpret_cast<void*>(start + size), tail);
#if defined(MADV_HUGEPAGE)
    madvise(reinterpret_cast<void*>(start), size, MADV_HUGEPAGE);
#endif
    return reinterpret_cast<T*>(start);
#else
    void* p = std::aligned_alloc(kHuge, size);
    if (!p) throw std::bad_alloc();
    return static_cast<T*>(p);
#endif
  }
  void deallocate(T* p, std::size_t n) {
    const std::size_t bytes = n * sizeof(T);
    if (bytes < kMinimum) return std::allocator<T>{}.deallocate(p, n);
#if defined(__linux__)
    munmap(p, rounded(bytes));
#else
    std::free(p);
#endif
  }
  template <class U>
  bool operator==(const HugePageAllocator<U>&) const { return true; }

 private:
  static std::size_t rounded(std::size_t bytes) { return (bytes + kHuge - 1) / kHuge * kHuge; }
};

/// A per-cell scratch array (see HugePageAllocator).
template <class T>
using BigVector = std::vector<T, HugePageAllocator<T>>;

/// Index offset of neighbour k in a row-major grid of `cols` columns.
inline std::ptrdiff_t neighbour_offset(int cols, int k) { return std::ptrdiff_t(drow[k]) * cols + dcol[k]; }

}  // namespace terrapolis::hydro
