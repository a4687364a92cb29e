#include "panmap/core/value_spread.h"

#include <algorithm>

namespace panmap {

ValueSpread spreadOf(std::vector<double> values) {
  ValueSpread s;
  if (values.empty()) return s;
  std::sort(values.begin(), values.end());
  s.median = values[values.size() / 2];
  s.p95 = values[std::min(values.size() - 1, values.size() * 95 / 100)];
  s.max = values.back();
  return s;
}

}  // namespace panmap
