#pragma once

#include "panmap/loop/pose_correction.h"
#include "panmap/pose_correction_t.hpp"

namespace panmap {

/// Message of a pose correction (channel PANMAP_POSE_CORRECTION).
pose_correction_t toMessage(const PoseCorrection& correction);

/// Pose correction of a message. Throws Error naming the correction and the problem: a pose
/// count that disagrees with num_poses, a pose that fromMessage(pose_t) refuses (non-finite,
/// not a unit quaternion, utime out of range), utimes out of order (PoseCorrection::check).
PoseCorrection fromMessage(const pose_correction_t& msg);

}  // namespace panmap
