#include "panmap/io/timestamps.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "panmap/core/error.h"

namespace panmap {

TimestampUnit timestampUnitOf(const std::vector<double>& values) {
  double largest = 0.0;
  for (double v : values) {
    if (std::isfinite(v)) largest = std::max(largest, std::abs(v));
  }
  if (largest < 1e11) return {1.0, "seconds"};
  if (largest < 1e14) return {1e-3, "milliseconds"};
  if (largest < 1e17) return {1e-6, "microseconds"};
  return {1e-9, "nanoseconds"};
}

int64_t utimeOfSeconds(double t_s, const std::string& where) {
  // 9.2e12 s is int64's limit in microseconds; any real clock is far below it.
  if (!std::isfinite(t_s) || std::abs(t_s) > 9.2e12) {
    std::ostringstream why;
    why << where << ": timestamp " << t_s << " s is not a time a clock gives";
    throw Error(why.str());
  }
  return static_cast<int64_t>(std::llround(t_s * 1e6));
}

}  // namespace panmap
