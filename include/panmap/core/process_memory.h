#pragma once

#include <cstddef>

namespace panmap {

/// Resident memory of this process now, bytes (0 when /proc is unavailable).
size_t residentBytes();

/// Peak resident memory of this process so far, bytes (getrusage's ru_maxrss).
size_t peakResidentBytes();

}  // namespace panmap
