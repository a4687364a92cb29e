#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace panmap {

/// The unit of a column of timestamps, judged by its largest magnitude: Unix times in seconds
/// stay below 1e11 (the year 5138), so a larger one is in ms, us or ns (ROS bags, EuRoC CSVs
/// and phone exports write those as integers). Below that, by the median step between rows:
/// more than 100 s between a camera's frames is a finer unit (times counted from the start of a
/// recording in us or ns; in ms at 30 Hz the step, 33, still reads as seconds).
struct TimestampUnit {
  double seconds_per_unit = 1.0;
  const char* name = "seconds";
};

/// The unit of the timestamps `values` (seconds when empty).
TimestampUnit timestampUnitOf(const std::vector<double>& values);

/// Seconds as microseconds, rounded. Throws Error naming `where` when t_s is not finite or
/// does not fit an int64 utime.
int64_t utimeOfSeconds(double t_s, const std::string& where);

}  // namespace panmap
