#pragma once
// Counter-based random numbers: a value is a pure function of (seed, index,
// stream), never of a shared generator, so parallel loops give the same
// output whatever the thread count.
#include <cstdint>

namespace exsynth {

/// SplitMix64 finaliser: a bijective 64-bit mix with good avalanche.
constexpr std::uint64_t mix64(std::uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

/// A 64-bit hash of (seed, index, stream).
constexpr std::uint64_t hash_index(std::uint64_t seed, std::uint64_t index, std::uint64_t stream = 0) {
  return mix64(mix64(mix64(seed) ^ index) ^ (stream * 0xD1B54A32D192ED03ull));
}

/// Small generator for the random numbers one element needs.
class IndexRng {
 public:
  IndexRng(std::uint64_t seed, std::uint64_t index, std::uint64_t stream = 0)
      : state_(hash_index(seed, index, stream)) {}
  std::uint64_t next() { return mix64(state_++); }
  /// Uniform in [0, 1).
  double uniform() { return double(next() >> 11) * 0x1.0p-53; }
  /// Uniform integer in [0, n) (n > 0).
  std::uint64_t below(std::uint64_t n) { return next() % n; }

 private:
  std::uint64_t state_;
};

}  // namespace exsynth
