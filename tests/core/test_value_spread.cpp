#include <gtest/gtest.h>

#include "panmap/core/value_spread.h"

namespace panmap {
namespace {

TEST(ValueSpread, NearestRanksOfUnsortedValues) {
  std::vector<double> values;
  for (int k = 20; k >= 1; --k) values.push_back(k);  // 20, 19, ..., 1
  const ValueSpread s = spreadOf(values);
  EXPECT_EQ(s.median, 11.0);  // element 10 of 1..20
  EXPECT_EQ(s.p95, 20.0);     // element min(19, 19)
  EXPECT_EQ(s.max, 20.0);
  const ValueSpread three = spreadOf({3.0, 1.0, 2.0});
  EXPECT_EQ(three.median, 2.0);
  EXPECT_EQ(three.p95, 3.0);  // element min(2, 2)
  const ValueSpread none = spreadOf({});
  EXPECT_EQ(none.median, 0.0);
  EXPECT_EQ(none.p95, 0.0);
  EXPECT_EQ(none.max, 0.0);
}

}  // namespace
}  // namespace panmap
