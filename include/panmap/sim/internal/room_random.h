#pragma once

#include <algorithm>
#include <cstdint>
#include <random>
#include <utility>
#include <vector>

#include "panmap/core/image.h"

namespace panmap {
namespace internal {
namespace room {

/// The room generator's random numbers. std::mt19937_64's output is fixed by the standard, its
/// distributions are not: every value is made here from the raw 64-bit words so a seed gives the
/// same room with any library. (Not core/random.h's Rng: rooms were calibrated on this stream.)
class RoomRng {
 public:
  /// Seeds the engine with `seed` as is.
  explicit RoomRng(uint64_t seed) : engine_(seed) {}
  /// Uniform in [0, 1) from the top 53 bits of one word.
  double uniform() { return static_cast<double>(engine_() >> 11) * 0x1.0p-53; }
  /// Uniform in [lo, hi), computed in double.
  float uniform(float lo, float hi) {
    return lo + static_cast<float>(uniform() * (static_cast<double>(hi) - lo));
  }
  /// Uniform integer in the inclusive range [lo, hi].
  int uniformInt(int lo, int hi) {
    return lo + static_cast<int>(engine_() % static_cast<uint64_t>(hi - lo + 1));
  }
  /// True with probability p.
  bool chance(double p) { return uniform() < p; }
  /// Fisher-Yates shuffle, one word per position.
  template <typename T>
  void shuffle(std::vector<T>* v) {
    for (size_t i = v->size(); i > 1; --i) std::swap((*v)[i - 1], (*v)[engine_() % i]);
  }

 private:
  std::mt19937_64 engine_;
};

/// (r, g, b) with each channel moved by a uniform integer in [-spread, spread], clamped to 0..255.
inline Rgb8 tint(RoomRng* rng, int r, int g, int b, int spread) {
  auto channel = [](int v) { return static_cast<uint8_t>(std::clamp(v, 0, 255)); };
  // Separate statements: the order of the draws is part of the room a seed gives.
  const int dr = rng->uniformInt(-spread, spread);
  const int dg = rng->uniformInt(-spread, spread);
  const int db = rng->uniformInt(-spread, spread);
  return Rgb8{channel(r + dr), channel(g + dg), channel(b + db)};
}

/// `c` with each channel moved as in tint(rng, r, g, b, spread).
inline Rgb8 tint(RoomRng* rng, const Rgb8& c, int spread) {
  return tint(rng, c.r, c.g, c.b, spread);
}

/// Any mid-range colour, for objects whose real colour varies widely (pictures, books).
inline Rgb8 anyColour(RoomRng* rng) { return tint(rng, 130, 130, 130, 100); }

}  // namespace room
}  // namespace internal
}  // namespace panmap
