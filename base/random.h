// SplitMix64 (Steele, Lea, Flood 2014): a well-mixed 64-bit value from a counter or a seed, the
// one mixer the renderer, the lived-in scenes and the evaluations draw their seeds from, so
// that nearby seeds and frame numbers give unrelated draws, the same on every platform.
#pragma once

#include <cstdint>

namespace oal {

/// SplitMix64's output function: `x` mixed.
constexpr std::uint64_t SplitMixFinal(std::uint64_t x) {
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ULL;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBULL;
  return x ^ (x >> 31);
}

/// One SplitMix64 step from state `x`: x advanced by the golden ratio, then mixed.
constexpr std::uint64_t SplitMix64(std::uint64_t x) {
  return SplitMixFinal(x + 0x9E3779B97F4A7C15ULL);
}

/// The top 53 bits of `bits` as a double in [0, 1).
constexpr double UnitInterval(std::uint64_t bits) {
  return static_cast<double>(bits >> 11) * 0x1.0p-53;
}

}  // namespace oal
