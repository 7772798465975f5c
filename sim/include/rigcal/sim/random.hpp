#pragma once
// Seeded randomness whose output is identical on every platform and standard library: the engine is
// std::mt19937_64 (fully specified by the standard) and every distribution is our own mapping of raw
// 64-bit draws (std::uniform_real_distribution and friends are implementation-defined).
// Per-ray noise uses a stateless counter hash instead, so it does not depend on evaluation order or
// thread count.
#include <cstdint>
#include <random>

#include <Eigen/Core>

namespace rigcal::sim {

/// SplitMix64 finaliser: a bijective 64-bit mixer with good avalanche.
constexpr std::uint64_t mix64(std::uint64_t z) {
  z += 0x9e3779b97f4a7c15ULL;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

/// Hash of a tuple of keys (seed, sensor, firing, laser, ...): the counter-based noise source.
constexpr std::uint64_t hashKeys(std::uint64_t a, std::uint64_t b, std::uint64_t c = 0,
                                 std::uint64_t d = 0) {
  return mix64(mix64(mix64(mix64(a) ^ b) ^ c) ^ d);
}

/// [0, 1) with 53 random bits.
constexpr double unitFromBits(std::uint64_t bits) { return double(bits >> 11) * 0x1.0p-53; }

/// A standard normal deviate from two independent hashes (Box–Muller).
double normalFromBits(std::uint64_t bits1, std::uint64_t bits2);

class Rng {
 public:
  explicit Rng(std::uint64_t seed) : engine_(seed) {}

  std::uint64_t bits() { return engine_(); }
  /// Uniform in [0, 1).
  double uniform() { return unitFromBits(engine_()); }
  /// Uniform in [lo, hi).
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
  /// Uniform integer in [lo, hi] (inclusive), unbiased (rejection sampling).
  std::int64_t uniformInt(std::int64_t lo, std::int64_t hi);
  /// True with probability p.
  bool chance(double p) { return uniform() < p; }
  /// Standard normal (Box–Muller; one deviate per two draws, no hidden cache).
  double normal();
  double normal(double mean, double sigma) { return mean + sigma * normal(); }
  /// Uniform direction on the unit sphere.
  Eigen::Vector3d unitVector();
  /// An independent stream for a named purpose, so adding draws to one part of the generator does
  /// not shift every other part.
  Rng fork(std::uint64_t tag) { return Rng(hashKeys(engine_(), tag)); }

 private:
  std::mt19937_64 engine_;
};

}  // namespace rigcal::sim
