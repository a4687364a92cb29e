#pragma once

#include <cmath>
#include <cstdint>

namespace panmap {

/// splitmix64 step: a well-mixed 64-bit hash, also used to derive independent seeds.
inline uint64_t splitmix64(uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

/// Hash of several values into one seed (order matters).
inline uint64_t hashSeed(uint64_t a, uint64_t b, uint64_t c = 0, uint64_t d = 0) {
  return splitmix64(splitmix64(splitmix64(splitmix64(a) ^ b) ^ c) ^ d);
}

/// A small deterministic random generator (xoshiro256**) with its own uniform and normal
/// sampling, so a seed gives the same numbers with every compiler and standard library
/// (std:: distributions do not promise that).
class Rng {
 public:
  /// Seeds the four state words from one 64-bit seed through splitmix64.
  explicit Rng(uint64_t seed) {
    for (uint64_t& s : state_) {
      seed = splitmix64(seed);
      s = seed;
    }
  }

  /// Next raw 64-bit value.
  uint64_t next() {
    const uint64_t result = rotl(state_[1] * 5, 7) * 9;
    const uint64_t t = state_[1] << 17;
    state_[2] ^= state_[0];
    state_[3] ^= state_[1];
    state_[1] ^= state_[2];
    state_[0] ^= state_[3];
    state_[2] ^= t;
    state_[3] = rotl(state_[3], 45);
    return result;
  }

  /// Uniform in [0, 1).
  double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }
  /// Uniform in [lo, hi).
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
  /// Uniform integer in [0, n) for n > 0.
  uint64_t below(uint64_t n) { return static_cast<uint64_t>(uniform() * static_cast<double>(n)); }
  /// True with probability p.
  bool bernoulli(double p) { return uniform() < p; }
  /// Standard normal sample (Box-Muller, one of the pair).
  double normal() {
    double u1 = uniform();
    while (u1 <= 0.0) u1 = uniform();
    const double u2 = uniform();
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(6.283185307179586 * u2);
  }
  /// Normal sample with mean and standard deviation.
  double normal(double mean, double sigma) { return mean + sigma * normal(); }

 private:
  static uint64_t rotl(uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }
  uint64_t state_[4];
};

}  // namespace panmap
