#pragma once

#include <vector>

namespace panmap {

/// Median, 95th percentile and largest of a list of values (all 0 for none).
struct ValueSpread {
  double median = 0.0;
  double p95 = 0.0;
  double max = 0.0;
};

/// Spread of the values by nearest rank: the median is element n / 2 of the sorted values, the
/// 95th percentile element min(n - 1, 95 n / 100).
ValueSpread spreadOf(std::vector<double> values);

}  // namespace panmap
