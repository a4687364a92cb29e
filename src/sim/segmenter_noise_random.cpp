#include "panmap/sim/internal/segmenter_random.h"

#include <cmath>

#include "panmap/core/random.h"

namespace panmap {
namespace internal {
namespace segmenter {

uint64_t hashOf(std::initializer_list<uint64_t> keys) {
  uint64_t h = 0x6a09e667f3bcc909ULL;
  // splitmix64(k) is mix64(k + golden gamma): the key is whitened before it is chained in.
  for (uint64_t k : keys) h = mix64(h ^ splitmix64(k));
  return h;
}

double SegmenterRng::normal() {
  const double u1 = 1.0 - uniform();  // (0, 1]: log stays finite
  const double u2 = uniform();
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * kPi * u2);
}

double SegmenterRng::gamma(double shape) {
  if (shape < 1.0) return gamma(shape + 1.0) * std::pow(1.0 - uniform(), 1.0 / shape);
  const double d = shape - 1.0 / 3.0;
  const double c = 1.0 / std::sqrt(9.0 * d);
  for (;;) {
    double x = 0.0;
    double v = 0.0;
    do {
      x = normal();
      v = 1.0 + c * x;
    } while (v <= 0.0);
    v = v * v * v;
    const double u = 1.0 - uniform();
    if (std::log(u) < 0.5 * x * x + d - d * v + d * std::log(v)) return d * v;
  }
}

double SegmenterRng::beta(double a, double b) {
  const double x = gamma(a);
  const double y = gamma(b);
  return x / (x + y);
}

int64_t FrameContext::window(uint64_t subject, Kind kind) const {
  const int64_t length = config_.window_frames;
  const int64_t phase =
      static_cast<int64_t>(hashOf({seed_, kPhase, kind, subject}) % static_cast<uint64_t>(length));
  return floorDiv(frame_ + phase, length);
}

double FrameContext::draw(uint64_t subject, Kind kind) const {
  return toUnit(hashOf({seed_, kind, subject, key(window(subject, kind))}));
}

uint64_t FrameContext::windowHash(uint64_t subject, Kind kind, Kind sub_kind) const {
  return hashOf({seed_, sub_kind, subject, key(window(subject, kind))});
}

}  // namespace segmenter
}  // namespace internal
}  // namespace panmap
