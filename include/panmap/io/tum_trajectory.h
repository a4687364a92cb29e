#pragma once

#include <string>
#include <vector>

#include "panmap/core/pose.h"

namespace panmap {

/// Reads a TUM trajectory file ("t tx ty tz qx qy qz qw" lines, t in seconds, '#' comments):
/// T_W_C per line with utime = round(t * 1e6). Throws Error naming the file and line on a
/// malformed line, a non-finite value or a quaternion far from unit length.
std::vector<StampedPose> readTumTrajectory(const std::string& path);

/// Writes a TUM trajectory file (timestamps in seconds with 6 decimals), replaced whole
/// (writeFileAtomically).
void writeTumTrajectory(const std::string& path, const std::vector<StampedPose>& trajectory);

}  // namespace panmap
