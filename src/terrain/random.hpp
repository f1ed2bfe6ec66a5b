// A small seeded generator whose sequence is the same on every platform and standard library.
// SPDX-License-Identifier: MIT
#pragma once
#include <cstdint>

namespace terrapolis::terrain {

/// SplitMix64 (Steele, Lea & Flood 2014): a 64-bit state advanced by a constant, then mixed.
class Rng {
 public:
  explicit Rng(std::uint64_t seed) : state_(seed) {}
  std::uint64_t next() {
    std::uint64_t z = (state_ += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
  }
  /// Uniform in [0, 1).
  double uniform() { return double(next() >> 11) * 0x1.0p-53; }
  /// Uniform in [-1, 1).
  double symmetric() { return 2 * uniform() - 1; }

 private:
  std::uint64_t state_;
};

}  // namespace terrapolis::terrain
