#pragma once

#include <cstddef>

namespace panmap {

/// Resident memory of this process now, bytes (0 when /proc is unavailable).
size_t residentBytes();

/// Peak resident memory of this process so far, bytes (getrusage's ru_maxrss).
size_t peakResidentBytes();

/// Minor page faults of this process so far (getrusage's ru_minflt): mostly pages touched for
/// the first time, which the kernel zeroes before handing them over.
long minorPageFaults();

}  // namespace panmap
