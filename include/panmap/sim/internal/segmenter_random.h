#pragma once

#include <cstdint>
#include <initializer_list>

#include "panmap/sim/segmenter_noise.h"

namespace panmap {
namespace internal {
namespace segmenter {

constexpr double kPi = 3.14159265358979323846;

/// Part of every hash, so that decisions of different kinds are independent.
enum Kind : uint64_t {
  kPhase = 1,
  kMiss,
  kConfuse,
  kConfuseClass,
  kMerge,
  kSplit,
  kSplitAngle,
  kFalsePositive,
  kFalsePositiveShape,
  kBoundary,
  kScore,
  kClutter,
  kClutterClass,
};

/// splitmix64's finaliser (core splitmix64 without its increment): a bijective, well-mixing
/// 64-bit hash.
inline uint64_t mix64(uint64_t z) {
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

/// Hash of several keys, order mattering. Not core hashSeed: it chains differently, and every
/// calibrated decision of the segmenter is keyed on this one.
uint64_t hashOf(std::initializer_list<uint64_t> keys);

/// The top 53 bits of a hash as a uniform double in [0, 1).
inline double toUnit(uint64_t h) { return static_cast<double>(h >> 11) * 0x1.0p-53; }

/// A signed value (instance id, frame, window index) as a hash key.
inline uint64_t key(int64_t v) { return static_cast<uint64_t>(v); }

/// a / b rounded towards minus infinity, for b > 0 (frame indices may be negative).
inline int64_t floorDiv(int64_t a, int64_t b) { return a >= 0 ? a / b : -((-a + b - 1) / b); }

/// The splitmix64 sequence with its own samplers: std:: distributions differ between standard
/// libraries, and the output must be identical everywhere for a seed. Not core's Rng
/// (xoshiro256**): switching would change every mask, score and calibrated rate.
class SegmenterRng {
 public:
  /// The sequence starting after `seed`.
  explicit SegmenterRng(uint64_t seed) : state_(seed) {}
  /// Next raw 64-bit value.
  uint64_t next() { return mix64(state_ += 0x9e3779b97f4a7c15ULL); }
  /// Uniform in [0, 1).
  double uniform() { return toUnit(next()); }
  /// Standard normal (Box-Muller, one of the pair).
  double normal();
  /// Gamma(shape, 1) by Marsaglia and Tsang (2000); shape < 1 through the boost u^(1/shape).
  double gamma(double shape);
  /// Beta(a, b) as X / (X + Y) of two Gammas.
  double beta(double a, double b);

 private:
  uint64_t state_;
};

/// The random decisions of one frame: uniform draws that hold over per-subject time windows,
/// so a network's errors persist over neighbouring frames. Keeps the hashing conventions in one
/// place.
class FrameContext {
 public:
  /// @param config must outlive the context.
  FrameContext(const SegmenterNoiseConfig& config, uint64_t seed, int frame)
      : config_(config), seed_(seed), frame_(frame) {}

  /// Index of the time window of (subject, kind) holding this frame. A per-subject phase keeps
  /// the windows of different instances from switching on the same frame.
  int64_t window(uint64_t subject, Kind kind) const;
  /// A uniform draw in [0, 1) constant over the window.
  double draw(uint64_t subject, Kind kind) const;
  /// A hash constant over the window of (subject, kind), for a further decision `sub_kind`.
  uint64_t windowHash(uint64_t subject, Kind kind, Kind sub_kind) const;

 private:
  const SegmenterNoiseConfig& config_;
  uint64_t seed_;
  int frame_;
};

}  // namespace segmenter
}  // namespace internal
}  // namespace panmap
