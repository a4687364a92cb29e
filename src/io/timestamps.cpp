#include "panmap/io/timestamps.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "panmap/core/error.h"

namespace panmap {

namespace {

// The median of the positive steps between the sorted finite values (0: none).
double medianStep(const std::vector<double>& values) {
  std::vector<double> sorted;
  for (double v : values) {
    if (std::isfinite(v)) sorted.push_back(v);
  }
  std::sort(sorted.begin(), sorted.end());
  std::vector<double> steps;
  for (size_t k = 1; k < sorted.size(); ++k) {
    if (sorted[k] > sorted[k - 1]) steps.push_back(sorted[k] - sorted[k - 1]);
  }
  if (steps.empty()) return 0.0;
  std::nth_element(steps.begin(), steps.begin() + steps.size() / 2, steps.end());
  return steps[steps.size() / 2];
}

}  // namespace

TimestampUnit timestampUnitOf(const std::vector<double>& values) {
  double largest = 0.0;
  for (double v : values) {
    if (std::isfinite(v)) largest = std::max(largest, std::abs(v));
  }
  if (largest < 1e11) {
    // Times counted from the start of a recording in ms, us or ns are small numbers: by their
    // magnitude alone they read as seconds, frames 33,333 s apart, and nothing matched. A
    // camera's frames and a SLAM system's poses are at most seconds apart, so a median step of
    // more than 100 "seconds" is a finer unit: the first that puts it at 10 s or less.
    const double step = medianStep(values);
    if (step > 100.0) {
      if (step * 1e-3 <= 10.0) return {1e-3, "milliseconds"};
      if (step * 1e-6 <= 10.0) return {1e-6, "microseconds"};
      return {1e-9, "nanoseconds"};
    }
    return {1.0, "seconds"};
  }
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
