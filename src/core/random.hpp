// Seeded numbers that are the same on every platform and standard library: the one home of
// SplitMix64 (Steele, Lea & Flood 2014), used for per-cell noise, per-arc jitter and generators.
// SPDX-License-Identifier: MIT
#pragma once
#include <cstdint>

namespace terrapolis {

/// SplitMix64 of x: x advanced by the golden-ratio constant, then mixed. A stateless hash.
constexpr std::uint64_t splitmix64(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

/// The SplitMix64 sequence from a seed.
class Rng {
 public:
  explicit Rng(std::uint64_t seed) : state_(seed) {}
  std::uint64_t next() {
    const std::uint64_t x = state_;
    state_ += 0x9e3779b97f4a7c15ull;
    return splitmix64(x);
  }
  /// Uniform in [0, 1).
  double uniform() { return double(next() >> 11) * 0x1.0p-53; }
  /// Uniform in [-1, 1).
  double symmetric() { return 2 * uniform() - 1; }

 private:
  std::uint64_t state_;
};

}  // namespace terrapolis
